//! Capability traits for parametric planar curves, one small trait per capability (in the
//! manner of kurbo's `ParamCurve` family). Analysis code is generic over these traits and never
//! matches on concrete spline types.

use crate::geom::{Point, Vec2};

/// Position and the first three derivatives of a curve at one parameter value.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Derivatives {
    /// The position r(t).
    pub point: Point,
    /// r'(t).
    pub d1: Vec2,
    /// r''(t).
    pub d2: Vec2,
    /// r'''(t); zero for curves of degree below three.
    pub d3: Vec2,
}

/// A curve `r(t)` on a closed parameter interval.
pub trait Curve {
    /// The parameter interval `[t_min, t_max]`.
    fn domain(&self) -> (f64, f64);

    /// The point at parameter `t`. Parameters outside the domain are clamped or extrapolated,
    /// as the implementation documents.
    fn eval(&self, t: f64) -> Point;
}

/// A curve whose first three derivatives can be evaluated.
///
/// At a breakpoint where a derivative jumps, implementations return the right-hand limit,
/// except at the end of the domain where they return the left-hand one.
pub trait CurveDeriv: Curve {
    /// Position and derivatives at `t`.
    fn derivatives(&self, t: f64) -> Derivatives;

    /// Position and derivatives at `t` as limits from the left (`t − 0`). The default is the
    /// same as [`CurveDeriv::derivatives`], which is right for curves that are smooth at `t`.
    fn derivatives_left(&self, t: f64) -> Derivatives {
        self.derivatives(t)
    }
}

/// A piecewise-polynomial curve: smooth between consecutive breakpoints.
pub trait Piecewise: Curve {
    /// The distinct breakpoints in increasing order, including both ends of the domain.
    /// Quadrature and sampling are done span by span between them.
    fn breakpoints(&self) -> Vec<f64>;
}
