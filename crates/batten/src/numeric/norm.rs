//! The Euclidean length of a short vector, fast where that is safe.

/// `|a|`: `√(Σ a_k²)` where the sum of squares neither overflows nor comes near the
/// underflow ([`SQUARES_SAFE_FROM`]), `hypot` otherwise. Both are within an ulp of the exact
/// length, but not always the same ulp: `hypot`, which scales its arguments to be safe
/// everywhere, took a fifth of the noise estimate's time at 10⁶ points. For lengths that
/// choose or estimate something (a median spacing, a noise scale). Where a length must agree
/// bit for bit with one measured elsewhere (a distance checked against the tolerance, the
/// chords that give a curve its parameters), use that measure. A vector in the plane
/// `z = 0` of space has the length of the planar one, bit for bit (the square of 0 adds
/// nothing).
pub(crate) fn norm<const D: usize>(a: &[f64; D]) -> f64 {
    let squares = a.iter().fold(0.0, |s, v| s + v * v);
    if (SQUARES_SAFE_FROM..f64::INFINITY).contains(&squares) {
        squares.sqrt()
    } else {
        (1..D).fold(a[0].abs(), |s, k| s.hypot(a[k]))
    }
}

/// The smallest sum of squares [`norm`] takes the square root of (`2⁻⁹⁰⁰`). Above it the
/// sum is a normal number, and a component whose square underflows (below `2⁻¹⁰²²`) is
/// shorter than the length by a factor `2⁻⁶¹` at least, so it would not change it.
const SQUARES_SAFE_FROM: f64 = f64::from_bits((1023 - 900) << 52);

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn norm_is_hypot_within_an_ulp_at_any_scale() {
        // A fixed spread of components, signs and ratios.
        let e: Vec<f64> = (0..4000)
            .map(|i| ((i * 7919 % 4001) as f64 / 4001.0 - 0.5) * (1.0 + (i % 13) as f64))
            .collect();
        let ulp = |v: f64| f64::from_bits(v.to_bits() + 1) - v;
        for k in -320..=307 {
            let s = 10f64.powi(k);
            for w in e.chunks(2) {
                let (x, y) = (w[0] * s, w[1] * s);
                let exact = x.hypot(y);
                let got = norm(&[x, y]);
                assert!(
                    (got - exact).abs() <= ulp(exact),
                    "{x:e} {y:e}: {got:e} vs {exact:e}"
                );
                // A planar vector in space has the planar length, bit for bit.
                assert_eq!(norm(&[x, y, 0.0]).to_bits(), got.to_bits());
            }
        }
        assert_eq!(norm(&[f64::MAX, f64::MAX]), f64::MAX.hypot(f64::MAX));
        assert_eq!(norm(&[3e-320, 4e-320]), 3e-320_f64.hypot(4e-320));
        assert_eq!(norm(&[0.0, -0.0]), 0.0);
    }
}
