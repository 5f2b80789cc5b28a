//! The `kuragano` method on point input: the designed curve (and, with `degree=auto`, the
//! evaluation), the target `ρ̂`, the shape modification within the tolerance and the ends,
//! and the report (`docs/algorithms/kuragano.md`, "The fairing method `kuragano`").

use serde_json::{Map, Value, json};

use super::Kuragano;
use super::params::{DEGREE, ENDS, GRADIENT_FRACTION, RESIDUAL, RHO_MAX, SAMPLES};
use crate::analysis::roc_fairness::{
    Design, DesignEnds, Evaluation, KuraganoOptions, MIN_DEGREE, Modification, Residual, RhoFit,
    RhoSamples, ShapeConstraints, StopReason, design_curve, design_samples, evaluate_detailed,
    fits, modify_shape,
};
use crate::curve::Curve;
use crate::error::{Error, Result};
use crate::fair::{FairOptions, FairStatus, HistoryRow, Outcome};
use crate::geom::{Point, PointSeq};

/// [`Kuragano`] on point input, in whatever frame it is given.
pub(super) fn run_points(input: &PointSeq, options: &FairOptions) -> Result<Outcome> {
    let points = input.points();
    let m = points.len();
    let (kopts, degree) = Kuragano::options(options)?;
    kopts.check()?;
    let params_u: Vec<f64> = (0..m).map(|i| i as f64).collect();
    let anchors = Some((&params_u[..], points));
    let mut parameters = Map::new();
    let mut notes = Vec::new();
    // The designed curve and, when the degree is automatic, the evaluation.
    let (design, samples, evaluation, mut reusable) = match degree {
        Some(_) => {
            let design = design_curve(Design::Points(points), &kopts)?;
            let samples = design_samples(&design, &kopts)?;
            (design, samples, None, Vec::new())
        }
        None => {
            let d = evaluate_detailed(Design::Points(points), &kopts, anchors)?;
            (d.design, d.samples, Some(d.evaluation), d.modifications)
        }
    };
    design_parameters(&mut parameters, &kopts, &samples, evaluation.as_ref());
    let chosen = choose_target(degree, &samples, evaluation.as_ref(), &mut notes)?;
    let Some((chosen, target)) = chosen else {
        return Ok(Outcome {
            points: points.to_vec(),
            status: FairStatus::NoChange,
            parameters,
            notes,
            curve: Some(design),
            ..Outcome::default()
        });
    };
    DEGREE.write(&mut parameters, Some(chosen));
    let constrained = options.tolerance.is_some() || options.fix_ends.is_fixed();
    let reuse = reusable
        .get_mut(chosen - MIN_DEGREE)
        .and_then(Option::take)
        .filter(|_| !constrained);
    let modification = match reuse {
        Some(done) => done,
        None => modify_shape(
            &design,
            &samples,
            &target,
            kopts.residual,
            kopts.max_iterations,
            &ShapeConstraints {
                anchors,
                tolerance: options.tolerance,
                ends: options.fix_ends,
            },
        )?,
    };
    let mut out: Vec<Point> = params_u
        .iter()
        .map(|&u| modification.curve.eval(u))
        .collect();
    if options.fix_ends.is_fixed() {
        out[0] = points[0];
        out[m - 1] = points[m - 1];
    }
    Ok(modified(
        out,
        modification,
        chosen,
        &samples,
        parameters,
        notes,
    ))
}

/// Report what the design is: `N_s`, `ρ_max`, the residual, the ends, the arc length and the
/// evaluation when there is one.
fn design_parameters(
    parameters: &mut Map<String, Value>,
    kopts: &KuraganoOptions,
    samples: &RhoSamples,
    evaluation: Option<&Evaluation>,
) {
    SAMPLES.write(parameters, Some(samples.s.len()));
    RHO_MAX.write(parameters, Some(samples.rho_max));
    let residual = match kopts.residual {
        Residual::Rho => "rho",
        Residual::Kappa => "kappa",
    };
    RESIDUAL.write(parameters, residual);
    let ends = match kopts.ends {
        DesignEnds::Natural => "natural",
        DesignEnds::Gradients { .. } => "gradients",
    };
    ENDS.write(parameters, ends);
    if let DesignEnds::Gradients { fraction } = kopts.ends {
        GRADIENT_FRACTION.write(parameters, fraction);
    }
    parameters.insert("arc_length".into(), json!(samples.length));
    if let Some(e) = evaluation {
        parameters.insert(
            "evaluation".into(),
            serde_json::to_value(e).unwrap_or(Value::Null),
        );
    }
}

/// The degree and the target `ρ̂_i`: the explicit `degree` (fitted to the valid samples of an
/// inflected design), or the evaluation's best degree; `None` (with a note) when no degree
/// is applicable.
///
/// # Errors
/// An explicit degree that is not applicable, and the fit's errors.
fn choose_target(
    degree: Option<usize>,
    samples: &RhoSamples,
    evaluation: Option<&Evaluation>,
    notes: &mut Vec<String>,
) -> Result<Option<(usize, Vec<f64>)>> {
    let all_fits = fits(samples)?;
    let why_not = || {
        if samples.inflected {
            "the designed curve has an inflection"
        } else if samples.straight {
            "the designed curve is straight"
        } else {
            "the fitted radius of curvature changes sign"
        }
    };
    let (chosen, target) = match degree {
        Some(d) if samples.inflected => {
            // [CHOICE] Fair through the inflections: ρ̂ from the valid samples only.
            let (vs, vr): (Vec<f64>, Vec<f64>) = samples
                .s
                .iter()
                .zip(&samples.rho)
                .zip(&samples.kappa)
                .filter(|(_, k)| samples.sigma * **k >= 1.0 / samples.rho_max)
                .map(|((s, r), _)| (*s, *r))
                .unzip();
            let fit = RhoFit::fit(&vs, &vr, d)?;
            let spec = fit.eval_all(&samples.s);
            if spec.iter().any(|&r| samples.sigma * r <= 0.0 || r.is_nan()) {
                return Err(Error::InvalidParameter {
                    name: "degree".into(),
                    reason: format!(
                        "degree {d} is not applicable: the radius of curvature fitted to \
                         the samples without inflection changes sign"
                    ),
                });
            }
            notes.push(format!(
                "the designed curve has an inflection: ρ̂ of degree {d} is fitted to the {} \
                 of {} samples where ρ is finite and has the curve's orientation",
                vs.len(),
                samples.s.len()
            ));
            (d, spec)
        }
        Some(d) if all_fits[d - MIN_DEGREE].2 => (d, all_fits[d - MIN_DEGREE].1.clone()),
        Some(d) => {
            return Err(Error::InvalidParameter {
                name: "degree".into(),
                reason: format!("degree {d} is not applicable: {}", why_not()),
            });
        }
        None => match evaluation.and_then(|e| e.best_degree) {
            Some(d) => (d, all_fits[d - MIN_DEGREE].1.clone()),
            None => {
                notes.push(format!(
                    "no polynomial degree is applicable ({}); the points are returned \
                     unchanged (with an inflection, --set degree=d fairs through it)",
                    why_not()
                ));
                return Ok(None);
            }
        },
    };
    Ok(Some((chosen, target)))
}

/// The outcome of a shape modification of degree `chosen`: its figures in the report, its
/// notes, history and status.
fn modified(
    points: Vec<Point>,
    modification: Modification,
    chosen: usize,
    samples: &RhoSamples,
    mut parameters: Map<String, Value>,
    mut notes: Vec<String>,
) -> Outcome {
    parameters.insert("s_initial".into(), json!(modification.s_initial));
    parameters.insert("s_final".into(), json!(modification.s_final));
    parameters.insert("rho_rms".into(), json!(modification.rho_rms));
    parameters.insert("accepted_steps".into(), json!(modification.accepted));
    parameters.insert("stop".into(), json!(modification.stop));
    notes.push(format!(
        "degree {chosen}: S {:.6e} -> {:.6e}, RMS(ρ − ρ̂) = {:.6e} over {} samples",
        modification.s_initial,
        modification.s_final,
        modification.rho_rms,
        samples.s.len()
    ));
    if modification.tolerance_rejections > 0 {
        notes.push(format!(
            "{} trial steps were rejected because they would exceed the tolerance",
            modification.tolerance_rejections
        ));
    }
    let history = modification
        .history
        .iter()
        .enumerate()
        .map(|(k, step)| HistoryRow {
            iteration: k + 1,
            measure: step.s,
            max_distance: step.max_distance.unwrap_or(0.0),
        })
        .collect();
    let status = match modification.stop {
        _ if modification.tolerance_rejections > 0 => FairStatus::ToleranceLimited,
        StopReason::IterationLimit => FairStatus::IterationLimit,
        _ if modification.accepted == 0 => FairStatus::NoChange,
        _ => FairStatus::Converged,
    };
    Outcome {
        points,
        status,
        iterations: modification.iterations,
        history,
        parameters,
        notes,
        curve: Some(modification.curve),
        ..Outcome::default()
    }
}
