//! What every trial of the smoothing spline's searches measures (see [`super`]):
//! the largest displacement of the points, which decides the tolerance search, and the
//! roughness, which the report's history prints. Both as the fairing report measures them,
//! bit for bit, and both cheap, since the search measures 5–20 trials (issue #17).

/// `a · b` (in 2-D as [`crate::geom::Vec2::dot`], bit for bit).
pub(super) fn dot<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    (1..D).fold(a[0] * b[0], |s, k| s + a[k] * b[k])
}

/// The distance `|a − b|` by `hypot`, as the fairing report measures it (in 2-D
/// [`crate::geom::Point::distance`] bit for bit).
fn distance<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    (1..D).fold((b[0] - a[0]).abs(), |s, k| s.hypot(b[k] - a[k]))
}

/// Relative margin of [`max_displacement`]'s shortlist: a point whose squared distance (a sum
/// of squares, a few ulps from the exact value) is within this fraction of the largest one
/// gets its `hypot` distance (within an ulp or two of the exact one) measured. Both errors are
/// below `8ε ≈ 2·10⁻¹⁵`, so every point that can hold the largest `hypot` is on the list.
const SHORTLIST_MARGIN: f64 = 1e-9;

/// Below this largest squared distance [`max_displacement`] measures every point: squares of
/// subnormal size lose their relative precision, which the shortlist's margin assumes.
const SHORTLIST_MIN_SQUARED: f64 = f64::MIN_POSITIVE / f64::EPSILON;

/// The largest `|g_i − y_i|`, measured as the fairing report measures it (`hypot`, see
/// [`distance`]), bit for bit. The largest squared distance is found first (no `hypot`, which
/// cost a third of a tolerance search, issue #17), then only the points within
/// [`SHORTLIST_MARGIN`] of it are measured; non-finite or tiny sums of squares fall back to
/// measuring every point.
pub(super) fn max_displacement<const D: usize>(y: &[[f64; D]], g: &[[f64; D]]) -> f64 {
    let squared = |a: &[f64; D], b: &[f64; D]| {
        (1..D).fold((b[0] - a[0]) * (b[0] - a[0]), |s, k| {
            s + (b[k] - a[k]) * (b[k] - a[k])
        })
    };
    let all = || {
        y.iter()
            .zip(g)
            .map(|(a, b)| distance(a, b))
            .fold(0.0, f64::max)
    };
    let (mut largest, mut total) = (0.0_f64, 0.0);
    for (a, b) in y.iter().zip(g) {
        let s = squared(a, b);
        largest = largest.max(s);
        total += s;
    }
    if !(total.is_finite() && largest >= SHORTLIST_MIN_SQUARED) {
        return all();
    }
    let floor = largest * (1.0 - SHORTLIST_MARGIN);
    y.iter()
        .zip(g)
        .filter(|(a, b)| squared(a, b) >= floor)
        .map(|(a, b)| distance(a, b))
        .fold(0.0, f64::max)
}

/// `∫ |C''|² dt` for C'' piecewise linear through `second` at the knots `t`.
pub(crate) fn roughness<const D: usize>(t: &[f64], second: &[[f64; D]], closed: bool) -> f64 {
    let span = |h: f64, a: &[f64; D], b: &[f64; D]| h * (dot(a, a) + dot(a, b) + dot(b, b)) / 3.0;
    let open = t
        .windows(2)
        .zip(second.windows(2))
        .map(|(t, c)| span(t[1] - t[0], &c[0], &c[1]));
    // A closed curve's last span returns to the first knot.
    let wrap = match (closed, second.first(), second.last()) {
        (true, Some(first), Some(last)) => {
            let n = second.len();
            Some(span(t[n] - t[n - 1], last, first))
        }
        _ => None,
    };
    open.chain(wrap).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plain measure: every point's `hypot`.
    fn every_point<const D: usize>(y: &[[f64; D]], g: &[[f64; D]]) -> f64 {
        y.iter()
            .zip(g)
            .map(|(a, b)| distance(a, b))
            .fold(0.0, f64::max)
    }

    /// A deterministic generator of numbers in [0, 1).
    fn uniform(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// The shortlist gives the plain measure's bits: random displacements at scales from
    /// 1e-300 to 1e300, near-ties (many points at one distance, in different directions),
    /// zeros, and non-finite values, in 2-D and 3-D.
    #[test]
    fn max_displacement_is_every_points_hypot() {
        let mut next = uniform(17);
        for case in 0..3000 {
            let n = 1 + (next() * 60.0) as usize;
            let scale = 10f64.powf(600.0 * next() - 300.0);
            let tie = case % 3 == 0;
            let y2: Vec<[f64; 2]> = (0..n).map(|_| [next() - 0.5, next() - 0.5]).collect();
            let g2: Vec<[f64; 2]> = y2
                .iter()
                .map(|p| {
                    let a = std::f64::consts::TAU * next();
                    let r = if tie { scale } else { scale * next() };
                    [p[0] + r * a.cos(), p[1] + r * a.sin()]
                })
                .collect();
            assert_eq!(
                max_displacement(&y2, &g2).to_bits(),
                every_point(&y2, &g2).to_bits(),
                "case {case}"
            );
            let y3: Vec<[f64; 3]> = y2.iter().map(|p| [p[0], p[1], next()]).collect();
            let g3: Vec<[f64; 3]> = g2
                .iter()
                .zip(&y3)
                .map(|(g, y)| [g[0], g[1], y[2] + scale * (next() - 0.5)])
                .collect();
            assert_eq!(
                max_displacement(&y3, &g3).to_bits(),
                every_point(&y3, &g3).to_bits(),
                "case {case} (3-D)"
            );
        }
        let y = [[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]];
        for g in [
            [[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]],
            [[0.0, 0.0], [f64::NAN, 1.0], [2.0, 2.5]],
            [[0.0, 0.0], [f64::INFINITY, f64::NAN], [2.0, 2.5]],
            [[1e300, 0.0], [1.0, -1e300], [2.0, 2.5]],
            [[5e-324, 0.0], [1.0, 1.0], [2.0, 2.0]],
        ] {
            assert_eq!(
                max_displacement(&y, &g).to_bits(),
                every_point(&y, &g).to_bits(),
                "{g:?}"
            );
        }
    }

    /// The roughness of the piecewise linear C'' against its closed form: C'' = c (constant)
    /// over [0, L] gives |c|²L; open and closed (the closing span counts).
    #[test]
    fn roughness_of_constant_second_derivative() {
        let t = [0.0, 0.5, 1.25, 2.0];
        let c = [[3.0, -4.0]; 4];
        assert_eq!(roughness(&t, &c, false), 25.0 * 2.0);
        assert_eq!(roughness(&t, &c[..3], true), 25.0 * 2.0);
        assert_eq!(roughness::<2>(&[0.0], &[], false), 0.0);
    }
}
