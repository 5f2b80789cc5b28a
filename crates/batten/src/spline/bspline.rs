use serde::{Deserialize, Serialize};

use super::KnotVector;
use crate::curve::{Curve, CurveDeriv, Derivatives, Piecewise};
use crate::error::{Error, Result};
use crate::geom::{Point, Vec2};

/// A planar B-spline curve of any degree `p ≥ 1`, optionally rational (NURBS).
///
/// `x(t) = Σ_i w_i P_i N_{i,p}(t) / Σ_i w_i N_{i,p}(t)` with `m + 1` control points and a knot
/// vector of `m + p + 2` knots (docs/algorithms/README.md §0.5). The domain is `[u_p, u_{m+1}]`; at
/// its end the last non-empty span is used.
///
/// Serialised as `{"degree": p, "knots": [...], "control_points": [[x, y], ...],
/// "weights": [...]}` (weights omitted when all are 1).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "BSplineJson", into = "BSplineJson")]
pub struct BSplineCurve {
    degree: usize,
    knots: KnotVector,
    control_points: Vec<Point>,
    weights: Option<Vec<f64>>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct BSplineJson {
    degree: usize,
    knots: Vec<f64>,
    control_points: Vec<[f64; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    weights: Option<Vec<f64>>,
}

impl TryFrom<BSplineJson> for BSplineCurve {
    type Error = Error;
    fn try_from(j: BSplineJson) -> Result<BSplineCurve> {
        let knots = KnotVector::try_new(j.knots)?;
        let pts = j.control_points.into_iter().map(Point::from).collect();
        BSplineCurve::try_new(j.degree, knots, pts, j.weights)
    }
}

impl From<BSplineCurve> for BSplineJson {
    fn from(c: BSplineCurve) -> BSplineJson {
        BSplineJson {
            degree: c.degree,
            knots: c.knots.into(),
            control_points: c.control_points.iter().map(|p| [p.x, p.y]).collect(),
            weights: c.weights,
        }
    }
}

impl BSplineCurve {
    /// A B-spline (with `weights = None`) or NURBS curve.
    ///
    /// # Errors
    /// - [`Error::InvalidParameter`] for degree 0;
    /// - [`Error::TooFewPoints`] for fewer than `degree + 1` control points;
    /// - [`Error::InvalidKnots`] when the knot count is not `n_ctrl + degree + 1`, a knot has
    ///   multiplicity above `degree + 1`, or the domain `[u_p, u_{n}]` is empty;
    /// - [`Error::NonFinite`] for a non-finite control point or weight;
    /// - [`Error::LengthMismatch`] / [`Error::InvalidParameter`] for weights of the wrong count
    ///   or not positive.
    pub fn try_new(
        degree: usize,
        knots: KnotVector,
        control_points: Vec<Point>,
        weights: Option<Vec<f64>>,
    ) -> Result<BSplineCurve> {
        if degree == 0 {
            return Err(Error::InvalidParameter {
                name: "degree".into(),
                reason: "must be at least 1".into(),
            });
        }
        let n = control_points.len();
        if n < degree + 1 {
            return Err(Error::TooFewPoints {
                needed: degree + 1,
                got: n,
            });
        }
        if knots.len() != n + degree + 1 {
            return Err(Error::InvalidKnots(format!(
                "{} knots for {n} control points of degree {degree}: expected {}",
                knots.len(),
                n + degree + 1
            )));
        }
        let u = knots.as_slice();
        if u[degree] >= u[n] {
            return Err(Error::InvalidKnots("the parameter domain is empty".into()));
        }
        let mut i = 0;
        while i < u.len() {
            let m = u[i..].iter().take_while(|&&k| k == u[i]).count();
            if m > degree + 1 {
                return Err(Error::InvalidKnots(format!(
                    "knot {} has multiplicity {m} > degree + 1",
                    u[i]
                )));
            }
            i += m;
        }
        if let Some(index) = control_points.iter().position(|p| !p.is_finite()) {
            return Err(Error::NonFinite { index });
        }
        if let Some(w) = &weights {
            if w.len() != n {
                return Err(Error::LengthMismatch {
                    what: "weights",
                    got: w.len(),
                    expected: n,
                });
            }
            if let Some(index) = w.iter().position(|x| !(x.is_finite() && *x > 0.0)) {
                return Err(Error::InvalidParameter {
                    name: "weights".into(),
                    reason: format!("weight {index} must be positive and finite"),
                });
            }
        }
        Ok(BSplineCurve {
            degree,
            knots,
            control_points,
            weights,
        })
    }

    /// As [`BSplineCurve::try_new`].
    ///
    /// # Panics
    /// When [`BSplineCurve::try_new`] would return an error.
    pub fn new(
        degree: usize,
        knots: KnotVector,
        control_points: Vec<Point>,
        weights: Option<Vec<f64>>,
    ) -> BSplineCurve {
        match BSplineCurve::try_new(degree, knots, control_points, weights) {
            Ok(c) => c,
            Err(e) => panic!("{e}"),
        }
    }

    /// The degree p.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The knot vector.
    pub fn knots(&self) -> &KnotVector {
        &self.knots
    }

    /// The control points.
    pub fn control_points(&self) -> &[Point] {
        &self.control_points
    }

    /// The weights, `None` for a non-rational curve.
    pub fn weights(&self) -> Option<&[f64]> {
        self.weights.as_deref()
    }

    /// Replace control point `i` (for local fairing moves).
    ///
    /// # Panics
    /// If `i` is out of range.
    pub fn set_control_point(&mut self, i: usize, p: Point) {
        self.control_points[i] = p;
    }

    /// The same curve with new control points (same count), e.g. after a fairing operator.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] or [`Error::NonFinite`].
    pub fn with_control_points(&self, pts: Vec<Point>) -> Result<BSplineCurve> {
        if pts.len() != self.control_points.len() {
            return Err(Error::LengthMismatch {
                what: "control points",
                got: pts.len(),
                expected: self.control_points.len(),
            });
        }
        BSplineCurve::try_new(self.degree, self.knots.clone(), pts, self.weights.clone())
    }

    /// The span index k with `u_k ≤ t < u_{k+1}` (see [`KnotVector::find_span`]).
    pub fn find_span(&self, t: f64) -> usize {
        self.knots
            .find_span(self.degree, self.control_points.len(), t)
    }

    /// [`BSplineCurve::find_span`] in a sweep over increasing parameters, walking on from
    /// `from` (see [`KnotVector::find_span_from`]); the same span.
    pub(crate) fn find_span_from(&self, t: f64, from: usize) -> usize {
        self.knots
            .find_span_from(self.degree, self.control_points.len(), t, from)
    }

    /// The non-zero basis functions `N_{k−p..=k, p}` and their derivatives up to order `nd`
    /// at `t` in span `k`, written to `out[d][j]` (d = 0..=nd, j = 0..=p). The algorithm of
    /// Piegl & Tiller (A2.3), with 0/0 := 0 for repeated knots.
    pub fn basis_derivs(&self, k: usize, t: f64, nd: usize, out: &mut [[f64; MAX_ORDER]; 4]) {
        basis_derivs(self.knots.as_slice(), self.degree, k, t, nd.min(3), out);
    }

    /// The first derivative `x'(t)` alone: cheaper than [`CurveDeriv::derivatives`] for arc
    /// length (basis derivatives of order one only; rational curves take the full path).
    pub fn first_derivative(&self, t: f64) -> Vec2 {
        if self.weights.is_some() {
            return self.derivatives(t).d1;
        }
        let p = self.degree;
        let k = self.find_span(t);
        let mut b = [[0.0; MAX_ORDER]; 4];
        basis_derivs(self.knots.as_slice(), p, k, t, 1, &mut b);
        let mut d = Vec2::ZERO;
        for (j, c) in self.control_points[k - p..=k].iter().enumerate() {
            d += c.to_vec2() * b[1][j];
        }
        d
    }

    /// `x'(t)` on span `k` (`u_k ≤ t ≤ u_{k+1}`, `u_k < u_{k+1}`) of a non-rational curve:
    /// the derivative's control points `Q_i = p (P_i − P_{i−1}) / (u_{i+p} − u_i)` against the
    /// degree-(p−1) basis (Piegl & Tiller eq 3.3 and A2.2). No span search and no basis
    /// derivatives, for the many evaluations of arc-length quadrature.
    ///
    /// # Panics
    /// In debug builds, for a rational curve or a span index out of range.
    pub(crate) fn first_derivative_in_span(&self, k: usize, t: f64) -> Vec2 {
        debug_assert!(self.weights.is_none(), "rational curves take the full path");
        let p = self.degree;
        if p == 0 {
            return Vec2::ZERO;
        }
        let u = self.knots.as_slice();
        let q = p - 1;
        // Every denominator of A2.2 spans the non-empty span k, so its 0/0 guard never acts.
        let n = basis_functions(u, q, k, t);
        let mut d = Vec2::ZERO;
        for (r, nr) in n.iter().enumerate().take(q + 1) {
            let i = k - q + r;
            let qi = (self.control_points[i] - self.control_points[i - 1])
                * (p as f64 / (u[i + p] - u[i]));
            d += qi * *nr;
        }
        d
    }

    /// `[x', x'', x''']` at `t` on span `k` (`u_k < u_{k+1}`) of a non-rational cubic, from
    /// the control points of the derivatives (Piegl & Tiller eq 3.3 applied three times:
    /// `Q_i = 3(P_i − P_{i−1})/(u_{i+3} − u_i)`, `R_i = 2(Q_i − Q_{i−1})/(u_{i+2} − u_i)`,
    /// `x''' = (R_k − R_{k−1})/(u_{k+1} − u_k)`), `x''` linear and `x'` by de Boor's
    /// algorithm on them. A fraction of the work of the general basis derivatives, for the
    /// 10⁶-point GFI. Every denominator spans the non-empty span `k`, so none is zero.
    ///
    /// # Panics
    /// In debug builds, for a rational curve or another degree.
    pub(crate) fn cubic_derivs_in_span(&self, k: usize, t: f64) -> [Vec2; 3] {
        debug_assert!(self.weights.is_none() && self.degree == 3);
        let u = self.knots.as_slice();
        let p = &self.control_points;
        let q = |i: usize| (p[i] - p[i - 1]) * (3.0 / (u[i + 3] - u[i]));
        let (q0, q1, q2) = (q(k - 2), q(k - 1), q(k));
        let r1 = (q1 - q0) * (2.0 / (u[k + 1] - u[k - 1]));
        let r2 = (q2 - q1) * (2.0 / (u[k + 2] - u[k]));
        let h = u[k + 1] - u[k];
        let a = (t - u[k]) / h;
        let d3 = (r2 - r1) / h;
        let d2 = r1 * (1.0 - a) + r2 * a;
        let b1 = (t - u[k - 1]) / (u[k + 1] - u[k - 1]);
        let b2 = (t - u[k]) / (u[k + 2] - u[k]);
        let e1 = q0 * (1.0 - b1) + q1 * b1;
        let e2 = q1 * (1.0 - b2) + q2 * b2;
        let d1 = e1 * (1.0 - a) + e2 * a;
        [d1, d2, d3]
    }

    /// Position and up to three derivatives, evaluated on span `k`.
    pub(crate) fn derivs_in_span(&self, k: usize, t: f64) -> Derivatives {
        let p = self.degree;
        let mut b = [[0.0; MAX_ORDER]; 4];
        basis_derivs(self.knots.as_slice(), p, k, t, 3, &mut b);
        let cp = &self.control_points[k - p..=k];
        match &self.weights {
            None => {
                let mut d = [Vec2::ZERO; 4];
                for (j, c) in cp.iter().enumerate() {
                    let v = c.to_vec2();
                    for (o, dd) in d.iter_mut().enumerate() {
                        *dd += v * b[o][j];
                    }
                }
                Derivatives {
                    point: d[0].to_point(),
                    d1: d[1],
                    d2: d[2],
                    d3: d[3],
                }
            }
            Some(w) => {
                let w = &w[k - p..=k];
                // Homogeneous derivatives A^(o) = Σ w_j P_j N^(o), W^(o) = Σ w_j N^(o).
                let mut a = [Vec2::ZERO; 4];
                let mut ww = [0.0; 4];
                for (j, c) in cp.iter().enumerate() {
                    let v = c.to_vec2() * w[j];
                    for o in 0..4 {
                        a[o] += v * b[o][j];
                        ww[o] += w[j] * b[o][j];
                    }
                }
                // Quotient rule (Piegl & Tiller A4.2): C^(o) = (A^(o) − Σ_{i=1}^{o} C(o,i) W^(i) C^(o−i)) / W.
                let binom = [
                    [1.0, 0.0, 0.0, 0.0],
                    [1.0, 1.0, 0.0, 0.0],
                    [1.0, 2.0, 1.0, 0.0],
                    [1.0, 3.0, 3.0, 1.0],
                ];
                let mut c = [Vec2::ZERO; 4];
                for o in 0..4 {
                    let mut v = a[o];
                    for i in 1..=o {
                        v -= c[o - i] * (binom[o][i] * ww[i]);
                    }
                    c[o] = v / ww[0];
                }
                Derivatives {
                    point: c[0].to_point(),
                    d1: c[1],
                    d2: c[2],
                    d3: c[3],
                }
            }
        }
    }
}

/// The largest degree + 1 supported by the fixed-size basis buffers (no allocation per
/// evaluation): degree ≤ 7.
pub const MAX_ORDER: usize = 8;

/// Basis functions and derivatives (Piegl & Tiller A2.3) into a fixed buffer.
pub(crate) fn basis_derivs(
    u: &[f64],
    p: usize,
    k: usize,
    t: f64,
    nd: usize,
    out: &mut [[f64; MAX_ORDER]; 4],
) {
    assert!(
        p < MAX_ORDER,
        "degree {p} above the supported maximum {}",
        MAX_ORDER - 1
    );
    if nd == 0 {
        // The cubic (every report's GFI interpolant) with its loop bounds known.
        match p {
            3 => basis_only(u, Cubic, k, t, out),
            _ => basis_only(u, p, k, t, out),
        }
        return;
    }
    let mut ndu = [[0.0; MAX_ORDER]; MAX_ORDER];
    let mut left = [0.0; MAX_ORDER];
    let mut right = [0.0; MAX_ORDER];
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = t - u[k + 1 - j];
        right[j] = u[k + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            // Lower triangle: knot differences.
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = if ndu[j][r] != 0.0 {
                ndu[r][j - 1] / ndu[j][r]
            } else {
                0.0
            };
            // Upper triangle: basis functions.
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    for row in out.iter_mut() {
        *row = [0.0; MAX_ORDER];
    }
    for j in 0..=p {
        out[0][j] = ndu[j][p];
    }
    let nd = nd.min(p);
    let mut a = [[0.0; MAX_ORDER]; 2];
    for r in 0..=p {
        let (mut s1, mut s2) = (0usize, 1usize);
        a[0] = [0.0; MAX_ORDER];
        a[0][0] = 1.0;
        for kk in 1..=nd {
            let mut d = 0.0;
            let rk = r as isize - kk as isize;
            let pk = p - kk;
            if r >= kk {
                let rk = rk as usize;
                a[s2][0] = if ndu[pk + 1][rk] != 0.0 {
                    a[s1][0] / ndu[pk + 1][rk]
                } else {
                    0.0
                };
                d = a[s2][0] * ndu[rk][pk];
            }
            let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
            let j2 = if (r as isize - 1) <= pk as isize {
                kk - 1
            } else {
                p - r
            };
            for j in j1..=j2 {
                let idx = (rk + j as isize) as usize;
                a[s2][j] = if ndu[pk + 1][idx] != 0.0 {
                    (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][idx]
                } else {
                    0.0
                };
                d += a[s2][j] * ndu[idx][pk];
            }
            if r <= pk {
                a[s2][kk] = if ndu[pk + 1][r] != 0.0 {
                    -a[s1][kk - 1] / ndu[pk + 1][r]
                } else {
                    0.0
                };
                d += a[s2][kk] * ndu[r][pk];
            }
            out[kk][r] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut f = p as f64;
    for kk in 1..=nd {
        for j in 0..=p {
            out[kk][j] *= f;
        }
        f *= (p - kk) as f64;
    }
}

/// [`basis_derivs`] without derivatives: [`basis_functions`] into `out[0]`, the other rows
/// zero. The same operations as the upper triangle of A2.3's table, so the same bits, without
/// the table and the derivative loops (the B-spline interpolant's collocation matrix, which
/// the GFI of every report builds).
fn basis_only(u: &[f64], p: impl Degree, k: usize, t: f64, out: &mut [[f64; MAX_ORDER]; 4]) {
    out[0] = basis_functions(u, p, k, t);
    for row in &mut out[1..] {
        *row = [0.0; MAX_ORDER];
    }
}

/// The four non-zero cubic basis functions `N_{k−3..=k, 3}` at `t` in span `k`: those
/// [`basis_derivs`] gives with no derivative, bit for bit, without its table of derivatives
/// (for the 10⁶ points of `band`'s spline layout).
pub(crate) fn cubic_basis(u: &[f64], k: usize, t: f64) -> [f64; 4] {
    let n = basis_functions(u, Cubic, k, t);
    [n[0], n[1], n[2], n[3]]
}

/// The non-zero basis functions `N_{k−p..=k, p}` at `t` in span `k` (Piegl & Tiller A2.2,
/// 0/0 := 0 for repeated knots), the rest of the array zero: each level's values overwrite
/// the level before.
fn basis_functions(u: &[f64], p: impl Degree, k: usize, t: f64) -> [f64; MAX_ORDER] {
    let p = p.degree();
    let mut n = [0.0; MAX_ORDER];
    let mut left = [0.0; MAX_ORDER];
    let mut right = [0.0; MAX_ORDER];
    n[0] = 1.0;
    for j in 1..=p {
        left[j] = t - u[k + 1 - j];
        right[j] = u[k + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            let den = right[r + 1] + left[j - r];
            let temp = if den != 0.0 { n[r] / den } else { 0.0 };
            n[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        n[j] = saved;
    }
    n
}

/// A degree known at run time (`usize`) or at compile time ([`Cubic`]), so that one body of
/// [`basis_only`] serves both.
trait Degree: Copy {
    fn degree(self) -> usize;
}

impl Degree for usize {
    #[inline(always)]
    fn degree(self) -> usize {
        self
    }
}

/// Degree 3, known at compile time.
#[derive(Clone, Copy)]
struct Cubic;

impl Degree for Cubic {
    #[inline(always)]
    fn degree(self) -> usize {
        3
    }
}

impl Curve for BSplineCurve {
    fn domain(&self) -> (f64, f64) {
        let u = self.knots.as_slice();
        (u[self.degree], u[self.control_points.len()])
    }

    fn eval(&self, t: f64) -> Point {
        self.derivatives(t).point
    }
}

impl CurveDeriv for BSplineCurve {
    fn derivatives(&self, t: f64) -> Derivatives {
        self.derivs_in_span(self.find_span(t), t)
    }

    fn derivatives_left(&self, t: f64) -> Derivatives {
        let u = self.knots.as_slice();
        let mut k = self.find_span(t);
        // At an interior knot, step back to the span that ends at t.
        while k > self.degree && u[k] == t {
            k -= 1;
            if u[k] < u[k + 1] {
                break;
            }
        }
        self.derivs_in_span(k, t)
    }
}

impl Piecewise for BSplineCurve {
    fn breakpoints(&self) -> Vec<f64> {
        let (a, b) = self.domain();
        let mut v: Vec<f64> = Vec::new();
        for &k in self.knots.as_slice() {
            if k >= a && k <= b && v.last() != Some(&k) {
                v.push(k);
            }
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cubic basis alone is [`basis_derivs`]'s with no derivative, bit for bit, on a
    /// clamped knot vector with uneven and repeated interior knots.
    #[test]
    fn cubic_basis_is_basis_derivs_without_derivatives() {
        let u = [0.0, 0.0, 0.0, 0.0, 0.3, 0.3, 0.7, 1.1, 2.0, 2.0, 2.0, 2.0];
        for k in 3..8 {
            if u[k + 1] <= u[k] {
                continue;
            }
            for step in 0..=20 {
                let t = u[k] + (u[k + 1] - u[k]) * f64::from(step) / 20.0;
                let mut out = [[0.0; MAX_ORDER]; 4];
                basis_derivs(&u, 3, k, t, 0, &mut out);
                let b = cubic_basis(&u, k, t);
                for j in 0..4 {
                    assert_eq!(b[j].to_bits(), out[0][j].to_bits(), "k {k} t {t} j {j}");
                }
            }
        }
    }

    /// The basis functions alone ([`basis_only`], nd = 0) are the bits of the full table's
    /// first row (nd ≥ 1), every degree, span and a spread of parameters, with repeated knots
    /// (the 0/0 := 0 guard); the derivative rows are zero.
    #[test]
    fn basis_only_is_the_tables_first_row() {
        let u = [
            0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.13, 0.4, 0.4, 0.4, 0.91, 1.3, 2.2, 2.2, 3.0,
            3.0, 3.0, 3.0, 3.0, 3.0, 3.0, 3.0,
        ];
        for p in 1..MAX_ORDER {
            for k in p..u.len() - p - 1 {
                for f in [0.0, 0.1, 0.37, 0.5, 0.999, 1.0] {
                    let t = u[k] + f * (u[k + 1] - u[k]);
                    let (mut fast, mut full) = ([[7.0; MAX_ORDER]; 4], [[0.0; MAX_ORDER]; 4]);
                    basis_derivs(&u, p, k, t, 0, &mut fast);
                    basis_derivs(&u, p, k, t, 1, &mut full);
                    for j in 0..MAX_ORDER {
                        assert_eq!(fast[0][j].to_bits(), full[0][j].to_bits(), "p {p} k {k}");
                        assert!(fast[1..].iter().all(|r| r[j] == 0.0));
                    }
                }
            }
        }
    }

    #[test]
    fn cubic_derivs_in_span_match_the_basis_derivatives() {
        // Non-uniform clamped knots with a double interior knot, every span, its ends and
        // inside: the derivative control points give the basis derivatives' values.
        let knots = vec![
            0.0, 0.0, 0.0, 0.0, 0.3, 0.7, 0.7, 1.6, 2.0, 3.5, 3.5, 3.5, 3.5,
        ];
        let n_ctrl = knots.len() - 4;
        let pts: Vec<Point> = (0..n_ctrl)
            .map(|i| {
                let x = i as f64;
                Point::new(x + 0.3 * (x * 1.7).sin(), (x * 0.9).cos() * (1.0 + 0.1 * x))
            })
            .collect();
        let curve = BSplineCurve::try_new(3, KnotVector::new(knots), pts, None).unwrap();
        let u = curve.knots().as_slice().to_vec();
        for k in 3..n_ctrl {
            if u[k] == u[k + 1] {
                continue;
            }
            for f in [0.0, 0.25, 0.5, 0.9, 1.0] {
                let t = u[k] + f * (u[k + 1] - u[k]);
                let want = curve.derivs_in_span(k, t);
                let [d1, d2, d3] = curve.cubic_derivs_in_span(k, t);
                for (got, want) in [(d1, want.d1), (d2, want.d2), (d3, want.d3)] {
                    let scale = 1.0 + want.length();
                    assert!((got - want).length() < 1e-12 * scale, "span {k}, t {t}");
                }
            }
        }
    }

    #[test]
    fn first_derivative_in_span_matches_the_basis_derivatives() {
        // Degrees 1..=5 on non-uniform clamped knots with a double interior knot: the
        // derivative from the degree-(p−1) basis equals the one from basis derivatives, at
        // the span ends too.
        for p in 1..=5 {
            let n_ctrl = p + 6;
            let mut knots = vec![0.0; p + 1];
            let inner = [0.3, 0.7, 0.7, 1.6, 2.0, 2.9];
            knots.extend_from_slice(&inner[..n_ctrl - p - 1]);
            knots.extend(std::iter::repeat_n(3.5, p + 1));
            let pts: Vec<Point> = (0..n_ctrl)
                .map(|i| {
                    let x = i as f64;
                    Point::new(x + 0.3 * (x * 1.7).sin(), (x * 0.9).cos() * (1.0 + 0.1 * x))
                })
                .collect();
            let curve = BSplineCurve::try_new(p, KnotVector::new(knots), pts, None)
                .unwrap_or_else(|e| panic!("degree {p}: {e}"));
            let u = curve.knots().as_slice().to_vec();
            for k in p..n_ctrl {
                if u[k] == u[k + 1] {
                    continue;
                }
                for f in [0.0, 0.13, 0.5, 0.91, 1.0] {
                    let t = u[k] + f * (u[k + 1] - u[k]);
                    let want = curve.derivs_in_span(k, t).d1;
                    let got = curve.first_derivative_in_span(k, t);
                    let err = (got - want).length();
                    assert!(
                        err <= 1e-12 * (1.0 + want.length()),
                        "p {p}, span {k}, t {t}: {err}"
                    );
                }
            }
        }
    }
}
