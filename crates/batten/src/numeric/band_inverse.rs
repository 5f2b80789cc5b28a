//! Selected elements of the inverse of a banded SPD matrix, from its `L D Lᵀ` factors.
//!
//! Hutchinson & de Hoog, *Smoothing noisy data with spline functions*, Numer. Math. 47 (1985)
//! 99–106 (after Takahashi, Fagan & Chen 1973): with `A = L D Lᵀ` and `Σ = A⁻¹`,
//! `Σ = D⁻¹ L⁻¹ + (I − Lᵀ) Σ`, so that for `r ≥ c`
//!
//! ```text
//! Σ[r][c] = δ_rc / D[c] − Σ_{k > c, L[k][c] ≠ 0} L[k][c] · Σ[k][r]
//! ```
//!
//! Taken column by column from the last, the recursion only ever needs entries of `Σ` inside
//! the band of `L`, so the band of the inverse costs O(n·bw²) — what the trace of a smoothing
//! spline's influence matrix (generalised cross-validation) needs.

use super::SymBanded;
use crate::error::Result;

/// Factorise `a` in place (as [`SymBanded::factorize`], so it can solve afterwards) and return
/// the entries of `A⁻¹` inside the band of `A` (`|i − j| ≤ bw`), as a (not factorised)
/// [`SymBanded`] of the same size and bandwidth; read it with [`SymBanded::get`]. Entries of
/// `A⁻¹` outside the band are not computed (they are not zero in general).
///
/// `a` must not have been factorised before.
///
/// # Errors
/// [`Error::Singular`](crate::Error::Singular) from the factorisation.
pub fn factorize_with_inverse_band(a: &mut SymBanded) -> Result<SymBanded> {
    a.factorize()?;
    let (n, bw) = (a.n(), a.bandwidth());
    let mut s = SymBanded::zeros(n, bw);
    for c in (0..n).rev() {
        let hi = (c + bw).min(n.saturating_sub(1));
        // Off-diagonal entries of column c first: they only need columns > c.
        for r in c + 1..=hi {
            let mut v = 0.0;
            for k in c + 1..=hi {
                v -= a.l(k, c) * s.get(k, r);
            }
            s.add(r, c, v);
        }
        let mut v = 1.0 / a.d(c);
        for k in c + 1..=hi {
            v -= a.l(k, c) * s.get(k, c);
        }
        s.add(c, c, v);
    }
    Ok(s)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn matches_dense_inverse() {
        let n = 9;
        for bw in 1..=3 {
            let mut a = SymBanded::zeros(n, bw);
            let mut dense = nalgebra::DMatrix::<f64>::zeros(n, n);
            for i in 0..n {
                for k in 0..=bw.min(i) {
                    let v = if k == 0 {
                        5.0 + (i as f64).sin()
                    } else {
                        0.4 - 0.1 * (i + k) as f64 / n as f64
                    };
                    a.add(i, i - k, v);
                    dense[(i, i - k)] = v;
                    dense[(i - k, i)] = v;
                }
            }
            let s = factorize_with_inverse_band(&mut a).unwrap();
            let inv = dense.try_inverse().unwrap();
            for i in 0..n {
                for j in i.saturating_sub(bw)..=i {
                    assert!(
                        (s.get(i, j) - inv[(i, j)]).abs() < 1e-13,
                        "bw {bw} ({i},{j})"
                    );
                }
            }
        }
    }

    #[test]
    fn indefinite_is_rejected() {
        let mut a = SymBanded::zeros(2, 1);
        a.add(0, 0, 1.0);
        a.add(1, 0, 2.0);
        a.add(1, 1, 1.0);
        assert!(factorize_with_inverse_band(&mut a).is_err());
    }
}
