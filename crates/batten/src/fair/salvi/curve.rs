//! Salvi & Várady's curve algorithm (docs/algorithms/salvi-varady.md §3 steps 5–9): the control
//! point of largest local deviation outside the recently-moved list, moved by downhill simplex
//! within δ of its original, accepted when Ê decreases, until the window rule stops the run; every
//! evaluation local to the support of the moved point (`docs/algorithms/salvi-varady.md`,
//! "Candidate selection" to "Acceptance and stopping").

use std::ops::Range;

use super::params::SalviParams;
use super::target::{MAX_SAMPLES, MIN_SAMPLES, sample_count, target_curvature, zero_speed};
use crate::curve::Curve;
use crate::error::{Error, Result};
use crate::fair::local::{
    self, LocalReport, RecentList, RunningMax, clamp_point, movable_mask, resolve_tolerance,
    select_candidate, support_ranges, uniform_samples,
};
use crate::fair::{HistoryRow, Move};
use crate::geom::{Point, Vec2};
use crate::numeric::{NelderMeadParams, minimize_nelder_mead};
use crate::spline::{BSplineCurve, MAX_ORDER};

/// A search that lowers the local measure of the moved point by less than this fraction
/// counts as no progress: the point is skipped until a neighbour makes progress
/// (`skip_stalled`).
pub(super) const STALL_REL_IMPROVEMENT: f64 = 1e-3;

/// The simplex edge s is this fraction of the mean length of the control-polygon legs at the
/// moved point (docs/algorithms/salvi-varady.md §3 step 6).
pub(super) const SIMPLEX_STEP_REL: f64 = 0.1;

/// Simplex evaluation budget per move (docs/algorithms/salvi-varady.md §3 step 6).
pub(super) const SIMPLEX_MAX_EVALUATIONS: usize = 400;

/// What [`fair_curve`] did, with the sampled curvatures.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SalviReport {
    /// The common report; the measure is Ê (eq 14).
    pub local: LocalReport,
    /// The sample parameters `t_i`.
    pub samples: Vec<f64>,
    /// The target g at the samples.
    pub target: Vec<f64>,
    /// κ of the input at the samples.
    pub curvature_before: Vec<f64>,
    /// κ of the result at the samples.
    pub curvature_after: Vec<f64>,
    /// Largest distance `|x(t_i) − x⁰(t_i)|` over the samples (≤ δ by eq 10).
    pub max_curve_deviation: f64,
}

/// Curvature from homogeneous derivatives `a = (A, A', A'')` and weight derivatives
/// `w = (W, W', W'')` (`w = (1, 0, 0)` for a non-rational curve, where this is §0.1 exactly).
#[inline]
fn curvature_h(a: &[Vec2; 3], w: &[f64; 3]) -> f64 {
    let c0 = a[0] / w[0];
    let c1 = (a[1] - c0 * w[1]) / w[0];
    let c2 = (a[2] - c1 * (2.0 * w[1]) - c0 * w[2]) / w[0];
    // |c1|³ as |c1|²·sqrt(|c1|²): `hypot` would cost more than the rest of the formula.
    let speed2 = c1.length_squared();
    c1.cross(c2) / (speed2 * speed2.sqrt())
}

/// The per-sample state of a run.
struct Samples {
    t: Vec<f64>,
    span: Vec<usize>,
    /// Homogeneous derivatives `Σ w_m d_m N_m^{(o)}`, o = 0, 1, 2.
    hom: Vec<[Vec2; 3]>,
    /// `Σ w_m N_m^{(o)}` (constant during a run).
    wd: Vec<[f64; 3]>,
    target: Vec<f64>,
    /// `(κ_i − g_i)²`.
    contrib: Vec<f64>,
}

impl Samples {
    /// The samples at `t` of `curve`, whose control points are `original` and weights
    /// `weights`: their spans and homogeneous derivatives, and the curvature and position of
    /// the curve at each (no target yet).
    ///
    /// # Errors
    /// [`Error::Degenerate`] where the curvature is undefined.
    fn new(
        curve: &BSplineCurve,
        t: Vec<f64>,
        original: &[Point],
        weights: Option<&[f64]>,
    ) -> Result<(Samples, Vec<f64>, Vec<Point>)> {
        let p = curve.degree();
        let n_samples = t.len();
        let mut b = [[0.0; MAX_ORDER]; 4];
        let mut s = Samples {
            span: Vec::with_capacity(n_samples),
            hom: Vec::with_capacity(n_samples),
            wd: Vec::with_capacity(n_samples),
            target: Vec::new(),
            contrib: Vec::with_capacity(n_samples),
            t,
        };
        let mut kappa0 = Vec::with_capacity(n_samples);
        let mut position0 = Vec::with_capacity(n_samples);
        for &ti in &s.t {
            let span = curve.find_span(ti);
            curve.basis_derivs(span, ti, 2, &mut b);
            let mut a = [Vec2::ZERO; 3];
            let mut w = [0.0; 3];
            for (c, dc) in original[span - p..=span].iter().enumerate() {
                let wm = weights.map_or(1.0, |w| w[span - p + c]);
                let dm = dc.to_vec2() * wm;
                for o in 0..3 {
                    a[o] += dm * b[o][c];
                    w[o] += wm * b[o][c];
                }
            }
            let k = curvature_h(&a, &w);
            if !k.is_finite() {
                return Err(zero_speed(ti));
            }
            kappa0.push(k);
            position0.push((a[0] / w[0]).to_point());
            s.span.push(span);
            s.hom.push(a);
            s.wd.push(w);
        }
        Ok((s, kappa0, position0))
    }
}

/// Fair `curve` by Salvi & Várady's method (see `docs/algorithms/salvi-varady.md`). Knots, degree
/// and weights are kept; the result is within δ of `curve` at every parameter.
///
/// # Errors
/// [`Error::InvalidParameter`] for a degree below 2, fewer than 4 samples, a non-positive
/// tolerance; [`Error::Degenerate`] when the curvature is undefined at a sample; the errors of
/// the target curvature ([`Error::LengthMismatch`] for a given target of the wrong length,
/// [`Error::InvalidParameter`] for a B-spline fit with fewer than 4 coefficients,
/// [`Error::Degenerate`] for a curve of zero length or zero speed, [`Error::Singular`]).
pub fn fair_curve(
    curve: &BSplineCurve,
    params: &SalviParams,
) -> Result<(BSplineCurve, SalviReport)> {
    let p = curve.degree();
    if p < 2 {
        return Err(Error::InvalidParameter {
            name: "degree".into(),
            reason: "curvature needs a curve of degree 2 or more".into(),
        });
    }
    if !(params.min_rel_improvement.is_finite() && params.min_rel_improvement >= 0.0) {
        return Err(Error::InvalidParameter {
            name: "min_rel_improvement".into(),
            reason: format!(
                "must be finite and non-negative, got {}",
                params.min_rel_improvement
            ),
        });
    }
    let delta = resolve_tolerance(params.tolerance, curve)?;
    let n_samples = sample_count(curve, params.samples);
    if n_samples < MIN_SAMPLES || params.samples.is_some_and(|n| n > MAX_SAMPLES) {
        return Err(Error::InvalidParameter {
            name: "samples".into(),
            reason: format!("{n_samples} is outside [{MIN_SAMPLES}, {MAX_SAMPLES}]"),
        });
    }
    let n_ctrl = curve.control_points().len();
    let t = uniform_samples(curve.domain(), n_samples);
    let ranges = support_ranges(curve.knots(), p, n_ctrl, &t)?;
    let original: Vec<Point> = curve.control_points().to_vec();
    let weights: Option<Vec<f64>> = curve.weights().map(<[f64]>::to_vec);

    // Per-sample state.
    let (mut s, kappa0, position0) = Samples::new(curve, t, &original, weights.as_deref())?;
    s.target = target_curvature(curve, &s.t, &kappa0, &params.smoother, params.pin_ends)?;
    s.contrib = kappa0
        .iter()
        .zip(&s.target)
        .map(|(k, g)| (k - g) * (k - g))
        .collect();
    let dev: Vec<f64> = (0..n_ctrl)
        .map(|j| local_sum(&s.contrib, &ranges[j]))
        .collect();
    let measure_before: f64 = s.contrib.iter().sum();

    let movable = movable_mask(
        n_ctrl,
        local::held_control_points(params.free_ends, params.held_ends),
    );
    let mut search = Search {
        p,
        delta,
        original,
        weights,
        ranges,
        s,
        dev,
        measure: measure_before,
        recent: RecentList::new(params.tabu_length),
        cur: curve.clone(),
        displacement: RunningMax::zeros(n_ctrl),
        history: vec![HistoryRow {
            iteration: 0,
            measure: measure_before,
            max_distance: 0.0,
        }],
        moves: Vec::new(),
        clamped_moves: 0,
        iterations: 0,
        // Movable points whose local objective may still improve (see `skip_stalled`).
        candidates: movable.clone(),
        movable,
        column: Vec::new(),
        b: [[0.0; MAX_ORDER]; 4],
    };
    let stopped = search.run(params);
    Ok(search.finish(kappa0, position0, measure_before, stopped))
}

/// `Σ (κ_i − g_i)²` over the samples of one support.
fn local_sum(contrib: &[f64], range: &Range<usize>) -> f64 {
    contrib[range.clone()].iter().sum()
}

/// The search of a run (docs/algorithms/salvi-varady.md §3 steps 5–9): the curve being faired and
/// what changes with it.
struct Search {
    p: usize,
    /// δ.
    delta: f64,
    original: Vec<Point>,
    weights: Option<Vec<f64>>,
    /// The samples in the support of each control point.
    ranges: Vec<Range<usize>>,
    s: Samples,
    /// `Dev_j`, the local measure of each control point.
    dev: Vec<f64>,
    /// Ê.
    measure: f64,
    movable: Vec<bool>,
    /// Movable points whose local objective may still improve (see `skip_stalled`).
    candidates: Vec<bool>,
    recent: RecentList,
    cur: BSplineCurve,
    displacement: RunningMax,
    history: Vec<HistoryRow>,
    moves: Vec<Move>,
    clamped_moves: usize,
    iterations: usize,
    /// Basis columns w_j N_j^{(o)}(t_i) of the samples of the current support.
    column: Vec<[f64; 3]>,
    /// Basis values and derivatives (scratch).
    b: [[f64; MAX_ORDER]; 4],
}

impl Search {
    /// Run until a stopping rule holds or `max_iterations`; returns whether a rule stopped
    /// the run.
    fn run(&mut self, params: &SalviParams) -> bool {
        let mut stopped = !self.movable.iter().any(|&m| m) || self.measure == 0.0;
        while !stopped && self.iterations < params.max_iterations {
            let Some(j) = select_candidate(&self.dev, &self.candidates, &mut self.recent) else {
                // Every movable point is at a local optimum of its own objective.
                stopped = true;
                break;
            };
            self.iterations += 1;
            let old_local = self.dev[j];
            let (q, clamped, fx) = self.search(j);
            let dj = self.cur.control_points()[j];
            let mut progress = false;
            if fx < old_local && q != dj {
                progress = self.commit(j, q, clamped, old_local);
            }
            if !progress && params.skip_stalled {
                self.candidates[j] = false;
            }
            self.recent.push(j);
            self.history.push(HistoryRow {
                iteration: self.iterations,
                measure: self.measure,
                max_distance: self.displacement.max(),
            });
            if self.measure == 0.0 {
                stopped = true;
            } else if params.window > 0 && self.iterations >= params.window {
                let earlier = self.history[self.iterations - params.window].measure;
                if earlier - self.measure <= params.min_rel_improvement * earlier {
                    stopped = true;
                }
            }
        }
        stopped
    }

    /// The downhill simplex over the displacement of control point `j` (step 6), every vertex
    /// evaluated at its clamped position: the clamped result (step 7), whether the clamp
    /// shortened it, and its local measure.
    fn search(&mut self, j: usize) -> (Point, bool, f64) {
        let p = self.p;
        let range = self.ranges[j].clone();
        let dj = self.cur.control_points()[j];
        let wj = self.weights.as_ref().map_or(1.0, |w| w[j]);
        self.column.clear();
        for i in range.clone() {
            let span = self.s.span[i];
            self.cur.basis_derivs(span, self.s.t[i], 2, &mut self.b);
            let c = j + p - span;
            let b = &self.b;
            self.column.push([wj * b[0][c], wj * b[1][c], wj * b[2][c]]);
        }
        let (original, delta, s, column) = (self.original[j], self.delta, &self.s, &self.column);
        let objective = |v: &[f64; 2]| -> f64 {
            let (q, _) = clamp_point(original, dj + Vec2::new(v[0], v[1]), delta);
            let dv = q - dj;
            let mut sum = 0.0;
            for (k, i) in range.clone().enumerate() {
                let col = &column[k];
                let h = &s.hom[i];
                let a = [h[0] + dv * col[0], h[1] + dv * col[1], h[2] + dv * col[2]];
                let e = curvature_h(&a, &s.wd[i]) - s.target[i];
                sum += e * e;
            }
            sum
        };
        let step = SIMPLEX_STEP_REL * mean_leg(self.cur.control_points(), j);
        let step = if step > 0.0 && step.is_finite() {
            step
        } else {
            delta
        };
        let nm =
            NelderMeadParams::with_scaled_step(step).with_max_evaluations(SIMPLEX_MAX_EVALUATIONS);
        let found = minimize_nelder_mead(objective, [0.0, 0.0], &nm);
        let proposed = dj + Vec2::new(found.x[0], found.x[1]);
        let (q, clamped) = clamp_point(original, proposed, delta);
        (q, clamped, found.fx)
    }

    /// Move control point `j` to `q` (step 8: its local measure fell from `old_local`):
    /// update the samples of its support, Ê, the deviations of the overlapping control
    /// points and the report; returns whether the move made progress (`skip_stalled`).
    fn commit(&mut self, j: usize, q: Point, clamped: bool, old_local: f64) -> bool {
        let p = self.p;
        let n_ctrl = self.dev.len();
        let range = self.ranges[j].clone();
        let dj = self.cur.control_points()[j];
        let s = &mut self.s;
        let dv = q - dj;
        let mut new_local = 0.0;
        for (k, i) in range.clone().enumerate() {
            let col = &self.column[k];
            let h = &mut s.hom[i];
            *h = [h[0] + dv * col[0], h[1] + dv * col[1], h[2] + dv * col[2]];
            let e = curvature_h(h, &s.wd[i]) - s.target[i];
            s.contrib[i] = e * e;
            new_local += e * e;
        }
        self.cur.set_control_point(j, q);
        // The difference is negative; `min` guards the running sum against rounding.
        self.measure = (self.measure - old_local + new_local).min(self.measure);
        let neighbours = j.saturating_sub(p)..(j + p + 1).min(n_ctrl);
        for (jj, dv) in self.dev[neighbours.clone()].iter_mut().enumerate() {
            *dv = local_sum(&s.contrib, &self.ranges[neighbours.start + jj]);
        }
        self.displacement.set(j, q.distance(self.original[j]));
        self.clamped_moves += usize::from(clamped);
        let progress = old_local - new_local > STALL_REL_IMPROVEMENT * old_local;
        if progress {
            // The objectives of the points whose supports overlap have changed.
            self.candidates[neighbours.clone()].copy_from_slice(&self.movable[neighbours]);
        }
        self.moves.push(Move {
            iteration: self.iterations,
            index: j,
            distance: dv.length(),
            before: old_local,
            after: new_local,
        });
        progress
    }

    /// The faired curve and the report, from the curvature `kappa0` and positions
    /// `position0` of the input at the samples and its measure `measure_before`.
    fn finish(
        self,
        kappa0: Vec<f64>,
        position0: Vec<Point>,
        measure_before: f64,
        stopped: bool,
    ) -> (BSplineCurve, SalviReport) {
        let Search {
            s,
            moves,
            clamped_moves,
            iterations,
            delta,
            displacement,
            history,
            cur,
            ..
        } = self;
        let status = LocalReport::status_of(!moves.is_empty(), stopped, clamped_moves);
        let measure_after: f64 = s.contrib.iter().sum();
        let curvature_after = s
            .hom
            .iter()
            .zip(&s.wd)
            .map(|(a, w)| curvature_h(a, w))
            .collect();
        let max_curve_deviation = s
            .hom
            .iter()
            .zip(&s.wd)
            .zip(&position0)
            .map(|((a, w), p0)| (a[0] / w[0]).to_point().distance(*p0))
            .fold(0.0, f64::max);
        let mut notes = Vec::new();
        if clamped_moves > 0 {
            notes.push(format!(
                "{clamped_moves} of {} accepted moves were shortened to keep the control \
                 points within δ = {delta:.6e} of the original",
                moves.len()
            ));
        }
        let report = SalviReport {
            local: LocalReport {
                status,
                iterations,
                accepted_moves: moves.len(),
                clamped_moves,
                measure_before,
                measure_after,
                tolerance: delta,
                max_control_displacement: displacement.max(),
                history,
                moves,
                notes,
            },
            samples: s.t,
            target: s.target,
            curvature_before: kappa0,
            curvature_after,
            max_curve_deviation,
        };
        (cur, report)
    }
}

/// The mean length of the control-polygon legs at `j` (one leg at an end).
fn mean_leg(d: &[Point], j: usize) -> f64 {
    let mut sum = 0.0;
    let mut count = 0.0;
    if j > 0 {
        sum += d[j].distance(d[j - 1]);
        count += 1.0;
    }
    if j + 1 < d.len() {
        sum += d[j].distance(d[j + 1]);
        count += 1.0;
    }
    if count > 0.0 { sum / count } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn homogeneous_curvature_matches_the_direct_formula() {
        let a = [
            Vec2::new(1.0, 2.0),
            Vec2::new(0.3, -0.4),
            Vec2::new(0.2, 0.5),
        ];
        let direct = a[1].cross(a[2]) / a[1].length().powi(3);
        assert!((curvature_h(&a, &[1.0, 0.0, 0.0]) - direct).abs() <= 1e-15 * direct.abs());
    }
}
