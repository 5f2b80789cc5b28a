//! The sign tests of HAN's cases, `sgn0` with the relative zero of docs/algorithms/han.md §1.7.0
//! and the rounding-noise floors, kept exact under local updates (`docs/algorithms/han.md`, "Sign
//! tests").

use super::responses::Changed;
use crate::analysis::{ZERO_REL, sgn0};

/// `sgn0(v, max_k |v_k|)` (docs/algorithms/han.md §1.7.0) for an array under local updates, without
/// keeping the maximum itself exact: an upper bound (raised by every written value) and a lower
/// bound (the magnitude of one tracked entry) decide almost every test; only a value between
/// `ZERO_REL·lower` and `ZERO_REL·upper` needs the exact maximum, which is then rescanned and
/// both bounds are reset to it. The result is the same as with the exact maximum.
#[derive(Clone, Debug)]
pub(super) struct SignScale {
    /// At least max |v_k|.
    upper: f64,
    /// `|v[at]|`, so at most max |v_k|.
    lower: f64,
    at: usize,
    /// Number of full rescans (for tests and tuning).
    rescans: usize,
}

impl SignScale {
    pub(super) fn new(values: &[f64]) -> SignScale {
        let (at, m) = abs_argmax(values);
        SignScale {
            upper: m,
            lower: m,
            at,
            rescans: 0,
        }
    }

    /// The entries `w.lo..=w.hi` of `values` were rewritten.
    pub(super) fn wrote(&mut self, values: &[f64], w: Changed) {
        if w.max > self.upper {
            self.upper = w.max;
        }
        if (w.lo..=w.hi).contains(&self.at) {
            self.lower = values[self.at].abs();
        }
        if w.max > self.lower {
            self.lower = w.max;
            self.at = w.lo + abs_argmax(&values[w.lo..=w.hi]).0;
        }
    }

    /// `sgn0(values[i], max |values|)`, and 0 when `|values[i]| ≤ floor[i]`.
    #[inline]
    pub(super) fn sign(&mut self, values: &[f64], floor: &[f64], i: usize) -> i8 {
        let v = values[i];
        let a = v.abs();
        if a <= ZERO_REL * self.lower || a <= floor[i] {
            return 0;
        }
        if a > ZERO_REL * self.upper {
            return if v > 0.0 { 1 } else { -1 };
        }
        self.rescan(values);
        sgn0(v, self.upper)
    }

    #[cold]
    fn rescan(&mut self, values: &[f64]) {
        let (at, m) = abs_argmax(values);
        self.upper = m;
        self.lower = m;
        self.at = at;
        self.rescans += 1;
    }
}

/// The index and magnitude of the largest |v| of a slice of finite values ((0, 0) when empty).
pub(super) fn abs_argmax(v: &[f64]) -> (usize, f64) {
    let m = abs_max(v);
    (v.iter().position(|x| x.abs() == m).unwrap_or(0), m)
}

/// max |v| of a slice of finite values (0 for an empty one), with independent accumulators so
/// that the reduction vectorises; max is exact, so the order does not matter. A plain
/// comparison replaces `f64::max`, whose NaN handling costs here and is not needed.
pub(super) fn abs_max(v: &[f64]) -> f64 {
    let bigger = |m: f64, x: f64| if x > m { x } else { m };
    let mut acc = [0.0_f64; 4];
    let mut chunks = v.chunks_exact(4);
    for ch in &mut chunks {
        for (a, x) in acc.iter_mut().zip(ch) {
            *a = bigger(*a, x.abs());
        }
    }
    let tail = chunks
        .remainder()
        .iter()
        .fold(0.0_f64, |m, x| bigger(m, x.abs()));
    acc.iter().fold(tail, |m, a| bigger(m, *a))
}

/// `#{i : sgn0(v_i)·sgn0(v_{i+1}) < 0}`, with values at or below their floor counted as 0.
pub(super) fn count_strict_changes(v: &[f64], floor: &[f64], scale: f64) -> usize {
    let sign = |i: usize| {
        if v[i].abs() <= floor[i] {
            0
        } else {
            sgn0(v[i], scale)
        }
    };
    (1..v.len()).filter(|&i| sign(i - 1) * sign(i) < 0).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sign_scale_agrees_with_the_exact_maximum() {
        // Random local rewrites, some to values right at ZERO_REL times the maximum: every
        // sign equals sgn0 with the exact maximum, and rescans stay rare.
        let n = 300;
        let mut state = 12345_u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            state >> 11
        };
        let mut v: Vec<f64> = (0..n).map(|_| (next() % 2000) as f64 - 1000.0).collect();
        let mut sc = SignScale::new(&v);
        let mut checks = 0;
        let no_floor = vec![0.0; n];
        for round in 0..5000 {
            let lo = next() as usize % n;
            let hi = (lo + next() as usize % 20).min(n - 1);
            let exact_before = abs_max(&v);
            for i in lo..=hi {
                let r = next();
                v[i] = match r % 5 {
                    0 => 0.0,
                    1 => ZERO_REL * exact_before * if r % 2 == 0 { 1.0 } else { -1.0 },
                    2 => ZERO_REL * exact_before * 1.5,
                    _ => ((r >> 8) % 2000) as f64 * 0.37 * (1.0 + (round % 7) as f64) - 400.0,
                };
            }
            sc.wrote(&v, Changed::of(&v, lo, hi));
            let exact = abs_max(&v);
            for _ in 0..5 {
                let i = next() as usize % n;
                assert_eq!(
                    sc.sign(&v, &no_floor, i),
                    sgn0(v[i], exact),
                    "round {round}, index {i}"
                );
                checks += 1;
            }
            assert!(sc.lower <= exact && exact <= sc.upper);
        }
        assert!(sc.rescans < checks / 2, "{} rescans", sc.rescans);
        let mut zeros = SignScale::new(&[0.0, 0.0]);
        assert_eq!(zeros.sign(&[0.0, 0.0], &[0.0, 0.0], 1), 0);
        let mut floored = SignScale::new(&[1.0, 1e-3]);
        assert_eq!(floored.sign(&[1.0, 1e-3], &[0.0, 1e-3], 1), 0);
        assert_eq!(floored.sign(&[1.0, 1e-3], &[0.0, 0.5e-3], 1), 1);
    }
}
