//! A long symmetric band matrix factorised from both ends at once, on two threads.
//!
//! The rows are cut into a top part `T` (rows `0..mid`), a middle block `S` of `bw` rows and a
//! bottom part `B` (the rest). With half-bandwidth `bw`, `T` and `B` do not touch: the matrix is
//!
//! ```text
//! [ A_TT  A_TS   0   ]
//! [ A_ST  A_SS  A_SB ]
//! [  0    A_BS  A_BB ]
//! ```
//!
//! `A_TT = L_T D_T L_Tᵀ` is factorised from its first row down, and `A_BB` from its last row up
//! (the ordinary factorisation of its rows in reverse order), both at the same time. Each part
//! meets the middle block only in its last `bw` rows (in its own order), so `Y = L⁻¹ A_·S` is
//! zero above them: `bw × bw` numbers a part. The middle block's Schur complement
//! `A_SS − Y_Tᵀ D_T⁻¹ Y_T − Y_Bᵀ D_B⁻¹ Y_B` is then factorised densely. A solve runs both
//! parts' forward substitutions at the same time, solves the middle block, and runs both back
//! substitutions at the same time: the work of the one-sided factorisation, in about half the
//! time on two cores. The numbers differ from the one-sided factorisation's by rounding only
//! (another elimination order); `band`'s interior point and debiasing stage use it for long
//! curves ([`SPLIT_FROM`] rows and more).

use super::Linear;
use super::banded::{SymBanded, checked_pivot, floored_pivot};
use crate::error::Result;

/// From this many rows on, `band`'s Newton and data-term matrices are factorised from both ends
/// ([`SymBanded::factorize_split`]). Below it the hand-off to a second thread costs more than
/// it saves, and the results stay those of the one-sided factorisation bit for bit (every curve
/// of the quality benchmark is below it).
pub(crate) const SPLIT_FROM: usize = 1 << 14;

/// How the pivots are taken: floored at `delta` (counted), or refused when not positive
/// relative to `scale`.
#[derive(Clone, Copy, Debug)]
pub(super) enum Pivots {
    Floor(f64),
    Check(f64),
}

/// One part of the split factorisation: its factors and its coupling to the middle block.
#[derive(Clone, Debug)]
struct Part {
    m: SymBanded,
    /// `Y = L⁻¹ C` on the part's last `bw` rows (row-major, `bw × bw`), `C` the part's
    /// entries in the middle block's columns.
    y: Vec<f64>,
}

impl Part {
    fn empty() -> Part {
        Part {
            m: SymBanded::zeros(0, 0),
            y: Vec::new(),
        }
    }

    /// Factorise the part (its matrix already filled) and compute `Y` from its coupling `c`
    /// (row-major, its last `bw` rows); the count of floored pivots.
    fn factorize(&mut self, c: &[f64], pivots: Pivots) -> Result<usize> {
        let floored = match pivots {
            Pivots::Floor(delta) => self.m.factorize_regularized(delta)?,
            Pivots::Check(_) => {
                self.m.factorize()?;
                0
            }
        };
        let (n, bw) = (self.m.n, self.m.bw);
        let w = bw + 1;
        self.y.clear();
        self.y.extend_from_slice(c);
        for r in 0..bw {
            let row = n - bw + r;
            for q in 0..r {
                let l = self.m.band[row * w + (r - q)];
                for j in 0..bw {
                    self.y[r * bw + j] -= l * self.y[q * bw + j];
                }
            }
        }
        Ok(floored)
    }

    /// The pivot `D` of the part's `r`-th last-but-`bw` row.
    fn d(&self, r: usize) -> f64 {
        let (n, bw) = (self.m.n, self.m.bw);
        self.m.band[(n - bw + r) * (bw + 1)]
    }

    /// `Σ_r Y[r][j] · z[row r] / D[row r]` for every `j`, from the part's forward-substituted
    /// right-hand side `z`.
    fn pull<T: Linear>(&self, z: &[T], out: &mut [T]) {
        let (n, bw) = (self.m.n, self.m.bw);
        for r in 0..bw {
            let v = z[n - bw + r] * (1.0 / self.d(r));
            for (j, o) in out.iter_mut().enumerate() {
                *o = *o + v * self.y[r * bw + j];
            }
        }
    }

    /// The back substitution of the part, after the middle block's solution `x` is known:
    /// `z − Y x` on its last rows, then `L⁻ᵀ D⁻¹`.
    fn finish<T: Linear>(&self, z: &mut [T], x: &[T]) {
        let (n, bw) = (self.m.n, self.m.bw);
        for r in 0..bw {
            let mut s = z[n - bw + r];
            for (j, xj) in x.iter().enumerate() {
                s = s - *xj * self.y[r * bw + j];
            }
            z[n - bw + r] = s;
        }
        self.m.backward(z);
    }
}

/// The factors of [`SymBanded::factorize_split`].
#[derive(Clone, Debug)]
pub(crate) struct Split {
    /// The middle block's first row.
    mid: usize,
    top: Part,
    /// Rows `n − 1` down to `mid + bw`.
    bottom: Part,
    /// The middle block's Schur complement as dense `L D Lᵀ` (row-major, `D` on the diagonal).
    schur: Vec<f64>,
    /// The couplings, kept for their storage.
    c_top: Vec<f64>,
    c_bottom: Vec<f64>,
}

impl Split {
    fn new() -> Split {
        Split {
            mid: 0,
            top: Part::empty(),
            bottom: Part::empty(),
            schur: Vec::new(),
            c_top: Vec::new(),
            c_bottom: Vec::new(),
        }
    }

    /// Fill the parts, the couplings and the middle block from the assembled matrix `a`.
    fn fill(&mut self, a: &SymBanded) {
        let (n, bw) = (a.n, a.bw);
        let w = bw + 1;
        let mid = (n - bw) / 2;
        let below = n - mid - bw;
        self.mid = mid;
        let band = &a.band;
        // The top part: the first rows as they are.
        let top = &mut self.top.m;
        (top.n, top.bw, top.factored, top.split_active) = (mid, bw, false, false);
        top.band.clear();
        top.band.extend_from_slice(&band[..mid * w]);
        // The bottom part in reverse order: its row i is row n − 1 − i, and its entry
        // (i, i − k) is A[n − 1 − i][n − 1 − i + k], stored in row n − 1 − i + k at offset k.
        let bottom = &mut self.bottom.m;
        (bottom.n, bottom.bw, bottom.factored, bottom.split_active) = (below, bw, false, false);
        bottom.band.clear();
        bottom.band.resize(below * w, 0.0);
        for i in 0..below {
            let o = n - 1 - i;
            for k in 0..=bw.min(i) {
                bottom.band[i * w + k] = band[(o + k) * w + k];
            }
        }
        // The couplings on each part's last bw rows: the top's row mid − bw + r meets column
        // mid + j when j ≤ r; the bottom's last row r (row mid + 2bw − 1 − r) meets column
        // mid + j when j ≥ bw − 1 − r.
        self.c_top.clear();
        self.c_top.resize(bw * bw, 0.0);
        self.c_bottom.clear();
        self.c_bottom.resize(bw * bw, 0.0);
        for r in 0..bw {
            for j in 0..bw {
                if j <= r {
                    self.c_top[r * bw + j] = band[(mid + j) * w + (bw + j - r)];
                }
                if j + r + 1 >= bw {
                    let row = mid + 2 * bw - 1 - r;
                    self.c_bottom[r * bw + j] = band[row * w + (2 * bw - 1 - r - j)];
                }
            }
        }
        // The middle block itself (lower triangle, row-major).
        self.schur.clear();
        self.schur.resize(bw * bw, 0.0);
        for j in 0..bw {
            for l in 0..=j {
                self.schur[j * bw + l] = band[(mid + j) * w + (j - l)];
            }
        }
    }

    /// Factorise both parts (at the same time) and the middle block's Schur complement; the
    /// count of floored pivots.
    fn factorize(&mut self, pivots: Pivots) -> Result<usize> {
        let (top, bottom) = (&mut self.top, &mut self.bottom);
        let (c_top, c_bottom) = (&self.c_top, &self.c_bottom);
        let (a, b) = rayon::join(
            || top.factorize(c_top, pivots),
            || bottom.factorize(c_bottom, pivots),
        );
        let mut floored = a? + b?;
        let bw = self.top.m.bw;
        for part in [&self.top, &self.bottom] {
            for r in 0..bw {
                let inv = 1.0 / part.d(r);
                for j in 0..bw {
                    let v = part.y[r * bw + j] * inv;
                    for l in 0..=j {
                        self.schur[j * bw + l] -= v * part.y[r * bw + l];
                    }
                }
            }
        }
        // Dense L D Lᵀ of the Schur complement, its pivots taken as the parts' are.
        let s = &mut self.schur;
        for i in 0..bw {
            for j in 0..i {
                let mut v = s[i * bw + j];
                for k in 0..j {
                    v -= s[i * bw + k] * s[k * bw + k] * s[j * bw + k];
                }
                s[i * bw + j] = v / s[j * bw + j];
            }
            let mut d = s[i * bw + i];
            for k in 0..i {
                let l = s[i * bw + k];
                d -= l * l * s[k * bw + k];
            }
            let row = self.mid + i;
            s[i * bw + i] = match pivots {
                Pivots::Floor(delta) => floored_pivot(d, delta, row, &mut floored)?,
                Pivots::Check(scale) => checked_pivot(d, scale, row)?,
            };
        }
        Ok(floored)
    }

    /// Solve with the factors, in place.
    pub(super) fn solve<T: Linear>(&self, rhs: &mut [T]) {
        let (mid, bw) = (self.mid, self.top.m.bw);
        let (head, rest) = rhs.split_at_mut(mid);
        let (middle, tail) = rest.split_at_mut(bw);
        rayon::join(
            || self.top.m.forward(head),
            || {
                tail.reverse();
                self.bottom.m.forward(tail);
            },
        );
        // The middle block: its right-hand side less both parts' pulls, then the dense
        // factors.
        let mut pulled = vec![T::default(); bw];
        self.top.pull(head, &mut pulled);
        self.bottom.pull(tail, &mut pulled);
        let s = &self.schur;
        let mut x: Vec<T> = (0..bw).map(|j| middle[j] - pulled[j]).collect();
        for i in 0..bw {
            for k in 0..i {
                x[i] = x[i] - x[k] * s[i * bw + k];
            }
        }
        for (i, xi) in x.iter_mut().enumerate() {
            *xi = *xi * (1.0 / s[i * bw + i]);
        }
        for i in (0..bw).rev() {
            for k in i + 1..bw {
                x[i] = x[i] - x[k] * s[k * bw + i];
            }
        }
        middle.copy_from_slice(&x);
        rayon::join(
            || self.top.finish(head, &x),
            || {
                self.bottom.finish(tail, &x);
                tail.reverse();
            },
        );
    }
}

impl SymBanded {
    /// [`SymBanded::factorize`], from both ends at once on two threads when the matrix has
    /// [`SPLIT_FROM`] rows or more (see the module's documentation): the same matrix's factors
    /// in another elimination order, for [`SymBanded::solve_in_place`] only (not
    /// [`SymBanded::l`] and [`SymBanded::d`]). A pivot's index in an error counts from the
    /// end in the lower part.
    ///
    /// # Errors
    /// As [`SymBanded::factorize`].
    pub fn factorize_split(&mut self) -> Result<()> {
        if self.n < SPLIT_FROM.max(4 * self.bw) {
            return self.factorize();
        }
        let w = self.bw + 1;
        let scale = (0..self.n).fold(0.0_f64, |m, i| m.max(self.band[i * w].abs()));
        self.split_factorize(Pivots::Check(scale)).map(|_| ())
    }

    /// [`SymBanded::factorize_regularized`], from both ends at once on two threads when the
    /// matrix has [`SPLIT_FROM`] rows or more (as [`SymBanded::factorize_split`]).
    ///
    /// # Errors
    /// As [`SymBanded::factorize_regularized`].
    pub fn factorize_regularized_split(&mut self, delta: f64) -> Result<usize> {
        if self.n < SPLIT_FROM.max(4 * self.bw) {
            return self.factorize_regularized(delta);
        }
        self.split_factorize(Pivots::Floor(delta))
    }

    fn split_factorize(&mut self, pivots: Pivots) -> Result<usize> {
        let mut split = self.split.take().unwrap_or_else(|| Box::new(Split::new()));
        split.fill(self);
        let result = split.factorize(pivots);
        self.split = Some(split);
        let floored = result?;
        self.factored = true;
        self.split_active = true;
        Ok(floored)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Vec2;

    /// A positive definite band matrix of `n` rows, with a few nearly singular rows when
    /// `weak`.
    fn matrix(n: usize, bw: usize, weak: bool) -> SymBanded {
        let mut a = SymBanded::zeros(n, bw);
        for i in 0..n {
            for j in i.saturating_sub(bw)..=i {
                let v = if i == j {
                    if weak && i % 997 == 4 {
                        1e-300
                    } else {
                        3.0 + (i as f64).sin()
                    }
                } else {
                    0.1 * ((i * 7 + j * 3) as f64).cos()
                };
                a.add(i, j, v);
            }
        }
        a
    }

    /// `A x` from the unfactorised matrix.
    fn apply(a: &SymBanded, x: &[f64]) -> Vec<f64> {
        let n = a.n();
        (0..n)
            .map(|i| {
                let lo = i.saturating_sub(a.bandwidth());
                let hi = (i + a.bandwidth()).min(n - 1);
                (lo..=hi).map(|j| a.get(i, j) * x[j]).sum()
            })
            .collect()
    }

    /// The split factorisation solves what the one-sided one solves, to rounding, for the
    /// bandwidths of `band` (7 in 2-D, 11 in 3-D) and a general one, plain and regularised,
    /// on scalars and on plane vectors; and its residual is at rounding.
    #[test]
    fn split_solves_as_the_one_sided_factorisation() {
        for bw in [3, 7, 11] {
            for n in [SPLIT_FROM, SPLIT_FROM + 1, SPLIT_FROM + 2 * bw + 5] {
                let a = matrix(n, bw, false);
                let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
                let b = apply(&a, &x);
                let mut one = a.clone();
                one.factorize().unwrap();
                let mut split = a.clone();
                split.factorize_split().unwrap();
                assert!(split.split_active, "{bw} {n}");
                let (mut want, mut got) = (b.clone(), b.clone());
                one.solve_in_place(&mut want).unwrap();
                split.solve_in_place(&mut got).unwrap();
                for i in 0..n {
                    assert!((got[i] - want[i]).abs() < 1e-12, "{bw} {n} {i}");
                    assert!((got[i] - x[i]).abs() < 1e-12, "{bw} {n} {i}");
                }
                // Plane vectors: each coordinate as the scalar solve.
                let mut v: Vec<Vec2> = b.iter().map(|&s| Vec2::new(s, -2.0 * s)).collect();
                split.solve_in_place(&mut v).unwrap();
                for i in 0..n {
                    assert_eq!(v[i].x.to_bits(), got[i].to_bits());
                    assert_eq!(v[i].y.to_bits(), (-2.0 * got[i]).to_bits());
                }
                // Regularised, with floored pivots: a floored pivot adds to its row's
                // diagonal, so the residual of the original matrix is at rounding on every
                // other row (the one-sided factorisation floors the same rows, by other
                // amounts: its numbers differ there).
                let weak = matrix(n, bw, true);
                let mut one = weak.clone();
                let mut split = weak.clone();
                let f1 = one.factorize_regularized(0.5).unwrap();
                let f2 = split.factorize_regularized_split(0.5).unwrap();
                assert!(f1 > 0);
                assert_eq!(f1, f2, "{bw} {n}");
                let mut got = b.clone();
                split.solve_in_place(&mut got).unwrap();
                let r = apply(&weak, &got);
                for i in (0..n).filter(|i| i % 997 != 4) {
                    assert!((r[i] - b[i]).abs() < 1e-10, "{bw} {n} {i}");
                }
            }
        }
    }

    /// Below [`SPLIT_FROM`] rows the split factorisation is the one-sided one, bit for bit; a
    /// later one-sided factorisation of the same matrix is solved with its own factors.
    #[test]
    fn short_matrices_and_refactorisations_take_the_one_sided_path() {
        let a = matrix(SPLIT_FROM - 1, 7, false);
        let b: Vec<f64> = (0..a.n()).map(|i| (i as f64).sin()).collect();
        let mut one = a.clone();
        one.factorize().unwrap();
        let mut split = a.clone();
        split.factorize_split().unwrap();
        assert!(!split.split_active);
        let (mut want, mut got) = (b.clone(), b.clone());
        one.solve_in_place(&mut want).unwrap();
        split.solve_in_place(&mut got).unwrap();
        assert!(
            want.iter()
                .zip(&got)
                .all(|(x, y)| x.to_bits() == y.to_bits())
        );

        let long = matrix(SPLIT_FROM + 40, 7, false);
        let mut m = long.clone();
        m.factorize_split().unwrap();
        let mut again = long.clone();
        again.factorize().unwrap();
        m.assign(&long);
        m.factorize().unwrap();
        assert!(!m.split_active);
        let b: Vec<f64> = (0..long.n()).map(|i| (i as f64).cos()).collect();
        let (mut want, mut got) = (b.clone(), b);
        again.solve_in_place(&mut want).unwrap();
        m.solve_in_place(&mut got).unwrap();
        assert!(
            want.iter()
                .zip(&got)
                .all(|(x, y)| x.to_bits() == y.to_bits())
        );
    }

    /// A matrix that is not positive definite is refused by the split path as by the
    /// one-sided one, wherever the bad pivot lies (top part, middle block, bottom part).
    #[test]
    fn indefinite_matrices_are_refused() {
        let n = SPLIT_FROM + 100;
        let mid = (n - 7) / 2;
        for bad in [10, mid + 3, n - 10] {
            let mut a = matrix(n, 7, false);
            a.add(bad, bad, -100.0);
            assert!(a.clone().factorize().is_err());
            assert!(a.factorize_split().is_err(), "{bad}");
        }
    }
}
