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
//! 5. Selection ([`super::local::select_candidate`]): the movable control point (all but the
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
//! [`super::local::support_ranges`]`[j]` change. The state keeps, per sample, the homogeneous
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
//!   subtracted (see [`super::local`]), so the output points (the faired curve at the input's
//!   parameters) stay within the tolerance. `--fix-ends` changes nothing about the curve: the
//!   end control points are fixed by default already (and an interpolating clamped fit
//!   passes through the end points); it makes the output's end points the input's exactly.
//!   `--fix-ends=tangent` (`curvature`) also holds the second (and third) control point at
//!   each end ([`SalviParams::held_ends`]), which keeps the curve's end tangents (and
//!   curvatures).
//!
//! [`DEFAULT_TOLERANCE_REL`]: super::local::DEFAULT_TOLERANCE_REL

use serde_json::{Map, Value};

use super::local::{
    self, DEFAULT_TABU_LENGTH, FIT_PARAMS, LocalReport, RecentList, RunningMax, clamp_point,
    json_f64, movable_mask, resolve_tolerance, select_candidate, support_ranges, uniform_samples,
};
use super::{FairMethod, FairOptions, FairStatus, HistoryRow, Move, Outcome, ParamSpec};
use crate::analysis::{ArcLengthTable, signed_curvature};
use crate::curve::{Curve, CurveDeriv, Piecewise};
use crate::error::{Error, Result};
use crate::geom::{Point, PointSeq, Vec2};
use crate::numeric::{NelderMeadParams, SymBanded, minimize_nelder_mead};
use crate::spline::{BSplineCurve, KnotVector, MAX_ORDER};

/// Spec default number of samples N (§3 step 2).
pub const DEFAULT_SAMPLES: usize = 200;

/// The default sample count is at least this many per non-empty knot span.
pub const SAMPLES_PER_SPAN: usize = 8;

/// Fewest samples accepted.
pub const MIN_SAMPLES: usize = 4;

/// Most samples accepted when given: every iteration evaluates its simplex over the samples
/// of one support, so a run costs about 1 ms per 1000 samples per iteration (20 000 samples
/// and the default 1000 iterations: about 20 s; 10⁶ ran for more than 5 minutes). The
/// automatic count, 8 per knot span, is not capped. Also the bound of `half_width` and
/// `target_coefficients`, which are counts of samples.
pub const MAX_SAMPLES: usize = 20_000;

/// The moving-average half-width is `⌊N / HALF_WIDTH_DIVISOR⌋` (spec §3 step 3.2).
pub const HALF_WIDTH_DIVISOR: usize = 20;

/// Passes of the moving average (spec §3 step 3.2).
pub const DEFAULT_PASSES: usize = 3;

/// Coefficients of the B-spline target fit: `max(MIN_TARGET_COEFFICIENTS, ⌊N/20⌋)`.
pub const MIN_TARGET_COEFFICIENTS: usize = 4;

/// The B-spline target fit samples κ at this many arc-length points per coefficient.
pub const LOOSE_SAMPLES_PER_COEFFICIENT: usize = 4;

/// Default iteration limit (the paper's Table 1 runs 1000 iterations).
pub const DEFAULT_MAX_ITERATIONS: usize = 1000;

/// Default window M of the stopping rule.
pub const DEFAULT_WINDOW: usize = 50;

/// Stop when Ê fell by less than this fraction of its value M iterations earlier.
pub const WINDOW_MIN_REL_IMPROVEMENT: f64 = 1e-3;

/// A search that lowers the local measure of the moved point by less than this fraction
/// counts as no progress: the point is skipped until a neighbour makes progress
/// (`skip_stalled`).
pub const STALL_REL_IMPROVEMENT: f64 = 1e-3;

/// The simplex edge s is this fraction of the mean length of the control-polygon legs at the
/// moved point (spec §3 step 6).
pub const SIMPLEX_STEP_REL: f64 = 0.1;

/// Simplex evaluation budget per move (spec §3 step 6).
pub const SIMPLEX_MAX_EVALUATIONS: usize = 400;

/// How the target curvature g is made from the curvature of the unfaired curve.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Smoother {
    /// Centred moving average, window truncated at the ends, repeated (normative, spec §3).
    MovingAverage {
        /// Half-width h in samples; `None`: `⌊N/20⌋`.
        half_width: Option<usize>,
        /// Number of passes.
        passes: usize,
    },
    /// Least-squares cubic B-spline function of arc length over a loose sampling.
    BSplineFit {
        /// Number of coefficients; `None`: `max(4, ⌊N/20⌋)`.
        coefficients: Option<usize>,
    },
    /// A target given sample by sample (the paper's manual editing); length N.
    Given(Vec<f64>),
}

impl Smoother {
    /// The normative default: moving average, `h = ⌊N/20⌋`, 3 passes.
    pub const DEFAULT: Smoother = Smoother::MovingAverage {
        half_width: None,
        passes: DEFAULT_PASSES,
    };
}

impl Default for Smoother {
    fn default() -> Smoother {
        Smoother::DEFAULT
    }
}

/// Parameters of [`fair_curve`]. Start from [`SalviParams::DEFAULT`].
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SalviParams {
    /// Number of samples N, at most [`MAX_SAMPLES`]; `None`: `max(200, 8 × non-empty spans)`.
    ///
    /// Default value: `None`.
    pub samples: Option<usize>,
    /// How g is made.
    ///
    /// Default value: [`Smoother::DEFAULT`].
    pub smoother: Smoother,
    /// Make g equal κ at both ends.
    ///
    /// Default value: `false`.
    pub pin_ends: bool,
    /// δ, the largest distance of a control point from its original position; `None`:
    /// [`local::DEFAULT_TOLERANCE_REL`] × the bounding-box diagonal of the control points.
    ///
    /// Default value: `None`.
    pub tolerance: Option<f64>,
    /// Length R of the recently-moved list.
    ///
    /// Default value: [`DEFAULT_TABU_LENGTH`] (4).
    pub tabu_length: usize,
    /// Iteration limit.
    ///
    /// Default value: [`DEFAULT_MAX_ITERATIONS`] (1000).
    pub max_iterations: usize,
    /// Window M of the stopping rule; 0 disables it (run `max_iterations`).
    ///
    /// Default value: [`DEFAULT_WINDOW`] (50).
    pub window: usize,
    /// Relative improvement over the window below which the run stops.
    ///
    /// Default value: [`WINDOW_MIN_REL_IMPROVEMENT`].
    pub min_rel_improvement: f64,
    /// Let the first and last control points move.
    ///
    /// Default value: `false`.
    pub free_ends: bool,
    /// Control points held at each end unless `free_ends`: 1 (the end points), 2 (also the
    /// end tangents) or 3 (also the end curvatures); `--fix-ends=tangent` / `curvature`.
    ///
    /// Default value: 1.
    pub held_ends: usize,
    /// Skip a control point whose last search made no progress (relative local improvement
    /// below [`STALL_REL_IMPROVEMENT`]) until a control point whose support overlaps its own
    /// makes progress; stop when every movable point is skipped. `false` follows spec §3 step 5
    /// literally (see the module documentation).
    ///
    /// Default value: `true`.
    pub skip_stalled: bool,
}

impl SalviParams {
    /// The defaults listed on each field.
    pub const DEFAULT: SalviParams = SalviParams {
        samples: None,
        smoother: Smoother::DEFAULT,
        pin_ends: false,
        tolerance: None,
        tabu_length: DEFAULT_TABU_LENGTH,
        max_iterations: DEFAULT_MAX_ITERATIONS,
        window: DEFAULT_WINDOW,
        min_rel_improvement: WINDOW_MIN_REL_IMPROVEMENT,
        free_ends: false,
        held_ends: 1,
        skip_stalled: true,
    };

    /// Set δ.
    pub fn with_tolerance(mut self, delta: f64) -> SalviParams {
        self.tolerance = Some(delta);
        self
    }

    /// Set N.
    pub fn with_samples(mut self, n: usize) -> SalviParams {
        self.samples = Some(n);
        self
    }

    /// Set the smoother.
    pub fn with_smoother(mut self, smoother: Smoother) -> SalviParams {
        self.smoother = smoother;
        self
    }

    /// Pin (or not) the target to κ at the ends.
    pub fn with_pin_ends(mut self, pin: bool) -> SalviParams {
        self.pin_ends = pin;
        self
    }

    /// Set the iteration limit.
    pub fn with_max_iterations(mut self, n: usize) -> SalviParams {
        self.max_iterations = n;
        self
    }

    /// Set the window M (0: no window rule).
    pub fn with_window(mut self, m: usize) -> SalviParams {
        self.window = m;
        self
    }

    /// Set the tabu length R.
    pub fn with_tabu_length(mut self, r: usize) -> SalviParams {
        self.tabu_length = r;
        self
    }

    /// Free (or fix) the end control points.
    pub fn with_free_ends(mut self, free: bool) -> SalviParams {
        self.free_ends = free;
        self
    }

    /// Hold `k` control points at each end (see [`SalviParams::held_ends`]).
    pub fn with_held_ends(mut self, k: usize) -> SalviParams {
        self.held_ends = k;
        self
    }

    /// Skip stalled control points (default) or follow the spec's selection literally.
    pub fn with_skip_stalled(mut self, skip: bool) -> SalviParams {
        self.skip_stalled = skip;
        self
    }
}

impl Default for SalviParams {
    fn default() -> SalviParams {
        SalviParams::DEFAULT
    }
}

/// What [`fair_curve`] did, with the sampled curvatures.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SalviReport {
    /// The common report; the measure is Ê (eq 14).
    pub local: LocalReport,
    /// The sample parameters `t_i`.
    pub samples: Vec<f64>,
    /// The target g at the samples.
    pub target: Vec<f64>,
    /// κ of the input at the samples.
    pub curvature_before: Vec<f64>,
    /// κ of the result at the samples.
    pub curvature_after: Vec<f64>,
    /// Largest distance `|x(t_i) − x⁰(t_i)|` over the samples (≤ δ by eq 10).
    pub max_curve_deviation: f64,
}

/// Signed curvature (§0.1) of `curve` at each parameter.
///
/// # Errors
/// [`Error::Degenerate`] at a parameter where the curvature is undefined (zero speed).
pub fn sample_curvature(curve: &BSplineCurve, t: &[f64]) -> Result<Vec<f64>> {
    t.iter()
        .map(|&ti| {
            let k = signed_curvature(&curve.derivatives(ti));
            if k.is_finite() {
                Ok(k)
            } else {
                Err(zero_speed(ti))
            }
        })
        .collect()
}

fn zero_speed(t: f64) -> Error {
    Error::Degenerate(format!(
        "the curve has zero speed at t = {t}, where its curvature is undefined"
    ))
}

/// The normative smoother (spec §3 step 3.2): a centred moving average of half-width h
/// whose window is truncated at the ends (the mean of the samples that exist), applied
/// `passes` times. O(N) per pass.
pub fn moving_average(values: &[f64], half_width: usize, passes: usize) -> Vec<f64> {
    let n = values.len();
    let mut cur = values.to_vec();
    let mut prefix = vec![0.0; n + 1];
    for _ in 0..passes {
        for i in 0..n {
            prefix[i + 1] = prefix[i] + cur[i];
        }
        for (i, c) in cur.iter_mut().enumerate() {
            let lo = i.saturating_sub(half_width);
            let hi = (i + half_width + 1).min(n);
            *c = (prefix[hi] - prefix[lo]) / (hi - lo) as f64;
        }
    }
    cur
}

/// Eq 14: `Σ_i (κ_i − g_i)²`.
///
/// # Panics
/// If the lengths differ.
pub fn target_measure(kappa: &[f64], target: &[f64]) -> f64 {
    assert_eq!(
        kappa.len(),
        target.len(),
        "κ and g must have one value per sample"
    );
    kappa
        .iter()
        .zip(target)
        .map(|(k, g)| (k - g) * (k - g))
        .sum()
}

/// The sample count asked for, or the default `max(200, 8 × non-empty spans)`.
pub fn sample_count(curve: &BSplineCurve, samples: Option<usize>) -> usize {
    samples.unwrap_or_else(|| {
        let spans = curve.breakpoints().len().saturating_sub(1);
        DEFAULT_SAMPLES.max(SAMPLES_PER_SPAN * spans)
    })
}

/// The target curvature g at the samples `t` of `curve`, whose curvature there is `kappa`
/// (spec §3 step 3).
///
/// # Errors
/// [`Error::LengthMismatch`] for a given target of the wrong length or `kappa` not matching
/// `t`; [`Error::InvalidParameter`] for a B-spline fit with fewer than 4 coefficients;
/// [`Error::Degenerate`] for a curve of zero length or zero speed; [`Error::Singular`].
pub fn target_curvature(
    curve: &BSplineCurve,
    t: &[f64],
    kappa: &[f64],
    smoother: &Smoother,
    pin_ends: bool,
) -> Result<Vec<f64>> {
    let n = t.len();
    if kappa.len() != n {
        return Err(Error::LengthMismatch {
            what: "curvature samples",
            got: kappa.len(),
            expected: n,
        });
    }
    let default_h = n / HALF_WIDTH_DIVISOR;
    let (mut g, ramp) = match smoother {
        Smoother::MovingAverage { half_width, passes } => {
            let h = half_width.unwrap_or(default_h);
            (moving_average(kappa, h, *passes), h)
        }
        Smoother::BSplineFit { coefficients } => {
            let m = coefficients.unwrap_or(MIN_TARGET_COEFFICIENTS.max(default_h));
            (bspline_target(curve, t, m)?, default_h)
        }
        Smoother::Given(g) => {
            if g.len() != n {
                return Err(Error::LengthMismatch {
                    what: "target curvature",
                    got: g.len(),
                    expected: n,
                });
            }
            if let Some(index) = g.iter().position(|v| !v.is_finite()) {
                return Err(Error::NonFinite { index });
            }
            (g.clone(), default_h)
        }
    };
    if pin_ends && n >= 2 {
        let h = ramp.clamp(1, (n - 1) / 2).max(1) as f64;
        let (e0, e1) = (kappa[0] - g[0], kappa[n - 1] - g[n - 1]);
        for (i, gi) in g.iter_mut().enumerate() {
            let a = (1.0 - i as f64 / h).max(0.0);
            let b = (1.0 - (n - 1 - i) as f64 / h).max(0.0);
            *gi += e0 * a + e1 * b;
        }
        g[0] = kappa[0];
        g[n - 1] = kappa[n - 1];
    }
    Ok(g)
}

/// Least-squares cubic B-spline function g(s) with `m` coefficients on uniform knots over
/// the arc length, fitted to κ at `4m` arc-length-uniform points, evaluated at `s(t_i)`.
fn bspline_target(curve: &BSplineCurve, t: &[f64], m: usize) -> Result<Vec<f64>> {
    if m < MIN_TARGET_COEFFICIENTS {
        return Err(Error::InvalidParameter {
            name: "target_coefficients".into(),
            reason: format!("{m} is below {MIN_TARGET_COEFFICIENTS}"),
        });
    }
    let table = ArcLengthTable::new(curve);
    let total = table.total();
    if !(total > 0.0 && total.is_finite()) {
        return Err(Error::Degenerate("the curve has zero length".into()));
    }
    let degree = 3;
    // The basis of g, evaluated through a B-spline whose control points are placeholders.
    let basis = BSplineCurve::try_new(
        degree,
        KnotVector::clamped_uniform(degree, m)?,
        vec![Point::ORIGIN; m],
        None,
    )?;
    let loose = LOOSE_SAMPLES_PER_COEFFICIENT * m;
    let mut normal = SymBanded::zeros(m, degree);
    let mut rhs = vec![0.0; m];
    let mut b = [[0.0; MAX_ORDER]; 4];
    for l in 0..loose {
        let u = l as f64 / (loose - 1) as f64;
        let tl = table.t_at(curve, u * total);
        let k = signed_curvature(&curve.derivatives(tl));
        if !k.is_finite() {
            return Err(zero_speed(tl));
        }
        let span = basis.find_span(u);
        basis.basis_derivs(span, u, 0, &mut b);
        for a in 0..=degree {
            let ia = span - degree + a;
            rhs[ia] += b[0][a] * k;
            for c in 0..=a {
                normal.add(ia, span - degree + c, b[0][a] * b[0][c]);
            }
        }
    }
    normal.factorize()?;
    normal.solve_in_place(&mut rhs)?;
    Ok(t.iter()
        .map(|&ti| {
            let u = (table.s_at(curve, ti) / total).clamp(0.0, 1.0);
            let span = basis.find_span(u);
            basis.basis_derivs(span, u, 0, &mut b);
            (0..=degree).map(|a| b[0][a] * rhs[span - degree + a]).sum()
        })
        .collect())
}

/// Curvature from homogeneous derivatives `a = (A, A', A'')` and weight derivatives
/// `w = (W, W', W'')` (`w = (1, 0, 0)` for a non-rational curve, where this is §0.1 exactly).
#[inline]
fn curvature_h(a: &[Vec2; 3], w: &[f64; 3]) -> f64 {
    let c0 = a[0] / w[0];
    let c1 = (a[1] - c0 * w[1]) / w[0];
    let c2 = (a[2] - c1 * (2.0 * w[1]) - c0 * w[2]) / w[0];
    // |c1|³ as |c1|²·sqrt(|c1|²): `hypot` would cost more than the rest of the formula.
    let speed2 = c1.length_squared();
    c1.cross(c2) / (speed2 * speed2.sqrt())
}

/// The per-sample state of a run.
struct Samples {
    t: Vec<f64>,
    span: Vec<usize>,
    /// Homogeneous derivatives `Σ w_m d_m N_m^{(o)}`, o = 0, 1, 2.
    hom: Vec<[Vec2; 3]>,
    /// `Σ w_m N_m^{(o)}` (constant during a run).
    wd: Vec<[f64; 3]>,
    target: Vec<f64>,
    /// `(κ_i − g_i)²`.
    contrib: Vec<f64>,
}

/// Fair `curve` by Salvi & Várady's method (see the module documentation). Knots, degree
/// and weights are kept; the result is within δ of `curve` at every parameter.
///
/// # Errors
/// [`Error::InvalidParameter`] for a degree below 2, fewer than [`MIN_SAMPLES`] samples, a
/// non-positive tolerance; [`Error::Degenerate`] when the curvature is undefined at a sample;
/// the errors of [`target_curvature`].
pub fn fair_curve(
    curve: &BSplineCurve,
    params: &SalviParams,
) -> Result<(BSplineCurve, SalviReport)> {
    let p = curve.degree();
    if p < 2 {
        return Err(Error::InvalidParameter {
            name: "degree".into(),
            reason: "curvature needs a curve of degree 2 or more".into(),
        });
    }
    if !(params.min_rel_improvement.is_finite() && params.min_rel_improvement >= 0.0) {
        return Err(Error::InvalidParameter {
            name: "min_rel_improvement".into(),
            reason: format!(
                "must be finite and non-negative, got {}",
                params.min_rel_improvement
            ),
        });
    }
    let delta = resolve_tolerance(params.tolerance, curve)?;
    let n_samples = sample_count(curve, params.samples);
    if n_samples < MIN_SAMPLES || params.samples.is_some_and(|n| n > MAX_SAMPLES) {
        return Err(Error::InvalidParameter {
            name: "samples".into(),
            reason: format!("{n_samples} is outside [{MIN_SAMPLES}, {MAX_SAMPLES}]"),
        });
    }
    let n_ctrl = curve.control_points().len();
    let t = uniform_samples(curve.domain(), n_samples);
    let ranges = support_ranges(curve.knots(), p, n_ctrl, &t)?;
    let original: Vec<Point> = curve.control_points().to_vec();
    let weights: Option<Vec<f64>> = curve.weights().map(<[f64]>::to_vec);

    // Per-sample state.
    let mut b = [[0.0; MAX_ORDER]; 4];
    let mut s = Samples {
        span: Vec::with_capacity(n_samples),
        hom: Vec::with_capacity(n_samples),
        wd: Vec::with_capacity(n_samples),
        target: Vec::new(),
        contrib: Vec::with_capacity(n_samples),
        t,
    };
    let mut kappa0 = Vec::with_capacity(n_samples);
    let mut position0 = Vec::with_capacity(n_samples);
    for &ti in &s.t {
        let span = curve.find_span(ti);
        curve.basis_derivs(span, ti, 2, &mut b);
        let mut a = [Vec2::ZERO; 3];
        let mut w = [0.0; 3];
        for (c, dc) in original[span - p..=span].iter().enumerate() {
            let wm = weights.as_ref().map_or(1.0, |w| w[span - p + c]);
            let dm = dc.to_vec2() * wm;
            for o in 0..3 {
                a[o] += dm * b[o][c];
                w[o] += wm * b[o][c];
            }
        }
        let k = curvature_h(&a, &w);
        if !k.is_finite() {
            return Err(zero_speed(ti));
        }
        kappa0.push(k);
        position0.push((a[0] / w[0]).to_point());
        s.span.push(span);
        s.hom.push(a);
        s.wd.push(w);
    }
    s.target = target_curvature(curve, &s.t, &kappa0, &params.smoother, params.pin_ends)?;
    s.contrib = kappa0
        .iter()
        .zip(&s.target)
        .map(|(k, g)| (k - g) * (k - g))
        .collect();
    let local_sum = |contrib: &[f64], j: usize| -> f64 { contrib[ranges[j].clone()].iter().sum() };
    let mut dev: Vec<f64> = (0..n_ctrl).map(|j| local_sum(&s.contrib, j)).collect();
    let measure_before: f64 = s.contrib.iter().sum();
    let mut measure = measure_before;

    let movable = movable_mask(
        n_ctrl,
        local::held_control_points(params.free_ends, params.held_ends),
    );
    let mut recent = RecentList::new(params.tabu_length);
    let mut cur = curve.clone();
    let mut displacement = RunningMax::zeros(n_ctrl);
    let mut history = vec![HistoryRow {
        iteration: 0,
        measure,
        max_distance: 0.0,
    }];
    let mut moves = Vec::new();
    let mut clamped_moves = 0;
    let mut iterations = 0;
    // Movable points whose local objective may still improve (see `skip_stalled`).
    let mut candidates = movable.clone();
    let mut stopped = !movable.iter().any(|&m| m) || measure == 0.0;
    // Basis columns w_j N_j^{(o)}(t_i) of the samples of the current support.
    let mut column: Vec<[f64; 3]> = Vec::new();

    while !stopped && iterations < params.max_iterations {
        let Some(j) = select_candidate(&dev, &candidates, &mut recent) else {
            // Every movable point is at a local optimum of its own objective.
            stopped = true;
            break;
        };
        iterations += 1;
        let range = ranges[j].clone();
        let old_local = dev[j];
        let dj = cur.control_points()[j];
        let wj = weights.as_ref().map_or(1.0, |w| w[j]);
        column.clear();
        for i in range.clone() {
            let span = s.span[i];
            cur.basis_derivs(span, s.t[i], 2, &mut b);
            let c = j + p - span;
            column.push([wj * b[0][c], wj * b[1][c], wj * b[2][c]]);
        }
        let objective = |v: &[f64; 2]| -> f64 {
            let (q, _) = clamp_point(original[j], dj + Vec2::new(v[0], v[1]), delta);
            let dv = q - dj;
            let mut sum = 0.0;
            for (k, i) in range.clone().enumerate() {
                let col = &column[k];
                let h = &s.hom[i];
                let a = [h[0] + dv * col[0], h[1] + dv * col[1], h[2] + dv * col[2]];
                let e = curvature_h(&a, &s.wd[i]) - s.target[i];
                sum += e * e;
            }
            sum
        };
        let step = SIMPLEX_STEP_REL * mean_leg(cur.control_points(), j);
        let step = if step > 0.0 && step.is_finite() {
            step
        } else {
            delta
        };
        let nm =
            NelderMeadParams::with_scaled_step(step).with_max_evaluations(SIMPLEX_MAX_EVALUATIONS);
        let found = minimize_nelder_mead(objective, [0.0, 0.0], &nm);
        let proposed = dj + Vec2::new(found.x[0], found.x[1]);
        let (q, clamped) = clamp_point(original[j], proposed, delta);
        let mut progress = false;
        if found.fx < old_local && q != dj {
            let dv = q - dj;
            let mut new_local = 0.0;
            for (k, i) in range.clone().enumerate() {
                let col = &column[k];
                let h = &mut s.hom[i];
                *h = [h[0] + dv * col[0], h[1] + dv * col[1], h[2] + dv * col[2]];
                let e = curvature_h(h, &s.wd[i]) - s.target[i];
                s.contrib[i] = e * e;
                new_local += e * e;
            }
            cur.set_control_point(j, q);
            // The difference is negative; `min` guards the running sum against rounding.
            measure = (measure - old_local + new_local).min(measure);
            let neighbours = j.saturating_sub(p)..(j + p + 1).min(n_ctrl);
            for (jj, dv) in dev[neighbours.clone()].iter_mut().enumerate() {
                *dv = local_sum(&s.contrib, neighbours.start + jj);
            }
            displacement.set(j, q.distance(original[j]));
            clamped_moves += usize::from(clamped);
            progress = old_local - new_local > STALL_REL_IMPROVEMENT * old_local;
            if progress {
                // The objectives of the points whose supports overlap have changed.
                candidates[neighbours.clone()].copy_from_slice(&movable[neighbours]);
            }
            moves.push(Move {
                iteration: iterations,
                index: j,
                distance: dv.length(),
                before: old_local,
                after: new_local,
            });
        }
        if !progress && params.skip_stalled {
            candidates[j] = false;
        }
        recent.push(j);
        history.push(HistoryRow {
            iteration: iterations,
            measure,
            max_distance: displacement.max(),
        });
        if measure == 0.0 {
            stopped = true;
        } else if params.window > 0 && iterations >= params.window {
            let earlier = history[iterations - params.window].measure;
            if earlier - measure <= params.min_rel_improvement * earlier {
                stopped = true;
            }
        }
    }

    let status = if moves.is_empty() {
        FairStatus::NoChange
    } else if !stopped {
        FairStatus::IterationLimit
    } else if clamped_moves > 0 {
        FairStatus::ToleranceLimited
    } else {
        FairStatus::Converged
    };
    let measure_after: f64 = s.contrib.iter().sum();
    let curvature_after = s
        .hom
        .iter()
        .zip(&s.wd)
        .map(|(a, w)| curvature_h(a, w))
        .collect();
    let max_curve_deviation = s
        .hom
        .iter()
        .zip(&s.wd)
        .zip(&position0)
        .map(|((a, w), p0)| (a[0] / w[0]).to_point().distance(*p0))
        .fold(0.0, f64::max);
    let mut notes = Vec::new();
    if clamped_moves > 0 {
        notes.push(format!(
            "{clamped_moves} of {} accepted moves were shortened to keep the control points \
             within δ = {delta:.6e} of the original",
            moves.len()
        ));
    }
    let report = SalviReport {
        local: LocalReport {
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
        },
        samples: s.t,
        target: s.target,
        curvature_before: kappa0,
        curvature_after,
        max_curve_deviation,
    };
    Ok((cur, report))
}

/// The mean length of the control-polygon legs at `j` (one leg at an end).
fn mean_leg(d: &[Point], j: usize) -> f64 {
    let mut sum = 0.0;
    let mut count = 0.0;
    if j > 0 {
        sum += d[j].distance(d[j - 1]);
        count += 1.0;
    }
    if j + 1 < d.len() {
        sum += d[j].distance(d[j + 1]);
        count += 1.0;
    }
    if count > 0.0 { sum / count } else { 0.0 }
}

/// The `salvi` method for point input: fit a B-spline, fair it, evaluate it at the fitted
/// parameters.
#[derive(Clone, Copy, Debug, Default)]
pub struct Salvi;

static PARAMS: [ParamSpec; 11] = [
    ParamSpec {
        name: "samples",
        default: "auto",
        doc: "number of curvature samples N, 4..=20000 (auto: max(200, 8 per knot span))",
    },
    ParamSpec {
        name: "smoother",
        default: "average",
        doc: "target curvature: average (moving average) or bspline (least-squares fit of κ(s))",
    },
    ParamSpec {
        name: "half_width",
        default: "auto",
        doc: "moving-average half-width in samples (auto: N/20; at most 20000)",
    },
    ParamSpec {
        name: "passes",
        default: "3",
        doc: "moving-average passes",
    },
    ParamSpec {
        name: "target_coefficients",
        default: "auto",
        doc: "coefficients of the bspline target fit (auto: max(4, N/20); at most 20000)",
    },
    ParamSpec {
        name: "pin_ends",
        default: "false",
        doc: "make the target equal the curvature at both ends",
    },
    ParamSpec {
        name: "tabu",
        default: "4",
        doc: "length R of the recently-moved list",
    },
    ParamSpec {
        name: "window",
        default: "50",
        doc: "stop when the measure improved < 0.1% over this many iterations (0: never; at most 1000000)",
    },
    FIT_PARAMS[0],
    FIT_PARAMS[1],
    FIT_PARAMS[2],
];

impl FairMethod for Salvi {
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
    parameters.insert("samples".into(), report.samples.len().into());
    parameters.insert(
        "smoother".into(),
        Value::from(match params.smoother {
            Smoother::BSplineFit { .. } => "bspline",
            _ => "average",
        }),
    );
    parameters.insert("pin_ends".into(), params.pin_ends.into());
    parameters.insert("tabu".into(), params.tabu_length.into());
    parameters.insert("window".into(), params.window.into());
    parameters.insert("max_iterations".into(), params.max_iterations.into());
    insert_common(&mut parameters, &report.local);
    parameters.insert(
        "max_curve_deviation".into(),
        json_f64(report.max_curve_deviation),
    );
    let mut notes = fitted.notes;
    notes.extend(report.local.notes);
    Ok(Outcome {
        solver: None,
        points,
        status: report.local.status,
        iterations: report.local.iterations,
        moves: report.local.moves,
        history: report.local.history,
        parameters,
        notes,
        curve: Some(faired),
        tangents: None,
        // Held end control points are the clamped curve's end points.
        ends_held: (!params.free_ends).then_some(super::EndFix::Position),
    })
}

/// Copy the common numbers of a [`LocalReport`] into the report parameters.
pub(crate) fn insert_common(parameters: &mut Map<String, Value>, r: &LocalReport) {
    parameters.insert("measure_before".into(), json_f64(r.measure_before));
    parameters.insert("measure_after".into(), json_f64(r.measure_after));
    parameters.insert("accepted_moves".into(), r.accepted_moves.into());
    parameters.insert("clamped_moves".into(), r.clamped_moves.into());
    parameters.insert(
        "max_control_displacement".into(),
        json_f64(r.max_control_displacement),
    );
}

/// The parameters of a run; `tolerance` (δ) and `free_ends` come from the fitted input. The
/// smoother parameters are all checked, whichever smoother is chosen.
fn salvi_params(
    options: &FairOptions,
    tolerance: Option<f64>,
    free_ends: bool,
) -> Result<SalviParams> {
    let samples = options.param_auto_usize_in("samples", MIN_SAMPLES, MAX_SAMPLES)?;
    let auto_usize = |key: &str, lo: usize| options.param_auto_usize_in(key, lo, MAX_SAMPLES);
    let coefficients = auto_usize("target_coefficients", MIN_TARGET_COEFFICIENTS)?;
    let half_width = auto_usize("half_width", 0)?;
    let passes = options.param_usize_in("passes", DEFAULT_PASSES, 0, 1000)?;
    let smoother = match options.param_choice("smoother", "average", &["average", "bspline"])? {
        "bspline" => Smoother::BSplineFit { coefficients },
        _ => Smoother::MovingAverage { half_width, passes },
    };
    let max_iterations = options.iterations_or(DEFAULT_MAX_ITERATIONS);
    Ok(SalviParams {
        samples,
        smoother,
        pin_ends: options.param_bool("pin_ends", false)?,
        tolerance,
        tabu_length: options.param_usize_in("tabu", DEFAULT_TABU_LENGTH, 0, 1000)?,
        max_iterations,
        window: options.param_usize_in("window", DEFAULT_WINDOW, 0, super::MAX_ITERATIONS)?,
        min_rel_improvement: WINDOW_MIN_REL_IMPROVEMENT,
        free_ends,
        held_ends: options.fix_ends.held().max(1),
        skip_stalled: true,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moving_average_vector() {
        // Vector sv.target_smoothing.
        let k = [0.0, 1.0, 0.0, 2.0, 1.0, 3.0, 2.0, 2.0, 5.0, 4.0];
        let g = moving_average(&k, 1, 1);
        let exp = [
            0.5,
            1.0 / 3.0,
            1.0,
            1.0,
            2.0,
            2.0,
            7.0 / 3.0,
            3.0,
            11.0 / 3.0,
            4.5,
        ];
        for (a, b) in g.iter().zip(exp) {
            assert!((a - b).abs() <= 1e-12 + 1e-12 * b.abs());
        }
        assert!((target_measure(&k, &g) - 7.83333333333).abs() < 1e-10);
        assert_eq!(moving_average(&k, 3, 0), k);
        assert_eq!(moving_average(&[], 3, 2), Vec::<f64>::new());
    }

    #[test]
    fn homogeneous_curvature_matches_the_direct_formula() {
        let a = [
            Vec2::new(1.0, 2.0),
            Vec2::new(0.3, -0.4),
            Vec2::new(0.2, 0.5),
        ];
        let direct = a[1].cross(a[2]) / a[1].length().powi(3);
        assert!((curvature_h(&a, &[1.0, 0.0, 0.0]) - direct).abs() <= 1e-15 * direct.abs());
    }
}
