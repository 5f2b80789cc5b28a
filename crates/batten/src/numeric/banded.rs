use super::{Linear, PIVOT_REL};
use crate::error::{Error, Result};

/// A symmetric band matrix with half-bandwidth `bw`, factorised in place as `L D Lᵀ`.
///
/// Storage: `band[i * (bw + 1) + k] = A[i][i − k]` for `k = 0..=bw` (the diagonal and the
/// `bw` entries to its left). Factorisation is O(n·bw²), a solve O(n·bw): the pentadiagonal
/// systems of smoothing splines (bw = 2) cost O(n).
#[derive(Clone, Debug)]
pub struct SymBanded {
    n: usize,
    bw: usize,
    band: Vec<f64>,
    factored: bool,
}

impl SymBanded {
    /// A zero n×n matrix with half-bandwidth `bw`.
    pub fn zeros(n: usize, bw: usize) -> SymBanded {
        SymBanded {
            n,
            bw,
            band: vec![0.0; n * (bw + 1)],
            factored: false,
        }
    }

    /// Dimension.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Half-bandwidth.
    pub fn bandwidth(&self) -> usize {
        self.bw
    }

    /// `A[i][j]` for `|i − j| ≤ bw` (either triangle); zero outside the band.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        if i - j > self.bw {
            0.0
        } else {
            self.band[i * (self.bw + 1) + (i - j)]
        }
    }

    /// Add `v` to `A[i][j]` (and so to `A[j][i]`).
    ///
    /// # Panics
    /// If `|i − j| > bw` or the matrix is already factorised.
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        assert!(!self.factored, "SymBanded::add after factorisation");
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        assert!(i - j <= self.bw, "entry outside the band");
        self.band[i * (self.bw + 1) + (i - j)] += v;
    }

    /// Add `v` to `A[i][j]` for `j ≤ i ≤ j + bw` (the lower band), for assembly loops that
    /// know their indices are in the band: [`SymBanded::add`] without its checks (debug
    /// builds keep them).
    #[inline]
    pub(crate) fn add_lower(&mut self, i: usize, j: usize, v: f64) {
        debug_assert!(!self.factored && j <= i && i - j <= self.bw);
        self.band[i * (self.bw + 1) + (i - j)] += v;
    }

    /// Factorise as `L D Lᵀ` (L unit lower triangular, banded). No pivoting: meant for
    /// symmetric positive definite matrices.
    ///
    /// # Errors
    /// [`Error::Singular`] when a pivot is (relatively) zero or negative.
    pub fn factorize(&mut self) -> Result<()> {
        let (n, w) = (self.n, self.bw + 1);
        let scale = (0..n).fold(0.0_f64, |m, i| m.max(self.band[i * w].abs()));
        for i in 0..n {
            // For j in i-bw..i: L[i][j] = (A[i][j] - sum_k L[i][k] D[k] L[j][k]) / D[j]
            let lo = i.saturating_sub(self.bw);
            for j in lo..i {
                let mut s = self.band[i * w + (i - j)];
                let klo = lo.max(j.saturating_sub(self.bw));
                for k in klo..j {
                    s -= self.band[i * w + (i - k)] * self.band[k * w] * self.band[j * w + (j - k)];
                }
                self.band[i * w + (i - j)] = s / self.band[j * w];
            }
            let mut d = self.band[i * w];
            for k in lo..i {
                let l = self.band[i * w + (i - k)];
                d -= l * l * self.band[k * w];
            }
            if d.is_nan() || d <= PIVOT_REL * scale || !d.is_finite() {
                return Err(Error::Singular(format!(
                    "band matrix is not positive definite (pivot {i})"
                )));
            }
            self.band[i * w] = d;
        }
        self.factored = true;
        Ok(())
    }

    /// Make this matrix a copy of `other` (same shape), unfactorised: the cheap way to start
    /// each Newton step from the same assembled part.
    ///
    /// # Panics
    /// If the shapes differ.
    pub fn assign(&mut self, other: &SymBanded) {
        assert!(
            self.n == other.n && self.bw == other.bw,
            "SymBanded::assign shapes differ"
        );
        self.band.copy_from_slice(&other.band);
        self.factored = false;
    }

    /// Factorise as `L D Lᵀ` with static regularisation, for the positive semidefinite
    /// systems of interior-point methods: a pivot below `delta` (absolute) is replaced by
    /// `delta`, and the count of such pivots returned. The solve is then that of a nearby
    /// matrix, which iterative refinement against the true one corrects. Same O(n·bw²) as
    /// [`SymBanded::factorize`], with half its multiplications (`L[i][k]·D[k]` is kept).
    ///
    /// # Errors
    /// [`Error::Singular`] for a non-finite pivot (NaN or infinite entries).
    pub fn factorize_regularized(&mut self, delta: f64) -> Result<usize> {
        let (n, bw, w) = (self.n, self.bw, self.bw + 1);
        let mut scaled = vec![0.0_f64; bw];
        let mut regularized = 0;
        for i in 0..n {
            let lo = i.saturating_sub(bw);
            let m = i - lo;
            // scaled[j - lo] = L[i][j]·D[j], before the division by D[j].
            for j in lo..i {
                let mut s = self.band[i * w + (i - j)];
                let klo = lo.max(j.saturating_sub(bw));
                for k in klo..j {
                    s -= scaled[k - lo] * self.band[j * w + (j - k)];
                }
                scaled[j - lo] = s;
                self.band[i * w + (i - j)] = s / self.band[j * w];
            }
            let mut d = self.band[i * w];
            for (k, v) in scaled[..m].iter().enumerate() {
                d -= v * self.band[i * w + (i - (lo + k))];
            }
            if !d.is_finite() {
                return Err(Error::Singular(format!(
                    "band matrix has a non-finite pivot ({i})"
                )));
            }
            if d < delta {
                d = delta;
                regularized += 1;
            }
            self.band[i * w] = d;
        }
        self.factored = true;
        Ok(regularized)
    }

    /// The factor entry `L[i][j]` (i > j, within the band) after [`SymBanded::factorize`].
    pub fn l(&self, i: usize, j: usize) -> f64 {
        debug_assert!(self.factored);
        if i == j {
            1.0
        } else if i < j || i - j > self.bw {
            0.0
        } else {
            self.band[i * (self.bw + 1) + (i - j)]
        }
    }

    /// The pivot `D[i]` after [`SymBanded::factorize`].
    pub fn d(&self, i: usize) -> f64 {
        debug_assert!(self.factored);
        self.band[i * (self.bw + 1)]
    }

    /// Solve `A x = rhs` in place with the factorisation.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] for a wrong right-hand side,
    /// [`Error::InvalidParameter`] if the matrix is not factorised yet.
    pub fn solve_in_place<T: Linear>(&self, rhs: &mut [T]) -> Result<()> {
        if !self.factored {
            return Err(Error::InvalidParameter {
                name: "SymBanded".into(),
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
        let (n, w) = (self.n, self.bw + 1);
        for i in 0..n {
            let lo = i.saturating_sub(self.bw);
            let mut s = rhs[i];
            for k in lo..i {
                s = s - rhs[k] * self.band[i * w + (i - k)];
            }
            rhs[i] = s;
        }
        for i in 0..n {
            rhs[i] = rhs[i] * (1.0 / self.band[i * w]);
        }
        for i in (0..n).rev() {
            let hi = (i + self.bw).min(n - 1);
            let mut s = rhs[i];
            for k in i + 1..=hi {
                s = s - rhs[k] * self.band[k * w + (k - i)];
            }
            rhs[i] = s;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pentadiagonal_spd_solve() {
        let n = 12;
        let mut a = SymBanded::zeros(n, 2);
        let mut dense = vec![vec![0.0; n]; n];
        for i in 0..n {
            let v = 6.0 + (i as f64 * 0.7).sin();
            a.add(i, i, v);
            dense[i][i] += v;
            if i >= 1 {
                let v = -1.0 + 0.1 * i as f64;
                a.add(i, i - 1, v);
                dense[i][i - 1] += v;
                dense[i - 1][i] += v;
            }
            if i >= 2 {
                let v = 0.5;
                a.add(i - 2, i, v);
                dense[i][i - 2] += v;
                dense[i - 2][i] += v;
            }
        }
        let x: Vec<f64> = (0..n).map(|i| (i as f64).sqrt() - 1.0).collect();
        let mut b: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| dense[i][j] * x[j]).sum())
            .collect();
        a.factorize().unwrap();
        a.solve_in_place(&mut b).unwrap();
        for i in 0..n {
            assert!((b[i] - x[i]).abs() < 1e-13, "{i}");
        }
    }

    #[test]
    fn regularized_factorisation_solves_spd_and_floors_pivots() {
        let n = 30;
        let mut a = SymBanded::zeros(n, 3);
        for i in 0..n {
            a.add(i, i, 8.0 + (i as f64).cos());
            for k in 1..=3.min(i) {
                a.add(
                    i,
                    i - k,
                    1.0 / (k as f64 + 0.5) - 0.2 * (i as f64 * 0.3).sin(),
                );
            }
        }
        let x: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * i as f64).collect();
        let mut b = vec![0.0; n];
        for i in 0..n {
            for j in 0..n {
                b[i] += a.get(i, j) * x[j];
            }
        }
        let mut plain = a.clone();
        plain.factorize().unwrap();
        let mut reg = a.clone();
        assert_eq!(reg.factorize_regularized(1e-12).unwrap(), 0);
        for i in 0..n {
            assert!((plain.d(i) - reg.d(i)).abs() < 1e-12 * plain.d(i));
        }
        reg.solve_in_place(&mut b).unwrap();
        for i in 0..n {
            assert!((b[i] - x[i]).abs() < 1e-12, "{i}");
        }
        // A singular (rank-one) matrix gets floored pivots instead of an error.
        let mut s = SymBanded::zeros(3, 2);
        for i in 0..3 {
            for j in 0..=i {
                s.add(i, j, 1.0);
            }
        }
        assert_eq!(s.factorize_regularized(1e-9).unwrap(), 2);
    }

    #[test]
    fn indefinite_is_rejected() {
        let mut a = SymBanded::zeros(2, 1);
        a.add(0, 0, 1.0);
        a.add(1, 0, 2.0);
        a.add(1, 1, 1.0);
        assert!(a.factorize().is_err());
    }
}
