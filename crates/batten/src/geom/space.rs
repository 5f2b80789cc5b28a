//! Space curves: the validated point sequence [`SpaceSeq`] of 3-D points.
//!
//! A 3-D point is a plain `[x, y, z]` array ([`Xyz`]), as on the surfaces: the space-curve
//! code (analysis, the `band` and `mst` methods) works on arrays of any dimension.

use serde::{Deserialize, Serialize};

use super::NEAR_DUPLICATE_REL;
use crate::error::{Error, Result};

/// A point (or vector) in space.
pub type Xyz = [f64; 3];

/// A validated sequence of points in space, open or closed: the same guarantees as
/// [`super::PointSeq`] (at least [`SpaceSeq::MIN_POINTS`] points, every coordinate finite, no
/// two consecutive points equal or closer than [`NEAR_DUPLICATE_REL`] of the bounding box's
/// largest side, the last and the first included when closed).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpaceSeq {
    points: Vec<Xyz>,
    closed: bool,
}

impl SpaceSeq {
    /// The fewest points: as for planar curves, a cubic needs four.
    pub const MIN_POINTS: usize = super::PointSeq::MIN_POINTS;

    /// Validate and wrap a point list.
    ///
    /// # Errors
    /// [`Error::TooFewPoints`], [`Error::NonFinite`], [`Error::DuplicatePoint`] or
    /// [`Error::NearDuplicate`] naming the index of the first offending point.
    pub fn new(points: Vec<Xyz>, closed: bool) -> Result<SpaceSeq> {
        if points.len() < Self::MIN_POINTS {
            return Err(Error::TooFewPoints {
                needed: Self::MIN_POINTS,
                got: points.len(),
            });
        }
        if let Some(index) = points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
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
        near_duplicates(&points, closed)?;
        Ok(SpaceSeq { points, closed })
    }

    /// The points.
    pub fn points(&self) -> &[Xyz] {
        &self.points
    }

    /// Consume and return the points.
    pub fn into_points(self) -> Vec<Xyz> {
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

    /// Always false: a `SpaceSeq` holds at least [`SpaceSeq::MIN_POINTS`] points.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The smallest and largest coordinate along each axis.
    pub fn bounds(&self) -> (Xyz, Xyz) {
        bounds(&self.points)
    }

    /// The diagonal of the bounding box: the data's length scale.
    pub fn scale(&self) -> f64 {
        let (lo, hi) = self.bounds();
        norm(sub(hi, lo))
    }

    /// A sequence with the same closedness and new points, validated again.
    ///
    /// # Errors
    /// As [`SpaceSeq::new`].
    pub fn with_points(&self, points: Vec<Xyz>) -> Result<SpaceSeq> {
        SpaceSeq::new(points, self.closed)
    }
}

/// `a − b`.
pub(crate) fn sub(a: Xyz, b: Xyz) -> Xyz {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// The Euclidean length of `v`, without overflow for finite components (`hypot`: the space
/// analysis and fair measure lengths by it, bit for bit).
#[inline]
pub(crate) fn norm(v: Xyz) -> f64 {
    v[0].hypot(v[1]).hypot(v[2])
}

/// The smallest and largest coordinate along each axis (zeros for no points).
fn bounds(points: &[Xyz]) -> (Xyz, Xyz) {
    let Some(first) = points.first() else {
        return ([0.0; 3], [0.0; 3]);
    };
    let (mut lo, mut hi) = (*first, *first);
    for p in points {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    (lo, hi)
}

/// [`Error::NearDuplicate`] for the first chord shorter than [`NEAR_DUPLICATE_REL`] of the
/// bounding box's largest side (halved coordinates, so nothing overflows near `f64::MAX`).
fn near_duplicates(points: &[Xyz], closed: bool) -> Result<()> {
    let (lo, hi) = bounds(points);
    let half = |v: f64| 0.5 * v;
    let size = (0..3)
        .map(|a| half(hi[a]) - half(lo[a]))
        .fold(0.0, f64::max);
    let limit = NEAR_DUPLICATE_REL * size;
    let n = points.len();
    let chords = if closed { n } else { n - 1 };
    for i in 0..chords {
        let (a, c) = (points[i], points[super::next_index(i, n)]);
        let d = norm(std::array::from_fn(|k| half(c[k]) - half(a[k])));
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

    fn helix(n: usize) -> Vec<Xyz> {
        (0..n)
            .map(|i| {
                let t = i as f64 * 0.3;
                [t.cos(), t.sin(), 0.2 * t]
            })
            .collect()
    }

    #[test]
    fn accepts_valid_and_rejects_bad() {
        assert!(SpaceSeq::new(helix(6), false).is_ok());
        assert_eq!(
            SpaceSeq::new(helix(3), false),
            Err(Error::TooFewPoints { needed: 4, got: 3 })
        );
        let mut p = helix(6);
        p[2][2] = f64::NAN;
        assert_eq!(SpaceSeq::new(p, false), Err(Error::NonFinite { index: 2 }));
        let mut p = helix(6);
        p[3] = p[2];
        assert_eq!(
            SpaceSeq::new(p, false),
            Err(Error::DuplicatePoint { index: 3 })
        );
        let mut p = helix(6);
        p.push(p[0]);
        assert!(SpaceSeq::new(p.clone(), false).is_ok());
        assert_eq!(
            SpaceSeq::new(p, true),
            Err(Error::DuplicatePoint { index: 6 })
        );
        // Points that differ in z alone are distinct; a z gap of 1e-15 is a near-duplicate.
        let mut p = helix(6);
        p[3] = [p[2][0], p[2][1], p[2][2] + 1e-15];
        assert!(matches!(
            SpaceSeq::new(p, false),
            Err(Error::NearDuplicate {
                index: 3,
                previous: 2,
                ..
            })
        ));
    }

    #[test]
    fn the_scale_is_the_diagonal() {
        let s = SpaceSeq::new(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 2.0, 0.0],
                [1.0, 2.0, 2.0],
            ],
            false,
        )
        .unwrap();
        assert_eq!(s.scale(), 3.0);
    }
}
