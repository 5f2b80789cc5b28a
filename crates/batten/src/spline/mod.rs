//! Spline representations and their constructors.
//!
//! - [`ParametricCubic`]: the C² cubic interpolating spline through planar points;
//! - [`KnotVector`] and [`BSplineCurve`]: B-spline / NURBS curves of any degree.
//!
//! Nothing here knows about fairing.

mod bspline;
mod interpolate;
mod knots;
mod parametric;

pub use bspline::{BSplineCurve, MAX_ORDER};
pub use knots::KnotVector;
pub use parametric::{EndCondition, ParametricCubic, Parametrization, parameters};
