use super::{Linear, PIVOT_REL};
use crate::error::{Error, Result};

/// A general (non-symmetric) band matrix with `kl` sub- and `ku` super-diagonals, factorised
/// in place as `L U` without pivoting.
///
/// Meant for B-spline collocation matrices, which are totally positive, so Gaussian
/// elimination without pivoting is stable for them (de Boor, *A Practical Guide to Splines*,
/// ch. XIII). Storage: row `i` holds columns `i − kl ..= i + ku`.
#[derive(Clone, Debug)]
pub struct BandLu {
    n: usize,
    kl: usize,
    ku: usize,
    data: Vec<f64>,
    factored: bool,
}

impl BandLu {
    /// A zero n×n band matrix.
    pub fn zeros(n: usize, kl: usize, ku: usize) -> BandLu {
        BandLu {
            n,
            kl,
            ku,
            data: vec![0.0; n * (kl + ku + 1)],
            factored: false,
        }
    }

    fn idx(&self, i: usize, j: usize) -> Option<usize> {
        if j + self.kl < i || j > i + self.ku || i >= self.n || j >= self.n {
            None
        } else {
            Some(i * (self.kl + self.ku + 1) + (j + self.kl - i))
        }
    }

    /// Set `A[i][j]`.
    ///
    /// # Panics
    /// When `(i, j)` lies outside the band or the matrix is factorised.
    pub fn set(&mut self, i: usize, j: usize, v: f64) {
        assert!(!self.factored, "BandLu::set after factorisation");
        let k = self.idx(i, j).expect("entry outside the band");
        self.data[k] = v;
    }

    /// `A[i][j]` (zero outside the band).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.idx(i, j).map_or(0.0, |k| self.data[k])
    }

    /// Factorise as `L U` (no pivoting), O(n·kl·ku).
    ///
    /// # Errors
    /// [`Error::Singular`] for a (relatively) zero pivot.
    pub fn factorize(&mut self) -> Result<()> {
        let n = self.n;
        let scale = self
            .data
            .iter()
            .fold(0.0_f64, |m, v| m.max(v.abs()))
            .max(f64::MIN_POSITIVE);
        for k in 0..n {
            let Some(pk) = self.idx(k, k) else { continue };
            let piv = self.data[pk];
            if piv.abs() <= PIVOT_REL * scale || !piv.is_finite() {
                return Err(Error::Singular(format!("zero pivot {k} in band LU")));
            }
            for i in k + 1..(k + self.kl + 1).min(n) {
                let Some(ik) = self.idx(i, k) else { continue };
                let f = self.data[ik] / piv;
                self.data[ik] = f;
                if f == 0.0 {
                    continue;
                }
                for j in k + 1..(k + self.ku + 1).min(n) {
                    let (Some(ij), Some(kj)) = (self.idx(i, j), self.idx(k, j)) else {
                        continue;
                    };
                    self.data[ij] -= f * self.data[kj];
                }
            }
        }
        self.factored = true;
        Ok(())
    }

    /// Solve `A x = rhs` in place.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`]; [`Error::InvalidParameter`] before factorisation.
    pub fn solve_in_place<T: Linear>(&self, rhs: &mut [T]) -> Result<()> {
        if !self.factored {
            return Err(Error::InvalidParameter {
                name: "BandLu".into(),
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
        let n = self.n;
        for i in 0..n {
            let mut s = rhs[i];
            for j in i.saturating_sub(self.kl)..i {
                s = s - rhs[j] * self.get(i, j);
            }
            rhs[i] = s;
        }
        for i in (0..n).rev() {
            let mut s = rhs[i];
            for j in i + 1..(i + self.ku + 1).min(n) {
                s = s - rhs[j] * self.get(i, j);
            }
            rhs[i] = s * (1.0 / self.get(i, i));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_banded_system() {
        let n = 10;
        let mut a = BandLu::zeros(n, 2, 1);
        let mut dense = vec![vec![0.0; n]; n];
        for i in 0..n {
            for j in i.saturating_sub(2)..(i + 2).min(n) {
                let v = if i == j {
                    5.0 + i as f64
                } else {
                    1.0 / (1.0 + (i + 2 * j) as f64)
                };
                a.set(i, j, v);
                dense[i][j] = v;
            }
        }
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
        let mut b: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| dense[i][j] * x[j]).sum())
            .collect();
        a.factorize().unwrap();
        a.solve_in_place(&mut b).unwrap();
        for i in 0..n {
            assert!((b[i] - x[i]).abs() < 1e-13);
        }
    }
}
