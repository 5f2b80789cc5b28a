//! B-spline surfaces: representation, interrogation and fairing.
//!
//! - [`BSplineSurface`]: a tensor-product B-spline or NURBS surface of any degrees on clamped
//!   knots, with partial derivatives up to second order, the normal, the fundamental forms and
//!   the principal, Gaussian and mean curvatures (docs/algorithms/README.md §0.6, κ1 ≥ κ2, signs
//!   following `S_u × S_v`).
//! - [`interpolate_grid`]: the bicubic through a regular grid of points (scanned patches).
//! - [`analyze_surface`]: curvature ranges, umbilics and the fairness measure Π̂ on the
//!   documented grid of [`SampleGrid::for_surface`]; [`Targets`]: the smooth target
//!   curvatures g1, g2 of Salvi & Várady (eqs 16–17).
//! - [`fair_surface`]: fairing within a hard tolerance on `|S_faired(u, v) − S(u, v)|`, by
//!   [`SurfaceMethod::Salvi`] (target principal curvatures, one control point at a time by
//!   3-D Nelder–Mead) or [`SurfaceMethod::EckHadenfeld`] (the closed-form local minimiser of
//!   the thin-plate energy), with the boundary rows optionally held ([`BoundaryFix`]).
//! - [`render`]: pictures for interrogation — curvature colour maps, isophotes, zebra
//!   stripes and the deviation between two surfaces — rasterised from a [`SurfaceMesh`] in an
//!   orthographic [`Camera`] view into an RGBA [`Raster`].

mod eck_hadenfeld;
mod fairing;
mod fit;
mod patch;
mod render;
mod salvi;
mod sample;
mod target;

pub use fairing::{
    BoundaryFix, DEVIATION_MIN_SAMPLES, DEVIATION_SAMPLES_PER_SPAN, SurfaceFairOptions,
    SurfaceFairReport, SurfaceMeasures, SurfaceMethod, deviation_grid, fair_surface, max_deviation,
};
pub use fit::{GRID_FIT_DEGREE, interpolate_grid};
pub use patch::{BSplineSurface, FundamentalForms, SurfaceCurvature, SurfaceDerivs, Xyz};
pub use render::{
    BACKGROUND_RGB, Camera, Field, MAP_SHADE_FLOOR, MESH_MIN_SAMPLES, MESH_SAMPLES_PER_SPAN,
    Palette, Raster, SINGULAR_RGB, Shading, SurfaceMesh, isophote_range, render, zebra_range,
};
pub use sample::{
    MIN_SAMPLES, MinMax, SAMPLES_PER_SPAN, SampleGrid, SurfaceAnalysis, UMBILIC_REL,
    analyze_surface, sample_curvature,
};
pub use target::{DEFAULT_ROBUST_PASSES, DEFAULT_SMOOTHING, TARGET_DEGREE, TargetParams, Targets};
