use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// A validated, non-decreasing knot vector with finite entries.
///
/// Validation (as truck's `KnotVec`): every knot finite (NaN is rejected), non-decreasing.
/// Length against a degree and control-point count is checked by [`super::BSplineCurve`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "Vec<f64>", into = "Vec<f64>")]
pub struct KnotVector(Vec<f64>);

impl KnotVector {
    /// Validate a knot sequence.
    ///
    /// # Errors
    /// [`Error::InvalidKnots`] for an empty vector, a non-finite knot or a decreasing pair.
    pub fn try_new(knots: Vec<f64>) -> Result<KnotVector> {
        if knots.is_empty() {
            return Err(Error::InvalidKnots("empty".into()));
        }
        if let Some(i) = knots.iter().position(|k| !k.is_finite()) {
            return Err(Error::InvalidKnots(format!("knot {i} is not finite")));
        }
        if let Some(i) = knots.windows(2).position(|w| w[1] < w[0]) {
            return Err(Error::InvalidKnots(format!(
                "knots must be non-decreasing: knot {} = {} < knot {} = {}",
                i + 1,
                knots[i + 1],
                i,
                knots[i]
            )));
        }
        Ok(KnotVector(knots))
    }

    /// Validate a knot sequence.
    ///
    /// # Panics
    /// When [`KnotVector::try_new`] would return an error.
    pub fn new(knots: Vec<f64>) -> KnotVector {
        match KnotVector::try_new(knots) {
            Ok(k) => k,
            Err(e) => panic!("{e}"),
        }
    }

    /// The clamped uniform knot vector for `n_ctrl` control points of degree `p` on [0, 1]:
    /// `p + 1` zeros, the interior knots `1/(n−p), …`, `p + 1` ones.
    ///
    /// # Errors
    /// [`Error::TooFewPoints`] when `n_ctrl < p + 1`.
    pub fn clamped_uniform(p: usize, n_ctrl: usize) -> Result<KnotVector> {
        if n_ctrl < p + 1 {
            return Err(Error::TooFewPoints {
                needed: p + 1,
                got: n_ctrl,
            });
        }
        let spans = n_ctrl - p;
        let mut k = vec![0.0; p + 1];
        k.extend((1..spans).map(|i| i as f64 / spans as f64));
        k.extend(std::iter::repeat_n(1.0, p + 1));
        Ok(KnotVector(k))
    }

    /// The knots.
    pub fn as_slice(&self) -> &[f64] {
        &self.0
    }

    /// Number of knots.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Always false for a validated vector.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Multiplicity of the knot value `u` (exact comparison).
    pub fn multiplicity(&self, u: f64) -> usize {
        self.0.iter().filter(|&&k| k == u).count()
    }

    /// The index `k` of the span `[u_k, u_{k+1})` of a degree-`p` curve with `n_ctrl`
    /// control points that contains `t`, clamped to `p..=n_ctrl−1`: the last non-empty span
    /// is used for `t` at (or beyond) the end of the domain (docs/algorithms/README.md §0.5).
    pub fn find_span(&self, p: usize, n_ctrl: usize, t: f64) -> usize {
        let u = &self.0;
        let hi = n_ctrl - 1;
        if t >= u[hi + 1] {
            // Last non-empty span.
            let mut k = hi;
            while k > p && u[k] == u[k + 1] {
                k -= 1;
            }
            return k;
        }
        if t <= u[p] {
            let mut k = p;
            while k < hi && u[k] == u[k + 1] {
                k += 1;
            }
            return k;
        }
        // Binary search for u[k] <= t < u[k+1].
        let (mut lo, mut hi_) = (p, hi + 1);
        while hi_ - lo > 1 {
            let mid = (lo + hi_) / 2;
            if t < u[mid] {
                hi_ = mid;
            } else {
                lo = mid;
            }
        }
        lo
    }

    /// [`KnotVector::find_span`] for parameters visited in increasing order: the search walks
    /// forward from `from`, a span found for a smaller parameter, instead of bisecting. The
    /// result is the same as [`KnotVector::find_span`]'s (the unique `k` with
    /// `u_k ≤ t < u_{k+1}` inside the domain, the same clamping at its ends); O(1) amortised in
    /// a sweep over sorted parameters.
    pub(crate) fn find_span_from(&self, p: usize, n_ctrl: usize, t: f64, from: usize) -> usize {
        let u = &self.0;
        let hi = n_ctrl - 1;
        if t >= u[hi + 1] || t <= u[p] || from < p || from > hi || u[from] > t {
            return self.find_span(p, n_ctrl, t);
        }
        // u[from] ≤ t < u[hi + 1]: the walk stops at some k ≤ hi.
        let mut k = from;
        while u[k + 1] <= t {
            k += 1;
        }
        k
    }

    /// The Greville (Schoenberg, "correspondence") abscissae of a degree-`p` spline on these
    /// knots: `ξ_i = (u_{i+1} + … + u_{i+p}) / p`, one per control point (docs/algorithms/README.md
    /// §0.5).
    pub fn greville(&self, p: usize) -> Vec<f64> {
        let u = &self.0;
        let n = u.len().saturating_sub(p + 1);
        (0..n)
            .map(|i| u[i + 1..=i + p].iter().sum::<f64>() / p as f64)
            .collect()
    }

    /// Insert a knot value, keeping the order (used by knot insertion).
    pub(crate) fn insert(&mut self, index: usize, u: f64) {
        self.0.insert(index, u);
    }

    /// Remove the knot at `index` (used by knot removal).
    pub(crate) fn remove(&mut self, index: usize) -> f64 {
        self.0.remove(index)
    }
}

impl TryFrom<Vec<f64>> for KnotVector {
    type Error = Error;
    fn try_from(v: Vec<f64>) -> Result<KnotVector> {
        KnotVector::try_new(v)
    }
}

impl From<KnotVector> for Vec<f64> {
    fn from(k: KnotVector) -> Vec<f64> {
        k.0
    }
}

/// The span of a piecewise curve with increasing breakpoints `breaks` (at least two) that
/// contains `t`: the `i` with `breaks[i] ≤ t < breaks[i + 1]`, the last span at its end
/// break, and clamped to the first and last span outside the domain.
pub(crate) fn break_span(breaks: &[f64], t: f64) -> usize {
    let last = breaks.len().saturating_sub(2);
    match breaks.binary_search_by(|k| k.total_cmp(&t)) {
        Ok(i) => i.min(last),
        Err(i) => i.saturating_sub(1).min(last),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn break_span_finds_and_clamps() {
        let b = [0.0, 1.0, 2.0, 3.0];
        for (t, want) in [
            (-1.0, 0),
            (0.0, 0),
            (0.5, 0),
            (1.0, 1),
            (2.5, 2),
            (3.0, 2),
            (4.0, 2),
        ] {
            assert_eq!(break_span(&b, t), want, "t = {t}");
        }
        assert_eq!(break_span(&[0.0, 1.0], 5.0), 0);
    }

    #[test]
    fn validation() {
        assert!(KnotVector::try_new(vec![]).is_err());
        assert!(KnotVector::try_new(vec![0.0, f64::NAN, 1.0]).is_err());
        assert!(KnotVector::try_new(vec![0.0, 0.5, 0.4, 1.0]).is_err());
        assert!(KnotVector::try_new(vec![0.0, 0.0, 1.0, 1.0]).is_ok());
    }

    #[test]
    fn clamped_uniform_and_spans() {
        let k = KnotVector::clamped_uniform(3, 8).unwrap();
        assert_eq!(
            k.as_slice(),
            &[0.0, 0.0, 0.0, 0.0, 0.2, 0.4, 0.6, 0.8, 1.0, 1.0, 1.0, 1.0]
        );
        assert_eq!(k.find_span(3, 8, 0.0), 3);
        assert_eq!(k.find_span(3, 8, 0.2), 4);
        assert_eq!(k.find_span(3, 8, 0.99), 7);
        assert_eq!(k.find_span(3, 8, 1.0), 7);
        assert_eq!(k.multiplicity(1.0), 4);
        let xi = k.greville(3);
        assert_eq!(xi.len(), 8);
        let expected = [0.0, 0.2 / 3.0, 0.2, 0.4, 0.6, 0.8, 2.8 / 3.0, 1.0];
        for (a, b) in xi.iter().zip(expected) {
            assert!((a - b).abs() < 1e-15, "{a} vs {b}");
        }
    }
}
