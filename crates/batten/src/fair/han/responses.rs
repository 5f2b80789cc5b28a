//! HAN's unit spline responses `c̃_i^j` and the exact update of c after a move, in O(n)
//! storage (eqs 13–17 with the end fix; `docs/algorithms/han.md`, "Unit spline responses",
//! docs/algorithms/han.md §1.6). The costs are in the module docs of `han`.

use super::sign::abs_max;
use crate::error::{Error, Result};
use crate::spline::{CubicSplineFn, FnEndCondition};

/// The summed response column of a move is walked outward until its entries fall to this
/// fraction of its largest entry. Below half an ulp of the largest change, so the truncated
/// update equals eq 13 to rounding.
pub(super) const RESPONSE_CUTOFF_REL: f64 = 1e-17;

/// HAN's unit spline responses `c̃_i^j` (docs/algorithms/han.md §1.6, eqs 14–17 with the end fix)
/// and the derived `ẽ_i^j`, for the end condition `c_1 = c_2`, `c_{n−1} = c_n`. They depend on x
/// only.
///
/// Storage is O(n): `c̃_{j−1}^j, c̃_j^j, c̃_{j+1}^j` for each interior j plus the sweep
/// coefficients; farther entries come from `c̃_i^j = −a_i c̃_{i+1}^j` (i ≤ j−2) and
/// `c̃_i^j = −a*_i c̃_{i−1}^j` (i ≥ j+2), O(|i−j|) each. Indices are 0-based; the columns are
/// the interior points `1..=n−2`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct UnitResponses {
    h: Vec<f64>,
    pub(super) inv_h: Vec<f64>,
    /// Forward sweep `a`, length n − 1 (`a[0] = −1`).
    a: Vec<f64>,
    /// Backward sweep `a*`, length n; `a_star[0]` is unused (0).
    a_star: Vec<f64>,
    diag: Vec<f64>,
    left: Vec<f64>,
    right: Vec<f64>,
    /// `ẽ_{j−1}^j, ẽ_j^j, ẽ_{j+1}^j` per column j (0 outside the interior): the entries the
    /// coarse cases use, computed once.
    e_near: Vec<[f64; 3]>,
}

impl UnitResponses {
    /// The responses for abscissae `x` (strictly increasing, at least 3 values).
    ///
    /// # Errors
    /// As [`CubicSplineFn::try_new`].
    #[cfg(test)]
    pub(crate) fn new(x: &[f64]) -> Result<UnitResponses> {
        let s = CubicSplineFn::try_new(x.to_vec(), vec![0.0; x.len()], FnEndCondition::Han)?;
        UnitResponses::from_spline(&s)
    }

    /// The responses for the abscissae of `spline` (which must use [`FnEndCondition::Han`]),
    /// reusing its sweep coefficients.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for another end condition.
    pub(crate) fn from_spline(spline: &CubicSplineFn) -> Result<UnitResponses> {
        if spline.end_condition() != FnEndCondition::Han {
            return Err(Error::InvalidParameter {
                name: "end condition".into(),
                reason: "unit responses are defined for the Han end condition".into(),
            });
        }
        let n = spline.len();
        let h = spline.h().to_vec();
        let a = spline.forward_a().to_vec();
        let mut a_star = vec![0.0; n];
        a_star[1..].copy_from_slice(spline.backward_a());
        let mut diag = vec![0.0; n];
        let mut left = vec![0.0; n];
        let mut right = vec![0.0; n];
        for j in 1..n - 1 {
            let (h0, h1) = (h[j - 1], h[j]);
            let a_bar = if j >= 2 { a[j - 1] } else { 0.0 };
            let a_star_bar = if j + 2 < n { a_star[j + 1] } else { 0.0 };
            let den = 2.0 * (h0 + h1) - a[j - 1] * h0 - a_star[j + 1] * h1;
            let d = -((1.0 + a_bar) / h0 + (1.0 + a_star_bar) / h1) / den; // eq 14
            diag[j] = d;
            left[j] = if j >= 2 {
                a[j - 1] * (1.0 / (h0 * h0) - d)
            } else {
                d
            }; // eq 15
            right[j] = if j + 2 < n {
                a_star[j + 1] * (1.0 / (h1 * h1) - d)
            } else {
                d
            };
        }
        let mut resp = UnitResponses {
            inv_h: h.iter().map(|v| 1.0 / v).collect(),
            h,
            a,
            a_star,
            diag,
            left,
            right,
            e_near: Vec::new(),
        };
        let mut e_near = vec![[0.0; 3]; n];
        for (j, near) in e_near.iter_mut().enumerate().take(n - 1).skip(1) {
            *near = [
                resp.e_walk(j - 1, j),
                resp.e_walk(j, j),
                resp.e_walk(j + 1, j),
            ];
        }
        resp.e_near = e_near;
        Ok(resp)
    }

    /// Number of points n.
    pub(crate) fn len(&self) -> usize {
        self.diag.len()
    }

    /// `c̃_i^j`: the change of `c_i` per unit move of `y_j`, for `i < n` and an interior j.
    /// O(|i − j|).
    ///
    /// # Panics
    /// When j is not interior or i is out of range.
    #[cfg(test)]
    pub(crate) fn c(&self, i: usize, j: usize) -> f64 {
        let n = self.len();
        assert!(
            j >= 1 && j + 1 < n && i < n,
            "unit response ({i}, {j}) out of range (n = {n})"
        );
        self.c_at(i, j)
    }

    /// [`UnitResponses::c`] for indices the caller has checked (the hot path).
    #[inline]
    pub(super) fn c_at(&self, i: usize, j: usize) -> f64 {
        debug_assert!(j >= 1 && j + 1 < self.len() && i < self.len());
        if i == j {
            self.diag[j]
        } else if i + 1 == j {
            self.left[j]
        } else if i == j + 1 {
            self.right[j]
        } else if i < j {
            // Walk outward from j so that c̃_0^j = c̃_1^j holds bit for bit (−a_0 = 1).
            let mut v = self.left[j];
            for k in (i..=j - 2).rev() {
                v *= -self.a[k];
            }
            v
        } else {
            let mut v = self.right[j];
            for k in j + 2..=i {
                v *= -self.a_star[k];
            }
            v
        }
    }

    /// `ẽ_i^j = (c̃_{i+1}^j − c̃_i^j)/h_i − (c̃_i^j − c̃_{i−1}^j)/h_{i−1}`, 0 at the end points
    /// (docs/algorithms/han.md §1.6). O(|i − j|).
    ///
    /// # Panics
    /// As [`UnitResponses::c`].
    #[cfg(test)]
    pub(crate) fn e(&self, i: usize, j: usize) -> f64 {
        let n = self.len();
        assert!(
            j >= 1 && j + 1 < n && i < n,
            "unit response ({i}, {j}) out of range (n = {n})"
        );
        self.e_at(i, j)
    }

    /// [`UnitResponses::e`] for indices the caller has checked (the hot path).
    #[inline]
    pub(super) fn e_at(&self, i: usize, j: usize) -> f64 {
        debug_assert!(j >= 1 && j + 1 < self.len() && i < self.len());
        if i + 1 >= j && i <= j + 1 {
            return self.e_near[j][i + 1 - j];
        }
        self.e_walk(i, j)
    }

    /// `ẽ_i^j` from the column entries (for valid indices).
    fn e_walk(&self, i: usize, j: usize) -> f64 {
        if i == 0 || i == self.len() - 1 {
            return 0.0;
        }
        let (cm, c0, cp) = (self.c_at(i - 1, j), self.c_at(i, j), self.c_at(i + 1, j));
        (cp - c0) / self.h[i] - (c0 - cm) / self.h[i - 1]
    }

    /// The whole column `c̃^j` (length n), by the recurrences. O(n); for inspection and tests.
    ///
    /// # Panics
    /// As [`UnitResponses::c`].
    #[cfg(test)]
    pub(crate) fn column_c(&self, j: usize) -> Vec<f64> {
        let n = self.len();
        let mut col = vec![0.0; n];
        col[j] = self.c(j, j);
        col[j - 1] = self.left[j];
        col[j + 1] = self.right[j];
        for i in (0..j.saturating_sub(1)).rev() {
            col[i] = -self.a[i] * col[i + 1];
        }
        for i in j + 2..n {
            col[i] = -self.a_star[i] * col[i - 1];
        }
        col
    }

    /// The whole column `ẽ^j` (length n). O(n); for inspection and tests.
    ///
    /// # Panics
    /// As [`UnitResponses::c`].
    #[cfg(test)]
    pub(crate) fn column_e(&self, j: usize) -> Vec<f64> {
        let c = self.column_c(j);
        let n = c.len();
        let mut e = vec![0.0; n];
        for i in 1..n - 1 {
            e[i] = (c[i + 1] - c[i]) / self.h[i] - (c[i] - c[i - 1]) / self.h[i - 1];
        }
        e
    }

    /// Eq 13 for a move of the consecutive interior points `start, start+1, …` by `gammas`:
    /// `c ← c + Σ γ_j c̃^j`. Returns the inclusive index range of `c` that changed and the
    /// largest new |c_i| on it. Entries below [`RESPONSE_CUTOFF_REL`] of the largest change
    /// are not added. O(57 + len²).
    ///
    /// # Panics
    /// When the moved points are not all interior or `c` has the wrong length.
    pub(crate) fn add_columns(&self, start: usize, gammas: &[f64], c: &mut [f64]) -> Changed {
        let n = self.len();
        assert_eq!(c.len(), n, "add_columns: c has the wrong length");
        assert!(
            start >= 1 && !gammas.is_empty() && start + gammas.len() < n,
            "add_columns: moved points must be interior"
        );
        let end = start + gammas.len() - 1;
        let (lo, hi) = (start - 1, end + 1);
        // The summed column on lo..=hi, in a fixed order (bitwise c̃_0 = c̃_1 preserved).
        let mut core = [0.0_f64; 8];
        let width = hi - lo + 1;
        for (k, &g) in gammas.iter().enumerate() {
            // Column j on lo..=hi, walked outward from j with the same products as `c_at`;
            // every entry of `core` sums the columns in the order of `gammas`.
            let j = start + k;
            core[j - lo] += g * self.diag[j];
            let mut v = self.left[j];
            core[j - 1 - lo] += g * v;
            for i in (lo..j - 1).rev() {
                v *= -self.a[i];
                core[i - lo] += g * v;
            }
            let mut v = self.right[j];
            core[j + 1 - lo] += g * v;
            for i in j + 2..=hi {
                v *= -self.a_star[i];
                core[i - lo] += g * v;
            }
        }
        let big = abs_max(&core[..width]);
        let (mut first, mut last) = (lo, hi);
        for (ci, d) in c[lo..=hi].iter_mut().zip(&core[..width]) {
            *ci += d;
        }
        let cut = RESPONSE_CUTOFF_REL * big;
        // Left of the moved points every column obeys c̃_i = −a_i c̃_{i+1}, so the sum does.
        let mut d = core[0];
        let mut i = lo;
        while i > 0 {
            i -= 1;
            d *= -self.a[i];
            if d.abs() <= cut {
                break;
            }
            c[i] += d;
            first = i;
        }
        let mut d = core[width - 1];
        let mut i = hi;
        while i + 1 < n {
            i += 1;
            d *= -self.a_star[i];
            if d.abs() <= cut {
                break;
            }
            c[i] += d;
            last = i;
        }
        Changed::of(c, first, last)
    }
}

/// The entries of an array that a local update rewrote: `lo..=hi`, and the largest new
/// magnitude among them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Changed {
    /// First rewritten index.
    pub lo: usize,
    /// Last rewritten index (inclusive).
    pub hi: usize,
    /// Largest |v_i| on `lo..=hi` after the update.
    pub max: f64,
}

impl Changed {
    /// The entries `lo..=hi` of `values`, rewritten.
    pub(super) fn of(values: &[f64], lo: usize, hi: usize) -> Changed {
        Changed {
            lo,
            hi,
            max: abs_max(&values[lo..=hi]),
        }
    }
}
