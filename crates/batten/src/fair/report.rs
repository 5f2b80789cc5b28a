use serde::Serialize;

use super::EndFix;
use crate::analysis::FairnessMetrics;

/// How a fairing run ended (after OCCT's `FairCurve_AnalysisCode`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum FairStatus {
    /// The method's stopping rule was met.
    #[default]
    Converged,
    /// The iteration limit stopped it before its stopping rule was met.
    IterationLimit,
    /// Moves were cut short to respect the tolerance; the curve may be less fair than
    /// the method would make it without the bound.
    ToleranceLimited,
    /// The result exceeds the tolerance (the method could not meet it).
    ToleranceExceeded,
    /// Rounding stopped the solver's progress before its stopping rule was met: the result
    /// meets the tolerance but may not be the optimum (a note gives how far it was).
    Stalled,
    /// Nothing changed: the input is already fair by the method's criterion, or the
    /// clean-curve guard returned the input because the result was worse (a note says so).
    NoChange,
}

impl FairStatus {
    /// The name the report uses (`converged`, `iteration_limit`, …).
    pub fn as_str(self) -> &'static str {
        match self {
            FairStatus::Converged => "converged",
            FairStatus::IterationLimit => "iteration_limit",
            FairStatus::ToleranceLimited => "tolerance_limited",
            FairStatus::ToleranceExceeded => "tolerance_exceeded",
            FairStatus::Stalled => "stalled",
            FairStatus::NoChange => "no_change",
        }
    }
}

impl std::fmt::Display for FairStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Where a run's tolerance came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum ToleranceSource {
    /// Given by the caller (`--tolerance D`).
    Given,
    /// Computed from the data as `k·σ̂` (`--tolerance auto`, or `band` without a tolerance).
    Auto,
}

/// What an optimisation-based method's solver did (`band`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
#[non_exhaustive]
pub struct SolverInfo {
    /// Interior-point iterations, over all passes.
    pub iterations: usize,
    /// The final surrogate duality gap, relative to the objective (or to 1).
    pub duality_gap: f64,
    /// Points whose displacement is within 0.01 % of the tolerance: where the band, not
    /// the energy, decided.
    pub points_on_band_edge: usize,
}

/// One point move of a local method.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Move {
    /// Iteration number (1-based) of the move.
    pub iteration: usize,
    /// Index (0-based) of the point or control point moved.
    pub index: usize,
    /// Length of the move.
    pub distance: f64,
    /// The method's local badness measure before the move (e.g. third-derivative jump).
    pub before: f64,
    /// The same measure after the move.
    pub after: f64,
}

/// One row of a per-iteration trace: the method's measure and the largest distance so far.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct HistoryRow {
    /// Iteration number.
    pub iteration: usize,
    /// The method's own fairness measure (energy, GFI, Ê, …) after this iteration.
    pub measure: f64,
    /// Largest displacement from the input so far.
    pub max_distance: f64,
}

/// The change at the two ends of an open curve, measured on the points: the discrete end
/// tangent is the direction of the end chord and the discrete end curvature that of the
/// circle through the three end points. Methods that move points keep both exactly with
/// `--fix-ends=curvature` (zero here); methods that move B-spline control points keep the
/// curve's end tangent and curvature exactly, and the data points next to the ends may then
/// move a little, which shows here.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct EndChanges {
    /// Angle between the old and the new end chord, in radians, at the start and the end.
    pub tangent_angle: [f64; 2],
    /// New minus old signed curvature of the circle through the three end points, at the
    /// start and the end.
    pub curvature: [f64; 2],
}

/// What a fairing run did. Serialised as the `--report` JSON.
#[derive(Clone, Debug, Serialize)]
#[non_exhaustive]
pub struct FairReport {
    /// Method name.
    pub method: String,
    /// How it ended.
    pub status: FairStatus,
    /// Iterations performed (the method's unit).
    pub iterations: usize,
    /// Indices (0-based) of the points whose position changed, increasing.
    pub moved_points: Vec<usize>,
    /// The individual moves in order, for local methods.
    pub moves: Vec<Move>,
    /// Largest point displacement.
    pub max_displacement: f64,
    /// Index of the point with the largest displacement.
    pub max_displacement_index: usize,
    /// Sum of point displacements (HAN's S_d).
    pub sum_displacement: f64,
    /// The tolerance used, if any: the one given, or the automatic `k·σ̂`.
    pub tolerance: Option<f64>,
    /// Where the tolerance came from: `given`, `auto` (`k·σ̂`), or `null` when there is none.
    pub tolerance_source: Option<ToleranceSource>,
    /// The noise estimate σ̂ of the input points, in data units
    /// ([`crate::analysis::noise_sigma`]; `null` for B-spline input).
    pub noise_sigma: Option<f64>,
    /// True when no point moved farther than the tolerance (always true without one).
    pub tolerance_met: bool,
    /// Whether the end points were fixed.
    pub fix_ends: bool,
    /// What was kept at the ends ([`EndFix`]): `free`, `position`, `tangent` or `curvature`.
    pub fixed_ends: EndFix,
    /// How the discrete tangent and curvature at the two ends changed ([`EndChanges`]; open
    /// curves of three or more points, `null` otherwise).
    pub end_changes: Option<EndChanges>,
    /// Metrics of the input.
    pub before: FairnessMetrics,
    /// Metrics of the result.
    pub after: FairnessMetrics,
    /// Wall-clock time of the method itself, in seconds.
    pub elapsed_seconds: f64,
    /// Parameters as used.
    pub parameters: serde_json::Map<String, serde_json::Value>,
    /// Per-iteration trace.
    pub history: Vec<HistoryRow>,
    /// The solver's figures, for methods that solve an optimisation problem (`band`).
    pub solver: Option<SolverInfo>,
    /// Remarks for the user.
    pub notes: Vec<String>,
}

#[cfg(test)]
mod tests {
    use super::FairStatus;

    /// The displayed names are the report's.
    #[test]
    fn status_names_are_the_serialised_ones() {
        for s in [
            FairStatus::Converged,
            FairStatus::IterationLimit,
            FairStatus::ToleranceLimited,
            FairStatus::ToleranceExceeded,
            FairStatus::Stalled,
            FairStatus::NoChange,
        ] {
            assert_eq!(
                serde_json::to_value(s).unwrap(),
                serde_json::Value::from(s.to_string())
            );
        }
    }
}
