//! `band`'s parameters, typed, with their defaults and ranges in one place.

use crate::error::Result;
use crate::fair::{FairOptions, ParamSpec};

use super::energy::Metric;

/// Default number of passes (solves), each re-taking the parameters and tangents from the
/// previous result: the first with the jerk energy, the others with the minimum-variation
/// energy.
pub const DEFAULT_PASSES: usize = 3;
/// Default significance of a biased window in the debiasing stage.
pub(super) const DEFAULT_LOCAL: f64 = 2.0;
/// Default weight of the speed term of the minimum-variation energy.
pub(super) const DEFAULT_SPEED: f64 = 0.0;
/// Default weight of the full jerk inside the minimum-variation energy.
pub const DEFAULT_EPS: f64 = 0.02;
/// Default residual target of the debiasing stage, in noise standard deviations.
pub const DEFAULT_FIT: f64 = 1.25;
/// Default interior-point iterations per pass (`--max-iterations`).
pub const DEFAULT_MAX_ITERATIONS: usize = 200;

/// The parameter table (`batten methods`).
pub(super) const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "k",
        default: crate::fair::ParamDefault::text(&"auto"),
        doc: "automatic tolerance D = k·σ̂ (σ̂ the noise estimate), used when no tolerance is given; auto = max(3, √(2 ln n)), or a number in (0, 100]",
    },
    ParamSpec {
        name: "energy",
        default: crate::fair::ParamDefault::text(&"min-variation"),
        doc: "min-variation (curvature variation off the tangent, re-weighted over the passes) or jerk (|C'''|²)",
    },
    ParamSpec {
        name: "eps",
        default: crate::fair::ParamDefault::text(&"0.02"),
        doc: "weight of the full jerk inside the min-variation energy, for regularity; [0, 10]",
    },
    ParamSpec {
        name: "speed",
        default: crate::fair::ParamDefault::text(&"0"),
        doc: "weight of the speed term inside the min-variation energy (the tangential second difference: keeps points from crowding where the curvature peaks); [0, 1e6]",
    },
    ParamSpec {
        name: "fit",
        default: crate::fair::ParamDefault::text(&"1.25"),
        doc: "debiasing: the last stage moves back towards the data until the mean residual is fit·σ̂ per coordinate; 0 turns it off; [0, 10]",
    },
    ParamSpec {
        name: "local",
        default: crate::fair::ParamDefault::text(&"2"),
        doc: "debiasing: the data weight is raised where the residual's mean over the smoothing length exceeds local·σ̂/√count (a flattened feature); 0 turns it off; [0, 100]",
    },
    ParamSpec {
        name: "passes",
        default: crate::fair::ParamDefault::text(&"3"),
        doc: "solves, each re-taking parameters and tangents from the previous result; 1..=10",
    },
];

/// The parameters as used.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct BandParams {
    /// Factor of the automatic tolerance (`None`: [`super::auto_k`] of the point count).
    pub k: Option<f64>,
    /// The energy of the passes after the first.
    pub metric: Metric,
    /// Number of passes.
    pub passes: usize,
    /// Interior-point iterations per pass.
    pub max_iterations: usize,
    /// The debiasing stage's residual target, in noise standard deviations (0: no stage).
    pub fit: f64,
    /// The significance of a biased window of the debiasing stage, in noise standard
    /// deviations of its mean (0: one data weight everywhere).
    pub local: f64,
}

impl BandParams {
    /// Read and check the parameters.
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] naming the parameter and its range.
    pub fn from_options(options: &FairOptions) -> Result<BandParams> {
        let k = options.param_auto_f64_in("k", f64::MIN_POSITIVE, 100.0)?;
        let eps = options.param_f64_in("eps", DEFAULT_EPS, 0.0, 10.0)?;
        let speed = options.param_f64_in("speed", DEFAULT_SPEED, 0.0, 1e6)?;
        let metric =
            match options.param_choice("energy", "min-variation", &["min-variation", "jerk"])? {
                "jerk" => Metric::Jerk,
                _ => Metric::MinVariation { eps, speed },
            };
        let passes = options.param_usize_in("passes", DEFAULT_PASSES, 1, 10)?;
        let max_iterations = options.iterations_or(DEFAULT_MAX_ITERATIONS);
        let fit = options.param_f64_in("fit", DEFAULT_FIT, 0.0, 10.0)?;
        let local = options.param_f64_in("local", DEFAULT_LOCAL, 0.0, 100.0)?;
        Ok(BandParams {
            local,
            k,
            metric,
            passes,
            max_iterations,
            fit,
        })
    }
}
