//! The surface fairing contract: [`SurfaceFairOptions`] in, a faired [`BSplineSurface`] and a
//! [`SurfaceFairReport`] out, for the methods of [`SurfaceMethod`].
//!
//! [`fair_surface`] validates the options, measures the input (curvature ranges and Π̂ on
//! [`SampleGrid::for_surface`], the thin-plate energy), runs the method, then measures the
//! result and checks the tolerance **independently of the method** on a dense parameter grid
//! ([`deviation_grid`]): `max_displacement = max |S_faired(u, v) − S(u, v)|` at the same
//! parameters. Both methods keep every control point within δ of its original position (the
//! eq-11 clamp in 3-D), which by the convex-hull property and the partition of unity keeps
//! the surface within δ everywhere; the dense check confirms it.
//!
//! Knots, degrees and weights are kept; only control points move.

use std::collections::BTreeMap;
use std::time::Instant;

use serde::Serialize;

use super::patch::{BSplineSurface, Xyz, distance};
use super::sample::{MinMax, SampleGrid, sample_curvature, summarize};
use super::target::{TargetParams, Targets};
use super::{eck_hadenfeld, salvi};
use crate::error::{Error, Result};
use crate::fair::FairStatus;
use crate::fair::local::{DEFAULT_TABU_LENGTH, DEFAULT_TOLERANCE_REL, ROUNDING_MARGIN_ULPS};
use crate::fair::params::{Auto, Number, Param};

/// Samples per knot span of the dense tolerance check, per direction.
pub const DEVIATION_SAMPLES_PER_SPAN: usize = 10;

/// The fewest samples per direction of the dense tolerance check.
pub const DEVIATION_MIN_SAMPLES: usize = 51;

/// The surface fairing methods.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SurfaceMethod {
    /// Salvi & Várady's target-curvature fairing (`surface/salvi.rs`).
    Salvi,
    /// Eck & Hadenfeld's local thin-plate energy fairing (`surface/eck_hadenfeld.rs`).
    EckHadenfeld,
}

impl SurfaceMethod {
    /// Every method, the default first.
    pub const ALL: [SurfaceMethod; 2] = [SurfaceMethod::Salvi, SurfaceMethod::EckHadenfeld];

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SurfaceMethod::Salvi => "salvi",
            SurfaceMethod::EckHadenfeld => "eck-hadenfeld",
        }
    }

    /// The method called `name`.
    ///
    /// # Errors
    /// [`Error::UnknownMethod`].
    pub fn from_name(name: &str) -> Result<SurfaceMethod> {
        SurfaceMethod::ALL
            .into_iter()
            .find(|m| m.name() == name)
            .ok_or_else(|| Error::UnknownMethod {
                name: name.into(),
                known: "salvi, eck-hadenfeld".into(),
            })
    }

    /// The `--set` keys the method accepts.
    pub fn keys(self) -> &'static [&'static str] {
        match self {
            SurfaceMethod::Salvi => &[
                SAMPLES.name,
                TARGET_SPANS.name,
                SMOOTHING.name,
                ROBUST_PASSES.name,
                TABU.name,
                SIMPLEX_EVALUATIONS.name,
            ],
            SurfaceMethod::EckHadenfeld => &[TABU.name],
        }
    }
}

/// `tabu` (both methods): the length of the recently-moved list.
const TABU: Param<Auto<usize>> = Param {
    name: "tabu",
    kind: Auto {
        min: 0,
        max: 100_000,
    },
    doc: "length of the recently-moved list; auto = max((p + 1)(q + 1), 4), the control points acting on one knot span; 0..=100000",
};
/// `samples_per_span` (`salvi`): curvature samples per knot span and direction.
const SAMPLES: Param<Number<usize>> = Param {
    name: "samples_per_span",
    kind: Number {
        default: super::sample::SAMPLES_PER_SPAN,
        min: 1,
        max: 64,
    },
    doc: "curvature samples per knot span in each direction; 1..=64",
};
/// `target_spans` (`salvi`): knot spans of the target surface in each direction.
const TARGET_SPANS: Param<Auto<usize>> = Param {
    name: "target_spans",
    kind: Auto {
        min: 1,
        max: 10_000,
    },
    doc: "knot spans of the smooth target in each direction; auto = half the surface's spans, at least 2; 1..=10000",
};
/// `smoothing` (`salvi`): the target's smoothing weight.
const SMOOTHING: Param<Number<f64>> = Param {
    name: "smoothing",
    kind: Number {
        default: super::target::DEFAULT_SMOOTHING,
        min: 0.0,
        max: 1e12,
    },
    doc: "smoothing weight of the target surface's fit to the sampled curvatures; [0, 1e12]",
};
/// `robust_passes` (`salvi`): re-weighted passes of the target's fit.
const ROBUST_PASSES: Param<Number<usize>> = Param {
    name: "robust_passes",
    kind: Number {
        default: super::target::DEFAULT_ROBUST_PASSES,
        min: 0,
        max: 100,
    },
    doc: "robust re-weighting passes of the target's fit (outliers down-weighted); 0..=100",
};
/// `simplex_evaluations` (`salvi`): objective evaluations per local simplex search.
const SIMPLEX_EVALUATIONS: Param<Number<usize>> = Param {
    name: "simplex_evaluations",
    kind: Number {
        default: salvi::DEFAULT_SIMPLEX_EVALUATIONS,
        min: 4,
        max: 100_000,
    },
    doc: "objective evaluations of one control point's simplex search; 4..=100000",
};

/// Which control points along the four edges stay where they are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum BoundaryFix {
    /// Every control point may move.
    #[default]
    Free,
    /// The outer ring of control points is held: the boundary curves are kept exactly.
    Position,
    /// The two outer rings are held: the boundary curves and the cross-boundary tangents
    /// (G1 to a neighbour) are kept exactly.
    Tangent,
}

impl BoundaryFix {
    /// Rows of control points held along every edge.
    pub fn rows(self) -> usize {
        match self {
            BoundaryFix::Free => 0,
            BoundaryFix::Position => 1,
            BoundaryFix::Tangent => 2,
        }
    }
}

/// Options of [`fair_surface`].
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SurfaceFairOptions {
    /// The method.
    ///
    /// Default value: [`SurfaceMethod::Salvi`].
    pub method: SurfaceMethod,
    /// The hard bound δ on `|S_faired(u, v) − S(u, v)|`; `None` for
    /// 1 % of the diagonal of the control net's bounding box.
    ///
    /// Default value: `None`.
    pub tolerance: Option<f64>,
    /// Held boundary rows.
    ///
    /// Default value: [`BoundaryFix::Free`].
    pub fix_boundary: BoundaryFix,
    /// Most control-point moves; `None` for the method's default.
    ///
    /// Default value: `None`.
    pub max_iterations: Option<usize>,
    /// Method parameters as `key → value` text (see [`SurfaceMethod::keys`]).
    ///
    /// Default value: empty.
    pub params: BTreeMap<String, String>,
}

impl Default for SurfaceFairOptions {
    fn default() -> SurfaceFairOptions {
        SurfaceFairOptions {
            method: SurfaceMethod::Salvi,
            tolerance: None,
            fix_boundary: BoundaryFix::Free,
            max_iterations: None,
            params: BTreeMap::new(),
        }
    }
}

impl SurfaceFairOptions {
    /// Set the method.
    pub fn with_method(mut self, m: SurfaceMethod) -> SurfaceFairOptions {
        self.method = m;
        self
    }

    /// Set the tolerance.
    pub fn with_tolerance(mut self, d: f64) -> SurfaceFairOptions {
        self.tolerance = Some(d);
        self
    }

    /// Set the held boundary rows.
    pub fn with_fix_boundary(mut self, f: BoundaryFix) -> SurfaceFairOptions {
        self.fix_boundary = f;
        self
    }

    /// Set the move budget.
    pub fn with_max_iterations(mut self, n: usize) -> SurfaceFairOptions {
        self.max_iterations = Some(n);
        self
    }

    /// Set one method parameter.
    pub fn with_param(mut self, key: &str, value: &str) -> SurfaceFairOptions {
        self.params.insert(key.into(), value.into());
        self
    }

    /// Reject unknown keys and malformed values before any work.
    ///
    /// # Errors
    /// [`Error::UnknownOption`], [`Error::InvalidParameter`].
    pub fn check(&self) -> Result<()> {
        if let Some(d) = self.tolerance
            && !(d.is_finite() && d > 0.0)
        {
            return Err(Error::InvalidParameter {
                name: "tolerance".into(),
                reason: format!("{d} is not a positive number"),
            });
        }
        let keys = self.method.keys();
        for k in self.params.keys() {
            if !keys.contains(&k.as_str()) {
                return Err(Error::UnknownOption {
                    method: self.method.name().into(),
                    key: k.clone(),
                    known: keys.join(", "),
                });
            }
        }
        self.common()?;
        if self.method == SurfaceMethod::Salvi {
            self.salvi()?;
        }
        Ok(())
    }

    fn text(&self, key: &str) -> Option<&str> {
        self.params.get(key).map(String::as_str)
    }

    pub(crate) fn common(&self) -> Result<Common> {
        Ok(Common {
            tabu: TABU.read(self.text(TABU.name))?,
        })
    }

    pub(crate) fn salvi(&self) -> Result<salvi::SalviSurfaceParams> {
        Ok(salvi::SalviSurfaceParams {
            samples_per_span: SAMPLES.read(self.text(SAMPLES.name))?,
            targets: TargetParams {
                spans: TARGET_SPANS.read(self.text(TARGET_SPANS.name))?,
                smoothing: SMOOTHING.read(self.text(SMOOTHING.name))?,
                robust_passes: ROBUST_PASSES.read(self.text(ROBUST_PASSES.name))?,
            },
            simplex_evaluations: SIMPLEX_EVALUATIONS.read(self.text(SIMPLEX_EVALUATIONS.name))?,
        })
    }
}

/// Options every method reads.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Common {
    /// Length of the recently-moved list; `None` for [`tabu_length`].
    pub tabu: Option<usize>,
}

/// The default length of the recently-moved list for a surface of degrees `(p, q)`:
/// `(p + 1)(q + 1)`, the number of control points that act on one knot span. The curve
/// version's R = 4 ([`DEFAULT_TABU_LENGTH`]) is too short on a net, where a point's support
/// overlaps those of `(2p + 1)(2q + 1) − 1` neighbours: the few points around the worst
/// defect take turns for ever while their neighbours, which would have to move with them,
/// never get chosen.
pub(super) fn tabu_length(degree: (usize, usize)) -> usize {
    ((degree.0 + 1) * (degree.1 + 1)).max(DEFAULT_TABU_LENGTH)
}

/// What a method did, before the common measurements.
#[derive(Clone, Debug, Default)]
pub(crate) struct MethodRun {
    pub control: Vec<Xyz>,
    pub moves: usize,
    pub rejected: usize,
    pub status: Option<FairStatus>,
    pub history: Vec<f64>,
    pub parameters: BTreeMap<String, serde_json::Value>,
}

/// The problem handed to a method.
#[derive(Debug)]
pub(crate) struct Problem<'a> {
    pub surface: &'a BSplineSurface,
    /// δ shrunk by the rounding margin, used by the clamp.
    pub delta: f64,
    /// Which control points may move (row order).
    pub movable: Vec<bool>,
    pub max_iterations: Option<usize>,
    pub common: Common,
}

/// Measurements of one surface.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct SurfaceMeasures {
    /// Π̂ (eq 15) on the `salvi` sample grid with the targets of the *input* surface.
    pub pi_hat: f64,
    /// The thin-plate energy `∬ |S_uu|² + 2|S_uv|² + |S_vv|² du dv`.
    pub thin_plate_energy: f64,
    /// Range of κ1.
    pub kappa1: Option<MinMax>,
    /// Range of κ2.
    pub kappa2: Option<MinMax>,
    /// Range of K.
    pub gaussian: Option<MinMax>,
    /// Range of H.
    pub mean: Option<MinMax>,
}

/// What a surface fairing did (the `--report` JSON of `batten fair-surface`).
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct SurfaceFairReport {
    /// The method.
    pub method: SurfaceMethod,
    /// How the run ended.
    pub status: FairStatus,
    /// δ.
    pub tolerance: f64,
    /// Where δ came from: `"given"` or `"default"` (1 % of the control net's diagonal).
    pub tolerance_source: &'static str,
    /// `max |S_faired − S|` on the dense grid [`deviation_grid`].
    pub max_displacement: f64,
    /// `max_displacement ≤ tolerance`.
    pub tolerance_met: bool,
    /// The dense grid size the deviation was measured on.
    pub deviation_samples: [usize; 2],
    /// The largest control-point move.
    pub max_control_point_move: f64,
    /// Held boundary rows.
    pub fix_boundary: BoundaryFix,
    /// Accepted moves.
    pub moves: usize,
    /// Moves tried and refused (no decrease).
    pub rejected_moves: usize,
    /// Distinct control points moved.
    pub moved_points: usize,
    /// Measures of the input.
    pub before: SurfaceMeasures,
    /// Measures of the result.
    pub after: SurfaceMeasures,
    /// The method's objective after each accepted move (Π̂ for `salvi`, the energy for
    /// `eck-hadenfeld`).
    pub history: Vec<f64>,
    /// The parameters used, defaults filled in.
    pub parameters: BTreeMap<String, serde_json::Value>,
    /// Wall-clock time of the run, seconds.
    pub time_s: f64,
}

/// Fair `s` with `options`.
///
/// # Errors
/// [`Error::UnknownOption`] / [`Error::InvalidParameter`] for bad options,
/// [`Error::InvalidParameter`] for `eck-hadenfeld` on a rational surface.
pub fn fair_surface(
    s: &BSplineSurface,
    options: &SurfaceFairOptions,
) -> Result<(BSplineSurface, SurfaceFairReport)> {
    options.check()?;
    let start = Instant::now();
    let diag = s.control_diagonal();
    let (delta, source) = match options.tolerance {
        Some(d) => (d, "given"),
        None => (DEFAULT_TOLERANCE_REL * diag, "default"),
    };
    let magnitude = s
        .control_points()
        .iter()
        .flat_map(|c| c.iter())
        .fold(0.0f64, |m, x| m.max(x.abs()));
    let clamp_delta = (delta - ROUNDING_MARGIN_ULPS * f64::EPSILON * magnitude).max(0.0);
    let (nu, nv) = s.size();
    let rows = options.fix_boundary.rows();
    let movable: Vec<bool> = (0..nu * nv)
        .map(|k| {
            let (i, j) = (k / nv, k % nv);
            i >= rows && j >= rows && i + rows < nu && j + rows < nv
        })
        .collect();
    let problem = Problem {
        surface: s,
        delta: clamp_delta,
        movable,
        max_iterations: options.max_iterations,
        common: options.common()?,
    };
    let salvi_params = options.salvi()?;
    let grid = SampleGrid::with_density(s, salvi_params.samples_per_span);
    let curv0 = sample_curvature(s, &grid);
    let targets = Targets::fit(s, &grid, &curv0, &salvi_params.targets);
    let run = match options.method {
        SurfaceMethod::Salvi => salvi::run(&problem, &salvi_params, &grid, &targets)?,
        SurfaceMethod::EckHadenfeld => eck_hadenfeld::run(&problem)?,
    };
    let faired = s.with_control_points(run.control.clone())?;
    let measures = |x: &BSplineSurface| {
        let curv = sample_curvature(x, &grid);
        let a = summarize(x, &grid, &curv, &targets);
        SurfaceMeasures {
            pi_hat: a.fairness_measure,
            thin_plate_energy: eck_hadenfeld::thin_plate_energy(x),
            kappa1: a.kappa1,
            kappa2: a.kappa2,
            gaussian: a.gaussian,
            mean: a.mean,
        }
    };
    let dense = deviation_grid(s);
    let max_displacement = max_deviation(s, &faired, &dense);
    let tolerance_met = max_displacement <= delta;
    let moved: Vec<f64> = s
        .control_points()
        .iter()
        .zip(&run.control)
        .map(|(a, b)| distance(*a, *b))
        .collect();
    let status = if !tolerance_met {
        FairStatus::ToleranceExceeded
    } else {
        run.status.unwrap_or(FairStatus::Converged)
    };
    let report = SurfaceFairReport {
        method: options.method,
        status,
        tolerance: delta,
        tolerance_source: source,
        max_displacement,
        tolerance_met,
        deviation_samples: [dense.u.len(), dense.v.len()],
        max_control_point_move: moved.iter().fold(0.0, |m, &x| m.max(x)),
        fix_boundary: options.fix_boundary,
        moves: run.moves,
        rejected_moves: run.rejected,
        moved_points: moved.iter().filter(|&&x| x > 0.0).count(),
        before: measures(s),
        after: measures(&faired),
        history: run.history,
        parameters: run.parameters,
        time_s: start.elapsed().as_secs_f64(),
    };
    Ok((faired, report))
}

/// The dense grid of the tolerance check: [`DEVIATION_SAMPLES_PER_SPAN`] samples per knot
/// span and direction, at least [`DEVIATION_MIN_SAMPLES`].
pub fn deviation_grid(s: &BSplineSurface) -> SampleGrid {
    let g = SampleGrid::with_density(s, DEVIATION_SAMPLES_PER_SPAN);
    if g.u.len() >= DEVIATION_MIN_SAMPLES && g.v.len() >= DEVIATION_MIN_SAMPLES {
        return g;
    }
    let (du, dv) = s.domain();
    SampleGrid {
        u: crate::fair::local::uniform_samples(du, g.u.len().max(DEVIATION_MIN_SAMPLES)),
        v: crate::fair::local::uniform_samples(dv, g.v.len().max(DEVIATION_MIN_SAMPLES)),
    }
}

/// `max |b(u, v) − a(u, v)|` over a grid.
pub fn max_deviation(a: &BSplineSurface, b: &BSplineSurface, grid: &SampleGrid) -> f64 {
    let mut m = 0.0f64;
    for &u in &grid.u {
        for &v in &grid.v {
            m = m.max(distance(a.point(u, v), b.point(u, v)));
        }
    }
    m
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn with(key: &str, value: &str) -> SurfaceFairOptions {
        let mut o = SurfaceFairOptions::default();
        o.params.insert(key.into(), value.into());
        o
    }

    #[test]
    fn the_declared_defaults_are_the_documented_ones() {
        let o = SurfaceFairOptions::default();
        assert_eq!(o.salvi().unwrap(), salvi::SalviSurfaceParams::DEFAULT);
        assert_eq!(o.common().unwrap().tabu, None);
        for (key, text) in [
            ("samples_per_span", "4"),
            ("target_spans", "auto"),
            ("smoothing", "0.0001"),
            ("robust_passes", "4"),
            ("simplex_evaluations", "120"),
            ("tabu", "auto"),
        ] {
            let given = with(key, text);
            assert_eq!(
                given.salvi().unwrap(),
                salvi::SalviSurfaceParams::DEFAULT,
                "{key}"
            );
            assert_eq!(given.common().unwrap().tabu, None, "{key}");
        }
    }

    #[test]
    fn bad_values_name_the_key_and_sizes_are_bounded() {
        for (key, text) in [
            ("samples_per_span", "0"),
            ("samples_per_span", "65"),
            ("target_spans", "0"),
            ("smoothing", "-1"),
            ("smoothing", "nan"),
            ("robust_passes", "101"),
            ("simplex_evaluations", "3"),
            ("simplex_evaluations", "1e9"),
            ("tabu", "x"),
        ] {
            let err = with(key, text).check().unwrap_err().to_string();
            assert!(err.contains(key), "{key}={text}: {err}");
        }
        assert!(with("tabu", "7").check().is_ok());
        assert_eq!(with("tabu", "7").common().unwrap().tabu, Some(7));
    }
}
