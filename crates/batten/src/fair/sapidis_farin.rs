//! Sapidis–Farin fairing of a cubic B-spline by knot removal and reinsertion (method
//! `sapidis-farin`).
//!
//! References: N. Sapidis and G. Farin, *Automatic fairing algorithm for B-spline curves*,
//! Computer-Aided Design 22(2), 1990 (cited as "Farin and Sapides, 1989" in
//! `../shared/papers/kjellander-poliakoff-improved.txt`); G. Farin, *Curves and Surfaces for
//! CAGD*, the section on fairing by knot removal. The five papers of the spec do not cover
//! this method: the local formula below is derived here, and the greedy loop, stopping rule
//! and tolerance handling are those of the Kjellander–Poliakoff family
//! (docs/algorithms/kjellander-poliakoff.md §2.6, module [`super::kjellander`]).
//!
//! # The local formula (remove and reinsert one knot)
//!
//! Let the cubic have control points `P_i` and knots `u_i`, and let `u_j` be a simple
//! interior knot. Removing `u_j` gives a curve with knots `U' = U \ {u_j}` and control points
//! `R_i`; inserting `u_j` back (Boehm) gives `Q_i = α_i R_i + (1 − α_i) R_{i−1}` for
//! `i = j−3, j−2, j−1`, `Q_i = R_i` below and `Q_i = R_{i−1}` above, with
//!
//! ```text
//! α_{j−3} = (u_j − u_{j−3}) / (u_{j+1} − u_{j−3})
//! α_{j−2} = (u_j − u_{j−2}) / (u_{j+2} − u_{j−2})
//! α_{j−1} = (u_j − u_{j−1}) / (u_{j+3} − u_{j−1})
//! ```
//!
//! Matching `Q = P` from the left (`R_{j−4} = P_{j−4}`) and from the right
//! (`R_{j−1} = P_j`) gives the two reconstructions
//!
//! ```text
//! L = R_{j−3} = P_{j−4} + (P_{j−3} − P_{j−4}) / α_{j−3}
//! R = R_{j−2} = P_j     + (P_{j−1} − P_j)     / (1 − α_{j−1})
//! ```
//!
//! and reinserting `u_j` into the curve with `R_{j−4}, L, R, R_{j−1}` reproduces `P_{j−3}`
//! and `P_{j−1}` exactly and replaces the middle point only:
//!
//! ```text
//! P̃_{j−2} = (1 − α_{j−2}) L + α_{j−2} R
//!         = [(u_{j+2} − u_j) L + (u_j − u_{j−2}) R] / (u_{j+2} − u_{j−2})
//! ```
//!
//! (Farin's formula; the same step as [`crate::spline::RemovalRule::Middle`] removal followed by
//! reinsertion, which `tests/kp.rs` checks, computed here in O(1) without copying the curve
//! or measuring the deviation). The knot vector is unchanged, exactly one control point moves, and the
//! new curve lies in the spline space without `u_j`, so its third derivative no longer jumps
//! at `u_j`: for a cubic, being C³ at a simple knot is exactly removability. Only the jumps at
//! `u_{j−2} … u_{j+2}` (the knots of the support of `N_{j−2}`) change.
//!
//! # The algorithm
//!
//! 1. Interpolate the points with the clamped cubic B-spline ([`BSplineCurve::interpolate`]:
//!    chord-length parameters normalised to [0, 1], averaging knots).
//! 2. The bad knot is the interior knot with the largest jump `|r'''(u_j+) − r'''(u_j−)|`
//!    (the jump of the third derivative, which drives the jump in curvature slope; the
//!    original paper ranks by the curvature slope itself).
//! 3. Stop when every jump is at most `ε` (`epsilon`, or `threshold` × the input's largest
//!    jump; [`super::kjellander::DEFAULT_THRESHOLD`]).
//! 4. Remove and reinsert the bad knot (the formula above); repeat. One iteration is one
//!    knot; the iteration limit defaults to
//!    [`super::kjellander::DEFAULT_MOVES_PER_POINT`] × the number of interior knots.
//!
//! The output points are the faired curve evaluated at the input parameters (same count and
//! order), computed as `Q_k + Σ_i N_i(t_k)(P_i − P_i⁰)` so that points outside the support of
//! every moved control point are returned bit for bit. A move of `P_{j−2}` by `d` moves data
//! point `k` by `N_{j−2}(t_k)·d`; the tolerance (a hard bound on every point's distance from
//! its input position) scales `d` back so that no data point crosses it, and a knot whose
//! move would be cut below [`super::kjellander::MIN_STEP_FRACTION`] is skipped for the
//! next-worst (the greedy engine of `fair/engine/`, which the Kjellander–Poliakoff methods of
//! [`super::kjellander`] run on too). [`crate::fair::Move::index`] is the index of the
//! moved **control point**, `distance` its displacement.
//!
//! **Ends.** The interior knots are `u_4 … u_m`, so the moved control point is one of
//! `P_2 … P_{m−2}`: `P_0, P_1, P_{m−1}, P_m` never move, and the first and last data points
//! (which are `P_0` and `P_m` of the clamped curve, where every other basis function
//! vanishes) never move. `--fix-ends` therefore holds by construction, and so does
//! `--fix-ends=tangent` for the curve (its end tangents are `3(P_1 − P_0)/Δu` and the mirror).
//! `--fix-ends=curvature` also holds `P_2` and `P_{m−2}`, which keeps the curve's end
//! curvatures; the data points next to the ends can still move a little (the report's
//! `end_changes` measures the curve through the output points).
//!
//! **Closed curves** use the periodic cubic through the points (chord-length parameters,
//! knots at the parameters, a cyclic tridiagonal solve) in a wrapped form where every knot of
//! the period is an interior knot (`interpolate_closed`): every knot is a candidate, a move
//! changes every copy of its control point, and data points and chords are taken cyclically,
//! so the seam is not special (listing the points from another start gives the same result).
//! No B-spline is returned for a closed curve (the wrapped form is not a curve of its own).
//! At least [`MIN_CLOSED_POINTS`] points.
//!
//! Cost: a move is local (one control point, five jumps, the few data points in the support
//! of one basis function) and the bad knot is kept in a max-tree: O(log n) per move after
//! the O(n) interpolation. Measured with `benches/kp.rs` (release, loaded 2-core machine):
//! 6–8 µs per move at n = 10³ and 10⁴; the set-up costs about 2 µs per point.

use serde_json::json;

use super::engine::{
    EPSILON, JUMP_PARAMS, JUMP_ZERO_REL, LocalProblem, MIN_CHORD_REL, MaxTree, Threshold, drive,
    driven_parameters, max_fraction, move_limit, tolerance_radius,
};
use super::periodic::{PAD, interpolate_closed, period_index};
use super::{FairMethod, FairOptions, Outcome, ParamSpec};
use crate::curve::Curve;
use crate::error::{Error, Result};
use crate::geom::{BBox, Point, PointSeq, Vec2};
use crate::spline::{BSplineCurve, MAX_ORDER, Parametrization};

/// The degree this method works with.
const DEGREE: usize = 3;

/// Method `sapidis-farin`: fairing a cubic B-spline by removing and reinserting its worst
/// knot (see `docs/algorithms/kjellander-poliakoff.md`).
#[derive(Clone, Copy, Debug, Default)]
pub struct SapidisFarin;

/// `|r'''(u_j+) − r'''(u_j−)|` of a cubic at the knot index `j`, or 0 when it is within
/// [`JUMP_ZERO_REL`] of the size (L1) of the terms it is computed from (rounding noise).
fn jump_norm(curve: &BSplineCurve, j: usize) -> f64 {
    let u = curve.knots().as_slice();
    let ctrl = curve.control_points();
    let mut b = [[0.0; MAX_ORDER]; 4];
    let (mut jump, mut mag) = (Vec2::ZERO, 0.0);
    for (span, sign) in [(j, 1.0), (j - 1, -1.0)] {
        curve.basis_derivs(span, u[j], 3, &mut b);
        for (l, w) in b[3][..=DEGREE].iter().enumerate() {
            let p = ctrl[span - DEGREE + l].to_vec2();
            jump += p * (sign * w);
            mag += (p.x.abs() + p.y.abs()) * w.abs();
        }
    }
    let norm = jump.length();
    if norm <= JUMP_ZERO_REL * mag {
        0.0
    } else {
        norm
    }
}

/// Whether knot index `j` is a simple interior knot of a cubic with `ncp` control points.
fn is_simple_interior(u: &[f64], ncp: usize, j: usize) -> bool {
    j > DEGREE && j < ncp && u[j - 1] < u[j] && u[j] < u[j + 1]
}

/// Farin's formula (module docs): the new `P_{j−2}` after removing and reinserting `u_j`.
fn farin_point(ctrl: &[Point], u: &[f64], j: usize) -> Point {
    let a1 = (u[j] - u[j - 3]) / (u[j + 1] - u[j - 3]);
    let a2 = (u[j] - u[j - 2]) / (u[j + 2] - u[j - 2]);
    let a3 = (u[j] - u[j - 1]) / (u[j + 3] - u[j - 1]);
    let left = ctrl[j - 4] + (ctrl[j - 3] - ctrl[j - 4]) / a1;
    let right = ctrl[j] + (ctrl[j - 1] - ctrl[j]) / (1.0 - a3);
    left.lerp(right, a2)
}

/// Remove the simple interior knot `u_j` (knot index `j`) of a non-rational cubic B-spline
/// and reinsert it (Farin's local formula, see `docs/algorithms/kjellander-poliakoff.md`). The
/// result has the same knot vector, differs from `curve` in the control point `j − 2` only, and its
/// third derivative is continuous at `u_j`.
///
/// # Errors
/// [`Error::InvalidParameter`] for a degree other than 3, a rational curve, or a `j` that is
/// not a simple interior knot (`3 < j < control points`, `u_{j−1} < u_j < u_{j+1}`).
pub fn remove_reinsert_knot(curve: &BSplineCurve, j: usize) -> Result<BSplineCurve> {
    if curve.degree() != DEGREE || curve.weights().is_some() {
        return Err(Error::InvalidParameter {
            name: "curve".into(),
            reason: "knot removal fairing needs a non-rational cubic".into(),
        });
    }
    let u = curve.knots().as_slice();
    let ncp = curve.control_points().len();
    if !is_simple_interior(u, ncp, j) {
        return Err(Error::InvalidParameter {
            name: "j".into(),
            reason: format!("knot index {j} is not a simple interior knot"),
        });
    }
    let mut ctrl = curve.control_points().to_vec();
    ctrl[j - 2] = farin_point(&ctrl, u, j);
    curve.with_control_points(ctrl)
}

/// The interpolating cubic and the data it was built from, faired knot by knot. For a
/// closed curve (`period = Some(N)`) the cubic is the wrapped form of [`interpolate_closed`]:
/// one candidate per period knot (indices `PAD..PAD + N`), every copy of a moved control point
/// moved together, data points and chords taken cyclically.
#[derive(Clone, Debug)]
struct KnotState {
    curve: BSplineCurve,
    /// The data parameters.
    t: Vec<f64>,
    /// The input points.
    q: Vec<Point>,
    /// Current displacement of every data point from its input position.
    e: Vec<Vec2>,
    disp: MaxTree,
    min_chord: f64,
    /// Control point index and its full move.
    planned: (usize, Vec2),
    /// Data points in the support of the planned control point, with `N_c(t_k)` (summed
    /// over its copies on a closed curve).
    affected: Vec<(usize, f64)>,
    /// Control points held at each end (`--fix-ends`): the moved `P_{j−2}` must be at least
    /// this far from both ends. Two always (`P_0, P_1` never move). Unused when closed.
    held: usize,
    /// The number of points of a closed curve.
    period: Option<usize>,
    /// Refuse moves that make the curve through the data points worse near them
    /// ([`FairOptions::keep_clean`], the per-move clean-curve check).
    keep_clean: bool,
}

impl KnotState {
    /// The control point indices that hold the same control point as `c` (itself, and on a
    /// closed curve its copies one period away).
    fn copies(&self, c: usize) -> impl Iterator<Item = usize> + use<> {
        let len = self.curve.control_points().len();
        let (up, down) = match self.period {
            Some(n) => (c + n, c.wrapping_sub(n)),
            None => (usize::MAX, usize::MAX),
        };
        [c, up, down].into_iter().filter(move |&r| r < len)
    }

    /// The knot index that stands for knot `x` among the candidates.
    fn candidate_knot(&self, x: usize) -> usize {
        match self.period {
            Some(n) => PAD + period_index(x, n),
            None => x,
        }
    }

    /// `N_c(t_k)` (summed over the copies of `c`) for the data points in its support.
    fn support_values(&mut self, c: usize) {
        self.affected.clear();
        let u = self.curve.knots().as_slice();
        let mut b = [[0.0; MAX_ORDER]; 4];
        for r in self.copies(c) {
            let (lo, hi) = (u[r], u[r + DEGREE + 1]);
            let first = self.t.partition_point(|&x| x <= lo);
            let last = self.t.partition_point(|&x| x < hi);
            for k in first..last {
                let tk = self.t[k];
                let span = self.curve.find_span(tk);
                if r + DEGREE < span || r > span {
                    continue;
                }
                self.curve.basis_derivs(span, tk, 0, &mut b);
                let v = b[0][r + DEGREE - span];
                if v != 0.0 {
                    match self.affected.iter_mut().find(|(i, _)| *i == k) {
                        Some((_, w)) => *w += v,
                        None => self.affected.push((k, v)),
                    }
                }
            }
        }
    }

    /// The position of data point `k` after the fraction `s` of the planned move.
    fn moved(&self, k: usize, s: f64) -> Point {
        let d = self.planned.1;
        let w = self
            .affected
            .iter()
            .find(|(i, _)| *i == k)
            .map_or(0.0, |(_, n)| *n);
        self.q[k] + self.e[k] + d * (s * w)
    }

    /// Whether the planned fraction `s` keeps consecutive output points distinct.
    fn chords_stay(&self, s: f64) -> bool {
        let n = self.q.len();
        let pairs: Vec<(usize, usize)> = match self.period {
            Some(_) => self
                .affected
                .iter()
                .flat_map(|&(k, _)| [((k + n - 1) % n, k), (k, (k + 1) % n)])
                .collect(),
            None => match (self.affected.first(), self.affected.last()) {
                (Some(a), Some(b)) => {
                    let (from, to) = (a.0.saturating_sub(1), (b.0 + 1).min(n - 1));
                    (from..to).map(|k| (k, k + 1)).collect()
                }
                _ => Vec::new(),
            },
        };
        pairs
            .iter()
            .all(|&(i, k)| (self.moved(k, s) - self.moved(i, s)).length() >= self.min_chord)
    }

    /// The output points: `Q_k + Σ_i N_i(t_k)(P_i − P_i⁰)`.
    fn output(&self, initial: &[Point]) -> Result<Vec<Point>> {
        let delta: Vec<Point> = self
            .curve
            .control_points()
            .iter()
            .zip(initial)
            .map(|(p, p0)| (*p - *p0).to_point())
            .collect();
        let diff = self.curve.with_control_points(delta)?;
        Ok(self
            .q
            .iter()
            .zip(&self.t)
            .map(|(q, &t)| *q + diff.eval(t).to_vec2())
            .collect())
    }
}

impl LocalProblem for KnotState {
    fn slots(&self) -> usize {
        self.curve.knots().len()
    }

    fn is_candidate(&self, j: usize) -> bool {
        let ncp = self.curve.control_points().len();
        match self.period {
            Some(n) => (PAD..PAD + n).contains(&j),
            None => {
                is_simple_interior(self.curve.knots().as_slice(), ncp, j)
                    && j >= 2 + self.held
                    && j + self.held <= ncp + 1
            }
        }
    }

    fn badness(&self, j: usize) -> f64 {
        jump_norm(&self.curve, j)
    }

    fn plan(&mut self, j: usize, tolerance: Option<f64>) -> Option<f64> {
        let c = j - 2;
        let ctrl = self.curve.control_points();
        let new = farin_point(ctrl, self.curve.knots().as_slice(), j);
        let d = new - ctrl[c];
        if !d.is_finite() {
            return None;
        }
        self.support_values(c);
        let s = match tolerance {
            None => 1.0,
            Some(tol) => {
                let radius = tolerance_radius(tol);
                self.affected
                    .iter()
                    .map(|&(k, n)| max_fraction(self.e[k], d * n, radius))
                    .fold(1.0, f64::min)
            }
        };
        self.planned = (c, d);
        self.chords_stay(s).then_some(s)
    }

    fn commit(&mut self, _j: usize, s: f64, changed: &mut Vec<usize>) -> Result<(usize, f64)> {
        let (c, d) = self.planned;
        let step = d * s;
        let p = self.curve.control_points()[c] + step;
        for r in self.copies(c) {
            self.curve.set_control_point(r, p);
            // The jumps at the knots of the support of P_r change.
            for x in r..=r + DEGREE + 1 {
                changed.push(self.candidate_knot(x));
            }
        }
        for &(k, n) in &self.affected {
            self.e[k] += step * n;
            self.disp.set(k, self.e[k].length());
        }
        // On a closed curve, the index of the distinct control point.
        let index = self.period.map_or(c, |n| period_index(c, n));
        Ok((index, step.length()))
    }

    fn max_displacement(&self) -> f64 {
        self.disp.max_value()
    }

    fn worsens(&self, _j: usize, s: f64) -> bool {
        if !self.keep_clean {
            return false;
        }
        // The data points move by N_c(t_k)·s·d (the affected list of the plan).
        let step = self.planned.1 * s;
        let moved: Vec<(usize, Point)> = self
            .affected
            .iter()
            .map(|&(k, n)| (k, self.q[k] + self.e[k] + step * n))
            .collect();
        super::clean::move_is_worse_by(
            self.q.len(),
            self.period.is_some(),
            |k| self.q[k] + self.e[k],
            &moved,
        )
    }
}

/// Parameters in data units and their power of length: the B-spline's third-derivative
/// jumps (on the averaging knots of the chord-length parameters, as the method measures them)
/// scale as a length.
const LENGTH_PARAMS: &[(&str, i32)] = &[(EPSILON.name, 1), ("initial_max_jump", 1)];

impl FairMethod for SapidisFarin {
    fn name(&self) -> &'static str {
        "sapidis-farin"
    }

    fn description(&self) -> &'static str {
        "Sapidis-Farin: cubic B-spline, worst knot (third-derivative jump) removed and reinserted"
    }

    fn parameters(&self) -> &'static [ParamSpec] {
        &JUMP_PARAMS
    }

    fn supports_closed(&self) -> bool {
        true
    }

    fn length_params(&self) -> &'static [(&'static str, i32)] {
        LENGTH_PARAMS
    }

    fn check_params(&self, options: &FairOptions) -> Result<()> {
        Threshold::from_options(options).map(|_| ())
    }

    fn run(&self, input: &PointSeq, options: &FairOptions) -> Result<Outcome> {
        let threshold = Threshold::from_options(options)?;
        let points = input.points();
        let n = points.len();
        let closed = input.is_closed();
        // Open: the clamped interpolant, P_0, P_1 (and more with --fix-ends) held. Closed: the
        // wrapped periodic cubic, every knot of the period a candidate.
        let (curve, t) = if closed {
            interpolate_closed(points)?
        } else {
            BSplineCurve::interpolate(points, DEGREE, Parametrization::ChordLength)?
        };
        let initial = curve.control_points().to_vec();
        let scale = BBox::from_points(points).map_or(0.0, |b| b.diagonal());
        let mut state = KnotState {
            curve,
            t,
            q: points.to_vec(),
            e: vec![Vec2::ZERO; n],
            disp: MaxTree::zeros(n),
            min_chord: MIN_CHORD_REL * scale,
            planned: (0, Vec2::ZERO),
            affected: Vec::new(),
            held: options.fix_ends.held().max(2),
            period: closed.then_some(n),
            keep_clean: options.keep_clean,
        };
        let candidates = if closed {
            n
        } else {
            n.saturating_sub(DEGREE + 1)
        };
        let max_moves = move_limit(options, candidates);
        let driven = drive(&mut state, threshold, max_moves, options.tolerance)?;
        let mut parameters = driven_parameters(&driven, threshold, max_moves);
        parameters.insert("degree".into(), json!(DEGREE));
        parameters.insert("parametrization".into(), json!("chord-length"));
        parameters.insert(
            "knots".into(),
            json!(if closed {
                "periodic, at the parameters"
            } else {
                "averaging"
            }),
        );
        let points = state.output(&initial)?;
        // P_0 and P_1 (and their mirror at the other end) are held: the end points (the
        // curve's end tangents too, but not the second points, which `tangent` means). The
        // wrapped form of a closed curve is not a curve of its own: none is returned.
        Ok(Outcome {
            curve: (!closed).then_some(state.curve),
            ..driven.into_outcome(points, parameters)
        })
    }
}
