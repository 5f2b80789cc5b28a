use std::collections::BTreeMap;

use super::params::{Kind, Param};
use crate::error::{Error, Result};
pub use crate::geom::EndFix;

/// The factor `k` of an automatic tolerance `k·σ̂` ([`FairOptions::auto_tolerance`]): three
/// noise standard deviations, which a Gaussian sample exceeds with probability 0.3 % per
/// coordinate.
pub const AUTO_TOLERANCE_K: f64 = 3.0;

/// Largest iteration limit accepted ([`FairOptions::max_iterations`]). Every method's
/// iteration costs at least one pass over its curve, and the per-iteration history of the
/// report grows with the count: at this bound a 30-point `kjellander` run takes about 6 s
/// and 70 MB, and larger limits only let a run go on for minutes and gigabytes.
pub const MAX_ITERATIONS: usize = 1_000_000;

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
    /// Take the tolerance from the data when [`FairOptions::tolerance`] is `None`:
    /// `k·σ̂`, with `σ̂` the noise estimate [`crate::analysis::noise_sigma`] and `k` the
    /// method's factor ([`AUTO_TOLERANCE_K`] unless the method has its own, `band`'s `k`).
    /// Methods that default to it (`band`) take it whenever no tolerance is given.
    ///
    /// Default value: `false`.
    pub auto_tolerance: bool,
    /// What to keep at the ends of an open curve ([`EndFix`]).
    ///
    /// Default value: [`EndFix::Free`].
    pub fix_ends: EndFix,
    /// Upper bound on the method's iterations (its unit: sweeps, moves or passes), from 0 (the
    /// method's starting state, e.g. `kuragano`'s design curve) to [`MAX_ITERATIONS`]. `None`:
    /// the method's own default. The CLI takes 1 and up.
    ///
    /// Default value: `None`.
    pub max_iterations: Option<usize>,
    /// Method parameters as `key = value` text (from `--set key=value`), checked against the
    /// method's [`ParamSpec`](super::ParamSpec)s.
    ///
    /// Default value: empty.
    pub params: BTreeMap<String, String>,
    /// The clean-curve guard: return the input unchanged (status `no_change`, with a note)
    /// when a method's result has more inflections, more curvature vibrations (for an input
    /// without inflections) or a higher variation energy than its input; and, on an input without inflections or vibrations,
    /// the per-move check of the local methods (`han`, the Kjellander family,
    /// `sapidis-farin`, `eck-hadenfeld`), which refuse single moves that would make the
    /// curve worse near them. Methods exempt from it (`mst`, the csaps baseline) say so in
    /// [`super::FairMethod::keeps_clean`]. `false` gives the methods as their papers state
    /// them.
    ///
    /// Default value: `true`.
    pub keep_clean: bool,
    /// σ̂ of the input ([`crate::analysis::noise_sigma`], or `noise_sigma_space` for a space
    /// curve), as the common path ([`super::fair_with`], [`super::fair_space`]) measured it
    /// for the report and the automatic tolerance, so that a method that needs it (`band`'s
    /// debiasing stage) does not measure it again, once per widening round. Set only there,
    /// for the input the method is given; `None` elsewhere and for runs on rescaled
    /// coordinates, where the method measures it itself.
    pub(crate) measured_noise: Option<f64>,
}

impl FairOptions {
    /// The default options: no tolerance, free ends, the method's own iteration limit, no
    /// parameters.
    pub const DEFAULT: FairOptions = FairOptions {
        tolerance: None,
        auto_tolerance: false,
        fix_ends: EndFix::Free,
        max_iterations: None,
        params: BTreeMap::new(),
        keep_clean: true,
        measured_noise: None,
    };

    /// Set the tolerance (largest allowed point displacement, data units).
    pub fn with_tolerance(mut self, tolerance: f64) -> FairOptions {
        self.tolerance = Some(tolerance);
        self
    }

    /// Take the tolerance from the data (`--tolerance auto`): `k·σ̂`, see
    /// [`FairOptions::auto_tolerance`]. Clears a given tolerance.
    pub fn with_auto_tolerance(mut self) -> FairOptions {
        self.tolerance = None;
        self.auto_tolerance = true;
        self
    }

    /// Fix (or free) the end points: [`EndFix::Position`] or [`EndFix::Free`].
    pub fn with_fix_ends(mut self, fix: bool) -> FairOptions {
        self.fix_ends = if fix { EndFix::Position } else { EndFix::Free };
        self
    }

    /// Keep what `fix` says at the ends.
    pub fn with_end_fix(mut self, fix: EndFix) -> FairOptions {
        self.fix_ends = fix;
        self
    }

    /// Bound the number of iterations.
    pub fn with_max_iterations(mut self, n: usize) -> FairOptions {
        self.max_iterations = Some(n);
        self
    }

    /// Turn the clean-curve guard on or off ([`FairOptions::keep_clean`]).
    pub fn with_keep_clean(mut self, keep: bool) -> FairOptions {
        self.keep_clean = keep;
        self
    }

    /// Set one method parameter.
    pub fn with_param(mut self, key: &str, value: impl ToString) -> FairOptions {
        self.params.insert(key.to_string(), value.to_string());
        self
    }

    /// Check the common options: a tolerance must be finite and positive, an iteration limit
    /// at most [`MAX_ITERATIONS`].
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
        if let Some(n) = self.max_iterations
            && n > MAX_ITERATIONS
        {
            return Err(Error::InvalidParameter {
                name: "max_iterations".into(),
                reason: format!("{n} is outside [0, {MAX_ITERATIONS}]"),
            });
        }
        Ok(())
    }

    /// The iteration limit, or `default` when none was given.
    pub fn iterations_or(&self, default: usize) -> usize {
        self.max_iterations.unwrap_or(default)
    }

    /// The value of the method parameter `param` ([`Param`]): its default when it is not
    /// given, else the given text read as its kind and checked against its range.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the parameter.
    pub(crate) fn get<K: Kind + 'static>(&self, param: &Param<K>) -> Result<K::Value> {
        param.read(self.params.get(param.name).map(String::as_str))
    }
}

impl Default for FairOptions {
    fn default() -> FairOptions {
        FairOptions::DEFAULT
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reason(o: &FairOptions) -> String {
        match o.validate() {
            Err(Error::InvalidParameter { reason, .. }) => reason,
            other => format!("{other:?}"),
        }
    }

    #[test]
    fn iteration_limit_is_bounded_both_ways() {
        let o = FairOptions::default();
        assert!(o.clone().with_max_iterations(0).validate().is_ok());
        assert!(o.clone().with_max_iterations(1).validate().is_ok());
        assert!(
            o.clone()
                .with_max_iterations(MAX_ITERATIONS)
                .validate()
                .is_ok()
        );
        assert_eq!(
            reason(&o.clone().with_max_iterations(MAX_ITERATIONS + 1)),
            "1000001 is outside [0, 1000000]"
        );
        assert_eq!(
            reason(&o.with_max_iterations(usize::MAX)),
            "18446744073709551615 is outside [0, 1000000]"
        );
    }
}
