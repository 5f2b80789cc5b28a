//! The parameters of the `kuragano` method: the `--set` table and their parsing into
//! [`KuraganoOptions`] and the degree (`docs/algorithms/kuragano.md`, "Parameters (`--set`)").

use super::Kuragano;
use crate::analysis::roc_fairness::{
    DEFAULT_MAX_ITERATIONS, DEFAULT_METHOD_GRADIENT_FRACTION, DesignEnds, KuraganoOptions,
    MAX_DEGREE, MAX_SAMPLES, MIN_DEGREE, MIN_SAMPLES, Residual,
};
use crate::error::Result;
use crate::fair::{FairOptions, ParamSpec};

/// The parameters of [`Kuragano`].
pub(super) const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "degree",
        default: crate::fair::ParamDefault::text(&"auto"),
        doc: "degree 1..6 of the ρ(s) polynomial; auto: the best degree of the evaluation",
    },
    ParamSpec {
        name: "samples",
        default: crate::fair::ParamDefault::text(&"auto"),
        doc: "number N_s of ρ samples along the normalised arc length, 7..=100000; auto: max(41, 10 per segment + 1)",
    },
    ParamSpec {
        name: "rho_max",
        default: crate::fair::ParamDefault::text(&"auto"),
        doc: "cap on |ρ| in data units (straight parts); auto: 100 × the curve length",
    },
    ParamSpec {
        name: "residual",
        default: crate::fair::ParamDefault::text(&"rho"),
        doc: "rho: ρ − ρ̂ (curvature form where ρ is infinite); kappa: κ − 1/ρ̂",
    },
    ParamSpec {
        name: "ends",
        default: crate::fair::ParamDefault::text(&"gradients"),
        doc: "ends of the quintic interpolant: gradients (estimated at points 0, 1, m−2, m−1) or natural (R'' = R'''' = 0)",
    },
    ParamSpec {
        name: "gradient_fraction",
        default: crate::fair::ParamDefault::text(&"1"),
        doc: "end-gradient magnitude as a fraction of the end chord (the paper's default is 1/3)",
    },
];

impl Kuragano {
    pub(super) fn options(options: &FairOptions) -> Result<(KuraganoOptions, Option<usize>)> {
        let mut k = KuraganoOptions::DEFAULT
            .with_max_iterations(options.iterations_or(DEFAULT_MAX_ITERATIONS));
        let degree = options.param_auto_usize_in("degree", MIN_DEGREE, MAX_DEGREE)?;
        if let Some(samples) = options.param_auto_usize_in("samples", MIN_SAMPLES, MAX_SAMPLES)? {
            k.samples = Some(samples);
        }
        if let Some(rho) = options.param_auto_f64_in("rho_max", f64::MIN_POSITIVE, f64::MAX)? {
            k.rho_max = Some(rho);
        }
        k.residual = match options.param_choice("residual", "rho", &["rho", "kappa"])? {
            "kappa" => Residual::Kappa,
            _ => Residual::Rho,
        };
        let fraction = options.param_f64_in(
            "gradient_fraction",
            DEFAULT_METHOD_GRADIENT_FRACTION,
            f64::MIN_POSITIVE,
            f64::MAX,
        )?;
        k.ends = match options.param_choice("ends", "gradients", &["gradients", "natural"])? {
            "natural" => DesignEnds::Natural,
            _ => DesignEnds::Gradients { fraction },
        };
        Ok((k, degree))
    }
}

/// Parameters in data units and their power of length.
pub(super) const LENGTH_PARAMS: &[(&str, i32)] = &[("rho_max", 1), ("arc_length", 1)];
