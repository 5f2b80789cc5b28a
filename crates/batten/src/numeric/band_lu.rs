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
        // The cubic B-spline collocation matrices of every report's GFI (kl = ku = 3) get the
        // loops with their bounds known, unrolled; the operations are the same.
        let result = match (self.kl, self.ku) {
            (3, 3) => factorize_band(&mut self.data, self.n, Fixed::<3, 3>),
            (kl, ku) => factorize_band(&mut self.data, self.n, Dynamic(kl, ku)),
        };
        self.factored = result.is_ok();
        result
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
        match (self.kl, self.ku) {
            (3, 3) => solve_band(&self.data, rhs, Fixed::<3, 3>),
            (kl, ku) => solve_band(&self.data, rhs, Dynamic(kl, ku)),
        }
        Ok(())
    }
}

/// The widths of a band: known at compile time ([`Fixed`]) or not ([`Dynamic`]), so that one
/// body of [`factorize_band`] and [`solve_band`] serves both.
trait Widths: Copy {
    /// Sub-diagonals.
    fn kl(self) -> usize;
    /// Super-diagonals.
    fn ku(self) -> usize;
    /// Row `i`, column `j` (within the band) in the row-major band storage.
    #[inline(always)]
    fn at(self, i: usize, j: usize) -> usize {
        i * (self.kl() + self.ku() + 1) + j + self.kl() - i
    }
}

/// Widths known at compile time.
#[derive(Clone, Copy)]
struct Fixed<const KL: usize, const KU: usize>;

impl<const KL: usize, const KU: usize> Widths for Fixed<KL, KU> {
    #[inline(always)]
    fn kl(self) -> usize {
        KL
    }
    #[inline(always)]
    fn ku(self) -> usize {
        KU
    }
}

/// Widths known at run time: `(kl, ku)`.
#[derive(Clone, Copy)]
struct Dynamic(usize, usize);

impl Widths for Dynamic {
    #[inline(always)]
    fn kl(self) -> usize {
        self.0
    }
    #[inline(always)]
    fn ku(self) -> usize {
        self.1
    }
}

/// [`BandLu::factorize`] on the storage `data` of an n×n band matrix.
fn factorize_band(data: &mut [f64], n: usize, w: impl Widths) -> Result<()> {
    let (kl, ku) = (w.kl(), w.ku());
    let scale = data
        .iter()
        .fold(0.0_f64, |m, v| m.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    for k in 0..n {
        // Every entry the elimination touches lies inside the band.
        let piv = data[w.at(k, k)];
        if piv.abs() <= PIVOT_REL * scale || !piv.is_finite() {
            return Err(Error::Singular(format!("zero pivot {k} in band LU")));
        }
        // Rows k+1..=k+rows below the pivot, columns k+1..=k+cols right of it: the whole
        // widths (a fixed count for fixed widths) but near the last row.
        let left = n - 1 - k;
        if left >= kl && left >= ku {
            eliminate(data, k, piv, kl, ku, w);
        } else {
            eliminate(data, k, piv, kl.min(left), ku.min(left), w);
        }
    }
    Ok(())
}

/// One step of [`factorize_band`]: the multipliers of column `k` in rows `k+1..=k+rows`, and
/// their multiples of pivot row `k` (columns `k+1..=k+cols`) taken from those rows.
#[inline(always)]
fn eliminate(data: &mut [f64], k: usize, piv: f64, rows: usize, cols: usize, w: impl Widths) {
    for di in 1..=rows {
        let i = k + di;
        let f = data[w.at(i, k)] / piv;
        data[w.at(i, k)] = f;
        if f == 0.0 {
            continue;
        }
        for dj in 1..=cols {
            let j = k + dj;
            data[w.at(i, j)] -= f * data[w.at(k, j)];
        }
    }
}

/// [`BandLu::solve_in_place`] with the factors in `data`.
fn solve_band<T: Linear>(data: &[f64], rhs: &mut [T], w: impl Widths) {
    let (n, kl, ku) = (rhs.len(), w.kl(), w.ku());
    for i in 0..n {
        let mut s = rhs[i];
        for j in i.saturating_sub(kl)..i {
            s = s - rhs[j] * data[w.at(i, j)];
        }
        rhs[i] = s;
    }
    for i in (0..n).rev() {
        let mut s = rhs[i];
        for j in i + 1..(i + ku + 1).min(n) {
            s = s - rhs[j] * data[w.at(i, j)];
        }
        rhs[i] = s * (1.0 / data[w.at(i, i)]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unrolled kl = ku = 3 code gives the bits of the general one, factors and solution,
    /// on a matrix with zeros inside its band (as collocation matrices have).
    #[test]
    fn fixed_widths_give_the_general_bits() {
        let n = 40;
        let mut a = BandLu::zeros(n, 3, 3);
        for i in 0..n {
            for j in i.saturating_sub(3)..(i + 4).min(n) {
                let x = (i * 7 + j * 3) as f64;
                let v = if i == j {
                    4.0 + x.sin()
                } else if (i + j) % 5 == 0 {
                    0.0
                } else {
                    0.3 * x.cos()
                };
                a.set(i, j, v);
            }
        }
        let (mut fixed, mut general) = (a.data.clone(), a.data.clone());
        factorize_band(&mut fixed, n, Fixed::<3, 3>).unwrap();
        factorize_band(&mut general, n, Dynamic(3, 3)).unwrap();
        assert!(
            fixed
                .iter()
                .zip(&general)
                .all(|(x, y)| x.to_bits() == y.to_bits())
        );
        let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
        let (mut x, mut y) = (rhs.clone(), rhs);
        solve_band(&fixed, &mut x, Fixed::<3, 3>);
        solve_band(&general, &mut y, Dynamic(3, 3));
        assert!(x.iter().zip(&y).all(|(a, b)| a.to_bits() == b.to_bits()));
    }

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
