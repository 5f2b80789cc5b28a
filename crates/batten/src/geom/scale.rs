//! Exact rescaling by powers of two, so that computations on coordinates of any magnitude
//! run on numbers near 1.
//!
//! Multiplying a finite `f64` by a power of two changes only its exponent, so a point list
//! divided by [`unit_scale`] and multiplied back is bit for bit the input (away from the
//! subnormal range), and a computation that is equivariant under scaling gives the same
//! digits on the scaled data as on the original. No translation is applied: subtracting a
//! centre would round every coordinate, and it is overflow and underflow, not the position,
//! that breaks computations at extreme magnitudes.

use super::{Point, Xyz};

/// The power of two nearest to the larger side of the bounding box of `points`: dividing
/// by it brings the larger side into `[2^-0.5, 2^0.5]`. `1.0` for fewer than two distinct
/// points or non-finite input (nothing to normalise).
pub fn unit_scale(points: &[Point]) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points {
        lo = [lo[0].min(p.x), lo[1].min(p.y)];
        hi = [hi[0].max(p.x), hi[1].max(p.y)];
    }
    // Half-extents, so that ±f64::MAX does not overflow the subtraction.
    let extent = (0.5 * hi[0] - 0.5 * lo[0]).max(0.5 * hi[1] - 0.5 * lo[1]);
    scale_of_half_extent(extent)
}

/// [`unit_scale`] for points in space: the largest side of their bounding box.
pub fn unit_scale_xyz(points: &[Xyz]) -> f64 {
    let mut extent = 0.0_f64;
    for a in 0..3 {
        let (lo, hi) = points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p[a]), hi.max(p[a]))
            });
        // Half-extents, so that ±f64::MAX does not overflow the subtraction.
        extent = extent.max(0.5 * hi - 0.5 * lo);
    }
    scale_of_half_extent(extent)
}

/// The power of two for a bounding box whose larger side is `2·extent`.
fn scale_of_half_extent(extent: f64) -> f64 {
    if !(extent.is_finite() && extent > 0.0) {
        return 1.0;
    }
    // extent is half the larger side; clamp the exponent so that the scale and its
    // reciprocal are both normal numbers.
    let exp = (extent.log2() + 1.0).round().clamp(-1021.0, 1021.0);
    pow2(exp as i32)
}

/// `2^k` for `|k| ≤ 1021`, exactly.
pub fn pow2(k: i32) -> f64 {
    f64::from_bits(((1023 + i64::from(k)) as u64) << 52)
}

/// The points multiplied by `factor` (exact when `factor` is a power of two and no result
/// over- or underflows).
pub fn scale_points(points: &[Point], factor: f64) -> Vec<Point> {
    points
        .iter()
        .map(|p| Point::new(p.x * factor, p.y * factor))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pow2_is_exact() {
        assert_eq!(pow2(0), 1.0);
        assert_eq!(pow2(10), 1024.0);
        assert_eq!(pow2(-3), 0.125);
        assert_eq!(pow2(1021), 2f64.powi(1021));
        assert_eq!(pow2(-1021), 2f64.powi(-1021));
    }

    #[test]
    fn unit_scale_brings_the_larger_side_near_one() {
        for k in [-300, -120, -1, 0, 1, 50, 155, 300] {
            let s = 10f64.powi(k);
            let pts = [Point::new(0.0, 0.0), Point::new(3.0 * s, 1.0 * s)];
            let u = unit_scale(&pts);
            let side = 3.0 * s / u;
            assert!((0.7..=1.42).contains(&side), "k = {k}: side {side}");
            let back = scale_points(&scale_points(&pts, 1.0 / u), u);
            assert_eq!(back, pts.to_vec());
        }
        assert_eq!(unit_scale(&[Point::new(1.0, 1.0)]), 1.0);
        assert_eq!(unit_scale(&[]), 1.0);
        let huge = [Point::new(-f64::MAX, 0.0), Point::new(f64::MAX, 1.0)];
        assert!(unit_scale(&huge).is_finite());
    }
}
