//! The tolerance budget of a move: the radius a point may reach (the tolerance less a margin
//! kept against rounding), the largest fraction of a planned move that stays inside it, and
//! the shortest chord a move may leave (`docs/algorithms/kjellander-poliakoff.md`, "The
//! algorithm", the tolerance).

use crate::geom::Vec2;

/// Relative margin kept inside the tolerance when a move is scaled back onto it, so that
/// rounding cannot put a point beyond the tolerance.
pub(super) const TOLERANCE_MARGIN: f64 = 1e-9;

/// A move that would leave a chord to a neighbour shorter than this fraction of the data's
/// size (its bounding-box diagonal) is refused: coincident consecutive points have no
/// chord-length parameter.
pub(crate) const MIN_CHORD_REL: f64 = 1e-9;

/// The radius a point may reach from its original position under the tolerance `tol`: `tol`
/// less the relative margin [`TOLERANCE_MARGIN`], so that rounding cannot put it beyond `tol`.
#[inline]
pub(crate) fn tolerance_radius(tol: f64) -> f64 {
    tol * (1.0 - TOLERANCE_MARGIN)
}

/// The largest fraction in [0, 1] of the move `step` of a point now at `offset` from its
/// original position that keeps it within [`tolerance_radius`] of it ([`max_fraction`]);
/// 1 without a tolerance.
pub(crate) fn step_fraction(offset: Vec2, step: Vec2, tolerance: Option<f64>) -> f64 {
    match tolerance {
        None => 1.0,
        Some(tol) => max_fraction(offset, step, tolerance_radius(tol)),
    }
}

/// The largest `s ∈ [0, 1]` with `|e + s·w| ≤ radius`, given `|e| ≤ radius` (the point's
/// current offset `e` from its original position, the move `w`).
pub(crate) fn max_fraction(e: Vec2, w: Vec2, radius: f64) -> f64 {
    let ww = w.length_squared();
    if ww == 0.0 {
        return 1.0;
    }
    let slack = radius * radius - e.length_squared();
    if slack <= 0.0 {
        // On (or beyond) the bound: only inward moves are allowed, and they end on it again.
        return if e.dot(w) < 0.0 {
            (-2.0 * e.dot(w) / ww).min(1.0)
        } else {
            0.0
        };
    }
    let b = e.dot(w);
    let root = (b * b + ww * slack).sqrt();
    // Positive root of ww s² + 2 b s − slack = 0, in the cancellation-free form.
    let s = if b > 0.0 {
        slack / (b + root)
    } else {
        (root - b) / ww
    };
    s.clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn max_fraction_stops_on_the_bound() {
        let e = Vec2::new(0.5, 0.0);
        let w = Vec2::new(1.0, 0.0);
        assert!((max_fraction(e, w, 1.0) - 0.5).abs() < 1e-15);
        assert_eq!(max_fraction(Vec2::ZERO, w, 2.0), 1.0);
        // On the bound, outward: nothing; inward: up to the far side.
        assert_eq!(max_fraction(Vec2::new(1.0, 0.0), w, 1.0), 0.0);
        assert_eq!(max_fraction(Vec2::new(1.0, 0.0), -w, 1.0), 1.0);
        let s = max_fraction(Vec2::new(0.3, 0.4), Vec2::new(-3.0, 1.0), 0.6);
        let end = Vec2::new(0.3, 0.4) + Vec2::new(-3.0, 1.0) * s;
        assert!((end.length() - 0.6).abs() < 1e-14);
    }
}
