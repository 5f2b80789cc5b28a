//! The periodic (closed) cubic B-spline through a closed point list, in the wrapped form the
//! control-point methods work on: `sapidis-farin` (knot removal and reinsertion) and
//! `eck-hadenfeld` (local energy) fair closed curves on it
//! (`docs/algorithms/cali.md`, "Baseline: `sapidis-farin`"; `docs/algorithms/salvi-varady.md`,
//! "Eck & Hadenfeld, the baseline").

use crate::error::{Error, Result};
use crate::geom::{Point, Vec2};
use crate::numeric::solve_cyclic_tridiagonal;
use crate::spline::{BSplineCurve, KnotVector, MAX_ORDER, Parametrization};

/// The degree of the periodic interpolant: cubic.
const DEGREE: usize = 3;

/// Padding of the wrapped form of a periodic cubic: period knot `τ_m` is knot index
/// `m + PAD`, so that every period knot is a simple interior knot with the whole Farin
/// stencil (control points `j−4..=j`, knots `j−3..=j+3`) inside the wrapped curve.
pub(crate) const PAD: usize = 4;

/// What wrapped index `r` (of a control point or a knot) stands for in one period: `D_d` or
/// `τ_d` with `d = (r − PAD) mod n`.
pub(crate) fn period_index(r: usize, n: usize) -> usize {
    (r + n - PAD % n) % n
}

/// The periodic (closed) cubic B-spline through `points` with chord-length parameters and
/// knots at the data parameters, in a wrapped form: a [`BSplineCurve`] with `N + 4` control
/// points `W_r = D_{(r−4) mod N}` (the last four repeat the first four) and knots
/// `u_r = τ_{r−4}`, where `τ_k = t_{k mod N} + L·⌊k/N⌋` is the periodic extension of the
/// parameters `t_0 = 0 < … < t_{N−1} < L`. Its domain `[τ_{−1}, τ_N]` covers one period.
/// Returns the curve, the data parameters `t_k` and N.
///
/// # Errors
/// [`Error::TooFewPoints`] below [`MIN_CLOSED_POINTS`]; duplicate or non-finite points; a
/// singular interpolation system.
pub(crate) fn interpolate_closed(points: &[Point]) -> Result<(BSplineCurve, Vec<f64>)> {
    let n = points.len();
    if n < MIN_CLOSED_POINTS {
        return Err(Error::TooFewPoints {
            needed: MIN_CLOSED_POINTS,
            got: n,
        });
    }
    let t = crate::spline::parameters(points, Parametrization::ChordLength, true)?;
    let period = t[n];
    let tau = |k: isize| {
        let q = k.div_euclid(n as isize);
        let r = k.rem_euclid(n as isize) as usize;
        t[r] + period * q as f64
    };
    let knots: Vec<f64> = (0..n + PAD + 4)
        .map(|r| tau(r as isize - PAD as isize))
        .collect();
    let knots = KnotVector::try_new(knots)?;
    // Row k: N_{k−3}(τ_k) D_{k−3} + N_{k−2}(τ_k) D_{k−2} + N_{k−1}(τ_k) D_{k−1} = Q_k, in the
    // unknowns x_i = D_{i−2} (cyclic tridiagonal).
    let shape = BSplineCurve::try_new(DEGREE, knots.clone(), vec![Point::ORIGIN; n + PAD], None)?;
    let (mut sub, mut diag, mut sup) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut b = [[0.0; MAX_ORDER]; 4];
    for k in 0..n {
        let span = k + PAD;
        shape.basis_derivs(span, t[k], 0, &mut b);
        sub[k] = b[0][0];
        diag[k] = b[0][1];
        sup[k] = b[0][2];
    }
    let mut x: Vec<Vec2> = points.iter().map(|p| p.to_vec2()).collect();
    solve_cyclic_tridiagonal(&sub, &diag, &sup, &mut x)?;
    // x_i = D_{i−2}, so D_d = x_{(d+2) mod N} and W_r = D_{(r−4) mod N} = x_{(r−2) mod N}.
    let ctrl: Vec<Point> = (0..n + PAD)
        .map(|r| x[(r + n - 2) % n].to_point())
        .collect();
    let curve = BSplineCurve::try_new(DEGREE, knots, ctrl, None)?;
    Ok((curve, t[..n].to_vec()))
}

/// Fewest points of a closed curve for `sapidis-farin`: the support of a basis function
/// (four spans) must be shorter than the period.
pub(super) const MIN_CLOSED_POINTS: usize = 6;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::curve::{Curve, CurveDeriv};

    #[test]
    fn closed_interpolant_passes_through_the_points_and_is_periodic() {
        let n = 11;
        let pts: Vec<Point> = (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64 + 0.05 * (i % 3) as f64;
                Point::new(2.0 * a.cos(), a.sin() + 0.1 * (2.0 * a).cos())
            })
            .collect();
        let (curve, t) = interpolate_closed(&pts).unwrap();
        assert_eq!(curve.control_points().len(), n + PAD);
        for (k, &tk) in t.iter().enumerate() {
            assert!(curve.eval(tk).distance(pts[k]) < 1e-12, "point {k}");
        }
        // One period on (τ_N = L, the domain end): the same point and derivatives, since
        // the copies of the control points are consistent.
        let period = curve.knots().as_slice()[n + PAD];
        let a = curve.derivatives(t[0]);
        let b = curve.derivatives_left(period);
        assert!((a.point - b.point).length() < 1e-12);
        assert!((a.d1 - b.d1).length() < 1e-9);
        assert!((a.d2 - b.d2).length() < 1e-9);
        // C² everywhere: no jump of the second derivative at any period knot.
        for k in 1..n {
            let (l, r) = (curve.derivatives_left(t[k]), curve.derivatives(t[k]));
            assert!((l.d2 - r.d2).length() < 1e-9, "knot {k}");
        }
    }
}
