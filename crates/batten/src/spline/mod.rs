//! Spline representations and their constructors.
//!
//! - [`ParametricCubic`]: the C² cubic interpolating spline through planar points;
//! - [`CubicSplineFn`]: the cubic spline *function* y(x) of HAN (docs/algorithms/han.md §1.2), end
//!   conditions [`FnEndCondition`];
//! - [`KnotVector`] and [`BSplineCurve`]: B-spline / NURBS curves of any degree, with knot
//!   insertion and removal ([`KnotRemoval`], [`RemovalRule`], [`KnotRef`]);
//! - [`LambdaOperator`]: the λ-operator of Calì et al.;
//! - the uniform quintic of Kuragano & Yamaguchi: [`interpolate_quintic`] (ends
//!   [`QuinticEnds`], end gradients from [`quintic_end_gradients`]),
//!   [`interpolate_quintic_hermite`], as a B-spline or NURBS ([`QuinticForm`]).
//!
//! The files below are private modules; everything public is re-exported here by name.
//! Nothing here knows about fairing.

mod bspline;
mod bspline_ops;
mod function;
mod interpolate;
mod knots;
mod lambda_operator;
mod parametric;
// The radius-of-curvature analysis samples the quintic in closed form.
pub(crate) mod quintic;

pub use bspline::{BSplineCurve, MAX_ORDER};
pub(crate) use bspline::{basis_derivs, cubic_basis};
pub use bspline_ops::{DEVIATION_SAMPLES_PER_SPAN, KnotRef, KnotRemoval, RemovalRule};
pub use function::{CubicSplineFn, FnEndCondition};
pub use knots::KnotVector;
pub(crate) use knots::break_span;
pub use lambda_operator::{LOCAL_HALF_WIDTH, LOCAL_WIDTH, LambdaOperator};
pub use parametric::{EndCondition, ParametricCubic, Parametrization, parameters};
pub(crate) use parametric::{
    Ends, c2_closed_tangents, c2_tangents, hermite_coeffs, open_tangents, periodic_tangents,
    span_derivatives,
};
pub use quintic::{
    DEFAULT_GRADIENT_FRACTION as QUINTIC_GRADIENT_FRACTION, Ends as QuinticEnds,
    HermiteSystem as QuinticHermiteSystem, QuinticForm, end_gradients as quintic_end_gradients,
    interpolate as interpolate_quintic, interpolate_hermite as interpolate_quintic_hermite,
};
