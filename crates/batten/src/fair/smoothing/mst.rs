//! The `mst` fairing method: the glue between the fairing contract and the smoothing spline
//! of [`super`] (its parameters, the choice of p, the report), for planar points
//! and, coordinate by coordinate with shared chord-length parameters and one p, for space
//! curves ([`crate::fair::fair_space`]).

use serde_json::{Map, Value};

use super::{DEFAULT_MAX_SEARCH_STEPS, Smoothing, check_p, param_p, roughness, select_any};
use crate::error::Result;
use crate::fair::{
    FairMethod, FairOptions, FairStatus, HistoryRow, Outcome, ParamSpec, SpaceOutcome,
};
use crate::geom::{Point, PointSeq, SpaceSeq, Xyz};
use crate::spline::{Parametrization, parameters};

use crate::fair::params::{Auto, Param};

/// The smoothing parameter p (`auto`: chosen for the tolerance, or by GCV).
pub(crate) const P: Param<Auto<f64>> = Param {
    name: "p",
    kind: Auto { min: 0.0, max: 1.0 },
    doc: "smoothing parameter in [0, 1] (1 interpolates, 0 is the least-squares line); \
          auto: the smoothest within --tolerance, else generalised cross-validation",
};

/// The parameter list of [`Mst`].
static PARAMS: &[ParamSpec] = &[P.spec()];

/// The `mst` fairing method: the cubic smoothing spline of the points at chord-length
/// parameters, with p given (`--set p=…`), chosen for `--tolerance`, or by GCV. See
/// [`super::SmoothingSpline`] for the library API (the equations are in the source,
/// `fair/smoothing/`).
///
/// Reports `p`, `alpha`, `selection` (`given`, `tolerance`, `gcv`), `roughness` and, for GCV,
/// `gcv` and `degrees_of_freedom` in [`Outcome::parameters`]; iterations are the splines the
/// search computed (the tolerance search's fits or GCV evaluations). [`Outcome::curve`] is left empty: the
/// method's product is the points, and building the curve would triple its cost at 10⁶
/// points; the library's [`SmoothingSpline::curve`](super::SmoothingSpline::curve) gives the spline itself
/// (`BSplineCurve::from_parametric_cubic` turns it into exact B-spline form).
#[derive(Clone, Copy, Debug, Default)]
pub struct Mst;

/// The smoothing parameter that gives the same curve when the data (points and chord-length
/// parameters) are multiplied by `f`: the objective `p·Σ|y − f|² + (1 − p)·∫|f''|² dt`
/// becomes `p·f²·Σ + (1 − p)/f·∫`, so the ratio `(1 − p)/p` is divided by `f³`. Exact in
/// real arithmetic; the limits p → 1 (interpolation) and p → 0 (the line) are kept.
pub(super) fn p_at_scale(p: f64, f: f64) -> f64 {
    if p <= 0.0 || p >= 1.0 {
        return p;
    }
    // One factor at a time: f³ alone may overflow where the ratio does not.
    let ratio = (1.0 - p) / p / f / f / f;
    1.0 / (1.0 + ratio)
}

impl FairMethod for Mst {
    /// No per-move check: a long input is measured while the method runs.
    fn checks_moves(&self) -> bool {
        false
    }

    fn name(&self) -> &'static str {
        "mst"
    }

    fn description(&self) -> &'static str {
        "cubic smoothing spline (Reinsch / de Boor SMOOTH, Matlab csaps; Han et al.'s MST): \
         p given, else the smoothest within the tolerance, else GCV"
    }

    fn parameters(&self) -> &'static [ParamSpec] {
        PARAMS
    }

    fn supports_closed(&self) -> bool {
        true
    }

    fn keeps_clean(&self) -> bool {
        // The csaps baseline: its result must stay equal to csaps'.
        false
    }

    fn params_at_scale(&self, options: &FairOptions, s: f64) -> Result<FairOptions> {
        let mut o = options.clone();
        if let Some(p) = param_p(options)? {
            o.params
                .insert(P.name.into(), format!("{:e}", p_at_scale(p, 1.0 / s)));
        }
        Ok(o)
    }

    fn report_params_at_scale(
        &self,
        parameters: &mut serde_json::Map<String, serde_json::Value>,
        s: f64,
    ) {
        if let Some(p) = parameters.get(P.name).and_then(serde_json::Value::as_f64) {
            P.write(parameters, Some(p_at_scale(p, s)));
        }
    }

    fn check_params(&self, options: &FairOptions) -> Result<()> {
        param_p(options).map(|_| ())
    }

    fn run(&self, input: &PointSeq, options: &FairOptions) -> Result<Outcome> {
        let closed = input.is_closed();
        let t = parameters(input.points(), Parametrization::ChordLength, closed)?;
        let points: Vec<[f64; 2]> = input.points().iter().map(|p| [p.x, p.y]).collect();
        let (values, mut outcome) = run_points(&points, &t, closed, options)?;
        outcome.points = values.iter().map(|g| Point::new(g[0], g[1])).collect();
        Ok(outcome)
    }

    fn run_space(&self, input: &SpaceSeq, options: &FairOptions) -> Option<Result<SpaceOutcome>> {
        let closed = input.is_closed();
        let t = chord_parameters(input.points(), closed);
        let run = run_points(input.points(), &t, closed, options);
        Some(run.map(|(points, outcome)| SpaceOutcome::from_parts(points, outcome)))
    }

    fn run_space_supported(&self) -> bool {
        true
    }
}

/// Chord-length parameters of space points (`t_0 = 0`; one more than points when closed),
/// the chords measured by `hypot` as [`parameters`] measures planar ones (the same numbers
/// in the plane `z = 0`). The points are a validated [`SpaceSeq`]: no chord is zero.
fn chord_parameters(points: &[Xyz], closed: bool) -> Vec<f64> {
    let n = points.len();
    let spans = if closed { n } else { n - 1 };
    let mut t = vec![0.0; spans + 1];
    for i in 0..spans {
        t[i + 1] =
            t[i] + crate::fair::space::distance(&points[crate::geom::next_index(i, n)], &points[i]);
    }
    t
}

/// `mst` on points of any dimension at the parameters `t`: the smoothed points, and the rest
/// of the outcome (its `points` left empty).
fn run_points<const D: usize>(
    points: &[[f64; D]],
    t: &[f64],
    closed: bool,
    options: &FairOptions,
) -> Result<(Vec<[f64; D]>, Outcome)> {
    let n = points.len();
    let p = param_p(options)?;
    if let Some(p) = p {
        check_p(p, closed)?;
    }
    let mut notes = Vec::new();
    let weights: Option<Vec<f64>> = if options.fix_ends.is_fixed() && !closed {
        // Pin the held points at each end (one for the position, two for the tangent,
        // three for the curvature).
        let held = options.fix_ends.held().min(n / 2);
        let mut w = vec![1.0; n];
        w[..held].fill(f64::INFINITY);
        w[n - held..].fill(f64::INFINITY);
        Some(w)
    } else {
        None
    };
    let (how, selection) = match (p, options.tolerance) {
        (Some(p), tol) => {
            if tol.is_some() {
                notes.push("p was given, so the tolerance does not choose it".to_string());
            }
            (Smoothing::P(p), "given")
        }
        (None, Some(tolerance)) => (
            Smoothing::MaxDisplacement {
                tolerance,
                max_steps: options.iterations_or(DEFAULT_MAX_SEARCH_STEPS),
            },
            "tolerance",
        ),
        (None, None) => (Smoothing::Gcv, "gcv"),
    };
    let (fit, info) = select_any(t, points, weights.as_deref(), closed, how)?;
    let mut parameters = Map::new();
    P.write(&mut parameters, Some(info.p));
    parameters.insert("alpha".into(), json_f64(info.alpha));
    parameters.insert("selection".into(), Value::from(selection));
    if let Some(g) = info.gcv {
        parameters.insert("gcv".into(), json_f64(g));
    }
    if let Some(d) = info.degrees_of_freedom {
        parameters.insert("degrees_of_freedom".into(), json_f64(d));
    }
    parameters.insert(
        "roughness".into(),
        json_f64(roughness(t, &fit.second, closed)),
    );
    let mut history = Vec::new();
    if matches!(how, Smoothing::MaxDisplacement { .. }) {
        history = info
            .trials
            .iter()
            .enumerate()
            .map(|(k, tr)| HistoryRow {
                iteration: k + 1,
                measure: tr.roughness,
                max_distance: tr.max_displacement,
            })
            .collect();
    }
    let status = if info.converged {
        FairStatus::Converged
    } else {
        FairStatus::IterationLimit
    };
    notes.extend(info.notes);
    let outcome = Outcome {
        iterations: info.trials.len(),
        status,
        parameters,
        history,
        notes,
        ..Outcome::default()
    };
    Ok((fit.values, outcome))
}

/// A JSON number, or `null` for a non-finite value (JSON has no infinity).
fn json_f64(v: f64) -> Value {
    serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number)
}
