//! `eck-hadenfeld`: local energy fairing of a B-spline curve, one control point at a time,
//! after M. Eck and J. Hadenfeld, *Local energy fairing of B-spline curves* (Computing Suppl.
//! 10, 1995), as Salvi and Várady review it (`../shared/papers/salvi-varady-local-fairing.txt`,
//! §3.2, eqs 9–11); the selection, recently-moved list and clamp are those of
//! docs/algorithms/salvi-varady.md §3 (`../shared/spec/ALGORITHMS.md`, steps 5, 7, 8), shared with
//! [`super::salvi`].
//!
//! # The algorithm
//!
//! The energy (eq 9, which misses its `dt` in the print — docs/algorithms/salvi-varady.md §3 OCR
//! notes) is `E_l = ∫ |x^{(l)}(t)|² dt` over the domain, `l = 2` or `3`. With knots and weights
//! fixed, `x = Σ d_i R_i` is linear in the control points, so
//! `E_l = Σ_a Σ_b G_ab d_a·d_b` with the Gram matrix `G_ab = ∫ R_a^{(l)} R_b^{(l)} dt` of the
//! l-th derivatives of the (rational) basis functions. G is banded (`|a − b| ≤ p`); its band
//! is computed once, span by span, by Gauss–Legendre quadrature ([`Gram`]): `p − l + 1` nodes
//! integrate the polynomial integrand of a non-rational curve exactly, rational curves use
//! [`RATIONAL_GRAM_NODES`].
//!
//! As a function of one control point `d_j`, `E_l = G_jj |d_j − d_j*|² + const` with
//!
//! ```text
//! d_j* = −(Σ_{i≠j} G_ji d_i) / G_jj,
//! ```
//!
//! the closed-form local minimiser. Because this quadratic is isotropic, the eq-11 clamp of
//! `d_j*` towards the **original** `d_j⁰` is exactly the minimiser over the disc
//! `|d_j − d_j⁰| ≤ δ`, and since the current `d_j` lies in that disc a move never raises the
//! energy.
//!
//! Each iteration moves the movable control point (all but the ends unless `free_ends`) not in
//! the recently-moved list whose clamped move lowers the energy most, `G_jj(|d_j − d_j*|² −
//! |d̃_j − d_j*|²)` — the local deviation of this method. The run stops when no single move
//! can lower the energy by more than [`DEFAULT_MIN_REL_DECREASE`] of its value, when the energy
//! is zero, or at `max_iterations`. Only the `2p + 1` neighbours' sums `Σ_{i≠j} G_ji d_i`
//! and gains change after a move; they are recomputed exactly from the band (O(p²)).
//!
//! Without a tolerance, δ = [`super::local::DEFAULT_TOLERANCE_REL`] × the bounding-box
//! diagonal of the data; point input is handled as in [`super::salvi`].
//!
//! **Closed curves** (point input, at least [`MIN_CLOSED_CONTROL_POINTS`] points) are
//! interpolated by the periodic cubic of `sapidis-farin` (one control point per point, in its
//! wrapped form), and the energy is taken over one period with the cyclic Gram matrix
//! (`Gram::periodic`): every control point is movable and the seam is not special (listing
//! the points from another start gives the same result, unless two control points tie exactly
//! as the best move, as on a symmetric curve, where the first in the list wins). Only the
//! cubic; no B-spline is returned for a closed curve.

use serde_json::Value;

use super::clean::ControlCheck;
use super::local::{
    self, CONTROL_POINTS, DEFAULT_TABU_LENGTH, FIT_DEGREE, FREE_ENDS, LocalReport, RecentList,
    RunningMax, TABU, clamp_point, movable_mask, resolve_tolerance, select_candidate,
};
use super::params::{Number, Param};
use super::periodic::{PAD, interpolate_closed, period_index};
use super::{FairMethod, FairOptions, HistoryRow, Move, Outcome, ParamSpec};
use crate::curve::Curve;
use crate::error::{Error, Result};
use crate::geom::{Point, PointSeq, Vec2};
use crate::numeric::GaussLegendre;
use crate::spline::{BSplineCurve, MAX_ORDER};

/// Default derivative order l of the energy.
pub(super) const DEFAULT_ORDER: usize = 2;

/// Default iteration limit (one control point per iteration).
pub(super) const DEFAULT_MAX_ITERATIONS: usize = 1000;

/// Stop when the best single move would lower the energy by less than this fraction of it.
pub(super) const DEFAULT_MIN_REL_DECREASE: f64 = 1e-9;

/// Fewest points of a closed curve: the cyclic band of the Gram matrix (half-width 3) must
/// not wrap onto itself.
pub(super) const MIN_CLOSED_CONTROL_POINTS: usize = 8;

/// Gauss–Legendre nodes per span for the Gram matrix of a rational curve (its integrand is not
/// a polynomial).
pub(super) const RATIONAL_GRAM_NODES: usize = GaussLegendre::DEFAULT_NODES;

/// Parameters of [`fair_curve`]. Start from [`EckHadenfeldParams::DEFAULT`].
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct EckHadenfeldParams {
    /// Derivative order l of the energy ∫|x^{(l)}|² dt: 2 or 3.
    ///
    /// Default value: 2.
    pub order: usize,
    /// δ, the largest distance of a control point from its original position; `None`:
    /// 1 % of the bounding-box diagonal of the control points.
    ///
    /// Default value: `None`.
    pub tolerance: Option<f64>,
    /// Length R of the recently-moved list.
    ///
    /// Default value: 4.
    pub tabu_length: usize,
    /// Iteration limit.
    ///
    /// Default value: 1000.
    pub max_iterations: usize,
    /// Stop when no move lowers the energy by more than this fraction of it.
    ///
    /// Default value: 10⁻⁹.
    pub min_rel_decrease: f64,
    /// Let the first and last control points move.
    ///
    /// Default value: `false`.
    pub free_ends: bool,
    /// Control points held at each end unless `free_ends`: 1 (the end points), 2 (also the
    /// end tangents) or 3 (also the end curvatures); `--fix-ends=tangent` / `curvature`.
    ///
    /// Default value: 1.
    pub held_ends: usize,
    /// The data parameters of the per-move clean-curve check: a move is refused when it
    /// gives the cubic through the curve's points at these parameters an inflection where
    /// it had none, or raises its variation energy where it was clean (`clean.rs`). `None`:
    /// no check. The method sets them from the fit unless [`FairOptions::keep_clean`] is
    /// false.
    ///
    /// Default value: `None`.
    pub clean_at: Option<Vec<f64>>,
}

impl EckHadenfeldParams {
    /// The defaults listed on each field.
    pub const DEFAULT: EckHadenfeldParams = EckHadenfeldParams {
        order: DEFAULT_ORDER,
        tolerance: None,
        tabu_length: DEFAULT_TABU_LENGTH,
        max_iterations: DEFAULT_MAX_ITERATIONS,
        min_rel_decrease: DEFAULT_MIN_REL_DECREASE,
        free_ends: false,
        held_ends: 1,
        clean_at: None,
    };

    /// Set the order l.
    pub fn with_order(mut self, order: usize) -> EckHadenfeldParams {
        self.order = order;
        self
    }

    /// Set δ.
    pub fn with_tolerance(mut self, delta: f64) -> EckHadenfeldParams {
        self.tolerance = Some(delta);
        self
    }

    /// Set the iteration limit.
    pub fn with_max_iterations(mut self, n: usize) -> EckHadenfeldParams {
        self.max_iterations = n;
        self
    }

    /// Set the relative-decrease threshold of the stopping rule (0: run to the limit or until
    /// no move helps at all).
    pub fn with_min_rel_decrease(mut self, v: f64) -> EckHadenfeldParams {
        self.min_rel_decrease = v;
        self
    }

    /// Set the tabu length R.
    pub fn with_tabu_length(mut self, r: usize) -> EckHadenfeldParams {
        self.tabu_length = r;
        self
    }

    /// Free (or fix) the end control points.
    pub fn with_free_ends(mut self, free: bool) -> EckHadenfeldParams {
        self.free_ends = free;
        self
    }

    /// Hold `k` control points at each end (see [`EckHadenfeldParams::held_ends`]).
    pub fn with_held_ends(mut self, k: usize) -> EckHadenfeldParams {
        self.held_ends = k;
        self
    }

    /// Refuse moves that make the curve at `params` worse ([`EckHadenfeldParams::clean_at`]).
    pub fn with_clean_at(mut self, params: Vec<f64>) -> EckHadenfeldParams {
        self.clean_at = Some(params);
        self
    }
}

impl Default for EckHadenfeldParams {
    fn default() -> EckHadenfeldParams {
        EckHadenfeldParams::DEFAULT
    }
}

/// The band of the Gram matrix `G_ab = ∫ R_a^{(l)}(t) R_b^{(l)}(t) dt` of a B-spline's
/// (rational) basis functions over its domain.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Gram {
    p: usize,
    n: usize,
    /// `band[a·(p+1) + k] = G[a][a+k]`, k = 0..=p (indices mod n when `cyclic`).
    band: Vec<f64>,
    /// The basis of a closed curve: indices are cyclic.
    cyclic: bool,
}

impl Gram {
    /// The Gram matrix of the order-`order` derivatives of the basis of `curve`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for an order outside `1..=3` or above the degree (the
    /// energy would vanish identically).
    pub(super) fn new(curve: &BSplineCurve, order: usize) -> Result<Gram> {
        let p = curve.degree();
        check_order(order, p)?;
        let n = curve.control_points().len();
        let u = curve.knots().as_slice();
        let weights = curve.weights();
        let gl = GaussLegendre::new(match weights {
            None => p - order + 1,
            Some(_) => RATIONAL_GRAM_NODES,
        });
        let mut band = vec![0.0; n * (p + 1)];
        let mut b = [[0.0; MAX_ORDER]; 4];
        let mut r = [0.0; MAX_ORDER];
        for span in p..n {
            let (a, bnd) = (u[span], u[span + 1]);
            if a >= bnd {
                continue;
            }
            let half = 0.5 * (bnd - a);
            let mid = 0.5 * (a + bnd);
            for (x, w) in gl.nodes().iter().zip(gl.weights()) {
                let t = mid + half * x;
                curve.basis_derivs(span, t, order, &mut b);
                match weights {
                    None => r[..=p].copy_from_slice(&b[order][..=p]),
                    Some(ws) => rational_derivative(&b, &ws[span - p..=span], order, &mut r),
                }
                add_products(&mut band, p, w * half, &r, |c| span - p + c);
            }
        }
        Ok(Gram {
            p,
            n,
            band,
            cyclic: false,
        })
    }

    /// The Gram matrix of the periodic cubic basis of a closed curve with `n` distinct control
    /// points `D_d`, given in the wrapped form of [`interpolate_closed`] (`W_r = D_{(r−PAD)
    /// mod n}`): `G_ab = ∫ R_a^{(l)} R_b^{(l)} dt` over one period, with cyclic indices.
    ///
    /// # Errors
    /// As [`Gram::new`]; [`Error::TooFewPoints`] below [`MIN_CLOSED_CONTROL_POINTS`].
    pub(crate) fn periodic(wrapped: &BSplineCurve, n: usize, order: usize) -> Result<Gram> {
        let p = wrapped.degree();
        check_order(order, p)?;
        if n < MIN_CLOSED_CONTROL_POINTS {
            return Err(Error::TooFewPoints {
                needed: MIN_CLOSED_CONTROL_POINTS,
                got: n,
            });
        }
        let u = wrapped.knots().as_slice();
        let gl = GaussLegendre::new(p - order + 1);
        let mut band = vec![0.0; n * (p + 1)];
        let mut b = [[0.0; MAX_ORDER]; 4];
        // The spans of one period: span k + PAD covers [τ_k, τ_{k+1}], where the basis
        // functions W_{k+PAD−p..=k+PAD}, i.e. D_{k+PAD−p−PAD..} (mod n), are non-zero.
        for k in 0..n {
            let span = k + PAD;
            let (a, bnd) = (u[span], u[span + 1]);
            let half = 0.5 * (bnd - a);
            let mid = 0.5 * (a + bnd);
            for (x, w) in gl.nodes().iter().zip(gl.weights()) {
                wrapped.basis_derivs(span, mid + half * x, order, &mut b);
                add_products(&mut band, p, w * half, &b[order], |c| {
                    period_index(span - p + c, n)
                });
            }
        }
        Ok(Gram {
            p,
            n,
            band,
            cyclic: true,
        })
    }

    /// `G[a][b]` (zero outside the band).
    pub(super) fn get(&self, a: usize, b: usize) -> f64 {
        if self.cyclic {
            let k = (b + self.n - a) % self.n;
            return if k <= self.p {
                self.band[a * (self.p + 1) + k]
            } else if self.n - k <= self.p {
                self.band[b * (self.p + 1) + (self.n - k)]
            } else {
                0.0
            };
        }
        let (a, b) = if a <= b { (a, b) } else { (b, a) };
        if b - a > self.p || b >= self.n {
            0.0
        } else {
            self.band[a * (self.p + 1) + (b - a)]
        }
    }

    /// The indices within the bandwidth of `j` (`j` included), cyclic for a closed curve.
    fn neighbours(&self, j: usize) -> impl Iterator<Item = usize> + use<> {
        let (p, n, cyclic) = (self.p, self.n, self.cyclic);
        let (lo, hi) = if cyclic {
            (j + n - p, j + n + p + 1)
        } else {
            (j.saturating_sub(p), (j + p + 1).min(n))
        };
        (lo..hi).map(move |i| if cyclic { i % n } else { i })
    }

    /// `Σ_{i≠j} G_ji d_i`, the coupling of control point j to the others.
    pub(super) fn coupling(&self, d: &[Point], j: usize) -> Vec2 {
        let mut s = Vec2::ZERO;
        for i in self.neighbours(j) {
            if i != j {
                s += d[i].to_vec2() * self.get(j, i);
            }
        }
        s
    }

    /// The energy `Σ_a Σ_b G_ab d_a·d_b`.
    ///
    /// # Panics
    /// If `d` has fewer entries than the matrix.
    pub(super) fn energy(&self, d: &[Point]) -> f64 {
        let mut e = 0.0;
        for (a, pa) in d.iter().enumerate().take(self.n) {
            let da = pa.to_vec2();
            e += self.get(a, a) * da.length_squared();
            // Each pair once: b = a + 1..=a + p (cyclically, or within the matrix).
            for k in 1..=self.p {
                let b = a + k;
                let b = match (self.cyclic, b < self.n) {
                    (_, true) => b,
                    (true, false) => b - self.n,
                    (false, false) => break,
                };
                e += 2.0 * self.get(a, b) * da.dot(d[b].to_vec2());
            }
        }
        e
    }
}

/// An energy order in `1..=3` and at most the degree `p` (else the energy vanishes).
fn check_order(order: usize, p: usize) -> Result<()> {
    if !(1..=3).contains(&order) || order > p {
        return Err(Error::InvalidParameter {
            name: "order".into(),
            reason: format!("must be in 1..=3 and at most the degree {p}, got {order}"),
        });
    }
    Ok(())
}

/// Add `wt · r_c · r_{c+k}` to `G[row(c)][row(c) + k]` for the `p + 1` basis values `r` of one
/// quadrature node (`row(c)` is the matrix index of the span's basis function c).
fn add_products(band: &mut [f64], p: usize, wt: f64, r: &[f64], row: impl Fn(usize) -> usize) {
    for c in 0..=p {
        let a = row(c);
        for k in 0..=p - c {
            band[a * (p + 1) + k] += wt * r[c] * r[c + k];
        }
    }
}

/// The order-`o` derivatives of the rational basis `R_c = w_c N_c / W` of one span from the
/// B-spline basis derivatives `b[k][c]` (k ≤ o): `R^{(o)} = (w N^{(o)} − Σ_{i=1}^{o} C(o,i)
/// W^{(i)} R^{(o−i)}) / W`.
fn rational_derivative(b: &[[f64; MAX_ORDER]; 4], w: &[f64], o: usize, out: &mut [f64; MAX_ORDER]) {
    const BINOM: [[f64; 4]; 4] = [
        [1.0, 0.0, 0.0, 0.0],
        [1.0, 1.0, 0.0, 0.0],
        [1.0, 2.0, 1.0, 0.0],
        [1.0, 3.0, 3.0, 1.0],
    ];
    let mut wd = [0.0; 4];
    for (k, wk) in wd.iter_mut().enumerate().take(o + 1) {
        *wk = w.iter().enumerate().map(|(c, wc)| wc * b[k][c]).sum();
    }
    for (c, wc) in w.iter().enumerate() {
        let mut r = [0.0; 4];
        for k in 0..=o {
            let mut v = wc * b[k][c];
            for i in 1..=k {
                v -= BINOM[k][i] * wd[i] * r[k - i];
            }
            r[k] = v / wd[0];
        }
        out[c] = r[o];
    }
}

/// The energy `∫ |x^{(order)}|² dt` of `curve` (eq 9), through its Gram matrix.
///
/// # Errors
/// As [`Gram::new`].
#[cfg(test)]
pub(super) fn energy(curve: &BSplineCurve, order: usize) -> Result<f64> {
    Ok(Gram::new(curve, order)?.energy(curve.control_points()))
}

/// Fair `curve` by local energy minimisation (see `docs/algorithms/salvi-varady.md`). Knots, degree
/// and weights are kept; every control point stays within δ of its original position, so the
/// curve stays within δ of `curve` (eq 10).
///
/// # Errors
/// [`Error::InvalidParameter`] for an order outside 2..=3 or above the degree, a non-positive
/// tolerance or a negative threshold; [`Error::Degenerate`] when every control point
/// coincides and no tolerance is given.
pub fn fair_curve(
    curve: &BSplineCurve,
    params: &EckHadenfeldParams,
) -> Result<(BSplineCurve, LocalReport)> {
    if !(2..=3).contains(&params.order) {
        return Err(Error::InvalidParameter {
            name: "order".into(),
            reason: format!("must be 2 or 3, got {}", params.order),
        });
    }
    if !(params.min_rel_decrease.is_finite() && params.min_rel_decrease >= 0.0) {
        return Err(Error::InvalidParameter {
            name: "min_rel_decrease".into(),
            reason: format!(
                "must be finite and non-negative, got {}",
                params.min_rel_decrease
            ),
        });
    }
    let delta = resolve_tolerance(params.tolerance, curve)?;
    let gram = Gram::new(curve, params.order)?;
    let original = curve.control_points();
    let movable = movable_mask(
        original.len(),
        local::held_control_points(params.free_ends, params.held_ends),
    );
    let check = params
        .clean_at
        .as_deref()
        .and_then(|t| ControlCheck::new(curve, t));
    let (d, report) = fair_control_points(original, &gram, &movable, params, delta, check);
    Ok((curve.with_control_points(d)?, report))
}

/// The loop of [`fair_curve`] on control points `original` with the Gram matrix `gram` (linear
/// or cyclic): the faired control points and the report.
fn fair_control_points(
    original: &[Point],
    gram: &Gram,
    movable: &[bool],
    params: &EckHadenfeldParams,
    delta: f64,
    mut check: Option<ControlCheck>,
) -> (Vec<Point>, LocalReport) {
    let n = original.len();
    let mut d = original.to_vec();

    // The clamped local optimum of j and the energy its move would remove.
    let best_move = |d: &[Point], j: usize| -> (Point, f64, bool) {
        let gjj = gram.get(j, j);
        if gjj.is_nan() || gjj <= 0.0 {
            return (d[j], 0.0, false);
        }
        let star = (gram.coupling(d, j) * (-1.0 / gjj)).to_point();
        let (c, clamped) = clamp_point(original[j], star, delta);
        let gain = gjj * ((d[j] - star).length_squared() - (c - star).length_squared());
        (c, gain.max(0.0), clamped)
    };
    let mut gain: Vec<f64> = (0..n)
        .map(|j| if movable[j] { best_move(&d, j).1 } else { 0.0 })
        .collect();

    let measure_before = gram.energy(&d);
    let mut e = measure_before;
    let mut recent = RecentList::new(params.tabu_length);
    let mut displacement = RunningMax::zeros(n);
    let mut history = vec![HistoryRow {
        iteration: 0,
        measure: e,
        max_distance: 0.0,
    }];
    let mut moves = Vec::new();
    let mut clamped_moves = 0;
    let mut iterations = 0;
    let mut converged = false;
    while iterations < params.max_iterations {
        let best_gain = gain.iter().copied().fold(0.0, f64::max);
        if e <= 0.0 || best_gain <= params.min_rel_decrease * e {
            converged = true;
            break;
        }
        let Some(j) = select_candidate(&gain, movable, &mut recent) else {
            converged = true;
            break;
        };
        iterations += 1;
        let (c, g, clamped) = best_move(&d, j);
        let refused =
            g > 0.0 && c != d[j] && check.as_mut().is_some_and(|k| k.refuses(j, c - d[j]));
        if refused {
            // Not a candidate again until a neighbour's move changes its optimum.
            gain[j] = 0.0;
        } else if g > 0.0 && c != d[j] {
            if let Some(k) = check.as_mut() {
                k.commit(j, c - d[j]);
            }
            let old = d[j];
            let b = gram.coupling(&d, j);
            let gjj = gram.get(j, j);
            // E(d_j) = G_jj |d_j|² + 2 d_j·b + const.
            let change = gjj * (c.to_vec2().length_squared() - old.to_vec2().length_squared())
                + 2.0 * b.dot(c - old);
            let before = e;
            // The change is negative; `min` guards the running energy against rounding.
            e = (e + change).min(e);
            d[j] = c;
            for jj in gram.neighbours(j) {
                gain[jj] = if movable[jj] {
                    best_move(&d, jj).1
                } else {
                    0.0
                };
            }
            displacement.set(j, c.distance(original[j]));
            clamped_moves += usize::from(clamped);
            moves.push(Move {
                iteration: iterations,
                index: j,
                distance: c.distance(old),
                before,
                after: e,
            });
        }
        recent.push(j);
        history.push(HistoryRow {
            iteration: iterations,
            measure: e,
            max_distance: displacement.max(),
        });
    }
    let measure_after = gram.energy(&d);
    let status = LocalReport::status_of(!moves.is_empty(), converged, clamped_moves);
    let mut notes = Vec::new();
    if clamped_moves > 0 {
        notes.push(format!(
            "{clamped_moves} of {} moves stopped at δ = {delta:.6e} from the original control point",
            moves.len()
        ));
    }
    notes.extend(check.as_ref().and_then(ControlCheck::note));
    let report = LocalReport {
        status,
        iterations,
        accepted_moves: moves.len(),
        clamped_moves,
        measure_before,
        measure_after,
        tolerance: delta,
        max_control_displacement: displacement.max(),
        history,
        moves,
        notes,
    };
    (d, report)
}

/// The `eck-hadenfeld` method for point input: fit a B-spline, fair it, evaluate it at the
/// fitted parameters.
#[derive(Clone, Copy, Debug, Default)]
pub struct EckHadenfeld;

/// The derivative order l of the energy ([`DEFAULT_ORDER`]).
const ORDER: Param<Number<usize>> = Param {
    name: "order",
    kind: Number {
        default: DEFAULT_ORDER,
        min: 2,
        max: 3,
    },
    doc: "derivative order l of the energy ∫|x^(l)|² dt (2 or 3)",
};

static PARAMS: [ParamSpec; 5] = [
    ORDER.spec(),
    TABU.spec(),
    FIT_DEGREE.spec(),
    CONTROL_POINTS.spec(),
    FREE_ENDS.spec(),
];

impl FairMethod for EckHadenfeld {
    fn name(&self) -> &'static str {
        "eck-hadenfeld"
    }

    fn description(&self) -> &'static str {
        "Eck & Hadenfeld local energy fairing: each B-spline control point in turn to the \
         closed-form minimiser of ∫|x^(l)|² dt, within δ of the original"
    }

    fn parameters(&self) -> &'static [ParamSpec] {
        &PARAMS
    }

    fn supports_closed(&self) -> bool {
        true
    }

    fn check_params(&self, options: &FairOptions) -> Result<()> {
        local::check_fit_params(options)?;
        order_and_tabu(options).map(|_| ())
    }

    fn run(&self, input: &PointSeq, options: &FairOptions) -> Result<Outcome> {
        if input.is_closed() {
            return run_closed(input, options);
        }
        let fitted = local::fit_input(input, options)?;
        run_fitted(fitted, input, options)
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

/// The `order` and `tabu` parameters, checked.
fn order_and_tabu(options: &FairOptions) -> Result<(usize, usize)> {
    Ok((options.get(&ORDER)?, options.get(&TABU)?))
}

/// The method on a fitted (or given) B-spline; `input` holds the points the output is
/// compared with.
fn run_fitted(
    fitted: local::FittedInput,
    input: &PointSeq,
    options: &FairOptions,
) -> Result<Outcome> {
    let (order, tabu_length) = order_and_tabu(options)?;
    let params = EckHadenfeldParams {
        order,
        tolerance: Some(fitted.delta),
        tabu_length,
        max_iterations: options.iterations_or(DEFAULT_MAX_ITERATIONS),
        min_rel_decrease: DEFAULT_MIN_REL_DECREASE,
        free_ends: fitted.free_ends,
        held_ends: fitted.held_ends,
        clean_at: options.keep_clean.then(|| fitted.params.clone()),
    };
    let (faired, report) = fair_curve(&fitted.curve, &params)?;
    let points = local::output_points(&faired, &fitted, input, options.fix_ends.is_fixed());
    Ok(outcome(
        points,
        report,
        &params,
        fitted.parameters.clone(),
        fitted.notes,
        Some(faired),
    ))
}

/// The method's [`Outcome`]: the parameters as used and the run's report.
fn outcome(
    points: Vec<Point>,
    report: LocalReport,
    params: &EckHadenfeldParams,
    mut parameters: serde_json::Map<String, Value>,
    notes: Vec<String>,
    curve: Option<BSplineCurve>,
) -> Outcome {
    ORDER.write(&mut parameters, params.order);
    TABU.write(&mut parameters, params.tabu_length);
    parameters.insert("max_iterations".into(), params.max_iterations.into());
    local::insert_common(&mut parameters, &report);
    report.into_outcome(points, parameters, notes, curve, params.free_ends)
}

/// The method on a closed curve: the periodic cubic through the points (the wrapped form
/// of [`interpolate_closed`]), its `n` distinct control points faired with the cyclic Gram
/// matrix, every one of them movable; the output points are the faired curve at the data
/// parameters. Only the cubic: a closed curve with another `degree` is refused.
fn run_closed(input: &PointSeq, options: &FairOptions) -> Result<Outcome> {
    let (order, tabu_length) = order_and_tabu(options)?;
    let degree = local::fit_degree(options)?;
    if degree != 3 {
        return Err(Error::InvalidParameter {
            name: "degree".into(),
            reason: format!("a closed curve is faired as the periodic cubic, not degree {degree}"),
        });
    }
    if options.get(&CONTROL_POINTS)?.is_some() {
        return Err(Error::InvalidParameter {
            name: "control_points".into(),
            reason: "a closed curve is interpolated (one control point per point)".into(),
        });
    }
    let points = input.points();
    let n = points.len();
    if n < MIN_CLOSED_CONTROL_POINTS {
        return Err(Error::TooFewPoints {
            needed: MIN_CLOSED_CONTROL_POINTS,
            got: n,
        });
    }
    let (wrapped, t) = interpolate_closed(points)?;
    let gram = Gram::periodic(&wrapped, n, order)?;
    let original: Vec<Point> = wrapped.control_points()[PAD..PAD + n].to_vec();
    let residual = points
        .iter()
        .zip(&t)
        .map(|(q, &tk)| q.distance(wrapped.eval(tk)))
        .fold(0.0, f64::max);
    let mut notes = Vec::new();
    let delta = match options.tolerance {
        // The faired curve is within δ of the interpolant, which is within `residual` of the
        // points (rounding).
        Some(tol) => {
            let margin = local::ROUNDING_MARGIN_ULPS
                * f64::EPSILON
                * crate::geom::max_abs_coordinate(points);
            let d = tol - residual - margin;
            if d > 0.0 {
                d
            } else {
                notes.push(format!(
                    "the periodic interpolant deviates {residual:.6e} from the points, which is \
                     not below the tolerance {tol:.6e}; fairing within δ = tolerance"
                ));
                tol
            }
        }
        None => {
            let d = local::DEFAULT_TOLERANCE_REL * input.scale();
            notes.push(format!(
                "no tolerance given: δ = {} × bounding-box diagonal = {d:.6e}",
                local::DEFAULT_TOLERANCE_REL
            ));
            d
        }
    };
    let params = EckHadenfeldParams {
        order,
        tolerance: Some(delta),
        tabu_length,
        max_iterations: options.iterations_or(DEFAULT_MAX_ITERATIONS),
        min_rel_decrease: DEFAULT_MIN_REL_DECREASE,
        free_ends: true,
        held_ends: 0,
        // The periodic curve's moves are left to the final guard of the common path.
        clean_at: None,
    };
    let (d, report) = fair_control_points(&original, &gram, &vec![true; n], &params, delta, None);
    let ctrl: Vec<Point> = (0..n + PAD).map(|r| d[period_index(r, n)]).collect();
    let faired = wrapped.with_control_points(ctrl)?;
    let out: Vec<Point> = t.iter().map(|&tk| faired.eval(tk)).collect();
    let mut parameters = serde_json::Map::new();
    parameters.insert("fit".into(), "periodic cubic interpolation".into());
    FIT_DEGREE.write(&mut parameters, 3);
    CONTROL_POINTS.write(&mut parameters, Some(n));
    parameters.insert("fit_residual".into(), local::json_f64(residual));
    parameters.insert("delta".into(), local::json_f64(delta));
    // The wrapped form is not a clamped curve of its own: no curve is returned.
    Ok(outcome(out, report, &params, parameters, notes, None))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::curve::CurveDeriv;
    use crate::spline::KnotVector;

    #[test]
    fn periodic_gram_is_the_energy_over_one_period() {
        let n = 13;
        let pts: Vec<Point> = (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64 + 0.07 * (i % 4) as f64;
                Point::new(2.0 * a.cos() + 0.05 * (3.0 * a).sin(), a.sin())
            })
            .collect();
        let (wrapped, _) = interpolate_closed(&pts).unwrap();
        let u = wrapped.knots().as_slice().to_vec();
        let d: Vec<Point> = wrapped.control_points()[PAD..PAD + n].to_vec();
        let gl = GaussLegendre::new(8);
        for order in [2, 3] {
            let gram = Gram::periodic(&wrapped, n, order).unwrap();
            // Direct quadrature of |x^(l)|² over the spans of one period.
            let mut direct = 0.0;
            for k in 0..n {
                let (a, b) = (u[k + PAD], u[k + PAD + 1]);
                direct += gl.integrate(a, b, |t| {
                    let dv = wrapped.derivatives(a.max(t.min(b)));
                    let v = if order == 2 { dv.d2 } else { dv.d3 };
                    v.length_squared()
                });
            }
            let e = gram.energy(&d);
            assert!(
                (e - direct).abs() <= 1e-9 * direct,
                "order {order}: {e} vs {direct}"
            );
            // Symmetric, and cyclic: entries across the seam are there.
            assert_eq!(gram.get(0, n - 1), gram.get(n - 1, 0));
            assert!(gram.get(0, n - 1) != 0.0);
            assert_eq!(gram.get(0, 4), 0.0);
        }
    }

    fn curve(weights: Option<Vec<f64>>) -> BSplineCurve {
        let pts = vec![
            Point::new(0.0, 0.0),
            Point::new(1.0, 1.2),
            Point::new(2.2, 1.9),
            Point::new(3.5, 2.0),
            Point::new(4.6, 1.4),
            Point::new(5.5, 0.9),
            Point::new(6.8, 1.1),
            Point::new(8.0, 2.0),
        ];
        let k = KnotVector::new(vec![
            0.0, 0.0, 0.0, 0.0, 0.2, 0.3, 0.6, 0.8, 1.0, 1.0, 1.0, 1.0,
        ]);
        BSplineCurve::new(3, k, pts, weights)
    }

    /// ∫|x^(l)|² dt by brute-force quadrature on the curve's own derivatives.
    fn brute_energy(c: &BSplineCurve, l: usize) -> f64 {
        let gl = GaussLegendre::new(24);
        let u = c.knots().as_slice();
        let mut e = 0.0;
        for s in 3..c.control_points().len() {
            if u[s] < u[s + 1] {
                e += gl.integrate(u[s], u[s + 1], |t| {
                    let d = c.derivatives(t);
                    let v = if l == 2 { d.d2 } else { d.d3 };
                    v.length_squared()
                });
            }
        }
        e
    }

    #[test]
    fn gram_energy_matches_quadrature() {
        for l in [2, 3] {
            let c = curve(None);
            let e = energy(&c, l).expect("energy");
            let b = brute_energy(&c, l);
            assert!((e - b).abs() < 1e-11 * b, "l={l}: {e} vs {b}");
            let c = curve(Some(vec![1.0, 0.8, 1.5, 1.0, 0.7, 1.2, 1.0, 1.0]));
            let e = energy(&c, l).expect("energy");
            let b = brute_energy(&c, l);
            assert!((e - b).abs() < 1e-6 * b, "rational l={l}: {e} vs {b}");
        }
        assert!(energy(&curve(None), 4).is_err());
    }

    #[test]
    fn closed_form_move_is_the_local_minimum() {
        let c = curve(None);
        let g = Gram::new(&c, 2).expect("gram");
        let d = c.control_points().to_vec();
        let j = 3;
        let star = (g.coupling(&d, j) * (-1.0 / g.get(j, j))).to_point();
        let e_at = |q: Point| {
            let mut dd = d.clone();
            dd[j] = q;
            g.energy(&dd)
        };
        let e0 = e_at(star);
        for v in [
            Vec2::new(1e-3, 0.0),
            Vec2::new(0.0, -1e-3),
            Vec2::new(7e-4, 7e-4),
        ] {
            let e1 = e_at(star + v);
            // Isotropic: E(d* + v) − E(d*) = G_jj |v|².
            assert!((e1 - e0 - g.get(j, j) * v.length_squared()).abs() < 1e-9 * e0.max(1.0));
        }
    }
}
