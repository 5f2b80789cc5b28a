//! B-spline surfaces: representation, interrogation and fairing.
//!
//! - [`BSplineSurface`]: a tensor-product B-spline or NURBS surface of any degrees on clamped
//!   knots, with partial derivatives up to second order, the normal, the fundamental forms and
//!   the principal, Gaussian and mean curvatures (spec §0.6, κ1 ≥ κ2, signs following
//!   `S_u × S_v`).
//! - [`interpolate_grid`]: the bicubic through a regular grid of points (scanned patches).

mod fit;
mod patch;

pub use fit::{GRID_FIT_DEGREE, interpolate_grid};
pub use patch::{BSplineSurface, FundamentalForms, SurfaceCurvature, SurfaceDerivs, Xyz};
