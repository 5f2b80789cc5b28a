use super::{Linear, PIVOT_REL};
use crate::error::{Error, Result};

/// Solve the tridiagonal system `sub[i] x[i-1] + diag[i] x[i] + sup[i] x[i+1] = rhs[i]` in place
/// (the Thomas algorithm, O(n)). `sub[0]` and `sup[n-1]` are ignored.
///
/// No pivoting: meant for the diagonally dominant systems of spline interpolation.
///
/// # Errors
/// [`Error::LengthMismatch`] for inconsistent lengths, [`Error::Singular`] for a zero pivot.
pub fn solve_tridiagonal<T: Linear>(
    sub: &[f64],
    diag: &[f64],
    sup: &[f64],
    rhs: &mut [T],
) -> Result<()> {
    let n = diag.len();
    check_len("sub", sub.len(), n)?;
    check_len("sup", sup.len(), n)?;
    check_len("rhs", rhs.len(), n)?;
    if n == 0 {
        return Ok(());
    }
    let scale = diag
        .iter()
        .fold(0.0_f64, |m, d| m.max(d.abs()))
        .max(f64::MIN_POSITIVE);
    let mut c = vec![0.0; n];
    let mut beta = diag[0];
    if beta.abs() <= PIVOT_REL * scale {
        return Err(Error::Singular("zero pivot in tridiagonal solve".into()));
    }
    rhs[0] = rhs[0] * (1.0 / beta);
    for i in 1..n {
        c[i - 1] = sup[i - 1] / beta;
        beta = diag[i] - sub[i] * c[i - 1];
        if beta.abs() <= PIVOT_REL * scale || !beta.is_finite() {
            return Err(Error::Singular("zero pivot in tridiagonal solve".into()));
        }
        rhs[i] = (rhs[i] - rhs[i - 1] * sub[i]) * (1.0 / beta);
    }
    for i in (0..n - 1).rev() {
        rhs[i] = rhs[i] - rhs[i + 1] * c[i];
    }
    Ok(())
}

/// Solve a cyclic tridiagonal system: as [`solve_tridiagonal`] plus the corner entries
/// `sub[0]` (row 0, column n−1) and `sup[n-1]` (row n−1, column 0), by the Sherman–Morrison
/// formula (two tridiagonal solves, O(n)). Needs n ≥ 3.
///
/// # Errors
/// As [`solve_tridiagonal`]; [`Error::TooFewPoints`] for n < 3.
pub fn solve_cyclic_tridiagonal<T: Linear>(
    sub: &[f64],
    diag: &[f64],
    sup: &[f64],
    rhs: &mut [T],
) -> Result<()> {
    let n = diag.len();
    if n < 3 {
        return Err(Error::TooFewPoints { needed: 3, got: n });
    }
    check_len("sub", sub.len(), n)?;
    check_len("sup", sup.len(), n)?;
    check_len("rhs", rhs.len(), n)?;
    let alpha = sup[n - 1]; // A[n-1][0]
    let beta = sub[0]; // A[0][n-1]
    let gamma = -diag[0];
    let mut d = diag.to_vec();
    d[0] -= gamma;
    d[n - 1] -= alpha * beta / gamma;
    solve_tridiagonal(sub, &d, sup, rhs)?;
    let mut u = vec![0.0; n];
    u[0] = gamma;
    u[n - 1] = alpha;
    solve_tridiagonal(sub, &d, sup, &mut u)?;
    // v = (1, 0, ..., 0, beta/gamma)
    let vz = u[0] + beta / gamma * u[n - 1];
    let denom = 1.0 + vz;
    if denom.abs() <= PIVOT_REL {
        return Err(Error::Singular("cyclic tridiagonal system".into()));
    }
    let vy = rhs[0] + rhs[n - 1] * (beta / gamma);
    let f = vy * (1.0 / denom);
    for i in 0..n {
        rhs[i] = rhs[i] - f * u[i];
    }
    Ok(())
}

fn check_len(what: &'static str, got: usize, expected: usize) -> Result<()> {
    if got == expected {
        Ok(())
    } else {
        Err(Error::LengthMismatch {
            what,
            got,
            expected,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Vec2;

    fn matvec(sub: &[f64], diag: &[f64], sup: &[f64], x: &[f64], cyclic: bool) -> Vec<f64> {
        let n = diag.len();
        (0..n)
            .map(|i| {
                let mut s = diag[i] * x[i];
                if i > 0 {
                    s += sub[i] * x[i - 1];
                } else if cyclic {
                    s += sub[0] * x[n - 1];
                }
                if i + 1 < n {
                    s += sup[i] * x[i + 1];
                } else if cyclic {
                    s += sup[n - 1] * x[0];
                }
                s
            })
            .collect()
    }

    #[test]
    fn thomas_solves() {
        let n = 7;
        let sub: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * i as f64).collect();
        let sup: Vec<f64> = (0..n).map(|i| 0.5 - 0.05 * i as f64).collect();
        let diag: Vec<f64> = (0..n).map(|i| 4.0 + i as f64).collect();
        let x: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let mut b = matvec(&sub, &diag, &sup, &x, false);
        solve_tridiagonal(&sub, &diag, &sup, &mut b).unwrap();
        for (a, e) in b.iter().zip(&x) {
            assert!((a - e).abs() < 1e-14);
        }
    }

    #[test]
    fn cyclic_solves_vectors() {
        let n = 9;
        let sub: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * i as f64).collect();
        let sup: Vec<f64> = (0..n).map(|i| 0.7 - 0.05 * i as f64).collect();
        let diag: Vec<f64> = (0..n).map(|i| 4.0 + 0.3 * i as f64).collect();
        let x: Vec<f64> = (0..n).map(|i| (i as f64).cos()).collect();
        let y: Vec<f64> = (0..n).map(|i| (i as f64 * 0.3).sin()).collect();
        let bx = matvec(&sub, &diag, &sup, &x, true);
        let by = matvec(&sub, &diag, &sup, &y, true);
        let mut b: Vec<Vec2> = bx.iter().zip(&by).map(|(a, b)| Vec2::new(*a, *b)).collect();
        solve_cyclic_tridiagonal(&sub, &diag, &sup, &mut b).unwrap();
        for i in 0..n {
            assert!((b[i].x - x[i]).abs() < 1e-13);
            assert!((b[i].y - y[i]).abs() < 1e-13);
        }
    }

    #[test]
    fn singular_is_an_error() {
        let mut b = vec![1.0, 1.0];
        assert!(solve_tridiagonal(&[0.0, 1.0], &[0.0, 1.0], &[1.0, 0.0], &mut b).is_err());
        let mut b = vec![1.0];
        assert!(solve_tridiagonal(&[0.0], &[1.0, 2.0], &[0.0], &mut b).is_err());
    }
}
