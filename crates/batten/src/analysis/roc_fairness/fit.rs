//! The specification `ρ̂(s)`: a least-squares polynomial of degree 1..=6 in the normalised arc
//! length, on the Chebyshev basis (docs/algorithms/kuragano.md §5.4 step 3;
//! `docs/algorithms/kuragano.md`, "Radius-of-curvature specification").

use crate::error::{Error, Result};

/// Lowest polynomial degree of the specification (linear).
pub(crate) const MIN_DEGREE: usize = 1;

/// Highest polynomial degree of the specification ("six degrees", paper §5).
pub(crate) const MAX_DEGREE: usize = 6;

/// A least-squares polynomial `ρ̂(s)` of degree d on [0, 1] (docs/algorithms/kuragano.md §5.4 step
/// 3), held in the Chebyshev basis `T_k(2s − 1)`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct RhoFit {
    degree: usize,
    chebyshev: Vec<f64>,
}

impl RhoFit {
    /// Fit a polynomial of degree `degree` (1..=6) to `(s_i, rho_i)`, `s_i ∈ [0, 1]`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a degree outside 1..=6, [`Error::LengthMismatch`],
    /// [`Error::TooFewPoints`] for fewer than `degree + 1` samples, [`Error::NonFinite`],
    /// [`Error::Singular`].
    pub(crate) fn fit(s: &[f64], rho: &[f64], degree: usize) -> Result<RhoFit> {
        if !(MIN_DEGREE..=MAX_DEGREE).contains(&degree) {
            return Err(Error::InvalidParameter {
                name: "degree".into(),
                reason: format!("{degree} is outside {MIN_DEGREE}..={MAX_DEGREE}"),
            });
        }
        if s.len() != rho.len() {
            return Err(Error::LengthMismatch {
                what: "rho samples",
                got: rho.len(),
                expected: s.len(),
            });
        }
        if s.len() < degree + 1 {
            return Err(Error::TooFewPoints {
                needed: degree + 1,
                got: s.len(),
            });
        }
        if let Some(index) = s.iter().chain(rho).position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                index: index % s.len(),
            });
        }
        let a = nalgebra::DMatrix::from_fn(s.len(), degree + 1, |i, k| {
            chebyshev_values(2.0 * s[i] - 1.0, degree)[k]
        });
        let b = nalgebra::DVector::from_column_slice(rho);
        let c = a
            .svd(true, true)
            .solve(&b, f64::EPSILON)
            .map_err(|e| Error::Singular(format!("radius-of-curvature fit: {e}")))?;
        Ok(RhoFit {
            degree,
            chebyshev: c.iter().copied().collect(),
        })
    }

    /// The degree d.
    pub(crate) fn degree(&self) -> usize {
        self.degree
    }

    /// `ρ̂(s)`.
    pub(crate) fn eval(&self, s: f64) -> f64 {
        let t = chebyshev_values(2.0 * s - 1.0, self.degree);
        self.chebyshev.iter().zip(&t).map(|(c, t)| c * t).sum()
    }

    /// The coefficients `c_0..c_d` of `ρ̂(s) = Σ c_e s^e` (monomial basis in s).
    #[cfg(test)]
    pub(crate) fn coefficients_ascending(&self) -> Vec<f64> {
        // T_k(2s − 1) as polynomials in s, by the recurrence T_{k+1} = 2x T_k − T_{k−1}.
        let d = self.degree;
        let mut out = vec![0.0; d + 1];
        let mut prev = vec![0.0; d + 2];
        let mut cur = vec![0.0; d + 2];
        prev[0] = 1.0; // T_0
        cur[0] = -1.0; // T_1 = 2s − 1
        cur[1] = 2.0;
        out[0] += self.chebyshev[0];
        for k in 1..=d {
            for (o, c) in out.iter_mut().zip(&cur) {
                *o += self.chebyshev[k] * c;
            }
            // next = 2(2s − 1)·cur − prev
            let mut next = vec![0.0; d + 2];
            for e in 0..=d {
                next[e] += -2.0 * cur[e] - prev[e];
                next[e + 1] += 4.0 * cur[e];
            }
            prev = std::mem::replace(&mut cur, next);
        }
        out
    }

    /// `ρ̂(s_i)` for every `s_i`.
    pub(crate) fn eval_all(&self, s: &[f64]) -> Vec<f64> {
        s.iter().map(|&x| self.eval(x)).collect()
    }
}

/// `T_0(x)..T_d(x)` (d ≤ 6).
fn chebyshev_values(x: f64, d: usize) -> [f64; MAX_DEGREE + 1] {
    let mut t = [0.0; MAX_DEGREE + 1];
    t[0] = 1.0;
    if d >= 1 {
        t[1] = x;
    }
    for k in 2..=d.min(MAX_DEGREE) {
        t[k] = 2.0 * x * t[k - 1] - t[k - 2];
    }
    t
}
