//! Numbers rounded for people: tables, notes and captions (not for data, which
//! [`super::format_f64`] writes exactly).

/// `x` with `digits` significant digits (at least one): fixed notation for magnitudes in
/// `[1e-3, 1e6)` (`0.08427`, `-123.5`, `123456`), exponent notation otherwise (`1.500e9`,
/// `2.5e-7`). Zero is `0`; non-finite values are `inf`, `-inf` and `NaN`.
///
/// ```
/// use batten::io::format_sig;
/// assert_eq!(format_sig(0.084_271_9, 4), "0.08427");
/// assert_eq!(format_sig(1.5e9, 4), "1.500e9");
/// ```
pub fn format_sig(x: f64, digits: usize) -> String {
    if !x.is_finite() {
        return x.to_string();
    }
    if x == 0.0 {
        return "0".to_string();
    }
    let digits = digits.max(1);
    let exp = x.abs().log10().floor();
    if (-3.0..6.0).contains(&exp) {
        // exp is a small integer here, so the conversion is exact.
        let decimals = (digits as f64 - 1.0 - exp).max(0.0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.prec$e}", prec = digits - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::format_sig as sig;

    #[test]
    fn significant_digits() {
        assert_eq!(sig(0.0, 4), "0");
        assert_eq!(sig(1.23456, 4), "1.235");
        assert_eq!(sig(-123.456, 4), "-123.5");
        assert_eq!(sig(0.0012345, 3), "0.00123");
        assert_eq!(sig(1.5e9, 4), "1.500e9");
        assert_eq!(sig(2.5e-7, 2), "2.5e-7");
        assert_eq!(sig(123456.0, 4), "123456");
        assert_eq!(sig(1234567.0, 4), "1.235e6");
        assert_eq!(sig(f64::INFINITY, 4), "inf");
        assert_eq!(sig(f64::NAN, 4), "NaN");
        assert_eq!(sig(3.0, 0), "3");
    }
}
