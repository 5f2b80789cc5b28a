//! `kuragano`: the fairing method of Kuragano & Yamaguchi, *NURBS curve shape modification
//! and fairness evaluation* (`../shared/papers/kuragano-nurbs-roc-fairness.txt`, §4–§5), as
//! specified (with fixes) in `../shared/spec/ALGORITHMS.md` §5.2 and §5.4–§5.6. The curve is
//! the uniform quintic of [`crate::spline::quintic`] (§5.1, §5.3); the radius-of-curvature
//! specification, the shape modification and the fairness evaluation it runs are measurements
//! of [`crate::analysis::roc_fairness`], whose module docs describe them and list where they
//! depart from the paper and the spec (their names are re-exported here too).
//!
//! # The fairing method
//!
//! [`Kuragano`] fairs a point sequence: the quintic interpolant (ends: see
//! [`DesignEnds`]; default natural ends would make ρ infinite at both ends,
//! docs/algorithms/kuragano.md §5.3, so the default is [`DesignEnds::Gradients`] with estimated end
//! gradients of magnitude [`DEFAULT_METHOD_GRADIENT_FRACTION`] of the end chord), the degree
//! (`degree=d`, default: the best degree of [`evaluate`]), the shape modification, and the modified
//! curve evaluated at the input points' parameters `u = 0, 1, …, m−1` (same count and order).
//!
//! - `--tolerance` is a hard bound: a trial step that would move any output point farther
//!   than the tolerance from its input is rejected like a step that does not decrease S
//!   (`μ *= 10`, so the next trial is shorter). The interpolant starts at zero displacement,
//!   so the bound always holds.
//! - `--fix-ends`: `q_0` and `q_{n−1}` are fixed anyway, but the curve's end points
//!   `R(0) = (q_0 + 26q_1 + 66q_2 + 26q_3 + q_4)/120` (eq 8) move with `q_1..q_4`. With
//!   fix-ends, `q_2` (and `q_{n−3}` at the other end, the control points with the largest eq-8
//!   weight) are eliminated: they are recomputed from the other control points after every step
//!   so that `R(0) = P_0` and `R(m−1) = P_{m−1}` hold exactly (to rounding); the Jacobian is
//!   taken through the elimination (chain rule). The output's end points are the input's.
//! - The report's parameters carry the degree, `N_s`, `ρ_max`, the initial and final S and the
//!   RMS of `ρ_i − ρ̂_i` after the modification.
//!
//! Straight input, and input whose interpolant has an inflection, have no applicable degree
//! (docs/algorithms/kuragano.md §5.4.4): with `degree=auto` the method returns the input unchanged
//! (status `no_change`) with a note. **\[CHOICE\]** With an explicit `degree=d` and an inflected
//! design (typically noise), ρ̂ is fitted to the samples where ρ is valid (finite, with the curve's
//! orientation) and the shape modification, whose residual takes the curvature form at the
//! inflected samples, removes the inflections; without inflections the explicit degree uses the
//! spec's fit. A degree whose ρ̂ changes sign is an error.
//!
//! **What to expect.** The method specifies the *shape* (ρ as a function of normalised arc
//! length), not closeness to the points: a small change of ρ(s) integrates twice along the arc,
//! and the fixed-u Jacobian lets the parametrisation drift, so without a tolerance the output
//! points can move by a sizeable fraction of the point spacing even on mildly noisy data (a
//! 25-point spiral with 3·10⁻⁴ radial noise: ρ matched to an RMS of 2·10⁻⁴, points moved by
//! 0.16 at a spacing of 0.25). Use `--tolerance` to bound that; heavy noise can also make the
//! parametrisation degenerate between samples (near-zero speed, a curvature spike no ρ sample
//! sees), which more `samples` mitigate.
//!
//! # Files
//!
//! - `params.rs`: the `--set` table and its parsing;
//! - `run.rs`: the method on point input;
//! - this file: the registered method.
//!
//! `docs/algorithms/kuragano.md` gives the formulas with the paper's equation numbers and maps
//! the spec sections cited here to its own.

mod params;
mod run;

use super::{FairMethod, FairOptions, Outcome, ParamSpec};
use crate::error::Result;
use crate::geom::PointSeq;

use params::{LENGTH_PARAMS, PARAMS};
use run::run_points;

/// The `kuragano` fairing method (see `docs/algorithms/kuragano.md`, and the module docs of
/// `fair/kuragano/mod.rs` in the source).
#[derive(Clone, Copy, Debug, Default)]
pub struct Kuragano;

impl FairMethod for Kuragano {
    /// No per-move check: a long input is measured while the method runs.
    fn checks_moves(&self) -> bool {
        false
    }

    fn name(&self) -> &'static str {
        "kuragano"
    }

    fn description(&self) -> &'static str {
        "Kuragano & Yamaguchi: uniform quintic B-spline, radius-of-curvature specification \
         by a polynomial in arc length, Levenberg–Marquardt shape modification"
    }

    fn parameters(&self) -> &'static [ParamSpec] {
        PARAMS
    }

    fn supports_closed(&self) -> bool {
        false
    }

    fn length_params(&self) -> &'static [(&'static str, i32)] {
        LENGTH_PARAMS
    }

    fn check_params(&self, options: &FairOptions) -> Result<()> {
        Kuragano::options(options)?.0.check()
    }

    fn run(&self, input: &PointSeq, options: &FairOptions) -> Result<Outcome> {
        // Not rotation invariant: the spec's Marquardt scaling diag(JᵀJ) depends on the
        // axes. Neither the principal frame nor a rotation-invariant scaling (the x and y
        // entries of a control point averaged) helped: each converged worse on the spec's
        // tests (degree 6: S 69 instead of below 1 % of S₀).
        run_points(input, options)
    }
}
