//! Arc length by Gauss–Legendre quadrature per span, and its inverse (docs/algorithms/README.md
//! §0.5).

use crate::curve::{CurveDeriv, Piecewise};
use crate::numeric::GaussLegendre;
use crate::spline::break_span;

/// Total arc length of a piecewise curve.
pub fn arc_length<C: CurveDeriv + Piecewise + ?Sized>(curve: &C) -> f64 {
    super::curvature::integrate_spans(curve, |d| d.d1.length())
}

/// Cumulative arc length at the breakpoints of a curve, for `s(t)` and its inverse `t(s)`.
#[derive(Clone, Debug)]
pub struct ArcLengthTable {
    breaks: Vec<f64>,
    cumulative: Vec<f64>,
    gl: GaussLegendre,
}

/// Newton iterations allowed when inverting `s(t)` inside one span.
const NEWTON_MAX: usize = 50;
/// Relative accuracy of `t(s)` against the span width.
const NEWTON_REL: f64 = 1e-14;
/// Newton also stops when its step is below this many ulps of t: far from 0, one ulp of t
/// exceeds `NEWTON_REL` of a span.
const PARAM_ULPS: f64 = 4.0;

impl ArcLengthTable {
    /// Build the table for `curve`.
    pub fn new<C: CurveDeriv + Piecewise + ?Sized>(curve: &C) -> ArcLengthTable {
        let gl = GaussLegendre::default();
        let breaks = curve.breakpoints();
        let mut cumulative = Vec::with_capacity(breaks.len());
        let mut s = 0.0;
        cumulative.push(0.0);
        for w in breaks.windows(2) {
            s += gl.integrate(w[0], w[1], |t| curve.derivatives(t).d1.length());
            cumulative.push(s);
        }
        ArcLengthTable {
            breaks,
            cumulative,
            gl,
        }
    }

    /// Total length.
    pub fn total(&self) -> f64 {
        self.cumulative.last().copied().unwrap_or(0.0)
    }

    fn span_of_t(&self, t: f64) -> usize {
        break_span(&self.breaks, t)
    }

    /// Arc length from the start of the domain to parameter `t`.
    pub fn s_at<C: CurveDeriv + Piecewise + ?Sized>(&self, curve: &C, t: f64) -> f64 {
        if self.breaks.len() < 2 {
            return 0.0;
        }
        let i = self.span_of_t(t);
        self.cumulative[i]
            + self
                .gl
                .integrate(self.breaks[i], t, |x| curve.derivatives(x).d1.length())
    }

    /// The parameter at arc length `s` (clamped to `[0, total]`), by Newton's method on
    /// `s(t) − s*` inside the bracketing span, safeguarded by bisection.
    pub fn t_at<C: CurveDeriv + Piecewise + ?Sized>(&self, curve: &C, s: f64) -> f64 {
        let n = self.breaks.len();
        if n < 2 {
            return self.breaks.first().copied().unwrap_or(0.0);
        }
        let s = s.clamp(0.0, self.total());
        let i = match self.cumulative.binary_search_by(|c| c.total_cmp(&s)) {
            Ok(i) => return self.breaks[i],
            Err(i) => i.saturating_sub(1).min(n - 2),
        };
        let (mut lo, mut hi) = (self.breaks[i], self.breaks[i + 1]);
        let target = s - self.cumulative[i];
        let span_len = self.cumulative[i + 1] - self.cumulative[i];
        let mut t = lo
            + (hi - lo)
                * if span_len > 0.0 {
                    target / span_len
                } else {
                    0.5
                };
        for _ in 0..NEWTON_MAX {
            let f = self
                .gl
                .integrate(self.breaks[i], t, |x| curve.derivatives(x).d1.length())
                - target;
            if f > 0.0 {
                hi = t;
            } else {
                lo = t;
            }
            let speed = curve.derivatives(t).d1.length();
            let step = if speed > 0.0 {
                f / speed
            } else {
                f64::INFINITY
            };
            // Converged: test before the bracket, which the root may have become (the Newton
            // point then falls on it and bisection would take over), at what t can resolve.
            let resolution = NEWTON_REL * (self.breaks[i + 1] - self.breaks[i])
                + PARAM_ULPS * f64::EPSILON * t.abs();
            if step.abs() <= resolution {
                return (t - step).clamp(self.breaks[i], self.breaks[i + 1]);
            }
            let mut next = t - step;
            if !(next > lo && next < hi) {
                next = 0.5 * (lo + hi);
            }
            if (next - t).abs() <= NEWTON_REL * (self.breaks[i + 1] - self.breaks[i]) {
                return next;
            }
            t = next;
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::spline::{ParametricCubic, Parametrization};

    #[test]
    fn circle_length_and_inverse() {
        let r = 3.0;
        let n = 64;
        let pts: Vec<Point> = (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                Point::new(r * a.cos(), r * a.sin())
            })
            .collect();
        let c = ParametricCubic::closed(&pts, Parametrization::ChordLength).unwrap();
        let len = arc_length(&c);
        assert!((len - std::f64::consts::TAU * r).abs() < 1e-5, "{len}");
        let table = ArcLengthTable::new(&c);
        assert!((table.total() - len).abs() < 1e-12);
        for s in [0.0, 1.0, 7.5, 15.0, len] {
            let t = table.t_at(&c, s);
            assert!((table.s_at(&c, t) - s).abs() < 1e-9, "{s}");
        }
    }
}
