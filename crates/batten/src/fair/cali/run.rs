//! The driver of `cali` (docs/algorithms/cali.md §4.5, the paper's Steps 1–5): interpolate, then
//! try the candidates in descending LFI order and accept the first whose move lowers the GFI below
//! τ·GFI within the tolerance, until none does (`docs/algorithms/cali.md`, "The algorithm").

use std::cmp::Reverse;
use std::collections::BTreeSet;

use serde_json::{Map, Value};

use super::indicators::{LocalIndicators, Trial};
use super::{DEGREE, LAMBDA_TOL, TAU};
use crate::error::Result;
use crate::fair::{FairStatus, HistoryRow, Move, Outcome};
use crate::geom::{Point, Vec2};
use crate::spline::{BSplineCurve, MAX_ORDER, Parametrization};

/// Everything the driver needs, parsed and checked.
#[derive(Clone, Copy, Debug)]
pub(super) struct Settings {
    pub(super) tau: f64,
    pub(super) lambda_tol: f64,
    pub(super) degree: usize,
    pub(super) tolerance: Option<f64>,
    pub(super) max_moves: usize,
    /// Control points held at each end (`--fix-ends`).
    pub(super) held_ends: usize,
    /// Reuse candidate results whose dependencies did not change (always on; off only in the
    /// unit test that checks the cache changes nothing).
    pub(super) use_cache: bool,
}

/// A cached candidate evaluation.
#[derive(Clone, Debug)]
struct Cached {
    trial: Trial,
    within_tolerance: bool,
    /// Control-point indices the result depends on (inclusive).
    deps: (usize, usize),
    /// The move counter when it was computed.
    stamp: u64,
}

pub(super) fn run_cali(points: &[Point], s: &Settings) -> Result<Outcome> {
    let (curve, params) =
        BSplineCurve::interpolate(points, s.degree, Parametrization::ChordLength)?;
    // A clamped interpolant has P_0 = Q_0 and P_m = Q_n exactly; the banded solve can leave a
    // rounding error there. Snap them, so the kept end control points are the input's ends.
    let mut ends = curve.control_points().to_vec();
    let last = ends.len() - 1;
    ends[0] = points[0];
    ends[last] = points[last];
    let curve = curve.with_control_points(ends)?;
    let mut state = LocalIndicators::new(&curve)?.with_held_ends(s.held_ends);
    let data = DataSamples::new(&curve, &params, points);

    let mut parameters = Map::new();
    TAU.write(&mut parameters, s.tau);
    LAMBDA_TOL.write(&mut parameters, s.lambda_tol);
    DEGREE.write(&mut parameters, s.degree);
    parameters.insert("max_moves".into(), Value::from(s.max_moves));
    parameters.insert("parametrization".into(), Value::from("chord_length"));
    parameters.insert("gfi_initial".into(), Value::from(state.gfi()));

    let mut run = Run::new(points, &state);
    let mut notes = Vec::new();

    let coordinate_scale = points
        .iter()
        .map(|q| q.x.abs().max(q.y.abs()))
        .fold(0.0, f64::max);
    let candidates = state.candidates();
    let status = loop {
        if run.moves.len() >= s.max_moves {
            break FairStatus::IterationLimit;
        }
        let gfi = state.gfi();
        let (chosen, tolerance_refused) = run.choose(&state, &data, s, gfi, coordinate_scale)?;
        let Some(c) = chosen else {
            break if tolerance_refused {
                FairStatus::ToleranceLimited
            } else if run.moves.is_empty() {
                FairStatus::NoChange
            } else {
                FairStatus::Converged
            };
        };
        let Some(entry) = run.cache[c].take() else {
            break FairStatus::Converged;
        };
        run.apply(&mut state, &data, entry.trial, c, gfi);
    };

    if candidates.is_empty() {
        notes.push(format!(
            "{} points give no candidate centre 2..=m-2 for a five-point move",
            points.len()
        ));
    } else if !run.any_above_rounding && status == FairStatus::NoChange {
        notes.push(
            "every LFI is at the rounding level of its divided difference (straight data): \
             nothing to fair"
                .to_string(),
        );
    } else if run.moves.is_empty() && status == FairStatus::NoChange {
        notes.push(format!(
            "no local move lowers the GFI below tau = {} times its value; on long inputs use a \
             tau closer to 1",
            s.tau
        ));
    }
    if status == FairStatus::ToleranceLimited {
        notes.push(
            "moves that would lower the GFI further were refused because they exceed the \
             tolerance"
                .to_string(),
        );
    }
    parameters.insert("gfi_final".into(), Value::from(state.gfi()));
    parameters.insert("lambdas".into(), Value::Array(run.lambdas));

    Ok(Outcome {
        solver: None,
        pressed: None,
        points: run.out,
        status,
        iterations: run.moves.len(),
        moves: run.moves,
        history: run.history,
        parameters,
        notes,
        curve: Some(state.curve()?),
        tangents: None,
        ends_held: Some(crate::fair::EndFix::Position),
    })
}

/// The state of a run beside the indicators: the output points and their displacements, the
/// report so far, and the candidate order with its cache.
struct Run {
    out: Vec<Point>,
    disp: Vec<f64>,
    max_disp: f64,
    moves: Vec<Move>,
    lambdas: Vec<Value>,
    history: Vec<HistoryRow>,
    /// The candidates by descending LFI ([`lfi_key`]).
    order: BTreeSet<(Reverse<u64>, usize)>,
    cache: Vec<Option<Cached>>,
    /// When each control point last moved (the move counter `clock`).
    modified: Vec<u64>,
    clock: u64,
    /// Whether the last pass over the candidates found an LFI above the rounding level.
    any_above_rounding: bool,
}

impl Run {
    /// A run on the input `points` from the interpolant's indicators `state`.
    fn new(points: &[Point], state: &LocalIndicators) -> Run {
        let m = state.len() - 1;
        let order = state
            .candidates()
            .map(|c| (lfi_key(state.lfi[c]), c))
            .collect();
        Run {
            out: points.to_vec(),
            disp: vec![0.0; points.len()],
            max_disp: 0.0,
            moves: Vec::new(),
            lambdas: Vec::new(),
            history: vec![HistoryRow {
                iteration: 0,
                measure: state.gfi(),
                max_distance: 0.0,
            }],
            order,
            cache: vec![None; m + 1],
            modified: vec![0u64; m + 1],
            clock: 0,
            any_above_rounding: false,
        }
    }

    /// One pass over the candidates in LFI order: the first whose move (evaluated, or taken
    /// from the cache while the control points it depends on are unchanged) lowers the GFI
    /// below τ·GFI within the tolerance, and whether a move was refused for the tolerance alone.
    fn choose(
        &mut self,
        state: &LocalIndicators,
        data: &DataSamples,
        s: &Settings,
        gfi: f64,
        coordinate_scale: f64,
    ) -> Result<(Option<usize>, bool)> {
        let p = s.degree;
        let threshold = s.tau * gfi;
        let mut chosen = None;
        let mut tolerance_refused = false;
        self.any_above_rounding = false;
        for &(_, c) in &self.order {
            if state.lfi[c].sqrt() <= state.rounding_level(c, coordinate_scale) {
                continue;
            }
            self.any_above_rounding = true;
            let valid = s.use_cache
                && self.cache[c].as_ref().is_some_and(|e| {
                    self.modified[e.deps.0..=e.deps.1]
                        .iter()
                        .all(|&t| t <= e.stamp)
                });
            if !valid {
                let trial = state.best_trial(c, s.lambda_tol)?;
                let (window_lo, window_hi) = trial.moved_range();
                let (k_lo, k_hi) = data.affected(window_lo, window_hi + p);
                let within_tolerance = match s.tolerance {
                    None => true,
                    Some(tol) => (k_lo..k_hi).all(|k| {
                        let q = data.eval(k, |j| trial.control_point(&state.ctrl, j));
                        (q - data.input[k]).length() <= tol
                    }),
                };
                let mut deps = trial.deps;
                if k_lo < k_hi {
                    deps.0 = deps.0.min(data.span[k_lo].saturating_sub(p));
                    deps.1 = deps.1.max(data.span[k_hi - 1]);
                }
                self.cache[c] = Some(Cached {
                    trial,
                    within_tolerance,
                    deps,
                    stamp: self.clock,
                });
            }
            let Some(entry) = self.cache[c].as_ref() else {
                continue;
            };
            // NaN (a zero-speed point created by the move) is not less: rejected.
            let accepted_by_gfi = (gfi + entry.trial.delta_gfi)
                .partial_cmp(&threshold)
                .is_some_and(|o| o.is_lt());
            if !accepted_by_gfi {
                continue;
            }
            if !entry.within_tolerance {
                tolerance_refused = true;
                continue;
            }
            chosen = Some(c);
            break;
        }
        Ok((chosen, tolerance_refused))
    }

    /// Make the move `trial` centred at `c` (the GFI was `gfi` before it): re-key the
    /// candidates whose LFI changes, stamp the moved control points, update the output points
    /// near the move and record it.
    fn apply(
        &mut self,
        state: &mut LocalIndicators,
        data: &DataSamples,
        trial: Trial,
        c: usize,
        gfi: f64,
    ) {
        let p = data.p;
        let candidates = state.candidates();
        // Re-key the candidates whose LFI changes.
        let (l_lo, l_hi) = trial.lfi_range();
        for j in l_lo.max(*candidates.start())..=l_hi.min(*candidates.end()) {
            self.order.remove(&(lfi_key(state.lfi[j]), j));
        }
        let (w_lo, w_hi) = trial.moved_range();
        let distance = (w_lo..=w_hi)
            .map(|j| (trial.control_point(&state.ctrl, j) - state.ctrl[j]).length())
            .fold(0.0, f64::max);
        let before = gfi;
        state.commit_unchecked(&trial);
        for j in l_lo.max(*candidates.start())..=l_hi.min(*candidates.end()) {
            self.order.insert((lfi_key(state.lfi[j]), j));
        }
        self.clock += 1;
        for t in &mut self.modified[w_lo..=w_hi] {
            *t = self.clock;
        }

        // The output points near the move.
        let (k_lo, k_hi) = data.affected(w_lo, w_hi + p);
        let mut max_was_here = false;
        // The end points are P_0 and P_m, which never move: keep them exactly.
        for k in k_lo.max(1)..k_hi.min(self.out.len() - 1) {
            max_was_here |= self.disp[k] == self.max_disp;
            self.out[k] = data.eval(k, |j| state.ctrl[j]);
            self.disp[k] = (self.out[k] - data.input[k]).length();
        }
        self.max_disp = if max_was_here {
            self.disp.iter().copied().fold(0.0, f64::max)
        } else {
            self.disp[k_lo..k_hi]
                .iter()
                .copied()
                .fold(self.max_disp, f64::max)
        };

        self.moves.push(Move {
            iteration: self.moves.len() + 1,
            index: c,
            distance,
            before,
            after: state.gfi(),
        });
        self.lambdas.push(Value::from(trial.lambda));
        self.history.push(HistoryRow {
            iteration: self.moves.len(),
            measure: state.gfi(),
            max_distance: self.max_disp,
        });
    }
}

/// Ordering key of a candidate: descending LFI (LFIs are finite and non-negative, so the bit
/// pattern orders like the value), ties by increasing index.
fn lfi_key(lfi: f64) -> Reverse<u64> {
    Reverse(lfi.to_bits())
}

/// Basis values of the interpolating curve at the data parameters, for the output points and
/// the tolerance check.
#[derive(Clone, Debug)]
struct DataSamples {
    p: usize,
    input: Vec<Point>,
    span: Vec<usize>,
    /// `N_{span−p..=span}` at each parameter, stride p + 1.
    basis: Vec<f64>,
}

impl DataSamples {
    fn new(curve: &BSplineCurve, params: &[f64], input: &[Point]) -> DataSamples {
        let p = curve.degree();
        let mut span = Vec::with_capacity(params.len());
        let mut basis = Vec::with_capacity(params.len() * (p + 1));
        let mut b = [[0.0; MAX_ORDER]; 4];
        for &t in params {
            let k = curve.find_span(t);
            curve.basis_derivs(k, t, 0, &mut b);
            span.push(k);
            basis.extend_from_slice(&b[0][..=p]);
        }
        DataSamples {
            p,
            input: input.to_vec(),
            span,
            basis,
        }
    }

    /// The data indices `k_lo..k_hi` (half open) whose curve point uses a control point in
    /// `lo..=hi + p` — pass `hi + p` as `hi_span`: the spans `lo..=hi_span`.
    fn affected(&self, lo: usize, hi_span: usize) -> (usize, usize) {
        let a = self.span.partition_point(|&k| k < lo);
        let b = self.span.partition_point(|&k| k <= hi_span);
        (a, b.max(a))
    }

    /// The curve point at data parameter `k`, with control points from `cp`.
    fn eval(&self, k: usize, cp: impl Fn(usize) -> Point) -> Point {
        let p = self.p;
        let first = self.span[k] - p;
        let mut v = Vec2::ZERO;
        for (l, &n) in self.basis[k * (p + 1)..(k + 1) * (p + 1)]
            .iter()
            .enumerate()
        {
            v += cp(first + l).to_vec2() * n;
        }
        v.to_point()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fair::cali::DEFAULT_LAMBDA_TOL;

    /// splitmix64 → uniform → Box–Muller, deterministic noise for the tests.
    fn noisy_arc(n: usize, sigma: f64, seed: u64) -> Vec<Point> {
        let mut state = seed;
        let mut next = || {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n)
            .map(|i| {
                let a = 2.5 * i as f64 / (n - 1) as f64;
                let r = 1.0
                    + sigma
                        * (-2.0 * (1.0 - next()).ln()).sqrt()
                        * (std::f64::consts::TAU * next()).cos();
                Point::new(r * a.cos(), r * a.sin())
            })
            .collect()
    }

    #[test]
    fn cache_changes_nothing() {
        for (n, seed) in [(31, 1), (60, 2), (45, 3)] {
            let pts = noisy_arc(n, 0.01, seed);
            let mut s = Settings {
                tau: 0.995,
                lambda_tol: DEFAULT_LAMBDA_TOL,
                degree: 3,
                tolerance: None,
                max_moves: 400,
                held_ends: 1,
                use_cache: true,
            };
            let with = run_cali(&pts, &s).expect("cached run");
            s.use_cache = false;
            let without = run_cali(&pts, &s).expect("uncached run");
            assert!(with.moves.len() > 3, "{n}: {} moves", with.moves.len());
            assert_eq!(with.moves, without.moves);
            assert_eq!(with.points, without.points);
            assert_eq!(with.status, without.status);
        }
    }
}
