//! The analysis curve of a space curve ([`SpaceCubic`]): the C² cubic spline through the
//! points, per coordinate on shared chord-length parameters, not-a-knot ends when open and
//! periodic when closed, as [`super::analysis_curve`] is for planar curves (the same
//! tridiagonal systems, solved for x, y and z together); its curvature, torsion and
//! principal normal ([`SpaceDerivatives`]), and samples of them by arc length for plots
//! ([`SpaceSample`]).

use std::ops::{Add, Div, Mul, Sub};

use crate::error::{Error, Result};
use crate::geom::{SpaceSeq, Xyz, norm3 as norm};
use crate::numeric::{GaussLegendre, Linear};
use crate::spline::{Ends, break_span, hermite_coeffs, open_tangents, periodic_tangents};

/// A space vector with the arithmetic the crate's linear solvers need.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct V3(pub(crate) Xyz);

impl Add for V3 {
    type Output = V3;
    #[inline]
    fn add(self, o: V3) -> V3 {
        V3(std::array::from_fn(|k| self.0[k] + o.0[k]))
    }
}

impl Sub for V3 {
    type Output = V3;
    #[inline]
    fn sub(self, o: V3) -> V3 {
        V3(std::array::from_fn(|k| self.0[k] - o.0[k]))
    }
}

impl Mul<f64> for V3 {
    type Output = V3;
    #[inline]
    fn mul(self, f: f64) -> V3 {
        V3(self.0.map(|c| c * f))
    }
}

impl Div<f64> for V3 {
    type Output = V3;
    #[inline]
    fn div(self, f: f64) -> V3 {
        V3(self.0.map(|c| c / f))
    }
}

impl Linear for V3 {}

/// `a · b`.
#[inline]
pub(crate) fn dot(a: Xyz, b: Xyz) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a × b`.
#[inline]
pub(crate) fn cross(a: Xyz, b: Xyz) -> Xyz {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Position and the first three derivatives with respect to the spline parameter at one
/// parameter of a [`SpaceCubic`], and the differential geometry they give.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpaceDerivatives {
    /// The position r(t).
    pub point: Xyz,
    /// r'(t).
    pub d1: Xyz,
    /// r''(t).
    pub d2: Xyz,
    /// r'''(t).
    pub d3: Xyz,
}

/// Speed, κ, dκ/ds, the triple product `(r'×r'')·r'''` and |r'×r''| at one parameter, sharing
/// the products (see [`SpaceDerivatives`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Frenet {
    pub(crate) speed: f64,
    pub(crate) kappa: f64,
    pub(crate) dkappa_ds: f64,
    /// `(r'×r'')·r'''`.
    pub(crate) triple: f64,
    /// `|r'×r''|²`.
    pub(crate) cross_sq: f64,
    /// `(r'×r'')·(r'×r''')`, the derivative of `|r'×r''|²/2`.
    pub(crate) cross_rate: f64,
}

impl Frenet {
    #[inline]
    pub(crate) fn of(d: &SpaceDerivatives) -> Frenet {
        let w = dot(d.d1, d.d1);
        let speed = w.sqrt();
        let c = cross(d.d1, d.d2);
        let cross_sq = dot(c, c);
        let cn = cross_sq.sqrt();
        let cross_rate = dot(c, cross(d.d1, d.d3));
        // κ = |c| w^(−3/2); dκ/dt = (c·c′ w − 3|c|² r′·r″)/(|c| w^(5/2)), c′ = r′×r‴.
        let dkappa_ds = if cn > 0.0 {
            (cross_rate * w - 3.0 * cross_sq * dot(d.d1, d.d2)) / (cn * w * w * w)
        } else {
            0.0
        };
        Frenet {
            speed,
            kappa: cn / (w * speed),
            dkappa_ds,
            triple: dot(c, d.d3),
            cross_sq,
            cross_rate,
        }
    }

    /// τ = `(r'×r'')·r'''/|r'×r''|²` (infinite or NaN where `r'×r'' = 0`).
    #[inline]
    pub(crate) fn torsion(&self) -> f64 {
        self.triple / self.cross_sq
    }

    /// dτ/ds on a cubic span, where `r'''` is constant and so the triple product too:
    /// `dτ/dt = −2 (r'×r'')·r''' (r'×r'')·(r'×r''') / |r'×r''|⁴`.
    #[inline]
    pub(crate) fn torsion_rate(&self) -> f64 {
        -2.0 * self.torsion() * self.cross_rate / (self.cross_sq * self.speed)
    }
}

impl SpaceDerivatives {
    /// The curvature κ = |r'×r''|/|r'|³ (unsigned; 0 where the curve is straight).
    pub fn curvature(&self) -> f64 {
        Frenet::of(self).kappa
    }

    /// The arc-length derivative of the (unsigned) curvature, 0 where κ = 0.
    pub fn curvature_derivative(&self) -> f64 {
        Frenet::of(self).dkappa_ds
    }

    /// The torsion τ = (r'×r'')·r'''/|r'×r''|², `None` where r'×r'' = 0 (no osculating plane).
    pub fn torsion(&self) -> Option<f64> {
        let f = Frenet::of(self);
        (f.cross_sq > 0.0)
            .then(|| f.torsion())
            .filter(|t| t.is_finite())
    }

    /// The unit principal normal N = (r'×r'')×r' / |(r'×r'')×r'|, towards the centre of
    /// curvature; `None` where κ = 0.
    pub fn principal_normal(&self) -> Option<Xyz> {
        let n = cross(cross(self.d1, self.d2), self.d1);
        let l = norm(n);
        (l > 0.0 && l.is_finite()).then(|| n.map(|c| c / l))
    }
}

/// The C² cubic spline through space points with chord-length parameters: not-a-knot ends
/// when open, periodic when closed (a closed curve has as many spans as points, and one more
/// knot than points). Each span stores its power-basis coefficients per coordinate.
#[derive(Clone, Debug, PartialEq)]
pub struct SpaceCubic {
    t: Vec<f64>,
    /// Per span: `a0 + a1 u + a2 u² + a3 u³`, u = t − t_i.
    coeffs: Vec<[Xyz; 4]>,
    closed: bool,
}

impl SpaceCubic {
    /// The analysis curve of a space curve: the C² cubic through its points with
    /// chord-length parameters, not-a-knot ends when open, periodic when closed.
    ///
    /// # Errors
    /// [`Error::Singular`] if the spline system cannot be solved or its coefficients are not
    /// finite (chords so long that their lengths overflow).
    pub fn of_seq(seq: &SpaceSeq) -> Result<SpaceCubic> {
        let p = seq.points();
        let n = p.len();
        let closed = seq.is_closed();
        let spans = if closed { n } else { n - 1 };
        let mut t = Vec::with_capacity(spans + 1);
        t.push(0.0);
        for i in 0..spans {
            t.push(t[i] + norm((V3(p[(i + 1) % n]) - V3(p[i])).0));
        }
        // The spacings of the knots (not the chords: they differ in rounding), as for planar
        // curves.
        let dt: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        if let Some(index) = dt.iter().position(|h| !(h.is_finite() && *h > 0.0)) {
            return Err(Error::Singular(format!(
                "chord {index} of the space curve has no usable length"
            )));
        }
        let slope: Vec<V3> = (0..spans)
            .map(|i| (V3(p[(i + 1) % n]) - V3(p[i])) / dt[i])
            .collect();
        let tangents = if closed {
            periodic_tangents(&dt, &slope)?
        } else {
            open_tangents(&t, |i| dt[i], |i| slope[i], Ends::NotAKnot)?
        };
        drop(slope);
        let coeffs: Vec<[Xyz; 4]> = (0..spans)
            .map(|i| {
                let j = (i + 1) % n;
                hermite_coeffs(V3(p[i]), V3(p[j]), tangents[i], tangents[j], dt[i]).map(|v| v.0)
            })
            .collect();
        if coeffs.iter().flatten().flatten().any(|c| !c.is_finite()) {
            return Err(Error::Singular(
                "space spline coefficients are not finite".into(),
            ));
        }
        Ok(SpaceCubic { t, coeffs, closed })
    }

    /// The knots (parameter values at the points; a closed curve has one more than points).
    pub fn knots(&self) -> &[f64] {
        &self.t
    }

    /// Number of cubic spans.
    pub fn num_spans(&self) -> usize {
        self.coeffs.len()
    }

    /// Whether the curve is periodic.
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// The parameter interval `(t_0, t_m)`.
    pub fn domain(&self) -> (f64, f64) {
        (self.t[0], self.t[self.t.len() - 1])
    }

    /// Power-basis coefficients `[a0, a1, a2, a3]` of span `i` in `u = t − t_i`.
    ///
    /// # Panics
    /// If `i` is not below [`SpaceCubic::num_spans`].
    pub fn span_coeffs(&self, i: usize) -> [Xyz; 4] {
        self.coeffs[i]
    }

    /// The span containing `t` (clamped to the first and last span).
    pub fn find_span(&self, t: f64) -> usize {
        break_span(&self.t, t)
    }

    /// Position and derivatives at `t` on span `i` (no span search; outside the span this is
    /// the span polynomial's extension).
    ///
    /// # Panics
    /// If `i` is not below [`SpaceCubic::num_spans`].
    #[inline]
    pub fn derivatives_in_span(&self, i: usize, t: f64) -> SpaceDerivatives {
        let [a0, a1, a2, a3] = self.coeffs[i];
        let u = t - self.t[i];
        SpaceDerivatives {
            point: std::array::from_fn(|k| a0[k] + (a1[k] + (a2[k] + a3[k] * u) * u) * u),
            d1: std::array::from_fn(|k| a1[k] + (a2[k] * 2.0 + a3[k] * (3.0 * u)) * u),
            d2: std::array::from_fn(|k| a2[k] * 2.0 + a3[k] * (6.0 * u)),
            d3: a3.map(|c| c * 6.0),
        }
    }

    /// Position and derivatives at `t` (the span on the right at a knot).
    pub fn derivatives(&self, t: f64) -> SpaceDerivatives {
        self.derivatives_in_span(self.find_span(t), t)
    }

    /// The point at `t`.
    pub fn point(&self, t: f64) -> Xyz {
        self.derivatives(t).point
    }

    /// `per_span` samples evenly spaced in parameter on every span, its start first, then
    /// the end of the domain (left-sided): `num_spans·per_span + 1` samples in parameter
    /// order, with arc length from the start by Gauss–Legendre quadrature. What the plots
    /// draw. `per_span` is taken as at least 1.
    pub fn samples(&self, per_span: usize) -> Vec<SpaceSample> {
        let k = per_span.max(1);
        let gl = GaussLegendre::new(8);
        let m = self.coeffs.len();
        let mut out = Vec::with_capacity(m * k + 1);
        let mut s = 0.0;
        for i in 0..m {
            let (t0, h) = (self.t[i], self.t[i + 1] - self.t[i]);
            let speed = |x: f64| norm(self.derivatives_in_span(i, x).d1);
            for j in 0..k {
                let (a, b) = (
                    t0 + h * j as f64 / k as f64,
                    t0 + h * (j + 1) as f64 / k as f64,
                );
                out.push(SpaceSample::of(s, &self.derivatives_in_span(i, a)));
                s += gl.integrate(a, b, speed);
            }
        }
        let end = self.t[m];
        out.push(SpaceSample::of(s, &self.derivatives_in_span(m - 1, end)));
        out
    }
}

/// One sample of a space curve for plotting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpaceSample {
    /// Arc length from the start of the curve.
    pub s: f64,
    /// The point.
    pub point: Xyz,
    /// The curvature κ ≥ 0.
    pub curvature: f64,
    /// The torsion τ, `None` where it is undefined (κ = 0).
    pub torsion: Option<f64>,
    /// The unit principal normal (towards the centre of curvature), zero where κ = 0: a comb
    /// tooth is `point + scale·κ·normal`.
    pub normal: Xyz,
}

impl SpaceSample {
    /// The sample at arc length `s` with the given derivatives.
    pub fn of(s: f64, d: &SpaceDerivatives) -> SpaceSample {
        let f = Frenet::of(d);
        SpaceSample {
            s,
            point: d.point,
            curvature: f.kappa,
            torsion: d.torsion(),
            normal: d.principal_normal().unwrap_or([0.0; 3]),
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::analysis::analysis_curve;
    use crate::geom::{Point, PointSeq};

    #[test]
    fn a_flat_curve_has_the_planar_coefficients_bit_for_bit() {
        let pts: Vec<Point> = (0..23)
            .map(|i| {
                let a = 0.31 * i as f64;
                Point::new(a.cos() * (1.0 + 0.1 * a), (1.7 * a).sin())
            })
            .collect();
        for closed in [false, true] {
            let planar = analysis_curve(&PointSeq::new(pts.clone(), closed).unwrap()).unwrap();
            let flat = pts.iter().map(|p| [p.x, p.y, 0.0]).collect();
            let space = SpaceCubic::of_seq(&SpaceSeq::new(flat, closed).unwrap()).unwrap();
            assert_eq!(space.knots(), planar.knots());
            assert_eq!(space.num_spans(), planar.num_spans());
            for i in 0..space.num_spans() {
                let (a, b) = (space.span_coeffs(i), planar.span_coeffs(i));
                for k in 0..4 {
                    assert_eq!([a[k][0], a[k][1], a[k][2]], [b[k].x, b[k].y, 0.0]);
                }
            }
        }
    }

    #[test]
    fn interpolates_and_is_c2() {
        let pts: Vec<Xyz> = (0..15)
            .map(|i| {
                let a = 0.4 * i as f64;
                [a.cos(), a.sin(), 0.3 * a * a]
            })
            .collect();
        for closed in [false, true] {
            let c = SpaceCubic::of_seq(&SpaceSeq::new(pts.clone(), closed).unwrap()).unwrap();
            let m = c.num_spans();
            for (k, p) in pts.iter().enumerate() {
                let q = c.point(c.knots()[k]);
                assert!(norm(V3(q).sub(V3(*p)).0) < 1e-12);
            }
            for k in 1..m {
                let (l, r) = (
                    c.derivatives_in_span(k - 1, c.knots()[k]),
                    c.derivatives_in_span(k, c.knots()[k]),
                );
                assert!(norm((V3(l.d1) - V3(r.d1)).0) < 1e-10);
                assert!(norm((V3(l.d2) - V3(r.d2)).0) < 1e-9);
            }
            if closed {
                let (a, b) = (
                    c.derivatives_in_span(m - 1, c.knots()[m]),
                    c.derivatives_in_span(0, 0.0),
                );
                assert!(norm((V3(a.point) - V3(b.point)).0) < 1e-12);
                assert!(norm((V3(a.d2) - V3(b.d2)).0) < 1e-9);
            }
        }
    }
}
