//! Sapidis–Farin fairing of a cubic B-spline by knot removal and reinsertion (method
//! `sapidis-farin`).
//!
//! References: N. Sapidis and G. Farin, *Automatic fairing algorithm for B-spline curves*,
//! Computer-Aided Design 22(2), 1990 (cited as "Farin and Sapides, 1989" in
//! `../shared/papers/kjellander-poliakoff-improved.txt`); G. Farin, *Curves and Surfaces for
//! CAGD*, the section on fairing by knot removal. The five papers of the spec do not cover
//! this method: the local formula below is derived here, and the greedy loop, stopping rule
//! and tolerance handling are those of the Kjellander–Poliakoff family (spec §2.6, module
//! [`super::kjellander`]).
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
//! next-worst (see [`super::kjellander`]). [`crate::fair::Move::index`] is the index of the
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
//! Closed curves are rejected ([`Error::ClosedUnsupported`]): the spline module has no
//! periodic B-spline interpolation yet.
//!
//! Cost: a move is local (one control point, five jumps, the few data points in the support
//! of one basis function) and the bad knot is kept in a max-tree: O(log n) per move after
//! the O(n) interpolation. Measured with `benches/kp.rs` (release, loaded 2-core machine):
//! 6–8 µs per move at n = 10³ and 10⁴; the set-up costs about 2 µs per point.

use serde_json::json;

use super::kjellander::{
    EPSILON_PARAM, JUMP_ZERO_REL, LocalProblem, MIN_CHORD_REL, MaxTree, THRESHOLD_PARAM,
    TOLERANCE_MARGIN, Threshold, drive, driven_parameters, max_fraction, move_limit,
};
use super::{FairMethod, FairOptions, Outcome, ParamSpec};
use crate::curve::Curve;
use crate::error::{Error, Result};
use crate::geom::{BBox, Point, PointSeq, Vec2};
use crate::spline::{BSplineCurve, MAX_ORDER, Parametrization};

/// The degree this method works with.
const DEGREE: usize = 3;

/// Method `sapidis-farin`: fairing a cubic B-spline by removing and reinserting its worst
/// knot (see the module docs).
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
/// and reinsert it (Farin's local formula, see the module docs). The result has the same
/// knot vector, differs from `curve` in the control point `j − 2` only, and its third
/// derivative is continuous at `u_j`.
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

/// The interpolating cubic and the data it was built from, faired knot by knot.
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
    /// Data points in the support of the planned control point, with `N_c(t_k)`.
    affected: Vec<(usize, f64)>,
    /// Control points held at each end (`--fix-ends`): the moved `P_{j−2}` must be at least
    /// this far from both ends. Two always (`P_0, P_1` never move).
    held: usize,
}

impl KnotState {
    /// `N_c(t_k)` for the data points in the support of control point `c`.
    fn support_values(&mut self, c: usize) {
        self.affected.clear();
        let u = self.curve.knots().as_slice();
        let (lo, hi) = (u[c], u[c + DEGREE + 1]);
        let first = self.t.partition_point(|&x| x <= lo);
        let last = self.t.partition_point(|&x| x < hi);
        let mut b = [[0.0; MAX_ORDER]; 4];
        for k in first..last {
            let tk = self.t[k];
            let span = self.curve.find_span(tk);
            if c + DEGREE < span || c > span {
                continue;
            }
            self.curve.basis_derivs(span, tk, 0, &mut b);
            let n = b[0][c + DEGREE - span];
            if n != 0.0 {
                self.affected.push((k, n));
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
        is_simple_interior(self.curve.knots().as_slice(), ncp, j)
            && j >= 2 + self.held
            && j + self.held <= ncp + 1
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
                let radius = tol * (1.0 - TOLERANCE_MARGIN);
                self.affected
                    .iter()
                    .map(|&(k, n)| max_fraction(self.e[k], d * n, radius))
                    .fold(1.0, f64::min)
            }
        };
        self.planned = (c, d);
        // Consecutive output points must stay distinct.
        let (first, last) = match (self.affected.first(), self.affected.last()) {
            (Some(a), Some(b)) => (a.0, b.0),
            _ => return Some(s),
        };
        let from = first.saturating_sub(1);
        let to = (last + 1).min(self.q.len() - 1);
        for k in from..to {
            if (self.moved(k + 1, s) - self.moved(k, s)).length() < self.min_chord {
                return None;
            }
        }
        Some(s)
    }

    fn commit(&mut self, j: usize, s: f64, changed: &mut Vec<usize>) -> Result<(usize, f64)> {
        let (c, d) = self.planned;
        let step = d * s;
        let p = self.curve.control_points()[c] + step;
        self.curve.set_control_point(c, p);
        for &(k, n) in &self.affected {
            self.e[k] += step * n;
            self.disp.set(k, self.e[k].length());
        }
        changed.extend(j.saturating_sub(2)..=j + 2);
        Ok((c, step.length()))
    }

    fn max_displacement(&self) -> f64 {
        self.disp.max_value()
    }
}

impl FairMethod for SapidisFarin {
    fn name(&self) -> &'static str {
        "sapidis-farin"
    }

    fn description(&self) -> &'static str {
        "Sapidis-Farin: cubic B-spline, worst knot (third-derivative jump) removed and reinserted"
    }

    fn parameters(&self) -> &'static [ParamSpec] {
        &[THRESHOLD_PARAM, EPSILON_PARAM]
    }

    fn supports_closed(&self) -> bool {
        false
    }

    fn check_params(&self, options: &FairOptions) -> Result<()> {
        Threshold::from_options(options).map(|_| ())
    }

    fn run(&self, input: &PointSeq, options: &FairOptions) -> Result<Outcome> {
        if input.is_closed() {
            return Err(Error::ClosedUnsupported {
                method: self.name().to_string(),
            });
        }
        let threshold = Threshold::from_options(options)?;
        let points = input.points();
        let (curve, t) = BSplineCurve::interpolate(points, DEGREE, Parametrization::ChordLength)?;
        let initial = curve.control_points().to_vec();
        let n = points.len();
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
        };
        let interior = n.saturating_sub(DEGREE + 1);
        let max_moves = move_limit(options, interior);
        let driven = drive(&mut state, threshold, max_moves, options.tolerance)?;
        let mut parameters = driven_parameters(&driven, threshold, max_moves);
        parameters.insert("degree".into(), json!(DEGREE));
        parameters.insert("parametrization".into(), json!("chord-length"));
        parameters.insert("knots".into(), json!("averaging"));
        let points = state.output(&initial)?;
        Ok(Outcome {
            points,
            status: driven.status,
            iterations: driven.moves.len(),
            moves: driven.moves,
            history: driven.history,
            parameters,
            notes: driven.notes,
            curve: Some(state.curve),
            tangents: None,
        })
    }
}
