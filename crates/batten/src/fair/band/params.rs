//! `band`'s parameters, typed, with their defaults and ranges in one place.

use serde_json::{Map, Value};

use crate::error::Result;
use crate::fair::params::{Auto, Choice, Number, Param};
use crate::fair::{FairOptions, ParamSpec};

use super::energy::Metric;

/// Default number of passes (solves), each re-taking the parameters and tangents from the
/// previous result: the first with the jerk energy, the others with the minimum-variation
/// energy.
pub(super) const DEFAULT_PASSES: usize = 3;
/// Default significance of a biased window in the debiasing stage.
pub(super) const DEFAULT_LOCAL: f64 = 2.0;
/// Default weight of the speed term of the minimum-variation energy at [`SPEED_POINTS`]
/// points: the value with the lowest curvature error per spurious inflection on the quality
/// benchmark's tuning split (as a fixed weight, 0.0003 / 0.0005 / 0.001: median 0.187 /
/// 0.185 / 0.185 with 172 / 171 / 188 spurious inflections; 0: 0.193 with 155). See
/// `docs/algorithms/band.md`, the speed term.
pub(super) const DEFAULT_SPEED: f64 = 0.0005;
/// Default weight of the full jerk inside the minimum-variation energy.
pub(super) const DEFAULT_EPS: f64 = 0.02;
/// Default residual target of the debiasing stage, in noise standard deviations.
pub(super) const DEFAULT_FIT: f64 = 1.25;
/// Default interior-point iterations per pass (`--max-iterations`).
pub(super) const DEFAULT_MAX_ITERATIONS: usize = 200;

/// The factor of the automatic tolerance (`auto`: [`super::auto_k`]).
pub(super) const K: Param<Auto<f64>> = Param {
    name: "k",
    kind: Auto {
        min: f64::MIN_POSITIVE,
        max: 100.0,
    },
    doc: "automatic tolerance D = k·σ̂ (σ̂ the noise estimate), used when no tolerance is given; auto = max(3, √(2 ln n)), or a number in (0, 100]",
};

/// The energy of the passes after the first.
pub(super) const ENERGY: Param<Choice> = Param {
    name: "energy",
    kind: Choice {
        default: "min-variation",
        choices: &["min-variation", "jerk"],
    },
    doc: "min-variation (curvature variation off the tangent, re-weighted over the passes) or jerk (|C'''|²)",
};

/// The weight of the full jerk ([`DEFAULT_EPS`]).
pub(super) const EPS: Param<Number<f64>> = Param {
    name: "eps",
    kind: Number {
        default: DEFAULT_EPS,
        min: 0.0,
        max: 10.0,
    },
    doc: "weight of the full jerk inside the min-variation energy, for regularity; [0, 10]",
};

/// The number of points at which the speed term has the weight `speed`: a curve of `n` points
/// takes `speed·(SPEED_POINTS/n)²`. Against the jerk, the speed term of a wave `L` spacings
/// long weighs about `L²` more, and the same feature spans `n/SPEED_POINTS` times as many
/// spacings at `n` points.
pub(super) const SPEED_POINTS: f64 = 300.0;

/// The weight of the speed term ([`DEFAULT_SPEED`]).
pub(super) const SPEED: Param<Number<f64>> = Param {
    name: "speed",
    kind: Number {
        default: DEFAULT_SPEED,
        min: 0.0,
        max: 1e6,
    },
    doc: "weight of the speed term inside the min-variation energy (the tangential second difference: keeps points from crowding where the curvature peaks; at n points the weight is speed·(300/n)²); [0, 1e6]",
};

/// The debiasing stage's residual target ([`DEFAULT_FIT`]).
pub(super) const FIT: Param<Number<f64>> = Param {
    name: "fit",
    kind: Number {
        default: DEFAULT_FIT,
        min: 0.0,
        max: 10.0,
    },
    doc: "debiasing: the last stage moves back towards the data until the mean residual is fit·σ̂ per coordinate; 0 turns it off; [0, 10]",
};

/// The significance of a biased window ([`DEFAULT_LOCAL`]).
pub(super) const LOCAL: Param<Number<f64>> = Param {
    name: "local",
    kind: Number {
        default: DEFAULT_LOCAL,
        min: 0.0,
        max: 100.0,
    },
    doc: "debiasing: the data weight is raised where the residual's mean over the smoothing length exceeds local·σ̂/√count (a flattened feature); 0 turns it off; [0, 100]",
};

/// The number of passes ([`DEFAULT_PASSES`]).
pub(super) const PASSES: Param<Number<usize>> = Param {
    name: "passes",
    kind: Number {
        default: DEFAULT_PASSES,
        min: 1,
        max: 10,
    },
    doc: "solves, each re-taking parameters and tangents from the previous result; 1..=10",
};

/// The parameter table (`batten methods`).
pub(super) static PARAMS: &[ParamSpec] = &[
    K.spec(),
    ENERGY.spec(),
    EPS.spec(),
    SPEED.spec(),
    FIT.spec(),
    LOCAL.spec(),
    PASSES.spec(),
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
    pub(super) fn from_options(options: &FairOptions) -> Result<BandParams> {
        let k = options.get(&K)?;
        let eps = options.get(&EPS)?;
        let speed = options.get(&SPEED)?;
        let metric = match options.get(&ENERGY)? {
            "jerk" => Metric::Jerk,
            _ => Metric::MinVariation { eps, speed },
        };
        let passes = options.get(&PASSES)?;
        let max_iterations = options.iterations_or(DEFAULT_MAX_ITERATIONS);
        let fit = options.get(&FIT)?;
        let local = options.get(&LOCAL)?;
        Ok(BandParams {
            local,
            k,
            metric,
            passes,
            max_iterations,
            fit,
        })
    }

    /// The parameters for a curve of `n` points: the speed term's weight is `speed·(300/n)²`
    /// ([`SPEED_POINTS`]).
    pub(super) fn at_points(&self, n: usize) -> BandParams {
        let mut p = *self;
        if let Metric::MinVariation { speed, .. } = &mut p.metric {
            *speed *= (SPEED_POINTS / n.max(1) as f64).powi(2);
        }
        p
    }

    /// The parameters as used, for the report (`speed` as given, before [`Self::at_points`]).
    pub(super) fn report(&self) -> Map<String, Value> {
        let mut parameters = Map::new();
        let p = &mut parameters;
        K.write(p, self.k);
        let energy = match self.metric {
            Metric::Jerk => "jerk",
            Metric::MinVariation { .. } => "min-variation",
        };
        ENERGY.write(p, energy);
        if let Metric::MinVariation { eps, speed } = self.metric {
            EPS.write(p, eps);
            SPEED.write(p, speed);
        }
        PASSES.write(p, self.passes);
        FIT.write(p, self.fit);
        LOCAL.write(p, self.local);
        parameters
    }
}
