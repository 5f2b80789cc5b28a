//! The structured interior-point solver of `band`.
//!
//! In units of the tolerance `D` (the band is the unit ball around every input point `a_i`),
//! and relative to a smooth reference `s` (the previous pass's result, or the input averaged
//! for the first pass), the unknowns are `y = x − s` and the problem is
//!
//! ```text
//! minimise  f(y) = E(s + y) = E(s) + 2 (A s)ᵀ y + yᵀ A y        (E(x) = xᵀ A x)
//! subject to g_i(y) = |y_i − c_i|² − 1 ≤ 0   for every point i not held (c = a − s),
//!            y_i = c_i                      for every held point,
//! ```
//!
//! Working relative to a smooth `s` keeps the numbers small: for dense noisy data `E(a)` is
//! orders of magnitude above the optimum, and `E(a) + 2(Aa)ᵀr + rᵀAr` would cancel away the
//! digits the stopping rule needs.
//!
//! This is a convex quadratically constrained program with the same feasible set as the second-order
//! cones `|q_i − p_i| ≤ D`. It is solved by a feasible primal-dual interior-point method
//! with Mehrotra's predictor-corrector (Nocedal & Wright, *Numerical Optimization*, §14.2 and
//! §19.3): with slacks `σ_i` (`h_i + σ_i = 0`, `h_i = |y_i − c_i|² − 1`) and multipliers
//! `λ_i`, each iteration linearises the conditions `∇f + Σ λ_i ∇h_i = 0`, `h + σ = 0`,
//! `λ_i σ_i = μ`, takes an affine predictor step (target `μ = 0`), picks the centring
//! `(μ_aff / μ)³` from how far it got, and takes the corrected step, 99 % of the way to the
//! boundary of `λ, σ > 0` and of the longest step that keeps every point inside its ball
//! with a thousandth of its slack ([`ball_step`]). The multipliers start centred, at a gap
//! equal to the objective's scale.
//! Every iterate is feasible, so the slack is recomputed as `σ_i = −h_i` and the constraint
//! residual `h + σ` is zero; the corrector's constraint target carries the second-order term
//! `|Δy_i|²` of the predictor instead (see [`direction`]).
//!
//! Eliminating `Δλ` and `Δσ` leaves one symmetric positive definite system per direction
//! (see [`direction`]), `(2A + Σ_i [2λ_i I + (4λ_i / σ_i) r_i r_iᵀ]) Δy = …`,
//!
//! where the constraint terms are one D×D block per point on the diagonal: the matrix has the
//! band of `A` (half-bandwidth `4D − 1` in the interleaved numbering, cyclic for closed
//! curves), so a step is one banded `L D Lᵀ`, O(n). Tiny pivots (the energy has a null space:
//! quadratics in t) are floored by static regularisation and the solve is corrected by a step
//! of iterative refinement against the true matrix (the point form always; the spline form
//! when a pivot was floored, since its factors are otherwise the matrix's own).

use super::design::Design;
use super::energy::Energy;
use crate::error::{Error, Result};
use crate::numeric::{CyclicSymBanded, SymBanded};

/// How far towards the boundary of `λ ≥ 0`, `σ ≥ 0` a step may go.
const STEP_TO_BOUNDARY: f64 = 0.99;
/// The fraction of its slack a point must keep after a step.
const SLACK_KEPT: f64 = 1e-3;
/// The factor by which a step that leaves the band is shortened.
const BACKTRACK: f64 = 0.5;
/// The most shortenings of one step.
const MAX_BACKTRACKS: usize = 60;
/// Consecutive steps shorter than [`MIN_STEP`] before the run stops.
const MAX_STALLS: usize = 3;
/// The objective below which the gap is measured absolutely, per free point (the problem is in
/// units of the tolerance and the spacing, so this is scale-free).
const OBJECTIVE_FLOOR: f64 = 1e-12;
/// The gradient size below which the dual residual is measured absolutely.
const GRADIENT_FLOOR: f64 = 1e-9;
/// Stop when the surrogate duality gap is below this fraction of the objective (or of 1).
pub(super) const GAP_REL: f64 = 1e-9;
/// The same for a pass whose result only gives the next pass its reference (its tangents
/// and the start of its anchor): the energy is right to this fraction, far inside what the
/// next pass's re-weighting changes, and the interior point's last third of iterations,
/// which only add digits, is saved.
pub(super) const INTERMEDIATE_GAP_REL: f64 = 1e-5;
/// The lowest complementarity gap a corrector aims at, as a fraction of the stopping rule's.
const GAP_TARGET_FLOOR: f64 = 0.1;
/// When rounding stops progress, the run still counts as converged if the gap is below this
/// fraction of the objective.
const ACCEPT_GAP_REL: f64 = 1e-6;
/// A step shorter than this (after the step to the boundary and the shortening that keeps
/// every point inside) makes no progress.
const MIN_STEP: f64 = 1e-10;
/// Stop when the dual residual is below this fraction of the size of its terms.
const DUAL_RESIDUAL_REL: f64 = 1e-9;
/// Static regularisation of the Newton matrix, relative to its largest diagonal entry.
const REGULARIZATION_REL: f64 = 1e-13;
/// Iterative refinement stops when the Newton residual is below this fraction of the
/// right-hand side.
const REFINEMENT_REL: f64 = 1e-10;
/// How far from its input point (in tolerances) each point starts.
const START_RADIUS: f64 = 0.9;
/// The most refinement steps per Newton step.
const MAX_REFINEMENTS: usize = 2;
/// Creeping: once the gap meets the stopping rule, a dual residual within this factor of its
/// bound that has not fallen below [`CREEP_PROGRESS`] of itself over [`CREEP_WINDOW`]
/// iterations ends the run as converged (see [`solve_all`]).
const CREEP_FACTOR: f64 = 10.0;
/// See [`CREEP_FACTOR`].
const CREEP_WINDOW: usize = 10;
/// See [`CREEP_FACTOR`].
const CREEP_PROGRESS: f64 = 0.5;

/// What [`solve`] needs.
#[derive(Debug)]
pub(super) struct Problem<'a, const D: usize> {
    /// The energy `E(x) = xᵀ A x`.
    pub energy: &'a Energy<D>,
    /// `A s`: the energy's matrix applied to the reference.
    pub anchor: Vec<f64>,
    /// `E(s)`.
    pub anchor_energy: f64,
    /// How the unknowns give the points (`B`; the identity in the point form).
    pub design: &'a Design,
    /// The ball centres `c = a − B s`, flat, one per point.
    pub centres: Vec<f64>,
    /// Unknowns that may not move (points in the point form, control points in the spline
    /// form).
    pub held: &'a [bool],
    /// Points without a band constraint: the held points, which sit on their input points.
    pub pinned: &'a [bool],
    /// A strictly feasible start (unknowns relative to the reference, held ones at their
    /// values); `None` in the point form, which moves each point into its ball.
    pub start: Option<Vec<f64>>,
    /// Newton steps allowed.
    pub max_iterations: usize,
    /// The stopping rule: the surrogate duality gap relative to `max(f, 1)` ([`GAP_REL`],
    /// or [`INTERMEDIATE_GAP_REL`] for a pass that is not the last).
    pub gap_rel: f64,
    /// Weights `μ_i` of the data term `Σ μ_i |y_i − c_i|²` added to the objective, one per
    /// point (empty: none).
    pub fidelity: Vec<f64>,
}

/// What [`solve`] found.
#[derive(Clone, Debug)]
pub(super) struct Solution {
    /// Displacements from the input, `B y − c`, in units of the tolerance, flat (`D` numbers a
    /// point).
    pub r: Vec<f64>,
    /// The unknowns relative to the reference, `y`.
    pub y: Vec<f64>,
    /// The objective `f(r)`.
    pub objective: f64,
    /// Newton steps taken.
    pub iterations: usize,
    /// The final surrogate duality gap relative to `max(f, 1)`.
    pub gap: f64,
    /// Whether the stopping rule was met (else the iteration limit stopped it).
    pub converged: bool,
    /// The multipliers `λ_i` of the band constraints (0 for held points): with them, weak
    /// duality bounds the optimum from below (the tests' certificate). Test builds only: the
    /// working set's would be a vector of every point, scattered into at each pass (about
    /// 4 ms of page faults a pass at 10⁶ points) for nothing the method reads.
    #[cfg(test)]
    pub multipliers: Vec<f64>,
}

/// The Newton matrix: the energy's part assembled once, the constraint blocks added per step.
enum Newton {
    /// `exact`: the last factorisation floored no pivot (see [`Newton::is_exact`]).
    Open {
        base: SymBanded,
        work: SymBanded,
        exact: bool,
        /// No unknown is held: `base` is `2A` itself.
        plain: bool,
    },
    Closed {
        work: Option<CyclicSymBanded>,
    },
}

impl Newton {
    /// The Newton matrix's energy part, and the largest row sum of `|A|` (of every entry,
    /// held or not), from one traversal of the energy's entries where the matrix is
    /// assembled (open): its entries `2A` halved are `A`'s exactly.
    fn new<const D: usize>(energy: &Energy<D>, held: &[bool]) -> (Newton, f64) {
        // `held` is per unknown.
        let dim = energy.n * D;
        let bw = 4 * D - 1;
        let mut rows = vec![0.0_f64; dim];
        let mut add_abs = |r: usize, c: usize, v: f64| {
            rows[r] += v.abs();
            if r != c {
                rows[c] += v.abs();
            }
        };
        if energy.closed {
            energy.for_each_lower(1.0, add_abs);
            return (Newton::Closed { work: None }, norm_inf(&rows));
        }
        let mut base = SymBanded::zeros(dim, bw);
        energy.for_each_lower(2.0, |r, c, v| {
            if !held[r / D] && !held[c / D] {
                base.add(r, c, v);
            }
            add_abs(r, c, 0.5 * v);
        });
        for (i, _) in held.iter().enumerate().filter(|(_, h)| **h) {
            for a in 0..D {
                base.add(i * D + a, i * D + a, 1.0);
            }
        }
        let work = base.clone();
        let newton = Newton::Open {
            base,
            work,
            exact: false,
            plain: !held.iter().any(|h| *h),
        };
        (newton, norm_inf(&rows))
    }

    /// `out += A x`: from the assembled band `2A` when it is the energy's own (open, nothing
    /// held), which reads 8 numbers a row where the energy's windows (three to seven a knot
    /// span in the spline form) read 9 each; from the windows otherwise.
    fn energy_apply_add<const D: usize>(&self, energy: &Energy<D>, x: &[f64], out: &mut [f64]) {
        match self {
            Newton::Open {
                base, plain: true, ..
            } => base.mul_add(x, 0.5, out),
            _ => energy.apply_add(x, out),
        }
    }

    /// Assemble `2A + Bᵀ blocks B` (`blocks[i]` the D×D block of point i) and factorise it.
    fn factorize<const D: usize>(
        &mut self,
        p: &Problem<'_, D>,
        blocks: &[[[f64; D]; D]],
    ) -> Result<()> {
        let (energy, held) = (p.energy, p.held);
        match self {
            Newton::Open {
                base, work, exact, ..
            } => {
                let top = match p.design {
                    Design::Spline(map) => {
                        map.add_blocks_open::<D>(blocks, p.pinned, held, base, work)
                    }
                    Design::Points { .. } => {
                        work.assign(base);
                        p.design
                            .for_each_block_lower::<D>(blocks, p.pinned, |r, c, v| {
                                if !held[r / D] && !held[c / D] {
                                    work.add(r, c, v);
                                }
                            });
                        let mut top = 0.0_f64;
                        for k in 0..work.n() {
                            top = top.max(work.get(k, k));
                        }
                        top
                    }
                };
                *exact = work.factorize_regularized_split(REGULARIZATION_REL * top)? == 0;
            }
            Newton::Closed { work } => {
                let dim = energy.n * D;
                let mut m = CyclicSymBanded::zeros(dim, 4 * D - 1);
                energy.for_each_lower(2.0, |r, c, v| m.add(r, c, v));
                let mut top = 0.0_f64;
                p.design
                    .for_each_block_lower::<D>(blocks, p.pinned, |r, c, v| m.add(r, c, v));
                for k in 0..dim {
                    top = top.max(m.get(k, k));
                }
                for k in 0..dim {
                    m.add(k, k, REGULARIZATION_REL * top);
                }
                m.factorize()?;
                *work = Some(m);
            }
        }
        Ok(())
    }

    /// Whether the factors are those of the Newton matrix itself: open, and no pivot floored
    /// by the static regularisation, which is what iterative refinement corrects.
    fn is_exact(&self) -> bool {
        matches!(self, Newton::Open { exact: true, .. })
    }

    fn solve(&self, rhs: &mut [f64]) -> Result<()> {
        match self {
            Newton::Open { work, .. } => work.solve_in_place(rhs),
            Newton::Closed { work } => match work {
                Some(m) => m.solve_in_place(rhs),
                None => Err(Error::InvalidParameter {
                    name: "band".into(),
                    reason: "Newton solve before factorisation".into(),
                }),
            },
        }
    }
}

/// `out = K v` for the true Newton matrix `K = 2A + Bᵀ blocks B` (held rows: the identity);
/// `work` is a point-sized buffer.
fn newton_apply<const D: usize>(
    p: &Problem<'_, D>,
    blocks: &[[[f64; D]; D]],
    v: &[f64],
    work: &mut [f64],
    out: &mut [f64],
) {
    out.fill(0.0);
    p.energy.apply_add(v, out);
    for o in out.iter_mut() {
        *o *= 2.0;
    }
    p.design
        .apply_blocks_add::<D>(blocks, p.pinned, v, work, out);
    for (k, o) in out.iter_mut().enumerate() {
        if p.held[k / D] {
            *o = v[k];
        }
    }
}

/// `h = |r|² − 1`: the constraint, negative strictly inside the ball.
#[inline]
fn constraint(r: &[f64]) -> f64 {
    r.iter().map(|x| x * x).sum::<f64>() - 1.0
}

fn norm_inf(v: &[f64]) -> f64 {
    v.iter().fold(0.0_f64, |m, x| m.max(x.abs()))
}

/// The starting point: each point moved from the reference towards its input point until it
/// is at most [`START_RADIUS`] from it, so that every constraint holds strictly.
fn start<const D: usize>(centres: &[f64], held: &[bool]) -> Vec<f64> {
    let mut y = vec![0.0; centres.len()];
    for (i, h) in held.iter().enumerate() {
        let c = &centres[i * D..(i + 1) * D];
        let len = c.iter().map(|v| v * v).sum::<f64>().sqrt();
        let theta = if *h {
            1.0
        } else if len > START_RADIUS {
            1.0 - START_RADIUS / len
        } else {
            0.0
        };
        for a in 0..D {
            y[i * D + a] = theta * c[a];
        }
    }
    y
}

/// Whether the step `α Δy` keeps every free point strictly inside the band, with at least
/// `1 − STEP_TO_BOUNDARY` of its slack.
fn inside<const D: usize>(st: &State<D>, dr: &[f64], alpha: f64, pinned: &[bool]) -> bool {
    (0..pinned.len()).all(|i| {
        if pinned[i] {
            return true;
        }
        let mut trial = [0.0; D];
        for a in 0..D {
            trial[a] = st.off[i * D + a] + alpha * dr[i * D + a];
        }
        -constraint(&trial) >= SLACK_KEPT * st.sig[i]
    })
}

/// The longest step along `Δr` that keeps every free point inside the band with at least
/// [`SLACK_KEPT`] of its slack: per point the larger root of the quadratic
/// `|r + α Δr|² = 1 − SLACK_KEPT·σ` (`a α² + b α + c = 0` with `c < 0` at a strictly feasible
/// iterate, so the roots have opposite signs), in the form that does not cancel. Infinite
/// when no point moves; 0 when rounding has left a point without that slack.
fn ball_step<const D: usize>(st: &State<D>, dr: &[f64], pinned: &[bool]) -> f64 {
    let mut longest = f64::INFINITY;
    for i in (0..pinned.len()).filter(|&i| !pinned[i]) {
        let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
        for k in 0..D {
            let (o, d) = (st.off[i * D + k], dr[i * D + k]);
            a += d * d;
            b += 2.0 * o * d;
            c += o * o;
        }
        c -= 1.0 - SLACK_KEPT * st.sig[i];
        if a == 0.0 {
            continue;
        }
        if c >= 0.0 {
            return 0.0;
        }
        let root = (b * b - 4.0 * a * c).sqrt();
        let alpha = if b >= 0.0 {
            -2.0 * c / (b + root)
        } else {
            (root - b) / (2.0 * a)
        };
        longest = longest.min(alpha);
    }
    longest
}

/// The longest step in `[0, 1]` along `(Δλ, Δσ)` that keeps `λ` and `σ` positive, times
/// [`STEP_TO_BOUNDARY`] when it is limited (1 when it is not).
fn step_length(lam: &[f64], dlam: &[f64], sig: &[f64], dsig: &[f64], held: &[bool]) -> f64 {
    let mut longest = f64::INFINITY;
    for i in 0..lam.len() {
        if held[i] {
            continue;
        }
        if dlam[i] < 0.0 {
            longest = longest.min(-lam[i] / dlam[i]);
        }
        if dsig[i] < 0.0 {
            longest = longest.min(-sig[i] / dsig[i]);
        }
    }
    (STEP_TO_BOUNDARY * longest).min(1.0)
}

/// The working arrays of one run.
struct State<const D: usize> {
    y: Vec<f64>,
    /// `B y − c`: the displacement from the input point, in tolerances.
    off: Vec<f64>,
    lam: Vec<f64>,
    /// The slacks `σ_i = −h_i` at feasibility, kept as variables so that a point close to the
    /// band's edge keeps its digits.
    sig: Vec<f64>,
}

/// Solve the band problem: the spline form on a working set of its points
/// (`working_set.rs`), the point form directly.
///
/// # Errors
/// [`Error::Singular`] if a Newton matrix has non-finite entries (it cannot happen for
/// finite input).
pub(super) fn solve<const D: usize>(p: &Problem<'_, D>) -> Result<Solution> {
    match (p.design, &p.start) {
        (Design::Spline(map), Some(start)) => super::working_set::solve(p, map, start),
        _ => solve_all(p),
    }
}

/// Solve the band problem with every point's constraint in every iteration.
///
/// # Errors
/// As [`solve`].
pub(super) fn solve_all<const D: usize>(p: &Problem<'_, D>) -> Result<Solution> {
    solve_all_checked(p, |_| false)
}

/// The relative gaps at which [`solve_all_checked`] asks whether to go on, from the first:
/// at 1e-1 the iterate mostly tells already which points will leave their balls, and a round
/// that must be followed by another ends sooner (#14's 10⁶-point sine: 89 iterations with the
/// check at 1e-2 alone, 79 with it at 1e-1 alone); where it does not tell yet, the check at
/// 1e-2 still ends the round before its last iterations (at 3e-1 alone the sine took 99: a
/// check before any point is outside let a round run to its end).
pub(super) const CHECK_GAPS_REL: [f64; 2] = [1e-1, 1e-2];

/// [`solve_all`], asking `stop(y)` once for each of [`CHECK_GAPS_REL`] the relative gap falls
/// below (once when one step passes several), whether the run should end there (not
/// converged) instead.
pub(super) fn solve_all_checked<const D: usize>(
    p: &Problem<'_, D>,
    mut stop: impl FnMut(&[f64]) -> bool,
) -> Result<Solution> {
    // The checks not yet asked.
    let mut checks = CHECK_GAPS_REL.iter().peekable();
    let mut ipm = Ipm::start(p)?;
    let free = ipm.free;
    let mut iterations = 0;
    let mut converged = free == 0;
    let mut last_gap = 0.0;
    let mut stalls = 0;
    // Where a creep began: the iteration and the dual residual's ratio to its bound.
    let mut creep: Option<(usize, f64)> = None;
    // Nothing to solve when every point is held.
    while free > 0 && iterations <= p.max_iterations {
        let Residuals {
            gap,
            scale,
            dual_ratio,
        } = ipm.residuals();
        last_gap = gap / scale;
        let gap_ok = gap <= p.gap_rel * scale;
        if !gap_ok && checks.next_if(|c| gap <= **c * scale).is_some() {
            while checks.next_if(|c| gap <= **c * scale).is_some() {}
            if stop(&ipm.st.y) {
                break;
            }
        }
        if gap_ok && dual_ratio <= 1.0 {
            converged = true;
            break;
        }
        // The gap is met and the dual residual creeps just above its bound: rounding at the
        // band's edge cuts every step short (a turned noisy helix's debiasing stage took 200
        // iterations from 1.3 to 1.29 times the bound). The objective is right to the gap.
        if gap_ok && dual_ratio <= CREEP_FACTOR {
            match creep {
                Some((from, ratio)) if iterations >= from + CREEP_WINDOW => {
                    if dual_ratio > CREEP_PROGRESS * ratio {
                        converged = true;
                        break;
                    }
                    creep = Some((iterations, dual_ratio));
                }
                Some(_) => {}
                None => creep = Some((iterations, dual_ratio)),
            }
        } else {
            creep = None;
        }
        if iterations >= p.max_iterations {
            break;
        }
        iterations += 1;
        let mu = gap / free as f64;

        // The iterate is strictly feasible at every step: if rounding makes the Newton system
        // unusable (a non-finite pivot or direction, possible only near the end when many
        // multipliers and slacks are both tiny), the run stops there with what it has.
        if ipm.factorize().is_err() {
            break;
        }
        let Ok((alpha_aff, gap_aff)) = ipm.predictor() else {
            break;
        };
        let centring = (gap_aff / gap).clamp(0.0, 1.0).powi(3);
        // The gap aimed at: Mehrotra's, but not below a tenth of the stopping rule's. Once the
        // gap meets the rule, what is left is the dual residual, which full steps at the same
        // gap remove; pushing the gap on towards zero instead makes the Newton matrix
        // singular (λ/σ without bound at the band's edge), and the residual then stays where
        // rounding leaves it while the points drift along the energy's flattest directions.
        let target = (centring * mu).max(GAP_TARGET_FLOOR * p.gap_rel * scale / free as f64);
        if ipm.corrector(alpha_aff, target).is_err() {
            break;
        }
        let alpha = ipm.step_size();
        if alpha < MIN_STEP {
            stalls += 1;
            if stalls >= MAX_STALLS {
                break;
            }
        } else {
            stalls = 0;
        }
        ipm.advance(alpha);
    }
    // Stopped short of the stopping rule (by rounding): still counts as converged when the
    // gap is small enough for the objective to be right to `ACCEPT_GAP_REL` (or to the
    // problem's own rule, when that is looser).
    converged |= last_gap <= ACCEPT_GAP_REL.max(p.gap_rel);
    Ok(ipm.finish(iterations, last_gap, converged))
}

/// The data term's weight `μ_i` of point `i` (0 without a data term).
fn weight<const D: usize>(p: &Problem<'_, D>, i: usize) -> f64 {
    p.fidelity.get(i).copied().unwrap_or(0.0)
}

/// The objective at `y` (`ay = A y`, `off = B y − c`).
fn objective<const D: usize>(p: &Problem<'_, D>, y: &[f64], ay: &[f64], off: &[f64]) -> f64 {
    let quad: f64 = y.iter().zip(ay).map(|(x, v)| x * v).sum();
    let lin: f64 = y.iter().zip(&p.anchor).map(|(x, v)| x * v).sum();
    let data: f64 = off
        .iter()
        .enumerate()
        .map(|(k, r)| weight(p, k / D) * r * r)
        .sum();
    p.anchor_energy + 2.0 * lin + quad + data
}

/// What the residuals of an iterate say: the duality gap, the objective's scale it is
/// measured against, and the dual residual against its bound.
struct Residuals {
    gap: f64,
    scale: f64,
    /// The dual residual against its bound (at most 1: at its rounding floor).
    dual_ratio: f64,
}

/// One run of the interior-point method: the iterate and the arrays every iteration reuses.
struct Ipm<'p, 'a, const D: usize> {
    p: &'p Problem<'a, D>,
    /// `n` points (constraints), `dim` unknowns.
    n: usize,
    dim: usize,
    /// The points with a band constraint.
    free: usize,
    /// The largest row sum of `|A|`.
    a_abs: f64,
    st: State<D>,
    newton: Newton,
    blocks: Vec<[[f64; D]; D]>,
    ay: Vec<f64>,
    grad: Vec<f64>,
    rd: Vec<f64>,
    rc: Vec<f64>,
    rp: Vec<f64>,
    dy: Vec<f64>,
    dr: Vec<f64>,
    dlam: Vec<f64>,
    dsig: Vec<f64>,
    work: Work,
    /// The constraint and data terms of the dual residual, per point.
    pull: Vec<f64>,
}

impl<'p, 'a, const D: usize> Ipm<'p, 'a, D> {
    /// The start: strictly inside the band, multipliers centred at the objective's scale.
    fn start(p: &'p Problem<'a, D>) -> Result<Ipm<'p, 'a, D>> {
        let energy = p.energy;
        let design = p.design;
        let n = design.points();
        let dim = design.vars() * D;
        let (held, pinned) = (p.held, p.pinned);
        let free = pinned.iter().filter(|h| !**h).count();
        let y = match &p.start {
            Some(y) => y.clone(),
            None => start::<D>(&p.centres, pinned),
        };
        let mut off = vec![0.0; n * D];
        design.residual::<D>(&y, &p.centres, None, &mut off);
        let sig: Vec<f64> = (0..n)
            .map(|i| {
                if pinned[i] {
                    1.0
                } else {
                    -constraint(&off[i * D..(i + 1) * D])
                }
            })
            .collect();
        if sig.iter().any(|s| *s <= 0.0) {
            return Err(Error::InvalidParameter {
                name: "band".into(),
                reason: "the solver's start is not strictly inside the band".into(),
            });
        }
        // Centred at a gap equal to the objective's scale: `λ_i σ_i = f / free` (in the
        // stopping rule's measure, `max(|f|, floor)`), so that the first steps work on the
        // gap and the dual residual together. Multipliers of 1 (the first version) put the
        // relative gap at 10–100 on dense runs, where the first five steps only brought it
        // back: 13 816 → 10 855 iterations on the dense quality split (results unchanged).
        let lam = {
            let mut ay = vec![0.0; dim];
            energy.apply_add(&y, &mut ay);
            let scale = objective(p, &y, &ay, &off)
                .abs()
                .max(OBJECTIVE_FLOOR * free as f64);
            let mu = scale / free.max(1) as f64;
            (0..n)
                .map(|i| if pinned[i] { 0.0 } else { mu / sig[i] })
                .collect()
        };
        let st = State::<D> { y, off, lam, sig };
        let (newton, a_abs) = Newton::new(energy, held);
        Ok(Ipm {
            p,
            n,
            dim,
            free,
            a_abs,
            st,
            newton,
            blocks: vec![[[0.0; D]; D]; n],
            ay: vec![0.0; dim],
            grad: vec![0.0; dim],
            rd: vec![0.0; dim],
            rc: vec![0.0; n],
            rp: vec![0.0; n],
            dy: vec![0.0; dim],
            dr: vec![0.0; n * D],
            dlam: vec![0.0; n],
            dsig: vec![0.0; n],
            work: Work {
                vars: vec![0.0; dim],
                points: vec![0.0; n * D],
                rhs: vec![0.0; dim],
            },
            pull: vec![0.0; n * D],
        })
    }

    /// The residuals at (y, λ, σ): the dual residual `rd` and the gap, for the stopping test.
    fn residuals(&mut self) -> Residuals {
        let p = self.p;
        let (n, dim) = (self.n, self.dim);
        let (held, pinned) = (p.held, p.pinned);
        let st = &mut self.st;
        self.ay.fill(0.0);
        self.newton.energy_apply_add(p.energy, &st.y, &mut self.ay);
        for k in 0..dim {
            self.grad[k] = 2.0 * (self.ay[k] + p.anchor[k]);
        }
        let mut gap = 0.0;
        for i in 0..n {
            if pinned[i] {
                for a in 0..D {
                    self.pull[i * D + a] = 0.0;
                }
                continue;
            }
            // Every iterate is strictly inside the band (the step below keeps it there), so
            // the slack is the constraint's own value and the primal residual is zero.
            st.sig[i] = -constraint(&st.off[i * D..(i + 1) * D]);
            gap += st.lam[i] * st.sig[i];
            for a in 0..D {
                let k = i * D + a;
                self.pull[k] = 2.0 * (st.lam[i] + weight(p, i)) * st.off[k];
            }
        }
        self.rd.copy_from_slice(&self.grad);
        p.design.eval_t_add::<D>(&self.pull, &mut self.rd);
        for (k, r) in self.rd.iter_mut().enumerate() {
            if held[k / D] {
                *r = 0.0;
            }
        }
        let f = objective(p, &st.y, &self.ay, &st.off);
        let scale = f.abs().max(OBJECTIVE_FLOOR * self.free as f64);
        // The dual residual is measured against the size of the terms that make it up
        // (`|A| |y|` bounds the rounding of `A y`), so that its rounding floor counts as zero.
        let terms = (2.0 * self.a_abs * norm_inf(&st.y))
            .max(2.0 * norm_inf(&p.anchor))
            .max(norm_inf(&self.grad))
            .max(GRADIENT_FLOOR);
        let dual_ratio = norm_inf(&self.rd) / (DUAL_RESIDUAL_REL * terms);
        Residuals {
            gap,
            scale,
            dual_ratio,
        }
    }

    /// The Newton matrix `2A + Σ [2λ_i I + (4λ_i/σ_i) r_i r_iᵀ]`, factorised once for both
    /// the predictor and the corrector.
    fn factorize(&mut self) -> Result<()> {
        let p = self.p;
        let pinned = p.pinned;
        let st = &self.st;
        for i in 0..self.n {
            self.blocks[i] = [[0.0; D]; D];
            if pinned[i] {
                continue;
            }
            let w = 4.0 * st.lam[i] / st.sig[i];
            for a in 0..D {
                for c in 0..D {
                    let id = if a == c {
                        2.0 * (st.lam[i] + weight(p, i))
                    } else {
                        0.0
                    };
                    self.blocks[i][a][c] = id + w * st.off[i * D + a] * st.off[i * D + c];
                }
            }
        }
        self.newton.factorize(p, &self.blocks)
    }

    /// The Newton direction for the current `rp` and `rc`, into `dy`, `dr`, `dlam`, `dsig`.
    fn direction(&mut self) -> Result<()> {
        let mut step = Step {
            dy: &mut self.dy,
            dr: &mut self.dr,
            dlam: &mut self.dlam,
            dsig: &mut self.dsig,
        };
        direction(
            self.p,
            &self.newton,
            &self.blocks,
            &self.st,
            &self.rd,
            &self.rp,
            &self.rc,
            &mut step,
            &mut self.work,
        )
    }

    /// Predictor (affine scaling): complementarity target 0, constraint target 0. Its step
    /// length and the gap it would reach.
    fn predictor(&mut self) -> Result<(f64, f64)> {
        let pinned = self.p.pinned;
        for i in 0..self.n {
            self.rc[i] = if pinned[i] {
                0.0
            } else {
                self.st.lam[i] * self.st.sig[i]
            };
        }
        self.rp.fill(0.0);
        self.direction()?;
        let st = &self.st;
        let (dlam, dsig) = (&self.dlam, &self.dsig);
        let alpha_aff = step_length(&st.lam, dlam, &st.sig, dsig, pinned);
        let mut gap_aff = 0.0;
        for i in 0..self.n {
            if !pinned[i] {
                gap_aff += (st.lam[i] + alpha_aff * dlam[i]) * (st.sig[i] + alpha_aff * dsig[i]);
            }
        }
        Ok((alpha_aff, gap_aff))
    }

    /// Corrector: the second-order terms of the predictor, centred at `target`. Two of them:
    /// `Δλ Δσ` in the complementarity (Mehrotra) and `|Δr|²` in the constraint, which is what
    /// a point sliding along the band's edge loses to the curvature of the edge (without it
    /// such a step leaves the band and is cut short).
    fn corrector(&mut self, alpha_aff: f64, target: f64) -> Result<()> {
        let pinned = self.p.pinned;
        let st = &self.st;
        for i in 0..self.n {
            if pinned[i] {
                self.rc[i] = 0.0;
                self.rp[i] = 0.0;
                continue;
            }
            self.rc[i] = st.lam[i] * st.sig[i] + self.dlam[i] * self.dsig[i] - target;
            let slide: f64 = (0..D)
                .map(|a| self.dr[i * D + a] * self.dr[i * D + a])
                .sum();
            self.rp[i] = alpha_aff * slide;
        }
        self.direction()
    }

    /// The step along the direction: to the boundary of the linearised slack, shortened until
    /// every point keeps at least a fraction of its slack (0 when backtracking gives up).
    fn step_size(&self) -> f64 {
        let pinned = self.p.pinned;
        let st = &self.st;
        // The constraints are curved: a point sliding along the band's edge leaves it at
        // second order, so the linearised slack's step can leave the band. The step is also
        // at most the part [`STEP_TO_BOUNDARY`] of the longest that keeps every point inside
        // with [`SLACK_KEPT`] of its slack ([`ball_step`], exact), and only rounding can leave
        // it to the shortening below. (Halving the step until it fitted, the first version,
        // cut the middle steps to a third: 127 → 110 iterations on #14's sine.)
        let mut alpha = step_length(&st.lam, &self.dlam, &st.sig, &self.dsig, pinned)
            .min(STEP_TO_BOUNDARY * ball_step::<D>(st, &self.dr, pinned));
        let mut tries = 0;
        while tries < MAX_BACKTRACKS && !inside(st, &self.dr, alpha, pinned) {
            alpha *= BACKTRACK;
            tries += 1;
        }
        if tries == MAX_BACKTRACKS {
            alpha = 0.0;
        }
        alpha
    }

    /// Take the step `alpha` along the direction.
    fn advance(&mut self, alpha: f64) {
        let pinned = self.p.pinned;
        let st = &mut self.st;
        for k in 0..self.dim {
            st.y[k] += alpha * self.dy[k];
        }
        for (o, d) in st.off.iter_mut().zip(&self.dr) {
            *o += alpha * d;
        }
        for i in 0..self.n {
            if !pinned[i] {
                st.lam[i] += alpha * self.dlam[i];
                st.sig[i] += alpha * self.dsig[i];
            }
        }
    }

    /// The solution at the last iterate.
    fn finish(mut self, iterations: usize, gap: f64, converged: bool) -> Solution {
        let p = self.p;
        let pinned = p.pinned;
        let mut st = self.st;
        self.ay.fill(0.0);
        p.energy.apply_add(&st.y, &mut self.ay);
        // Pinned points sit on their input points by definition; in the spline form the
        // displacement accumulated over the steps can carry rounding (1e-13 tolerances seen).
        for (i, _) in pinned.iter().enumerate().filter(|(_, p)| **p) {
            st.off[i * D..(i + 1) * D].fill(0.0);
        }
        let objective = objective(p, &st.y, &self.ay, &st.off);
        Solution {
            r: st.off,
            y: st.y,
            objective,
            iterations,
            gap,
            converged,
            #[cfg(test)]
            multipliers: st.lam,
        }
    }
}

/// A direction: the unknowns' `Δy`, the points' `Δr = B Δy`, and the multipliers' and
/// slacks' steps.
struct Step<'s> {
    dy: &'s mut [f64],
    dr: &'s mut [f64],
    dlam: &'s mut [f64],
    dsig: &'s mut [f64],
}

/// Scratch buffers of [`direction`].
struct Work {
    vars: Vec<f64>,
    points: Vec<f64>,
    rhs: Vec<f64>,
}

/// One Newton direction for the complementarity residual `rc` (`λ_i σ_i` minus its target):
///
/// ```text
/// K Δy = −r_d − Bᵀ [2 r_i (λ_i r_p,i − r_c,i) / σ_i]_i
/// Δλ_i = (λ_i / σ_i) 2 r_i·(B Δy)_i + (λ_i r_p,i − r_c,i) / σ_i
/// Δσ_i = (−r_c,i − σ_i Δλ_i) / λ_i
/// ```
///
/// with iterative refinement of `Δy` against the unregularised matrix.
#[allow(clippy::too_many_arguments)]
fn direction<const D: usize>(
    p: &Problem<'_, D>,
    newton: &Newton,
    blocks: &[[[f64; D]; D]],
    st: &State<D>,
    rd: &[f64],
    rp: &[f64],
    rc: &[f64],
    step: &mut Step<'_>,
    work: &mut Work,
) -> Result<()> {
    let (held, pinned) = (p.held, p.pinned);
    let n = pinned.len();
    for i in 0..n {
        let t = if pinned[i] {
            0.0
        } else {
            (st.lam[i] * rp[i] - rc[i]) / st.sig[i]
        };
        for a in 0..D {
            let k = i * D + a;
            work.points[k] = -2.0 * st.off[k] * t;
        }
    }
    let rhs = &mut work.rhs;
    for (r, d) in rhs.iter_mut().zip(rd) {
        *r = -d;
    }
    p.design.eval_t_add::<D>(&work.points, rhs);
    for (k, r) in rhs.iter_mut().enumerate() {
        if held[k / D] {
            *r = 0.0;
        }
    }
    let dy = &mut *step.dy;
    dy.copy_from_slice(rhs);
    newton.solve(dy)?;
    // The spline form's factors without a floored pivot are the matrix's own: no refinement
    // (its check alone, a product with the whole matrix, was a fifth of a direction's time,
    // and on #14's 10⁶-point sine it never refined).
    let refinements = if newton.is_exact() && matches!(p.design, Design::Spline(_)) {
        0
    } else {
        MAX_REFINEMENTS
    };
    let rhs_size = if refinements > 0 {
        norm_inf(rhs).max(f64::MIN_POSITIVE)
    } else {
        0.0
    };
    for _ in 0..refinements {
        newton_apply(p, blocks, dy, &mut work.points, &mut work.vars);
        for k in 0..dy.len() {
            work.vars[k] = rhs[k] - work.vars[k];
        }
        if norm_inf(&work.vars) <= REFINEMENT_REL * rhs_size {
            break;
        }
        newton.solve(&mut work.vars)?;
        for k in 0..dy.len() {
            dy[k] += work.vars[k];
        }
    }
    p.design.eval::<D>(dy, step.dr);
    let (dr, dlam, dsig) = (&*step.dr, &mut *step.dlam, &mut *step.dsig);
    for i in 0..n {
        if pinned[i] {
            dlam[i] = 0.0;
            dsig[i] = 0.0;
            continue;
        }
        let odot: f64 = (0..D).map(|a| st.off[i * D + a] * dr[i * D + a]).sum();
        dlam[i] = (st.lam[i] / st.sig[i]) * 2.0 * odot + (st.lam[i] * rp[i] - rc[i]) / st.sig[i];
        dsig[i] = (-rc[i] - st.sig[i] * dlam[i]) / st.lam[i];
    }
    let finite = dy
        .iter()
        .chain(dlam.iter())
        .chain(dsig.iter())
        .all(|v| v.is_finite());
    if !finite {
        return Err(Error::Singular("band: non-finite Newton direction".into()));
    }
    Ok(())
}
