//! `salvi`: local fairing of a B-spline curve towards a target curvature, after P. Salvi and
//! T. Várady, *Local fairing of freeform curves and surfaces*
//! (`../shared/papers/salvi-varady-local-fairing.txt`, §4, eqs 11 and 14), as specified in
//! `../shared/spec/ALGORITHMS.md` §3 (curve algorithm, steps 1–9).
//!
//! # The algorithm
//!
//! 1. The curve `x(t) = Σ d_i N_{i,k}(t)` keeps its knots, degree and weights; only control
//!    points move.
//! 2. N uniform parameter samples `t_i` over the domain ([`SalviParams::samples`]; spec
//!    default 200, see *Deviations*).
//! 3. The target curvature g is the signed curvature `κ(t_i)` of the **unfaired** curve
//!    (§0.1), smoothed ([`Smoother`]): by default the normative centred moving average of
//!    half-width `⌊N/20⌋`, truncated at the ends, 3 passes ([`moving_average`]); or a
//!    least-squares cubic B-spline fit of κ(s) over a loose arc-length sampling; or given.
//!    `pin_ends` makes g equal κ at both ends. g stays fixed for the run.
//! 4. The measure is eq 14, `Ê = Σ_i (κ(t_i) − g(t_i))²` ([`target_measure`]).
//! 5. Selection ([`crate::fair::local::select_candidate`]): the movable control point (all but the
//!    first and last unless `free_ends`) with the largest local deviation
//!    `Dev_j = Σ_{t_i ∈ supp N_j} (κ_i − g_i)²` that is not in the recently-moved FIFO of
//!    length R = 4.
//! 6. Downhill simplex ([`crate::numeric::minimize_nelder_mead`]) over the displacement v of
//!    `d_j`: initial simplex `{0, (s,0), (0,s)}`, s = 0.1 × the mean length of the two
//!    control-polygon legs at j, stop at `xatol = 1e-9·s` or 400 evaluations.
//! 7. The eq-11 clamp keeps `|d_j − d_j⁰| ≤ δ` relative to the **original** point.
//! 8. The move is accepted only if Ê decreases; j enters the recent list either way.
//! 9. Stop when Ê improved by less than [`WINDOW_MIN_REL_IMPROVEMENT`] (relative) over the last
//!    `window` iterations, when Ê = 0, when no movable point can improve (see *Stalled
//!    points*), or at `max_iterations`.
//!
//! # Locality
//!
//! Moving `d_j` changes the curve only on the support of `N_j`, so only the samples of
//! [`crate::fair::local::support_ranges`]`[j]` change. The state keeps, per sample, the homogeneous
//! derivatives `A, A', A''` (with `W, W', W''` for rational curves) and the contribution
//! `(κ_i − g_i)²`. At the start of a move the basis column `w_j N_j^{(o)}(t_i)` is computed
//! once for the samples of the support; every simplex evaluation is then a sum over those
//! samples only (`A^{(o)} + v·w_j N_j^{(o)}`), with no allocation. An accepted move updates
//! those samples, Ê by the local difference, and `Dev` of the `2p + 1` control points whose
//! supports overlap.
//!
//! # Choices beyond the spec
//!
//! - **Clamp inside the search.** Every simplex vertex is evaluated at its clamped position
//!   (eq 11 applied to the trial point), so the simplex searches the feasible disc and the
//!   point it returns, clamped (step 7), is the one whose Ê it measured. On the spec's
//!   verification run the clamp is never active and the two readings agree.
//! - **Stalled points.** A point whose search lowered its local measure by less than
//!   [`STALL_REL_IMPROVEMENT`] (0.1 %) is skipped until a control point whose support overlaps
//!   its own makes progress — until then its objective is (nearly) unchanged and the
//!   deterministic search would repeat itself — and the run stops when every movable point is
//!   skipped ([`SalviParams::skip_stalled`]). Taken literally, step 5 keeps revisiting the
//!   R + 1 points of largest deviation once they sit at (or creep towards) their local optima,
//!   while points of smaller deviation that could still improve wait: on the spec's test
//!   (20 control points, N(0, 0.03), δ = 0.2, 300 iterations; our sine base, 12 seeds) the
//!   literal rule lowers Ê 10–86 times, the default 52–248 times (the spec's reference run:
//!   300 times, on a base curve it does not give).
//! - **Samples.** The default is `max(200, 8 × non-empty spans)`
//!   ([`DEFAULT_SAMPLES`], [`SAMPLES_PER_SPAN`]): with thousands of control points, 200
//!   samples would leave most supports empty.
//! - **Pinned ends.** `pin_ends` adds linear ramps over the first and last h samples (h the
//!   smoothing half-width) so that g = κ at both end samples without a jump in g.
//! - **B-spline smoother.** κ is sampled at `4·m` points uniform in arc length and fitted by a
//!   cubic B-spline function of s with m coefficients on uniform knots, m = `max(4, ⌊N/20⌋)`
//!   unless given; g(t_i) is that function at `s(t_i)`.
//! - **Degenerate curves.** A sample where the speed vanishes has no curvature: the input is
//!   rejected ([`Error::Degenerate`]) and a trial position that creates one counts as `+∞`.
//! - **Tolerance.** δ = the tolerance; without one, [`DEFAULT_TOLERANCE_REL`] × the diagonal
//!   of the data's bounding box. For point input the fit residual and a rounding margin are
//!   subtracted (see [`crate::fair::local`]), so the output points (the faired curve at the input's
//!   parameters) stay within the tolerance. `--fix-ends` changes nothing about the curve: the
//!   end control points are fixed by default already (and an interpolating clamped fit
//!   passes through the end points); it makes the output's end points the input's exactly.
//!   `--fix-ends=tangent` (`curvature`) also holds the second (and third) control point at
//!   each end ([`SalviParams::held_ends`]), which keeps the curve's end tangents (and
//!   curvatures).
//!
//! # Files
//!
//! - `params.rs`: [`SalviParams`], the `--set` table and its parsing;
//! - `target.rs`: the samples, the curvature, the target g and the measure Ê
//!   (docs/algorithms/salvi-varady.md §3 steps 2–4);
//! - `curve.rs`: [`fair_curve`], the search (docs/algorithms/salvi-varady.md §3 steps 5–9);
//! - this file: the method on point or B-spline input and its report.
//!
//! `docs/algorithms/salvi-varady.md` gives the formulas with the paper's equation numbers and
//! maps the spec sections cited here to its own.
//!
//! [`DEFAULT_TOLERANCE_REL`]: crate::fair::local::DEFAULT_TOLERANCE_REL
//! [`Error::Degenerate`]: crate::error::Error::Degenerate

mod curve;
mod params;
mod target;
#[cfg(test)]
mod tests;

use super::local::{self, json_f64};
use super::{FairMethod, FairOptions, Outcome, ParamSpec};
use crate::error::Result;
use crate::geom::PointSeq;
use crate::spline::BSplineCurve;

pub use curve::{SalviReport, fair_curve};
pub use params::SalviParams;
use params::{PARAMS, report_params, salvi_params};
pub use target::{MAX_SAMPLES, Smoother};

/// The `salvi` method for point input: fit a B-spline, fair it, evaluate it at the fitted
/// parameters.
#[derive(Clone, Copy, Debug, Default)]
pub struct Salvi;

impl FairMethod for Salvi {
    /// No per-move check: a long input is measured while the method runs.
    fn checks_moves(&self) -> bool {
        false
    }

    fn name(&self) -> &'static str {
        "salvi"
    }

    fn description(&self) -> &'static str {
        "Salvi & Várady local fairing: one B-spline control point at a time by downhill simplex \
         towards a smoothed target curvature, within δ of the original"
    }

    fn parameters(&self) -> &'static [ParamSpec] {
        &PARAMS
    }

    fn supports_closed(&self) -> bool {
        false
    }

    fn check_params(&self, options: &FairOptions) -> Result<()> {
        local::check_fit_params(options)?;
        salvi_params(options, None, false).map(|_| ())
    }

    fn run(&self, input: &PointSeq, options: &FairOptions) -> Result<Outcome> {
        // The simplex is axis-aligned: run in the principal frame for rigid invariance.
        super::guard::in_principal_frame(input, |input| {
            let fitted = local::fit_input(input, options)?;
            run_fitted(fitted, input, options)
        })
    }

    fn run_curve_supported(&self) -> bool {
        true
    }

    fn run_curve(
        &self,
        curve: &BSplineCurve,
        options: &FairOptions,
    ) -> Option<Result<(PointSeq, Outcome)>> {
        Some(local::on_curve(curve, options, run_fitted))
    }
}

/// The method on a fitted (or given) B-spline; `input` holds the points the output is
/// compared with.
fn run_fitted(
    fitted: local::FittedInput,
    input: &PointSeq,
    options: &FairOptions,
) -> Result<Outcome> {
    let params = salvi_params(options, Some(fitted.delta), fitted.free_ends)?
        .with_held_ends(fitted.held_ends);
    let (faired, report) = fair_curve(&fitted.curve, &params)?;
    let points = local::output_points(&faired, &fitted, input, options.fix_ends.is_fixed());
    let mut parameters = fitted.parameters.clone();
    report_params(&mut parameters, &params, report.samples.len());
    parameters.insert("max_iterations".into(), params.max_iterations.into());
    local::insert_common(&mut parameters, &report.local);
    parameters.insert(
        "max_curve_deviation".into(),
        json_f64(report.max_curve_deviation),
    );
    Ok(report.local.into_outcome(
        points,
        parameters,
        fitted.notes,
        Some(faired),
        params.free_ends,
    ))
}
