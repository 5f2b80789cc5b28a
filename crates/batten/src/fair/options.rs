use std::collections::BTreeMap;

use crate::error::{Error, Result};

/// Options common to every fairing method, plus the method's own parameters.
///
/// Built with [`FairOptions::default`] and the `with_*` methods; the defaults are in
/// [`FairOptions::DEFAULT`].
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct FairOptions {
    /// The largest displacement any point may have from its input position, in data units.
    /// `None`: no bound (the method's own stopping rule decides).
    ///
    /// Default value: `None`.
    pub tolerance: Option<f64>,
    /// Keep the first and last points (of an open curve) exactly where they are.
    ///
    /// Default value: `false`.
    pub fix_ends: bool,
    /// Upper bound on the method's iterations (its unit: sweeps, moves or passes).
    /// `None`: the method's own default.
    ///
    /// Default value: `None`.
    pub max_iterations: Option<usize>,
    /// Method parameters as `key = value` text (from `--set key=value`), checked against the
    /// method's [`ParamSpec`]s.
    ///
    /// Default value: empty.
    pub params: BTreeMap<String, String>,
}

impl FairOptions {
    /// The default options: no tolerance, free ends, the method's own iteration limit, no
    /// parameters.
    pub const DEFAULT: FairOptions = FairOptions {
        tolerance: None,
        fix_ends: false,
        max_iterations: None,
        params: BTreeMap::new(),
    };

    /// Set the tolerance (largest allowed point displacement, data units).
    pub fn with_tolerance(mut self, tolerance: f64) -> FairOptions {
        self.tolerance = Some(tolerance);
        self
    }

    /// Fix (or free) the end points.
    pub fn with_fix_ends(mut self, fix: bool) -> FairOptions {
        self.fix_ends = fix;
        self
    }

    /// Bound the number of iterations.
    pub fn with_max_iterations(mut self, n: usize) -> FairOptions {
        self.max_iterations = Some(n);
        self
    }

    /// Set one method parameter.
    pub fn with_param(mut self, key: &str, value: impl ToString) -> FairOptions {
        self.params.insert(key.to_string(), value.to_string());
        self
    }

    /// Check the common options: a tolerance must be finite and positive.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`].
    pub fn validate(&self) -> Result<()> {
        if let Some(t) = self.tolerance
            && !(t.is_finite() && t > 0.0)
        {
            return Err(Error::InvalidParameter {
                name: "tolerance".into(),
                reason: format!("must be a positive finite number, got {t}"),
            });
        }
        Ok(())
    }

    /// The iteration limit, or `default` when none was given.
    pub fn iterations_or(&self, default: usize) -> usize {
        self.max_iterations.unwrap_or(default)
    }

    /// A numeric parameter, or `None` when it was not set.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when the text is not a finite number.
    pub fn param_f64(&self, key: &str) -> Result<Option<f64>> {
        match self.params.get(key) {
            None => Ok(None),
            Some(s) => match s.trim().parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(Some(v)),
                _ => Err(Error::InvalidParameter {
                    name: key.into(),
                    reason: format!("'{s}' is not a finite number"),
                }),
            },
        }
    }

    /// A numeric parameter with a default, checked to lie in `[lo, hi]`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when it is not a number or out of range.
    pub fn param_f64_in(&self, key: &str, default: f64, lo: f64, hi: f64) -> Result<f64> {
        let v = self.param_f64(key)?.unwrap_or(default);
        if !(lo..=hi).contains(&v) {
            return Err(Error::InvalidParameter {
                name: key.into(),
                reason: format!("{v} is outside [{lo}, {hi}]"),
            });
        }
        Ok(v)
    }

    /// A non-negative integer parameter with a default, checked to lie in `[lo, hi]`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when it is not a whole number or out of range.
    pub fn param_usize_in(&self, key: &str, default: usize, lo: usize, hi: usize) -> Result<usize> {
        let v = match self.params.get(key) {
            None => default,
            Some(s) => s
                .trim()
                .parse::<usize>()
                .map_err(|_| Error::InvalidParameter {
                    name: key.into(),
                    reason: format!("'{s}' is not a whole number"),
                })?,
        };
        if !(lo..=hi).contains(&v) {
            return Err(Error::InvalidParameter {
                name: key.into(),
                reason: format!("{v} is outside [{lo}, {hi}]"),
            });
        }
        Ok(v)
    }

    /// A parameter that must be one of `choices`, with a default.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the allowed values.
    pub fn param_choice(
        &self,
        key: &str,
        default: &'static str,
        choices: &[&'static str],
    ) -> Result<&'static str> {
        match self.params.get(key) {
            None => Ok(default),
            Some(s) => choices
                .iter()
                .copied()
                .find(|c| *c == s.trim())
                .ok_or_else(|| Error::InvalidParameter {
                    name: key.into(),
                    reason: format!("'{s}' is not one of {}", choices.join(", ")),
                }),
        }
    }
}

impl Default for FairOptions {
    fn default() -> FairOptions {
        FairOptions::DEFAULT
    }
}

/// Description of one method parameter, for validation and `batten methods`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ParamSpec {
    /// The key used in `--set key=value`.
    pub name: &'static str,
    /// The default, as text ("auto" where it is computed).
    pub default: &'static str,
    /// One line on what it does.
    pub doc: &'static str,
}
