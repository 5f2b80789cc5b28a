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
//! `A_TT = L_T D_T L_Tᵀ` is factorised from its first row down, and `A_BB = U_B D_B U_Bᵀ` (`U`
//! unit upper) from its last row up, both at the same time and in the matrix's own storage. Each part
//! meets the middle block only in its last `bw` rows (in its own order), so `Y = L⁻¹ A_·S` is
//! zero above them: `bw × bw` numbers a part. The middle block's Schur complement
//! `A_SS − Y_Tᵀ D_T⁻¹ Y_T − Y_Bᵀ D_B⁻¹ Y_B` is then factorised densely. A solve runs both
//! parts' forward substitutions at the same time, solves the middle block, and runs both back
//! substitutions at the same time: the work of the one-sided factorisation, in less time on
//! two cores (both are bound by memory traffic: on a 56 044-row matrix of half-bandwidth 7 the
//! factorisation takes 1.1 → 0.9 ms and a solve 0.95 → 0.68 ms). The numbers differ from the one-sided factorisation's by rounding only
//! (another elimination order); `band`'s interior point and debiasing stage use it for long
//! curves ([`SPLIT_FROM`] rows and more).

use super::Linear;
use super::banded::{
    SymBanded, backward_sub, checked_pivot, floored_pivot, forward_sub, ldl_fixed, ldl_rows,
};
use crate::error::Result;

/// From this many rows on, `band`'s Newton and data-term matrices are factorised from both ends
/// ([`SymBanded::factorize_split`]). Below it the hand-off to a second thread costs more than
/// it saves, and the results stay those of the one-sided factorisation bit for bit (every curve
/// of the quality benchmark is below it).
pub(crate) const SPLIT_FROM: usize = 1 << 14;

/// How the pivots are taken: floored at `delta` (counted), or refused when not positive
/// relative to `scale`.
#[derive(Clone, Copy, Debug)]
enum Pivots {
    Floor(f64),
    Check(f64),
}

impl Pivots {
    /// The pivot `d` of row `i` under this rule; `floored` counts the floored ones.
    fn take(self, d: f64, i: usize, floored: &mut usize) -> Result<f64> {
        match self {
            Pivots::Floor(delta) => floored_pivot(d, delta, i, floored),
            Pivots::Check(scale) => checked_pivot(d, scale, i),
        }
    }
}

/// What [`SymBanded::factorize_split`] keeps besides the factors, which stay in the matrix's
/// own storage: the top part's `L D Lᵀ` in rows `0..mid`, the bottom part's `U D Uᵀ` (`U`
/// unit upper, stored where `Uᵀ` would be) in rows `mid + bw..n`, the middle rows untouched.
#[derive(Clone, Debug)]
pub(crate) struct Split {
    /// The middle block's first row.
    mid: usize,
    /// `Y = L⁻¹ A_TS` on the top part's last `bw` rows and `Y = U⁻¹ A_BS` on the bottom
    /// part's first `bw` rows (row-major, `bw × bw`): zero elsewhere.
    y_top: Vec<f64>,
    y_bottom: Vec<f64>,
    /// The middle block's Schur complement, factorised as `L D Lᵀ` in band storage of
    /// half-bandwidth `bw − 1` (dense: entry `(j, l)` at `j·bw + j − l`).
    schur: Vec<f64>,
}

/// Rows `0..n` of a `U D Uᵀ` factorisation from the last row up, on band storage of
/// half-bandwidth `BW` (the mirror of [`ldl_fixed`]): `U[i][j]` (`i < j ≤ i + BW`) overwrites
/// `A[j][i]`, `D[i]` the diagonal. The entries of the first rows that reach left of row 0 (a
/// coupling to rows before the slice) are neither read nor written.
fn udu<const BW: usize>(
    band: &mut [f64],
    n: usize,
    pivot: &mut impl FnMut(f64, usize) -> Result<f64>,
) -> Result<()> {
    let w = BW + 1;
    let mut scaled = [0.0_f64; BW];
    for i in (0..n).rev() {
        let m = BW.min(n - 1 - i);
        if m == BW {
            // A full window: rows i..=i + BW, with loops of fixed length (row i is the
            // window's first; `U[i][j]` sits in row j at offset j − i).
            let win = &mut band[i * w..(i + BW + 1) * w];
            for jj in (0..BW).rev() {
                let rj = (1 + jj) * w;
                let mut s = win[rj + 1 + jj];
                for kk in jj + 1..BW {
                    s -= scaled[kk] * win[(1 + kk) * w + (kk - jj)];
                }
                scaled[jj] = s;
                win[rj + 1 + jj] = s / win[rj];
            }
            let mut d = win[0];
            for (kk, v) in scaled.iter().enumerate() {
                d -= v * win[(1 + kk) * w + 1 + kk];
            }
            win[0] = pivot(d, i)?;
            continue;
        }
        // The last rows: scaled[j − i − 1] = U[i][j]·D[j], before the division by D[j].
        for jj in (0..m).rev() {
            let j = i + 1 + jj;
            let mut s = band[j * w + (j - i)];
            for kk in jj + 1..m {
                let k = i + 1 + kk;
                s -= scaled[kk] * band[k * w + (k - j)];
            }
            scaled[jj] = s;
            band[j * w + (j - i)] = s / band[j * w];
        }
        let mut d = band[i * w];
        for kk in 0..m {
            let k = i + 1 + kk;
            d -= scaled[kk] * band[k * w + (k - i)];
        }
        band[i * w] = pivot(d, i)?;
    }
    Ok(())
}

/// `U z = rhs` from the last row up, with the factors of [`udu`] (half-bandwidth `BW`), in
/// place.
fn forward_up<const BW: usize, T: Linear>(band: &[f64], rhs: &mut [T]) {
    let (n, w) = (rhs.len(), BW + 1);
    for i in (0..n).rev() {
        let mut s = rhs[i];
        if i + BW < n {
            // A full window: loops of fixed length.
            let after = &rhs[i + 1..=i + BW];
            let rows = &band[(i + 1) * w..(i + 1 + BW) * w];
            for kk in 0..BW {
                s = s - after[kk] * rows[kk * w + 1 + kk];
            }
        } else {
            for k in i + 1..n {
                s = s - rhs[k] * band[k * w + (k - i)];
            }
        }
        rhs[i] = s;
    }
}

/// `x = U⁻ᵀ D⁻¹ z` from the first row down, with the factors of [`udu`] (half-bandwidth
/// `BW`), in place.
fn backward_up<const BW: usize, T: Linear>(band: &[f64], rhs: &mut [T]) {
    let w = BW + 1;
    for (i, r) in rhs.iter_mut().enumerate() {
        *r = *r * (1.0 / band[i * w]);
    }
    for i in 0..rhs.len() {
        let mut s = rhs[i];
        if i >= BW {
            // A full window: loops of fixed length.
            let before = &rhs[i - BW..i];
            let row = &band[i * w..(i + 1) * w];
            for kk in 0..BW {
                s = s - before[kk] * row[BW - kk];
            }
        } else {
            for k in 0..i {
                s = s - rhs[k] * band[i * w + (i - k)];
            }
        }
        rhs[i] = s;
    }
}

impl Split {
    /// Factorise `a` in place from both ends, then the middle block's Schur complement: what
    /// the solve needs besides `a`, and the count of floored pivots.
    fn factorize<const BW: usize>(a: &mut SymBanded, pivots: Pivots) -> Result<(Split, usize)> {
        let (n, w) = (a.n, BW + 1);
        let mid = (n - BW) / 2;
        let below = n - mid - BW;
        let (top, rest) = a.band.split_at_mut(mid * w);
        let (middle, bottom) = rest.split_at_mut(BW * w);
        let first = mid + BW;
        let (ft, fb) = rayon::join(
            || {
                let mut floored = 0;
                ldl_fixed::<BW>(top, mid, &mut |d, i| pivots.take(d, i, &mut floored))
                    .map(|()| floored)
            },
            || {
                let mut floored = 0;
                udu::<BW>(bottom, below, &mut |d, i| {
                    pivots.take(d, first + i, &mut floored)
                })
                .map(|()| floored)
            },
        );
        let mut floored = ft? + fb?;
        // The couplings on each part's rows next to the middle block, then Y. The top's row
        // mid − BW + r meets column mid + j when j ≤ r (entry in the middle row mid + j); the
        // bottom's row r (row mid + BW + r) meets column mid + j when r ≤ j (in its own row).
        let mut y_top = vec![0.0; BW * BW];
        let mut y_bottom = vec![0.0; BW * BW];
        for r in 0..BW {
            for j in 0..BW {
                if j <= r {
                    y_top[r * BW + j] = middle[j * w + (BW + j - r)];
                }
                if r <= j {
                    y_bottom[r * BW + j] = bottom[r * w + (BW + r - j)];
                }
            }
        }
        for r in 0..BW {
            let row = mid - BW + r;
            for q in 0..r {
                let l = top[row * w + (r - q)];
                for j in 0..BW {
                    y_top[r * BW + j] -= l * y_top[q * BW + j];
                }
            }
        }
        for r in (0..BW).rev() {
            for q in r + 1..BW {
                let u = bottom[q * w + (q - r)];
                for j in 0..BW {
                    y_bottom[r * BW + j] -= u * y_bottom[q * BW + j];
                }
            }
        }
        // The Schur complement A_SS − Yᵀ D⁻¹ Y of both parts, lower triangle.
        let mut schur = vec![0.0; BW * BW];
        for j in 0..BW {
            for l in 0..=j {
                schur[j * BW + (j - l)] = middle[j * w + (j - l)];
            }
        }
        // Each part's `Yᵀ D⁻¹ Y`, `d(r)` the pivot of its row next to the middle block.
        let mut less = |y: &[f64], d: &dyn Fn(usize) -> f64| {
            for r in 0..BW {
                for j in 0..BW {
                    let v = y[r * BW + j] / d(r);
                    for l in 0..=j {
                        schur[j * BW + (j - l)] -= v * y[r * BW + l];
                    }
                }
            }
        };
        less(&y_top, &|r| top[(mid - BW + r) * w]);
        less(&y_bottom, &|r| bottom[r * w]);
        // L D Lᵀ of the Schur complement, its pivots taken as the parts' are.
        ldl_rows(&mut schur, BW - 1, BW, &mut |d, i| {
            pivots.take(d, mid + i, &mut floored)
        })?;
        Ok((
            Split {
                mid,
                y_top,
                y_bottom,
                schur,
            },
            floored,
        ))
    }

    /// Solve with the factors (in `band`, half-bandwidth `bw`), in place.
    pub(super) fn solve<T: Linear>(&self, band: &[f64], bw: usize, rhs: &mut [T]) {
        match bw {
            7 => self.solve_fixed::<7, T>(band, rhs),
            _ => self.solve_fixed::<11, T>(band, rhs),
        }
    }

    fn solve_fixed<const BW: usize, T: Linear>(&self, band: &[f64], rhs: &mut [T]) {
        let (mid, bw, w) = (self.mid, BW, BW + 1);
        let (top, rest) = band.split_at(mid * w);
        let bottom = &rest[bw * w..];
        let (head, rest) = rhs.split_at_mut(mid);
        let (middle, tail) = rest.split_at_mut(bw);
        rayon::join(
            || forward_sub(top, bw, head),
            || forward_up::<BW, T>(bottom, tail),
        );
        // The middle block: its right-hand side less both parts' pulls `Yᵀ D⁻¹ z`, then the
        // dense factors.
        let mut x: Vec<T> = middle.to_vec();
        for r in 0..bw {
            let zt = head[mid - bw + r] * (1.0 / top[(mid - bw + r) * w]);
            let zb = tail[r] * (1.0 / bottom[r * w]);
            for (j, xj) in x.iter_mut().enumerate() {
                *xj = *xj - zt * self.y_top[r * bw + j] - zb * self.y_bottom[r * bw + j];
            }
        }
        forward_sub(&self.schur, bw - 1, &mut x);
        backward_sub(&self.schur, bw - 1, &mut x);
        middle.copy_from_slice(&x);
        // Each part: `z − Y x` on its rows next to the middle block, then its back
        // substitution.
        let less = |z: &mut T, r: usize, y: &[f64]| {
            for (j, xj) in x.iter().enumerate() {
                *z = *z - *xj * y[r * bw + j];
            }
        };
        rayon::join(
            || {
                for r in 0..bw {
                    less(&mut head[mid - bw + r], r, &self.y_top);
                }
                backward_sub(top, bw, head);
            },
            || {
                for r in 0..bw {
                    less(&mut tail[r], r, &self.y_bottom);
                }
                backward_up::<BW, T>(bottom, tail);
            },
        );
    }
}

impl SymBanded {
    /// [`SymBanded::factorize`], from both ends at once on two threads when the matrix has
    /// `SPLIT_FROM` (16 384) rows or more and a half-bandwidth of 7 or 11 (`band`'s; see the
    /// module's documentation): the same matrix's factors in another elimination order, in
    /// place, for [`SymBanded::solve_in_place`] only (not [`SymBanded::l`] and
    /// [`SymBanded::d`]).
    ///
    /// # Errors
    /// As [`SymBanded::factorize`].
    pub fn factorize_split(&mut self) -> Result<()> {
        if !self.splits() {
            return self.factorize();
        }
        let w = self.bw + 1;
        let scale = (0..self.n).fold(0.0_f64, |m, i| m.max(self.band[i * w].abs()));
        self.split_factorize(Pivots::Check(scale)).map(|_| ())
    }

    /// [`SymBanded::factorize_regularized`], from both ends at once on two threads (as
    /// [`SymBanded::factorize_split`]).
    ///
    /// # Errors
    /// As [`SymBanded::factorize_regularized`].
    pub fn factorize_regularized_split(&mut self, delta: f64) -> Result<usize> {
        if !self.splits() {
            return self.factorize_regularized(delta);
        }
        self.split_factorize(Pivots::Floor(delta))
    }

    /// Whether [`SymBanded::factorize_split`] factorises from both ends.
    fn splits(&self) -> bool {
        self.n >= SPLIT_FROM && matches!(self.bw, 7 | 11)
    }

    fn split_factorize(&mut self, pivots: Pivots) -> Result<usize> {
        self.split = None;
        self.factored = false;
        let (split, floored) = match self.bw {
            7 => Split::factorize::<7>(self, pivots)?,
            _ => Split::factorize::<11>(self, pivots)?,
        };
        self.split = Some(Box::new(split));
        self.factored = true;
        Ok(floored)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Vec2;
    use crate::numeric::banded::test_matrix;

    /// A positive definite band matrix of `n` rows, with a few nearly singular rows when
    /// `weak`.
    fn matrix(n: usize, bw: usize, weak: bool) -> SymBanded {
        test_matrix(n, bw, weak.then_some(997))
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
        for bw in [7, 11] {
            for n in [SPLIT_FROM, SPLIT_FROM + 1, SPLIT_FROM + 2 * bw + 5] {
                let a = matrix(n, bw, false);
                let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
                let b = apply(&a, &x);
                let mut one = a.clone();
                one.factorize().unwrap();
                let mut split = a.clone();
                split.factorize_split().unwrap();
                assert!(split.split.is_some(), "{bw} {n}");
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
        assert!(split.split.is_none());
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
        assert!(m.split.is_none());
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
