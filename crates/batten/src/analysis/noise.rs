//! A robust estimate of the noise in sampled points, for `--tolerance auto`.
//!
//! The third difference `Δ³p_i = p_{i+3} − 3p_{i+2} + 3p_{i+1} − p_i` of a smooth curve
//! sampled densely is small (`h³ C'''`), while independent noise of standard deviation `σ`
//! in each coordinate gives it a standard deviation of `σ·√20` per coordinate (the squared
//! binomial coefficients 1, 9, 9, 1 add up to 20). Only the component along the local normal
//! is used: the chord `p_{i+3} − p_i` turned by 90° gives the normal, and the tangential
//! component of `Δ³p` holds the curve's own `h³ C'''`, which for a curve turning steadily
//! (a circle) is not small. The estimate is the median absolute deviation of that normal
//! component, `σ̂ = 1.4826 · median |n_i · Δ³p_i| / √20` (1.4826 makes the MAD a consistent
//! estimator of σ for Gaussian noise).
//!
//! A MAD pooled over both coordinates underestimates noise that lies in one coordinate only
//! (the bundled `sine-noisy.csv`, noise in y: 0.0045 against a true 0.03); projected on the
//! normal it gives 0.033. See `docs/algorithms/band.md`.

use crate::geom::{Point, Vec2};

/// The MAD-to-σ factor for Gaussian noise.
pub const MAD_TO_SIGMA: f64 = 1.482_6;

/// The standard deviation of a third difference of unit-variance independent noise: √20.
const THIRD_DIFFERENCE_GAIN: f64 = 4.472_135_954_999_579;

/// How long the chord that gives the local normal must be, in units of a rough noise scale:
/// where the noise is as large as the point spacing (dense scans), the chord over four points
/// points anywhere, and the projection would hide the noise. The chord is widened
/// symmetrically until it spans about this many rough noise scales.
const NORMAL_CHORD_NOISE_SPANS: f64 = 20.0;

/// The noise estimate σ̂ of the points `pts` (per coordinate, in data units), from the third
/// differences along the local normal. Closed curves wrap around. Returns 0 for fewer than
/// four points or where every normal component vanishes (points on a line, exact samples of
/// a parabola).
///
/// The normal at a third difference `p_i … p_{i+3}` is that of the chord `p_{i+3+m} −
/// p_{i−m}` (indices clamped at the ends of an open curve), with `m = 0` unless the noise is
/// comparable to the point spacing: `m` is chosen so the chord spans about
/// [`NORMAL_CHORD_NOISE_SPANS`] times a rough noise scale (the same MAD taken over the whole
/// third-difference vectors, an overestimate) — at most an eighth of the points.
pub fn noise_sigma(pts: &[Point], closed: bool) -> f64 {
    let n = pts.len();
    if n < 4 {
        return 0.0;
    }
    let count = if closed { n } else { n - 3 };
    let at = |i: isize| -> Point {
        if closed {
            pts[i.rem_euclid(n as isize) as usize]
        } else {
            pts[i.clamp(0, n as isize - 1) as usize]
        }
    };
    let third = |i: usize| -> Vec2 {
        let i = i as isize;
        let (p0, p1, p2, p3) = (at(i), at(i + 1), at(i + 2), at(i + 3));
        Vec2::new(
            p3.x - 3.0 * p2.x + 3.0 * p1.x - p0.x,
            p3.y - 3.0 * p2.y + 3.0 * p1.y - p0.y,
        )
    };
    let rough = median((0..count).map(|i| third(i).length()).collect()) * MAD_TO_SIGMA
        / THIRD_DIFFERENCE_GAIN;
    let spacing = median(
        (0..if closed { n } else { n - 1 })
            .map(|i| (at(i as isize + 1) - at(i as isize)).length())
            .collect(),
    );
    let reach = if spacing > 0.0 {
        let m = (NORMAL_CHORD_NOISE_SPANS * rough / spacing).ceil();
        if m.is_finite() {
            (m as usize).min(n / 8)
        } else {
            0
        }
    } else {
        0
    };
    let normal_parts: Vec<f64> = (0..count)
        .filter_map(|i| {
            let chord = at(i as isize + 3 + reach as isize) - at(i as isize - reach as isize);
            let len = chord.length();
            (len > 0.0).then(|| third(i).cross(chord).abs() / len)
        })
        .collect();
    MAD_TO_SIGMA * median(normal_parts) / THIRD_DIFFERENCE_GAIN
}

/// The median of `v` (the upper one for an even count; 0 when empty).
fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// A deterministic pseudo-random normal sample (Box–Muller over a small LCG).
    fn gaussian(seed: u64, count: usize) -> Vec<f64> {
        let mut s = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
        let mut uniform = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        (0..count)
            .map(|_| {
                let (u, v) = (uniform(), uniform());
                (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
            })
            .collect()
    }

    #[test]
    fn exact_line_and_parabola_have_no_noise() {
        let line: Vec<Point> = (0..20)
            .map(|i| Point::new(i as f64, 2.0 * i as f64))
            .collect();
        assert_eq!(noise_sigma(&line, false), 0.0);
        let parabola: Vec<Point> = (0..20)
            .map(|i| Point::new(i as f64, (i * i) as f64 * 0.1))
            .collect();
        assert!(noise_sigma(&parabola, false) < 1e-12);
    }

    #[test]
    fn recovers_noise_in_one_coordinate() {
        // A shallow sine sampled at 2000 points, closer than the noise (0.005 against 0.03),
        // with noise in y only: the estimate is within 10 % of the truth (a pooled MAD gives
        // about a third of it). The estimate is of the noise along the normal, so the sine is
        // shallow (slope at most 0.2), where the normal is nearly y.
        let sigma = 0.03;
        let e = gaussian(7, 2000);
        let pts: Vec<Point> = (0..2000)
            .map(|i| {
                let x = i as f64 * 0.005;
                Point::new(x, 0.2 * x.sin() + sigma * e[i])
            })
            .collect();
        let est = noise_sigma(&pts, false);
        assert!((est / sigma - 1.0).abs() < 0.1, "σ̂ = {est}");
    }

    #[test]
    fn isotropic_noise_on_a_closed_circle() {
        let sigma = 1e-3;
        let (ex, ey) = (gaussian(1, 3000), gaussian(2, 3000));
        let pts: Vec<Point> = (0..3000)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / 3000.0;
                Point::new(a.cos() + sigma * ex[i], a.sin() + sigma * ey[i])
            })
            .collect();
        let est = noise_sigma(&pts, true);
        assert!((est / sigma - 1.0).abs() < 0.1, "σ̂ = {est}");
    }

    #[test]
    fn scales_with_the_data_and_ignores_rigid_motion() {
        let e = gaussian(3, 500);
        let pts: Vec<Point> = (0..500)
            .map(|i| Point::new(i as f64 * 0.01, (i as f64 * 0.01).cos() + 0.01 * e[i]))
            .collect();
        let base = noise_sigma(&pts, false);
        let (c, s) = (0.6_f64, 0.8_f64);
        let moved: Vec<Point> = pts
            .iter()
            .map(|p| {
                Point::new(
                    1e3 * (c * p.x - s * p.y) + 5.0,
                    1e3 * (s * p.x + c * p.y) - 2.0,
                )
            })
            .collect();
        let est = noise_sigma(&moved, false);
        assert!(
            (est / (1e3 * base) - 1.0).abs() < 1e-6,
            "{est} vs {}",
            1e3 * base
        );
    }

    #[test]
    fn too_few_points() {
        let pts = [
            Point::new(0.0, 0.0),
            Point::new(1.0, 0.0),
            Point::new(2.0, 1.0),
        ];
        assert_eq!(noise_sigma(&pts, false), 0.0);
    }
}
