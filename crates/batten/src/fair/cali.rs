//! `cali`: local fairing with the integral λ-spline operator, after Calì, Miglio, Moroni and
//! Rasella, *Curve fairing using integral spline operators*
//! (`../shared/papers/cali-integral-spline-operators.txt`, §4, Steps 1–5), as specified in
//! spec §4.3–4.5 (`../shared/spec/ALGORITHMS.md`).
//!
//! # The algorithm
//!
//! 1. Interpolate the points `Q_0..Q_n` by a clamped degree-p B-spline (spec §4.3 \[CHOICE\]:
//!    chord-length parameters normalised to [0, 1], averaging knots; [`BSplineCurve::interpolate`]),
//!    so there are m + 1 = n + 1 control points.
//! 2. Compute the indicators of spec §4.4 \[CHOICE\]: the signed curvature `κ_j` and arc length
//!    `s_j` at the correspondence points `ξ_j`, `LFI_j = (κ''_j)²` from the second divided
//!    difference of κ with respect to s (j = 1..m−1), `GFI = Σ LFI_j`
//!    ([`crate::analysis::fairness_indicators`]).
//! 3. Take the candidates i = 2..m−2 in order of descending `LFI_i`. For each, move the five
//!    control points `P_{i−2..i+2}` to `(M^λ P)_j` ([`LambdaOperator`], spec §4.2, with the
//!    γ_0/α_m fix), λ minimising `LFI_i(λ)` on [0, 1] by a golden section to `lambda_tol`
//!    with both end points compared (spec §4.5 \[CHOICE\]). `P_0` and `P_m` are never changed
//!    (spec §4.5 \[CHOICE\]), so the curve keeps its end points.
//! 4. Accept the first candidate with `GFI_new < τ·GFI` (τ = 0.99 \[PAPER\]) and go back to 2;
//!    the knots are never changed and the curve is not re-interpolated.
//! 5. Stop when no candidate is accepted (the paper's "if i is the last point the procedure is
//!    finished"). The result is the B-spline with the final control points.
//!
//! # Reading of the paper
//!
//! The paper leaves the interpolation, the place where κ'' is evaluated and the λ search open;
//! the spec's normative choices above are used. Its printed operator has two errors (γ_0
//! missing, last matrix row), fixed as in spec §4.2; its strophoid numbers (GFI 75 → 10,
//! "analytic max |κ| ≈ 0.7") are not reproducible from eq 30 as printed (spec §4.6) and are
//! not asserted anywhere.
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

use std::cmp::Reverse;
use std::collections::BTreeSet;

use serde_json::{Map, Value};

use super::{FairMethod, FairOptions, FairStatus, HistoryRow, Move, Outcome, ParamSpec};
use crate::analysis::{fairness_indicators, signed_curvature};
use crate::curve::Derivatives;
use crate::error::{Error, Result};
use crate::geom::{Point, PointSeq, Vec2};
use crate::numeric::{GaussLegendre, minimize_golden};
use crate::spline::{
    BSplineCurve, LOCAL_HALF_WIDTH, LOCAL_WIDTH, LambdaOperator, MAX_ORDER, Parametrization,
};

/// The relaxation factor τ of the acceptance test `GFI_new < τ·GFI` (paper §5, spec §4.5).
pub const DEFAULT_TAU: f64 = 0.99;

/// Default absolute tolerance in λ of the golden-section search (spec §4.5 \[CHOICE\]).
pub const DEFAULT_LAMBDA_TOL: f64 = 1e-6;

/// Default spline degree: cubic, as in the paper's tests.
pub const DEFAULT_DEGREE: usize = 3;

/// Default limit on accepted moves, per input point, when `max_iterations` is not given. The
/// spec's strophoid reproduction (31 points) accepts 29–55 moves; each accepted move lowers the
/// GFI by at least the factor τ, so the limit is only a guard against very long runs.
pub const MAX_MOVES_PER_POINT: usize = 50;

/// A candidate is only tried when `|κ''_i|` exceeds `ROUNDING_FACTOR` times the rounding level
/// of its divided difference, `ε·S/h⁴` (S the largest coordinate magnitude of the input, h the
/// shorter arc-length step next to ξ_i, ε the machine epsilon): the position error `ε·S`
/// becomes a curvature error `ε·S/h²` and a κ'' error `ε·S/h⁴`. Below it `LFI_i` is noise — on
/// collinear data κ is 0 up to rounding, and chasing that noise would slide the points along
/// the line by a fair part of their spacing.
pub const ROUNDING_FACTOR: f64 = 16.0;

/// The smallest allowed `lambda_tol`: below it the golden section only resolves rounding.
const MIN_LAMBDA_TOL: f64 = 1e-12;

static PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "tau",
        default: "0.99",
        doc: "accept a move when GFI_new < tau * GFI, 0 < tau <= 1 (paper: 0.99)",
    },
    ParamSpec {
        name: "lambda_tol",
        default: "1e-6",
        doc: "tolerance in lambda of the golden-section search on [0, 1]",
    },
    ParamSpec {
        name: "degree",
        default: "3",
        doc: "degree of the interpolating B-spline, 2..=7",
    },
];

/// The `cali` fairing method (see the module documentation).
#[derive(Clone, Copy, Debug, Default)]
pub struct Cali;

/// `tau`, `lambda_tol` and `degree`, checked.
fn cali_params(options: &FairOptions) -> Result<(f64, f64, usize)> {
    let tau = options.param_f64_in("tau", DEFAULT_TAU, 0.0, 1.0)?;
    if tau <= 0.0 {
        return Err(Error::InvalidParameter {
            name: "tau".into(),
            reason: "must be positive (no move can make the GFI negative)".into(),
        });
    }
    let lambda_tol = options.param_f64_in("lambda_tol", DEFAULT_LAMBDA_TOL, MIN_LAMBDA_TOL, 0.5)?;
    let degree = options.param_usize_in("degree", DEFAULT_DEGREE, 2, MAX_ORDER - 1)?;
    Ok((tau, lambda_tol, degree))
}

impl FairMethod for Cali {
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

/// Everything the driver needs, parsed and checked.
#[derive(Clone, Copy, Debug)]
struct Settings {
    tau: f64,
    lambda_tol: f64,
    degree: usize,
    tolerance: Option<f64>,
    max_moves: usize,
    /// Control points held at each end (`--fix-ends`).
    held_ends: usize,
    /// Reuse candidate results whose dependencies did not change (always on; off only in the
    /// unit test that checks the cache changes nothing).
    use_cache: bool,
}

/// A cached candidate evaluation.
#[derive(Clone, Debug)]
struct Cached {
    trial: Trial,
    within_tolerance: bool,
    /// Control-point indices the result depends on (inclusive).
    deps: (usize, usize),
    /// The move counter when it was computed.
    stamp: u64,
}

fn run_cali(points: &[Point], s: &Settings) -> Result<Outcome> {
    let (curve, params) =
        BSplineCurve::interpolate(points, s.degree, Parametrization::ChordLength)?;
    // A clamped interpolant has P_0 = Q_0 and P_m = Q_n exactly; the banded solve can leave a
    // rounding error there. Snap them, so the kept end control points are the input's ends.
    let mut ends = curve.control_points().to_vec();
    let last = ends.len() - 1;
    ends[0] = points[0];
    ends[last] = points[last];
    let curve = curve.with_control_points(ends)?;
    let mut state = LocalIndicators::new(&curve)?.with_held_ends(s.held_ends);
    let data = DataSamples::new(&curve, &params, points);
    let m = state.len() - 1;
    let p = s.degree;

    let mut parameters = Map::new();
    parameters.insert("tau".into(), Value::from(s.tau));
    parameters.insert("lambda_tol".into(), Value::from(s.lambda_tol));
    parameters.insert("degree".into(), Value::from(s.degree));
    parameters.insert("max_moves".into(), Value::from(s.max_moves));
    parameters.insert("parametrization".into(), Value::from("chord_length"));
    parameters.insert("gfi_initial".into(), Value::from(state.gfi()));

    let mut out: Vec<Point> = points.to_vec();
    let mut disp = vec![0.0; out.len()];
    let mut max_disp = 0.0_f64;
    let mut moves = Vec::new();
    let mut lambdas = Vec::new();
    let mut history = vec![HistoryRow {
        iteration: 0,
        measure: state.gfi(),
        max_distance: 0.0,
    }];
    let mut notes = Vec::new();

    let coordinate_scale = points
        .iter()
        .map(|q| q.x.abs().max(q.y.abs()))
        .fold(0.0, f64::max);
    let candidates = state.candidates();
    let mut order: BTreeSet<(Reverse<u64>, usize)> = candidates
        .clone()
        .map(|c| (lfi_key(state.lfi[c]), c))
        .collect();
    let mut cache: Vec<Option<Cached>> = vec![None; m + 1];
    let mut modified = vec![0u64; m + 1];
    let mut clock = 0u64;

    let mut any_above_rounding = false;
    let status = loop {
        if moves.len() >= s.max_moves {
            break FairStatus::IterationLimit;
        }
        let gfi = state.gfi();
        let threshold = s.tau * gfi;
        let mut chosen = None;
        let mut tolerance_refused = false;
        any_above_rounding = false;
        for &(_, c) in &order {
            if state.lfi[c].sqrt() <= state.rounding_level(c, coordinate_scale) {
                continue;
            }
            any_above_rounding = true;
            let valid = s.use_cache
                && cache[c]
                    .as_ref()
                    .is_some_and(|e| modified[e.deps.0..=e.deps.1].iter().all(|&t| t <= e.stamp));
            if !valid {
                let trial = state.best_trial(c, s.lambda_tol)?;
                let (window_lo, window_hi) = trial.moved_range();
                let (k_lo, k_hi) = data.affected(window_lo, window_hi + p);
                let within_tolerance = match s.tolerance {
                    None => true,
                    Some(tol) => (k_lo..k_hi).all(|k| {
                        let q = data.eval(k, |j| trial.control_point(&state.ctrl, j));
                        (q - data.input[k]).length() <= tol
                    }),
                };
                let mut deps = trial.deps;
                if k_lo < k_hi {
                    deps.0 = deps.0.min(data.span[k_lo].saturating_sub(p));
                    deps.1 = deps.1.max(data.span[k_hi - 1]);
                }
                cache[c] = Some(Cached {
                    trial,
                    within_tolerance,
                    deps,
                    stamp: clock,
                });
            }
            let Some(entry) = cache[c].as_ref() else {
                continue;
            };
            // NaN (a zero-speed point created by the move) is not less: rejected.
            let accepted_by_gfi = (gfi + entry.trial.delta_gfi)
                .partial_cmp(&threshold)
                .is_some_and(|o| o.is_lt());
            if !accepted_by_gfi {
                continue;
            }
            if !entry.within_tolerance {
                tolerance_refused = true;
                continue;
            }
            chosen = Some(c);
            break;
        }
        let Some(c) = chosen else {
            break if tolerance_refused {
                FairStatus::ToleranceLimited
            } else if moves.is_empty() {
                FairStatus::NoChange
            } else {
                FairStatus::Converged
            };
        };
        let Some(entry) = cache[c].take() else {
            break FairStatus::Converged;
        };
        let trial = entry.trial;

        // Re-key the candidates whose LFI changes.
        let (l_lo, l_hi) = trial.lfi_range();
        for j in l_lo.max(*candidates.start())..=l_hi.min(*candidates.end()) {
            order.remove(&(lfi_key(state.lfi[j]), j));
        }
        let (w_lo, w_hi) = trial.moved_range();
        let distance = (w_lo..=w_hi)
            .map(|j| (trial.control_point(&state.ctrl, j) - state.ctrl[j]).length())
            .fold(0.0, f64::max);
        let before = gfi;
        state.commit_unchecked(&trial);
        for j in l_lo.max(*candidates.start())..=l_hi.min(*candidates.end()) {
            order.insert((lfi_key(state.lfi[j]), j));
        }
        clock += 1;
        for t in &mut modified[w_lo..=w_hi] {
            *t = clock;
        }

        // The output points near the move.
        let (k_lo, k_hi) = data.affected(w_lo, w_hi + p);
        let mut max_was_here = false;
        // The end points are P_0 and P_m, which never move: keep them exactly.
        for k in k_lo.max(1)..k_hi.min(out.len() - 1) {
            max_was_here |= disp[k] == max_disp;
            out[k] = data.eval(k, |j| state.ctrl[j]);
            disp[k] = (out[k] - data.input[k]).length();
        }
        max_disp = if max_was_here {
            disp.iter().copied().fold(0.0, f64::max)
        } else {
            disp[k_lo..k_hi].iter().copied().fold(max_disp, f64::max)
        };

        moves.push(Move {
            iteration: moves.len() + 1,
            index: c,
            distance,
            before,
            after: state.gfi(),
        });
        lambdas.push(Value::from(trial.lambda));
        history.push(HistoryRow {
            iteration: moves.len(),
            measure: state.gfi(),
            max_distance: max_disp,
        });
    };

    if candidates.is_empty() {
        notes.push(format!(
            "{} points give no candidate centre 2..=m-2 for a five-point move",
            points.len()
        ));
    } else if !any_above_rounding && status == FairStatus::NoChange {
        notes.push(
            "every LFI is at the rounding level of its divided difference (straight data): \
             nothing to fair"
                .to_string(),
        );
    } else if moves.is_empty() && status == FairStatus::NoChange {
        notes.push(format!(
            "no local move lowers the GFI below tau = {} times its value; on long inputs use a \
             tau closer to 1",
            s.tau
        ));
    }
    if status == FairStatus::ToleranceLimited {
        notes.push(
            "moves that would lower the GFI further were refused because they exceed the \
             tolerance"
                .to_string(),
        );
    }
    parameters.insert("gfi_final".into(), Value::from(state.gfi()));
    parameters.insert("lambdas".into(), Value::Array(lambdas));

    Ok(Outcome {
        solver: None,
        points: out,
        status,
        iterations: moves.len(),
        moves,
        history,
        parameters,
        notes,
        curve: Some(state.curve()?),
        tangents: None,
        ends_held: Some(super::EndFix::Position),
    })
}

/// Ordering key of a candidate: descending LFI (LFIs are finite and non-negative, so the bit
/// pattern orders like the value), ties by increasing index.
fn lfi_key(lfi: f64) -> Reverse<u64> {
    Reverse(lfi.to_bits())
}

/// Basis values of the interpolating curve at the data parameters, for the output points and
/// the tolerance check.
#[derive(Clone, Debug)]
struct DataSamples {
    p: usize,
    input: Vec<Point>,
    span: Vec<usize>,
    /// `N_{span−p..=span}` at each parameter, stride p + 1.
    basis: Vec<f64>,
}

impl DataSamples {
    fn new(curve: &BSplineCurve, params: &[f64], input: &[Point]) -> DataSamples {
        let p = curve.degree();
        let mut span = Vec::with_capacity(params.len());
        let mut basis = Vec::with_capacity(params.len() * (p + 1));
        let mut b = [[0.0; MAX_ORDER]; 4];
        for &t in params {
            let k = curve.find_span(t);
            curve.basis_derivs(k, t, 0, &mut b);
            span.push(k);
            basis.extend_from_slice(&b[0][..=p]);
        }
        DataSamples {
            p,
            input: input.to_vec(),
            span,
            basis,
        }
    }

    /// The data indices `k_lo..k_hi` (half open) whose curve point uses a control point in
    /// `lo..=hi + p` — pass `hi + p` as `hi_span`: the spans `lo..=hi_span`.
    fn affected(&self, lo: usize, hi_span: usize) -> (usize, usize) {
        let a = self.span.partition_point(|&k| k < lo);
        let b = self.span.partition_point(|&k| k <= hi_span);
        (a, b.max(a))
    }

    /// The curve point at data parameter `k`, with control points from `cp`.
    fn eval(&self, k: usize, cp: impl Fn(usize) -> Point) -> Point {
        let p = self.p;
        let first = self.span[k] - p;
        let mut v = Vec2::ZERO;
        for (l, &n) in self.basis[k * (p + 1)..(k + 1) * (p + 1)]
            .iter()
            .enumerate()
        {
            v += cp(first + l).to_vec2() * n;
        }
        v.to_point()
    }
}

/// The new control points of a move: the window `P_{i−2..i+2}` with the ends of the polygon
/// kept.
#[derive(Clone, Copy, Debug)]
struct Window {
    /// i − 2.
    first: usize,
    /// Moved indices `lo..=hi` (the window without `P_0` and `P_m`).
    lo: usize,
    hi: usize,
    pts: [Point; LOCAL_WIDTH],
}

impl Window {
    #[inline]
    fn get(&self, ctrl: &[Point], k: usize) -> Point {
        if k >= self.lo && k <= self.hi {
            self.pts[k - self.first]
        } else {
            ctrl[k]
        }
    }
}

/// The result of trying one local move on a [`LocalIndicators`] state, without committing it.
#[derive(Clone, Debug)]
pub struct Trial {
    centre: usize,
    lambda: f64,
    lfi_centre: f64,
    gfi_before: f64,
    delta_gfi: f64,
    window: Window,
    kappa_lo: usize,
    kappa: Vec<f64>,
    h_lo: usize,
    h: Vec<f64>,
    lfi_lo: usize,
    lfi: Vec<f64>,
    deps: (usize, usize),
    generation: u64,
}

impl Trial {
    /// The centre i of the move.
    pub fn centre(&self) -> usize {
        self.centre
    }

    /// The shape parameter λ.
    pub fn lambda(&self) -> f64 {
        self.lambda
    }

    /// `LFI_i` at the centre after the move.
    pub fn lfi_centre(&self) -> f64 {
        self.lfi_centre
    }

    /// `GFI_new − GFI`.
    pub fn gfi_change(&self) -> f64 {
        self.delta_gfi
    }

    /// `GFI_new`, the GFI of the curve after the move.
    pub fn gfi_after(&self) -> f64 {
        self.gfi_before + self.delta_gfi
    }

    /// The indices `lo..=hi` of the control points the move changes (`P_{i−2..i+2}` without
    /// `P_0` and `P_m`).
    pub fn moved_range(&self) -> (usize, usize) {
        (self.window.lo, self.window.hi)
    }

    /// The new position of control point `j` (for `j` in [`Trial::moved_range`]), or `None`.
    pub fn moved_point(&self, j: usize) -> Option<Point> {
        (j >= self.window.lo && j <= self.window.hi).then(|| self.window.pts[j - self.window.first])
    }

    /// The indices `lo..=hi` of the LFIs the move changes.
    pub fn lfi_range(&self) -> (usize, usize) {
        (self.lfi_lo, self.lfi_lo + self.lfi.len().saturating_sub(1))
    }

    #[inline]
    fn control_point(&self, ctrl: &[Point], j: usize) -> Point {
        self.window.get(ctrl, j)
    }
}

/// Calì's indicators (spec §4.4) of a clamped, non-rational B-spline, kept up to date under
/// the local λ-moves of spec §4.5 in time independent of the number of control points.
///
/// Holds the control points, κ at the correspondence points, the arc-length increments
/// `h_j = s_j − s_{j−1}` (a move shifts every later `s_j` by a constant, which the divided
/// differences do not see), the LFIs and the GFI. [`LocalIndicators::trial`] evaluates a move
/// without committing it; [`LocalIndicators::commit`] applies it.
#[derive(Clone, Debug)]
pub struct LocalIndicators {
    p: usize,
    template: BSplineCurve,
    op: LambdaOperator,
    ctrl: Vec<Point>,
    /// Span of ξ_j and the first and second basis derivatives there (stride 2(p + 1)).
    xi_span: Vec<usize>,
    xi_basis: Vec<f64>,
    /// Quadrature nodes of interval j (between ξ_{j−1} and ξ_j) are
    /// `iv_start[j]..iv_start[j + 1]`; interval 0 is empty.
    iv_start: Vec<usize>,
    /// Smallest and largest span used by the nodes of interval j.
    iv_kmin: Vec<usize>,
    iv_kmax: Vec<usize>,
    node_span: Vec<usize>,
    node_weight: Vec<f64>,
    /// First basis derivatives at the nodes, stride p + 1.
    node_basis: Vec<f64>,
    kappa: Vec<f64>,
    h: Vec<f64>,
    lfi: Vec<f64>,
    gfi: f64,
    generation: u64,
    /// Control points held at each end (at least `P_0` and `P_m`; `--fix-ends`).
    held: usize,
}

impl LocalIndicators {
    /// The indicators of `curve`, from [`fairness_indicators`], with the basis values the
    /// local updates need.
    ///
    /// # Errors
    /// - [`Error::InvalidParameter`] for a rational curve or a degree above
    ///   [`MAX_ORDER`] − 1;
    /// - the errors of [`LambdaOperator::for_curve`] (knots not clamped, …);
    /// - [`Error::Degenerate`] when a curvature or an LFI is not finite (zero speed at a
    ///   correspondence point) or two correspondence points coincide (an interior knot of
    ///   multiplicity p + 1).
    pub fn new(curve: &BSplineCurve) -> Result<LocalIndicators> {
        let p = curve.degree();
        if p >= MAX_ORDER {
            return Err(Error::InvalidParameter {
                name: "degree".into(),
                reason: format!("must be at most {}", MAX_ORDER - 1),
            });
        }
        let op = LambdaOperator::for_curve(curve)?;
        let m = op.len() - 1;
        let xi = op.xi();
        if let Some(j) = xi.windows(2).position(|w| w[1] <= w[0]) {
            return Err(Error::Degenerate(format!(
                "correspondence points {j} and {} coincide (interior knot of multiplicity {})",
                j + 1,
                p + 1
            )));
        }
        let u = curve.knots().as_slice();
        let mut b = [[0.0; MAX_ORDER]; 4];

        let mut xi_span = Vec::with_capacity(m + 1);
        let mut xi_basis = Vec::with_capacity((m + 1) * 2 * (p + 1));
        for &t in xi {
            let k = curve.find_span(t);
            curve.basis_derivs(k, t, 2, &mut b);
            xi_span.push(k);
            xi_basis.extend_from_slice(&b[1][..=p]);
            xi_basis.extend_from_slice(&b[2][..=p]);
        }

        let gl = GaussLegendre::default();
        let mut iv_start = vec![0, 0];
        let mut iv_kmin = vec![p];
        let mut iv_kmax = vec![p];
        let mut node_span = Vec::new();
        let mut node_weight = Vec::new();
        let mut node_basis = Vec::new();
        for j in 1..=m {
            let (a, end) = (xi[j - 1], xi[j]);
            let mut t0 = a;
            let (mut kmin, mut kmax) = (usize::MAX, 0);
            while t0 < end {
                let k = curve.find_span(t0);
                let t1 = end.min(u[k + 1]);
                if t1 <= t0 {
                    break;
                }
                let (half, mid) = (0.5 * (t1 - t0), 0.5 * (t0 + t1));
                for (x, w) in gl.nodes().iter().zip(gl.weights()) {
                    let t = mid + half * x;
                    curve.basis_derivs(k, t, 1, &mut b);
                    node_span.push(k);
                    node_weight.push(w * half);
                    node_basis.extend_from_slice(&b[1][..=p]);
                }
                kmin = kmin.min(k);
                kmax = kmax.max(k);
                t0 = t1;
            }
            if kmin > kmax {
                return Err(Error::Degenerate(format!(
                    "the interval between correspondence points {} and {j} is empty",
                    j - 1
                )));
            }
            iv_start.push(node_span.len());
            iv_kmin.push(kmin);
            iv_kmax.push(kmax);
        }

        let ind = fairness_indicators(curve);
        let h: Vec<f64> = std::iter::once(0.0)
            .chain(ind.s.windows(2).map(|w| w[1] - w[0]))
            .collect();
        if let Some(j) = (0..=m).find(|&j| !ind.kappa[j].is_finite() || !ind.lfi[j].is_finite()) {
            return Err(Error::Degenerate(format!(
                "the curvature at correspondence point {j} (parameter {}) is not finite",
                xi[j]
            )));
        }
        if let Some(j) = (1..=m).find(|&j| h[j].partial_cmp(&0.0).is_none_or(|o| o.is_le())) {
            return Err(Error::Degenerate(format!(
                "zero arc length between correspondence points {} and {j}",
                j - 1
            )));
        }
        Ok(LocalIndicators {
            p,
            template: curve.clone(),
            op,
            ctrl: curve.control_points().to_vec(),
            xi_span,
            xi_basis,
            iv_start,
            iv_kmin,
            iv_kmax,
            node_span,
            node_weight,
            node_basis,
            kappa: ind.kappa,
            h,
            lfi: ind.lfi,
            gfi: ind.gfi,
            generation: 0,
            held: 1,
        })
    }

    /// Hold `k` control points at each end (at least 1, `P_0` and `P_m`): 2 keeps the end
    /// tangents of the curve and 3 its end curvatures. A move changes only the control points
    /// of its window that are not held.
    pub fn with_held_ends(mut self, k: usize) -> LocalIndicators {
        self.held = k.max(1);
        self
    }

    /// The number of control points, m + 1.
    pub fn len(&self) -> usize {
        self.ctrl.len()
    }

    /// Always false.
    pub fn is_empty(&self) -> bool {
        self.ctrl.is_empty()
    }

    /// The current control points.
    pub fn control_points(&self) -> &[Point] {
        &self.ctrl
    }

    /// The λ-operator of the knot vector.
    pub fn operator(&self) -> &LambdaOperator {
        &self.op
    }

    /// Signed curvature at the correspondence points ξ_0..ξ_m.
    pub fn kappa(&self) -> &[f64] {
        &self.kappa
    }

    /// `LFI_0..LFI_m` (zero at 0 and m, where it is not defined).
    pub fn lfi(&self) -> &[f64] {
        &self.lfi
    }

    /// The GFI, `Σ LFI_j`.
    pub fn gfi(&self) -> f64 {
        self.gfi
    }

    /// The candidate centres `2..=m−2` (empty when m < 4).
    pub fn candidates(&self) -> std::ops::RangeInclusive<usize> {
        let m = self.len() - 1;
        LOCAL_HALF_WIDTH..=m.saturating_sub(LOCAL_HALF_WIDTH)
    }

    /// The curve with the current control points.
    ///
    /// # Errors
    /// [`Error::NonFinite`] if a control point became non-finite (it cannot for λ ∈ [0, 1]).
    pub fn curve(&self) -> Result<BSplineCurve> {
        self.template.with_control_points(self.ctrl.clone())
    }

    /// `LFI_i` after the move centred at `i` with shape parameter λ: the objective of the
    /// λ search (spec §4.5 step 3.3).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a centre outside [`LocalIndicators::candidates`] or
    /// λ outside [0, 1].
    pub fn lfi_after(&self, i: usize, lambda: f64) -> Result<f64> {
        self.check_move(i, lambda)?;
        Ok(self.objective(i, lambda))
    }

    /// Evaluate the move centred at `i` with shape parameter λ: the new control points
    /// `(M^λ P)_j`, j = i−2..=i+2 (except `P_0` and `P_m`, which are kept), and the LFIs and
    /// GFI that result, recomputed only where the curve changed.
    ///
    /// # Errors
    /// As [`LocalIndicators::lfi_after`].
    pub fn trial(&self, i: usize, lambda: f64) -> Result<Trial> {
        self.check_move(i, lambda)?;
        Ok(self.trial_unchecked(i, lambda))
    }

    /// The move centred at `i` with the λ that minimises `LFI_i(λ)` on [0, 1]: golden section
    /// to `lambda_tol`, both end points compared (spec §4.5 \[CHOICE\]).
    ///
    /// # Errors
    /// As [`LocalIndicators::lfi_after`], and [`Error::InvalidParameter`] for a `lambda_tol`
    /// that is not positive and finite.
    pub fn best_trial(&self, i: usize, lambda_tol: f64) -> Result<Trial> {
        self.check_move(i, 0.0)?;
        if !(lambda_tol.is_finite() && lambda_tol > 0.0) {
            return Err(Error::InvalidParameter {
                name: "lambda_tol".into(),
                reason: format!("must be positive and finite, got {lambda_tol}"),
            });
        }
        let best = minimize_golden(|l| self.objective(i, l), 0.0, 1.0, lambda_tol);
        Ok(self.trial_unchecked(i, best.x))
    }

    /// Apply a move evaluated by [`LocalIndicators::trial`] on this very state.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when the state has changed since the trial was made.
    pub fn commit(&mut self, trial: &Trial) -> Result<()> {
        if trial.generation != self.generation {
            return Err(Error::InvalidParameter {
                name: "trial".into(),
                reason: "it was made before the last commit".into(),
            });
        }
        self.commit_unchecked(trial);
        Ok(())
    }

    fn commit_unchecked(&mut self, t: &Trial) {
        for j in t.window.lo..=t.window.hi {
            self.ctrl[j] = t.window.pts[j - t.window.first];
        }
        self.kappa[t.kappa_lo..t.kappa_lo + t.kappa.len()].copy_from_slice(&t.kappa);
        self.h[t.h_lo..t.h_lo + t.h.len()].copy_from_slice(&t.h);
        self.lfi[t.lfi_lo..t.lfi_lo + t.lfi.len()].copy_from_slice(&t.lfi);
        // Re-sum rather than accumulate differences, so rounding does not drift.
        self.gfi = self.lfi.iter().sum();
        self.generation += 1;
    }

    /// [`ROUNDING_FACTOR`] times the rounding level `ε·S/h⁴` of `κ''_i` for coordinates of
    /// magnitude `scale`.
    fn rounding_level(&self, i: usize, scale: f64) -> f64 {
        let h = self.h[i].min(self.h[i + 1]);
        ROUNDING_FACTOR * f64::EPSILON * scale / h / h / h / h
    }

    fn check_move(&self, i: usize, lambda: f64) -> Result<()> {
        if !self.candidates().contains(&i) {
            return Err(Error::InvalidParameter {
                name: "centre".into(),
                reason: format!(
                    "{i} is outside the candidates {}..={}",
                    self.candidates().start(),
                    self.candidates().end()
                ),
            });
        }
        if !(0.0..=1.0).contains(&lambda) {
            return Err(Error::InvalidParameter {
                name: "lambda".into(),
                reason: format!("{lambda} is outside [0, 1]"),
            });
        }
        Ok(())
    }

    fn window(&self, i: usize, lambda: f64) -> Window {
        let m = self.len() - 1;
        Window {
            first: i - LOCAL_HALF_WIDTH,
            lo: (i - LOCAL_HALF_WIDTH).max(self.held),
            hi: (i + LOCAL_HALF_WIDTH).min(m.saturating_sub(self.held)),
            pts: self.op.local_unchecked(&self.ctrl, i, lambda),
        }
    }

    /// κ at ξ_j with the window's control points.
    #[inline]
    fn kappa_with(&self, j: usize, w: &Window) -> f64 {
        let p = self.p;
        let k = self.xi_span[j];
        let stride = 2 * (p + 1);
        let b = &self.xi_basis[j * stride..(j + 1) * stride];
        let mut d1 = Vec2::ZERO;
        let mut d2 = Vec2::ZERO;
        for l in 0..=p {
            let v = w.get(&self.ctrl, k - p + l).to_vec2();
            d1 += v * b[l];
            d2 += v * b[p + 1 + l];
        }
        signed_curvature(&Derivatives {
            d1,
            d2,
            ..Derivatives::default()
        })
    }

    /// `s_j − s_{j−1}` with the window's control points.
    #[inline]
    fn h_with(&self, j: usize, w: &Window) -> f64 {
        let p = self.p;
        let mut s = 0.0;
        for n in self.iv_start[j]..self.iv_start[j + 1] {
            let first = self.node_span[n] - p;
            let b = &self.node_basis[n * (p + 1)..(n + 1) * (p + 1)];
            let mut d1 = Vec2::ZERO;
            for (l, &bl) in b.iter().enumerate() {
                d1 += w.get(&self.ctrl, first + l).to_vec2() * bl;
            }
            // sqrt rather than hypot: the speed is far from overflow and this is the hot loop.
            s += self.node_weight[n] * d1.length_squared().sqrt();
        }
        s
    }

    fn objective(&self, i: usize, lambda: f64) -> f64 {
        let w = self.window(i, lambda);
        let d = second_difference(
            [
                self.kappa_with(i - 1, &w),
                self.kappa_with(i, &w),
                self.kappa_with(i + 1, &w),
            ],
            self.h_with(i, &w),
            self.h_with(i + 1, &w),
        );
        d * d
    }

    fn trial_unchecked(&self, i: usize, lambda: f64) -> Trial {
        let m = self.len() - 1;
        let p = self.p;
        let w = self.window(i, lambda);
        // Curvatures whose span uses a moved control point: a ≤ span ≤ b + p.
        let k_lo = self.xi_span.partition_point(|&k| k < w.lo);
        let k_hi = self.xi_span.partition_point(|&k| k <= w.hi + p).max(k_lo);
        let kappa: Vec<f64> = (k_lo..k_hi).map(|j| self.kappa_with(j, &w)).collect();
        // Arc-length intervals with a node in such a span.
        let h_lo = 1 + self.iv_kmax[1..].partition_point(|&k| k < w.lo);
        let h_hi = (1 + self.iv_kmin[1..].partition_point(|&k| k <= w.hi + p)).max(h_lo);
        let h: Vec<f64> = (h_lo..h_hi).map(|j| self.h_with(j, &w)).collect();
        // LFI_j reads κ_{j−1..j+1}, h_j, h_{j+1}.
        let l_lo = k_lo.saturating_sub(1).min(h_lo - 1).max(1);
        let l_hi = (k_hi.max(h_hi.saturating_sub(1))).min(m - 1); // inclusive: k_hi − 1 + 1
        let get_k = |j: usize| {
            if (k_lo..k_hi).contains(&j) {
                kappa[j - k_lo]
            } else {
                self.kappa[j]
            }
        };
        let get_h = |j: usize| {
            if (h_lo..h_hi).contains(&j) {
                h[j - h_lo]
            } else {
                self.h[j]
            }
        };
        let mut lfi = Vec::with_capacity(l_hi + 1 - l_lo.min(l_hi + 1));
        let mut delta = 0.0;
        for j in l_lo..=l_hi {
            let d = second_difference(
                [get_k(j - 1), get_k(j), get_k(j + 1)],
                get_h(j),
                get_h(j + 1),
            );
            let v = d * d;
            delta += v - self.lfi[j];
            lfi.push(v);
        }
        let lfi_centre = if (l_lo..=l_hi).contains(&i) {
            lfi[i - l_lo]
        } else {
            self.lfi[i]
        };
        // Control points the result depends on: the operator rows (i−3..=i+3) and everything
        // the LFIs in l_lo..=l_hi read.
        let deps = (
            (w.first.saturating_sub(1))
                .min(self.xi_span[l_lo - 1] - p)
                .min(self.iv_kmin[l_lo] - p),
            (i + LOCAL_HALF_WIDTH + 1)
                .min(m)
                .max(self.xi_span[l_hi + 1])
                .max(self.iv_kmax[l_hi + 1]),
        );
        Trial {
            centre: i,
            lambda,
            lfi_centre,
            gfi_before: self.gfi,
            delta_gfi: delta,
            window: w,
            kappa_lo: k_lo,
            kappa,
            h_lo,
            h,
            lfi_lo: l_lo,
            lfi,
            deps,
            generation: self.generation,
        }
    }
}

/// `κ''` at the middle of three curvature samples from the arc-length increments before and
/// after it (spec §4.4): `2 [(κ_+ − κ_0)/h_+ − (κ_0 − κ_−)/h_−] / (h_− + h_+)`.
#[inline]
fn second_difference(k: [f64; 3], h_minus: f64, h_plus: f64) -> f64 {
    2.0 * ((k[2] - k[1]) / h_plus - (k[1] - k[0]) / h_minus) / (h_minus + h_plus)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// splitmix64 → uniform → Box–Muller, deterministic noise for the tests.
    fn noisy_arc(n: usize, sigma: f64, seed: u64) -> Vec<Point> {
        let mut state = seed;
        let mut next = || {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n)
            .map(|i| {
                let a = 2.5 * i as f64 / (n - 1) as f64;
                let r = 1.0
                    + sigma
                        * (-2.0 * (1.0 - next()).ln()).sqrt()
                        * (std::f64::consts::TAU * next()).cos();
                Point::new(r * a.cos(), r * a.sin())
            })
            .collect()
    }

    #[test]
    fn cache_changes_nothing() {
        for (n, seed) in [(31, 1), (60, 2), (45, 3)] {
            let pts = noisy_arc(n, 0.01, seed);
            let mut s = Settings {
                tau: 0.995,
                lambda_tol: DEFAULT_LAMBDA_TOL,
                degree: 3,
                tolerance: None,
                max_moves: 400,
                held_ends: 1,
                use_cache: true,
            };
            let with = run_cali(&pts, &s).expect("cached run");
            s.use_cache = false;
            let without = run_cali(&pts, &s).expect("uncached run");
            assert!(with.moves.len() > 3, "{n}: {} moves", with.moves.len());
            assert_eq!(with.moves, without.moves);
            assert_eq!(with.points, without.points);
            assert_eq!(with.status, without.status);
        }
    }
}
