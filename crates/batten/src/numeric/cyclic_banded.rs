//! Symmetric *cyclic* band matrices (periodic splines), factorised as `L D Lᵀ` in O(n·bw²).

use super::{Linear, PIVOT_REL};
use crate::error::{Error, Result};

/// A symmetric n×n matrix whose nonzeros lie in the cyclic band `min(|i − j|, n − |i − j|) ≤ bw`
/// (a banded matrix plus the corner blocks that close it into a ring), factorised in place as
/// `L D Lᵀ` without pivoting (for SPD matrices).
///
/// Method: envelope (profile) factorisation. The corner entries make the last `bw` rows full
/// from column 0; every other row keeps its band. `L` has no fill outside this envelope, so
/// the factorisation costs O(n·bw²) time and O(n·bw) storage, needs no rank-`2bw`
/// Sherman–Morrison–Woodbury correction, and keeps the stability of a plain SPD `L D Lᵀ`. The same envelope carries the
/// elements of the inverse that [`CyclicSymBanded::factorize_with_inverse`] computes (the
/// Takahashi / Hutchinson–de Hoog recursion, see `band_inverse.rs`).
///
/// Storage: rows `0..n − nb` (`nb = min(bw, n)`) hold `A[i][i − k]`, `k = 0..=bw`, at
/// `i·(bw + 1) + k`; the last `nb` rows are stored in full (columns `0..=i`) after them.
#[derive(Clone, Debug)]
pub struct CyclicSymBanded {
    n: usize,
    bw: usize,
    /// Index of the first fully stored row: `n − min(bw, n)`.
    border: usize,
    data: Vec<f64>,
    factored: bool,
}

impl CyclicSymBanded {
    /// A zero n×n matrix with cyclic half-bandwidth `bw`.
    pub fn zeros(n: usize, bw: usize) -> CyclicSymBanded {
        let nb = bw.min(n);
        let border = n - nb;
        CyclicSymBanded {
            n,
            bw,
            border,
            data: vec![0.0; border * (bw + 1) + nb * n],
            factored: false,
        }
    }

    /// Dimension.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Cyclic half-bandwidth.
    pub fn bandwidth(&self) -> usize {
        self.bw
    }

    /// First column stored in row `i` (the start of the envelope).
    #[inline]
    fn first(&self, i: usize) -> usize {
        if i >= self.border {
            0
        } else {
            i.saturating_sub(self.bw)
        }
    }

    /// Storage index of `(i, j)`, `i ≥ j`, inside the envelope.
    #[inline]
    fn idx(&self, i: usize, j: usize) -> usize {
        debug_assert!(i >= j && j >= self.first(i));
        if i >= self.border {
            self.border * (self.bw + 1) + (i - self.border) * self.n + j
        } else {
            i * (self.bw + 1) + (i - j)
        }
    }

    /// Whether `(i, j)` (either triangle) lies in the stored envelope.
    fn in_envelope(&self, i: usize, j: usize) -> bool {
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        i < self.n && j >= self.first(i)
    }

    /// `A[i][j]` (either triangle); zero outside the cyclic band. After
    /// [`CyclicSymBanded::factorize`] this reads the factors instead (see
    /// [`CyclicSymBanded::l`]).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        if self.in_envelope(i, j) {
            self.data[self.idx(i, j)]
        } else {
            0.0
        }
    }

    /// Add `v` to `A[i][j]` (and so to `A[j][i]`). Entries that wrap around (e.g. `(0, n−1)`)
    /// are the corner entries of the cyclic band; for small `n` two band positions may name the
    /// same entry, and their contributions add.
    ///
    /// # Panics
    /// If `i` or `j` is out of range, `(i, j)` is outside the cyclic band, or the matrix is
    /// already factorised.
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        assert!(!self.factored, "CyclicSymBanded::add after factorisation");
        assert!(i < self.n && j < self.n, "index out of range");
        let d = i.abs_diff(j);
        assert!(
            d.min(self.n - d) <= self.bw,
            "entry outside the cyclic band"
        );
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        // Inside the cyclic band implies inside the envelope: a wrapped entry has its row in
        // the last bw rows.
        let k = self.idx(i, j);
        self.data[k] += v;
    }

    /// Factorise as `L D Lᵀ` (L unit lower triangular, envelope-structured). No pivoting.
    ///
    /// # Errors
    /// [`Error::Singular`] when a pivot is (relatively) zero or negative, i.e. the matrix is not
    /// (numerically) positive definite.
    pub fn factorize(&mut self) -> Result<()> {
        let n = self.n;
        let scale = (0..n).fold(0.0_f64, |m, i| m.max(self.data[self.idx(i, i)].abs()));
        for i in 0..n {
            let fi = self.first(i);
            for j in fi..i {
                let fj = self.first(j);
                let mut s = self.data[self.idx(i, j)];
                for k in fi.max(fj)..j {
                    s -= self.data[self.idx(i, k)]
                        * self.data[self.idx(k, k)]
                        * self.data[self.idx(j, k)];
                }
                let (ij, jj) = (self.idx(i, j), self.idx(j, j));
                self.data[ij] = s / self.data[jj];
            }
            let mut d = self.data[self.idx(i, i)];
            for k in fi..i {
                let l = self.data[self.idx(i, k)];
                d -= l * l * self.data[self.idx(k, k)];
            }
            if !d.is_finite() || d <= PIVOT_REL * scale {
                return Err(Error::Singular(format!(
                    "cyclic band matrix is not positive definite (pivot {i})"
                )));
            }
            let ii = self.idx(i, i);
            self.data[ii] = d;
        }
        self.factored = true;
        Ok(())
    }

    /// Whether [`CyclicSymBanded::factorize`] has run.
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// The factor entry `L[i][j]` after factorisation (1 on the diagonal, 0 outside the
    /// envelope and above the diagonal).
    pub fn l(&self, i: usize, j: usize) -> f64 {
        debug_assert!(self.factored);
        if i == j {
            1.0
        } else if i < j || !self.in_envelope(i, j) {
            0.0
        } else {
            self.data[self.idx(i, j)]
        }
    }

    /// The pivot `D[i]` after factorisation.
    pub fn d(&self, i: usize) -> f64 {
        debug_assert!(self.factored);
        self.data[self.idx(i, i)]
    }

    /// Solve `A x = rhs` in place with the factorisation.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] for a wrong right-hand side,
    /// [`Error::InvalidParameter`] if the matrix is not factorised yet.
    pub fn solve_in_place<T: Linear>(&self, rhs: &mut [T]) -> Result<()> {
        if !self.factored {
            return Err(Error::InvalidParameter {
                name: "CyclicSymBanded".into(),
                reason: "solve before factorize".into(),
            });
        }
        if rhs.len() != self.n {
            return Err(Error::LengthMismatch {
                what: "rhs",
                got: rhs.len(),
                expected: self.n,
            });
        }
        // L z = b, then D, then Lᵀ x = z (row i of L subtracts x_i from the earlier entries).
        for i in 0..self.n {
            let fi = self.first(i);
            let (done, rest) = rhs.split_at_mut(i);
            let mut s = rest[0];
            for (k, &zk) in done.iter().enumerate().skip(fi) {
                s = s - zk * self.data[self.idx(i, k)];
            }
            rest[0] = s;
        }
        for (i, z) in rhs.iter_mut().enumerate() {
            *z = *z * (1.0 / self.data[self.idx(i, i)]);
        }
        for i in (0..self.n).rev() {
            let fi = self.first(i);
            let (before, rest) = rhs.split_at_mut(i);
            let xi = rest[0];
            for (j, zj) in before.iter_mut().enumerate().skip(fi) {
                *zj = *zj - xi * self.data[self.idx(i, j)];
            }
        }
        Ok(())
    }

    /// Factorise in place (as [`CyclicSymBanded::factorize`]) and return the elements of
    /// `A⁻¹` on the envelope of the factors, which contains the cyclic band. The result is a
    /// (not factorised) matrix of the same shape; read it with [`CyclicSymBanded::get`]
    /// (entries of `A⁻¹` outside the envelope read as 0 there but are not zero in general).
    ///
    /// Recursion (Takahashi; Hutchinson & de Hoog 1985), column by column from the last:
    /// `Σ[r][c] = δ_rc / D[c] − Σ_{k > c} L[k][c] Σ[k][r]`. For `r, k > c` both in column
    /// `c`'s envelope, `(max(k, r), min(k, r))` is in the envelope too, so the recursion stays
    /// inside it: O(n·bw²).
    ///
    /// # Errors
    /// [`Error::Singular`] from the factorisation; [`Error::InvalidParameter`] when the matrix
    /// was already factorised.
    pub fn factorize_with_inverse(&mut self) -> Result<CyclicSymBanded> {
        if self.factored {
            return Err(Error::InvalidParameter {
                name: "CyclicSymBanded".into(),
                reason: "already factorised".into(),
            });
        }
        self.factorize()?;
        let n = self.n;
        let mut s = CyclicSymBanded::zeros(n, self.bw);
        // Rows r > c whose envelope reaches column c: the band rows c+1..=c+bw below the
        // border, then every border row after c.
        let mut rows: Vec<usize> = Vec::with_capacity(2 * self.bw);
        for c in (0..n).rev() {
            rows.clear();
            rows.extend((c + 1..=(c + self.bw).min(n - 1)).filter(|&r| r < self.border));
            rows.extend(self.border.max(c + 1)..n);
            for &r in &rows {
                let mut v = 0.0;
                for &k in &rows {
                    v -= self.data[self.idx(k, c)] * s.get(k, r);
                }
                let at = s.idx(r, c);
                s.data[at] = v;
            }
            let mut v = 1.0 / self.data[self.idx(c, c)];
            for &k in &rows {
                v -= self.data[self.idx(k, c)] * s.get(k, c);
            }
            let at = s.idx(c, c);
            s.data[at] = v;
        }
        Ok(s)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::geom::Vec2;

    fn build(n: usize, bw: usize) -> (CyclicSymBanded, nalgebra::DMatrix<f64>) {
        let mut a = CyclicSymBanded::zeros(n, bw);
        let mut dense = nalgebra::DMatrix::<f64>::zeros(n, n);
        for i in 0..n {
            let v = 4.0 * bw as f64 + (i as f64 * 0.3).cos();
            a.add(i, i, v);
            dense[(i, i)] += v;
            for k in 1..=bw {
                let j = (i + k) % n;
                let v = -0.8 + 0.05 * ((i * 7 + k) % 5) as f64;
                a.add(i, j, v);
                dense[(i, j)] += v;
                dense[(j, i)] += v;
            }
        }
        (a, dense)
    }

    #[test]
    fn solves_and_inverts_like_dense() {
        for (n, bw) in [(3, 1), (4, 2), (5, 2), (6, 2), (11, 2), (12, 3), (9, 1)] {
            let (mut a, dense) = build(n, bw);
            let inv = dense.clone().try_inverse().unwrap();
            let s = a.factorize_with_inverse().unwrap();
            for i in 0..n {
                for k in 0..=bw {
                    let j = (i + k) % n;
                    assert!(
                        (s.get(i, j) - inv[(i, j)]).abs() < 1e-12,
                        "n {n} bw {bw} ({i},{j})"
                    );
                }
            }
            let x: Vec<Vec2> = (0..n)
                .map(|i| Vec2::new((i as f64).sin(), 1.0 - i as f64 * 0.2))
                .collect();
            let mut b: Vec<Vec2> = (0..n)
                .map(|i| (0..n).fold(Vec2::ZERO, |acc, j| acc + x[j] * dense[(i, j)]))
                .collect();
            a.solve_in_place(&mut b).unwrap();
            for i in 0..n {
                assert!((b[i] - x[i]).length() < 1e-12, "n {n} bw {bw} row {i}");
            }
        }
    }

    #[test]
    fn not_positive_definite_is_an_error() {
        let mut a = CyclicSymBanded::zeros(5, 1);
        for i in 0..5 {
            a.add(i, i, 1.0);
            a.add(i, (i + 1) % 5, 1.0);
        }
        assert!(matches!(a.factorize(), Err(Error::Singular(_))));
    }
}
