//! Measurements of curves: signed curvature and its arc-length derivative, radius of
//! curvature, arc length, energies, inflections, curvature extrema, curvature-comb samples,
//! Calì's fairness indicators, the [`FairnessMetrics`] every report carries, and Kuragano &
//! Yamaguchi's radius-of-curvature fairness evaluation ([`roc_fairness`]).
//!
//! Everything is generic over the capability traits in [`crate::curve`].

mod arclength;
mod curvature;
mod gfi;
mod metrics;
mod noise;
pub mod roc_fairness;
mod space;
mod space_curve;

pub use arclength::{ArcLengthTable, arc_length};
pub use curvature::{
    CombSample, curvature_at, curvature_comb, curvature_derivative, radius_of_curvature,
    signed_curvature, strain_energy, variation_energy,
};
pub use gfi::{FairnessIndicators, fairness_indicators};
pub use metrics::{
    Displacement, FairnessMetrics, ZERO_REL, analysis_curve, count_sign_changes, displacement, sgn0,
};
pub(crate) use noise::is_planar;
pub use noise::{MAD_TO_SIGMA, MEDIAN_LENGTH_2D_TO_SIGMA, noise_sigma, noise_sigma_space};
pub use space::SpaceMetrics;
pub use space_curve::{SpaceCubic, SpaceDerivatives, SpaceSample};
