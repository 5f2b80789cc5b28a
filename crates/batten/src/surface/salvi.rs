//! `salvi` for surfaces: P. Salvi and T. Várady, *Local fairing of freeform curves and
//! surfaces* (`../shared/papers/salvi-varady-local-fairing.txt`, the surface section, eqs
//! 12–17), as the spec fixes its details (`../shared/spec/ALGORITHMS.md` §3 "Surface
//! algorithm", §0.6).
//!
//! 1. The principal curvatures κ1 ≥ κ2 are sampled on a uniform grid
//!    ([`super::SampleGrid::with_density`], `samples_per_span` per knot span).
//! 2. The targets g1, g2 are smooth fits of the two fields over the parameter domain with a
//!    squared roughness penalty ([`super::Targets`], the spec's reading of eq 17), computed
//!    once from the unfaired surface.
//! 3. The measure is Π̂ = Σ (κ1 − g1)² + (κ2 − g2)² (eq 15).
//! 4. Each move picks the movable control point with the largest local deviation — the sum
//!    of the residuals over the samples inside its support `supp N_i × supp N_j` — that is not
//!    in the recently-moved list, and minimises the local Π̂ over its 3-D displacement with
//!    Nelder–Mead; the selection and the tabu list are those of the curve version
//!    ([`crate::fair::local::select_candidate`], [`crate::fair::local::RecentList`]).
//! 5. The eq-11 clamp in 3-D ([`crate::fair::local::clamp_to_original`]) keeps every control
//!    point within δ of its **original** position. It is applied inside the objective, so the
//!    simplex searches the ball `|d − d⁰| ≤ δ` and never proposes a point the clamp would move.
//! 6. The simplex starts with edge [`SIMPLEX_STEP_REL`] × the mean distance to the
//!    neighbouring control points. A move is kept only if it lowers Π̂. The run stops when Π̂
//!    is at the rounding floor ([`PI_HAT_FLOOR_REL`]), when a window of as many moves as
//!    there are movable points lowered Π̂ by less than [`STALL_REL_IMPROVEMENT`] of its
//!    value, or after `max_iterations` moves (default [`DEFAULT_MAX_ITERATIONS`]).
//!
//! Moving `d_ij` changes the homogeneous sums of the samples in its support by
//! `w_ij N_i^{(a)} N_j^{(b)} Δd` only, so each trial evaluates the curvature at those samples
//! alone, from cached sums, without re-evaluating the surface.

use std::collections::BTreeMap;
use std::ops::Range;

use serde_json::json;

use super::fairing::{MethodRun, Problem, tabu_length};
use super::patch::{
    BSplineSurface, Homogeneous, SurfaceCurvature, Xyz, curvature_of, distance, rational_derivs,
};
use super::sample::SampleGrid;
use super::target::{TargetParams, Targets};
use crate::error::Result;
use crate::fair::FairStatus;
use crate::fair::local::{RecentList, clamp_to_original, select_candidate, support_ranges};
use crate::numeric::{NelderMeadParams, minimize_nelder_mead};

/// Default move budget.
pub(super) const DEFAULT_MAX_ITERATIONS: usize = 600;

/// The run stops when a window of moves lowers Π̂ by less than this fraction of its value.
pub(super) const STALL_REL_IMPROVEMENT: f64 = 1e-3;

/// Curvature residuals below this fraction of the largest |κ| on the grid are rounding
/// error of the target fit (its solve loses a few digits): a run whose Π̂ is below
/// `N · (PI_HAT_FLOOR_REL · max |κ|)²` (N regular samples) has nothing to fair and stops, so a
/// sphere or a plane comes back bit for bit.
pub(super) const PI_HAT_FLOOR_REL: f64 = 1e-6;

/// Initial simplex edge as a fraction of the mean distance to the neighbouring control
/// points.
pub(super) const SIMPLEX_STEP_REL: f64 = 0.1;

/// Default Nelder–Mead evaluation budget per move.
pub(super) const DEFAULT_SIMPLEX_EVALUATIONS: usize = 120;

/// Nelder–Mead stops when the simplex is smaller than this fraction of its first edge.
pub(super) const SIMPLEX_XATOL_REL: f64 = 1e-4;

/// Parameters of the surface `salvi` method.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub(crate) struct SalviSurfaceParams {
    /// Grid samples per knot span and direction.
    ///
    /// Default value: [`SAMPLES_PER_SPAN`](super::sample::SAMPLES_PER_SPAN).
    pub samples_per_span: usize,
    /// How the targets are fitted.
    ///
    /// Default value: [`TargetParams::DEFAULT`].
    pub targets: TargetParams,
    /// Nelder–Mead evaluations per move.
    ///
    /// Default value: [`DEFAULT_SIMPLEX_EVALUATIONS`].
    pub simplex_evaluations: usize,
}

impl SalviSurfaceParams {
    /// The defaults written on the fields (the `--set` declarations of `fairing.rs` read to
    /// them; a test checks it).
    #[cfg(test)]
    pub(crate) const DEFAULT: SalviSurfaceParams = SalviSurfaceParams {
        samples_per_span: super::sample::SAMPLES_PER_SPAN,
        targets: TargetParams::DEFAULT,
        simplex_evaluations: DEFAULT_SIMPLEX_EVALUATIONS,
    };
}

/// The cached state of a run.
struct State<'a> {
    nv: usize,
    n_sv: usize,
    weights: Option<&'a [f64]>,
    /// Basis values at each u sample: first index and values `[d][a]`.
    bu: Vec<super::patch::Basis1>,
    bv: Vec<super::patch::Basis1>,
    range_u: Vec<Range<usize>>,
    range_v: Vec<Range<usize>>,
    homog: Vec<Homogeneous>,
    residual: Vec<f64>,
    valid: Vec<bool>,
    targets: &'a Targets,
}

impl State<'_> {
    /// `w_ij N_i^{(a)}(u_s) N_j^{(b)}(v_t)` for the six partials, at sample `(s, t)`.
    fn factors(&self, i: usize, j: usize, s: usize, t: usize) -> [f64; 6] {
        let (bu, bv) = (&self.bu[s], &self.bv[t]);
        let (a, b) = (i - bu.first, j - bv.first);
        let w = self.weights.map_or(1.0, |w| w[i * self.nv + j]);
        let mut f = [0.0; 6];
        for (k, &(du, dv)) in super::patch::HOMOGENEOUS_ORDER.iter().enumerate() {
            f[k] = w * bu.values[du][a] * bv.values[dv][b];
        }
        f
    }

    /// The regular samples in the support of `d_ij` with their factors
    /// ([`State::factors`]), computed once per move.
    fn support(&self, i: usize, j: usize) -> Vec<(usize, [f64; 6])> {
        let mut out = Vec::with_capacity(self.range_u[i].len() * self.range_v[j].len());
        for s in self.range_u[i].clone() {
            for t in self.range_v[j].clone() {
                let k = s * self.n_sv + t;
                if self.valid[k] {
                    out.push((k, self.factors(i, j, s, t)));
                }
            }
        }
        out
    }

    /// The local Π̂ over `support` after a move of its control point by `delta` (`+∞` when
    /// the move makes a regular sample singular).
    fn local(&self, support: &[(usize, [f64; 6])], delta: Xyz) -> f64 {
        let mut sum = 0.0;
        for &(k, f) in support {
            let mut h = self.homog[k];
            for (row, fk) in h.iter_mut().zip(f) {
                for c in 0..3 {
                    row[c] += fk * delta[c];
                }
            }
            let Some(c): Option<SurfaceCurvature> = curvature_of(&rational_derivs(&h)) else {
                return f64::INFINITY;
            };
            sum += self.targets.residual(k, Some(&c));
        }
        sum
    }

    /// Apply a move of `d_ij` by `delta` to the cached sums and residuals.
    fn apply(&mut self, i: usize, j: usize, delta: Xyz) {
        for s in self.range_u[i].clone() {
            for t in self.range_v[j].clone() {
                let k = s * self.n_sv + t;
                let f = self.factors(i, j, s, t);
                for (row, fk) in self.homog[k].iter_mut().zip(f) {
                    for c in 0..3 {
                        row[c] += fk * delta[c];
                    }
                }
                if self.valid[k] {
                    let c = curvature_of(&rational_derivs(&self.homog[k]));
                    self.residual[k] = self.targets.residual(k, c.as_ref());
                }
            }
        }
    }

    fn deviation(&self, i: usize, j: usize) -> f64 {
        let mut sum = 0.0;
        for s in self.range_u[i].clone() {
            sum += self.residual
                [s * self.n_sv + self.range_v[j].start..s * self.n_sv + self.range_v[j].end]
                .iter()
                .sum::<f64>();
        }
        sum
    }
}

/// Run the method (called by [`super::fair_surface`]).
pub(crate) fn run(
    p: &Problem<'_>,
    params: &SalviSurfaceParams,
    grid: &SampleGrid,
    targets: &Targets,
) -> Result<MethodRun> {
    let s = p.surface;
    let (nu, nv) = s.size();
    let (mut st, floor) = State::sample(s, grid, targets)?;
    let original = s.control_points().to_vec();
    let mut control = original.clone();
    let max_iter = p.max_iterations.unwrap_or(DEFAULT_MAX_ITERATIONS);
    let n_movable = p.movable.iter().filter(|&&m| m).count();
    let window = n_movable.max(1);
    let tabu = p.common.tabu.unwrap_or(tabu_length(s.degree()));
    let mut recent = RecentList::new(tabu);
    let mut total: f64 = st.residual.iter().sum();
    let mut history = vec![total];
    let (mut moves, mut rejected) = (0, 0);
    let mut status = FairStatus::IterationLimit;
    let mut iterations = 0;
    while iterations < max_iter {
        if total <= floor || n_movable == 0 || p.delta <= 0.0 {
            status = if moves == 0 {
                FairStatus::NoChange
            } else {
                FairStatus::Converged
            };
            break;
        }
        if iterations >= window {
            let before = history[history.len().saturating_sub(window + 1)];
            if before - total < STALL_REL_IMPROVEMENT * before {
                status = FairStatus::Converged;
                break;
            }
        }
        iterations += 1;
        let dev: Vec<f64> = (0..nu * nv).map(|k| st.deviation(k / nv, k % nv)).collect();
        let Some(k) = select_candidate(&dev, &p.movable, &mut recent) else {
            break;
        };
        recent.push(k);
        if st.improve(p, params, &mut control, &original, k) {
            total = st.residual.iter().sum();
            moves += 1;
        } else {
            rejected += 1;
        }
        history.push(total);
    }
    Ok(MethodRun {
        control,
        moves,
        rejected,
        status: Some(status),
        history,
        parameters: run_parameters(params, grid, tabu, max_iter),
    })
}

/// The parameters a run reports.
fn run_parameters(
    params: &SalviSurfaceParams,
    grid: &SampleGrid,
    tabu: usize,
    max_iter: usize,
) -> BTreeMap<String, serde_json::Value> {
    let mut parameters = BTreeMap::new();
    parameters.insert("samples_per_span".into(), json!(params.samples_per_span));
    parameters.insert("samples".into(), json!([grid.u.len(), grid.v.len()]));
    parameters.insert("target_spans".into(), json!(params.targets.spans));
    parameters.insert("smoothing".into(), json!(params.targets.smoothing));
    parameters.insert("robust_passes".into(), json!(params.targets.robust_passes));
    parameters.insert(
        "simplex_evaluations".into(),
        json!(params.simplex_evaluations),
    );
    parameters.insert("tabu".into(), json!(tabu));
    parameters.insert("max_iterations".into(), json!(max_iter));
    parameters
}

impl<'a> State<'a> {
    /// The surface sampled on the grid, with each sample's residual; and the total residual
    /// below which the run stops (curvature at rounding level).
    fn sample(
        s: &'a BSplineSurface,
        grid: &SampleGrid,
        targets: &'a Targets,
    ) -> Result<(State<'a>, f64)> {
        let (nu, nv) = s.size();
        let (du, dv) = s.degree();
        let (ku, kv) = s.knots();
        let range_u = support_ranges(ku, du, nu, &grid.u)?;
        let range_v = support_ranges(kv, dv, nv, &grid.v)?;
        let bu: Vec<_> = grid.u.iter().map(|&u| s.basis_u(u)).collect();
        let bv: Vec<_> = grid.v.iter().map(|&v| s.basis_v(v)).collect();
        let mut homog = Vec::with_capacity(grid.len());
        for b in &bu {
            for c in &bv {
                homog.push(s.homogeneous(b, c, 2));
            }
        }
        let curv: Vec<_> = homog
            .iter()
            .map(|h| curvature_of(&rational_derivs(h)))
            .collect();
        let valid: Vec<bool> = curv.iter().map(Option::is_some).collect();
        let kappa_max = curv
            .iter()
            .flatten()
            .fold(0.0f64, |m, c| m.max(c.kappa1.abs()).max(c.kappa2.abs()));
        let n_valid = valid.iter().filter(|&&v| v).count() as f64;
        let floor = n_valid * (PI_HAT_FLOOR_REL * kappa_max).powi(2);
        let residual: Vec<f64> = curv
            .iter()
            .enumerate()
            .map(|(k, c)| targets.residual(k, c.as_ref()))
            .collect();
        let st = State {
            nv,
            n_sv: grid.v.len(),
            weights: s.weights(),
            bu,
            bv,
            range_u,
            range_v,
            homog,
            residual,
            valid,
            targets,
        };
        Ok((st, floor))
    }

    /// Move control point `k` to where the local simplex search lowers its support's
    /// residual most, within δ of its original place; whether it moved.
    fn improve(
        &mut self,
        p: &Problem<'_>,
        params: &SalviSurfaceParams,
        control: &mut [Xyz],
        original: &[Xyz],
        k: usize,
    ) -> bool {
        let (nu, nv) = p.surface.size();
        let (i, j) = (k / nv, k % nv);
        let here = control[k];
        let orig = original[k];
        let step = SIMPLEX_STEP_REL * neighbour_spacing(control, nu, nv, i, j).unwrap_or(p.delta);
        let target = |d: &Xyz| {
            let (c, _) = clamp_to_original(
                &orig,
                &[here[0] + d[0], here[1] + d[1], here[2] + d[2]],
                p.delta,
            );
            [c[0] - here[0], c[1] - here[1], c[2] - here[2]]
        };
        let support = self.support(i, j);
        let current = self.local(&support, [0.0; 3]);
        let nm = NelderMeadParams::with_scaled_step(step)
            .with_xatol(SIMPLEX_XATOL_REL * step)
            .with_max_evaluations(params.simplex_evaluations);
        let best = minimize_nelder_mead(|d| self.local(&support, target(d)), [0.0; 3], &nm);
        let delta = target(&best.x);
        let value = self.local(&support, delta);
        if value < current && delta != [0.0; 3] {
            self.apply(i, j, delta);
            control[k] = [here[0] + delta[0], here[1] + delta[1], here[2] + delta[2]];
            true
        } else {
            false
        }
    }
}

/// The mean distance from `P_ij` to its (up to four) neighbours in the net; `None` when they
/// all coincide with it (the caller then steps by δ).
pub(crate) fn neighbour_spacing(
    c: &[Xyz],
    nu: usize,
    nv: usize,
    i: usize,
    j: usize,
) -> Option<f64> {
    let here = c[i * nv + j];
    let mut sum = 0.0;
    let mut n = 0;
    let mut add = |ii: usize, jj: usize| {
        sum += distance(here, c[ii * nv + jj]);
        n += 1;
    };
    if i > 0 {
        add(i - 1, j);
    }
    if i + 1 < nu {
        add(i + 1, j);
    }
    if j > 0 {
        add(i, j - 1);
    }
    if j + 1 < nv {
        add(i, j + 1);
    }
    let m = if n > 0 { sum / n as f64 } else { 0.0 };
    (m > 0.0).then_some(m)
}
