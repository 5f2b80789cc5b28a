//! The C² parametric cubic interpolating spline through planar points (docs/algorithms/README.md
//! §0.2, docs/algorithms/kjellander-poliakoff.md §2.1).

use serde::{Deserialize, Serialize};

use crate::curve::{Curve, CurveDeriv, Derivatives, Piecewise};
use crate::error::{Error, Result};
use crate::geom::{Point, Vec2};
use std::ops::Div;

use super::knots::break_span;
use crate::numeric::{Linear, PIVOT_REL, map_indices, solve_cyclic_tridiagonal};

/// How parameter values are assigned to a point sequence (docs/algorithms/README.md §0.2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Parametrization {
    /// `t_i = i`.
    Uniform,
    /// Increments `|P_{i+1} − P_i|`.
    #[default]
    ChordLength,
    /// Increments `|P_{i+1} − P_i|^(1/2)`.
    Centripetal,
}

/// End conditions of an open interpolating spline.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EndCondition {
    /// `r'' = 0` at both ends.
    Natural,
    /// Given first derivatives `r'(t_0)`, `r'(t_n)` (with respect to the spline parameter).
    Clamped(Vec2, Vec2),
    /// `r'''` continuous at the second and the second-to-last knot (de Boor's not-a-knot).
    #[default]
    NotAKnot,
}

/// Parameter values `t_0 = 0, t_1, …` for a point sequence. For a closed sequence one more
/// value is returned: the parameter at which the curve returns to `P_0`.
///
/// # Errors
/// [`Error::DuplicatePoint`] for a zero chord, [`Error::NonFinite`] for a non-finite point.
pub fn parameters(points: &[Point], kind: Parametrization, closed: bool) -> Result<Vec<f64>> {
    if let Some(index) = points.iter().position(|p| !p.is_finite()) {
        return Err(Error::NonFinite { index });
    }
    let n = points.len();
    let m = if closed { n } else { n.saturating_sub(1) };
    // The chord lengths (hypot, the costly part) in parallel for long sequences, then summed
    // in order: the same bits with any number of threads.
    let lengths = map_indices(m, |i| {
        (points[crate::geom::next_index(i, n)] - points[i]).length()
    });
    let mut t = Vec::with_capacity(m + 1);
    t.push(0.0);
    for (i, &d) in lengths.iter().enumerate() {
        if d == 0.0 {
            return Err(Error::DuplicatePoint { index: (i + 1) % n });
        }
        let inc = match kind {
            Parametrization::Uniform => 1.0,
            Parametrization::ChordLength => d,
            Parametrization::Centripetal => d.sqrt(),
        };
        t.push(t[i] + inc);
    }
    Ok(t)
}

/// A piecewise cubic Hermite curve through `P_0..P_m` at parameters `t_0 < … < t_m`; each span
/// is the cubic with the end positions and first derivatives of its knots (KP eq 6).
///
/// Built by [`ParametricCubic::interpolate`] (the C² spline), [`ParametricCubic::closed`]
/// (the periodic C² spline) or [`ParametricCubic::from_hermite`] (given tangents, C¹). A closed
/// curve stores `P_0` again as its last knot point, so it has as many spans as points.
#[derive(Clone, Debug, PartialEq)]
pub struct ParametricCubic {
    t: Vec<f64>,
    points: Vec<Point>,
    tangents: Vec<Vec2>,
    /// Per span: `a0 + a1 s + a2 s² + a3 s³`, s = t − t_i.
    coeffs: Vec<[Vec2; 4]>,
    closed: bool,
}

impl ParametricCubic {
    /// The C² interpolating cubic spline through an open point sequence.
    ///
    /// # Errors
    /// [`Error::TooFewPoints`] (fewer than 2 points; not-a-knot needs 4), and the errors of
    /// [`parameters`].
    pub fn interpolate(
        points: &[Point],
        param: Parametrization,
        end: EndCondition,
    ) -> Result<ParametricCubic> {
        let t = parameters(points, param, false)?;
        ParametricCubic::interpolate_at(&t, points, end)
    }

    /// The C² interpolating cubic spline through `points` at the given increasing parameters.
    ///
    /// # Errors
    /// [`Error::TooFewPoints`], [`Error::LengthMismatch`], [`Error::NotIncreasing`],
    /// [`Error::NonFinite`].
    pub fn interpolate_at(
        t: &[f64],
        points: &[Point],
        end: EndCondition,
    ) -> Result<ParametricCubic> {
        let tangents = c2_tangents(t, points, end)?;
        ParametricCubic::build(t.to_vec(), points.to_vec(), tangents, false)
    }

    /// The periodic C² cubic spline through a closed point sequence (the last point connects
    /// back to the first, which must not be repeated).
    ///
    /// # Errors
    /// [`Error::TooFewPoints`] (fewer than 3 points) and the errors of [`parameters`].
    pub fn closed(points: &[Point], param: Parametrization) -> Result<ParametricCubic> {
        let (t, tangents) = c2_closed_tangents(points, param)?;
        let mut pts = points.to_vec();
        pts.push(points[0]);
        ParametricCubic::build(t, pts, tangents, true)
    }

    /// A C¹ piecewise cubic Hermite curve from parameters, points and tangents (all of equal
    /// length). For closed Hermite data repeat the first point and tangent at the end.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`], [`Error::NotIncreasing`], [`Error::NonFinite`],
    /// [`Error::TooFewPoints`].
    pub fn from_hermite(
        t: Vec<f64>,
        points: Vec<Point>,
        tangents: Vec<Vec2>,
    ) -> Result<ParametricCubic> {
        if points.len() < 2 {
            return Err(Error::TooFewPoints {
                needed: 2,
                got: points.len(),
            });
        }
        check_params(&t, points.len())?;
        if tangents.len() != points.len() {
            return Err(Error::LengthMismatch {
                what: "tangents",
                got: tangents.len(),
                expected: points.len(),
            });
        }
        if let Some(index) = tangents.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite { index });
        }
        ParametricCubic::build(t, points, tangents, false)
    }

    fn build(
        t: Vec<f64>,
        points: Vec<Point>,
        tangents: Vec<Vec2>,
        closed: bool,
    ) -> Result<ParametricCubic> {
        let coeffs = (0..points.len() - 1)
            .map(|i| {
                hermite_coeffs(
                    points[i].to_vec2(),
                    points[i + 1].to_vec2(),
                    tangents[i],
                    tangents[i + 1],
                    t[i + 1] - t[i],
                )
            })
            .collect::<Vec<_>>();
        if coeffs.iter().flatten().any(|c| !c.is_finite()) {
            return Err(Error::Singular("spline coefficients are not finite".into()));
        }
        Ok(ParametricCubic {
            t,
            points,
            tangents,
            coeffs,
            closed,
        })
    }

    /// The knots (parameter values at the points); a closed curve has one more than points.
    pub fn knots(&self) -> &[f64] {
        &self.t
    }

    /// The interpolated points (a closed curve repeats `P_0` at the end).
    pub fn points(&self) -> &[Point] {
        &self.points
    }

    /// The first derivatives at the knots.
    pub fn tangents(&self) -> &[Vec2] {
        &self.tangents
    }

    /// Whether the curve is periodic.
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// Number of cubic spans.
    pub fn num_spans(&self) -> usize {
        self.coeffs.len()
    }

    /// Power-basis coefficients `[a0, a1, a2, a3]` of span `i` in `s = t − t_i` (KP eq 6).
    pub fn span_coeffs(&self, i: usize) -> [Vec2; 4] {
        self.coeffs[i]
    }

    /// The span containing `t` (clamped to the first and last span).
    pub fn find_span(&self, t: f64) -> usize {
        break_span(&self.t, t)
    }

    /// Jumps `r'''(t_k+) − r'''(t_k−) = 6(a_{k,3} − a_{k−1,3})` at the interior knots
    /// k = 1..m−1 (KP §2.2). A closed curve has a jump at every knot, `P_0` first.
    pub fn third_derivative_jumps(&self) -> Vec<Vec2> {
        let m = self.coeffs.len();
        if self.closed {
            (0..m)
                .map(|k| (self.coeffs[k][3] - self.coeffs[(k + m - 1) % m][3]) * 6.0)
                .collect()
        } else {
            (1..m)
                .map(|k| (self.coeffs[k][3] - self.coeffs[k - 1][3]) * 6.0)
                .collect()
        }
    }

    /// Position and derivatives at `t` evaluated on span `i` (no span search; `t` may lie
    /// outside the span, giving the span polynomial's extension). For loops that walk the
    /// spans in order.
    pub fn derivatives_in_span(&self, i: usize, t: f64) -> Derivatives {
        span_derivatives(&self.coeffs[i], t - self.t[i])
    }
}

/// Position and derivatives of a span with power-basis coefficients `c` at `s = t − t_i`
/// (for loops that form the coefficients one span at a time, as the metrics' span pass).
#[inline]
pub(crate) fn span_derivatives(c: &[Vec2; 4], s: f64) -> Derivatives {
    let [a0, a1, a2, a3] = *c;
    let p = a0 + (a1 + (a2 + a3 * s) * s) * s;
    let d1 = a1 + (a2 * 2.0 + a3 * (3.0 * s)) * s;
    let d2 = a2 * 2.0 + a3 * (6.0 * s);
    Derivatives {
        point: p.to_point(),
        d1,
        d2,
        d3: a3 * 6.0,
    }
}

/// The first derivatives at the knots of the C² interpolating cubic spline through `points`
/// at the increasing parameters `t` ([`ParametricCubic::interpolate_at`] without the span
/// coefficients, for the metrics' span pass that forms them one span at a time).
///
/// # Errors
/// As [`ParametricCubic::interpolate_at`].
pub(crate) fn c2_tangents(t: &[f64], points: &[Point], end: EndCondition) -> Result<Vec<Vec2>> {
    let n = points.len();
    let min = if matches!(end, EndCondition::NotAKnot) {
        4
    } else {
        2
    };
    if n < min {
        return Err(Error::TooFewPoints {
            needed: min,
            got: n,
        });
    }
    check_params(t, n)?;
    let ends = match end {
        EndCondition::Natural => Ends::Natural,
        EndCondition::Clamped(a, b) => Ends::Clamped(a, b),
        EndCondition::NotAKnot => Ends::NotAKnot,
    };
    // The spacings and chord slopes formed where the solve needs them (no stored copies).
    let dt = |i: usize| t[i + 1] - t[i];
    open_tangents(t, dt, |i| (points[i + 1] - points[i]) / dt(i), ends)
}

/// The parameters and the first derivatives at the knots (the first repeated at the end) of
/// the periodic C² cubic spline through a closed point sequence ([`ParametricCubic::closed`]
/// without the span coefficients).
///
/// # Errors
/// As [`ParametricCubic::closed`].
pub(crate) fn c2_closed_tangents(
    points: &[Point],
    param: Parametrization,
) -> Result<(Vec<f64>, Vec<Vec2>)> {
    let n = points.len();
    if n < 3 {
        return Err(Error::TooFewPoints { needed: 3, got: n });
    }
    let t = parameters(points, param, true)?;
    let dt: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect(); // n spans
    let slope: Vec<Vec2> = (0..n)
        .map(|i| (points[crate::geom::next_index(i, n)] - points[i]) / dt[i])
        .collect();
    let mut tangents = periodic_tangents(&dt, &slope)?;
    tangents.push(tangents[0]);
    Ok((t, tangents))
}

/// End conditions of [`open_tangents`], for values of any [`Linear`] type.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Ends<T> {
    /// `r'' = 0` at both ends.
    Natural,
    /// Given first derivatives at the first and the last knot.
    Clamped(T, T),
    /// de Boor's not-a-knot (needs at least 4 knots).
    NotAKnot,
}

/// The first derivatives at the knots `t` (spacings `dt(i) = t[i+1] − t[i]`) of the C² cubic
/// spline whose chord slopes are `slope(i)` (`(P_{i+1} − P_i)/dt_i`, one fewer than knots),
/// open with the given ends, for values of any [`Linear`] type (plane points, space points,
/// scalars alike).
///
/// The tridiagonal system of [`ParametricCubic::interpolate_at`], solved by the Thomas
/// algorithm with each row formed as the sweep reaches it: the operations of
/// [`crate::numeric::solve_tridiagonal`] on the assembled system, in the same order, without storing the
/// system (three arrays and a right-hand side fewer: at 10⁶ points, 40 MB not written).
pub(crate) fn open_tangents<T: Linear + Div<f64, Output = T>>(
    t: &[f64],
    dt: impl Fn(usize) -> f64,
    slope: impl Fn(usize) -> T,
    end: Ends<T>,
) -> Result<Vec<T>> {
    let n = t.len();
    // Row i as (sub, diag, sup, rhs); the interior rows' `sub[0]` and `sup[n−1]` do not occur.
    let row = |i: usize| -> (f64, f64, f64, T) {
        if i > 0 && i < n - 1 {
            let (h0, h1) = (dt(i - 1), dt(i));
            let rhs = (slope(i - 1) * h1 + slope(i) * h0) * 3.0;
            return (h1, 2.0 * (h0 + h1), h0, rhs);
        }
        let last = i == n - 1;
        match end {
            Ends::Natural if last => (1.0, 2.0, 0.0, slope(n - 2) * 3.0),
            Ends::Natural => (0.0, 2.0, 1.0, slope(0) * 3.0),
            Ends::Clamped(_, b) if last => (0.0, 1.0, 0.0, b),
            Ends::Clamped(a, _) => (0.0, 1.0, 0.0, a),
            Ends::NotAKnot if last => {
                let d = t[n - 1] - t[n - 3];
                let (h2, h3) = (dt(n - 2), dt(n - 3));
                let rhs = (slope(n - 3) * (h2 * h2) + slope(n - 2) * ((2.0 * d + h2) * h3)) / d;
                (d, h3, 0.0, rhs)
            }
            Ends::NotAKnot => {
                let d = t[2] - t[0];
                let (h0, h1) = (dt(0), dt(1));
                let rhs = (slope(0) * ((h0 + 2.0 * d) * h1) + slope(1) * (h0 * h0)) / d;
                (0.0, h1, d, rhs)
            }
        }
    };
    // The pivot test of `solve_tridiagonal` (a pivot within `PIVOT_REL` of the largest
    // diagonal entry, or a non-finite one past the first row), made once the sweep has seen
    // every diagonal entry: a failed test ends in the same error, and a passed one leaves the
    // same values.
    let mut scale = 0.0_f64;
    let (mut smallest_pivot, mut finite) = (f64::INFINITY, true);
    let mut c = vec![0.0; n];
    let mut x = Vec::with_capacity(n);
    let (_, mut beta, mut sup, rhs) = row(0);
    scale = scale.max(beta.abs());
    smallest_pivot = smallest_pivot.min(beta.abs());
    x.push(rhs * (1.0 / beta));
    for i in 1..n {
        let (sub, d, next_sup, rhs) = row(i);
        scale = scale.max(d.abs());
        c[i - 1] = sup / beta;
        beta = d - sub * c[i - 1];
        smallest_pivot = smallest_pivot.min(beta.abs());
        finite &= beta.is_finite();
        x.push((rhs - x[i - 1] * sub) * (1.0 / beta));
        sup = next_sup;
    }
    if !(finite && smallest_pivot > PIVOT_REL * scale.max(f64::MIN_POSITIVE)) {
        return Err(Error::Singular("zero pivot in tridiagonal solve".into()));
    }
    for i in (0..n - 1).rev() {
        x[i] = x[i] - x[i + 1] * c[i];
    }
    Ok(x)
}

/// The first derivatives at the knots of the periodic C² cubic spline with spacings `dt` and
/// chord slopes `slope` (as many as points): the cyclic system of
/// [`ParametricCubic::closed`], for values of any [`Linear`] type.
pub(crate) fn periodic_tangents<T: Linear>(dt: &[f64], slope: &[T]) -> Result<Vec<T>> {
    let n = dt.len();
    let mut sub = vec![0.0; n];
    let mut diag = vec![0.0; n];
    let mut sup = vec![0.0; n];
    let mut rhs = vec![T::default(); n];
    for i in 0..n {
        let im = (i + n - 1) % n;
        sub[i] = dt[i];
        diag[i] = 2.0 * (dt[im] + dt[i]);
        sup[i] = dt[im];
        rhs[i] = (slope[im] * dt[i] + slope[i] * dt[im]) * 3.0;
    }
    solve_cyclic_tridiagonal(&sub, &diag, &sup, &mut rhs)?;
    Ok(rhs)
}

/// KP eq 6: the power-basis coefficients of the cubic Hermite span (`p0` and `p1` as position
/// vectors), for values of any [`Linear`] type.
pub(crate) fn hermite_coeffs<T: Linear + Div<f64, Output = T>>(
    p0: T,
    p1: T,
    d0: T,
    d1: T,
    h: f64,
) -> [T; 4] {
    let dp = p1 - p0;
    let a2 = dp * (3.0 / (h * h)) - (d0 * 2.0 + d1) / h;
    let a3 = dp * (-2.0 / (h * h * h)) + (d0 + d1) / (h * h);
    [p0, d0, a2, a3]
}

fn check_params(t: &[f64], n: usize) -> Result<()> {
    if t.len() != n {
        return Err(Error::LengthMismatch {
            what: "parameters",
            got: t.len(),
            expected: n,
        });
    }
    if let Some(index) = t.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite { index });
    }
    if let Some(i) = t.windows(2).position(|w| w[1] <= w[0]) {
        return Err(Error::NotIncreasing { index: i + 1 });
    }
    Ok(())
}

impl Curve for ParametricCubic {
    fn domain(&self) -> (f64, f64) {
        (self.t[0], self.t[self.t.len() - 1])
    }

    fn eval(&self, t: f64) -> Point {
        self.derivatives(t).point
    }
}

impl CurveDeriv for ParametricCubic {
    fn derivatives(&self, t: f64) -> Derivatives {
        self.derivatives_in_span(self.find_span(t), t)
    }

    fn derivatives_left(&self, t: f64) -> Derivatives {
        let mut i = self.find_span(t);
        if i > 0 && self.t[i] == t {
            i -= 1;
        }
        self.derivatives_in_span(i, t)
    }
}

impl Piecewise for ParametricCubic {
    fn breakpoints(&self) -> Vec<f64> {
        self.t.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(n: usize, r: f64) -> Vec<Point> {
        (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                Point::new(r * a.cos(), r * a.sin())
            })
            .collect()
    }

    #[test]
    fn interpolates_and_is_c2() {
        let pts: Vec<Point> = (0..9)
            .map(|i| Point::new(i as f64, (i as f64 * 0.7).sin()))
            .collect();
        for end in [
            EndCondition::Natural,
            EndCondition::NotAKnot,
            EndCondition::Clamped(Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0)),
        ] {
            for par in [
                Parametrization::Uniform,
                Parametrization::ChordLength,
                Parametrization::Centripetal,
            ] {
                let s = ParametricCubic::interpolate(&pts, par, end).unwrap();
                for (k, p) in s.knots().iter().zip(&pts) {
                    assert!((s.eval(*k) - *p).length() < 1e-12);
                }
                for &k in &s.knots()[1..pts.len() - 1] {
                    let l = s.derivatives_left(k);
                    let r = s.derivatives(k);
                    assert!((l.d1 - r.d1).length() < 1e-10);
                    assert!((l.d2 - r.d2).length() < 1e-9);
                }
                let (a, b) = s.domain();
                match end {
                    EndCondition::Natural => {
                        assert!(s.derivatives(a).d2.length() < 1e-10);
                        assert!(s.derivatives(b).d2.length() < 1e-10);
                    }
                    EndCondition::NotAKnot => {
                        let j = s.third_derivative_jumps();
                        assert!(j[0].length() < 1e-9 && j[j.len() - 1].length() < 1e-9);
                    }
                    EndCondition::Clamped(d0, d1) => {
                        assert!((s.derivatives(a).d1 - d0).length() < 1e-12);
                        assert!((s.derivatives(b).d1 - d1).length() < 1e-12);
                    }
                }
            }
        }
    }

    #[test]
    fn natural_matches_kp_system() {
        // Not-a-knot reproduces a cubic exactly.
        let pts: Vec<Point> = (0..7)
            .map(|i| Point::new(i as f64, (i as f64).powi(3) - 2.0 * i as f64))
            .collect();
        let t: Vec<f64> = (0..7).map(|i| i as f64).collect();
        let s = ParametricCubic::interpolate_at(&t, &pts, EndCondition::NotAKnot).unwrap();
        for k in 0..60 {
            let x = k as f64 * 0.1;
            assert!((s.eval(x).y - (x.powi(3) - 2.0 * x)).abs() < 1e-10);
        }
    }

    #[test]
    fn closed_is_periodic_c2() {
        let pts = circle(12, 2.0);
        let s = ParametricCubic::closed(&pts, Parametrization::ChordLength).unwrap();
        let (a, b) = s.domain();
        let l = s.derivatives_left(b);
        let r = s.derivatives(a);
        assert!((l.point - r.point).length() < 1e-12);
        assert!((l.d1 - r.d1).length() < 1e-10);
        assert!((l.d2 - r.d2).length() < 1e-9);
        assert_eq!(s.third_derivative_jumps().len(), 12);
    }

    #[test]
    fn rejects_bad_input() {
        let p = vec![
            Point::new(0.0, 0.0),
            Point::new(0.0, 0.0),
            Point::new(1.0, 0.0),
            Point::new(2.0, 1.0),
        ];
        assert_eq!(
            ParametricCubic::interpolate(&p, Parametrization::ChordLength, EndCondition::Natural),
            Err(Error::DuplicatePoint { index: 1 })
        );
        let t = vec![0.0, 1.0, 1.0, 2.0];
        let p = vec![
            Point::new(0.0, 0.0),
            Point::new(1.0, 0.0),
            Point::new(2.0, 0.0),
            Point::new(3.0, 1.0),
        ];
        assert_eq!(
            ParametricCubic::interpolate_at(&t, &p, EndCondition::Natural),
            Err(Error::NotIncreasing { index: 2 })
        );
    }
}
