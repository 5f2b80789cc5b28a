use super::banded_split::Split;
use super::{Linear, PIVOT_REL};
use crate::error::{Error, Result};

/// A symmetric band matrix with half-bandwidth `bw`, factorised in place as `L D Lᵀ`.
///
/// Storage: `band[i * (bw + 1) + k] = A[i][i − k]` for `k = 0..=bw` (the diagonal and the
/// `bw` entries to its left). Factorisation is O(n·bw²), a solve O(n·bw): the pentadiagonal
/// systems of smoothing splines (bw = 2) cost O(n).
#[derive(Clone, Debug)]
pub struct SymBanded {
    pub(super) n: usize,
    pub(super) bw: usize,
    pub(super) band: Vec<f64>,
    pub(super) factored: bool,
    /// The middle block's factors when [`SymBanded::factorize_split`] factorised the matrix
    /// from both ends (the solve then takes that path); `None` otherwise.
    pub(super) split: Option<Box<Split>>,
}

impl SymBanded {
    /// A zero n×n matrix with half-bandwidth `bw`.
    pub fn zeros(n: usize, bw: usize) -> SymBanded {
        SymBanded {
            n,
            bw,
            band: vec![0.0; n * (bw + 1)],
            factored: false,
            split: None,
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

    /// Factorise as `L D Lᵀ` (L unit lower triangular, banded). No pivoting: meant for
    /// symmetric positive definite matrices.
    ///
    /// # Errors
    /// [`Error::Singular`] when a pivot is (relatively) zero or negative.
    pub fn factorize(&mut self) -> Result<()> {
        let (n, w) = (self.n, self.bw + 1);
        let scale = (0..n).fold(0.0_f64, |m, i| m.max(self.band[i * w].abs()));
        let head = match self.bw {
            7 | 11 => n.min(self.bw),
            _ => n,
        };
        for i in 0..head {
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
            self.band[i * w] = checked_pivot(d, scale, i)?;
        }
        match self.bw {
            7 => self.factorize_rows_fixed::<7>(head, scale)?,
            11 => self.factorize_rows_fixed::<11>(head, scale)?,
            _ => {}
        }
        self.factored = true;
        self.split = None;
        Ok(())
    }

    /// The rows from `from` (at least `BW`) of [`SymBanded::factorize`] for a half-bandwidth
    /// known at compile time: loops of fixed length over a fixed window, the same operations
    /// in the same order.
    fn factorize_rows_fixed<const BW: usize>(&mut self, from: usize, scale: f64) -> Result<()> {
        let w = BW + 1;
        for i in from..self.n {
            let lo = i - BW;
            let win = &mut self.band[lo * w..(i + 1) * w];
            let row = BW * w;
            for jj in 0..BW {
                let mut s = win[row + (BW - jj)];
                for kk in 0..jj {
                    s -= win[row + (BW - kk)] * win[kk * w] * win[jj * w + (jj - kk)];
                }
                win[row + (BW - jj)] = s / win[jj * w];
            }
            let mut d = win[row];
            for kk in 0..BW {
                let l = win[row + (BW - kk)];
                d -= l * l * win[kk * w];
            }
            win[row] = checked_pivot(d, scale, i)?;
        }
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
        self.split = None;
    }

    /// Take the matrix as unfactorised, its factors' storage to be set again row by row
    /// ([`BandRows::assign_from`]) before anything else reads it.
    pub(crate) fn reassemble(&mut self) {
        self.factored = false;
        self.split = None;
    }

    /// The rows `from..to` of the (unfactorised) lower band, to add entries to.
    ///
    /// # Panics
    /// After factorisation, or if the rows are not within the matrix.
    pub(crate) fn rows_mut(&mut self, from: usize, to: usize) -> BandRows<'_> {
        assert!(
            !self.factored && from <= to && to <= self.n,
            "SymBanded::rows_mut"
        );
        let w = self.bw + 1;
        BandRows {
            band: &mut self.band[from * w..to * w],
            from,
            w,
        }
    }

    /// The rows before `row` and the rows from it on, to add entries to from two threads.
    ///
    /// # Panics
    /// After factorisation, or if `row` is past the last row.
    pub(crate) fn split_rows_mut(&mut self, row: usize) -> (BandRows<'_>, BandRows<'_>) {
        assert!(!self.factored && row <= self.n, "SymBanded::split_rows_mut");
        let w = self.bw + 1;
        let (top, bottom) = self.band.split_at_mut(row * w);
        (
            BandRows {
                band: top,
                from: 0,
                w,
            },
            BandRows {
                band: bottom,
                from: row,
                w,
            },
        )
    }

    /// `out += scale · A x` for the (unfactorised) symmetric matrix: each stored entry of the
    /// lower band read once and applied to both its row and its column.
    ///
    /// # Panics
    /// After factorisation, or if the lengths are not `n`.
    pub(crate) fn mul_add(&self, x: &[f64], scale: f64, out: &mut [f64]) {
        assert!(!self.factored, "SymBanded::mul_add after factorisation");
        assert!(
            x.len() == self.n && out.len() == self.n,
            "SymBanded::mul_add lengths"
        );
        match self.bw {
            7 => mul_add_fixed::<7>(&self.band, x, scale, out),
            11 => mul_add_fixed::<11>(&self.band, x, scale, out),
            bw => {
                let w = bw + 1;
                for (i, row) in self.band.chunks_exact(w).enumerate() {
                    let xi = scale * x[i];
                    let mut acc = row[0] * xi;
                    for k in 1..=bw.min(i) {
                        acc += row[k] * scale * x[i - k];
                        out[i - k] += row[k] * xi;
                    }
                    out[i] += acc;
                }
            }
        }
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
        let mut regularized = 0;
        let mut pivot = |d: f64, i: usize| floored_pivot(d, delta, i, &mut regularized);
        match self.bw {
            7 => ldl_fixed::<7>(&mut self.band, self.n, &mut pivot)?,
            11 => ldl_fixed::<11>(&mut self.band, self.n, &mut pivot)?,
            _ => ldl_rows(&mut self.band, self.bw, self.n, &mut pivot)?,
        }
        self.factored = true;
        self.split = None;
        Ok(regularized)
    }

    /// The factor entry `L[i][j]` (i > j, within the band) after [`SymBanded::factorize`].
    pub fn l(&self, i: usize, j: usize) -> f64 {
        debug_assert!(self.factored && self.split.is_none());
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
        debug_assert!(self.factored && self.split.is_none());
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
        match &self.split {
            Some(split) => split.solve(&self.band, self.bw, rhs),
            None => {
                forward_sub(&self.band, self.bw, rhs);
                backward_sub(&self.band, self.bw, rhs);
            }
        }
        Ok(())
    }
}

/// Consecutive rows of a [`SymBanded`]'s lower band ([`SymBanded::rows_mut`],
/// [`SymBanded::split_rows_mut`]): entries are added by their matrix indices.
#[derive(Debug)]
pub(crate) struct BandRows<'a> {
    band: &'a mut [f64],
    /// The first row held.
    from: usize,
    /// The stored entries a row (`bw + 1`).
    w: usize,
}

impl BandRows<'_> {
    /// Whether row `i` is held.
    #[inline]
    pub(crate) fn holds(&self, i: usize) -> bool {
        i >= self.from && (i - self.from) * self.w < self.band.len()
    }

    /// Set the rows held to those of `other`, a matrix of the same shape.
    ///
    /// # Panics
    /// If `other`'s shape differs.
    pub(crate) fn assign_from(&mut self, other: &SymBanded) {
        assert!(
            other.bw + 1 == self.w,
            "BandRows::assign_from shapes differ"
        );
        let at = self.from * self.w;
        self.band
            .copy_from_slice(&other.band[at..at + self.band.len()]);
    }

    /// The largest diagonal entry of the rows held, and 0.
    pub(crate) fn max_diagonal(&self) -> f64 {
        self.band.iter().step_by(self.w).fold(0.0, |m, v| m.max(*v))
    }

    /// Add `v` to `A[i][j]` (`j ≤ i ≤ j + bw`); an entry of a row not held is left out.
    #[inline]
    pub(crate) fn add_lower(&mut self, i: usize, j: usize, v: f64) {
        if self.holds(i) {
            debug_assert!(j <= i && i - j < self.w);
            self.band[(i - self.from) * self.w + (i - j)] += v;
        }
    }
}

/// [`SymBanded::mul_add`] with the half-bandwidth fixed at compile time (loops of fixed
/// length past the first `BW` rows).
fn mul_add_fixed<const BW: usize>(band: &[f64], x: &[f64], scale: f64, out: &mut [f64]) {
    let w = BW + 1;
    for (i, row) in band.chunks_exact(w).enumerate() {
        let xi = scale * x[i];
        let mut acc = row[0] * xi;
        if i >= BW {
            let row: &[f64; BW] = row[1..].try_into().unwrap_or(&[0.0; BW]);
            let xs = &x[i - BW..i];
            let os = &mut out[i - BW..i];
            for k in 0..BW {
                // Entry (i, i − 1 − k) of the row, stored at offset k + 1.
                let j = BW - 1 - k;
                acc += row[k] * scale * xs[j];
                os[j] += row[k] * xi;
            }
        } else {
            for k in 1..=i {
                acc += row[k] * scale * x[i - k];
                out[i - k] += row[k] * xi;
            }
        }
        out[i] += acc;
    }
}

/// Rows `0..n` of the regularised `L D Lᵀ` factorisation on band storage of half-bandwidth
/// `BW` known at compile time (`band`'s Newton matrices: 7 in 2-D, 11 in 3-D), `pivot` taking
/// each pivot: the rows past the first `BW` with loops of fixed length over a fixed window,
/// the same operations in the same order as [`ldl_rows`] (the same factors, bit for bit).
pub(super) fn ldl_fixed<const BW: usize>(
    band: &mut [f64],
    n: usize,
    pivot: &mut impl FnMut(f64, usize) -> Result<f64>,
) -> Result<()> {
    let w = BW + 1;
    let head = n.min(BW);
    ldl_rows(band, BW, head, pivot)?;
    let mut scaled = [0.0_f64; BW];
    for i in head..n {
        let lo = i - BW;
        // Rows lo..=i; row i is the window's last.
        let win = &mut band[lo * w..(i + 1) * w];
        let row = BW * w;
        for jj in 0..BW {
            let mut s = win[row + (BW - jj)];
            for kk in 0..jj {
                s -= scaled[kk] * win[jj * w + (jj - kk)];
            }
            scaled[jj] = s;
            win[row + (BW - jj)] = s / win[jj * w];
        }
        let mut d = win[row];
        for (kk, v) in scaled.iter().enumerate() {
            d -= v * win[row + (BW - kk)];
        }
        win[row] = pivot(d, i)?;
    }
    Ok(())
}

/// The first `rows` rows of the regularised factorisation on band storage of half-bandwidth
/// `bw`, whatever it is (`L[i][k]·D[k]` kept before its division, half the multiplications
/// of [`SymBanded::factorize`]).
pub(super) fn ldl_rows(
    band: &mut [f64],
    bw: usize,
    rows: usize,
    pivot: &mut impl FnMut(f64, usize) -> Result<f64>,
) -> Result<()> {
    let w = bw + 1;
    let mut scaled = vec![0.0_f64; bw];
    for i in 0..rows {
        let lo = i.saturating_sub(bw);
        let m = i - lo;
        // scaled[j - lo] = L[i][j]·D[j], before the division by D[j].
        for j in lo..i {
            let mut s = band[i * w + (i - j)];
            let klo = lo.max(j.saturating_sub(bw));
            for k in klo..j {
                s -= scaled[k - lo] * band[j * w + (j - k)];
            }
            scaled[j - lo] = s;
            band[i * w + (i - j)] = s / band[j * w];
        }
        let mut d = band[i * w];
        for (k, v) in scaled[..m].iter().enumerate() {
            d -= v * band[i * w + (i - (lo + k))];
        }
        band[i * w] = pivot(d, i)?;
    }
    Ok(())
}

/// The forward substitution `L z = rhs` with the factors on band storage of half-bandwidth
/// `bw` (as many rows as `rhs`), in place.
pub(super) fn forward_sub<T: Linear>(band: &[f64], bw: usize, rhs: &mut [T]) {
    let n = rhs.len();
    match bw {
        7 if n > 14 => forward_fixed::<7, T>(band, rhs),
        11 if n > 22 => forward_fixed::<11, T>(band, rhs),
        _ => forward_any(band, bw, rhs),
    }
}

/// `x = L⁻ᵀ D⁻¹ z` with the factors on band storage of half-bandwidth `bw`, in place.
pub(super) fn backward_sub<T: Linear>(band: &[f64], bw: usize, rhs: &mut [T]) {
    let (n, w) = (rhs.len(), bw + 1);
    for (i, r) in rhs.iter_mut().enumerate() {
        *r = *r * (1.0 / band[i * w]);
    }
    match bw {
        7 if n > 14 => backward_fixed::<7, T>(band, rhs),
        11 if n > 22 => backward_fixed::<11, T>(band, rhs),
        _ => backward_any(band, bw, rhs),
    }
}

/// The forward substitution, any bandwidth.
fn forward_any<T: Linear>(band: &[f64], bw: usize, rhs: &mut [T]) {
    let (n, w) = (rhs.len(), bw + 1);
    for i in 0..n {
        let lo = i.saturating_sub(bw);
        let mut s = rhs[i];
        for k in lo..i {
            s = s - rhs[k] * band[i * w + (i - k)];
        }
        rhs[i] = s;
    }
}

/// The back substitution `Lᵀ x = y`, any bandwidth.
fn backward_any<T: Linear>(band: &[f64], bw: usize, rhs: &mut [T]) {
    let (n, w) = (rhs.len(), bw + 1);
    for i in (0..n).rev() {
        let hi = (i + bw).min(n - 1);
        let mut s = rhs[i];
        for k in i + 1..=hi {
            s = s - rhs[k] * band[k * w + (k - i)];
        }
        rhs[i] = s;
    }
}

/// [`forward_any`] for a half-bandwidth `BW` known at compile time (`n > 2·BW`): the rows
/// with a full band take loops of fixed length (the same operations in the same order).
fn forward_fixed<const BW: usize, T: Linear>(band: &[f64], rhs: &mut [T]) {
    let (n, w) = (rhs.len(), BW + 1);
    for i in 0..BW {
        let mut s = rhs[i];
        for k in 0..i {
            s = s - rhs[k] * band[i * w + (i - k)];
        }
        rhs[i] = s;
    }
    for i in BW..n {
        let lo = i - BW;
        let row = &band[i * w..(i + 1) * w];
        let (before, rest) = rhs.split_at_mut(i);
        let before = &before[lo..];
        let mut s = rest[0];
        for kk in 0..BW {
            s = s - before[kk] * row[BW - kk];
        }
        rest[0] = s;
    }
}

/// [`backward_any`] for a half-bandwidth `BW` known at compile time (`n > 2·BW`).
fn backward_fixed<const BW: usize, T: Linear>(band: &[f64], rhs: &mut [T]) {
    let (n, w) = (rhs.len(), BW + 1);
    for i in (n - BW..n).rev() {
        let mut s = rhs[i];
        for k in i + 1..n {
            s = s - rhs[k] * band[k * w + (k - i)];
        }
        rhs[i] = s;
    }
    for i in (0..n - BW).rev() {
        let (head, after) = rhs.split_at_mut(i + 1);
        let after = &after[..BW];
        let rows = &band[(i + 1) * w..(i + 1 + BW) * w];
        let mut s = head[i];
        for kk in 1..=BW {
            s = s - after[kk - 1] * rows[(kk - 1) * w + kk];
        }
        head[i] = s;
    }
}

/// A pivot of [`SymBanded::factorize_regularized`]: `d`, or `delta` when `d` is below it
/// (counted in `regularized`); the error when it is not finite.
pub(super) fn floored_pivot(d: f64, delta: f64, i: usize, regularized: &mut usize) -> Result<f64> {
    if !d.is_finite() {
        return Err(Error::Singular(format!(
            "band matrix has a non-finite pivot ({i})"
        )));
    }
    if d < delta {
        *regularized += 1;
        return Ok(delta);
    }
    Ok(d)
}

/// A pivot of [`SymBanded::factorize`], or the error when it is (relatively) zero,
/// negative or not finite.
pub(super) fn checked_pivot(d: f64, scale: f64, i: usize) -> Result<f64> {
    if d.is_nan() || d <= PIVOT_REL * scale || !d.is_finite() {
        return Err(Error::Singular(format!(
            "band matrix is not positive definite (pivot {i})"
        )));
    }
    Ok(d)
}

/// A band matrix for the tests: diagonal `3 + sin i`, off-diagonal `0.1 cos(7i + 3j)`
/// (positive definite), with the diagonal `1e-300` on the rows `i ≡ 4 (mod m)` when
/// `weak_every` is `Some(m)` (to floor their pivots).
#[cfg(test)]
pub(super) fn test_matrix(n: usize, bw: usize, weak_every: Option<usize>) -> SymBanded {
    let mut a = SymBanded::zeros(n, bw);
    for i in 0..n {
        for j in i.saturating_sub(bw)..=i {
            let v = if i != j {
                0.1 * ((i * 7 + j * 3) as f64).cos()
            } else if weak_every.is_some_and(|m| i % m == 4) {
                1e-300
            } else {
                3.0 + (i as f64).sin()
            };
            a.add(i, j, v);
        }
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The product with the symmetric band matches the dense one entry by entry, for the
    /// fixed half-bandwidths and a general one, short matrices included; `scale` multiplies.
    #[test]
    fn mul_add_is_the_symmetric_product() {
        for (n, bw) in [(40, 7), (5, 7), (60, 11), (9, 11), (30, 3), (2, 3)] {
            let a = test_matrix(n, bw, None);
            let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin() + 0.5).collect();
            let mut got: Vec<f64> = (0..n).map(|i| i as f64).collect();
            a.mul_add(&x, 0.5, &mut got);
            for i in 0..n {
                let row: f64 = (0..n)
                    .filter(|&j| i.abs_diff(j) <= bw)
                    .map(|j| a.get(i, j) * x[j])
                    .sum();
                let want = i as f64 + 0.5 * row;
                assert!(
                    (got[i] - want).abs() <= 1e-14 * (1.0 + want.abs()),
                    "n {n} bw {bw} row {i}: {} against {want}",
                    got[i]
                );
            }
        }
    }

    impl SymBanded {
        /// The general loops of [`SymBanded::solve_in_place`], whatever the bandwidth.
        fn substitute_any(&self, rhs: &mut [f64]) {
            let w = self.bw + 1;
            forward_any(&self.band, self.bw, rhs);
            for (i, r) in rhs.iter_mut().enumerate() {
                *r *= 1.0 / self.band[i * w];
            }
            backward_any(&self.band, self.bw, rhs);
        }

        /// The general loops of [`SymBanded::factorize`], whatever the bandwidth (the
        /// reference of the fixed-bandwidth path).
        fn bw_general_factorize(&mut self) {
            let (n, w) = (self.n, self.bw + 1);
            for i in 0..n {
                let lo = i.saturating_sub(self.bw);
                for j in lo..i {
                    let mut s = self.band[i * w + (i - j)];
                    let klo = lo.max(j.saturating_sub(self.bw));
                    for k in klo..j {
                        s -= self.band[i * w + (i - k)]
                            * self.band[k * w]
                            * self.band[j * w + (j - k)];
                    }
                    self.band[i * w + (i - j)] = s / self.band[j * w];
                }
                let mut d = self.band[i * w];
                for k in lo..i {
                    let l = self.band[i * w + (i - k)];
                    d -= l * l * self.band[k * w];
                }
                self.band[i * w] = d;
            }
        }
    }

    /// The fixed-bandwidth factorisation and substitutions give the general ones' numbers
    /// bit for bit, with floored pivots, at sizes below, at and above twice the bandwidth.
    #[test]
    fn fixed_bandwidth_paths_match_the_general_ones() {
        for bw in [7, 11] {
            for n in [3, 7, 2 * bw, 2 * bw + 1, 60] {
                // A few rows nearly singular, to floor their pivots.
                let mut a = test_matrix(n, bw, Some(9));
                let mut general = a.clone();
                let mut floored_general = 0;
                ldl_rows(&mut general.band, bw, n, &mut |d, i| {
                    floored_pivot(d, 0.5, i, &mut floored_general)
                })
                .unwrap();
                let floored = a.factorize_regularized(0.5).unwrap();
                assert!(n < 5 || floored > 0, "{bw} {n}");
                assert_eq!(floored, floored_general, "{bw} {n}");
                for (x, y) in a.band.iter().zip(&general.band) {
                    assert_eq!(x.to_bits(), y.to_bits(), "{bw} {n}");
                }
                if n >= 5 {
                    // The plain factorisation (no floored pivot: a positive definite matrix).
                    let mut spd = test_matrix(n, bw, None);
                    let mut general = spd.clone();
                    general.bw_general_factorize();
                    spd.factorize().unwrap();
                    for (x, y) in spd.band.iter().zip(&general.band) {
                        assert_eq!(x.to_bits(), y.to_bits(), "plain {bw} {n}");
                    }
                }
                let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 1.3).sin()).collect();
                let mut want = rhs.clone();
                general.substitute_any(&mut want);
                let mut got = rhs;
                a.solve_in_place(&mut got).unwrap();
                for (x, y) in got.iter().zip(&want) {
                    assert_eq!(x.to_bits(), y.to_bits(), "{bw} {n}");
                }
            }
        }
    }

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
