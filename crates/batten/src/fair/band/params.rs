//! `band`'s parameters, typed, with their defaults and ranges in one place.

use crate::error::Result;
use crate::fair::{AUTO_TOLERANCE_K, FairOptions, ParamSpec};

use super::energy::Metric;

/// Default number of passes (solves), each re-taking the parameters and tangents from the
/// previous result: the first with the jerk energy, the others with the minimum-variation
/// energy.
pub const DEFAULT_PASSES: usize = 3;
/// Default weight of the full jerk inside the minimum-variation energy.
pub const DEFAULT_EPS: f64 = 0.02;
/// Default interior-point iterations per pass (`--max-iterations`).
pub const DEFAULT_MAX_ITERATIONS: usize = 200;

/// The parameter table (`batten methods`).
pub(super) const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "k",
        default: "3",
        doc: "automatic tolerance D = k·σ̂ (σ̂ the noise estimate), used when no tolerance is given; (0, 100]",
    },
    ParamSpec {
        name: "energy",
        default: "min-variation",
        doc: "min-variation (curvature variation off the tangent, re-weighted over the passes) or jerk (|C'''|²)",
    },
    ParamSpec {
        name: "eps",
        default: "0.02",
        doc: "weight of the full jerk inside the min-variation energy, for regularity; [0, 10]",
    },
    ParamSpec {
        name: "passes",
        default: "3",
        doc: "solves, each re-taking parameters and tangents from the previous result; 1..=10",
    },
];

/// The parameters as used.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct BandParams {
    /// Factor of the automatic tolerance.
    pub k: f64,
    /// The energy of the passes after the first.
    pub metric: Metric,
    /// Number of passes.
    pub passes: usize,
    /// Interior-point iterations per pass.
    pub max_iterations: usize,
}

impl BandParams {
    /// Read and check the parameters.
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] naming the parameter and its range.
    pub fn from_options(options: &FairOptions) -> Result<BandParams> {
        let k = options.param_f64_in("k", AUTO_TOLERANCE_K, f64::MIN_POSITIVE, 100.0)?;
        let eps = options.param_f64_in("eps", DEFAULT_EPS, 0.0, 10.0)?;
        let metric =
            match options.param_choice("energy", "min-variation", &["min-variation", "jerk"])? {
                "jerk" => Metric::Jerk,
                _ => Metric::MinVariation { eps },
            };
        let passes = options.param_usize_in("passes", DEFAULT_PASSES, 1, 10)?;
        let max_iterations = options.iterations_or(DEFAULT_MAX_ITERATIONS);
        Ok(BandParams {
            k,
            metric,
            passes,
            max_iterations,
        })
    }
}
