//! The registry as data: every method with its summary, what input it takes and its
//! parameters, for `batten methods --json` and the Python package's `batten.methods()`.
//!
//! Built from the registry's own [`FairMethod`] answers, so it cannot drift from what the
//! methods accept: each entry is a parameter's declaration ([`ParamSpec`]), its type the
//! declared kind ([`ParamDefault::param_type`](super::ParamDefault::param_type)) and its
//! default shown as text.

use serde::Serialize;

use super::{FairMethod, ParamSpec, ParamType, methods};

/// One parameter of a method.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct ParamInfo {
    /// The key of `--set KEY=VALUE` (a keyword argument in Python).
    pub name: &'static str,
    /// What kind of value it takes, as declared.
    #[serde(rename = "type")]
    pub kind: ParamType,
    /// The default, as text (`auto` where the method computes it).
    pub default: String,
    /// One line on what it does.
    pub doc: &'static str,
}

impl ParamInfo {
    /// The entry of one [`ParamSpec`].
    pub fn of(spec: &ParamSpec) -> ParamInfo {
        ParamInfo {
            name: spec.name,
            kind: spec.default.param_type(),
            default: spec.default.to_string(),
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

    /// Real-valued parameters are numbers whatever their default (`band`'s `speed=0` takes
    /// `0.5`), counts integers, `auto`-or-a-value parameters text.
    #[test]
    fn types_are_the_declared_kinds() {
        let kind = |method: &str, param: &str| {
            catalogue()
                .into_iter()
                .find(|m| m.name == method)
                .and_then(|m| m.parameters.into_iter().find(|p| p.name == param))
                .map(|p| (p.kind, p.default))
        };
        let number = |d: &str| Some((ParamType::Number, d.to_string()));
        assert_eq!(kind("band", "speed"), number("0.0005"));
        assert_eq!(kind("band", "local"), number("2"));
        assert_eq!(kind("kuragano", "gradient_fraction"), number("1"));
        assert_eq!(kind("han", "max_turn"), number("pi/2"));
        assert_eq!(kind("cali", "lambda_tol"), number("1e-6"));
        assert_eq!(
            kind("band", "passes"),
            Some((ParamType::Integer, "3".to_string()))
        );
        assert_eq!(
            kind("han", "fine_run3"),
            Some((ParamType::Boolean, "true".to_string()))
        );
        assert_eq!(
            kind("band", "energy"),
            Some((ParamType::Choice, "min-variation".to_string()))
        );
        assert_eq!(
            kind("salvi", "control_points"),
            Some((ParamType::Text, "auto".to_string()))
        );
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
