//! Pieces shared by the local fairing methods that move one B-spline control point at a time:
//! Salvi & Várady's target-curvature fairing ([`super::salvi`]) and Eck & Hadenfeld's local
//! energy fairing ([`super::eck_hadenfeld`]), both as described in
//! `../shared/papers/salvi-varady-local-fairing.txt` (§3.2 eqs 9–11, §4.2) and specified in
//! `../shared/spec/ALGORITHMS.md` §3.
//!
//! - [`support_ranges`]: the samples inside the support `[u_j, u_{j+k})` of each basis
//!   function, the last span closed (docs/algorithms/salvi-varady.md §3 step 5);
//! - [`RecentList`] and [`select_candidate`]: the largest local deviation among the control
//!   points not moved recently, a FIFO tabu list of length R (default
//!   [`DEFAULT_TABU_LENGTH`]) that is cleared when every candidate is in it
//!   (docs/algorithms/salvi-varady.md §3 step 5);
//! - [`clamp_to_original`]: the eq-11 clamp `|d_r − d_r⁰| ≤ δ` relative to the **original**
//!   control point (docs/algorithms/salvi-varady.md §3 step 7), which keeps the curve within δ of
//!   the original by the convex-hull property and the partition of unity (eq 10);
//! - [`principal_curvatures`] (docs/algorithms/README.md §0.6) for the later surface version;
//! - [`LocalReport`]: what a run did, as both methods' library entry points return it.
//!
//! The selection, the tabu list and the clamp do not know the dimension of a control point
//! (the clamp works on `[f64; D]`), so the surface version can reuse them.

use std::collections::VecDeque;
use std::ops::Range;

use serde::Serialize;

use super::params::{Auto, Flag, Number, Param};
use super::{FairOptions, FairStatus, HistoryRow, Move, Outcome};
use crate::curve::Curve;
use crate::error::{Error, Result};
use crate::geom::{BBox, Point, PointSeq};
use crate::spline::{BSplineCurve, KnotVector, Parametrization};

/// Length R of the recently-moved list (docs/algorithms/salvi-varady.md §3 step 5).
pub(crate) const DEFAULT_TABU_LENGTH: usize = 4;

/// Without a tolerance, δ is this fraction of the diagonal of the bounding box of the data
/// (the input points, or the control points of a B-spline given directly).
pub(crate) const DEFAULT_TOLERANCE_REL: f64 = 0.01;

/// δ used for point input is reduced by this many units of `f64::EPSILON` times the
/// coordinate magnitude, so that rounding in the clamp and in evaluation cannot push an output
/// point past the tolerance the user asked for.
pub(crate) const ROUNDING_MARGIN_ULPS: f64 = 64.0;

/// Degree of the B-spline fitted to point input (global interpolation, docs/algorithms/README.md
/// §0.5).
pub(crate) const DEFAULT_FIT_DEGREE: usize = 3;

/// The eq-11 clamp (docs/algorithms/salvi-varady.md §3 step 7): when `|proposed − original| > δ`,
/// return `original + δ·(proposed − original)/|proposed − original|`, else `proposed`. The flag
/// says whether the clamp was active.
///
/// `original` is the control point of the *unfaired* curve, so a run of many moves never
/// drifts farther than δ from it.
pub(crate) fn clamp_to_original<const D: usize>(
    original: &[f64; D],
    proposed: &[f64; D],
    delta: f64,
) -> ([f64; D], bool) {
    let mut diff = [0.0; D];
    for k in 0..D {
        diff[k] = proposed[k] - original[k];
    }
    let len = diff.iter().map(|d| d * d).sum::<f64>().sqrt();
    if len > delta {
        let scale = delta / len;
        let mut out = [0.0; D];
        for k in 0..D {
            out[k] = original[k] + diff[k] * scale;
        }
        (out, true)
    } else {
        (*proposed, false)
    }
}

/// [`clamp_to_original`] for planar points.
pub(crate) fn clamp_point(original: Point, proposed: Point, delta: f64) -> (Point, bool) {
    let (p, clamped) =
        clamp_to_original(&[original.x, original.y], &[proposed.x, proposed.y], delta);
    (Point::from(p), clamped)
}

/// For every basis function `N_j` of a degree-`p` B-spline with `n_ctrl` control points, the
/// index range of the samples inside its support `[u_j, u_{j+p+1})`, the last non-empty span
/// closed (docs/algorithms/salvi-varady.md §3 step 5). A sample `t` belongs to `N_j` exactly when
/// `j` is one of the `p + 1` functions of the span [`KnotVector::find_span`] returns for `t`, i.e.
/// when moving `d_j` can change the curve at `t`. Functions whose support holds no sample get an
/// empty range.
///
/// # Errors
/// [`Error::InvalidParameter`] when the samples are not finite and non-decreasing, or the
/// knot vector does not fit `degree` and `n_ctrl`.
pub(crate) fn support_ranges(
    knots: &KnotVector,
    degree: usize,
    n_ctrl: usize,
    samples: &[f64],
) -> Result<Vec<Range<usize>>> {
    if n_ctrl < degree + 1 || knots.len() != n_ctrl + degree + 1 {
        return Err(Error::InvalidParameter {
            name: "knots".into(),
            reason: format!(
                "{} knots do not fit {n_ctrl} control points of degree {degree}",
                knots.len()
            ),
        });
    }
    if let Some(i) = samples.iter().position(|t| !t.is_finite()) {
        return Err(Error::InvalidParameter {
            name: "samples".into(),
            reason: format!("sample {i} is not finite"),
        });
    }
    if let Some(i) = samples.windows(2).position(|w| w[1] < w[0]) {
        return Err(Error::InvalidParameter {
            name: "samples".into(),
            reason: format!(
                "samples must be non-decreasing: sample {} < sample {i}",
                i + 1
            ),
        });
    }
    let mut ranges = vec![0..0; n_ctrl];
    for (i, &t) in samples.iter().enumerate() {
        let span = knots.find_span(degree, n_ctrl, t);
        for r in &mut ranges[span - degree..=span] {
            if r.start == r.end {
                *r = i..i + 1;
            } else {
                r.end = i + 1;
            }
        }
    }
    Ok(ranges)
}

/// `n ≥ 2` uniform parameters `t_i = t_min + i (t_max − t_min)/(n − 1)` over `domain`, the last
/// one exactly `t_max` (docs/algorithms/salvi-varady.md §3 step 2). `n < 2` gives `[t_min]` or
/// nothing.
pub(crate) fn uniform_samples(domain: (f64, f64), n: usize) -> Vec<f64> {
    let (a, b) = domain;
    match n {
        0 => Vec::new(),
        1 => vec![a],
        _ => {
            let mut t: Vec<f64> = (0..n)
                .map(|i| a + i as f64 * (b - a) / (n - 1) as f64)
                .collect();
            t[n - 1] = b;
            t
        }
    }
}

/// The recently-moved list of docs/algorithms/salvi-varady.md §3 step 5: a FIFO of control-point
/// indices of fixed capacity R (the oldest entry leaves when a new one arrives at capacity). It
/// keeps the selection from moving the same point over and over, the deadlock the paper warns
/// about.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct RecentList {
    items: VecDeque<usize>,
    capacity: usize,
}

impl RecentList {
    /// An empty list of capacity `capacity` (0 disables it).
    pub(crate) fn new(capacity: usize) -> RecentList {
        RecentList {
            items: VecDeque::with_capacity(capacity),
            capacity,
        }
    }

    /// Record a move of control point `j`.
    pub(crate) fn push(&mut self, j: usize) {
        if self.capacity == 0 {
            return;
        }
        if self.items.len() == self.capacity {
            self.items.pop_front();
        }
        self.items.push_back(j);
    }

    /// Whether `j` was moved recently.
    pub(crate) fn contains(&self, j: usize) -> bool {
        self.items.contains(&j)
    }

    /// Forget every entry.
    pub(crate) fn clear(&mut self) {
        self.items.clear();
    }

    /// Whether the list is empty.
    #[cfg(test)]
    pub(crate) fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// The entries, oldest first.
    #[cfg(test)]
    pub(crate) fn iter(&self) -> impl Iterator<Item = usize> + '_ {
        self.items.iter().copied()
    }
}

/// The next control point to move (docs/algorithms/salvi-varady.md §3 step 5): the movable index
/// with the largest `deviation` that is not in `recent`. When every movable index is in `recent`,
/// the list is cleared and the largest deviation overall wins. Ties go to the lowest index; NaN
/// deviations rank below every number. `None` when nothing is movable.
///
/// # Panics
/// If `movable` is shorter than `deviation`.
pub(crate) fn select_candidate(
    deviation: &[f64],
    movable: &[bool],
    recent: &mut RecentList,
) -> Option<usize> {
    let pick = |recent: &RecentList| {
        let mut best: Option<(usize, f64)> = None;
        for (j, &d) in deviation.iter().enumerate() {
            if !movable[j] {
                continue;
            }
            let d = if d.is_nan() { f64::NEG_INFINITY } else { d };
            // The list is consulted only for a point that would win.
            if best.is_none_or(|(_, b)| d > b) && !recent.contains(j) {
                best = Some((j, d));
            }
        }
        best.map(|(j, _)| j)
    };
    match pick(recent) {
        Some(j) => Some(j),
        None => {
            recent.clear();
            pick(recent)
        }
    }
}

/// Principal curvatures of a parametric surface from its first and second partial
/// derivatives (docs/algorithms/README.md §0.6): `n = S_u × S_v / |S_u × S_v|`, the fundamental
/// forms E, F, G and L, M, N, `K = (LN − M²)/(EG − F²)`, `H = (EN − 2FM + GL)/(2(EG − F²))`,
/// `κ1,2 = H ± sqrt(max(H² − K, 0))`. Signs follow the orientation of `n`.
///
/// `None` where the surface is singular (`S_u × S_v = 0`, or non-finite input).
pub(crate) fn principal_curvatures(
    su: [f64; 3],
    sv: [f64; 3],
    suu: [f64; 3],
    suv: [f64; 3],
    svv: [f64; 3],
) -> Option<PrincipalCurvatures> {
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = [
        su[1] * sv[2] - su[2] * sv[1],
        su[2] * sv[0] - su[0] * sv[2],
        su[0] * sv[1] - su[1] * sv[0],
    ];
    let len = dot(cross, cross).sqrt();
    if !(len > 0.0 && len.is_finite()) {
        return None;
    }
    let n = [cross[0] / len, cross[1] / len, cross[2] / len];
    let (e, f, g) = (dot(su, su), dot(su, sv), dot(sv, sv));
    let (l, m, nn) = (dot(suu, n), dot(suv, n), dot(svv, n));
    let det = e * g - f * f;
    let k = (l * nn - m * m) / det;
    let h = (e * nn - 2.0 * f * m + g * l) / (2.0 * det);
    let root = (h * h - k).max(0.0).sqrt();
    let out = PrincipalCurvatures {
        kappa1: h + root,
        kappa2: h - root,
        normal: n,
    };
    (out.kappa1.is_finite() && out.kappa2.is_finite()).then_some(out)
}

/// The result of [`principal_curvatures`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PrincipalCurvatures {
    /// The larger principal curvature κ1.
    pub kappa1: f64,
    /// The smaller principal curvature κ2.
    pub kappa2: f64,
    /// The unit normal `S_u × S_v / |S_u × S_v|` that fixes the signs.
    pub normal: [f64; 3],
}

/// What a local fairing run did: the library entry points return it next to the faired
/// curve, and the [`super::FairMethod`] wrappers copy it into the [`super::FairReport`].
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct LocalReport {
    /// How the run ended.
    pub status: FairStatus,
    /// Iterations performed: one selected control point each, moved or not.
    pub iterations: usize,
    /// Moves accepted (the measure decreased).
    pub accepted_moves: usize,
    /// Accepted moves that the eq-11 clamp shortened.
    pub clamped_moves: usize,
    /// The method's measure of the input curve.
    pub measure_before: f64,
    /// The method's measure of the result.
    pub measure_after: f64,
    /// The δ that bounded every control point's distance from its original position.
    pub tolerance: f64,
    /// The largest control-point distance from the original: an upper bound of the distance
    /// between the two curves at equal parameters (eq 10).
    pub max_control_displacement: f64,
    /// One row per iteration, after row 0 for the input: the measure and the largest
    /// control-point displacement so far (the paper's Table 1).
    pub history: Vec<HistoryRow>,
    /// The accepted moves in order: control-point index, distance moved, and the measure
    /// before and after (local to the point's support for `salvi`, global for
    /// `eck-hadenfeld`).
    pub moves: Vec<Move>,
    /// Remarks.
    pub notes: Vec<String>,
}

impl LocalReport {
    /// How a run of a local method ended: `no_change` when it accepted no move,
    /// `iteration_limit` when no stopping rule ended it (`stopped` false), `tolerance_limited`
    /// when the clamp shortened an accepted move, else `converged`.
    pub(crate) fn status_of(moved: bool, stopped: bool, clamped_moves: usize) -> FairStatus {
        if !moved {
            FairStatus::NoChange
        } else if !stopped {
            FairStatus::IterationLimit
        } else if clamped_moves > 0 {
            FairStatus::ToleranceLimited
        } else {
            FairStatus::Converged
        }
    }

    /// The method's [`Outcome`] from this report: the output `points`, the report's
    /// `parameters` and the `notes` so far (the run's own notes follow them) and the faired
    /// `curve`. Unless `free_ends`, the end control points were held, and they are the clamped
    /// curve's end points.
    pub(crate) fn into_outcome(
        self,
        points: Vec<Point>,
        parameters: serde_json::Map<String, serde_json::Value>,
        mut notes: Vec<String>,
        curve: Option<BSplineCurve>,
        free_ends: bool,
    ) -> Outcome {
        notes.extend(self.notes);
        Outcome {
            solver: None,
            pressed: None,
            points,
            status: self.status,
            iterations: self.iterations,
            moves: self.moves,
            history: self.history,
            parameters,
            notes,
            curve,
            tangents: None,
            // Held end control points are the clamped curve's end points.
            ends_held: (!free_ends).then_some(super::EndFix::Position),
        }
    }
}

/// The largest of a set of per-index values under point updates, with the maximum recomputed
/// only when the current maximum decreases.
#[derive(Clone, Debug)]
pub(crate) struct RunningMax {
    values: Vec<f64>,
    max: f64,
    argmax: usize,
}

impl RunningMax {
    /// All zeros.
    pub(crate) fn zeros(n: usize) -> RunningMax {
        RunningMax {
            values: vec![0.0; n],
            max: 0.0,
            argmax: 0,
        }
    }

    /// Set entry `j`.
    pub(crate) fn set(&mut self, j: usize, v: f64) {
        self.values[j] = v;
        if v >= self.max {
            self.max = v;
            self.argmax = j;
        } else if j == self.argmax {
            let (mut max, mut argmax) = (0.0, 0);
            for (i, &x) in self.values.iter().enumerate() {
                if x > max {
                    max = x;
                    argmax = i;
                }
            }
            self.max = max;
            self.argmax = argmax;
        }
    }

    /// The maximum.
    pub(crate) fn max(&self) -> f64 {
        self.max
    }
}

/// Movable control points: all but `held` at each end (docs/algorithms/salvi-varady.md §3 step 5:
/// boundary control points are excluded, as the paper recommends; `held` is 0 with `free_ends`, 1
/// by default, 2 or 3 with `--fix-ends=tangent` / `curvature`, which keep the clamped curve's end
/// tangents and curvatures).
pub(crate) fn movable_mask(n_ctrl: usize, held: usize) -> Vec<bool> {
    let mut m = vec![true; n_ctrl];
    let held = held.min(n_ctrl);
    m[..held].fill(false);
    m[n_ctrl - held..].fill(false);
    m
}

/// Control points held at each end: none with `free_ends`, else those `--fix-ends` asks for
/// (at least the end points).
pub(crate) fn held_control_points(free_ends: bool, held_ends: usize) -> usize {
    if free_ends { 0 } else { held_ends.max(1) }
}

/// δ of a library call: the given tolerance (checked positive and finite) or
/// [`DEFAULT_TOLERANCE_REL`] times the diagonal of the control points' bounding box.
pub(crate) fn resolve_tolerance(tolerance: Option<f64>, curve: &BSplineCurve) -> Result<f64> {
    match tolerance {
        Some(d) if d.is_finite() && d > 0.0 => Ok(d),
        Some(d) => Err(Error::InvalidParameter {
            name: "tolerance".into(),
            reason: format!("must be a positive finite number, got {d}"),
        }),
        None => {
            let diag = BBox::from_points(curve.control_points()).map_or(0.0, |b| b.diagonal());
            if diag > 0.0 {
                Ok(DEFAULT_TOLERANCE_REL * diag)
            } else {
                Err(Error::Degenerate(
                    "all control points coincide, so there is no default tolerance".into(),
                ))
            }
        }
    }
}

/// The degree of the B-spline fitted to point input ([`DEFAULT_FIT_DEGREE`]).
pub(crate) const FIT_DEGREE: Param<Number<usize>> = Param {
    name: "degree",
    kind: Number {
        default: DEFAULT_FIT_DEGREE,
        min: 2,
        max: 5,
    },
    doc: "degree of the B-spline fitted to point input (2..=5)",
};

/// The control points of the fit to point input (`auto`: interpolate); more than the degree,
/// and at most the number of points ([`fit_input`] narrows the range to the input's).
pub(crate) const CONTROL_POINTS: Param<Auto<usize>> = Param {
    name: "control_points",
    kind: Auto {
        min: FIT_DEGREE.kind.min + 1,
        max: usize::MAX,
    },
    doc: "auto: interpolate the points; N: least-squares fit with N control points",
};

/// Let the end control points move ([`FittedInput::free_ends`]).
pub(crate) const FREE_ENDS: Param<Flag> = Param {
    name: "free_ends",
    kind: Flag { default: false },
    doc: "let the first and last control points move too (ignored with --fix-ends)",
};

/// The length R of the recently-moved list ([`DEFAULT_TABU_LENGTH`]).
pub(crate) const TABU: Param<Number<usize>> = Param {
    name: "tabu",
    kind: Number {
        default: DEFAULT_TABU_LENGTH,
        min: 0,
        max: 1000,
    },
    doc: "length R of the recently-moved list",
};

/// Check the values of the fit parameters ([`FIT_DEGREE`], [`CONTROL_POINTS`], [`FREE_ENDS`])
/// without an input: the degree, the control-point count against the degree (the bound by the
/// number of points is checked by [`fit_input`]), and `free_ends`.
///
/// # Errors
/// [`Error::InvalidParameter`].
pub(crate) fn check_fit_params(options: &FairOptions) -> Result<()> {
    let degree = fit_degree(options)?;
    options.get(&CONTROL_POINTS.within(degree + 1, usize::MAX))?;
    options.get(&FREE_ENDS).map(|_| ())
}

/// The `degree` of the B-spline fitted to point input, 2..=5.
pub(crate) fn fit_degree(options: &FairOptions) -> Result<usize> {
    options.get(&FIT_DEGREE)
}

/// Point input fitted with a B-spline, and what the fit means for the tolerance.
#[derive(Clone, Debug)]
pub(crate) struct FittedInput {
    /// The fitted curve.
    pub curve: BSplineCurve,
    /// The data parameters: `curve.eval(params[k])` is the fitted point k.
    pub params: Vec<f64>,
    /// δ for the fairing run.
    pub delta: f64,
    /// Whether the first and last control points may move.
    pub free_ends: bool,
    /// Control points held at each end when not `free_ends` (`--fix-ends`; at least 1).
    pub held_ends: usize,
    /// Remarks for the report.
    pub notes: Vec<String>,
    /// Parameters as used.
    pub parameters: serde_json::Map<String, serde_json::Value>,
}

/// Fit point input with a B-spline (docs/algorithms/README.md §0.5): global interpolation with
/// chord-length parameters by default, least squares with `control_points = N`; and choose δ.
///
/// With a tolerance `D`, δ = `D − residual − margin` ([`ROUNDING_MARGIN_ULPS`]), so that an
/// output point (the faired curve at the input's parameter) is within `D` of the input point:
/// the faired curve is within δ of the fitted curve (eq 10) and the fitted curve within
/// `residual` of the point. Without one, δ = [`DEFAULT_TOLERANCE_REL`] × the bounding-box
/// diagonal of the points.
///
/// # Errors
/// Parameter errors, and those of [`BSplineCurve::interpolate`] /
/// [`BSplineCurve::approximate`].
pub(crate) fn fit_input(input: &PointSeq, options: &FairOptions) -> Result<FittedInput> {
    let points = input.points();
    let degree = fit_degree(options)?;
    let mut notes = Vec::new();
    let mut parameters = serde_json::Map::new();
    let (curve, params, fit) = match options
        .get(&CONTROL_POINTS.within(degree + 1, points.len()))?
    {
        None => {
            let (c, t) = BSplineCurve::interpolate(points, degree, Parametrization::ChordLength)?;
            (c, t, "interpolation")
        }
        Some(n) => {
            let (c, t) =
                BSplineCurve::approximate(points, degree, n, Parametrization::ChordLength)?;
            (c, t, "least_squares")
        }
    };
    let residual = points
        .iter()
        .zip(&params)
        .map(|(q, &t)| q.distance(curve.eval(t)))
        .fold(0.0, f64::max);
    let free = options.get(&FREE_ENDS)?;
    if free && options.fix_ends.is_fixed() {
        notes.push("free_ends is ignored because the ends are fixed (--fix-ends)".to_string());
    }
    let free_ends = free && !options.fix_ends.is_fixed();
    let magnitude = points
        .iter()
        .chain(curve.control_points())
        .map(|p| p.x.abs().max(p.y.abs()))
        .fold(0.0, f64::max);
    let margin = ROUNDING_MARGIN_ULPS * f64::EPSILON * magnitude;
    let delta = match options.tolerance {
        Some(tol) => {
            let d = tol - residual - margin;
            if d > 0.0 {
                d
            } else {
                notes.push(format!(
                    "the {fit} fit alone deviates {residual:.6e} from the points, which is not \
                     below the tolerance {tol:.6e}; fairing within δ = tolerance of the fit \
                     (use more control_points)"
                ));
                tol
            }
        }
        None => {
            let d = DEFAULT_TOLERANCE_REL * input.scale();
            notes.push(format!(
                "no tolerance given: δ = {DEFAULT_TOLERANCE_REL} × bounding-box diagonal = {d:.6e}"
            ));
            d
        }
    };
    parameters.insert("fit".into(), fit.into());
    FIT_DEGREE.write(&mut parameters, degree);
    CONTROL_POINTS.write(&mut parameters, Some(curve.control_points().len()));
    parameters.insert("fit_residual".into(), json_f64(residual));
    parameters.insert("delta".into(), json_f64(delta));
    FREE_ENDS.write(&mut parameters, free_ends);
    Ok(FittedInput {
        curve,
        params,
        delta,
        free_ends,
        held_ends: options.fix_ends.held().max(1),
        notes,
        parameters,
    })
}

/// B-spline input taken as it is (no fit): the data parameters are the Greville abscissae
/// `ξ_i` (one per control point, the curve's natural correspondence points), the "input
/// points" are the curve there, and δ is the tolerance, or [`DEFAULT_TOLERANCE_REL`] × the
/// bounding-box diagonal of the control points without one. Returns the fitted-input record
/// and the sampled points as the sequence that displacements and metrics are measured on.
///
/// # Errors
/// [`crate::Error::DuplicatePoint`] and the like when the curve's points at consecutive
/// Greville abscissae coincide; parameter errors.
pub(crate) fn curve_input(
    curve: &BSplineCurve,
    options: &FairOptions,
) -> Result<(FittedInput, PointSeq)> {
    let p = curve.degree();
    let n = curve.control_points().len();
    let params = curve.knots().greville(p);
    let seq = PointSeq::open(params.iter().map(|&t| curve.eval(t)).collect())?;
    let mut notes = Vec::new();
    let free = options.get(&FREE_ENDS)?;
    let free_ends = free && !options.fix_ends.is_fixed();
    let delta = match options.tolerance {
        Some(tol) => tol,
        None => {
            let scale = BBox::from_points(curve.control_points()).map_or(0.0, |b| b.diagonal());
            let d = DEFAULT_TOLERANCE_REL * scale;
            notes.push(format!(
                "no tolerance given: δ = {DEFAULT_TOLERANCE_REL} × control-polygon diagonal = {d:.6e}"
            ));
            d
        }
    };
    let mut parameters = serde_json::Map::new();
    parameters.insert("fit".into(), "none (B-spline input)".into());
    FIT_DEGREE.write(&mut parameters, p);
    CONTROL_POINTS.write(&mut parameters, Some(n));
    parameters.insert("delta".into(), json_f64(delta));
    FREE_ENDS.write(&mut parameters, free_ends);
    Ok((
        FittedInput {
            curve: curve.clone(),
            params,
            delta,
            free_ends,
            held_ends: options.fix_ends.held().max(1),
            notes,
            parameters,
        },
        seq,
    ))
}

/// Run a control-point method on a given B-spline (see [`curve_input`]): `run` gets the
/// curve as its "fit" and the points it is measured against.
///
/// # Errors
/// Those of [`curve_input`] and of `run`.
pub(crate) fn on_curve(
    curve: &BSplineCurve,
    options: &FairOptions,
    run: impl FnOnce(FittedInput, &PointSeq, &FairOptions) -> Result<Outcome>,
) -> Result<(PointSeq, Outcome)> {
    let (fitted, seq) = curve_input(curve, options)?;
    let out = run(fitted, &seq, options)?;
    Ok((seq, out))
}

/// The output points for point input: the faired curve at the fitted parameters, same count
/// and order; with `fix_ends` the first and last are the input's own (the curve's ends are
/// the fixed end control points of a clamped fit, equal to them up to rounding).
pub(crate) fn output_points(
    faired: &BSplineCurve,
    fitted: &FittedInput,
    input: &PointSeq,
    fix_ends: bool,
) -> Vec<Point> {
    let mut out: Vec<Point> = fitted.params.iter().map(|&t| faired.eval(t)).collect();
    let pts = input.points();
    if fix_ends && !out.is_empty() {
        let n = out.len();
        out[0] = pts[0];
        out[n - 1] = pts[n - 1];
    }
    out
}

/// Copy the common numbers of a [`LocalReport`] into the report parameters.
pub(crate) fn insert_common(
    parameters: &mut serde_json::Map<String, serde_json::Value>,
    r: &LocalReport,
) {
    parameters.insert("measure_before".into(), json_f64(r.measure_before));
    parameters.insert("measure_after".into(), json_f64(r.measure_after));
    parameters.insert("accepted_moves".into(), r.accepted_moves.into());
    parameters.insert("clamped_moves".into(), r.clamped_moves.into());
    parameters.insert(
        "max_control_displacement".into(),
        json_f64(r.max_control_displacement),
    );
}

/// A float as a JSON value (`null` when not finite).
pub(crate) fn json_f64(v: f64) -> serde_json::Value {
    serde_json::Number::from_f64(v).map_or(serde_json::Value::Null, serde_json::Value::Number)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clamp_eq11() {
        // Vector sv.clamp_eq11.
        let (p, c) = clamp_to_original(&[1.0, 2.0], &[4.0, 6.0], 2.5);
        assert!(c);
        assert!((p[0] - 2.5).abs() <= 1e-14 && (p[1] - 4.0).abs() <= 1e-14);
        let (p, c) = clamp_to_original(&[1.0, 2.0], &[1.3, 2.4], 2.5);
        assert!(!c);
        assert_eq!(p, [1.3, 2.4]);
        // Three dimensions and the boundary itself.
        let (p, c) = clamp_to_original(&[0.0, 0.0, 0.0], &[0.0, 3.0, 4.0], 5.0);
        assert!(!c);
        assert_eq!(p, [0.0, 3.0, 4.0]);
        let (p, c) = clamp_to_original(&[0.0, 0.0, 0.0], &[0.0, 6.0, 8.0], 5.0);
        assert!(c);
        assert!((p[1] - 3.0).abs() < 1e-15 && (p[2] - 4.0).abs() < 1e-15);
        let (p, _) = clamp_point(Point::new(1.0, 2.0), Point::new(4.0, 6.0), 2.5);
        assert!((p - Point::new(2.5, 4.0)).length() < 1e-14);
    }

    #[test]
    fn support_counts_vector() {
        // Vector sv.support_counts.
        let k = KnotVector::new(vec![
            0.0, 0.0, 0.0, 0.0, 0.2, 0.4, 0.6, 0.8, 1.0, 1.0, 1.0, 1.0,
        ]);
        let t = uniform_samples((0.0, 1.0), 200);
        let r = support_ranges(&k, 3, 8, &t).expect("ranges");
        let counts: Vec<usize> = r.iter().map(|r| r.len()).collect();
        assert_eq!(counts, [40, 80, 120, 160, 160, 120, 80, 40]);
        assert_eq!(r[0], 0..40);
        assert_eq!(r[7], 160..200);
        assert!(support_ranges(&k, 3, 8, &[0.5, 0.2]).is_err());
        assert!(support_ranges(&k, 3, 8, &[0.5, f64::NAN]).is_err());
        assert!(support_ranges(&k, 3, 9, &t).is_err());
    }

    #[test]
    fn support_of_unclamped_knots_and_empty_supports() {
        // Uniform (unclamped) knots: the domain is [u_3, u_8] = [3, 8].
        let k = KnotVector::new((0..12).map(f64::from).collect());
        let t = uniform_samples((3.0, 8.0), 11);
        let r = support_ranges(&k, 3, 8, &t).expect("ranges");
        // N_0 lives on [0, 4): samples 3.0 and 3.5.
        assert_eq!(r[0], 0..2);
        // N_7 lives on [7, 11): samples 7.0, 7.5 and the closed end 8.0.
        assert_eq!(r[7], 8..11);
        // Samples only in the first span leave later functions empty.
        let r = support_ranges(&k, 3, 8, &[3.0, 3.5]).expect("ranges");
        assert!(r[4].is_empty() && r[7].is_empty());
        assert_eq!(r[3], 0..2);
    }

    #[test]
    fn recent_list_is_a_fifo() {
        let mut l = RecentList::new(DEFAULT_TABU_LENGTH);
        for j in [1, 2, 3, 4, 5] {
            l.push(j);
        }
        assert_eq!(l.iter().collect::<Vec<_>>(), [2, 3, 4, 5]);
        assert!(!l.contains(1) && l.contains(5));
        l.clear();
        assert!(l.is_empty());
        let mut off = RecentList::new(0);
        off.push(3);
        assert!(!off.contains(3));
    }

    #[test]
    fn selection_skips_recent_and_clears_when_all_are_recent() {
        // Indices 0 and 5 (the largest) are boundary points.
        let dev = [9.0, 5.0, 7.0, 6.0, 8.0, 10.0];
        let movable = movable_mask(6, 1);
        let mut recent = RecentList::new(2);
        assert_eq!(select_candidate(&dev, &movable, &mut recent), Some(4));
        recent.push(4);
        assert_eq!(select_candidate(&dev, &movable, &mut recent), Some(2));
        recent.push(2);
        assert_eq!(select_candidate(&dev, &movable, &mut recent), Some(3));
        recent.push(3);
        // 4 left the FIFO of length 2.
        assert_eq!(select_candidate(&dev, &movable, &mut recent), Some(4));
        // All four candidates recent: the list is cleared and the largest wins.
        let mut recent = RecentList::new(4);
        for j in [1, 2, 3, 4] {
            recent.push(j);
        }
        assert_eq!(select_candidate(&dev, &movable, &mut recent), Some(4));
        assert!(recent.is_empty());
        // With free ends the boundary points compete too.
        assert_eq!(
            select_candidate(&dev, &movable_mask(6, 0), &mut recent),
            Some(5)
        );
        // NaN ranks last; nothing movable gives None.
        let dev = [0.0, f64::NAN, 1.0, 0.0];
        assert_eq!(
            select_candidate(&dev, &movable_mask(4, 1), &mut RecentList::new(4)),
            Some(2)
        );
        let mut recent = RecentList::new(4);
        assert_eq!(
            select_candidate(&[1.0, 2.0], &movable_mask(2, 1), &mut recent),
            None
        );
        assert_eq!(
            select_candidate(&[1.0, 2.0], &movable_mask(2, 0), &mut recent),
            Some(1)
        );
    }

    #[test]
    fn running_max_tracks_decreases() {
        let mut m = RunningMax::zeros(4);
        m.set(1, 3.0);
        m.set(2, 2.0);
        assert_eq!(m.max(), 3.0);
        m.set(1, 1.0);
        assert_eq!(m.max(), 2.0);
        m.set(3, 2.5);
        assert_eq!(m.max(), 2.5);
    }

    #[test]
    fn principal_curvatures_of_a_cylinder_and_a_singular_point() {
        // Cylinder of radius 2 about the y axis: S(u, v) = (2 sin u, v, 2 cos u) at u = 0.
        // n = S_u × S_v = (2,0,0)×(0,1,0) = (0,0,2)/2 = (0,0,1); S_uu = (0,0,−2): κ = −1/2, 0.
        let pc = principal_curvatures(
            [2.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, -2.0],
            [0.0; 3],
            [0.0; 3],
        )
        .expect("regular point");
        assert!((pc.kappa1 - 0.0).abs() < 1e-15 && (pc.kappa2 + 0.5).abs() < 1e-15);
        assert_eq!(pc.normal, [0.0, 0.0, 1.0]);
        assert!(
            principal_curvatures(
                [1.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [0.0; 3],
                [0.0; 3],
                [0.0; 3]
            )
            .is_none()
        );
    }
}
