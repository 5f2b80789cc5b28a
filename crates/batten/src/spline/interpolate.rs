//! Global B-spline interpolation through points (docs/algorithms/cali.md §4.3: chord-length
//! parameters normalised to [0, 1], averaging knots, clamped ends; Piegl & Tiller §9.2.1).

use super::{BSplineCurve, KnotVector, MAX_ORDER, Parametrization, basis_derivs, parameters};
use crate::error::{Error, Result};
use crate::geom::Point;
use crate::numeric::BandLu;

impl BSplineCurve {
    /// The clamped degree-`p` B-spline through `points`, with parameters of the given kind
    /// normalised to [0, 1] and averaging knots `u_{j+p} = (t_j + … + t_{j+p−1})/p`,
    /// j = 1..n−p. Returns the curve and the data parameters `t_k` (`C(t_k) = Q_k`).
    ///
    /// # Errors
    /// [`Error::TooFewPoints`] for fewer than `p + 1` points, [`Error::InvalidParameter`] for
    /// a degree outside 1..=7, the errors of [`parameters`] (zero chords, NaN), and
    /// [`Error::Singular`].
    pub fn interpolate(
        points: &[Point],
        degree: usize,
        param: Parametrization,
    ) -> Result<(BSplineCurve, Vec<f64>)> {
        let p = degree;
        if p == 0 || p >= MAX_ORDER {
            return Err(Error::InvalidParameter {
                name: "degree".into(),
                reason: format!("must be in 1..={}", MAX_ORDER - 1),
            });
        }
        let n = points.len();
        if n < p + 1 {
            return Err(Error::TooFewPoints {
                needed: p + 1,
                got: n,
            });
        }
        let t = parameters(points, param, false)?;
        BSplineCurve::interpolate_at_parameters(points, p, t)
    }

    /// [`BSplineCurve::interpolate`] with the parameters of the points already computed
    /// (`parameters(points, param, false)`, not yet normalised; the analysis curve of the
    /// metrics has them): the same curve and parameters.
    ///
    /// # Errors
    /// As [`BSplineCurve::interpolate`], less those of [`parameters`].
    pub(crate) fn interpolate_at_parameters(
        points: &[Point],
        degree: usize,
        mut t: Vec<f64>,
    ) -> Result<(BSplineCurve, Vec<f64>)> {
        let p = degree;
        let n = points.len();
        if p == 0 || p >= MAX_ORDER {
            return Err(Error::InvalidParameter {
                name: "degree".into(),
                reason: format!("must be in 1..={}", MAX_ORDER - 1),
            });
        }
        if n < p + 1 {
            return Err(Error::TooFewPoints {
                needed: p + 1,
                got: n,
            });
        }
        if t.len() != n {
            return Err(Error::LengthMismatch {
                what: "parameters",
                got: t.len(),
                expected: n,
            });
        }
        let total = t[n - 1];
        for v in &mut t {
            *v /= total;
        }
        t[n - 1] = 1.0;
        let mut knots = vec![0.0; p + 1];
        for j in 1..n - p {
            knots.push(t[j..j + p].iter().sum::<f64>() / p as f64);
        }
        knots.extend(std::iter::repeat_n(1.0, p + 1));
        let knots = KnotVector::try_new(knots)?;
        // The collocation matrix from the knots alone (no provisional curve, no copy of the
        // points), the data parameters swept in order; the curve is built once at the end,
        // which validates it as before.
        let mut a = BandLu::zeros(n, p, p);
        let mut b = [[0.0; MAX_ORDER]; 4];
        let mut span = p;
        for (row, &tk) in t.iter().enumerate() {
            span = knots.find_span_from(p, n, tk, span);
            basis_derivs(knots.as_slice(), p, span, tk, 0, &mut b);
            for j in 0..=p {
                let col = span - p + j;
                if col.abs_diff(row) <= p {
                    a.set(row, col, b[0][j]);
                } else if b[0][j] != 0.0 {
                    return Err(Error::Singular(
                        "collocation matrix outside its band".into(),
                    ));
                }
            }
        }
        a.factorize()?;
        let mut rhs: Vec<_> = points.iter().map(|q| q.to_vec2()).collect();
        a.solve_in_place(&mut rhs)?;
        drop(a);
        let ctrl = rhs.into_iter().map(|v| v.to_point()).collect();
        let curve = BSplineCurve::try_new(p, knots, ctrl, None)?;
        Ok((curve, t))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::curve::Curve;

    #[test]
    fn interpolates_through_points() {
        let pts: Vec<Point> = (0..12)
            .map(|i| Point::new(i as f64 * 0.5, (i as f64 * 0.4).sin()))
            .collect();
        for p in 1..=5 {
            let (c, t) = BSplineCurve::interpolate(&pts, p, Parametrization::ChordLength).unwrap();
            for (tk, q) in t.iter().zip(&pts) {
                assert!((c.eval(*tk) - *q).length() < 1e-12, "degree {p}");
            }
        }
    }
}
