//! `cali`: local fairing with the integral λ-spline operator, after Calì, Miglio, Moroni and
//! Rasella, *Curve fairing using integral spline operators*
//! (`../shared/papers/cali-integral-spline-operators.txt`, §4, Steps 1–5), as specified in
//! docs/algorithms/cali.md §4.3–4.5 (`../shared/spec/ALGORITHMS.md`).
//!
//! # The algorithm
//!
//! 1. Interpolate the points `Q_0..Q_n` by a clamped degree-p B-spline (docs/algorithms/cali.md
//!    §4.3 \[CHOICE\]: chord-length parameters normalised to [0, 1], averaging knots;
//!    [`BSplineCurve::interpolate`]), so there are m + 1 = n + 1 control points.
//! 2. Compute the indicators of docs/algorithms/cali.md §4.4 \[CHOICE\]: the signed curvature
//!    `κ_j` and arc length `s_j` at the correspondence points `ξ_j`, `LFI_j = (κ''_j)²` from the
//!    second divided difference of κ with respect to s (j = 1..m−1), `GFI = Σ LFI_j`
//!    ([`crate::analysis::fairness_indicators`]).
//! 3. Take the candidates i = 2..m−2 in order of descending `LFI_i`. For each, move the five
//!    control points `P_{i−2..i+2}` to `(M^λ P)_j` ([`LambdaOperator`], docs/algorithms/cali.md
//!    §4.2, with the γ_0/α_m fix), λ minimising `LFI_i(λ)` on [0, 1] by a golden section to
//!    `lambda_tol` with both end points compared (docs/algorithms/cali.md §4.5 \[CHOICE\]). `P_0`
//!    and `P_m` are never changed (docs/algorithms/cali.md §4.5 \[CHOICE\]), so the curve keeps its
//!    end points.
//! 4. Accept the first candidate with `GFI_new < τ·GFI` (τ = 0.99 \[PAPER\]) and go back to 2;
//!    the knots are never changed and the curve is not re-interpolated.
//! 5. Stop when no candidate is accepted (the paper's "if i is the last point the procedure is
//!    finished"). The result is the B-spline with the final control points.
//!
//! # Reading of the paper
//!
//! The paper leaves the interpolation, the place where κ'' is evaluated and the λ search open;
//! the spec's normative choices above are used. Its printed operator has two errors (γ_0
//! missing, last matrix row), fixed as in docs/algorithms/cali.md §4.2; its strophoid numbers (GFI
//! 75 → 10, "analytic max |κ| ≈ 0.7") are not reproducible from eq 30 as printed
//! (docs/algorithms/cali.md §4.6) and are not asserted anywhere.
//!
//! # Common options
//!
//! - `tolerance`: the output points are the faired curve at the data parameters; a move that
//!   would take any of them farther than the tolerance from its input point is refused and the
//!   next candidate is tried. The paper has no explicit deviation bound (λ ∈ [0, 1] keeps the
//!   convex-hull property), so without a tolerance nothing is refused.
//! - `fix_ends`: always in effect, since `P_0` and `P_m` never move and the curve is clamped.
//!   `--fix-ends=tangent` (`curvature`) also holds `P_1`, `P_{m−1}` (and `P_2`, `P_{m−2}`): a
//!   move then changes only the control points of its window that are not held, which keeps
//!   the curve's end tangents (curvatures).
//! - `max_iterations`: the largest number of accepted moves, by default
//!   [`MAX_MOVES_PER_POINT`] per input point.
//!
//! Output points whose neighbourhood no accepted move touched are returned exactly as given:
//! the interpolant passes through them (up to rounding), so this is the curve's value there.
//! The first and last output points are always the input's: the curve is clamped, so they
//! are `P_0` and `P_m`, which are set to the input's ends after the interpolation (the banded
//! solve may leave a rounding error there) and never move.
//!
//! # Report
//!
//! - `moves`: one per accepted move, `index` = the centre i, `before`/`after` = the GFI,
//!   `distance` = the largest control-point displacement of the move;
//! - `history`: the GFI trend of the paper's Figures 7, 11 and 15 — row 0 is the interpolant,
//!   then one row per accepted move, with the largest output-point displacement so far;
//! - `parameters`: `tau`, `lambda_tol`, `degree`, `max_moves`, `parametrization`,
//!   `gfi_initial`, `gfi_final`, and `lambdas` (λ* of each accepted move);
//! - status: `converged` when a full pass accepted nothing after at least one move,
//!   `no_change` when nothing was ever accepted, `tolerance_limited` when the last pass refused
//!   a move that would have been accepted but for the tolerance, `iteration_limit` when
//!   `max_iterations` moves were made.
//!
//! # Degenerate input
//!
//! - Collinear (or locally straight) data: κ is zero up to rounding, and so are the LFIs.
//!   Candidates whose `|κ''_i|` is within [`ROUNDING_FACTOR`] of the rounding level of the
//!   divided difference are not tried, so a straight line comes back unchanged.
//! - Fewer than five points: no candidate centre `2..=m−2` exists; the input is returned.
//! - A move that creates a zero-speed point gives a non-finite GFI and is rejected; a
//!   zero-speed point in the interpolant itself is reported as [`Error::Degenerate`].
//!
//! # Cost
//!
//! A move changes the curve only on the support of `P_{i−2..i+2}`, so [`LocalIndicators`]
//! recomputes only the curvature at the few `ξ_j` there and the arc-length increments
//! `s_j − s_{j−1}` of the few intervals there; every `s_j` beyond the window shifts by the same
//! constant, which the divided differences do not see. A λ evaluation is O(p²) and a candidate
//! O(p²·log(1/lambda_tol)), independent of n. Basis values at the `ξ_j`, at the quadrature
//! nodes and at the data parameters are computed once. Candidate results are cached and
//! reused until an accepted move changes a control point they depend on (the result would be
//! bit-for-bit the same), and the candidate order is kept in an ordered set, so an accepted
//! move costs O(p² + log n) plus the walk over the candidates ranked above it and an O(n)
//! re-summation of the GFI.
//!
//! # Scale of τ
//!
//! The acceptance test compares a local change with the global GFI. On long inputs whose noise
//! is spread evenly, one five-point move can only remove a fraction of order 10/n of the GFI,
//! so with the paper's τ = 0.99 (31 and ~200 points in its tests) nothing is accepted beyond a
//! few hundred points; set `tau` closer to 1 there (e.g. `1 − 1/n`).
//!
//! # Files
//!
//! - this file: the method and its parameters;
//! - `run.rs`: the driver of docs/algorithms/cali.md §4.5 (candidates in LFI order, the tolerance
//!   check, the cache of candidate results, the output points and the report);
//! - `indicators.rs`: [`LocalIndicators`], the indicators kept up to date under local moves.
//!
//! `docs/algorithms/cali.md` gives the formulas with the paper's equation numbers and maps the
//! spec sections cited here to its own.
//!
//! [`BSplineCurve::interpolate`]: crate::spline::BSplineCurve::interpolate
//! [`LambdaOperator`]: crate::spline::LambdaOperator

mod indicators;
mod run;

use super::params::{Number, Param};
use super::{FairMethod, FairOptions, Outcome, ParamSpec};
use crate::error::{Error, Result};
use crate::geom::PointSeq;
use crate::spline::MAX_ORDER;

pub use indicators::{LocalIndicators, Trial};
use run::{Settings, run_cali};

/// The relaxation factor τ of the acceptance test `GFI_new < τ·GFI` (paper §5,
/// docs/algorithms/cali.md §4.5).
pub(super) const DEFAULT_TAU: f64 = 0.99;

/// Default absolute tolerance in λ of the golden-section search (docs/algorithms/cali.md §4.5
/// \[CHOICE\]).
pub(super) const DEFAULT_LAMBDA_TOL: f64 = 1e-6;

/// Default spline degree: cubic, as in the paper's tests.
pub(super) const DEFAULT_DEGREE: usize = 3;

/// Default limit on accepted moves, per input point, when `max_iterations` is not given. The
/// spec's strophoid reproduction (31 points) accepts 29–55 moves; each accepted move lowers the
/// GFI by at least the factor τ, so the limit is only a guard against very long runs.
pub(super) const MAX_MOVES_PER_POINT: usize = 50;

/// The smallest allowed `lambda_tol`: below it the golden section only resolves rounding.
const MIN_LAMBDA_TOL: f64 = 1e-12;

/// τ ([`DEFAULT_TAU`]).
const TAU: Param<Number<f64>> = Param {
    name: "tau",
    kind: Number {
        default: DEFAULT_TAU,
        min: 0.0,
        max: 1.0,
    },
    doc: "accept a move when GFI_new < tau * GFI, 0 < tau <= 1 (paper: 0.99)",
};

/// The golden section's tolerance in λ ([`DEFAULT_LAMBDA_TOL`]).
const LAMBDA_TOL: Param<Number<f64>> = Param {
    name: "lambda_tol",
    kind: Number {
        default: DEFAULT_LAMBDA_TOL,
        min: MIN_LAMBDA_TOL,
        max: 0.5,
    },
    doc: "tolerance in lambda of the golden-section search on [0, 1]",
};

/// The spline degree ([`DEFAULT_DEGREE`]).
const DEGREE: Param<Number<usize>> = Param {
    name: "degree",
    kind: Number {
        default: DEFAULT_DEGREE,
        min: 2,
        max: MAX_ORDER - 1,
    },
    doc: "degree of the interpolating B-spline, 2..=7",
};

static PARAMS: &[ParamSpec] = &[TAU.spec(), LAMBDA_TOL.spec(), DEGREE.spec()];

/// The `cali` fairing method (see `docs/algorithms/cali.md`, and the module docs of
/// `fair/cali/mod.rs` in the source).
#[derive(Clone, Copy, Debug, Default)]
pub struct Cali;

/// `tau`, `lambda_tol` and `degree`, checked.
fn cali_params(options: &FairOptions) -> Result<(f64, f64, usize)> {
    let tau = options.get(&TAU)?;
    if tau <= 0.0 {
        return Err(Error::InvalidParameter {
            name: "tau".into(),
            reason: "must be positive (no move can make the GFI negative)".into(),
        });
    }
    let lambda_tol = options.get(&LAMBDA_TOL)?;
    let degree = options.get(&DEGREE)?;
    Ok((tau, lambda_tol, degree))
}

impl FairMethod for Cali {
    /// No per-move check: a long input is measured while the method runs.
    fn checks_moves(&self) -> bool {
        false
    }

    fn name(&self) -> &'static str {
        "cali"
    }

    fn description(&self) -> &'static str {
        "Cali et al.: B-spline interpolation, then local integral lambda-operator moves of five \
         control points at the worst LFI while the GFI falls by the factor tau"
    }

    fn parameters(&self) -> &'static [ParamSpec] {
        PARAMS
    }

    fn supports_closed(&self) -> bool {
        false
    }

    fn check_params(&self, options: &FairOptions) -> Result<()> {
        cali_params(options).map(|_| ())
    }

    fn run(&self, input: &PointSeq, options: &FairOptions) -> Result<Outcome> {
        if input.is_closed() {
            return Err(Error::ClosedUnsupported {
                method: self.name().to_string(),
            });
        }
        let (tau, lambda_tol, degree) = cali_params(options)?;
        let points = input.points();
        let settings = Settings {
            tau,
            lambda_tol,
            degree,
            tolerance: options.tolerance,
            max_moves: options.iterations_or(MAX_MOVES_PER_POINT.saturating_mul(points.len())),
            held_ends: options.fix_ends.held().max(1),
            use_cache: true,
        };
        run_cali(points, &settings)
    }
}
