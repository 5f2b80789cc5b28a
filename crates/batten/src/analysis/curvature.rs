//! Signed curvature and derived quantities (docs/algorithms/README.md §0.1), energies (§0.4), comb
//! samples.

use serde::Serialize;

use crate::curve::{CurveDeriv, Derivatives, Piecewise};
use crate::geom::{Point, Vec2};
use crate::numeric::GaussLegendre;

/// Signed curvature `κ = (x'y'' − y'x'') / (x'² + y'²)^{3/2}` from derivatives
/// (docs/algorithms/README.md §0.1); positive when the tangent turns counter-clockwise. Zero speed
/// gives a non-finite value.
#[inline]
pub fn signed_curvature(d: &Derivatives) -> f64 {
    // sqrt of the squared length rather than hypot: this is the innermost call of every
    // curvature loop, and hypot's overflow guard costs more than the whole formula.
    let w = d.d1.length_squared();
    d.d1.cross(d.d2) / (w * w.sqrt())
}

/// dκ/ds, the derivative of curvature with respect to arc length (docs/algorithms/README.md §0.1):
/// `κ_t = [(r'×r''')|r'|² − 3(r'×r'')(r'·r'')] / |r'|⁵`, `dκ/ds = κ_t / |r'|`.
#[inline]
pub fn curvature_derivative(d: &Derivatives) -> f64 {
    let w = d.d1.length_squared();
    let k_t = (d.d1.cross(d.d3) * w - 3.0 * d.d1.cross(d.d2) * d.d1.dot(d.d2)) / (w * w * w.sqrt());
    k_t / w.sqrt()
}

/// Signed radius of curvature `ρ = 1/κ`, infinite at inflections and on straight parts.
#[inline]
pub fn radius_of_curvature(d: &Derivatives) -> f64 {
    1.0 / signed_curvature(d)
}

/// Signed curvature of `curve` at `t`.
pub fn curvature_at<C: CurveDeriv + ?Sized>(curve: &C, t: f64) -> f64 {
    signed_curvature(&curve.derivatives(t))
}

/// `∫ κ² ds` (docs/algorithms/README.md §0.4), by Gauss–Legendre quadrature on every span.
pub fn strain_energy<C: CurveDeriv + Piecewise + ?Sized>(curve: &C) -> f64 {
    integrate_spans(curve, |d| {
        let k = signed_curvature(d);
        k * k * d.d1.length()
    })
}

/// `∫ (dκ/ds)² ds`, the variation energy of the minimum-variation curve.
pub fn variation_energy<C: CurveDeriv + Piecewise + ?Sized>(curve: &C) -> f64 {
    integrate_spans(curve, |d| {
        let k = curvature_derivative(d);
        k * k * d.d1.length()
    })
}

pub(crate) fn integrate_spans<C: CurveDeriv + Piecewise + ?Sized>(
    curve: &C,
    f: impl Fn(&Derivatives) -> f64,
) -> f64 {
    let gl = GaussLegendre::default();
    let bp = curve.breakpoints();
    bp.windows(2)
        .map(|w| gl.integrate(w[0], w[1], |t| f(&curve.derivatives(t))))
        .sum()
}

/// One tooth of a curvature comb: the curve point, the unit normal (the tangent turned by
/// +90°) and the signed curvature. A comb draws `point + scale·curvature·normal`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CombSample {
    /// Curve parameter.
    pub t: f64,
    /// Point on the curve.
    pub point: Point,
    /// Unit left normal (zero where the speed vanishes).
    pub normal: Vec2,
    /// Signed curvature.
    pub curvature: f64,
}

/// Curvature-comb samples: `per_span` evenly spaced samples in every span, plus the end of
/// the domain.
pub fn curvature_comb<C: CurveDeriv + Piecewise + ?Sized>(
    curve: &C,
    per_span: usize,
) -> Vec<CombSample> {
    let per_span = per_span.max(1);
    let bp = curve.breakpoints();
    let mut out = Vec::with_capacity(bp.len().saturating_sub(1) * per_span + 1);
    let mut push = |t: f64, d: Derivatives| {
        out.push(CombSample {
            t,
            point: d.point,
            normal: d.d1.normalize().map_or(Vec2::ZERO, Vec2::perp),
            curvature: signed_curvature(&d),
        });
    };
    for w in bp.windows(2) {
        for j in 0..per_span {
            let t = w[0] + (w[1] - w[0]) * j as f64 / per_span as f64;
            push(t, curve.derivatives(t));
        }
    }
    if let Some(&t) = bp.last() {
        push(t, curve.derivatives_left(t));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::{EndCondition, ParametricCubic, Parametrization};

    #[test]
    fn circle_curvature_from_derivatives() {
        // r(t) = (2cos t, 2 sin t) and its mirror (vector common.signed_curvature.circle).
        for (sign, expected) in [(1.0, 0.5), (-1.0, -0.5)] {
            for t in [0.0, 0.7, 2.0] {
                let d = Derivatives {
                    point: Point::new(2.0 * f64::cos(t), sign * 2.0 * f64::sin(t)),
                    d1: Vec2::new(-2.0 * f64::sin(t), sign * 2.0 * f64::cos(t)),
                    d2: Vec2::new(-2.0 * f64::cos(t), -sign * 2.0 * f64::sin(t)),
                    d3: Vec2::new(2.0 * f64::sin(t), -sign * 2.0 * f64::cos(t)),
                };
                assert!((signed_curvature(&d) - expected).abs() < 1e-14);
                assert!(curvature_derivative(&d).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn curvature_derivative_matches_finite_differences() {
        let pts: Vec<Point> = (0..10)
            .map(|i| Point::new(i as f64, (i as f64 * 0.5).sin() * 2.0))
            .collect();
        let s = ParametricCubic::interpolate(
            &pts,
            Parametrization::ChordLength,
            EndCondition::NotAKnot,
        )
        .unwrap();
        for t in [1.3, 4.2, 7.7] {
            let h = 1e-5;
            let arc = |a: f64, b: f64| {
                GaussLegendre::default().integrate(a, b, |x| {
                    crate::curve::CurveDeriv::derivatives(&s, x).d1.length()
                })
            };
            let fd = (curvature_at(&s, t + h) - curvature_at(&s, t - h)) / arc(t - h, t + h);
            let an = curvature_derivative(&crate::curve::CurveDeriv::derivatives(&s, t));
            assert!((fd - an).abs() < 1e-6 * (1.0 + an.abs()), "{fd} vs {an}");
        }
    }
}
