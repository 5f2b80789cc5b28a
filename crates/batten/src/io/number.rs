//! Numbers as the point writers print them: the shortest decimal text that reads back as the
//! same `f64`, laid out as Rust's `Display` (`0.1`, `-2.5`, `-0`) for magnitudes in
//! `[1e-5, 1e16)` and zeros, and as `LowerExp` (`1e300`, `5e-324`) for all others.
//!
//! The digits come from [`zmij`] (Schubfach: the shortest digit string that rounds back to
//! the value, the closest to it among those), which the standard formatter also computes
//! (Grisu with a Dragon4 fallback) in several times the time: at 10⁶ points the writer spent
//! more on formatting than `mst` on its fit (issue #14). The two choose the same digits but
//! for one case: a value exactly halfway between two shortest candidates (such as
//! `100000000000000.125`, 17 digits either way), where zmij rounds the last digit to even and
//! the standard formatter up. [`is_tie`] finds that case exactly, in integers, and leaves it
//! to the standard formatter, so the text is the standard formatter's, byte for byte (tested
//! on every class of value and on random ones).

use std::fmt::Write as _;

/// The most significant digits a shortest `f64` representation needs.
const MAX_DIGITS: usize = 17;

/// The shortest decimal text that reads back (with `f64::from_str`) as exactly `x`.
///
/// Rust's `Display` for `f64` prints the shortest digit string that round-trips, but never
/// in exponent form, so `1e300` would take 301 characters; `LowerExp` prints the same digits
/// with an exponent. Numbers of magnitude in `[1e-5, 1e16)` (and zeros) use `Display`
/// (`0.1`, `-2.5`, `-0`), all others `LowerExp` (`1e300`, `5e-324`). Both are exact.
/// Non-finite values are the caller's to reject.
pub fn format_f64(x: f64) -> String {
    let mut s = String::new();
    push_f64(&mut s, x);
    s
}

/// [`format_f64`], appended to `out` without an intermediate string.
pub(crate) fn push_f64(out: &mut String, x: f64) {
    let a = x.abs();
    let fixed = a == 0.0 || (1e-5..1e16).contains(&a);
    if x != 0.0 && x.is_finite() {
        let mut buffer = zmij::Buffer::new();
        let text = buffer.format_finite(x);
        if fixed {
            // zmij's fixed form (decimal exponents −5..=15, the same range) is `Display`'s,
            // but for the `.0` of a whole number.
            if let Some((int, frac)) = text.split_once('.') {
                let whole = frac == "0";
                let (digits, k) = if whole {
                    let zeros = int.len() - int.trim_end_matches('0').len();
                    (int.trim_end_matches('0'), zeros as i32)
                } else {
                    (text, -(frac.len() as i32))
                };
                if !is_tie(x, digits, k) {
                    out.push_str(if whole { int } else { text });
                    return;
                }
            }
        } else if let Some((digits, exp)) = shortest(text) {
            let d = digits.as_str();
            if !is_tie(x, d, exp - (d.len() as i32 - 1)) {
                if x < 0.0 {
                    out.push('-');
                }
                out.push_str(&d[..1]);
                if d.len() > 1 {
                    out.push('.');
                    out.push_str(&d[1..]);
                }
                // An i32 is never written with an error into a String.
                let _ = write!(out, "e{exp}");
                return;
            }
        }
    }
    // Zeros, non-finite values and ties, as the standard formatter prints them. Writing to a
    // String cannot fail.
    let _ = if fixed {
        write!(out, "{x}")
    } else {
        write!(out, "{x:e}")
    };
}

/// The significant digits (no leading or trailing zeros) of zmij's `text` for a finite
/// non-zero number, and the decimal exponent of the first: `±d₁.d₂…dₙ × 10^exp`.
fn shortest(text: &str) -> Option<(Digits, i32)> {
    // `[-]ddd.ddd` or `[-]d[.ddd]e±dd`.
    let text = text.strip_prefix('-').unwrap_or(text);
    let (mantissa, exponent) = match text.split_once('e') {
        Some((m, e)) => (m, e.parse::<i32>().ok()?),
        None => (text, 0),
    };
    let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    let mut digits = Digits::default();
    let mut first = None;
    for (i, c) in int.bytes().chain(frac.bytes()).enumerate() {
        if !c.is_ascii_digit() {
            return None;
        }
        if first.is_none() && c != b'0' {
            first = Some(i);
        }
        if first.is_some() {
            digits.push(c)?;
        }
    }
    digits.trim_zeros();
    Some((digits, exponent + int.len() as i32 - 1 - first? as i32))
}

/// Whether the finite non-zero `x` lies exactly halfway between its shortest representation
/// and a neighbour one unit away in the last digit: then the two are equally close and the
/// standard formatter may choose the other. The representation is `D·10^k`, `D` the digits
/// of `digits` (a sign, a point and leading zeros are skipped; no trailing zeros).
///
/// The halfway points are `(2D ± 1)·10^k / 2 = (2D ± 1)·5^k·2^(k−1)`, and `x = m·2^E` (`m`
/// odd, below 2⁵³). For `k ≥ 0` they are equal when `E = k − 1` and `m = (2D ± 1)·5^k`; for
/// `k < 0` when `5^−k` divides `2D ± 1`, `E = k − 1` and `m = (2D ± 1)/5^−k`. Almost every
/// number fails the first test, which needs no digits.
fn is_tie(x: f64, digits: &str, k: i32) -> bool {
    let bits = x.to_bits();
    let (field, biased) = (bits & ((1 << 52) - 1), ((bits >> 52) & 0x7ff) as i32);
    let (mut m, mut e) = if biased == 0 {
        (field, -1074)
    } else {
        (field | (1 << 52), biased - 1075)
    };
    let zeros = m.trailing_zeros();
    m >>= zeros;
    e += zeros as i32;
    if e != k - 1 {
        return false;
    }
    let big_d = digits
        .bytes()
        .filter(u8::is_ascii_digit)
        .fold(0_u128, |v, c| 10 * v + u128::from(c - b'0'));
    let m = u128::from(m);
    [2 * big_d - 1, 2 * big_d + 1].into_iter().any(|odd| {
        if k >= 0 {
            // (2D ± 1)·5^k, or more than 2⁵³ (no tie) when it overflows.
            (0..k).try_fold(odd, |v, _| v.checked_mul(5)) == Some(m)
        } else {
            let p = (0..-k).try_fold(1_u128, |v, _| v.checked_mul(5));
            p.is_some_and(|p| odd % p == 0 && odd / p == m)
        }
    })
}

/// Up to [`MAX_DIGITS`] decimal digits, on the stack.
#[derive(Default)]
struct Digits {
    bytes: [u8; MAX_DIGITS],
    len: usize,
}

impl Digits {
    /// Append a digit; `None` past [`MAX_DIGITS`] (not a shortest representation).
    fn push(&mut self, c: u8) -> Option<()> {
        *self.bytes.get_mut(self.len)? = c;
        self.len += 1;
        Some(())
    }

    /// Drop trailing zeros (zmij writes `1234000.0` for a whole number).
    fn trim_zeros(&mut self) {
        while self.len > 1 && self.bytes[self.len - 1] == b'0' {
            self.len -= 1;
        }
    }

    fn as_str(&self) -> &str {
        // Only ASCII digits are pushed.
        std::str::from_utf8(&self.bytes[..self.len]).unwrap_or("0")
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// The standard formatter's text, as the writer printed it before.
    fn standard(x: f64) -> String {
        let a = x.abs();
        if a == 0.0 || (1e-5..1e16).contains(&a) {
            format!("{x}")
        } else {
            format!("{x:e}")
        }
    }

    /// Every class of value: zeros, subnormals, the largest and smallest, powers of ten and
    /// two and their neighbours, the edges of the plain range, and whole numbers.
    fn classes() -> Vec<f64> {
        let mut v = vec![
            0.0,
            -0.0,
            f64::MIN_POSITIVE,
            f64::MAX,
            f64::MIN,
            f64::EPSILON,
            5e-324,
            1e-5,
            1e16,
            9_999_999_999_999_998.0,
            0.1,
            -2.5,
            123_456_789.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for e in -323..=308 {
            let p = format!("1e{e}").parse::<f64>().unwrap();
            for x in [
                p,
                -p,
                9.999_999_999_999_999 * p,
                1.000_000_000_000_001 * p,
                3.0 * p,
            ] {
                v.extend([
                    x,
                    f64::from_bits(x.to_bits() + 1),
                    f64::from_bits(x.to_bits() - 1),
                ]);
            }
        }
        // 2^e, subnormal below e = −1022.
        for e in -1074..=1023_i64 {
            let bits = if e >= -1022 {
                ((e + 1023) as u64) << 52
            } else {
                1 << (e + 1074)
            };
            v.extend([bits, bits + 1, bits - 1].map(f64::from_bits));
        }
        v
    }

    #[test]
    fn same_text_as_the_standard_formatter() {
        for x in classes() {
            assert_eq!(format_f64(x), standard(x), "{:#x}", x.to_bits());
        }
        // Random bit patterns (every exponent) and random values of point-file size.
        let mut state = 0x9E37_79B9_7F4A_7C15_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for _ in 0..200_000 {
            let x = f64::from_bits(next());
            assert_eq!(format_f64(x), standard(x), "{:#x}", x.to_bits());
            let y = (next() >> 11) as f64 / (1u64 << 53) as f64 * 2000.0 - 1000.0;
            assert_eq!(format_f64(y), standard(y), "{:#x}", y.to_bits());
        }
    }
}
