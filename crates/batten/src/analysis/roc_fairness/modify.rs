//! The shape modification of docs/algorithms/kuragano.md §5.5 (paper eqs 10–13): the interior
//! control points move to minimise `S = Σ δ_i²` towards a fixed `ρ̂`, by Levenberg–Marquardt on the
//! banded normal equations (`docs/algorithms/kuragano.md`, "Shape modification").

use serde::Serialize;

use super::layout::Layout;
use super::options::Residual;
use super::samples::{Evaluator, RhoSamples, check_polynomial, sample_at_fractions};
use crate::curve::Curve;
use crate::error::{Error, Result};
use crate::geom::{EndFix, Point};
use crate::numeric::SymBanded;
use crate::spline::{BSplineCurve, MAX_ORDER};

/// Initial Levenberg–Marquardt damping (docs/algorithms/kuragano.md §5.5).
pub(super) const MU_INITIAL: f64 = 1e-3;

/// Factor by which μ is divided after an accepted step and multiplied after a rejected one
/// (docs/algorithms/kuragano.md §5.5).
pub(super) const MU_FACTOR: f64 = 10.0;

/// Damping beyond which no step is deemed acceptable and the iteration stops: the step is
/// then shorter than rounding of the control points.
pub(super) const MU_MAX: f64 = 1e12;

/// Default cap on linearisations of the shape modification (the test vectors' 60).
pub(crate) const DEFAULT_MAX_ITERATIONS: usize = 60;

/// Floor of the Marquardt scaling `diag(JᵀJ)`, relative to its largest entry.
pub(super) const DIAG_FLOOR_REL: f64 = 1e-12;

/// ρ at parameter `u` of a non-rational B-spline and its gradient with respect to the control
/// points of the span, holding `u` fixed (docs/algorithms/kuragano.md §5.5):
///
/// ```text
/// ∂ρ/∂q_r^x = 3 W^{1/2} x' N'_r / K − W^{3/2} (N'_r y'' − y' N''_r) / K²
/// ∂ρ/∂q_r^y = 3 W^{1/2} y' N'_r / K − W^{3/2} (x' N''_r − N'_r x'') / K²
/// ```
///
/// with `W = x'² + y'²`, `K = x'y'' − y'x''`. Returns `(ρ, first control-point index,
/// gradients)`; entry j of the gradients belongs to control point `first + j`. Where `K = 0`
/// the values are infinite.
///
/// # Errors
/// [`Error::InvalidParameter`] for a rational curve with unequal weights.
#[cfg(test)]
pub(super) fn rho_gradient(
    curve: &BSplineCurve,
    u: f64,
) -> Result<(f64, usize, Vec<crate::geom::Vec2>)> {
    check_polynomial(curve)?;
    let local = Evaluator::new(curve).local(u);
    let rho = 1.0 / local.kappa;
    let g = (0..=curve.degree())
        .map(|j| local.dkappa(j) * (-rho * rho))
        .collect();
    Ok((rho, local.first, g))
}

/// Why the shape modification stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub(crate) enum StopReason {
    /// No step decreased S (μ grew beyond [`MU_MAX`]): converged as far as LM can tell.
    NoAcceptableStep,
    /// The iteration cap was reached.
    IterationLimit,
    /// S reached zero.
    ZeroResidual,
    /// No sample depends on any free control point.
    NothingToMove,
}

/// Constraints of [`modify_shape`] beyond the fixed `q_0` and `q_{n−1}`.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ShapeConstraints<'a> {
    /// Output points to watch: `(parameters u_k, original points P_k)`. The history records
    /// the largest `|C(u_k) − P_k|` after every accepted step.
    pub anchors: Option<(&'a [f64], &'a [Point])>,
    /// A hard bound on `|C(u_k) − P_k|` over the anchors: a trial step that breaks it is
    /// rejected. Needs `anchors`.
    pub tolerance: Option<f64>,
    /// What to keep at the ends (`--fix-ends`). `Position`: the curve's end points at the
    /// first and last anchor, by elimination (see the module docs); needs `anchors`.
    /// `Tangent` and `Curvature`: every control point whose basis function is non-zero at a
    /// domain end is held, so the curve's end points, tangents and curvatures stay exactly as
    /// they are.
    pub ends: EndFix,
}

impl ShapeConstraints<'_> {
    /// The largest distance of the anchors from the curve, `None` without anchors.
    fn max_distance(&self, curve: &BSplineCurve) -> Option<f64> {
        self.anchors.map(|(params, original)| {
            params
                .iter()
                .zip(original)
                .map(|(&u, &p)| (curve.eval(u) - p).length())
                .fold(0.0_f64, f64::max)
        })
    }
}

/// One accepted step of [`modify_shape`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ModificationStep {
    /// S after the step.
    pub s: f64,
    /// The largest anchor distance after the step (`None` without anchors).
    pub max_distance: Option<f64>,
}

/// The result of [`modify_shape`].
#[derive(Clone, Debug)]
pub(crate) struct Modification {
    /// The modified curve.
    pub curve: BSplineCurve,
    /// Its ρ samples at the same fractions (capped with the target's ρ_max and orientation).
    pub samples: RhoSamples,
    /// S of the starting curve.
    pub s_initial: f64,
    /// S of the result.
    pub s_final: f64,
    /// RMS of `ρ_i − ρ̂_i` over the samples after the modification.
    pub rho_rms: f64,
    /// Linearisations performed.
    pub iterations: usize,
    /// Steps accepted.
    pub accepted: usize,
    /// Trial steps rejected because they broke the tolerance.
    pub tolerance_rejections: usize,
    /// Every accepted step in order.
    pub history: Vec<ModificationStep>,
    /// Why it stopped.
    pub stop: StopReason,
}

/// The residual form of one sample, fixed within a linearisation.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Form {
    Rho,
    /// `(1/ρ̂ − κ)·ρ̂²`.
    ScaledKappa,
    /// `κ − 1/ρ̂`.
    Kappa,
}

fn choose_forms(samples: &RhoSamples, residual: Residual) -> Vec<Form> {
    let k_min = 1.0 / samples.rho_max;
    samples
        .kappa
        .iter()
        .map(|&k| match residual {
            Residual::Kappa => Form::Kappa,
            Residual::Rho if samples.sigma * k >= k_min => Form::Rho,
            Residual::Rho => Form::ScaledKappa,
        })
        .collect()
}

fn residuals(samples: &RhoSamples, target: &[f64], forms: &[Form]) -> Vec<f64> {
    samples
        .kappa
        .iter()
        .zip(&samples.rho)
        .zip(target.iter().zip(forms))
        .map(|((&k, &rho), (&t, f))| match f {
            Form::Rho => rho - t,
            Form::ScaledKappa => (1.0 / t - k) * t * t,
            Form::Kappa => k - 1.0 / t,
        })
        .collect()
}

fn sum_sq(r: &[f64]) -> f64 {
    r.iter().map(|x| x * x).sum()
}

/// Re-sample a curve at the target's fractions with the target's cap and orientation.
fn resample(curve: &BSplineCurve, like: &RhoSamples) -> Result<RhoSamples> {
    let mut s = sample_at_fractions(curve, like.s.len())?;
    s.rho_max = like.rho_max;
    s.orient_and_cap(Some(like.sigma));
    Ok(s)
}

/// Modify the shape of `curve` so that its ρ at the fractions `start.s` approaches `target`
/// (`ρ̂_i`, fixed), by Levenberg–Marquardt (docs/algorithms/kuragano.md §5.5; see the module docs).
/// `start` are the samples of `curve` itself (from [`sample_rho`]), which fix `N_s`, `ρ_max` and σ.
///
/// # Errors
/// [`Error::LengthMismatch`] when `target` and `start` differ in length,
/// [`Error::InvalidParameter`] for a rational curve with unequal weights or a target whose
/// sign is not σ at some sample, [`Error::TooFewPoints`] when `fix_ends` leaves nothing to
/// move, and [`Error::Degenerate`] when the curve collapses.
///
/// [`sample_rho`]: super::sample_rho
pub(crate) fn modify_shape(
    curve: &BSplineCurve,
    start: &RhoSamples,
    target: &[f64],
    residual: Residual,
    max_iterations: usize,
    constraints: &ShapeConstraints<'_>,
) -> Result<Modification> {
    check_polynomial(curve)?;
    if target.len() != start.s.len() {
        return Err(Error::LengthMismatch {
            what: "target radii",
            got: target.len(),
            expected: start.s.len(),
        });
    }
    if let Some(i) = target
        .iter()
        .position(|&t| !(t.is_finite() && start.sigma * t > 0.0))
    {
        return Err(Error::InvalidParameter {
            name: "target".into(),
            reason: format!("ρ̂ at sample {i} is not finite or has the wrong sign"),
        });
    }
    if constraints.tolerance.is_some() && constraints.anchors.is_none() {
        return Err(Error::InvalidParameter {
            name: "tolerance".into(),
            reason: "a tolerance needs anchor points".into(),
        });
    }
    let end_points = constraints
        .anchors
        .and_then(|(_, original)| Some((*original.first()?, *original.last()?)));
    if constraints.ends == EndFix::Position && end_points.is_none() {
        return Err(Error::InvalidParameter {
            name: "fix_ends".into(),
            reason: "fixed end points need anchor points".into(),
        });
    }
    let layout = Layout::new(curve, constraints.ends, end_points)?;
    let mut q: Vec<Point> = curve.control_points().to_vec();
    for e in &layout.elim {
        e.apply(&mut q);
    }
    let cur_curve = curve.with_control_points(q.clone())?;
    let samples = if layout.elim.is_empty() {
        start.clone()
    } else {
        resample(&cur_curve, start)?
    };
    let mut cur = Iterate {
        q,
        curve: cur_curve,
        samples,
    };
    let problem = Problem {
        layout,
        target,
        constraints,
    };
    let s_initial = sum_sq(&residuals(
        &cur.samples,
        target,
        &choose_forms(&cur.samples, residual),
    ));
    let mut damping = Damping {
        mu: MU_INITIAL,
        tolerance_rejections: 0,
    };
    let mut history = Vec::new();
    let (mut iterations, mut accepted) = (0, 0);
    let mut row: Vec<(usize, f64)> = Vec::with_capacity(4 * MAX_ORDER);
    let stop = loop {
        if iterations >= max_iterations {
            break StopReason::IterationLimit;
        }
        iterations += 1;
        let forms = choose_forms(&cur.samples, residual);
        let r = residuals(&cur.samples, target, &forms);
        let s_cur = sum_sq(&r);
        if s_cur == 0.0 {
            break StopReason::ZeroResidual;
        }
        let Some(normal) = Normal::assemble(&problem, &cur, &forms, &r, &mut row) else {
            break StopReason::NothingToMove;
        };
        let Some((next, step)) = damped_step(&problem, &cur, &normal, &forms, s_cur, &mut damping)
        else {
            break StopReason::NoAcceptableStep;
        };
        cur = next;
        accepted += 1;
        history.push(step);
    };
    let forms = choose_forms(&cur.samples, residual);
    let s_final = sum_sq(&residuals(&cur.samples, target, &forms));
    let rho_rms = (cur
        .samples
        .rho
        .iter()
        .zip(target)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f64>()
        / target.len() as f64)
        .sqrt();
    Ok(Modification {
        curve: cur.curve,
        samples: cur.samples,
        s_initial,
        s_final,
        rho_rms,
        iterations,
        accepted,
        tolerance_rejections: damping.tolerance_rejections,
        history,
        stop,
    })
}

/// What one run of [`modify_shape`] keeps fixed: the unknowns, the target `ρ̂_i` and the
/// constraints.
struct Problem<'a, 'c> {
    layout: Layout,
    target: &'a [f64],
    constraints: &'a ShapeConstraints<'c>,
}

/// The current iterate: the control points, their curve and its ρ samples.
struct Iterate {
    q: Vec<Point>,
    curve: BSplineCurve,
    samples: RhoSamples,
}

/// The Levenberg–Marquardt damping μ, and the trial steps rejected so far because they broke
/// the tolerance.
struct Damping {
    mu: f64,
    tolerance_rejections: usize,
}

/// One linearisation: `JᵀJ` (banded, undamped), its diagonal with the floor of the Marquardt
/// scaling, and `Jᵀr`.
struct Normal {
    base: SymBanded,
    diag: Vec<f64>,
    floor: f64,
    jtr: Vec<f64>,
}

impl Normal {
    /// Assemble `JᵀJ` and `Jᵀr` at `cur` for the residual forms `forms` and residuals `r`;
    /// `None` when no sample depends on any free control point.
    fn assemble(
        problem: &Problem<'_, '_>,
        cur: &Iterate,
        forms: &[Form],
        r: &[f64],
        row: &mut Vec<(usize, f64)>,
    ) -> Option<Normal> {
        // Assemble JᵀJ (banded) and Jᵀr.
        let mut rows: Vec<(usize, usize, f64)> = Vec::new();
        let mut bw = 0;
        let ev = Evaluator::new(&cur.curve);
        for (i, (&u, form)) in cur.samples.u.iter().zip(forms).enumerate() {
            let local = ev.local(u);
            let t = problem.target[i];
            // d(residual)/dκ for the form.
            let scale = match form {
                Form::Rho => {
                    let rho = 1.0 / local.kappa;
                    -rho * rho
                }
                Form::ScaledKappa => -t * t,
                Form::Kappa => 1.0,
            };
            row.clear();
            for j in 0..=cur.curve.degree() {
                problem
                    .layout
                    .scatter(local.first + j, local.dkappa(j) * scale, row);
            }
            if let (Some(lo), Some(hi)) =
                (row.iter().map(|e| e.0).min(), row.iter().map(|e| e.0).max())
            {
                bw = bw.max(hi - lo);
            }
            rows.extend(row.iter().map(|&(c, v)| (i, c, v)));
        }
        let m = problem.layout.unknowns;
        let mut jtj_band: Vec<(usize, usize, f64)> = Vec::new();
        let mut jtr = vec![0.0; m];
        let mut diag = vec![0.0; m];
        let mut k = 0;
        while k < rows.len() {
            let i = rows[k].0;
            let mut e = k;
            while e < rows.len() && rows[e].0 == i {
                e += 1;
            }
            for a in k..e {
                let (_, ca, va) = rows[a];
                jtr[ca] += va * r[i];
                for &(_, cb, vb) in &rows[k..e] {
                    if cb <= ca {
                        jtj_band.push((ca, cb, va * vb));
                        if cb == ca {
                            diag[ca] += va * vb;
                        }
                    }
                }
            }
            k = e;
        }
        let dmax = diag.iter().fold(0.0_f64, |a, v| a.max(*v));
        if dmax <= 0.0 || !dmax.is_finite() {
            return None;
        }
        let floor = DIAG_FLOOR_REL * dmax;
        let mut base = SymBanded::zeros(m, bw);
        for &(a, b, v) in &jtj_band {
            base.add(a, b, v);
        }
        Some(Normal {
            base,
            diag,
            floor,
            jtr,
        })
    }
}

/// The damped steps of one linearisation: raise μ until a step is accepted (S decreases
/// within the tolerance; μ then falls) or μ exceeds [`MU_MAX`] (`None`). Returns the new
/// iterate and its history row.
fn damped_step(
    problem: &Problem<'_, '_>,
    cur: &Iterate,
    normal: &Normal,
    forms: &[Form],
    s_cur: f64,
    damping: &mut Damping,
) -> Option<(Iterate, ModificationStep)> {
    // Inner loop: raise μ until a step is accepted or μ exceeds MU_MAX.
    while damping.mu <= MU_MAX {
        let mut a = normal.base.clone();
        for (c, d) in normal.diag.iter().enumerate() {
            a.add(c, c, damping.mu * d.max(normal.floor));
        }
        let mut step: Vec<f64> = normal.jtr.iter().map(|g| -g).collect();
        if a.factorize().is_err() || a.solve_in_place(&mut step).is_err() {
            damping.mu *= MU_FACTOR;
            continue;
        }
        let trial_q = problem.layout.apply(&cur.q, &step);
        let Ok(trial_curve) = cur.curve.with_control_points(trial_q.clone()) else {
            damping.mu *= MU_FACTOR;
            continue;
        };
        let max_distance = problem.constraints.max_distance(&trial_curve);
        if let (Some(tol), Some(d)) = (problem.constraints.tolerance, max_distance)
            && (d > tol || d.is_nan())
        {
            damping.tolerance_rejections += 1;
            damping.mu *= MU_FACTOR;
            continue;
        }
        let Ok(trial) = resample(&trial_curve, &cur.samples) else {
            damping.mu *= MU_FACTOR;
            continue;
        };
        let s_trial = sum_sq(&residuals(&trial, problem.target, forms));
        if s_trial < s_cur {
            damping.mu /= MU_FACTOR;
            let next = Iterate {
                q: trial_q,
                curve: trial_curve,
                samples: trial,
            };
            let step = ModificationStep {
                s: s_trial,
                max_distance,
            };
            return Some((next, step));
        }
        damping.mu *= MU_FACTOR;
    }
    None
}
