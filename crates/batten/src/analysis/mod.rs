//! Measurements of curves: signed curvature and its arc-length derivative, radius of
//! curvature, arc length, energies, inflections, curvature extrema, curvature-comb samples,
//! Calì's fairness indicators, the [`FairnessMetrics`] every report carries, and Kuragano &
//! Yamaguchi's radius-of-curvature fairness evaluation ([`evaluate_roc_fairness`]).
//!
//! Everything is generic over the capability traits in [`crate::curve`]. The files below are
//! private modules; this namespace re-exports, by name:
//!
//! - curvature and arc length: [`signed_curvature`], [`curvature_at`],
//!   [`curvature_derivative`], [`radius_of_curvature`], [`curvature_comb`] ([`CombSample`]),
//!   [`strain_energy`], [`variation_energy`], [`arc_length`], [`ArcLengthTable`];
//! - fairness measures: [`FairnessMetrics`] (on [`analysis_curve`], with [`ZERO_REL`],
//!   [`count_sign_changes`] and [`sgn0`] for its sign tests), [`displacement`]
//!   ([`Displacement`]), Calì's [`fairness_indicators`] ([`FairnessIndicators`]), the noise
//!   estimates [`noise_sigma`] and [`noise_sigma_space`], and [`difference_correlation`], which
//!   tells noise from a clean curve's own differences;
//! - space curves: [`SpaceCubic`], [`SpaceSample`], [`SpaceDerivatives`], [`SpaceMetrics`];
//! - Kuragano & Yamaguchi's evaluation (which polynomial ρ(s) a curve follows best, paper
//!   §4–§5, `batten evaluate`): [`evaluate_roc_fairness`] of a [`RocDesign`] under
//!   [`KuraganoOptions`] ([`DesignEnds`], [`RhoResidual`]) gives a [`RocEvaluation`], one
//!   [`DegreeResult`] per degree, with ties within [`ROC_TIE_TOLERANCE`]; [`angle_degrees`]
//!   and [`truncate_angle`] read a cosine as the paper prints it. Its formulas, choices and
//!   departures from the paper are in `docs/algorithms/kuragano.md`; the fairing method that
//!   applies the same shape modification is [`crate::fair::Kuragano`].

mod arclength;
mod curvature;
mod gfi;
mod metrics;
mod noise;
// `fair::kuragano` runs the same specification and shape modification.
pub(crate) mod roc_fairness;
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
pub use noise::{
    MAD_TO_SIGMA, MEDIAN_LENGTH_2D_TO_SIGMA, difference_correlation, noise_sigma, noise_sigma_space,
};
pub(crate) use noise::{NoiseMeasure, Spread, is_planar};
pub use roc_fairness::{
    DEFAULT_METHOD_GRADIENT_FRACTION, DegreeResult, Design as RocDesign, DesignEnds,
    Evaluation as RocEvaluation, KuraganoOptions, MAX_SAMPLES as ROC_MAX_SAMPLES,
    Residual as RhoResidual, TIE_TOLERANCE as ROC_TIE_TOLERANCE, angle_degrees,
    evaluate as evaluate_roc_fairness, truncate_angle,
};
pub use space::SpaceMetrics;
pub use space_curve::{SpaceCubic, SpaceDerivatives, SpaceSample};
