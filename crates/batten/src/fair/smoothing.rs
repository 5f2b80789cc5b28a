//! `mst`: the cubic smoothing spline, the global baseline that Han et al.
//! (`../shared/papers/han-explicit-fairing-indicator.txt`, §5) call MST — Matlab's `csaps`.
//!
//! # The problem
//!
//! For points `P_0..P_{n−1}` at chord-length parameters `t_i` (spec §0.2) and weights `w_i`,
//! find the C² cubic spline curve `C` with knots `t_i` that minimises
//!
//! ```text
//! p · Σ_i w_i |P_i − C(t_i)|²  +  (1 − p) · ∫ |C''(t)|² dt ,        p ∈ [0, 1],
//! ```
//!
//! the objective of Matlab's and PyPI's `csaps` (Han et al. write `λE_d + (1 − λ)E_s`). Both
//! coordinates share the parameter and the matrix, so one factorisation serves x and y. The
//! minimiser is the natural cubic spline (`C'' = 0` at the ends) of its own values
//! `g_i = C(t_i)`; a closed curve gives the periodic spline.
//!
//! # The algorithm (Reinsch 1967; de Boor, *A Practical Guide to Splines*, ch. XIV, `SMOOTH`)
//!
//! With `h_i = t_{i+1} − t_i`, `γ_k = C''(t_k)` at the interior knots (all knots when closed),
//! `Q` the n×m matrix of second divided differences (column k: `1/h_{k−1}`,
//! `−(1/h_{k−1} + 1/h_k)`, `1/h_k` in rows k−1, k, k+1), `R` the tridiagonal m×m matrix
//! (`(h_{k−1} + h_k)/3` on the diagonal, `h_k/6` beside it) and `W⁻¹ = diag(1/w_i)`:
//!
//! ```text
//! (R + α Qᵀ W⁻¹ Q) γ = Qᵀ y,     g = y − α W⁻¹ Q γ,     α = (1 − p)/p.
//! ```
//!
//! We solve the equivalent scaled form `(p R + (1 − p) Qᵀ W⁻¹ Q) u = Qᵀ y`, `γ = p·u`,
//! `g = y − (1 − p) W⁻¹ Q u` — csaps's system divided by 6 — whose coefficients stay in
//! `[0, 1]` for every α (`p = 1/(1 + α)`, `1 − p = α/(1 + α)`, each computed without
//! cancellation). The matrix is symmetric positive definite and pentadiagonal (cyclic
//! pentadiagonal when closed): [`SymBanded`] `L D Lᵀ` in O(n) for open curves,
//! [`CyclicSymBanded`] (envelope `L D Lᵀ`, also O(n)) for closed ones.
//!
//! **Infinite weights** pin a point: `W⁻¹_ii = 0`, so `g_i = y_i` exactly. `fix_ends` pins the
//! first and last points of an open curve (and the second and third at each end for
//! `--fix-ends=tangent` / `curvature`). The matrix stays SPD because `R` is SPD for any
//! weights (and `p > 0`).
//!
//! **p = 0** (`α = ∞`) is the limit, solved directly: the weighted least-squares straight line
//! in t (through the pinned point, or the line through the two pinned points, when there are
//! pins). A closed curve would collapse to a point, so p = 0 is rejected for it.
//!
//! # Choosing p
//!
//! - `--set p=<value>`: that p.
//! - `--tolerance D` without p: the smoothest spline whose largest displacement is at most D.
//!   Bisection on `ln α` (a well-conditioned variable: the smoothing bandwidth grows like
//!   `α^{1/4}`) until the bracket is narrower than [`BISECTION_REL_PRECISION`] in α; the
//!   feasible end of the bracket is returned, so the tolerance always holds (`p = 1`
//!   interpolates with zero displacement, the fallback). For an open curve the least-squares
//!   line is tried first.
//! - neither: generalised cross-validation (Craven & Wahba 1979),
//!   `GCV(α) = n·RSS / tr(I − A)²`, RSS summed over x and y, `A` the influence matrix
//!   `g = A y`. `tr(I − A) = (1 − p)·Σ_i W⁻¹_ii q_iᵀ M⁻¹ q_i` (`q_i` row i of Q, M the scaled
//!   matrix) needs only the band of `M⁻¹`, from the `L D Lᵀ` factors by the recursion of
//!   Hutchinson & de Hoog (1985) in O(n). Minimised over `ln α` by a coarse scan then
//!   [`minimize_brent`] (GCV can have several local minima).
//!
//! Scale: p is not scale invariant (the two terms of the objective have different units);
//! this is csaps's convention and is kept for parity. The searches work relative to
//! `α_ref = tr R / tr(Qᵀ W⁻¹ Q)`, csaps's default ([`SmoothingSpline::default_p`]), and so
//! behave the same at every scale.

use super::FairOptions;
pub use super::smoothing_mst::Mst;
use super::smoothing_system::Penta;
pub(crate) use super::smoothing_trial::roughness;
use super::smoothing_trial::{dot, max_displacement};
use crate::error::{Error, Result};
use crate::geom::{Point, Vec2};
use crate::numeric::{CyclicSymBanded, SymBanded, factorize_with_inverse_band, minimize_brent};
use crate::spline::ParametricCubic;

/// The bisection on `ln α` (tolerance mode) stops when the bracket `[α_lo, α_hi]` satisfies
/// `α_hi / α_lo ≤ 1 + BISECTION_REL_PRECISION`.
pub const BISECTION_REL_PRECISION: f64 = 1e-3;

/// Default limit on bisection steps in tolerance mode (`max_iterations` overrides it). The
/// bracket is about 90 units of `ln α` wide at n = 10⁶, so ~17 steps reach
/// [`BISECTION_REL_PRECISION`]; the default leaves ample room.
pub(super) const DEFAULT_MAX_BISECTION_STEPS: usize = 60;

/// The searches start `LOG_ALPHA_BELOW` units of `ln α` below `ln α_ref`. The displacements
/// `g − y = α W⁻¹ Q γ` vanish linearly with α, so at `α = α_ref·e⁻²⁵ ≈ 1.4·10⁻¹¹ α_ref` they
/// are that fraction of those at `α_ref`: interpolation, to plotting accuracy.
const LOG_ALPHA_BELOW: f64 = 25.0;

/// The searches end `4 ln n + LOG_ALPHA_ABOVE` units of `ln α` above `ln α_ref`: the smoothing
/// bandwidth (in points) grows like `(α/α_ref)^{1/4}`, so there it spans ~e² n points and the
/// spline is the least-squares line to plotting accuracy.
const LOG_ALPHA_ABOVE: f64 = 8.0;

/// Step of the coarse GCV scan in `ln α` (a factor e² ≈ 7.4 in α, 1.65 in bandwidth).
const GCV_SCAN_STEP: f64 = 2.0;

/// Brent refinement of the GCV minimum: absolute tolerance in `ln α`.
const GCV_LOG_ALPHA_TOL: f64 = 1e-4;

/// Brent refinement of the GCV minimum: evaluation budget.
const GCV_MAX_EVALUATIONS: usize = 60;

/// The most memory the searches spend on keeping the data's part of every row of the system
/// ([`KnotTerms`], 72 bytes a point in the plane) instead of making it again for each of
/// their ~19 trials: 8 MiB, about 10⁵ points. Kept, the rows cost a third of a trial on a
/// 200-point curve (issue #17); at 10⁶ points they would raise the peak memory by a third.
const TERMS_CACHE_BYTES: usize = 8 << 20;

/// How the smoothing parameter is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum Smoothing {
    /// The given `p ∈ [0, 1]` (1 interpolates, 0 is the least-squares line).
    P(f64),
    /// The smoothest spline (largest α) with every `|g_i − P_i| ≤ tolerance`, by bisection on
    /// `ln α` with at most `max_steps` steps.
    MaxDisplacement {
        /// The largest allowed displacement, data units.
        tolerance: f64,
        /// Bisection step limit.
        max_steps: usize,
    },
    /// Generalised cross-validation.
    Gcv,
}

/// One spline computed during a search (the trace behind [`SmoothingInfo::trials`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct SmoothingTrial {
    /// The smoothing parameter.
    pub p: f64,
    /// `α = (1 − p)/p` (infinite for p = 0).
    pub alpha: f64,
    /// Largest `|g_i − P_i|`.
    pub max_displacement: f64,
    /// `∫ |C''|² dt`.
    pub roughness: f64,
    /// The GCV score, when computed.
    pub gcv: Option<f64>,
}

/// How p was chosen and what the search saw.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SmoothingInfo {
    /// The smoothing parameter used.
    pub p: f64,
    /// `α = (1 − p)/p` (infinite for p = 0).
    pub alpha: f64,
    /// The GCV score of the result (GCV mode only).
    pub gcv: Option<f64>,
    /// `tr A`, the equivalent degrees of freedom per coordinate (GCV mode only).
    pub degrees_of_freedom: Option<f64>,
    /// Splines computed by the search, in order (empty for a given p).
    pub trials: Vec<SmoothingTrial>,
    /// Whether the search reached its precision (always true for a given p).
    pub converged: bool,
    /// Remarks (e.g. that the tolerance is so small that the result interpolates).
    pub notes: Vec<String>,
}

/// A fitted cubic smoothing spline: the smoothed values at the data parameters and the second
/// derivatives there, which together define the natural (or periodic) cubic spline.
#[derive(Clone, Debug, PartialEq)]
pub struct SmoothingSpline {
    t: Vec<f64>,
    values: Vec<Point>,
    second: Vec<Vec2>,
    p: f64,
    alpha: f64,
    closed: bool,
}

impl SmoothingSpline {
    /// The smoothing spline of an open point sequence at parameters `t` (strictly increasing,
    /// one per point) with smoothing parameter `p ∈ [0, 1]`.
    ///
    /// `weights`: one per point, positive; `f64::INFINITY` pins a point. `None`: all 1.
    ///
    /// # Errors
    /// [`Error::TooFewPoints`] (fewer than 2), [`Error::LengthMismatch`],
    /// [`Error::NotIncreasing`], [`Error::NonFinite`], [`Error::InvalidParameter`] for p or a
    /// weight out of range (or p = 0 with more than two pinned points), [`Error::Singular`]
    /// when the system is numerically singular (extreme p on extreme data).
    pub fn fit(
        t: &[f64],
        points: &[Point],
        weights: Option<&[f64]>,
        p: f64,
    ) -> Result<SmoothingSpline> {
        Ok(Self::select(t, points, weights, false, Smoothing::P(p))?.0)
    }

    /// The periodic smoothing spline of a closed point sequence: `t` has one more entry than
    /// `points`, the parameter at which the curve returns to `P_0` (as
    /// [`crate::spline::parameters`]`(…, closed = true)` returns). `p` must be in `(0, 1]`.
    ///
    /// # Errors
    /// As [`SmoothingSpline::fit`]; [`Error::TooFewPoints`] for fewer than 3 points.
    pub fn fit_periodic(
        t: &[f64],
        points: &[Point],
        weights: Option<&[f64]>,
        p: f64,
    ) -> Result<SmoothingSpline> {
        Ok(Self::select(t, points, weights, true, Smoothing::P(p))?.0)
    }

    /// The smoothing spline with p chosen as `how` says; see [`SmoothingSpline::fit`] and
    /// [`SmoothingSpline::fit_periodic`] for `t`, `weights` and `closed`.
    ///
    /// # Errors
    /// As [`SmoothingSpline::fit`]; [`Error::InvalidParameter`] for a tolerance that is not
    /// positive and finite; [`Error::TooFewPoints`] for GCV on fewer than 3 points;
    /// [`Error::NoConvergence`] when no trial of the GCV search could be solved.
    pub fn select(
        t: &[f64],
        points: &[Point],
        weights: Option<&[f64]>,
        closed: bool,
        how: Smoothing,
    ) -> Result<(SmoothingSpline, SmoothingInfo)> {
        let y: Vec<[f64; 2]> = points.iter().map(|p| [p.x, p.y]).collect();
        let (fit, info) = select_any(t, &y, weights, closed, how)?;
        let spline = SmoothingSpline {
            t: t.to_vec(),
            values: fit.values.iter().map(|g| Point::new(g[0], g[1])).collect(),
            second: fit.second.iter().map(|c| Vec2::new(c[0], c[1])).collect(),
            p: fit.p,
            alpha: fit.alpha,
            closed,
        };
        Ok((spline, info))
    }

    /// csaps's default smoothing parameter for these parameters and weights:
    /// `p = 1 / (1 + tr R / tr(Qᵀ W⁻¹ Q))`, which balances the traces of the two terms
    /// (`1/(1 + tr(A)/(6 tr(B)))` in csaps's scaling). `t` has one entry per point for an open
    /// curve and one more for a closed one.
    ///
    /// # Errors
    /// As [`SmoothingSpline::select`]; [`Error::Degenerate`] when every point is pinned.
    pub fn default_p(t: &[f64], weights: &[f64], closed: bool) -> Result<f64> {
        let n = if closed {
            t.len().saturating_sub(1)
        } else {
            t.len()
        };
        let dummy = vec![[0.0; 2]; n];
        let problem = Problem::new(t, &dummy, Some(weights), closed)?;
        let alpha = problem.alpha_ref()?;
        Ok(1.0 / (1.0 + alpha))
    }

    /// The smoothed points `g_i = C(t_i)`, same count and order as the data.
    pub fn values(&self) -> &[Point] {
        &self.values
    }

    /// Consume the spline and return the smoothed points.
    pub fn into_values(self) -> Vec<Point> {
        self.values
    }

    /// The second derivatives `C''(t_i)` at the data parameters (zero at the ends of an open
    /// curve).
    pub fn second_derivatives(&self) -> &[Vec2] {
        &self.second
    }

    /// The parameters (one more than points for a closed curve).
    pub fn knots(&self) -> &[f64] {
        &self.t
    }

    /// The smoothing parameter.
    pub fn p(&self) -> f64 {
        self.p
    }

    /// `α = (1 − p)/p`, the weight of the roughness term relative to the data term
    /// (infinite for p = 0).
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// Whether this is the periodic spline of a closed curve.
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// The roughness `∫ |C''(t)|² dt` (exact: C'' is piecewise linear).
    pub fn roughness(&self) -> f64 {
        let second: Vec<[f64; 2]> = self.second.iter().map(|c| [c.x, c.y]).collect();
        roughness(&self.t, &second, self.closed)
    }

    /// The spline itself, as a [`ParametricCubic`] through the smoothed values with the
    /// spline's own tangents (so it is the C² natural or periodic spline exactly, not a new
    /// interpolation). A closed curve is returned with `P_0` repeated at the end, as
    /// [`ParametricCubic::from_hermite`] takes closed Hermite data.
    ///
    /// # Errors
    /// Those of [`ParametricCubic::from_hermite`] (not expected for a fitted spline).
    pub fn curve(&self) -> Result<ParametricCubic> {
        let n = self.values.len();
        let spans = if self.closed { n } else { n - 1 };
        let at = |i: usize| if i == n { 0 } else { i };
        let mut tangents = Vec::with_capacity(spans + 1);
        for i in 0..spans {
            let h = self.t[i + 1] - self.t[i];
            let (g0, g1) = (self.values[i], self.values[at(i + 1)]);
            let (c0, c1) = (self.second[i], self.second[at(i + 1)]);
            tangents.push((g1 - g0) / h - (c0 * 2.0 + c1) * (h / 6.0));
        }
        // The derivative at the end of the last span.
        let i = spans - 1;
        let h = self.t[i + 1] - self.t[i];
        let (g0, g1) = (self.values[i], self.values[at(i + 1)]);
        let (c0, c1) = (self.second[i], self.second[at(i + 1)]);
        tangents.push((g1 - g0) / h + (c0 + c1 * 2.0) * (h / 6.0));
        let mut pts = self.values.clone();
        if self.closed {
            pts.push(self.values[0]);
        }
        ParametricCubic::from_hermite(self.t.clone(), pts, tangents)
    }
}

/// The smoothing spline of points of any dimension (one parameter and one p for every
/// coordinate), with p chosen as `how` says: the fit and how p was chosen. As
/// [`SmoothingSpline::select`], which is this for planar points.
///
/// # Errors
/// As [`SmoothingSpline::select`].
pub(crate) fn select_any<const D: usize>(
    t: &[f64],
    points: &[[f64; D]],
    weights: Option<&[f64]>,
    closed: bool,
    how: Smoothing,
) -> Result<(Fit<D>, SmoothingInfo)> {
    let problem = Problem::new(t, points, weights, closed)?;
    match how {
        Smoothing::P(p) => {
            check_p(p, closed)?;
            let fit = problem.fit_p(p)?;
            let info = SmoothingInfo {
                p,
                alpha: fit.alpha,
                gcv: None,
                degrees_of_freedom: None,
                trials: Vec::new(),
                converged: true,
                notes: Vec::new(),
            };
            Ok((fit, info))
        }
        Smoothing::MaxDisplacement {
            tolerance,
            max_steps,
        } => {
            if !(tolerance.is_finite() && tolerance > 0.0) {
                return Err(Error::InvalidParameter {
                    name: "tolerance".into(),
                    reason: format!("must be a positive finite number, got {tolerance}"),
                });
            }
            problem.with_terms().search_tolerance(tolerance, max_steps)
        }
        Smoothing::Gcv => problem.with_terms().search_gcv(),
    }
}

/// Solve for each coordinate of `rhs` in turn with `solve` (one factorisation, a scalar
/// right-hand side each: the same numbers as solving for the planar vectors together).
fn by_coordinate<const D: usize>(
    rhs: &mut [[f64; D]],
    solve: impl Fn(&mut [f64]) -> Result<()>,
) -> Result<()> {
    let mut column = vec![0.0; rhs.len()];
    for c in 0..D {
        for (x, v) in column.iter_mut().zip(rhs.iter()) {
            *x = v[c];
        }
        solve(&mut column)?;
        for (v, x) in rhs.iter_mut().zip(&column) {
            v[c] = *x;
        }
    }
    Ok(())
}

/// `α = (1 − p)/p`.
fn alpha_of(p: f64) -> f64 {
    if p == 0.0 {
        f64::INFINITY
    } else {
        (1.0 - p) / p
    }
}

/// The `p` parameter: `None` for `auto` (or not given), else a number in [0, 1].
pub(crate) fn param_p(options: &FairOptions) -> Result<Option<f64>> {
    options.get(&super::smoothing_mst::P)
}

pub(crate) fn check_p(p: f64, closed: bool) -> Result<()> {
    if !(0.0..=1.0).contains(&p) {
        return Err(Error::InvalidParameter {
            name: "p".into(),
            reason: format!("{p} is outside [0, 1]"),
        });
    }
    if closed && p == 0.0 {
        return Err(Error::InvalidParameter {
            name: "p".into(),
            reason: "p = 0 collapses a closed curve to a point; use p > 0".into(),
        });
    }
    Ok(())
}

/// One solved spline: the fitted values, `u` (with `γ = p·u`) at every knot, and the
/// quantities the searches need.
pub(crate) struct Fit<const D: usize> {
    pub(crate) p: f64,
    /// `α = (1 − p)/p` as used (kept apart from p, which rounds to 1 for tiny α).
    pub(crate) alpha: f64,
    /// The smoothed values `g_i`.
    pub(crate) values: Vec<[f64; D]>,
    /// `C''(t_k)` at every knot.
    pub(crate) second: Vec<[f64; D]>,
    /// `Σ w_i |y_i − g_i|²` (GCV only).
    rss: f64,
    /// `tr(I − A)` (GCV only).
    trace_residual: f64,
}

/// The data of one smoothing problem, validated, with what every trial shares.
struct Problem<'a, const D: usize> {
    t: &'a [f64],
    y: &'a [[f64; D]],
    closed: bool,
    /// `W⁻¹_ii` (0 for a pinned point); `None` for unit weights.
    dinv: Option<Vec<f64>>,
    /// Reciprocal span lengths `1/h_k`: n − 1 (open) or n (closed).
    ih: Vec<f64>,
    /// [`KnotTerms`] of every unknown, for the searches, which solve many times (empty for
    /// one solve: they are then made as the matrix is assembled).
    terms: Vec<KnotTerms<D>>,
}

/// What row `j` of the system takes from the data, whatever p: `Qᵀ y` and the parts of the
/// entries of `a R + b Qᵀ W⁻¹ Q` (see [`KnotTerms::entries`]). Computed once per search
/// instead of once per trial.
#[derive(Clone, Copy, Debug)]
struct KnotTerms<const D: usize> {
    /// `(Qᵀ y)` at the knot.
    qty: [f64; D],
    /// `h_{k−1} + h_k`.
    span_sum: f64,
    /// `h_k`.
    span: f64,
    /// `1/h_k`.
    ih: f64,
    /// `1/h_{k+1}` (0 when span k+1 does not exist).
    ih_next: f64,
    /// `W⁻¹` at knot k + 1.
    d_next: f64,
    /// The diagonal's data part, `W⁻¹_{k−1}/h²_{k−1} + W⁻¹_k (1/h_{k−1} + 1/h_k)² + W⁻¹_{k+1}/h²_k`.
    data_diag: f64,
    /// The first off-diagonal's data part over `1/h_k`.
    data_next: f64,
}

impl<const D: usize> KnotTerms<D> {
    /// The entries `(k,k)`, `(k,k+1)`, `(k,k+2)` of `a R + b Qᵀ W⁻¹ Q`, in the order of
    /// operations they have always been computed in (so the same bits).
    #[inline]
    fn entries(&self, a: f64, b: f64) -> [f64; 3] {
        let d0 = a * self.span_sum / 3.0 + b * self.data_diag;
        let d1 = a * self.span / 6.0 - b * self.ih * self.data_next;
        let d2 = b * self.d_next * self.ih * self.ih_next;
        [d0, d1, d2]
    }
}

impl<'a, const D: usize> Problem<'a, D> {
    fn new(
        t: &'a [f64],
        y: &'a [[f64; D]],
        weights: Option<&[f64]>,
        closed: bool,
    ) -> Result<Problem<'a, D>> {
        let n = y.len();
        let min = if closed { 3 } else { 2 };
        if n < min {
            return Err(Error::TooFewPoints {
                needed: min,
                got: n,
            });
        }
        let nt = if closed { n + 1 } else { n };
        if t.len() != nt {
            return Err(Error::LengthMismatch {
                what: "parameters",
                got: t.len(),
                expected: nt,
            });
        }
        if let Some(index) = t.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite { index });
        }
        if let Some(i) = t.windows(2).position(|w| w[1] <= w[0]) {
            return Err(Error::NotIncreasing { index: i + 1 });
        }
        if let Some(index) = y.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(Error::NonFinite { index });
        }
        let dinv = match weights {
            None => None,
            Some(w) => {
                if w.len() != n {
                    return Err(Error::LengthMismatch {
                        what: "weights",
                        got: w.len(),
                        expected: n,
                    });
                }
                if let Some(i) = w.iter().position(|&v| v.is_nan() || v <= 0.0) {
                    return Err(Error::InvalidParameter {
                        name: "weights".into(),
                        reason: format!("weight {i} is {}, must be positive", w[i]),
                    });
                }
                Some(w.iter().map(|&v| 1.0 / v).collect())
            }
        };
        let ih: Vec<f64> = t.windows(2).map(|w| 1.0 / (w[1] - w[0])).collect();
        Ok(Problem {
            t,
            y,
            closed,
            dinv,
            ih,
            terms: Vec::new(),
        })
    }

    /// The problem with the [`KnotTerms`] of every unknown kept, for a search, when they
    /// take at most [`TERMS_CACHE_BYTES`] (larger curves make them as each trial assembles
    /// its matrix: the same numbers, without the memory).
    fn with_terms(mut self) -> Self {
        if self.m() * std::mem::size_of::<KnotTerms<D>>() <= TERMS_CACHE_BYTES {
            self.terms = (0..self.m()).map(|j| self.knot_terms(j)).collect();
        }
        self
    }

    /// The [`KnotTerms`] of unknown `j`: kept, or made now.
    #[inline]
    fn terms_of(&self, j: usize) -> KnotTerms<D> {
        self.terms
            .get(j)
            .copied()
            .unwrap_or_else(|| self.knot_terms(j))
    }

    /// The [`KnotTerms`] of unknown `j` from the data.
    fn knot_terms(&self, j: usize) -> KnotTerms<D> {
        let k = self.knot(j);
        let (km, kp) = (self.prev(k), self.next(k));
        let (ihm, ihp) = (self.ih[km], self.ih[k]);
        let s = ihm + ihp;
        let (dm, d, dp) = (self.d(km), self.d(k), self.d(kp));
        // Span k+1 exists whenever knot k+1 is an unknown.
        let ihpp = if self.closed || kp < self.n() - 1 {
            self.ih[kp]
        } else {
            0.0
        };
        KnotTerms {
            qty: self.qty(k),
            span_sum: self.span(km) + self.span(k),
            span: self.span(k),
            ih: ihp,
            ih_next: ihpp,
            d_next: dp,
            data_diag: dm * ihm * ihm + d * s * s + dp * ihp * ihp,
            data_next: d * s + dp * (ihp + ihpp),
        }
    }

    /// `W⁻¹_ii`.
    #[inline]
    fn d(&self, i: usize) -> f64 {
        self.dinv.as_ref().map_or(1.0, |d| d[i])
    }

    /// The length of span k, `h_k = t_{k+1} − t_k`.
    #[inline]
    fn span(&self, k: usize) -> f64 {
        self.t[k + 1] - self.t[k]
    }

    /// `(Qᵀ y)` at knot k: the jump of the divided differences.
    #[inline]
    fn qty(&self, k: usize) -> [f64; D] {
        let (km, kp) = (self.prev(k), self.next(k));
        let (y, ih) = (self.y, &self.ih);
        std::array::from_fn(|a| (y[kp][a] - y[k][a]) * ih[k] - (y[k][a] - y[km][a]) * ih[km])
    }

    fn n(&self) -> usize {
        self.y.len()
    }

    /// Number of unknowns (second derivatives not fixed by the end conditions).
    fn m(&self) -> usize {
        if self.closed { self.n() } else { self.n() - 2 }
    }

    /// The knot of unknown `j`.
    #[inline]
    fn knot(&self, j: usize) -> usize {
        if self.closed { j } else { j + 1 }
    }

    /// The knot (and span) before knot `k` (cyclically when closed). Only called for `k ≥ 1`
    /// on open curves.
    #[inline]
    fn prev(&self, k: usize) -> usize {
        if k == 0 { self.n() - 1 } else { k - 1 }
    }

    /// The knot after knot `k` (cyclically when closed).
    #[inline]
    fn next(&self, k: usize) -> usize {
        if k + 1 == self.n() { 0 } else { k + 1 }
    }

    /// `tr R / tr(Qᵀ W⁻¹ Q)`: csaps's default α and the centre of the searches.
    fn alpha_ref(&self) -> Result<f64> {
        let (mut tr_r, mut tr_n) = (0.0, 0.0);
        for j in 0..self.m() {
            let k = self.knot(j);
            let (km, kp) = (self.prev(k), self.next(k));
            tr_r += (self.span(km) + self.span(k)) / 3.0;
            let s = self.ih[km] + self.ih[k];
            tr_n += self.d(km) * self.ih[km] * self.ih[km]
                + self.d(k) * s * s
                + self.d(kp) * self.ih[k] * self.ih[k];
        }
        let alpha = tr_r / tr_n;
        if alpha.is_finite() && alpha > 0.0 {
            Ok(alpha)
        } else {
            Err(Error::Degenerate(
                "no roughness/data balance: every point is pinned or there are no interior knots"
                    .into(),
            ))
        }
    }

    /// Solve for `p ∈ [0, 1]` (p = 0 by the least-squares line on open curves).
    fn fit_p(&self, p: f64) -> Result<Fit<D>> {
        if p == 0.0 {
            self.fit_line()
        } else {
            self.solve(p, 1.0 - p, alpha_of(p), false)
        }
    }

    /// Solve for `α` given on a log scale, `α = α_ref · e^s`.
    fn fit_log_alpha(&self, alpha_ref: f64, s: f64, gcv: bool) -> Result<Fit<D>> {
        let alpha = alpha_ref * s.exp();
        self.solve(1.0 / (1.0 + alpha), alpha / (1.0 + alpha), alpha, gcv)
    }

    /// The spline for the scaled system `(a R + b Qᵀ W⁻¹ Q) u = Qᵀ y` (`a = p`, `b = 1 − p`,
    /// `alpha = b/a` computed by the caller without rounding p);
    /// with `gcv`, also RSS and `tr(I − A)`.
    fn solve(&self, a: f64, b: f64, alpha: f64, gcv: bool) -> Result<Fit<D>> {
        let (n, m) = (self.n(), self.m());
        // u at every knot; the open ends stay 0 (natural end conditions).
        let mut u = vec![[0.0; D]; n];
        let mut trace_residual = 0.0;
        if self.closed {
            let mut mat = CyclicSymBanded::zeros(m, 2);
            for (k, uk) in u.iter_mut().enumerate() {
                let terms = self.terms_of(k);
                *uk = terms.qty;
                let [d0, d1, d2] = terms.entries(a, b);
                mat.add(k, k, d0);
                mat.add(k, (k + 1) % m, d1);
                mat.add(k, (k + 2) % m, d2);
            }
            if gcv {
                let inv = mat.factorize_with_inverse()?;
                trace_residual = b * self.trace_term(|i, j| inv.get(i, j));
            } else {
                mat.factorize()?;
            }
            by_coordinate(&mut u, |c| mat.solve_in_place(c))?;
        } else if gcv {
            let mut mat = SymBanded::zeros(m, 2);
            for j in 0..m {
                let terms = self.terms_of(j);
                u[j + 1] = terms.qty;
                let [d0, d1, d2] = terms.entries(a, b);
                mat.add(j, j, d0);
                if j + 1 < m {
                    mat.add(j + 1, j, d1);
                }
                if j + 2 < m {
                    mat.add(j + 2, j, d2);
                }
            }
            let inv = factorize_with_inverse_band(&mut mat)?;
            trace_residual = b * self.trace_term(|i, j| inv.get(i - 1, j - 1));
            by_coordinate(&mut u[1..n - 1], |c| mat.solve_in_place(c))?;
        } else {
            // The same entries and operations as the band code above, written out for
            // half-bandwidth 2 (see `smoothing_system`).
            let row = |terms: &KnotTerms<D>, uj: &mut [f64; D]| {
                *uj = terms.qty;
                terms.entries(a, b)
            };
            let interior = u[1..n - 1].iter_mut();
            let mut mat = if self.terms.is_empty() {
                Penta::from_columns(
                    interior
                        .enumerate()
                        .map(|(j, uj)| row(&self.knot_terms(j), uj)),
                )
            } else {
                Penta::from_columns(self.terms.iter().zip(interior).map(|(t, uj)| row(t, uj)))
            };
            mat.factorize()?;
            mat.solve_in_place(&mut u[1..n - 1]);
        }
        let mut values = Vec::with_capacity(n);
        let mut rss = 0.0;
        let mut push = |i: usize, qu: [f64; D]| {
            let di = self.d(i);
            let yi = self.y[i];
            values.push(std::array::from_fn(|c| yi[c] - qu[c] * (b * di)));
            if gcv {
                // w_i |y_i − g_i|² = b² D_i |(Qu)_i|², exact even where g_i ≈ y_i.
                rss += b * b * di * dot(&qu, &qu);
            }
        };
        if self.closed {
            for i in 0..n {
                push(i, self.q_row_times(&u, i));
            }
        } else {
            // `q_row_times` for open curves, with the end terms apart (the same operations).
            let ih = &self.ih;
            push(0, std::array::from_fn(|c| (u[1][c] - u[0][c]) * ih[0]));
            for (k, (w, h)) in u.windows(3).zip(ih.windows(2)).enumerate() {
                let qu = std::array::from_fn(|c| {
                    (w[0][c] - w[1][c]) * h[0] + (w[2][c] - w[1][c]) * h[1]
                });
                push(k + 1, qu);
            }
            push(
                n - 1,
                std::array::from_fn(|c| (u[n - 2][c] - u[n - 1][c]) * ih[n - 2]),
            );
        }
        for v in &mut u {
            for c in v.iter_mut() {
                *c *= a;
            }
        }
        Ok(Fit {
            p: a,
            alpha,
            values,
            second: u,
            rss,
            trace_residual,
        })
    }

    /// `(Q v)_i` of a closed curve, for `v` given at every knot (open curves: in
    /// [`Problem::solve`], the ends apart).
    #[inline]
    fn q_row_times(&self, v: &[[f64; D]], i: usize) -> [f64; D] {
        let ih = &self.ih;
        let term = |j: usize, h: usize, c: usize| (v[j][c] - v[i][c]) * ih[h];
        let (im, ip) = (self.prev(i), self.next(i));
        std::array::from_fn(|c| term(im, im, c) + term(ip, i, c))
    }

    /// `Σ_i W⁻¹_ii q_iᵀ M⁻¹ q_i` with `M⁻¹` read by knot indices through `inv` (only pairs of
    /// unknown knots at cyclic distance ≤ 2 are asked for).
    fn trace_term(&self, inv: impl Fn(usize, usize) -> f64) -> f64 {
        let n = self.n();
        let is_unknown = |k: usize| self.closed || (1..n - 1).contains(&k);
        let mut total = 0.0;
        for i in 0..n {
            let di = self.d(i);
            if di == 0.0 {
                continue;
            }
            // Row i of Q: knots i−1, i, i+1 with 1/h_{i−1}, −(1/h_{i−1} + 1/h_i), 1/h_i.
            let mut q = [(0usize, 0.0f64); 3];
            let mut len = 0;
            if self.closed || i > 0 {
                let im = self.prev(i);
                if is_unknown(im) {
                    q[len] = (im, self.ih[im]);
                    len += 1;
                }
            }
            if is_unknown(i) {
                q[len] = (i, -(self.ih[self.prev(i)] + self.ih[i]));
                len += 1;
            }
            if self.closed || i + 1 < n {
                let ip = self.next(i);
                if is_unknown(ip) {
                    q[len] = (ip, self.ih[i]);
                    len += 1;
                }
            }
            let mut quad = 0.0;
            for &(ka, va) in &q[..len] {
                for &(kb, vb) in &q[..len] {
                    quad += va * vb * inv(ka, kb);
                }
            }
            total += di * quad;
        }
        total
    }

    /// p = 0 on an open curve: the weighted least-squares line in t, constrained through the
    /// pinned points (at most two).
    fn fit_line(&self) -> Result<Fit<D>> {
        let n = self.n();
        let pins: Vec<usize> = (0..n).filter(|&i| self.d(i) == 0.0).collect();
        let t = self.t;
        // The line is `origin + slope · (t − t_origin)`.
        let (t_origin, origin, slope) = match pins.as_slice() {
            [] => {
                let (mut sw, mut st, mut sy) = (0.0, 0.0, [0.0; D]);
                for (i, (&ti, yi)) in t.iter().zip(self.y).enumerate() {
                    let w = 1.0 / self.d(i);
                    sw += w;
                    st += w * ti;
                    for c in 0..D {
                        sy[c] += yi[c] * w;
                    }
                }
                let (tm, ym) = (st / sw, sy.map(|v| v / sw));
                (tm, ym, self.slope_about(tm, ym, None))
            }
            &[k] => {
                let (tk, yk) = (t[k], self.y[k]);
                (tk, yk, self.slope_about(tk, yk, Some(k)))
            }
            &[k0, k1] => {
                let (t0, y0, y1) = (t[k0], self.y[k0], self.y[k1]);
                (
                    t0,
                    y0,
                    std::array::from_fn(|c| (y1[c] - y0[c]) / (t[k1] - t0)),
                )
            }
            _ => {
                return Err(Error::InvalidParameter {
                    name: "p".into(),
                    reason: "p = 0 with more than two pinned points (infinite weights) is not \
                             a line; use p > 0"
                        .into(),
                });
            }
        };
        let mut values = Vec::with_capacity(n);
        for (i, (&ti, &yi)) in t.iter().zip(self.y).enumerate() {
            let g = if self.d(i) == 0.0 {
                yi
            } else {
                std::array::from_fn(|c| origin[c] + slope[c] * (ti - t_origin))
            };
            values.push(g);
        }
        if values.iter().flatten().any(|g| !g.is_finite()) {
            return Err(Error::Singular("least-squares line is not finite".into()));
        }
        Ok(Fit {
            p: 0.0,
            alpha: f64::INFINITY,
            values,
            second: vec![[0.0; D]; n],
            rss: 0.0,
            trace_residual: 0.0,
        })
    }

    /// The weighted least-squares slope of the points about the fixed `(t0, y0)`, leaving out
    /// point `skip`.
    fn slope_about(&self, t0: f64, y0: [f64; D], skip: Option<usize>) -> [f64; D] {
        let (mut stt, mut sty) = (0.0, [0.0; D]);
        for i in (0..self.n()).filter(|&i| Some(i) != skip) {
            let w = 1.0 / self.d(i);
            let dt = self.t[i] - t0;
            stt += w * dt * dt;
            for c in 0..D {
                sty[c] += (self.y[i][c] - y0[c]) * (w * dt);
            }
        }
        sty.map(|v| v / stt)
    }

    fn trial(&self, fit: &Fit<D>, gcv: Option<f64>) -> SmoothingTrial {
        SmoothingTrial {
            p: fit.p,
            alpha: fit.alpha,
            max_displacement: max_displacement(self.y, &fit.values),
            roughness: roughness(self.t, &fit.second, self.closed),
            gcv,
        }
    }

    /// The `ln(α/α_ref)` search interval.
    fn log_alpha_range(&self) -> (f64, f64) {
        (
            -LOG_ALPHA_BELOW,
            4.0 * (self.n() as f64).ln() + LOG_ALPHA_ABOVE,
        )
    }

    /// The result of tolerance mode.
    fn finish(
        self,
        fit: Fit<D>,
        trials: Vec<SmoothingTrial>,
        converged: bool,
        notes: Vec<String>,
    ) -> Result<(Fit<D>, SmoothingInfo)> {
        let info = SmoothingInfo {
            p: fit.p,
            alpha: fit.alpha,
            gcv: None,
            degrees_of_freedom: None,
            trials,
            converged,
            notes,
        };
        Ok((fit, info))
    }

    /// Tolerance mode: bisection on `ln α` for the largest feasible α. Each solved trial is
    /// measured once ([`Problem::trial`]), and its largest displacement decides.
    fn search_tolerance(self, tolerance: f64, max_steps: usize) -> Result<(Fit<D>, SmoothingInfo)> {
        let mut trials = Vec::new();
        let mut notes = Vec::new();
        // A solved trial, recorded; whether it is within the tolerance.
        let record = |fit: &Fit<D>, trials: &mut Vec<SmoothingTrial>| {
            let trial = self.trial(fit, None);
            trials.push(trial);
            trial.max_displacement <= tolerance
        };
        // The smoothest candidate of an open curve: the least-squares line.
        if !self.closed {
            match self.fit_line() {
                Ok(line) => {
                    if record(&line, &mut trials) {
                        notes.push("the least-squares line is within the tolerance".into());
                        return self.finish(line, trials, true, notes);
                    }
                }
                Err(e @ Error::Singular(_)) => return Err(e),
                Err(_) => {} // more than two pins: no line candidate
            }
        }
        let interpolant = |problem: &Problem<'_, D>| problem.solve(1.0, 0.0, 0.0, false);
        if self.m() == 0 {
            let fit = interpolant(&self)?;
            return self.finish(fit, trials, true, notes);
        }
        let alpha_ref = self.alpha_ref()?;
        let (mut lo, mut hi) = self.log_alpha_range();
        let top = self.fit_log_alpha(alpha_ref, hi, false);
        if top.as_ref().is_ok_and(|f| record(f, &mut trials)) {
            notes.push("the smoothest spline searched is within the tolerance".into());
            let fit = top?;
            return self.finish(fit, trials, true, notes);
        }
        // (The guard records a solved trial, feasible or not.)
        let mut best = match self.fit_log_alpha(alpha_ref, lo, false) {
            Ok(f) if record(&f, &mut trials) => f,
            _ => {
                notes.push(
                    "the tolerance is below what any smoothing allows; the result interpolates"
                        .into(),
                );
                let fit = interpolant(&self)?;
                return self.finish(fit, trials, true, notes);
            }
        };
        let precision = BISECTION_REL_PRECISION.ln_1p();
        let mut steps = 0;
        while hi - lo > precision && steps < max_steps {
            let mid = 0.5 * (lo + hi);
            let fit = self.fit_log_alpha(alpha_ref, mid, false);
            if fit.as_ref().is_ok_and(|f| record(f, &mut trials)) {
                lo = mid;
                best = fit?;
            } else {
                hi = mid;
            }
            steps += 1;
        }
        let converged = hi - lo <= precision;
        if !converged {
            notes.push(format!(
                "bisection stopped after {steps} steps with α known to a factor {:.3e}",
                (hi - lo).exp()
            ));
        }
        self.finish(best, trials, converged, notes)
    }

    /// GCV mode: coarse scan of `ln α`, then Brent around the best scan point.
    fn search_gcv(self) -> Result<(Fit<D>, SmoothingInfo)> {
        if self.n() < 3 {
            return Err(Error::TooFewPoints {
                needed: 3,
                got: self.n(),
            });
        }
        let alpha_ref = self.alpha_ref()?;
        let n = self.n() as f64;
        let mut trials = Vec::new();
        let score = |s: f64, trials: &mut Vec<SmoothingTrial>| -> f64 {
            match self.fit_log_alpha(alpha_ref, s, true) {
                Ok(f) => {
                    let v = n * f.rss / (f.trace_residual * f.trace_residual);
                    let v = if v.is_finite() { v } else { f64::INFINITY };
                    trials.push(self.trial(&f, Some(v)));
                    v
                }
                Err(_) => f64::INFINITY,
            }
        };
        let (lo, hi) = self.log_alpha_range();
        let steps = ((hi - lo) / GCV_SCAN_STEP).ceil() as usize;
        let mut best = (f64::NAN, f64::INFINITY);
        for k in 0..=steps {
            let s = (lo + k as f64 * GCV_SCAN_STEP).min(hi);
            let v = score(s, &mut trials);
            if v < best.1 {
                best = (s, v);
            }
        }
        if !best.1.is_finite() {
            return Err(Error::NoConvergence(
                "generalised cross-validation: no trial spline could be solved".into(),
            ));
        }
        let (a, b) = (
            (best.0 - GCV_SCAN_STEP).max(lo),
            (best.0 + GCV_SCAN_STEP).min(hi),
        );
        let m = minimize_brent(
            |s| score(s, &mut trials),
            a,
            b,
            0.0,
            GCV_LOG_ALPHA_TOL,
            GCV_MAX_EVALUATIONS,
        );
        let converged = m.evaluations < GCV_MAX_EVALUATIONS;
        let s = if m.fx < best.1 { m.x } else { best.0 };
        let fit = self.fit_log_alpha(alpha_ref, s, true)?;
        let gcv = n * fit.rss / (fit.trace_residual * fit.trace_residual);
        let mut notes = Vec::new();
        if s <= lo || s >= hi {
            notes.push(format!(
                "the GCV minimum is at the end of the searched range (ln(α/α_ref) = {s:.1})"
            ));
        }
        let info = SmoothingInfo {
            p: fit.p,
            alpha: fit.alpha,
            gcv: Some(gcv),
            degrees_of_freedom: Some(n - fit.trace_residual),
            trials,
            converged,
            notes,
        };
        Ok((fit, info))
    }
}
