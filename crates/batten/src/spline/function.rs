//! The cubic spline *function* `y(x)` through points with strictly increasing abscissae
//! (HAN, docs/algorithms/han.md §1.2–§1.3, §1.5; paper
//! `shared/papers/han-explicit-fairing-indicator.txt`, eqs 2–10).
//!
//! The spline is stored by its values `y_i` and the scaled second derivatives
//! `c_i = y''(x_i)/6` (the paper's notation). On `[x_i, x_{i+1}]` (eq 2)
//!
//! ```text
//! y(x) = y_i + m_i (x − x_i)
//!        − (x − x_i)(x_{i+1} − x)/h_i · [c_i (2x_{i+1} − x − x_i) + c_{i+1}(x_{i+1} + x − 2x_i)]
//! ```
//!
//! with `h_i = x_{i+1} − x_i` and `m_i = (y_{i+1} − y_i)/h_i`. The `c_i` solve the three-moment
//! equations (eq 4 with the spec's **\[FIX\]**: the printed `c_i + 1` is `c_{i+1}`)
//!
//! ```text
//! h_{i−1} c_{i−1} + 2 (h_{i−1} + h_i) c_i + h_i c_{i+1} = m_i − m_{i−1},   i = 2..n−1
//! ```
//!
//! plus one of the three end conditions of the paper ([`FnEndCondition`]). The system is solved
//! in O(n) by the forward sweep `c_i + a_i c_{i+1} = b_i` (eqs 5–6) and the backward sweep
//! `c_i + a*_i c_{i−1} = b*_i` (eqs 7–8); both are kept because HAN's unit spline responses are
//! built from `a` and `a*` (docs/algorithms/han.md §1.6).
//!
//! Indices in this API are 0-based: point `k` here is the paper's point `k + 1`.

use crate::curve::{Curve, CurveDeriv, Derivatives, Piecewise};
use crate::error::{Error, Result};
use crate::geom::{Point, Vec2};

/// End conditions of a [`CubicSplineFn`]: the three of the HAN paper (its ①, ② and ③).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FnEndCondition {
    /// Given end slopes `y'(x_1)` and `y'(x_n)` (the paper's ①).
    Slopes(f64, f64),
    /// Zero second derivative at both ends, `c_1 = c_n = 0` (the paper's ②).
    Natural,
    /// HAN's condition ③: `c_1 = c_2` and `c_{n−1} = c_n`. The second derivative is constant
    /// on the first and the last interval, so the x–c plot is flat at both ends.
    Han,
}

impl FnEndCondition {
    /// The fewest points the condition determines a unique spline for: 2 for
    /// [`Slopes`](FnEndCondition::Slopes) and [`Natural`](FnEndCondition::Natural), 3 for
    /// [`Han`](FnEndCondition::Han) (with two points `c_1 = c_2` is stated twice and the
    /// spline is not determined).
    pub fn min_points(self) -> usize {
        match self {
            FnEndCondition::Han => 3,
            FnEndCondition::Slopes(..) | FnEndCondition::Natural => 2,
        }
    }

    /// The start row `c_1 + a_1 c_2 = b_1` as `(a_1, b_1)`, given `h_1` and `m_1`.
    fn start_row(self, h: f64, m: f64) -> (f64, f64) {
        match self {
            // y'(x_1 + 0) = m_1 − h_1 (2c_1 + c_2) = s  ⇔  c_1 + c_2/2 = (m_1 − s)/(2h_1)
            FnEndCondition::Slopes(s, _) => (0.5, (m - s) / (2.0 * h)),
            FnEndCondition::Natural => (0.0, 0.0),
            FnEndCondition::Han => (-1.0, 0.0),
        }
    }

    /// The end row `c_n + a*_n c_{n−1} = b*_n` as `(a*_n, b*_n)`, given `h_{n−1}`, `m_{n−1}`.
    fn end_row(self, h: f64, m: f64) -> (f64, f64) {
        match self {
            // y'(x_n − 0) = m + h (c_{n−1} + 2c_n) = s  ⇔  c_n + c_{n−1}/2 = (s − m)/(2h)
            FnEndCondition::Slopes(_, s) => (0.5, (s - m) / (2.0 * h)),
            FnEndCondition::Natural => (0.0, 0.0),
            FnEndCondition::Han => (-1.0, 0.0),
        }
    }
}

/// A C² cubic spline function `y(x)` interpolating `(x_i, y_i)` with `x` strictly increasing
/// (HAN eqs 1–10, docs/algorithms/han.md §1.2–§1.3).
///
/// As a [`Curve`] it is the graph `t ↦ (t, y(t))` on `[x_1, x_n]`; outside that interval the
/// first or last cubic piece is extrapolated.
///
/// ```
/// use batten::spline::{CubicSplineFn, FnEndCondition};
///
/// let x = vec![0.0, 1.0, 2.5, 3.0, 4.5];
/// let y = vec![0.0, 0.8, 1.1, 0.7, 0.2];
/// let s = CubicSplineFn::try_new(x, y, FnEndCondition::Han).unwrap();
/// assert!((s.value(2.5) - 1.1).abs() < 1e-15);
/// assert_eq!(s.c()[0], s.c()[1]); // c_1 = c_2
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct CubicSplineFn {
    x: Vec<f64>,
    y: Vec<f64>,
    end: FnEndCondition,
    /// `h_i = x_{i+1} − x_i`, length n − 1.
    h: Vec<f64>,
    /// `c_i = y''(x_i)/6`, length n.
    c: Vec<f64>,
    /// Forward sweep `a_1..a_{n−1}`.
    a: Vec<f64>,
    /// Forward sweep `b_1..b_{n−1}`.
    b: Vec<f64>,
    /// Backward sweep `a*_2..a*_n` (entry k belongs to point k + 1).
    a_star: Vec<f64>,
    /// Backward sweep `b*_2..b*_n` (entry k belongs to point k + 1).
    b_star: Vec<f64>,
}

impl CubicSplineFn {
    /// Interpolate `(x[k], y[k])` with the given end condition. O(n).
    ///
    /// # Errors
    /// - [`Error::LengthMismatch`] when `y` and `x` differ in length;
    /// - [`Error::TooFewPoints`] below [`FnEndCondition::min_points`];
    /// - [`Error::NonFinite`] for a NaN or infinite `x[k]` or `y[k]` (index k);
    /// - [`Error::NotIncreasing`] when `x` is not strictly increasing;
    /// - [`Error::InvalidParameter`] for a non-finite end slope;
    /// - [`Error::Degenerate`] when the coefficients overflow (spacings so small that the
    ///   divided differences are not representable).
    pub fn try_new(x: Vec<f64>, y: Vec<f64>, end: FnEndCondition) -> Result<CubicSplineFn> {
        let n = x.len();
        if y.len() != n {
            return Err(Error::LengthMismatch {
                what: "y",
                got: y.len(),
                expected: n,
            });
        }
        if n < end.min_points() {
            return Err(Error::TooFewPoints {
                needed: end.min_points(),
                got: n,
            });
        }
        if let Some(index) = x
            .iter()
            .zip(&y)
            .position(|(a, b)| !(a.is_finite() && b.is_finite()))
        {
            return Err(Error::NonFinite { index });
        }
        if let Some(i) = x.windows(2).position(|w| w[1] <= w[0]) {
            return Err(Error::NotIncreasing { index: i + 1 });
        }
        if let FnEndCondition::Slopes(s0, s1) = end
            && !(s0.is_finite() && s1.is_finite())
        {
            return Err(Error::InvalidParameter {
                name: "end slopes".into(),
                reason: format!("must be finite, got ({s0}, {s1})"),
            });
        }
        let h: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
        let m: Vec<f64> = (0..n - 1).map(|i| (y[i + 1] - y[i]) / h[i]).collect();

        // Forward sweep (eqs 5–6): rows 0..n−2.
        let mut a = vec![0.0; n - 1];
        let mut b = vec![0.0; n - 1];
        (a[0], b[0]) = end.start_row(h[0], m[0]);
        for i in 1..n - 1 {
            let den = 2.0 * (h[i - 1] + h[i]) - a[i - 1] * h[i - 1];
            a[i] = h[i] / den;
            b[i] = (m[i] - m[i - 1] - h[i - 1] * b[i - 1]) / den;
        }
        // Backward sweep (eqs 7–8): rows n−1 down to 1, stored at k − 1.
        let mut a_star = vec![0.0; n - 1];
        let mut b_star = vec![0.0; n - 1];
        (a_star[n - 2], b_star[n - 2]) = end.end_row(h[n - 2], m[n - 2]);
        for i in (1..n - 1).rev() {
            let den = 2.0 * (h[i - 1] + h[i]) - a_star[i] * h[i];
            a_star[i - 1] = h[i - 1] / den;
            b_star[i - 1] = (m[i] - m[i - 1] - h[i] * b_star[i]) / den;
        }
        // Close with the end row: c_n + a*_n c_{n−1} = b*_n and c_{n−1} + a_{n−1} c_n = b_{n−1}.
        // The denominator is ≥ 3/4 for every end condition (0 < a_{n−1} ≤ 1/2 or a*_n = 0).
        let mut c = vec![0.0; n];
        let (an, bn) = (a_star[n - 2], b_star[n - 2]);
        c[n - 1] = (bn - an * b[n - 2]) / (1.0 - an * a[n - 2]);
        for i in (0..n - 1).rev() {
            c[i] = b[i] - a[i] * c[i + 1];
        }
        if c.iter()
            .chain(&a)
            .chain(&b)
            .chain(&a_star)
            .chain(&b_star)
            .any(|v| !v.is_finite())
        {
            return Err(Error::Degenerate(
                "cubic spline function coefficients overflow (spacing too small)".into(),
            ));
        }
        Ok(CubicSplineFn {
            x,
            y,
            end,
            h,
            c,
            a,
            b,
            a_star,
            b_star,
        })
    }

    /// As [`CubicSplineFn::try_new`], for data known to be valid.
    ///
    /// # Panics
    /// On every input [`CubicSplineFn::try_new`] rejects.
    pub fn new(x: Vec<f64>, y: Vec<f64>, end: FnEndCondition) -> CubicSplineFn {
        match CubicSplineFn::try_new(x, y, end) {
            Ok(s) => s,
            Err(e) => panic!("CubicSplineFn::new: {e}"),
        }
    }

    /// Number of data points n.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Always false: a spline has at least two points.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// The abscissae `x_1 < … < x_n`.
    pub fn x(&self) -> &[f64] {
        &self.x
    }

    /// The interpolated values `y_1..y_n`.
    pub fn y(&self) -> &[f64] {
        &self.y
    }

    /// The end condition.
    pub fn end_condition(&self) -> FnEndCondition {
        self.end
    }

    /// The spacings `h_i = x_{i+1} − x_i`, length n − 1.
    pub fn h(&self) -> &[f64] {
        &self.h
    }

    /// `c_i = y''(x_i)/6`, length n: the vertices of HAN's x–c plot.
    pub fn c(&self) -> &[f64] {
        &self.c
    }

    /// Forward sweep coefficients `a_1..a_{n−1}` of `c_i + a_i c_{i+1} = b_i` (eq 5); entry k
    /// belongs to point k. `a_1` comes from the end condition (−1 for [`FnEndCondition::Han`]).
    pub fn forward_a(&self) -> &[f64] {
        &self.a
    }

    /// Forward sweep right-hand sides `b_1..b_{n−1}` (eq 6); entry k belongs to point k.
    pub fn forward_b(&self) -> &[f64] {
        &self.b
    }

    /// Backward sweep coefficients `a*_2..a*_n` of `c_i + a*_i c_{i−1} = b*_i` (eq 7); entry
    /// k belongs to point **k + 1**. `a*_n` comes from the end condition.
    pub fn backward_a(&self) -> &[f64] {
        &self.a_star
    }

    /// Backward sweep right-hand sides `b*_2..b*_n` (eq 8); entry k belongs to point k + 1.
    pub fn backward_b(&self) -> &[f64] {
        &self.b_star
    }

    /// `c_j` for an interior point j (1 ≤ j ≤ n − 2, 0-based) from the explicit formula
    /// (eq 9 with the spec's **\[FIX\]** `h_j = x_{j+1} − x_j` in the numerator):
    /// `c_j = (d_j − h_{j−1} b_{j−1} − h_j b*_{j+1}) / (D_j − a_{j−1} h_{j−1} − a*_{j+1} h_j)`.
    /// Equal to [`CubicSplineFn::c`]`[j]` up to rounding.
    ///
    /// # Panics
    /// When j is not an interior index.
    pub fn c_explicit(&self, j: usize) -> f64 {
        assert!(
            j >= 1 && j + 1 < self.len(),
            "c_explicit: {j} is not an interior index"
        );
        let (h0, h1) = (self.h[j - 1], self.h[j]);
        let d = (self.y[j + 1] - self.y[j]) / h1 - (self.y[j] - self.y[j - 1]) / h0;
        let num = d - h0 * self.b[j - 1] - h1 * self.b_star[j];
        let den = 2.0 * (h0 + h1) - self.a[j - 1] * h0 - self.a_star[j] * h1;
        num / den
    }

    /// HAN's indicator `e_i = (c_{i+1} − c_i)/h_i − (c_i − c_{i−1})/h_{i−1}` for the interior
    /// points, with `e_1 = e_n = 0` (docs/algorithms/README.md §0.3, docs/algorithms/han.md §1.5
    /// \[CHOICE\]: the x–c plot extended flat). `6 e_i` is the jump of `y'''` at `x_i`. Length n.
    pub fn indicator(&self) -> Vec<f64> {
        let n = self.len();
        let mut e = vec![0.0; n];
        for (i, ei) in e.iter_mut().enumerate().take(n - 1).skip(1) {
            *ei = (self.c[i + 1] - self.c[i]) / self.h[i]
                - (self.c[i] - self.c[i - 1]) / self.h[i - 1];
        }
        e
    }

    /// The interval index i with `x_i ≤ x < x_{i+1}`, clamped to the first and last interval
    /// (so `x_n` belongs to the last one).
    pub fn find_span(&self, x: f64) -> usize {
        let last = self.h.len() - 1;
        // Number of knots ≤ x, minus one.
        let k = self.x.partition_point(|&xi| xi <= x);
        k.saturating_sub(1).min(last)
    }

    /// `y(x)`.
    pub fn value(&self, x: f64) -> f64 {
        self.derivs_in_span(self.find_span(x), x)[0]
    }

    /// `[y, y', y'', y''']` at `x` (right-hand limits at interior knots, left-hand at `x_n`).
    pub fn derivs(&self, x: f64) -> [f64; 4] {
        self.derivs_in_span(self.find_span(x), x)
    }

    /// `[y, y', y'', y''']` at `x` as limits from the left (`x − 0`).
    pub fn derivs_left(&self, x: f64) -> [f64; 4] {
        let mut i = self.find_span(x);
        if i > 0 && self.x[i] == x {
            i -= 1;
        }
        self.derivs_in_span(i, x)
    }

    /// Value and derivatives of interval `i`'s cubic at `x`, from the power form in
    /// `s = x − x_i`: `y_i + B1 s + 3 c_i s² + (c_{i+1} − c_i)/h_i s³` with
    /// `B1 = y'(x_i + 0) = m_i − h_i (2c_i + c_{i+1})` (eq 3). Identical to eq 2.
    fn derivs_in_span(&self, i: usize, x: f64) -> [f64; 4] {
        let h = self.h[i];
        let (c0, c1) = (self.c[i], self.c[i + 1]);
        let m = (self.y[i + 1] - self.y[i]) / h;
        let b1 = m - h * (2.0 * c0 + c1);
        let b2 = 3.0 * c0;
        let b3 = (c1 - c0) / h;
        let s = x - self.x[i];
        let y = self.y[i] + s * (b1 + s * (b2 + s * b3));
        let d1 = b1 + s * (2.0 * b2 + 3.0 * b3 * s);
        let d2 = 2.0 * b2 + 6.0 * b3 * s;
        [y, d1, d2, 6.0 * b3]
    }
}

fn graph_derivatives(t: f64, d: [f64; 4]) -> Derivatives {
    Derivatives {
        point: Point::new(t, d[0]),
        d1: Vec2::new(1.0, d[1]),
        d2: Vec2::new(0.0, d[2]),
        d3: Vec2::new(0.0, d[3]),
    }
}

impl Curve for CubicSplineFn {
    fn domain(&self) -> (f64, f64) {
        (self.x[0], self.x[self.x.len() - 1])
    }

    fn eval(&self, t: f64) -> Point {
        Point::new(t, self.value(t))
    }
}

impl CurveDeriv for CubicSplineFn {
    fn derivatives(&self, t: f64) -> Derivatives {
        graph_derivatives(t, self.derivs(t))
    }

    fn derivatives_left(&self, t: f64) -> Derivatives {
        graph_derivatives(t, self.derivs_left(t))
    }
}

impl Piecewise for CubicSplineFn {
    fn breakpoints(&self) -> Vec<f64> {
        self.x.clone()
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::needless_range_loop)]
mod tests {
    use super::*;

    fn data() -> (Vec<f64>, Vec<f64>) {
        // The spec's `han.spline_function.coefficients` data.
        (
            vec![0.0, 1.0, 2.5, 3.0, 4.5, 6.0, 7.0, 8.5],
            vec![0.0, 0.8, 1.1, 0.7, 0.2, 0.5, 1.2, 1.0],
        )
    }

    fn close(a: f64, b: f64, abs: f64, rel: f64) -> bool {
        (a - b).abs() <= abs + rel * b.abs()
    }

    /// Dense Gaussian elimination of the full n×n system, as an independent reference.
    fn dense_c(x: &[f64], y: &[f64], end: FnEndCondition) -> Vec<f64> {
        let n = x.len();
        let mut m = vec![vec![0.0; n + 1]; n];
        let h: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
        let sl: Vec<f64> = (0..n - 1).map(|i| (y[i + 1] - y[i]) / h[i]).collect();
        for i in 1..n - 1 {
            m[i][i - 1] = h[i - 1];
            m[i][i] = 2.0 * (h[i - 1] + h[i]);
            m[i][i + 1] = h[i];
            m[i][n] = sl[i] - sl[i - 1];
        }
        match end {
            FnEndCondition::Han => {
                m[0][0] = 1.0;
                m[0][1] = -1.0;
                m[n - 1][n - 1] = 1.0;
                m[n - 1][n - 2] = -1.0;
            }
            FnEndCondition::Natural => {
                m[0][0] = 1.0;
                m[n - 1][n - 1] = 1.0;
            }
            FnEndCondition::Slopes(s0, s1) => {
                m[0][0] = -2.0 * h[0];
                m[0][1] = -h[0];
                m[0][n] = s0 - sl[0];
                m[n - 1][n - 2] = h[n - 2];
                m[n - 1][n - 1] = 2.0 * h[n - 2];
                m[n - 1][n] = s1 - sl[n - 2];
            }
        }
        for col in 0..n {
            let p = (col..n)
                .max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))
                .unwrap();
            m.swap(col, p);
            for r in 0..n {
                if r != col {
                    let f = m[r][col] / m[col][col];
                    for k in col..=n {
                        m[r][k] -= f * m[col][k];
                    }
                }
            }
        }
        (0..n).map(|i| m[i][n] / m[i][i]).collect()
    }

    #[test]
    fn matches_dense_solve_and_explicit_formula() {
        let (x, y) = data();
        for end in [
            FnEndCondition::Han,
            FnEndCondition::Natural,
            FnEndCondition::Slopes(0.3, -1.2),
        ] {
            let s = CubicSplineFn::new(x.clone(), y.clone(), end);
            let d = dense_c(&x, &y, end);
            for (a, b) in s.c().iter().zip(&d) {
                assert!(close(*a, *b, 1e-14, 1e-12), "{end:?}: {a} vs {b}");
            }
            for j in 1..x.len() - 1 {
                assert!(
                    close(s.c_explicit(j), s.c()[j], 1e-14, 1e-12),
                    "eq 9 at {j}"
                );
            }
        }
    }

    #[test]
    fn spec_vector_coefficients() {
        // `han.spline_function.coefficients`: 1-based arrays stored without slot 0.
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/data/test-vectors.json"
        ))
        .unwrap();
        let all: serde_json::Value = serde_json::from_str(&text).unwrap();
        let v = all["han"]
            .as_array()
            .unwrap()
            .iter()
            .find(|v| v["id"] == "han.spline_function.coefficients")
            .unwrap();
        let arr = |val: &serde_json::Value| -> Vec<f64> {
            val.as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect()
        };
        let (abs, rel) = (
            v["tolerance"]["abs"].as_f64().unwrap(),
            v["tolerance"]["rel"].as_f64().unwrap(),
        );
        let s = CubicSplineFn::new(
            arr(&v["inputs"]["x"]),
            arr(&v["inputs"]["y"]),
            FnEndCondition::Han,
        );
        let e = s.indicator();
        let exp = &v["expected"];
        for (got, want) in [
            (s.c(), arr(&exp["c"])),
            (s.forward_a(), arr(&exp["a"])),
            (s.forward_b(), arr(&exp["b"])),
            (s.backward_a(), arr(&exp["a_star"])),
            (s.backward_b(), arr(&exp["b_star"])),
            (&e[..], arr(&exp["e"])),
        ] {
            assert_eq!(got.len(), want.len());
            for (g, w) in got.iter().zip(&want) {
                assert!(close(*g, *w, abs, rel), "{g} vs {w}");
            }
        }
    }

    #[test]
    fn propagation_eq10_from_any_j() {
        // c_i = b_i − a_i c_{i+1} below j, c_i = b*_i − a*_i c_{i−1} above j (eq 10, fixed).
        let (x, y) = data();
        let s = CubicSplineFn::new(x.clone(), y, FnEndCondition::Han);
        let n = x.len();
        for j in 1..n - 1 {
            let mut c = vec![0.0; n];
            c[j] = s.c_explicit(j);
            for i in (0..j).rev() {
                c[i] = s.forward_b()[i] - s.forward_a()[i] * c[i + 1];
            }
            for i in j + 1..n {
                c[i] = s.backward_b()[i - 1] - s.backward_a()[i - 1] * c[i - 1];
            }
            for (a, b) in c.iter().zip(s.c()) {
                assert!(close(*a, *b, 1e-14, 1e-12));
            }
        }
    }

    #[test]
    fn interpolates_and_is_c2() {
        let (x, y) = data();
        for end in [
            FnEndCondition::Han,
            FnEndCondition::Natural,
            FnEndCondition::Slopes(1.0, 0.0),
        ] {
            let s = CubicSplineFn::new(x.clone(), y.clone(), end);
            for (xi, yi) in x.iter().zip(&y) {
                assert!((s.value(*xi) - yi).abs() < 1e-14);
                assert!((s.derivs_left(*xi)[0] - yi).abs() < 1e-14);
            }
            for k in 1..x.len() - 1 {
                let l = s.derivs_left(x[k]);
                let r = s.derivs(x[k]);
                assert!((l[1] - r[1]).abs() < 1e-13, "y' jumps at {k}");
                assert!((l[2] - r[2]).abs() < 1e-13, "y'' jumps at {k}");
                assert!((r[2] - 6.0 * s.c()[k]).abs() < 1e-13);
            }
        }
    }

    #[test]
    fn end_conditions_hold() {
        let (x, y) = data();
        let n = x.len();
        let s = CubicSplineFn::new(x.clone(), y.clone(), FnEndCondition::Natural);
        assert_eq!(s.c()[0], 0.0);
        assert!(s.c()[n - 1].abs() < 1e-16);
        assert!(s.derivs(x[0])[2].abs() < 1e-15 && s.derivs(x[n - 1])[2].abs() < 1e-14);
        let s = CubicSplineFn::new(x.clone(), y.clone(), FnEndCondition::Slopes(0.7, -0.4));
        assert!((s.derivs(x[0])[1] - 0.7).abs() < 1e-14);
        assert!((s.derivs(x[n - 1])[1] + 0.4).abs() < 1e-14);
        let s = CubicSplineFn::new(x, y, FnEndCondition::Han);
        assert_eq!(s.c()[0], s.c()[1]);
        assert_eq!(s.c()[n - 1], s.c()[n - 2]);
        let e = s.indicator();
        assert_eq!((e[0], e[n - 1]), (0.0, 0.0));
    }

    #[test]
    fn reproduces_a_cubic_with_slopes() {
        let f = |x: f64| x * x * x - 2.0 * x * x + 0.5 * x - 1.0;
        let df = |x: f64| 3.0 * x * x - 4.0 * x + 0.5;
        let x = vec![-1.0, -0.3, 0.4, 0.5, 1.7, 2.0, 3.1];
        let y: Vec<f64> = x.iter().map(|&v| f(v)).collect();
        let s = CubicSplineFn::new(x, y, FnEndCondition::Slopes(df(-1.0), df(3.1)));
        for k in 0..=100 {
            let t = -1.0 + 4.1 * k as f64 / 100.0;
            let d = s.derivs(t);
            assert!((d[0] - f(t)).abs() < 1e-12);
            assert!((d[1] - df(t)).abs() < 1e-11);
            assert!((d[2] - (6.0 * t - 4.0)).abs() < 1e-10);
            assert!((d[3] - 6.0).abs() < 1e-9);
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let (x, y) = data();
        let s = CubicSplineFn::new(x, y, FnEndCondition::Han);
        let step = 1e-6;
        for k in 0..40 {
            // Stay inside spans so the differences do not straddle a knot.
            let t = 0.13 + 0.2 * k as f64;
            if s.x().iter().any(|&xi| (xi - t).abs() < 4.0 * step) {
                continue;
            }
            let d = s.derivs(t);
            let (p, m) = (s.derivs(t + step), s.derivs(t - step));
            assert!(((p[0] - m[0]) / (2.0 * step) - d[1]).abs() < 1e-8);
            assert!(((p[1] - m[1]) / (2.0 * step) - d[2]).abs() < 1e-8);
            assert!(((p[2] - m[2]) / (2.0 * step) - d[3]).abs() < 1e-7);
            let cd = s.derivatives(t);
            assert_eq!(cd.point, Point::new(t, d[0]));
            assert_eq!(cd.d1, Vec2::new(1.0, d[1]));
        }
        assert_eq!(s.domain(), (0.0, 8.5));
        assert_eq!(s.breakpoints(), s.x().to_vec());
    }

    #[test]
    fn sweep_coefficients_are_in_range() {
        // Spec §1.3 property 5: 0 < a_i, a*_i < 1/2 for the interior points.
        let x: Vec<f64> = [0.0, 0.01, 3.0, 3.02, 3.5, 9.0, 9.001, 12.0].to_vec();
        let y = vec![0.0; x.len()];
        let s = CubicSplineFn::new(x.clone(), y, FnEndCondition::Han);
        let n = x.len();
        for i in 1..n - 1 {
            assert!(s.forward_a()[i] > 0.0 && s.forward_a()[i] < 0.5);
            assert!(s.backward_a()[i - 1] > 0.0 && s.backward_a()[i - 1] < 0.5);
        }
        assert_eq!(s.forward_a()[0], -1.0);
        assert_eq!(s.backward_a()[n - 2], -1.0);
    }

    #[test]
    fn small_inputs() {
        let s = CubicSplineFn::new(vec![0.0, 2.0], vec![1.0, 3.0], FnEndCondition::Natural);
        assert_eq!(s.c(), &[0.0, 0.0]);
        assert!((s.value(1.0) - 2.0).abs() < 1e-15);
        let s = CubicSplineFn::new(
            vec![0.0, 1.0, 3.0],
            vec![0.0, 1.0, 0.0],
            FnEndCondition::Han,
        );
        // Three points, c_1 = c_2 = c_3: one parabola through them.
        assert!((s.c()[0] - s.c()[2]).abs() < 1e-16);
        assert!((s.value(2.0) - (s.derivs(0.0)[1] * 2.0 + 3.0 * s.c()[0] * 4.0)).abs() < 1e-14);
    }

    #[test]
    fn rejects_bad_input() {
        let han = FnEndCondition::Han;
        assert_eq!(
            CubicSplineFn::try_new(vec![0.0, 1.0, 1.0, 2.0], vec![0.0; 4], han),
            Err(Error::NotIncreasing { index: 2 })
        );
        assert_eq!(
            CubicSplineFn::try_new(vec![0.0, 2.0, 1.0], vec![0.0; 3], han),
            Err(Error::NotIncreasing { index: 2 })
        );
        assert_eq!(
            CubicSplineFn::try_new(vec![0.0, f64::NAN, 1.0], vec![0.0; 3], han),
            Err(Error::NonFinite { index: 1 })
        );
        assert_eq!(
            CubicSplineFn::try_new(vec![0.0, 1.0, 2.0], vec![0.0, 0.0, f64::INFINITY], han),
            Err(Error::NonFinite { index: 2 })
        );
        assert_eq!(
            CubicSplineFn::try_new(vec![0.0, 1.0], vec![0.0; 2], han),
            Err(Error::TooFewPoints { needed: 3, got: 2 })
        );
        assert_eq!(
            CubicSplineFn::try_new(vec![0.0], vec![0.0], FnEndCondition::Natural),
            Err(Error::TooFewPoints { needed: 2, got: 1 })
        );
        assert!(matches!(
            CubicSplineFn::try_new(vec![0.0, 1.0, 2.0], vec![0.0; 2], han),
            Err(Error::LengthMismatch { .. })
        ));
        assert!(matches!(
            CubicSplineFn::try_new(
                vec![0.0, 1.0],
                vec![0.0; 2],
                FnEndCondition::Slopes(f64::NAN, 0.0)
            ),
            Err(Error::InvalidParameter { .. })
        ));
    }

    #[test]
    #[should_panic(expected = "strictly increasing")]
    fn new_panics_on_bad_input() {
        let _ = CubicSplineFn::new(vec![1.0, 0.0, 2.0], vec![0.0; 3], FnEndCondition::Han);
    }
}
