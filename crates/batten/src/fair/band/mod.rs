//! `band`: batten's own fairing method — the least curvature variation inside the tolerance
//! band, a convex program with a hard guarantee.
//!
//! # The problem
//!
//! The unknowns are the faired points `q_i`, as many as the input points `p_i`, in order. Minimise
//! a fairness energy `E(q)` built from third divided differences at chord-length parameters
//! (see `energy.rs`: `≈ ∫ |C'''|² ds`, or its minimum-variation form, the part of `C'''` off
//! the tangent, `≈ ∫ κ'² ds`) subject to
//!
//! - the tolerance band `|q_i − p_i| ≤ D` for every point (second-order cones, hard);
//! - `--fix-ends`: 1, 2 or 3 points held exactly at each end of an open curve (position,
//!   tangent, curvature), as the other point methods hold them;
//! - closed curves: cyclic differences, no ends.
//!
//! Neither the jerk nor the minimum-variation energy is a data-fit term: inside the band the
//! passes' result is as fair as the energy can make it, and no point leaves the band. That
//! result flattens features by up to `D`; the debiasing stage (`debias.rs`) then adds a data
//! term whose weight the noise decides (the discrepancy principle, parameter `fit`).
//!
//! # Passes
//!
//! The energy depends on the parameters and, for minimum variation, on the tangents of the
//! curve it measures. The first pass takes both from the input (averaged) with the jerk metric;
//! each further pass keeps those parameters and takes the tangents from the previous result,
//! with the minimum-variation metric (Moreton & Séquin's energy, re-weighted as in iteratively
//! re-weighted least squares). Default: 3 passes.
//!
//! # The tolerance
//!
//! `--tolerance D`, or by default `D = k·σ̂` (`k = max(3, √(2 ln n))`, [`auto_k`]; `--set k=`),
//! with `σ̂` the noise estimate
//! of [`crate::analysis::noise_sigma`] (fifth differences along the local normal: their
//! median absolute value, then their root mean square clipped at 3σ̂). The report gives
//! `noise_sigma`, the `tolerance` and `tolerance_source`.
//!
//! # The solver
//!
//! A primal-dual interior point (Mehrotra predictor-corrector, every iterate strictly inside
//! the band) on the banded Newton system (`solver.rs`): O(n) per iteration, 12–25 iterations
//! per pass on the bundled examples. Its optimum is checked against the Lagrangian dual bound
//! of its own multipliers (within 1e-6) and against Clarabel's in the tests. Coordinates are in units of `D` (the band is
//! the unit ball) and parameters in units of the mean spacing, so the problem's numbers are
//! O(1) at any scale. The result is put into the band exactly (`max_displacement ≤ D`
//! always). The report's `solver` gives the iterations, the final duality gap and the number of
//! points on the band's edge.
//!
//! # Space curves
//!
//! Everything above is generic over the dimension: [`crate::fair::fair_space`] runs the same
//! passes on 3-D points (the band's cones become 3-D, `|q_i − p_i| ≤ D` in 3-D distance),
//! with σ̂ from [`crate::analysis::noise_sigma_space`] and the same parameters and notes.

mod debias;
mod design;
mod energy;
mod form;
mod params;
mod solver;
mod spline;
mod working_set;

#[cfg(test)]
mod reference_tests;

use crate::error::{Error, Result};
use crate::fair::{
    AUTO_TOLERANCE_K, FairMethod, FairOptions, FairStatus, HistoryRow, Outcome, ParamSpec,
    SolverInfo, SpaceOutcome,
};
use crate::geom::{Point, PointSeq, SpaceSeq};
use crate::numeric::{map_indices, map_pieces};

use debias::{ENERGY_CAP, Penalized};
use energy::{Energy, Metric};
use form::Form;
use params::{BandParams, PARAMS};
use solver::{Problem, solve};

/// A point counts as on the band's edge when its displacement is within this fraction of the
/// tolerance.
pub(super) const BAND_EDGE_REL: f64 = 1e-4;

/// How many tolerances the averaging window of the first pass's parameters spans.
const PARAMETER_WINDOW_TOLERANCES: f64 = 4.0;

/// The fewest points of a closed curve (the cyclic band of the Newton matrix must not wrap
/// onto itself).
const MIN_CLOSED_POINTS: usize = 8;

/// Rounds of re-measuring the spacing for the parameter window of dense points.
const DENSE_WINDOW_ROUNDS: usize = 8;

/// Shortenings [`into_band`] tries before it leaves a point where it was (the cut doubles each
/// time, so 64 reach any scale).
const MAX_SHRINKS: usize = 64;

/// The factor of the automatic tolerance for `n` points: `max(3, √(2 ln n))`.
///
/// With Gaussian noise of `σ` per coordinate the distance of a point from the truth exceeds
/// `kσ` with probability `exp(−k²/2)` (in 2-D), so `√(2 ln n)` leaves one of the `n` true
/// points outside the band on average. A fixed `k = 3` leaves `n·1.1 %` of them outside, and
/// at 1000 points the ten or so the band then forces towards the noise made most of `band`'s
/// spurious inflections (229 on 90 curves of the tuning set at `k = 3`, 37 at `k = 3.72`).
/// Below 90 points the rule gives less than 3 and 3 is kept.
pub fn auto_k(n: usize) -> f64 {
    AUTO_TOLERANCE_K.max((2.0 * (n.max(1) as f64).ln()).sqrt())
}

/// The `band` method (see `docs/algorithms/band.md`).
#[derive(Clone, Copy, Debug, Default)]
pub struct Band;

impl FairMethod for Band {
    /// No per-move check: a long input is measured while the method runs.
    fn checks_moves(&self) -> bool {
        false
    }

    /// Its interior point's iterations are serial but for the Newton matrix's assembly and
    /// factorisation, which take the second core in short stretches: the input's measures
    /// run in the background (#14's 10⁶-point sine: 0.05 s less).
    fn measures_in_background(&self) -> bool {
        true
    }

    fn name(&self) -> &'static str {
        "band"
    }

    fn description(&self) -> &'static str {
        "batten's own: least curvature variation inside the tolerance band |q_i − p_i| ≤ D \
         (a convex program, structured interior point); D = k·σ̂ from the noise by default"
    }

    fn parameters(&self) -> &'static [ParamSpec] {
        PARAMS
    }

    fn supports_closed(&self) -> bool {
        true
    }

    fn check_params(&self, options: &FairOptions) -> Result<()> {
        BandParams::from_options(options).map(|_| ())
    }

    fn auto_tolerance_by_default(&self) -> bool {
        true
    }

    fn auto_tolerance_factor(&self, options: &FairOptions, n: usize) -> Result<f64> {
        Ok(BandParams::from_options(options)?
            .k
            .unwrap_or_else(|| auto_k(n)))
    }

    fn run(&self, input: &PointSeq, options: &FairOptions) -> Result<Outcome> {
        let pts: Vec<[f64; 2]> = input.points().iter().map(|p| [p.x, p.y]).collect();
        let closed = input.is_closed();
        let (faired, mut outcome) = run_points(&pts, closed, options, || {
            let sigma = options
                .measured_noise
                .unwrap_or_else(|| crate::analysis::noise_sigma(input.points(), closed));
            (sigma, 2)
        })?;
        outcome.points = faired.iter().map(|q| Point::new(q[0], q[1])).collect();
        Ok(outcome)
    }

    fn run_space(&self, input: &SpaceSeq, options: &FairOptions) -> Option<Result<SpaceOutcome>> {
        let closed = input.is_closed();
        let run = run_points(input.points(), closed, options, || {
            let pts = input.points();
            let dims = if crate::analysis::is_planar(pts) {
                2
            } else {
                3
            };
            let sigma = options
                .measured_noise
                .unwrap_or_else(|| crate::analysis::noise_sigma_space(pts, closed));
            (sigma, dims)
        });
        Some(run.map(|(points, outcome)| SpaceOutcome::from_parts(points, outcome)))
    }

    fn run_space_supported(&self) -> bool {
        true
    }
}

/// `band` on points of any dimension (the planar method and the space one): the faired
/// points, and the rest of the outcome (its `points` left empty). `noise` gives σ̂ of the
/// input and the number of coordinates the noise lies in (the debiasing stage's target: 2
/// for points in one plane, also in space), asked once the input has passed its checks.
fn run_points<const D: usize>(
    pts: &[[f64; D]],
    closed: bool,
    options: &FairOptions,
    noise: impl FnOnce() -> (f64, usize),
) -> Result<(Vec<[f64; D]>, Outcome)> {
    let params = BandParams::from_options(options)?;
    let tolerance = options.tolerance.ok_or_else(|| Error::InvalidParameter {
        name: "tolerance".into(),
        reason: "band needs a tolerance (the common path gives it k·σ̂ when none is given)".into(),
    })?;
    if closed && pts.len() < MIN_CLOSED_POINTS {
        return Err(Error::InvalidParameter {
            name: "input".into(),
            reason: format!(
                "band needs at least {MIN_CLOSED_POINTS} points on a closed curve, got {}",
                pts.len()
            ),
        });
    }
    let held = held_mask(pts.len(), closed, options.fix_ends.held());
    let (noise, noise_dims) = noise();
    let faired = fair_points(pts, closed, &held, tolerance, (noise, noise_dims), &params)?;
    let parameters = params.report();
    let mut notes: Vec<String> = faired
        .fidelity
        .map(|(mu, raised)| {
            format!(
                "debiasing stage: data weight {mu:.3e} (in units of the tolerance and the \
                 mean spacing), for a mean residual of {}·σ̂ = {:.6e}; raised at {raised} \
                 of {} points where the residual was biased",
                params.fit,
                params.fit * noise,
                pts.len()
            )
        })
        .into_iter()
        .collect();
    if let Some(vars) = faired.spline {
        notes.push(format!(
            "dense points: solved in the spline form, a cubic B-spline with {vars} control \
             points through which every point is taken (see docs/algorithms/band.md, \
             Dense points)"
        ));
    }
    if let Some(gap) = faired.stalled {
        notes.push(format!(
            "the solver stopped short of its stopping rule: rounding stopped its progress at \
             a relative duality gap of {gap:.1e}; the result is inside the band but may \
             not be the fairest one. This happens when the points are dense against the \
             noise (the energy's long waves fall below double precision); see \
             docs/algorithms/band.md, Limits"
        ));
    }
    let outcome = Outcome {
        status: if faired.converged {
            FairStatus::Converged
        } else if faired.stalled.is_some() {
            FairStatus::Stalled
        } else {
            FairStatus::IterationLimit
        },
        iterations: faired.solver.iterations,
        history: faired.history,
        parameters,
        // With `k` given, the band's width is the user's choice, not a noise model's.
        pressed: faired
            .fidelity
            .filter(|_| params.k.is_none())
            .map(|_| faired.solver.points_on_band_edge),
        solver: Some(faired.solver),
        notes,
        ..Outcome::default()
    };
    Ok((faired.points, outcome))
}

/// Which points are held: `held` at each end of an open curve.
fn held_mask(n: usize, closed: bool, held: usize) -> Vec<bool> {
    let mut mask = vec![false; n];
    if !closed {
        let h = held.min(n);
        mask[..h].fill(true);
        mask[n - h..].fill(true);
    }
    mask
}

/// The result of the passes.
#[derive(Debug)]
struct Faired<const D: usize> {
    points: Vec<[f64; D]>,
    converged: bool,
    /// When rounding stopped a stage short of its stopping rule (not the iteration limit):
    /// the largest relative duality gap such a stage ended with.
    stalled: Option<f64>,
    history: Vec<HistoryRow>,
    /// The data weight of the debiasing stage, when it ran, and the number of points whose
    /// weight was raised locally.
    fidelity: Option<(f64, usize)>,
    /// The number of control points when the spline form ran.
    spline: Option<usize>,
    solver: SolverInfo,
}

/// Above this many points the spline form is tried (`spline.rs`): the point form's solver
/// stalls from a few thousand points on (see `docs/algorithms/band.md`, Limits).
pub(super) const DENSE_POINTS: usize = 2000;

/// Run the passes on points of any dimension and put the result into the band exactly.
/// `(noise_sigma, noise_dims)`: σ̂ per coordinate and the number of coordinates the noise
/// lies in (the debiasing stage's target is a mean squared residual of `noise_dims·(fit·σ̂)²`).
fn fair_points<const D: usize>(
    pts: &[[f64; D]],
    closed: bool,
    held: &[bool],
    tolerance: f64,
    (noise_sigma, noise_dims): (f64, usize),
    params: &BandParams,
) -> Result<Faired<D>> {
    let n = pts.len();
    let params = &params.at_points(n);
    // The input in units of the tolerance, about its centroid (the energy ignores
    // translation; centring keeps the numbers small).
    let centre = centroid(pts);
    let scale = |p: &[f64; D]| -> [f64; D] { in_units(p, &centre, tolerance) };
    let scaled: Vec<f64> = pts.iter().flat_map(scale).collect();
    let held_ends = held.iter().take_while(|h| **h).count();
    let dense = n > DENSE_POINTS && held_ends <= 1;
    // The first pass's reference and parameters: the input, averaged where the noise is as
    // large as the spacing.
    let mut shape: Vec<[f64; D]> = if dense {
        dense_parameter_average(pts, closed, tolerance)
    } else {
        smoothed_for_parameters(pts, closed, tolerance)
    };
    // Every pass keeps the first pass's parameters. A faired result keeps the tangential
    // part of the noise (the band lets points slide along the curve, and the minimum-variation
    // energy hardly weighs it), so its own chords are noisy where the noise is as large as the
    // spacing: on the tuning set, re-taking them gave 170 spurious inflections against 71.
    let chords = energy::chords_of(&shape, closed);
    let spline = if dense {
        Form::spline(&chords, tolerance, &scaled, closed, held_ends == 1)?
    } else {
        None
    };
    let spline_form = spline.is_some();
    let form = spline.unwrap_or_else(|| Form::points(held, chords, closed));
    let mut reference = form.first_reference(|| shape.iter().flat_map(scale).collect());
    if spline_form {
        // Its energy takes its tangents from the control points: the averaged points are
        // done with.
        shape = Vec::new();
    }
    let mut stages = Stages {
        pts,
        tolerance,
        max_iterations: params.max_iterations,
        history: Vec::with_capacity(params.passes),
        iterations: 0,
        converged: true,
        stalled: None,
        gap: 0.0,
    };
    // The last stage's displacements, put into the band at the end. The point form's energy
    // takes its tangents from the points, so there `shape` follows every stage; the spline
    // form's takes them from its control points, and putting a million points into the band
    // after every stage only to measure them cost about 8 ms a stage.
    let mut last = Vec::new();
    for pass in 0..params.passes {
        let energy = form.energy(&shape, &reference, pass_metric(pass, params));
        // A pass before the last gives only the next pass's reference: a looser stopping rule.
        let gap_rel = if pass + 1 < params.passes {
            solver::INTERMEDIATE_GAP_REL
        } else {
            solver::GAP_REL
        };
        let limits = (params.max_iterations, gap_rel);
        let problem = band_problem(&form, &energy, &reference, &scaled, limits);
        let sol = solve(&problem)?;
        stages.record(&sol, pass + 1);
        if !spline_form {
            shape = into_band(pts, &sol.r, tolerance);
        }
        reference = form.next_reference(&reference, &scaled, &sol);
        last = sol.r;
    }
    let mut fidelity = None;
    if params.fit > 0.0 && noise_sigma > 0.0 {
        let noise = (noise_sigma, noise_dims);
        if let Some((sol, mu, raised)) =
            debias_stage(&form, &shape, &reference, &scaled, tolerance, noise, params)?
        {
            stages.record(&sol, params.passes + 1);
            last = sol.r;
            // Reported in the point form's units.
            fidelity = Some((mu / form.unit(), raised));
        }
    }
    let shape = into_band(pts, &last, tolerance);
    let edge = (1.0 - BAND_EDGE_REL) * tolerance;
    let on_edge = map_indices(n, |i| distance(&shape[i], &pts[i]) >= edge)
        .into_iter()
        .filter(|e| *e)
        .count();
    Ok(Faired {
        points: shape,
        converged: stages.converged,
        stalled: stages.stalled,
        history: stages.history,
        fidelity,
        spline: spline_form.then(|| form.vars()),
        solver: SolverInfo {
            iterations: stages.iterations,
            duality_gap: stages.gap,
            points_on_band_edge: on_edge,
        },
    })
}

/// The centroid of the points.
fn centroid<const D: usize>(pts: &[[f64; D]]) -> [f64; D] {
    let n = pts.len();
    let mut centre = [0.0; D];
    for p in pts {
        for a in 0..D {
            centre[a] += p[a] / n as f64;
        }
    }
    centre
}

/// A point in units of the tolerance, about `centre`.
fn in_units<const D: usize>(p: &[f64; D], centre: &[f64; D], tolerance: f64) -> [f64; D] {
    std::array::from_fn(|a| (p[a] - centre[a]) / tolerance)
}

/// What the stages of [`fair_points`] add up to.
struct Stages<'p, const D: usize> {
    pts: &'p [[f64; D]],
    tolerance: f64,
    max_iterations: usize,
    history: Vec<HistoryRow>,
    iterations: usize,
    converged: bool,
    stalled: Option<f64>,
    gap: f64,
}

impl<const D: usize> Stages<'_, D> {
    /// Each stage: one solve from the current reference, a history row with its result put
    /// into the band (`stage` counts from 1: the passes, then the debiasing stage).
    fn record(&mut self, sol: &solver::Solution, stage: usize) {
        self.iterations += sol.iterations;
        self.converged &= sol.converged;
        if !sol.converged && sol.iterations < self.max_iterations {
            // Stopped by rounding, not by the iteration limit: keep the worst stage's gap.
            self.stalled = Some(self.stalled.map_or(sol.gap, |g: f64| g.max(sol.gap)));
        }
        self.gap = sol.gap;
        self.history.push(HistoryRow {
            iteration: stage,
            measure: sol.objective,
            max_distance: farthest(self.pts, &sol.r, self.tolerance),
        });
    }
}

/// The debiasing stage: the last pass's problem with a data term weighted for the noise
/// level (`noise`: σ̂ and the coordinates it lies in), solved; `None` when no weight is
/// needed. With the solution, the weight μ and the number of points whose weight was
/// raised locally.
fn debias_stage<const D: usize>(
    form: &Form<D>,
    shape: &[[f64; D]],
    reference: &[f64],
    scaled: &[f64],
    tolerance: f64,
    (noise_sigma, noise_dims): (f64, usize),
    params: &BandParams,
) -> Result<Option<(solver::Solution, f64, usize)>> {
    // The last pass's metric, its tangents re-taken from the passes' result.
    let metric = pass_metric(params.passes - 1, params);
    let energy = form.energy(shape, reference, metric);
    let limits = (params.max_iterations, solver::GAP_REL);
    let mut problem = band_problem(form, &energy, reference, scaled, limits);
    let fixed = form.fixed(&problem.centres);
    let fit = Penalized::new(
        &energy,
        form.unit(),
        &form.design,
        &form.held,
        &form.pinned,
        &fixed,
        &problem.anchor,
        &problem.centres,
    );
    let scaled_noise = params.fit * noise_sigma / tolerance;
    let target = noise_dims as f64 * scaled_noise * scaled_noise;
    let anchor_energy = problem.anchor_energy;
    let cap = ENERGY_CAP * anchor_energy;
    let Some(mu) = fit.discrepancy_weight(anchor_energy, target, cap)? else {
        return Ok(None);
    };
    let (weights, raised) = fit.local_weights(
        mu,
        anchor_energy,
        cap,
        noise_sigma / tolerance,
        params.local,
    )?;
    problem.fidelity = weights;
    let sol = solve(&problem)?;
    Ok(Some((sol, mu, raised)))
}

/// The metric of pass `pass` (from 0): the jerk first, then the parameters' metric.
fn pass_metric(pass: usize, params: &BandParams) -> Metric {
    if pass == 0 {
        Metric::Jerk
    } else {
        params.metric
    }
}

/// The band problem of `form` with the energy `energy` taken relative to `reference` (its
/// unknowns, in units of the tolerance, flat; the input `scaled` likewise), without a data
/// term; `(max_iterations, gap_rel)` its iteration limit and stopping rule.
fn band_problem<'a, const D: usize>(
    form: &'a Form<D>,
    energy: &'a Energy<D>,
    reference: &[f64],
    scaled: &[f64],
    (max_iterations, gap_rel): (usize, f64),
) -> Problem<'a, D> {
    let mut anchor = vec![0.0; reference.len()];
    energy.apply_add(reference, &mut anchor);
    let mut centres = vec![0.0; scaled.len()];
    form.design.eval_then::<D>(reference, &mut centres, |i, q| {
        std::array::from_fn(|a| scaled[i * D + a] - q[a])
    });
    Problem {
        energy,
        anchor,
        anchor_energy: energy.value(reference),
        design: &form.design,
        centres,
        held: &form.held,
        pinned: &form.pinned,
        start: form.start(reference),
        max_iterations,
        gap_rel,
        fidelity: Vec::new(),
    }
}

/// The largest distance of a point put into the band ([`into_band_point`] of the
/// displacements `r`) from its input point, by [`distance`]: the squared distances pick the
/// candidates (within rounding of the largest), which are then measured exactly.
///
/// One sweep, in parallel pieces: each piece measures the points whose square is within
/// rounding of the largest so far in the piece, a superset of the candidates (that largest is
/// at most the overall one), and the candidates are those of them within rounding of the
/// overall largest. The same candidates, so the same number, in any number of pieces.
fn farthest<const D: usize>(pts: &[[f64; D]], r: &[f64], tolerance: f64) -> f64 {
    const NEAR: f64 = 1.0 - 1e-12;
    let parts = map_pieces(pts.len(), FARTHEST_PIECE, |points| {
        let mut top = 0.0_f64;
        let mut measured = Vec::new();
        for i in points {
            let (p, q) = (
                &pts[i],
                into_band_point(&pts[i], &r[i * D..(i + 1) * D], tolerance),
            );
            let square = (0..D).map(|a| (q[a] - p[a]).powi(2)).sum::<f64>();
            if square >= top * NEAR {
                top = top.max(square);
                measured.push((square, distance(&q, p)));
            }
        }
        (top, measured)
    });
    let near = parts.iter().fold(0.0_f64, |m, (top, _)| m.max(*top)) * NEAR;
    parts
        .iter()
        .flat_map(|(_, measured)| measured)
        .filter(|(square, _)| *square >= near)
        .fold(0.0_f64, |m, (_, d)| m.max(*d))
}

/// The points of a piece of [`farthest`]'s sweep.
const FARTHEST_PIECE: usize = 1 << 14;

/// The half-width `m` of the parameter window: `⌊c·D / h⌋`, `c` =
/// [`PARAMETER_WINDOW_TOLERANCES`], `h` the median chord of the input, at most an eighth of
/// the points.
fn parameter_window<const D: usize>(pts: &[[f64; D]], tolerance: f64) -> usize {
    let n = pts.len();
    let mut chords: Vec<f64> = map_indices(n - 1, |i| spacing(&pts[i], &pts[i + 1]));
    let mid = chords.len() / 2;
    let h = *chords.select_nth_unstable_by(mid, f64::total_cmp).1;
    if h > 0.0 {
        ((PARAMETER_WINDOW_TOLERANCES * tolerance / h).floor() as usize).min(n / 8)
    } else {
        0
    }
}

/// The input averaged over the parameter window for dense points: as [`parameter_window`],
/// but with the spacing re-measured on the averaged points until the window stops growing.
/// Where the noise is much larger than the spacing the input's median chord is noise, and a
/// window set by it leaves the averaged chords noisy too. (The last round's average is the
/// result, not made again.)
fn dense_parameter_average<const D: usize>(
    pts: &[[f64; D]],
    closed: bool,
    tolerance: f64,
) -> Vec<[f64; D]> {
    let n = pts.len();
    let mut m = parameter_window(pts, tolerance);
    for _ in 0..DENSE_WINDOW_ROUNDS {
        let s = moving_average(pts, closed, m);
        let mut chords: Vec<f64> = map_indices(n - 1, |i| spacing(&s[i], &s[i + 1]));
        let mid = chords.len() / 2;
        let h = *chords.select_nth_unstable_by(mid, f64::total_cmp).1;
        if h <= 0.0 {
            return s;
        }
        let want = ((PARAMETER_WINDOW_TOLERANCES * tolerance / h).floor() as usize).min(n / 8);
        if want <= m {
            return s;
        }
        m = want;
    }
    moving_average(pts, closed, m)
}

/// The input averaged over a moving window of `2m + 1` points (cyclic when closed; near the
/// ends of an open curve a symmetric window, so the ends are not pulled inwards), by prefix
/// sums: O(n) whatever `m` (at most an eighth of the points).
fn moving_average<const D: usize>(pts: &[[f64; D]], closed: bool, m: usize) -> Vec<[f64; D]> {
    let n = pts.len();
    if m == 0 {
        return pts.to_vec();
    }
    // prefix[j] = the sum of the first j points of the input, padded cyclically by m on each
    // side when closed.
    let pad = if closed { m } else { 0 };
    let mut prefix = Vec::with_capacity(n + 2 * pad + 1);
    let mut sum = [0.0; D];
    prefix.push(sum);
    // The last `pad` points, all of them, the first `pad` (pad ≤ n/8).
    for p in pts[n - pad..].iter().chain(pts).chain(&pts[..pad]) {
        for a in 0..D {
            sum[a] += p[a];
        }
        prefix.push(sum);
    }
    map_indices(n, |i| {
        let (lo, hi) = if closed {
            (i, i + 2 * m)
        } else {
            let half = i.min(n - 1 - i).min(m);
            (i - half, i + half)
        };
        let count = (hi - lo + 1) as f64;
        let mut acc = [0.0; D];
        for a in 0..D {
            acc[a] = (prefix[hi + 1][a] - prefix[lo][a]) / count;
        }
        acc
    })
}

/// The points whose chord lengths give the first pass its parameters: the input, averaged
/// over a moving window of `2m + 1` points where the tolerance is not small against the
/// spacing (`m = ⌊c·D / h⌋`, `c` = [`PARAMETER_WINDOW_TOLERANCES`], `h` the median chord, at
/// most an eighth of the points). Where the noise is
/// as large as the spacing, the input's own chords are mostly noise, and a fair curve
/// parametrised by them crowds its points where the noise happened to be small; averaged
/// chords follow the curve.
fn smoothed_for_parameters<const D: usize>(
    pts: &[[f64; D]],
    closed: bool,
    tolerance: f64,
) -> Vec<[f64; D]> {
    let n = pts.len();
    let m = parameter_window(pts, tolerance);
    if m == 0 {
        return pts.to_vec();
    }
    (0..n)
        .map(|i| {
            let mut acc = [0.0; D];
            let (lo, hi) = if closed {
                (i as isize - m as isize, i as isize + m as isize)
            } else {
                let lo = i.saturating_sub(m);
                let hi = (i + m).min(n - 1);
                // A symmetric window near the ends, so the ends are not pulled inwards.
                let half = (i - lo).min(hi - i);
                ((i - half) as isize, (i + half) as isize)
            };
            for j in lo..=hi {
                let p = &pts[j.rem_euclid(n as isize) as usize];
                for a in 0..D {
                    acc[a] += p[a];
                }
            }
            let count = (hi - lo + 1) as f64;
            acc.map(|v| v / count)
        })
        .collect()
}

/// The distance between two points for a median spacing, which only chooses a window
/// ([`crate::numeric::norm`]: faster than [`distance`], within an ulp of it).
fn spacing<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    crate::numeric::norm::<D>(&std::array::from_fn(|k| a[k] - b[k]))
}

/// Euclidean distance, computed as the fairing contract measures displacement (`hypot`, in 2-D
/// bit for bit [`crate::Point::distance`]): the band's guarantee is checked by that measure, and a
/// square root of the summed squares can differ from it in the last place.
fn distance<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    // From the first coordinate's size (what `hypot(0, x)` gives): one `hypot` fewer.
    (1..D).fold((a[0] - b[0]).abs(), |acc, k| acc.hypot(a[k] - b[k]))
}

/// `q_i = p_i + D·r_i`, then pulled in where rounding put it a hair outside the band, so that
/// `|q_i − p_i| ≤ D` holds exactly as computed: first scaled to the unit length if it is
/// longer, then shortened by a cut that starts at a few units in the last place and doubles.
fn into_band<const D: usize>(pts: &[[f64; D]], r: &[f64], tolerance: f64) -> Vec<[f64; D]> {
    map_indices(pts.len(), |i| {
        into_band_point(&pts[i], &r[i * D..(i + 1) * D], tolerance)
    })
}

/// Point `p` of [`into_band`], displaced by `ri` (in tolerances).
fn into_band_point<const D: usize>(p: &[f64; D], ri: &[f64], tolerance: f64) -> [f64; D] {
    let len = ri.iter().map(|v| v * v).sum::<f64>().sqrt();
    // Clearly inside, rounding of `q` and of its distance included (a few units in
    // the last place of the coordinates and of `D`; 16 of them here): no check needed.
    let size = p.iter().fold(tolerance, |m, v| m.max(v.abs()));
    if len <= 1.0 - 16.0 * f64::EPSILON * (1.0 + size / tolerance) {
        return std::array::from_fn(|a| p[a] + tolerance * ri[a]);
    }
    let mut shrink = if len > 1.0 { 1.0 / len } else { 1.0 };
    // Far from the origin the rounding of `q` is large against `D`: the cut doubles
    // at each try, from 4 units in the last place.
    let mut cut = 4.0 * f64::EPSILON;
    for _ in 0..MAX_SHRINKS {
        let mut q = *p;
        for a in 0..D {
            q[a] = p[a] + tolerance * (shrink * ri[a]);
        }
        if distance(&q, p) <= tolerance {
            return q;
        }
        shrink *= 1.0 - cut;
        cut = (2.0 * cut).min(1.0);
    }
    *p
}

#[cfg(test)]
mod into_band_tests {
    use super::{distance, farthest, into_band};
    use crate::Point;
    use crate::numeric::PARALLEL_FROM;

    /// Points pushed to the band's edge in every direction, at scales where rounding matters,
    /// stay inside it by the contract's own measure (`Point::distance`, a `hypot`). A square
    /// root of summed squares passed this check 1 ulp outside on a 1000-point cubic.
    #[test]
    fn edge_points_stay_inside_by_the_contract_measure() {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..20_000 {
            let scale = 10f64.powf(next() * 12.0 - 6.0);
            let p = [scale * (next() - 0.5), scale * (next() - 0.5)];
            let tolerance = scale * 10f64.powf(-next() * 8.0);
            let angle = next() * std::f64::consts::TAU;
            let r = [angle.cos(), angle.sin()];
            let q = into_band(&[p], &r, tolerance)[0];
            let d = Point::new(p[0], p[1]).distance(Point::new(q[0], q[1]));
            assert!(d <= tolerance, "{d} > {tolerance} at {p:?}");
        }
    }

    /// The farthest point of one sweep is that of the two sweeps over the points put into
    /// the band (the largest square, then the exact distances of those within rounding of
    /// it), on runs long enough to be cut into parallel pieces, with displacements growing,
    /// shrinking and at the band's edge, where rounding makes the candidates many.
    #[test]
    fn farthest_is_the_largest_distance_of_the_points_put_into_the_band() {
        let n = 2 * PARALLEL_FROM + 123;
        let pts: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let t = i as f64 * 1e-3;
                [1e3 * t.cos(), 7e2 * t.sin() + 3.0]
            })
            .collect();
        let tolerance = 0.05;
        let shapes: [&dyn Fn(usize) -> f64; 4] = [
            &|i| i as f64 / n as f64,
            &|i| 1.0 - i as f64 / n as f64,
            &|i| 0.5 + 0.5 * (i as f64 * 0.37).sin(),
            &|i| {
                if i % 3 == 0 {
                    1.0
                } else {
                    1.0 - 1e-15 * (i % 7) as f64
                }
            },
        ];
        for length in shapes {
            let r: Vec<f64> = (0..n)
                .flat_map(|i| {
                    let a = i as f64 * 0.011;
                    [length(i) * a.cos(), length(i) * a.sin()]
                })
                .collect();
            let shape = into_band(&pts, &r, tolerance);
            let square = |i: usize| {
                (0..2)
                    .map(|a| (shape[i][a] - pts[i][a]).powi(2))
                    .sum::<f64>()
            };
            let top = (0..n).map(square).fold(0.0_f64, f64::max);
            let expected = (0..n)
                .filter(|&i| square(i) >= top * (1.0 - 1e-12))
                .map(|i| distance(&shape[i], &pts[i]))
                .fold(0.0_f64, f64::max);
            assert_eq!(farthest(&pts, &r, tolerance).to_bits(), expected.to_bits());
        }
    }
}
