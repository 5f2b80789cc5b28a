//! The options of the radius-of-curvature specification, the shape modification and the
//! fairness evaluation (`docs/algorithms/kuragano.md`, "Parameters").

use serde::Serialize;

use super::modify::DEFAULT_MAX_ITERATIONS;
use super::samples::{MAX_SAMPLES, MIN_SAMPLES};
use crate::error::{Error, Result};

/// End-gradient magnitude used by the fairing method, as a fraction of the end chord. The
/// interpolant's parameter advances by one per point, so `|dR/du|` is about one chord; the
/// paper's default of one third ([`quintic::DEFAULT_GRADIENT_FRACTION`]) slows the curve
/// down near its ends and puts curvature peaks there.
///
/// [`quintic::DEFAULT_GRADIENT_FRACTION`]: crate::spline::quintic::DEFAULT_GRADIENT_FRACTION
pub const DEFAULT_METHOD_GRADIENT_FRACTION: f64 = 1.0;

/// Which residual the shape modification minimises (docs/algorithms/kuragano.md §5.5).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum Residual {
    /// `ρ_i − ρ̂_i`, with the curvature form where ρ is infinite or capped.
    #[default]
    Rho,
    /// `κ_i − 1/ρ̂_i` everywhere.
    Kappa,
}

/// The end conditions of the designed curve when [`evaluate`] or the method starts from
/// points.
///
/// [`evaluate`]: super::evaluate
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum DesignEnds {
    /// `R'' = 0`, `R'''' = 0` at both ends (ρ is infinite there).
    Natural,
    /// Gradients at point indices `0, 1, m−2, m−1` estimated by
    /// [`quintic::end_gradients`] with this fraction of the end chord as magnitude.
    ///
    /// [`quintic::end_gradients`]: crate::spline::quintic::end_gradients
    Gradients {
        /// Magnitude of each gradient relative to the end chord.
        fraction: f64,
    },
}

/// Options of the specification, shape modification and evaluation.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct KuraganoOptions {
    /// Number of ρ samples `N_s`, in `7..=`[`ROC_MAX_SAMPLES`]; `None`:
    /// `max(41, 10·segments + 1)` for a curve of that many spans.
    ///
    /// Default value: `None`.
    ///
    /// [`ROC_MAX_SAMPLES`]: crate::analysis::ROC_MAX_SAMPLES
    pub samples: Option<usize>,
    /// The cap `ρ_max` in data units; `None`: 100 times the arc length.
    ///
    /// Default value: `None`.
    pub rho_max: Option<f64>,
    /// The residual of the shape modification.
    ///
    /// Default value: [`Residual::Rho`].
    pub residual: Residual,
    /// Cap on Levenberg–Marquardt linearisations.
    ///
    /// Default value: 60.
    pub max_iterations: usize,
    /// Ends of the interpolant when the design is given as points.
    ///
    /// Default value: `Gradients { fraction: DEFAULT_METHOD_GRADIENT_FRACTION }`.
    pub ends: DesignEnds,
}

impl KuraganoOptions {
    /// The defaults listed on the fields.
    pub const DEFAULT: KuraganoOptions = KuraganoOptions {
        samples: None,
        rho_max: None,
        residual: Residual::Rho,
        max_iterations: DEFAULT_MAX_ITERATIONS,
        ends: DesignEnds::Gradients {
            fraction: DEFAULT_METHOD_GRADIENT_FRACTION,
        },
    };

    /// Set `N_s`.
    pub fn with_samples(mut self, n: usize) -> KuraganoOptions {
        self.samples = Some(n);
        self
    }

    /// Set `ρ_max` (data units).
    pub fn with_rho_max(mut self, rho_max: f64) -> KuraganoOptions {
        self.rho_max = Some(rho_max);
        self
    }

    /// Set the residual form.
    pub fn with_residual(mut self, residual: Residual) -> KuraganoOptions {
        self.residual = residual;
        self
    }

    /// Set the iteration cap.
    pub fn with_max_iterations(mut self, n: usize) -> KuraganoOptions {
        self.max_iterations = n;
        self
    }

    /// Set the ends of the interpolant of a point design.
    pub fn with_ends(mut self, ends: DesignEnds) -> KuraganoOptions {
        self.ends = ends;
        self
    }

    pub(crate) fn check(&self) -> Result<()> {
        if let Some(n) = self.samples
            && !(MIN_SAMPLES..=MAX_SAMPLES).contains(&n)
        {
            return Err(Error::InvalidParameter {
                name: "samples".into(),
                reason: format!("{n} is outside [{MIN_SAMPLES}, {MAX_SAMPLES}]"),
            });
        }
        if let Some(r) = self.rho_max
            && !(r.is_finite() && r > 0.0)
        {
            return Err(Error::InvalidParameter {
                name: "rho_max".into(),
                reason: format!("must be positive and finite, got {r}"),
            });
        }
        if let DesignEnds::Gradients { fraction } = self.ends
            && !(fraction.is_finite() && fraction > 0.0)
        {
            return Err(Error::InvalidParameter {
                name: "gradient_fraction".into(),
                reason: format!("must be positive and finite, got {fraction}"),
            });
        }
        Ok(())
    }
}

impl Default for KuraganoOptions {
    fn default() -> KuraganoOptions {
        KuraganoOptions::DEFAULT
    }
}
