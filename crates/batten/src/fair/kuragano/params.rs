//! The parameters of the `kuragano` method: the `--set` table and their parsing into
//! [`KuraganoOptions`] and the degree (`docs/algorithms/kuragano.md`, "Parameters (`--set`)").

use super::Kuragano;
use crate::analysis::roc_fairness::{
    DEFAULT_MAX_ITERATIONS, DEFAULT_METHOD_GRADIENT_FRACTION, DesignEnds, KuraganoOptions,
    MAX_DEGREE, MAX_SAMPLES, MIN_DEGREE, MIN_SAMPLES, Residual,
};
use crate::error::Result;
use crate::fair::params::{Auto, Choice, Number, Param};
use crate::fair::{FairOptions, ParamSpec};

/// The degree of the ρ(s) polynomial (`auto`: the evaluation's best).
pub(super) const DEGREE: Param<Auto<usize>> = Param {
    name: "degree",
    kind: Auto {
        min: MIN_DEGREE,
        max: MAX_DEGREE,
    },
    doc: "degree 1..6 of the ρ(s) polynomial; auto: the best degree of the evaluation",
};

/// `N_s` ([`KuraganoOptions::samples`]).
pub(super) const SAMPLES: Param<Auto<usize>> = Param {
    name: "samples",
    kind: Auto {
        min: MIN_SAMPLES,
        max: MAX_SAMPLES,
    },
    doc: "number N_s of ρ samples along the normalised arc length, 7..=100000; auto: max(41, 10 per segment + 1)",
};

/// The cap on |ρ| ([`KuraganoOptions::rho_max`]).
pub(super) const RHO_MAX: Param<Auto<f64>> = Param {
    name: "rho_max",
    kind: Auto {
        min: f64::MIN_POSITIVE,
        max: f64::MAX,
    },
    doc: "cap on |ρ| in data units (straight parts); auto: 100 × the curve length",
};

/// The residual of the fit ([`Residual`]).
pub(super) const RESIDUAL: Param<Choice> = Param {
    name: "residual",
    kind: Choice {
        default: "rho",
        choices: &["rho", "kappa"],
    },
    doc: "rho: ρ − ρ̂ (curvature form where ρ is infinite); kappa: κ − 1/ρ̂",
};

/// The ends of the design curve ([`DesignEnds`]).
pub(super) const ENDS: Param<Choice> = Param {
    name: "ends",
    kind: Choice {
        default: "gradients",
        choices: &["gradients", "natural"],
    },
    doc: "ends of the quintic interpolant: gradients (estimated at points 0, 1, m−2, m−1) or natural (R'' = R'''' = 0)",
};

/// The end gradients' magnitude ([`DEFAULT_METHOD_GRADIENT_FRACTION`]).
pub(super) const GRADIENT_FRACTION: Param<Number<f64>> = Param {
    name: "gradient_fraction",
    kind: Number {
        default: DEFAULT_METHOD_GRADIENT_FRACTION,
        min: f64::MIN_POSITIVE,
        max: f64::MAX,
    },
    doc: "end-gradient magnitude as a fraction of the end chord (the paper's default is 1/3)",
};

/// The parameters of [`Kuragano`].
pub(super) static PARAMS: &[ParamSpec] = &[
    DEGREE.spec(),
    SAMPLES.spec(),
    RHO_MAX.spec(),
    RESIDUAL.spec(),
    ENDS.spec(),
    GRADIENT_FRACTION.spec(),
];

impl Kuragano {
    pub(super) fn options(options: &FairOptions) -> Result<(KuraganoOptions, Option<usize>)> {
        let mut k = KuraganoOptions::DEFAULT
            .with_max_iterations(options.iterations_or(DEFAULT_MAX_ITERATIONS));
        let degree = options.get(&DEGREE)?;
        if let Some(samples) = options.get(&SAMPLES)? {
            k.samples = Some(samples);
        }
        if let Some(rho) = options.get(&RHO_MAX)? {
            k.rho_max = Some(rho);
        }
        k.residual = match options.get(&RESIDUAL)? {
            "kappa" => Residual::Kappa,
            _ => Residual::Rho,
        };
        let fraction = options.get(&GRADIENT_FRACTION)?;
        k.ends = match options.get(&ENDS)? {
            "natural" => DesignEnds::Natural,
            _ => DesignEnds::Gradients { fraction },
        };
        Ok((k, degree))
    }
}

/// Parameters in data units and their power of length.
pub(super) const LENGTH_PARAMS: &[(&str, i32)] = &[(RHO_MAX.name, 1), ("arc_length", 1)];
