//! `mst`: the cubic smoothing spline, the global baseline that Han et al.
//! (`../shared/papers/han-explicit-fairing-indicator.txt`, §5) call MST — Matlab's `csaps`.
//!
//! # The problem
//!
//! For points `P_0..P_{n−1}` at chord-length parameters `t_i` (docs/algorithms/README.md §0.2) and
//! weights `w_i`, find the C² cubic spline curve `C` with knots `t_i` that minimises
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
//! - `--tolerance D` without p: the smoothest spline whose largest displacement is at most D,
//!   searched in `λ = ln(α/α_ref)` (a well-conditioned variable: the smoothing bandwidth grows
//!   like `α^{1/4}`). For an open curve the least-squares line is tried first, then the two
//!   ends of the range; between them a bracket `[λ_lo, λ_hi]` (`λ_lo` feasible, `λ_hi` not, or
//!   the end of the range) is narrowed until `α_hi/α_lo ≤ 1 +` [`BISECTION_REL_PRECISION`],
//!   and its feasible end is returned, so the tolerance always holds (`p = 1` interpolates
//!   with zero displacement, the fallback). The narrowing (`bracket.rs`) interpolates
//!   `g(λ) = ln(d(λ)/D)`, `d` the largest displacement: `g` rises with slope 1 at the bottom
//!   (`d ∝ α`), so the first step is that slope's guess and small tolerances take 5–8 fits in
//!   all; above, `g` has plateaus (noise smoothed away, signal not yet) and kinks (another
//!   point takes the largest displacement), where Chandrupatla's inverse quadratic
//!   interpolation with bisection in reserve takes 10–14 fits at noise-level tolerances
//!   (19–20 for the bisection this replaced). Every step stays within the ITP method's
//!   projection towards the midpoint, so no search takes more than three fits beyond the
//!   bisection's count.
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
//!
//! [`SymBanded`]: crate::numeric::SymBanded
//! [`CyclicSymBanded`]: crate::numeric::CyclicSymBanded
//! [`minimize_brent`]: crate::numeric::minimize_brent

mod mst;
mod problem;
mod search;
mod system;
mod trial;

pub use mst::Mst;
use problem::Problem;
use system::Penta;
pub(crate) use trial::roughness;
use trial::{dot, max_displacement};

use super::FairOptions;
use crate::error::{Error, Result};
use crate::geom::{Point, Vec2};
use crate::spline::ParametricCubic;

/// The tolerance search stops when its bracket `[α_lo, α_hi]` satisfies
/// `α_hi / α_lo ≤ 1 + BISECTION_REL_PRECISION` (the name is from the bisection it used to be).
pub const BISECTION_REL_PRECISION: f64 = 1e-3;

/// Default limit on the steps of the tolerance search, the fits after the two ends of the
/// range (`max_iterations` overrides it). The bracket is about 90 units of `ln α` wide at
/// n = 10⁶, so a bisection would take 17 steps to reach [`BISECTION_REL_PRECISION`], and the
/// search takes at most three more; the default leaves ample room.
pub(super) const DEFAULT_MAX_SEARCH_STEPS: usize = 60;

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
/// their 5–20 trials: 8 MiB, about 10⁵ points. Kept, the rows cost a third of a trial on a
/// 200-point curve (issue #17); at 10⁶ points they would raise the peak memory by a third.
const TERMS_CACHE_BYTES: usize = 8 << 20;

/// How the smoothing parameter is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum Smoothing {
    /// The given `p ∈ [0, 1]` (1 interpolates, 0 is the least-squares line).
    P(f64),
    /// The smoothest spline (largest α) with every `|g_i − P_i| ≤ tolerance`, to within a
    /// factor `1 +` [`BISECTION_REL_PRECISION`] in α: a bracketing search on `ln α` (see the
    /// module documentation, "Choosing p") that takes at most `max_steps` steps, counted as
    /// the fits after the least-squares line and the two ends of the range.
    MaxDisplacement {
        /// The largest allowed displacement, data units.
        tolerance: f64,
        /// Step limit of the search.
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
    options.get(&mst::P)
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
