use serde::{Deserialize, Serialize};

use super::{BBox, Point};
use crate::error::{Error, Result};

/// A validated sequence of planar points, open or closed.
///
/// Guarantees, checked by [`PointSeq::new`]:
/// - at least [`PointSeq::MIN_POINTS`] points;
/// - every coordinate finite;
/// - no two consecutive points equal (for a closed sequence this includes the last and the
///   first: a closed curve is given *without* repeating its first point at the end), nor
///   closer than [`NEAR_DUPLICATE_REL`] of the larger side of the bounding box.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PointSeq {
    points: Vec<Point>,
    closed: bool,
}

impl PointSeq {
    /// The fewest points batten fairs or analyses: a cubic needs four to be determined.
    pub const MIN_POINTS: usize = 4;

    /// Validate and wrap a point list.
    ///
    /// # Errors
    /// [`Error::TooFewPoints`], [`Error::NonFinite`], [`Error::DuplicatePoint`] or
    /// [`Error::NearDuplicate`] naming the index of the first offending point.
    pub fn new(points: Vec<Point>, closed: bool) -> Result<PointSeq> {
        validate_points(&points, closed, Self::MIN_POINTS)?;
        Ok(PointSeq { points, closed })
    }

    /// An open sequence; see [`PointSeq::new`].
    ///
    /// # Errors
    /// As [`PointSeq::new`].
    pub fn open(points: Vec<Point>) -> Result<PointSeq> {
        PointSeq::new(points, false)
    }

    /// A closed sequence (the last point connects back to the first); see [`PointSeq::new`].
    ///
    /// # Errors
    /// As [`PointSeq::new`].
    pub fn closed(points: Vec<Point>) -> Result<PointSeq> {
        PointSeq::new(points, true)
    }

    /// The points.
    pub fn points(&self) -> &[Point] {
        &self.points
    }

    /// Consume and return the points.
    pub fn into_points(self) -> Vec<Point> {
        self.points
    }

    /// Whether the curve is closed.
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Always false: a `PointSeq` holds at least [`PointSeq::MIN_POINTS`] points.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Bounding box of the points.
    pub fn bbox(&self) -> BBox {
        // Non-empty by construction.
        BBox::from_points(&self.points).unwrap_or(BBox {
            min: Point::ORIGIN,
            max: Point::ORIGIN,
        })
    }

    /// The length scale of the data: the diagonal of its bounding box. Tolerances that must
    /// scale with the data are relative to it.
    pub fn scale(&self) -> f64 {
        self.bbox().diagonal()
    }

    /// A sequence with the same closedness and new points, validated again.
    ///
    /// # Errors
    /// As [`PointSeq::new`].
    pub fn with_points(&self, points: Vec<Point>) -> Result<PointSeq> {
        PointSeq::new(points, self.closed)
    }

    /// The sequence with its coordinates multiplied by `factor`, the power of two that brings
    /// the bounding box's larger side near 1 (`1/`[`crate::geom::unit_scale`]), without
    /// validating it again: such a scaling is exact but for coordinates that become
    /// subnormal, far below the near-duplicate limit, so a valid sequence stays valid (the
    /// measurements scale every report's curves this way, twice a fair; validating them again
    /// was a few per cent of a small fair).
    pub(crate) fn scaled_to_unit(&self, factor: f64) -> PointSeq {
        let scaled = PointSeq {
            points: crate::geom::scale_points(&self.points, factor),
            closed: self.closed,
        };
        debug_assert!(validate_points(&scaled.points, scaled.closed, Self::MIN_POINTS).is_ok());
        scaled
    }
}

/// Check that `points` has at least `min` entries, all finite, with no zero-length chord.
///
/// # Errors
/// [`Error::TooFewPoints`], [`Error::NonFinite`], [`Error::DuplicatePoint`] or
/// [`Error::NearDuplicate`].
pub(crate) fn validate_points(points: &[Point], closed: bool, min: usize) -> Result<()> {
    if points.len() < min {
        return Err(Error::TooFewPoints {
            needed: min,
            got: points.len(),
        });
    }
    if let Some(index) = points.iter().position(|p| !p.is_finite()) {
        return Err(Error::NonFinite { index });
    }
    if let Some(i) = points.windows(2).position(|w| w[0] == w[1]) {
        return Err(Error::DuplicatePoint { index: i + 1 });
    }
    if closed && points.first() == points.last() {
        return Err(Error::DuplicatePoint {
            index: points.len() - 1,
        });
    }
    near_duplicates(points, closed)
}

/// The index after `i` on a closed sequence of `n` items (`0` after the last): `(i + 1) % n`
/// for `i < n` by a comparison, not a division (it runs once a point in the sweeps over
/// 10⁶-point curves).
#[inline]
pub(crate) fn next_index(i: usize, n: usize) -> usize {
    if i + 1 < n { i + 1 } else { 0 }
}

/// Consecutive points closer than this fraction of the larger side of the bounding box are
/// refused as near-duplicates ([`Error::NearDuplicate`]). Coordinates of magnitude R carry a
/// rounding of about 10⁻¹⁶·R, so a chord of 10⁻¹² of the curve's size has its length and
/// direction known to no better than 10⁻⁴: every chord-length spline through it (the analysis
/// curve, most methods) is then shaped by rounding, and below about 10⁻¹⁴ its system is
/// singular. The densest scan batten is meant for (10⁷ points) has chords near 10⁻⁷ of the
/// size.
pub const NEAR_DUPLICATE_REL: f64 = 1e-12;

/// [`Error::NearDuplicate`] for the first chord shorter than [`NEAR_DUPLICATE_REL`] of the
/// larger side of the bounding box. Halved coordinates, so that nothing overflows near
/// `f64::MAX`.
fn near_duplicates(points: &[Point], closed: bool) -> Result<()> {
    let Some(b) = BBox::from_points(points) else {
        return Ok(());
    };
    let half = |v: f64| 0.5 * v;
    let size = (half(b.max.x) - half(b.min.x)).max(half(b.max.y) - half(b.min.y));
    let limit = NEAR_DUPLICATE_REL * size;
    let n = points.len();
    let chords = if closed { n } else { n - 1 };
    for i in 0..chords {
        let (a, c) = (points[i], points[next_index(i, n)]);
        let (dx, dy) = (half(c.x) - half(a.x), half(c.y) - half(a.y));
        // hypot(dx, dy) ≥ max(|dx|, |dy|), so a chord with either difference at the limit
        // passes without it (nearly every chord: the check costs a tenth of reading).
        if dx.abs() >= limit || dy.abs() >= limit {
            continue;
        }
        let d = dx.hypot(dy);
        if d < limit {
            return Err(Error::NearDuplicate {
                index: (i + 1) % n,
                previous: i,
                relative: d / size,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn near_duplicates_are_refused_at_any_scale() {
        for scale in [1e-300, 1.0, 1e300, f64::MAX / 16.0] {
            let pts = |gap: f64| -> Vec<Point> {
                [
                    (0.0, 0.0),
                    (1.0, 0.5),
                    (1.0 + gap, 0.5),
                    (2.0, 0.0),
                    (3.0, 1.0),
                ]
                .iter()
                .map(|&(x, y)| Point::new(x * scale, y * scale))
                .collect()
            };
            // Issue #14: two points 1e-15 apart made the analysis spline singular.
            match PointSeq::open(pts(1e-15)) {
                Err(Error::NearDuplicate {
                    index: 2,
                    previous: 1,
                    relative,
                }) => assert!(relative < NEAR_DUPLICATE_REL, "{relative}"),
                other => panic!("at scale {scale}: {other:?}"),
            }
            assert!(PointSeq::open(pts(1e-9)).is_ok(), "at scale {scale}");
        }
        // The closing chord of a closed curve.
        let sq = vec![
            Point::new(0.0, 0.0),
            Point::new(1.0, 0.0),
            Point::new(1.0, 1.0),
            Point::new(0.0, 1.0),
            Point::new(1e-14, 0.0),
        ];
        assert!(PointSeq::open(sq.clone()).is_ok());
        assert!(matches!(
            PointSeq::closed(sq),
            Err(Error::NearDuplicate {
                index: 0,
                previous: 4,
                ..
            })
        ));
    }

    fn square() -> Vec<Point> {
        vec![
            Point::new(0.0, 0.0),
            Point::new(1.0, 0.0),
            Point::new(1.0, 1.0),
            Point::new(0.0, 1.0),
        ]
    }

    #[test]
    fn accepts_valid_and_rejects_bad() {
        assert!(PointSeq::open(square()).is_ok());
        assert!(PointSeq::closed(square()).is_ok());
        assert_eq!(
            PointSeq::open(square()[..3].to_vec()),
            Err(Error::TooFewPoints { needed: 4, got: 3 })
        );
        let mut p = square();
        p[2].y = f64::NAN;
        assert_eq!(PointSeq::open(p), Err(Error::NonFinite { index: 2 }));
        let mut p = square();
        p[2] = p[1];
        assert_eq!(PointSeq::open(p), Err(Error::DuplicatePoint { index: 2 }));
        let mut p = square();
        p.push(p[0]);
        assert!(PointSeq::open(p.clone()).is_ok());
        assert_eq!(PointSeq::closed(p), Err(Error::DuplicatePoint { index: 4 }));
    }
}
