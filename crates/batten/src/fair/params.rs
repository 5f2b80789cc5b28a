//! Method parameters, each declared once: a [`Param`] constant holds the `--set` key, the
//! kind of value with its default and range, and the one-line doc. Everything else is read
//! from it: the parser ([`FairOptions::get`](super::FairOptions::get)), the method's table
//! ([`ParamSpec`], shown by `batten methods` and the catalogue), and the value written into
//! the report's `parameters` ([`Param::write`]).
//!
//! One syntax for every method: numbers in Rust's float syntax, finite; counts as whole
//! numbers; booleans as `true/false`, `yes/no`, `1/0`, `on/off` (any case); `auto` for a value
//! the method computes; angles also as `pi` and `pi/N`. A value that does not read, or lies
//! outside the declared range, is an [`Error::InvalidParameter`] naming the parameter in one
//! line.

use std::f64::consts::PI;
use std::fmt;

use serde::Serialize;
use serde_json::{Map, Value};

use crate::error::{Error, Result};

/// One method parameter: its `--set` key, the kind of value it takes with its default and
/// range (`K`: [`Number`], [`Auto`], [`Angle`], [`Flag`], [`Choice`]), and one line on what it
/// does. Declared as a `const`; the method's table lists its [`Param::spec`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Param<K> {
    /// The key of `--set KEY=VALUE`.
    pub(crate) name: &'static str,
    /// The values it takes and its default.
    pub(crate) kind: K,
    /// One line on what it does (`batten methods`).
    pub(crate) doc: &'static str,
}

impl<K: Kind + 'static> Param<K> {
    /// The entry of the method's table.
    pub(crate) const fn spec(&'static self) -> ParamSpec {
        ParamSpec {
            name: self.name,
            default: ParamDefault(&self.kind),
            doc: self.doc,
        }
    }

    /// The value given as `text` (`None`: not given, the default), read and checked.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the parameter.
    pub(crate) fn read(&self, text: Option<&str>) -> Result<K::Value> {
        self.kind.read(self.name, text)
    }

    /// Record `value`, as used, under the parameter's name in a report's `parameters`.
    pub(crate) fn write(&self, parameters: &mut Map<String, Value>, value: K::Value) {
        parameters.insert(self.name.to_string(), K::json(value));
    }
}

/// The description of one method parameter, for validation and `batten methods`: the table
/// entry made from its declaration (`Param::spec`).
#[derive(Clone, Copy, Debug)]
pub struct ParamSpec {
    /// The key used in `--set key=value`.
    pub name: &'static str,
    /// The default; it displays as `batten methods` shows it (`auto` where it is computed).
    pub default: ParamDefault,
    /// One line on what it does.
    pub doc: &'static str,
}

/// The default of a parameter, from its declaration. Displays as its text (`0.8`, `pi/2`,
/// `true`, `average`, `auto`), which the parameter accepts as its default.
#[derive(Clone, Copy, Debug)]
pub struct ParamDefault(&'static dyn Declared);

impl ParamDefault {
    /// The kind of value the parameter takes.
    pub fn param_type(&self) -> ParamType {
        self.0.param_type()
    }
}

impl fmt::Display for ParamDefault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0.default_text())
    }
}

/// The kind of value a parameter takes, as the catalogue says it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
#[non_exhaustive]
pub enum ParamType {
    /// A real number (`0.5`, `1e-6`, `pi/2`).
    Number,
    /// A whole number (`3`).
    Integer,
    /// `true` or `false`.
    Boolean,
    /// One of several words (`average`, `position-and-tangent`); the doc names them.
    Choice,
    /// Anything else, notably `auto` (a value computed from the data unless one is given;
    /// the doc says what else it takes).
    Text,
}

/// What the table needs of a kind of parameter: its default as text and its type.
pub(crate) trait Declared: fmt::Debug + Sync {
    /// The default as `batten methods` shows it.
    fn default_text(&self) -> String;
    /// The kind of value, for the catalogue.
    fn param_type(&self) -> ParamType;
}

/// A kind of parameter: how its text is read and how a value is written into a report.
pub(crate) trait Kind: Declared {
    /// The typed value.
    type Value;
    /// Read the text given for the parameter `name` (`None`: not given).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `name`.
    fn read(&self, name: &str, text: Option<&str>) -> Result<Self::Value>;
    /// The value as the report states it.
    fn json(value: Self::Value) -> Value;
}

/// The two kinds of number a parameter takes: reals (`f64`) and counts (`usize`).
pub(crate) trait Scalar:
    Copy + PartialOrd + fmt::Debug + Sync + Into<Value> + 'static
{
    /// The catalogue's type.
    const TYPE: ParamType;
    /// Read the text given for `name`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when it is not a number of this kind.
    fn parse(name: &str, text: &str) -> Result<Self>;
    /// Why `v` is not in `[lo, hi]`, in one line.
    fn outside(v: Self, lo: Self, hi: Self) -> String;
    /// The value as text.
    fn text(self) -> String;
}

impl Scalar for f64 {
    const TYPE: ParamType = ParamType::Number;

    fn parse(name: &str, text: &str) -> Result<f64> {
        match text.trim().parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(invalid(name, format!("'{text}' is not a finite number"))),
        }
    }

    fn outside(v: f64, lo: f64, hi: f64) -> String {
        range_reason(v, lo, hi)
    }

    fn text(self) -> String {
        crate::io::format_f64(self)
    }
}

impl Scalar for usize {
    const TYPE: ParamType = ParamType::Integer;

    fn parse(name: &str, text: &str) -> Result<usize> {
        text.trim()
            .parse::<usize>()
            .map_err(|_| invalid(name, format!("'{text}' is not a whole number")))
    }

    fn outside(v: usize, lo: usize, hi: usize) -> String {
        format!("{v} is outside [{lo}, {hi}]")
    }

    fn text(self) -> String {
        self.to_string()
    }
}

/// A real number (`Number<f64>`) or a count (`Number<usize>`) in `[min, max]`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Number<T> {
    pub(crate) default: T,
    pub(crate) min: T,
    pub(crate) max: T,
}

impl<T: Scalar> Declared for Number<T> {
    fn default_text(&self) -> String {
        self.default.text()
    }

    fn param_type(&self) -> ParamType {
        T::TYPE
    }
}

impl<T: Scalar> Kind for Number<T> {
    type Value = T;

    fn read(&self, name: &str, text: Option<&str>) -> Result<T> {
        let v = match text {
            None => self.default,
            Some(s) => T::parse(name, s)?,
        };
        if (self.min..=self.max).contains(&v) {
            Ok(v)
        } else {
            Err(invalid(name, T::outside(v, self.min, self.max)))
        }
    }

    fn json(value: T) -> Value {
        value.into()
    }
}

/// `auto` (the default: the method computes the value; read as `None`) or a number in
/// `[min, max]`. The report states `auto` for `None`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Auto<T> {
    pub(crate) min: T,
    pub(crate) max: T,
}

impl<T: Scalar> Param<Auto<T>> {
    /// The same parameter with the range `[min, max]`, for bounds known only at run time (a
    /// count of control points between the degree and the number of points).
    pub(crate) fn within(self, min: T, max: T) -> Param<Auto<T>> {
        Param {
            kind: Auto { min, max },
            ..self
        }
    }
}

impl<T: Scalar> Declared for Auto<T> {
    fn default_text(&self) -> String {
        "auto".to_string()
    }

    fn param_type(&self) -> ParamType {
        ParamType::Text
    }
}

impl<T: Scalar> Kind for Auto<T> {
    type Value = Option<T>;

    fn read(&self, name: &str, text: Option<&str>) -> Result<Option<T>> {
        match text {
            None => Ok(None),
            Some(s) if s.trim() == "auto" => Ok(None),
            Some(s) => {
                let number = Number {
                    default: self.min,
                    min: self.min,
                    max: self.max,
                };
                number.read(name, Some(s)).map(Some)
            }
        }
    }

    fn json(value: Option<T>) -> Value {
        value.map_or_else(|| Value::from("auto"), Into::into)
    }
}

/// An angle in radians in (0, π]: a number, `pi` (or `π`), or `pi/N`. The default shows as
/// `pi` or `pi/N` when it is one of those.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Angle {
    pub(crate) default: f64,
}

impl Declared for Angle {
    fn default_text(&self) -> String {
        let n = PI / self.default;
        if self.default == PI {
            "pi".to_string()
        } else if n.fract() == 0.0 && n > 1.0 && PI / n == self.default {
            format!("pi/{n}")
        } else {
            crate::io::format_f64(self.default)
        }
    }

    fn param_type(&self) -> ParamType {
        ParamType::Number
    }
}

impl Kind for Angle {
    type Value = f64;

    fn read(&self, name: &str, text: Option<&str>) -> Result<f64> {
        let Some(text) = text else {
            return Ok(self.default);
        };
        let t = text.trim().to_ascii_lowercase().replace('π', "pi");
        let bad = || {
            invalid(
                name,
                format!("'{text}' is not an angle (radians, pi or pi/N)"),
            )
        };
        let v = if t == "pi" {
            PI
        } else if let Some(d) = t.strip_prefix("pi/") {
            PI / d.trim().parse::<f64>().map_err(|_| bad())?
        } else {
            t.parse::<f64>().map_err(|_| bad())?
        };
        if v > 0.0 && v <= PI {
            Ok(v)
        } else {
            Err(invalid(name, format!("{v} is outside (0, π]")))
        }
    }

    fn json(value: f64) -> Value {
        value.into()
    }
}

/// A boolean: `true/false`, `yes/no`, `1/0`, `on/off`, any case.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Flag {
    pub(crate) default: bool,
}

impl Declared for Flag {
    fn default_text(&self) -> String {
        self.default.to_string()
    }

    fn param_type(&self) -> ParamType {
        ParamType::Boolean
    }
}

impl Kind for Flag {
    type Value = bool;

    fn read(&self, name: &str, text: Option<&str>) -> Result<bool> {
        match text.map(|s| s.trim().to_ascii_lowercase()) {
            None => Ok(self.default),
            Some(s) => match s.as_str() {
                "true" | "yes" | "1" | "on" => Ok(true),
                "false" | "no" | "0" | "off" => Ok(false),
                _ => Err(invalid(
                    name,
                    format!("'{s}' is not a boolean (true/false)"),
                )),
            },
        }
    }

    fn json(value: bool) -> Value {
        value.into()
    }
}

/// One of `choices`, read as the chosen word.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Choice {
    pub(crate) default: &'static str,
    pub(crate) choices: &'static [&'static str],
}

impl Declared for Choice {
    fn default_text(&self) -> String {
        self.default.to_string()
    }

    fn param_type(&self) -> ParamType {
        ParamType::Choice
    }
}

impl Kind for Choice {
    type Value = &'static str;

    fn read(&self, name: &str, text: Option<&str>) -> Result<&'static str> {
        let Some(s) = text else {
            return Ok(self.default);
        };
        self.choices
            .iter()
            .copied()
            .find(|c| *c == s.trim())
            .ok_or_else(|| {
                let list = self.choices.join(", ");
                invalid(name, format!("'{s}' is not one of {list}"))
            })
    }

    fn json(value: &'static str) -> Value {
        value.into()
    }
}

fn invalid(name: &str, reason: String) -> Error {
    Error::InvalidParameter {
        name: name.into(),
        reason,
    }
}

/// Why `v` is not in `[lo, hi]`, in words short enough for one line: the open ends of the
/// `f64` range (`f64::MIN_POSITIVE`, `f64::MAX`) are said as "positive" and "at least", not
/// printed as 300-digit numbers; other bounds in their shortest exact form. `[0, f64::MAX]`
/// is "non-negative".
pub(crate) fn range_reason(v: f64, lo: f64, hi: f64) -> String {
    let num = crate::io::format_f64;
    if lo == 0.0 && hi == f64::MAX {
        return format!("must be non-negative, got {v}");
    }
    match (lo == f64::MIN_POSITIVE, hi == f64::MAX) {
        (true, true) => format!("must be a positive number, got {}", num(v)),
        (false, true) => format!("must be at least {}, got {}", num(lo), num(v)),
        (true, false) => format!("must be positive and at most {}, got {}", num(hi), num(v)),
        (false, false) => format!("{} is outside [{}, {}]", num(v), num(lo), num(hi)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reason<T: fmt::Debug>(r: Result<T>) -> String {
        match r {
            Err(Error::InvalidParameter { reason, .. }) => reason,
            other => format!("{other:?}"),
        }
    }

    /// Every method's boolean parameters take the same spellings (one parser).
    #[test]
    fn booleans_are_read_one_way() {
        for (v, want) in [
            ("true", true),
            ("Yes", true),
            ("1", true),
            (" on ", true),
            ("FALSE", false),
            ("no", false),
            ("0", false),
            ("off", false),
        ] {
            assert_eq!(
                Flag { default: !want }.read("flag", Some(v)).ok(),
                Some(want),
                "{v}"
            );
        }
        assert_eq!(Flag { default: true }.read("flag", None).ok(), Some(true));
        assert_eq!(
            reason(Flag { default: true }.read("flag", Some(" Maybe"))),
            "'maybe' is not a boolean (true/false)"
        );
    }

    #[test]
    fn numbers_read_with_default_and_range() {
        let n = Number {
            default: 0.8,
            min: 0.0,
            max: 1.0,
        };
        assert_eq!(n.read("x", None).ok(), Some(0.8));
        assert_eq!(n.read("x", Some(" 0.25 ")).ok(), Some(0.25));
        assert_eq!(reason(n.read("x", Some("2"))), "2 is outside [0, 1]");
        assert_eq!(
            reason(n.read("x", Some("inf"))),
            "'inf' is not a finite number"
        );
        let c = Number {
            default: 5,
            min: 1,
            max: 10,
        };
        assert_eq!(c.read("x", Some("7")).ok(), Some(7));
        assert_eq!(reason(c.read("x", Some("0"))), "0 is outside [1, 10]");
        assert_eq!(
            reason(c.read("x", Some("2.5"))),
            "'2.5' is not a whole number"
        );
    }

    #[test]
    fn auto_or_a_number() {
        let a = Auto { min: 1, max: 10 };
        assert_eq!(a.read("x", None).ok(), Some(None));
        assert_eq!(a.read("x", Some(" auto ")).ok(), Some(None));
        assert_eq!(a.read("x", Some("3")).ok(), Some(Some(3)));
        assert_eq!(reason(a.read("x", Some("11"))), "11 is outside [1, 10]");
        assert_eq!(Auto::<usize>::json(None), Value::from("auto"));
        assert_eq!(Auto::<f64>::json(Some(0.5)), Value::from(0.5));
        assert_eq!(a.default_text(), "auto");
    }

    #[test]
    fn choices_name_the_allowed_words() {
        let c = Choice {
            default: "rho",
            choices: &["rho", "kappa"],
        };
        assert_eq!(c.read("x", None).ok(), Some("rho"));
        assert_eq!(c.read("x", Some(" kappa")).ok(), Some("kappa"));
        assert_eq!(
            reason(c.read("x", Some("k"))),
            "'k' is not one of rho, kappa"
        );
    }

    #[test]
    fn angle_forms() {
        let a = Angle {
            default: std::f64::consts::FRAC_PI_2,
        };
        assert_eq!(a.read("t", Some("pi")).ok(), Some(PI));
        assert_eq!(
            a.read("t", Some("π/2")).ok(),
            Some(std::f64::consts::FRAC_PI_2)
        );
        assert_eq!(a.read("t", Some(" 1.25 ")).ok(), Some(1.25));
        assert_eq!(reason(a.read("t", Some("4"))), "4 is outside (0, π]");
        assert!(a.read("t", Some("pi/x")).is_err());
        assert!(a.read("t", Some("0")).is_err());
        assert_eq!(a.default_text(), "pi/2");
        assert_eq!(Angle { default: PI }.default_text(), "pi");
        assert_eq!(Angle { default: 1.25 }.default_text(), "1.25");
    }

    #[test]
    fn defaults_show_as_written() {
        let text = |default: f64| {
            Number {
                default,
                min: 0.0,
                max: 1.0,
            }
            .default_text()
        };
        assert_eq!(text(0.8), "0.8");
        assert_eq!(text(1e-6), "1e-6");
        assert_eq!(text(0.001), "0.001");
        assert_eq!(text(0.0), "0");
        assert_eq!(text(2.0), "2");
    }

    #[test]
    fn range_reasons_stay_short() {
        assert_eq!(
            range_reason(0.0, f64::MIN_POSITIVE, f64::MAX),
            "must be a positive number, got 0"
        );
        assert_eq!(
            range_reason(-1.0, 0.5, f64::MAX),
            "must be at least 0.5, got -1"
        );
        assert_eq!(
            range_reason(-1.0, 0.0, f64::MAX),
            "must be non-negative, got -1"
        );
        assert_eq!(
            range_reason(3.0, f64::MIN_POSITIVE, 2.0),
            "must be positive and at most 2, got 3"
        );
        assert_eq!(range_reason(2.0, 0.0, 1.0), "2 is outside [0, 1]");
        assert_eq!(
            range_reason(1e300, -1e-7, 1.0),
            "1e300 is outside [-1e-7, 1]"
        );
    }
}
