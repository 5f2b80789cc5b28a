//! The pentadiagonal system of the open smoothing spline (see [`super`]), solved
//! without the general band code: the matrix as three diagonals, its `L D Lᵀ` factorisation
//! and the solve for every coordinate at once, written out for half-bandwidth 2.
//!
//! The operations, their order and the pivot test are those of
//! [`crate::numeric::SymBanded::factorize`] and [`crate::numeric::SymBanded::solve_in_place`]
//! on the same entries, so the results are the same bits; the tolerance search of `mst` solves
//! one such system per trial (10–14 on a 200-point curve at a noise-level tolerance, issue
//! #17), and the general code spent most of its time on index arithmetic, bounds checks and
//! zeroed buffers.

use crate::error::{Error, Result};
use crate::numeric::PIVOT_REL;

/// A symmetric positive definite pentadiagonal matrix `A`, by diagonals, and after
/// [`Penta::factorize`] its `L D Lᵀ` factors in the same places.
#[derive(Clone, Debug, Default)]
pub(crate) struct Penta {
    /// `A[i][i]`, then the pivot `D[i]`.
    diag: Vec<f64>,
    /// `A[i][i−1]` (row 0: unused), then `L[i][i−1]`.
    sub1: Vec<f64>,
    /// `A[i][i−2]` (rows 0 and 1: unused), then `L[i][i−2]`.
    sub2: Vec<f64>,
}

impl Penta {
    /// The matrix whose column `j` is `[A[j][j], A[j+1][j], A[j+2][j]]`, given in order: each
    /// diagonal entry and the two below it (those past the last row are ignored), as
    /// [`crate::numeric::SymBanded::add`] would store them in a zero matrix.
    pub(crate) fn from_columns(columns: impl ExactSizeIterator<Item = [f64; 3]>) -> Penta {
        let m = columns.len();
        // Row 0 has no entry left of the diagonal, row 1 one; the last columns' entries
        // below the matrix are written past its end and cut off. (Written by index into
        // zeros, not pushed: a push costs a capacity check and more.)
        let mut a = Penta {
            diag: vec![0.0; m],
            sub1: vec![0.0; m + 1],
            sub2: vec![0.0; m + 2],
        };
        for (j, [d0, d1, d2]) in columns.enumerate().take(m) {
            // `0.0 + v`, as an addition into a zero matrix stores it (−0 becomes +0).
            a.diag[j] = 0.0 + d0;
            a.sub1[j + 1] = 0.0 + d1;
            a.sub2[j + 2] = 0.0 + d2;
        }
        a.sub1.truncate(m);
        a.sub2.truncate(m);
        a
    }

    /// Factorise in place as `L D Lᵀ` (no pivoting).
    ///
    /// # Errors
    /// [`Error::Singular`] when a pivot is (relatively) zero or negative, with the message of
    /// [`crate::numeric::SymBanded::factorize`].
    pub(crate) fn factorize(&mut self) -> Result<()> {
        let m = self.diag.len();
        let scale = self.diag.iter().fold(0.0_f64, |s, v| s.max(v.abs()));
        let (diag, sub1, sub2) = (&mut self.diag[..], &mut self.sub1[..], &mut self.sub2[..]);
        for i in 0..m {
            let mut d = diag[i];
            if i >= 2 {
                let l2 = sub2[i] / diag[i - 2];
                sub2[i] = l2;
                let l1 = (sub1[i] - l2 * diag[i - 2] * sub1[i - 1]) / diag[i - 1];
                sub1[i] = l1;
                d = d - l2 * l2 * diag[i - 2] - l1 * l1 * diag[i - 1];
            } else if i == 1 {
                let l1 = sub1[1] / diag[0];
                sub1[1] = l1;
                d -= l1 * l1 * diag[0];
            }
            if d.is_nan() || d <= PIVOT_REL * scale || !d.is_finite() {
                return Err(Error::Singular(format!(
                    "band matrix is not positive definite (pivot {i})"
                )));
            }
            diag[i] = d;
        }
        Ok(())
    }

    /// Solve `A x = rhs` in place for every coordinate, with the factors of
    /// [`Penta::factorize`].
    ///
    /// # Panics
    /// If `rhs` has not one entry per row.
    pub(crate) fn solve_in_place<const D: usize>(&self, rhs: &mut [[f64; D]]) {
        let m = self.diag.len();
        assert_eq!(
            rhs.len(),
            m,
            "Penta::solve_in_place: one right-hand side per row"
        );
        let (diag, sub1, sub2) = (&self.diag[..m], &self.sub1[..m], &self.sub2[..m]);
        if m >= 2 {
            for c in 0..D {
                rhs[1][c] -= rhs[0][c] * sub1[1];
            }
        }
        for i in 2..m {
            for c in 0..D {
                let s = rhs[i][c] - rhs[i - 2][c] * sub2[i];
                rhs[i][c] = s - rhs[i - 1][c] * sub1[i];
            }
        }
        for (r, d) in rhs.iter_mut().zip(diag) {
            let inv = 1.0 / d;
            for v in r.iter_mut() {
                *v *= inv;
            }
        }
        if m >= 2 {
            for c in 0..D {
                rhs[m - 2][c] -= rhs[m - 1][c] * sub1[m - 1];
            }
            for i in (0..m - 2).rev() {
                for c in 0..D {
                    let s = rhs[i][c] - rhs[i + 1][c] * sub1[i + 1];
                    rhs[i][c] = s - rhs[i + 2][c] * sub2[i + 2];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numeric::SymBanded;

    /// A pentadiagonal SPD matrix with entries of mixed sign and size, by its columns.
    fn column(j: usize) -> [f64; 3] {
        let x = j as f64;
        [
            7.0 + (0.7 * x).sin() + 1e-3 * x,
            -1.5 + 0.1 * (1.3 * x).cos(),
            0.4 + 0.05 * (2.1 * x).sin(),
        ]
    }

    /// The m×m matrix with columns `column(j)` in the general band code.
    fn sym_banded(m: usize, column: impl Fn(usize) -> [f64; 3]) -> SymBanded {
        let mut general = SymBanded::zeros(m, 2);
        for j in 0..m {
            let [d0, d1, d2] = column(j);
            general.add(j, j, d0);
            if j + 1 < m {
                general.add(j + 1, j, d1);
            }
            if j + 2 < m {
                general.add(j + 2, j, d2);
            }
        }
        general
    }

    /// The same bits as the general band code, factors and solutions, for every small size
    /// (the first rows are special cases) and a large one.
    #[test]
    fn same_bits_as_sym_banded() {
        for m in (0..12).chain([257]) {
            let mut general = sym_banded(m, column);
            let mut penta = Penta::from_columns((0..m).map(column));
            general.factorize().unwrap();
            penta.factorize().unwrap();
            for i in 0..m {
                assert_eq!(penta.diag[i].to_bits(), general.d(i).to_bits(), "D {i}");
                if i >= 1 {
                    assert_eq!(penta.sub1[i].to_bits(), general.l(i, i - 1).to_bits());
                }
                if i >= 2 {
                    assert_eq!(penta.sub2[i].to_bits(), general.l(i, i - 2).to_bits());
                }
            }
            let rhs: Vec<[f64; 3]> = (0..m)
                .map(|i| {
                    let x = i as f64;
                    [x.sin(), -1e-7 * x, (0.3 * x).cos() * 1e5]
                })
                .collect();
            let mut got = rhs.clone();
            penta.solve_in_place(&mut got);
            for c in 0..3 {
                let mut col: Vec<f64> = rhs.iter().map(|r| r[c]).collect();
                general.solve_in_place(&mut col).unwrap();
                for i in 0..m {
                    assert_eq!(got[i][c].to_bits(), col[i].to_bits(), "m {m}, row {i}");
                }
            }
        }
    }

    /// A matrix that is not positive definite fails at the same pivot with the same message.
    #[test]
    fn indefinite_fails_as_sym_banded() {
        let m = 9;
        let col = |j: usize| {
            let [d0, d1, d2] = column(j);
            [if j == 5 { -d0 } else { d0 }, d1, d2]
        };
        let want = sym_banded(m, col).factorize().unwrap_err().to_string();
        let got = Penta::from_columns((0..m).map(col))
            .factorize()
            .unwrap_err()
            .to_string();
        assert_eq!(got, want);
        assert!(got.contains("pivot 5"), "{got}");
    }
}
