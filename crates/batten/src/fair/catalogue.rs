//! The registry as data: every method with its summary, what input it takes and its
//! parameters, for `batten methods --json` and the Python package's `batten.methods()`.
//!
//! Built from the registry's own [`FairMethod`] answers, so it cannot drift from what the
//! methods accept: each entry is a parameter's declaration ([`ParamSpec`]) with its default
//! shown as text. The listed [`ParamType`] is still read from that text, as it was before the
//! declarations were typed ([`ParamType::of_default`]): `true`/`false` are booleans, whole
//! numbers integers, other numbers (and `pi`, `pi/N`) numbers, a lowercase word one of
//! several choices, and anything else (`auto`: computed from the data unless given) text. It
//! differs from the declared kind ([`ParamDefault::param_type`](super::ParamDefault)) only
//! for real-valued parameters whose default is a whole number (`band`'s `speed` and `local`,
//! `kuragano`'s `gradient_fraction`), which are listed as integers.

use serde::Serialize;

use super::{FairMethod, ParamSpec, ParamType, methods};

/// One parameter of a method.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct ParamInfo {
    /// The key of `--set KEY=VALUE` (a keyword argument in Python).
    pub name: &'static str,
    /// What kind of value it takes, as read from the default.
    #[serde(rename = "type")]
    pub kind: ParamType,
    /// The default, as text (`auto` where the method computes it).
    pub default: String,
    /// One line on what it does.
    pub doc: &'static str,
}

impl ParamType {
    /// The kind of value whose default text is `default`.
    pub fn of_default(default: &str) -> ParamType {
        let d = default.trim();
        let is_pi = d == "pi"
            || d.strip_prefix("pi/")
                .is_some_and(|n| n.parse::<f64>().is_ok_and(f64::is_finite));
        if d == "true" || d == "false" {
            ParamType::Boolean
        } else if d.parse::<i64>().is_ok() {
            ParamType::Integer
        } else if d.parse::<f64>().is_ok_and(f64::is_finite) || is_pi {
            ParamType::Number
        } else if d != "auto"
            && !d.is_empty()
            && d.chars()
                .all(|c| c.is_ascii_lowercase() || c == '-' || c == '_')
        {
            ParamType::Choice
        } else {
            ParamType::Text
        }
    }
}

impl ParamInfo {
    /// The entry of one [`ParamSpec`].
    pub fn of(spec: &ParamSpec) -> ParamInfo {
        let default = spec.default.to_string();
        ParamInfo {
            name: spec.name,
            kind: ParamType::of_default(&default),
            default,
            doc: spec.doc,
        }
    }
}

/// One method of the registry.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct MethodInfo {
    /// The name given to `--method` (or `method=` in Python).
    pub name: &'static str,
    /// One line on what it does ([`FairMethod::description`]).
    pub summary: &'static str,
    /// Whether it fairs closed curves ([`FairMethod::supports_closed`]).
    pub closed_curves: bool,
    /// Whether it takes a B-spline curve as input ([`FairMethod::run_curve_supported`]).
    pub bspline_input: bool,
    /// Its parameters, in the order the method lists them.
    pub parameters: Vec<ParamInfo>,
}

impl MethodInfo {
    /// The entry of one method.
    pub fn of(m: &dyn FairMethod) -> MethodInfo {
        MethodInfo {
            name: m.name(),
            summary: m.description(),
            closed_curves: m.supports_closed(),
            bspline_input: m.run_curve_supported(),
            parameters: m.parameters().iter().map(ParamInfo::of).collect(),
        }
    }
}

/// Every registered method, in registry order: the default ([`super::default_method`]) first.
pub fn catalogue() -> Vec<MethodInfo> {
    methods().iter().map(|m| MethodInfo::of(*m)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The listed type is the declared one, but for real parameters with a whole-number
    /// default (listed as integers).
    #[test]
    fn listed_types_are_the_declared_ones_but_for_whole_number_defaults() {
        let mut integers = Vec::new();
        for m in methods() {
            for p in m.parameters() {
                let (listed, declared) = (ParamInfo::of(p).kind, p.default.param_type());
                if listed != declared {
                    assert_eq!((listed, declared), (ParamType::Integer, ParamType::Number));
                    integers.push(format!("{}.{}", m.name(), p.name));
                }
            }
        }
        assert_eq!(
            integers,
            ["band.speed", "band.local", "kuragano.gradient_fraction"]
        );
    }

    #[test]
    fn types_follow_the_default_text() {
        let cases = [
            ("true", ParamType::Boolean),
            ("false", ParamType::Boolean),
            ("3", ParamType::Integer),
            ("0", ParamType::Integer),
            ("0.99", ParamType::Number),
            ("1e-6", ParamType::Number),
            ("pi", ParamType::Number),
            ("pi/2", ParamType::Number),
            ("average", ParamType::Choice),
            ("position-and-tangent", ParamType::Choice),
            ("auto", ParamType::Text),
            ("NaN", ParamType::Text),
            ("", ParamType::Text),
        ];
        for (text, kind) in cases {
            assert_eq!(ParamType::of_default(text), kind, "{text:?}");
        }
    }

    #[test]
    fn catalogue_mirrors_the_registry() {
        let cat = catalogue();
        assert_eq!(cat.len(), methods().len());
        assert_eq!(cat[0].name, super::super::default_method());
        for (info, m) in cat.iter().zip(methods()) {
            assert_eq!(info.name, m.name());
            assert_eq!(info.summary, m.description());
            assert_eq!(info.closed_curves, m.supports_closed());
            assert_eq!(info.bspline_input, m.run_curve_supported());
            let names: Vec<_> = info.parameters.iter().map(|p| p.name).collect();
            let specs: Vec<_> = m.parameters().iter().map(|p| p.name).collect();
            assert_eq!(names, specs);
        }
        // The registry's B-spline methods say so.
        assert!(
            cat.iter()
                .any(|m| m.name == "salvi" && m.bspline_input && !m.parameters.is_empty())
        );
    }

    #[test]
    fn serialises_with_the_documented_keys() {
        let json = serde_json::to_value(catalogue()).unwrap_or_default();
        let first = &json[0];
        for key in [
            "name",
            "summary",
            "closed_curves",
            "bspline_input",
            "parameters",
        ] {
            assert!(first.get(key).is_some(), "{key} missing from {first}");
        }
        let mst = json
            .as_array()
            .and_then(|a| a.iter().find(|m| m["name"] == "mst"))
            .cloned()
            .unwrap_or_default();
        assert_eq!(mst["parameters"][0]["name"], "p");
        assert_eq!(mst["parameters"][0]["type"], "text");
        assert_eq!(mst["parameters"][0]["default"], "auto");
    }
}
