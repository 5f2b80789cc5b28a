//! The per-move half of the clean-curve promise (the other half, the last guard on the
//! whole result, is in the common path, `guard.rs`): a local method refuses a move that
//! would give the curve more inflections or a higher variation energy `∫(dκ/ds)² ds` near
//! the move.
//!
//! The check is local, so that a move costs O(1) and not the O(n) of measuring the whole
//! curve: the C² chord-length cubic (the analysis curve of
//! [`crate::analysis::FairnessMetrics`]) through the points within
//! [`LOCAL_CHECK_HALF_WIDTH`] of the moved ones, before and after the move, measured by the
//! same metrics. A move is refused when it gives a window without inflections one, or when
//! it gives a clean window (no inflections, no vibrations) a vibration or raises its
//! variation energy beyond the slack [`super::CLEAN_SLACK_REL`]; see [`refuse`] for why windows that already wiggle
//! are left to the method. The influence of a point on the cubic interpolant decays by
//! a factor of about 2 − √3 ≈ 0.27 per span, so a window of six points each side sees the
//! move's effect on the curve to within about 0.27⁶ ≈ 4·10⁻⁴ of it; the last guard catches
//! what the window misses.

use crate::analysis::FairnessMetrics;
use crate::curve::Curve;
use crate::geom::{Point, PointSeq, Vec2};
use crate::spline::{BSplineCurve, MAX_ORDER};

/// Points each side of the moved ones that the local check measures.
pub const LOCAL_CHECK_HALF_WIDTH: usize = 6;

/// Whether moving the points `moved` (index, new position) makes the curve through
/// `points` worse near them ([`refuse`]). A window that cannot be measured after the move
/// (coincident points) counts as worse.
pub(crate) fn move_is_worse(points: &[Point], closed: bool, moved: &[(usize, Point)]) -> bool {
    move_is_worse_by(points.len(), closed, |i| points[i], moved)
}

/// [`move_is_worse`] for `n` points given by `point(i)` (e.g. a segment's `(x, y)` arrays).
pub(crate) fn move_is_worse_by(
    n: usize,
    closed: bool,
    point: impl Fn(usize) -> Point,
    moved: &[(usize, Point)],
) -> bool {
    let Some(lo) = moved.iter().map(|m| m.0).min() else {
        return false;
    };
    let hi = moved.iter().map(|m| m.0).max().unwrap_or(lo);
    let w = LOCAL_CHECK_HALF_WIDTH;
    // The window's indices into `points`, and whether it is the whole closed curve.
    let (idx, whole_closed): (Vec<usize>, bool) = if closed {
        // Moved points of a closed curve may straddle the seam: take the shorter arc.
        let (a, b) = if hi - lo <= n / 2 {
            (lo, hi)
        } else {
            (hi, lo + n)
        };
        let len = b - a + 1 + 2 * w;
        if len >= n {
            ((0..n).collect(), true)
        } else {
            ((0..len).map(|j| (a + n - w + j) % n).collect(), false)
        }
    } else {
        (
            (lo.saturating_sub(w)..=(hi + w).min(n - 1)).collect(),
            false,
        )
    };
    let before: Vec<Point> = idx.iter().map(|&i| point(i)).collect();
    let mut after = before.clone();
    for &(i, p) in moved {
        if let Some(j) = idx.iter().position(|&k| k == i) {
            after[j] = p;
        }
    }
    let measure = |pts: Vec<Point>| {
        PointSeq::new(pts, whole_closed)
            .ok()
            .and_then(|s| FairnessMetrics::of_seq(&s).ok())
    };
    match (measure(before), measure(after)) {
        (Some(b), Some(a)) => refuse(&b, &a),
        // The window is degenerate before the move: nothing to compare, do not refuse.
        (None, _) => false,
        (Some(_), None) => true,
    }
}

/// The per-move rule, on the window before (`b`) and after (`a`) the move: refuse a move
/// that gives a window without inflections one, or that gives a clean window (one with
/// neither inflections nor curvature vibrations) a vibration or raises its variation energy
/// beyond [`super::CLEAN_SLACK_REL`]. Windows that already wiggle are noise the method is there to
/// remove: its greedy moves there may pass through a locally worse state on the way to a
/// fairer curve (refusing those too cost han and the Kjellander family up to 3 more
/// inflections and 5× the GFI on the bundled noisy examples), and the final guard of the
/// common path judges the whole result.
fn refuse(b: &FairnessMetrics, a: &FairnessMetrics) -> bool {
    let clean = b.inflections == 0 && b.vibrations == 0;
    (b.inflections == 0 && a.inflections > 0)
        || (clean && a.vibrations > 0)
        || (clean && a.variation_energy > b.variation_energy * (1.0 + super::CLEAN_SLACK_REL))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arc(n: usize) -> Vec<Point> {
        (0..n)
            .map(|i| {
                let t = 0.1 * i as f64;
                Point::new(2.0 * t.cos(), 2.0 * t.sin())
            })
            .collect()
    }

    #[test]
    fn a_bump_on_a_clean_arc_is_worse_and_no_move_is_not() {
        let pts = arc(30);
        let bumped = Point::new(pts[15].x * 1.001, pts[15].y * 1.001);
        assert!(move_is_worse(&pts, false, &[(15, bumped)]));
        assert!(!move_is_worse(&pts, false, &[(15, pts[15])]));
        // A closed circle, the moved point at the seam.
        let circle: Vec<Point> = (0..30)
            .map(|i| {
                let t = std::f64::consts::TAU * f64::from(i) / 30.0;
                Point::new(t.cos(), t.sin())
            })
            .collect();
        assert!(move_is_worse(&circle, true, &[(0, Point::new(1.001, 0.0))]));
        assert!(!move_is_worse(&circle, true, &[(0, circle[0])]));
    }

    #[test]
    fn removing_a_bump_is_not_worse() {
        let clean = arc(30);
        let mut noisy = clean.clone();
        noisy[12] = Point::new(clean[12].x * 1.002, clean[12].y * 1.002);
        assert!(!move_is_worse(&noisy, false, &[(12, clean[12])]));
        // Near the ends too.
        noisy[1] = Point::new(clean[1].x * 1.002, clean[1].y * 1.002);
        assert!(!move_is_worse(&noisy, false, &[(1, clean[1])]));
    }
}

/// The per-move check for the methods that move one control point of an open, non-rational
/// B-spline at a time (`eck-hadenfeld`, `salvi`): the data points are the curve at the data
/// parameters, and a move of control point `j` by `Δ` moves each data point in its support
/// by `N_j(t_k)·Δ`.
#[derive(Clone, Debug)]
pub(crate) struct ControlCheck {
    curve: BSplineCurve,
    params: Vec<f64>,
    points: Vec<Point>,
    /// Moves refused so far.
    pub(crate) refused: usize,
}

impl ControlCheck {
    /// The check for `curve` sampled at the increasing `params`; `None` for a rational curve
    /// (a control point move is not linear in the points there) or unsorted parameters.
    pub(crate) fn new(curve: &BSplineCurve, params: &[f64]) -> Option<ControlCheck> {
        if curve.weights().is_some() || params.windows(2).any(|w| w[1] < w[0]) {
            return None;
        }
        Some(ControlCheck {
            curve: curve.clone(),
            params: params.to_vec(),
            points: params.iter().map(|&t| curve.eval(t)).collect(),
            refused: 0,
        })
    }

    /// The data points in the support of control point `j`, with `N_j` there.
    fn affected(&self, j: usize) -> Vec<(usize, f64)> {
        let p = self.curve.degree();
        let u = self.curve.knots().as_slice();
        let (lo, hi) = (u[j], u[j + p + 1]);
        let first = self.params.partition_point(|&t| t < lo);
        let last = self.params.partition_point(|&t| t <= hi);
        let mut out = [[0.0; MAX_ORDER]; 4];
        (first..last)
            .filter_map(|k| {
                let t = self.params[k];
                let span = self.curve.find_span(t);
                self.curve.basis_derivs(span, t, 0, &mut out);
                let n = if j + p >= span && j <= span {
                    out[0][j + p - span]
                } else {
                    0.0
                };
                (n != 0.0).then_some((k, n))
            })
            .collect()
    }

    /// Whether moving control point `j` by `delta` makes the data points worse near it
    /// ([`refuse`]); counts a refusal.
    pub(crate) fn refuses(&mut self, j: usize, delta: Vec2) -> bool {
        let moved: Vec<(usize, Point)> = self
            .affected(j)
            .into_iter()
            .map(|(k, n)| (k, self.points[k] + delta * n))
            .collect();
        let worse = move_is_worse(&self.points, false, &moved);
        self.refused += usize::from(worse);
        worse
    }

    /// Record the move of control point `j` by `delta`.
    pub(crate) fn commit(&mut self, j: usize, delta: Vec2) {
        for (k, n) in self.affected(j) {
            self.points[k] += delta * n;
        }
        let moved = self.curve.control_points()[j] + delta;
        self.curve.set_control_point(j, moved);
    }

    /// The note for the report, when moves were refused.
    pub(crate) fn note(&self) -> Option<String> {
        (self.refused > 0).then(|| {
            format!(
                "{} moves were refused because they would have added an inflection to the \
                 curve through the data points, or raised its variation energy where it was \
                 clean (the clean-curve check)",
                self.refused
            )
        })
    }
}
