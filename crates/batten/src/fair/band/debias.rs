//! The debiasing stage of `band`: back towards the data, as far as the noise allows.
//!
//! The passes give the fairest curve inside the band, and that curve lies on the band's inner
//! edge wherever the energy gains by it: features are flattened by up to `D`, several noise
//! standard deviations. The last stage adds a data term to the passes' energy (its metric
//! re-taken from their result, as a further pass would),
//!
//! ```text
//! minimise  E(q) + μ Σ_i |q_i − p_i|²      subject to the band, as before,
//! ```
//!
//! with `μ` chosen by the discrepancy principle (Morozov): the smallest `μ` whose unconstrained
//! minimiser has a mean squared residual no larger than that of the noise,
//! `(1/n) Σ |q_i − p_i|² ≤ d·(τ σ̂)²` in `d` dimensions (`τ` the parameter `fit`, slightly above 1,
//! errs towards the smoother side). The residual shrinks and the energy grows as `μ` grows,
//! so a bracketing search on `log μ` finds it, each step one banded solve, O(n). Where `σ̂`
//! underestimates the noise the target cannot be met; the energy is then capped at
//! [`ENERGY_CAP`] times the passes' optimum, so the stage never returns to the noise.
//! Where one `μ` still flattens a feature, [`Penalized::local_weights`] raises it there, from
//! the residual's windowed means (see `docs/algorithms/band.md`, local data weights).
//! The constrained problem is then solved once with those weights by the interior point.

use super::design::{Design, SplineMap};
use super::energy::{Energy, four_from};
use crate::error::Result;
use crate::numeric::{Bracket, CyclicSymBanded, PARALLEL_FROM, SymBanded, map_indices, map_pieces};
use rayon::prelude::*;

/// Points a task of [`Windows::significant`] scans.
const SIGNIFICANT_CHUNK: usize = 1 << 14;

/// The most the debiased energy may exceed the passes' optimum, as a factor.
pub(super) const ENERGY_CAP: f64 = 4.0;

/// Rounds of [`Penalized::local_weights`].
const LOCAL_ROUNDS: usize = 6;
/// The factor by which a round raises the data weight around a biased window.
const LOCAL_FACTOR: f64 = 4.0;
/// The raised weights are smoothed: each point's logarithm of its weight is averaged over
/// this many of its smoothing lengths (see [`smooth_log_weights`]).
const WEIGHT_SMOOTHING: f64 = 3.0;

/// The precision of the search for `μ`, as the bisection steps on `log μ` that would reach it
/// (the bracket spans 6·ln(2n) in `ln μ`, under 90 for 10⁶ points; 24 halvings leave `μ`
/// within 1e-5 of itself, far below what the residual sees).
const BISECTIONS: u32 = 24;

/// The matrix `2A` with the held unknowns' rows and columns replaced by the identity, before
/// the data weight is added.
#[derive(Clone)]
enum Base {
    Open(SymBanded),
    Closed(CyclicSymBanded),
}

impl Base {
    fn add(&mut self, r: usize, c: usize, v: f64) {
        match self {
            Base::Open(m) => m.add(r, c, v),
            Base::Closed(m) => m.add(r, c, v),
        }
    }

    fn factorize_and_solve(mut self, y: &mut [f64]) -> Result<()> {
        match &mut self {
            Base::Open(m) => {
                m.factorize_split()?;
                m.solve_in_place(y)
            }
            Base::Closed(m) => {
                m.factorize()?;
                m.solve_in_place(y)
            }
        }
    }
}

/// The penalised problem, in the solver's units (see `solver.rs`): `y` relative to the
/// reference `s`, ball centres `c`, points `B y`. Everything that does not depend on `μ` is
/// assembled once by [`Penalized::new`]; each `μ` of the search then costs one copy, the
/// data term (a diagonal in the point form, the Gram matrix `BᵀB` times `μ` in the spline
/// form) and one banded factorisation.
pub(super) struct Penalized<'a, const D: usize> {
    energy: &'a Energy<D>,
    design: &'a Design,
    held: &'a [bool],
    pinned: &'a [bool],
    /// `A s`.
    anchor: &'a [f64],
    /// `c = a − B s`.
    centres: &'a [f64],
    /// The held unknowns' values (zero elsewhere).
    fixed: Vec<f64>,
    base: Base,
    /// `A` applied to the held unknowns' values: their columns, moved to the right-hand side.
    coupling: Vec<f64>,
    /// `2 BᵀB` on the free unknowns, lower entries (the spline form; empty for points).
    gram: Vec<(usize, usize, f64)>,
    /// `2 Bᵀ (c − B x_held)`.
    pull: Vec<f64>,
    /// The spline form's residual sums by knot span (empty in the point form).
    sums: Vec<SpanSums<D>>,
    /// The largest entry `2A` reports on the diagonal (one window's), the scale of rounding.
    top: f64,
    /// The energy's scale against the point form's units (parameters in mean spacings): a
    /// data weight `μ` smooths over about `(μ / unit)^(−1/6)` points.
    unit: f64,
}

impl<'a, const D: usize> Penalized<'a, D> {
    /// `fixed` gives the held unknowns' values, `unit` the energy's scale.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn new(
        energy: &'a Energy<D>,
        unit: f64,
        design: &'a Design,
        held: &'a [bool],
        pinned: &'a [bool],
        fixed: &[f64],
        anchor: &'a [f64],
        centres: &'a [f64],
    ) -> Penalized<'a, D> {
        let dim = energy.n * D;
        let fixed: Vec<f64> = (0..dim)
            .map(|k| if held[k / D] { fixed[k] } else { 0.0 })
            .collect();
        let mut coupling = vec![0.0; dim];
        energy.apply_add(&fixed, &mut coupling);
        let bw = 4 * D - 1;
        // The matrix and its largest diagonal entry in one traversal of the energy's entries.
        let mut top = 0.0_f64;
        let mut diagonal = |r: usize, c: usize, v: f64| {
            if r == c {
                top = top.max(v.abs());
            }
        };
        let base = if energy.closed {
            let mut m = CyclicSymBanded::zeros(dim, bw);
            energy.for_each_lower(2.0, |r, c, v| {
                m.add(r, c, v);
                diagonal(r, c, v);
            });
            Base::Closed(m)
        } else {
            let mut m = SymBanded::zeros(dim, bw);
            energy.for_each_lower(2.0, |r, c, v| {
                if !held[r / D] && !held[c / D] {
                    m.add(r, c, v);
                }
                diagonal(r, c, v);
            });
            for k in (0..dim).filter(|k| held[k / D]) {
                m.add(k, k, 1.0);
            }
            Base::Open(m)
        };
        // The data term's parts that do not depend on the weights: in the spline form from
        // the knot spans' sums (one sweep over the points), in the point form per point.
        let (gram, pull, sums) = match design {
            Design::Spline(map) => {
                let sums = SpanSums::of(map, pinned, centres);
                let gram = span_gram(map, &sums, held);
                let pull = span_pull(map, &sums, &fixed);
                (gram, pull, sums)
            }
            Design::Points { .. } => {
                // `2 (c − x_held)` at the free points: the point form's `2 Bᵀ (c − B x_held)`.
                let pull = (0..dim)
                    .map(|k| {
                        if pinned[k / D] {
                            0.0
                        } else {
                            2.0 * (centres[k] - fixed[k])
                        }
                    })
                    .collect();
                (Vec::new(), pull, Vec::new())
            }
        };
        Penalized {
            energy,
            design,
            held,
            pinned,
            anchor,
            centres,
            fixed,
            base,
            coupling,
            gram,
            pull,
            sums,
            top,
            unit,
        }
    }

    /// The number of points.
    fn points(&self) -> usize {
        self.design.points()
    }

    /// The unconstrained minimiser of `E(s + y) + Σ μ_i |(B y)_i − c_i|²` with the held
    /// unknowns at their values: `(2A + 2 Bᵀ diag μ B) y = 2 Bᵀ μ c − 2 A s` on the free rows
    /// (`weight(i)` gives `μ_i` of point `i`; `uniform` when every point has the same one).
    pub(super) fn minimiser(
        &self,
        weight: impl Fn(usize) -> f64 + Sync,
        uniform: bool,
    ) -> Result<Vec<f64>> {
        let held = self.held;
        let dim = self.energy.n * D;
        if uniform && matches!(self.design, Design::Spline(_)) {
            let (m, y) = self.uniform_spline_term(weight(0));
            return self.finish_minimiser(m, y);
        }
        let mut m = self.base.clone();
        let mut y = vec![0.0; dim];
        match self.design {
            Design::Points { .. } => {
                for (k, yk) in y.iter_mut().enumerate() {
                    *yk = 2.0 * weight(k / D) * self.centres[k];
                }
                let skip = matches!(m, Base::Open(_));
                for k in 0..dim {
                    if !(skip && held[k / D]) {
                        m.add(k, k, 2.0 * weight(k / D));
                    }
                }
            }
            Design::Spline(map) if !held.iter().any(|h| *h) => {
                self.spline_data_term(map, &weight, &mut m, &mut y);
            }
            Design::Spline(_) => self.spline_data_term_sweep(weight, &mut m, &mut y),
        }
        self.finish_minimiser(m, y)
    }

    /// The spline form's data term as [`Penalized::spline_data_term`] gives it, from every
    /// point's basis values (in parallel pieces), with held unknowns.
    fn spline_data_term_sweep(
        &self,
        weight: impl Fn(usize) -> f64 + Sync,
        m: &mut Base,
        y: &mut [f64],
    ) {
        let held = self.held;
        self.design.for_each_weight_lower::<D>(
            |i| 2.0 * weight(i),
            self.pinned,
            |r, c, v| {
                if !held[r / D] && !held[c / D] {
                    m.add(r, c, v);
                }
            },
        );
        let mut weighted = vec![0.0; self.points() * D];
        self.design
            .eval_then::<D>(&self.fixed, &mut weighted, |i, q| {
                let w = 2.0 * weight(i);
                self.shifted(i, q).map(|c| w * c)
            });
        self.design.eval_t_add::<D>(&weighted, y);
    }

    /// `c_i − (B x_held)_i` at a free point `i` (`q` the held unknowns' value there), zero at
    /// a pinned one: what the data term pulls point `i` towards.
    fn shifted(&self, i: usize, q: [f64; D]) -> [f64; D] {
        if self.pinned[i] {
            [0.0; D]
        } else {
            std::array::from_fn(|a| self.centres[i * D + a] - q[a])
        }
    }

    /// [`Penalized::minimiser`] by the sweep over every point, for the tests.
    #[cfg(test)]
    pub(super) fn minimiser_by_sweep(
        &self,
        weight: impl Fn(usize) -> f64 + Sync,
    ) -> Result<Vec<f64>> {
        let mut m = self.base.clone();
        let mut y = vec![0.0; self.energy.n * D];
        self.spline_data_term_sweep(weight, &mut m, &mut y);
        self.finish_minimiser(m, y)
    }

    /// The spline form's data term `2 Bᵀ diag μ B` into `m` and `2 Bᵀ μ c` into `y`, nothing
    /// held: a knot span whose free points share one weight `w` (the local weights' rounds
    /// raise windows many spans long) takes `2w` times its sums assembled once (`Σ b bᵀ`,
    /// `Σ b cᵀ`), O(1); only the spans where the weight changes are summed point by point.
    /// A round at 10⁶ points then costs a pass over the weights and a factorisation, where
    /// the sweep over every point's basis took 22 of its 25 ms.
    fn spline_data_term(
        &self,
        map: &SplineMap,
        weight: &impl Fn(usize) -> f64,
        m: &mut Base,
        y: &mut [f64],
    ) {
        let pinned = self.pinned;
        for s in &self.sums {
            let mut free = s.points.clone().filter(|&i| !pinned[i]);
            let w0 = free.next().map_or(0.0, weight);
            let gram;
            let mut pull = [[0.0; D]; 4];
            if free.all(|i| weight(i) == w0) {
                let w2 = 2.0 * w0;
                gram = s.gram.map(|row| row.map(|g| w2 * g));
                for (p, q) in pull.iter_mut().zip(&s.pull) {
                    *p = q.map(|v| w2 * v);
                }
            } else {
                let mut acc = [[0.0; 4]; 4];
                for i in s.points.clone().filter(|&i| !pinned[i]) {
                    let c = &self.centres[i * D..(i + 1) * D];
                    add_weighted(&mut acc, &mut pull, 2.0 * weight(i), &map.basis[i], c);
                }
                gram = acc;
            }
            map.add_span_lower::<D>(s.first, &gram, &mut |r, c, v| m.add(r, c, v));
            for (k, p) in pull.iter().enumerate() {
                let j = (s.first + k) % map.vars;
                for a in 0..D {
                    y[j * D + a] += p[a];
                }
            }
        }
    }

    /// Solve for the minimiser from the matrix `m` (`2A` plus the data term) and the data
    /// term's part `y` of the right-hand side: the held unknowns at their values, the
    /// others pulled by the anchor and the held ones' coupling.
    fn finish_minimiser(&self, m: Base, mut y: Vec<f64>) -> Result<Vec<f64>> {
        for (k, yk) in y.iter_mut().enumerate() {
            *yk = if self.held[k / D] {
                self.fixed[k]
            } else {
                *yk - 2.0 * self.anchor[k] - 2.0 * self.coupling[k]
            };
        }
        m.factorize_and_solve(&mut y)?;
        Ok(y)
    }

    /// [`Penalized::minimiser`] with the weight `mu` at every point but those of `raised`,
    /// whose weights `weights` gives: in the spline form the uniform part comes from the
    /// sums assembled once and only the raised points are visited, so a round of
    /// [`super::spline::feasible_fit`], which raises a few points of 10⁶, costs a
    /// factorisation rather than a sweep over every point.
    pub(super) fn minimiser_raised(
        &self,
        mu: f64,
        weights: &[f64],
        raised: &[usize],
    ) -> Result<Vec<f64>> {
        let Design::Spline(map) = self.design else {
            return self.minimiser(|i| weights[i], false);
        };
        let held = self.held;
        let (mut m, mut y) = self.uniform_spline_term(mu);
        for &i in raised.iter().filter(|&&i| !self.pinned[i]) {
            let extra = 2.0 * (weights[i] - mu);
            let shifted = self.shifted(i, map.point::<D>(i, &self.fixed));
            map.add_point::<D>(
                i,
                extra,
                &shifted,
                |r, c, v| {
                    if !held[r / D] && !held[c / D] {
                        m.add(r, c, v);
                    }
                },
                &mut y,
            );
        }
        self.finish_minimiser(m, y)
    }

    /// The spline form's matrix `2A` and right-hand side with the data term of weight `mu`
    /// at every point, from the sums assembled once (`2 BᵀB` and `2 Bᵀ(c − B x_held)`).
    fn uniform_spline_term(&self, mu: f64) -> (Base, Vec<f64>) {
        let mut m = self.base.clone();
        for (r, c, v) in &self.gram {
            m.add(*r, *c, mu * v);
        }
        (m, self.pull.iter().map(|p| mu * p).collect())
    }

    /// `E(s + y)` from `A s` and `E(s)`.
    fn energy_at(&self, y: &[f64], anchor_energy: f64) -> f64 {
        let mut ay = vec![0.0; y.len()];
        self.energy.apply_add(y, &mut ay);
        let quad: f64 = y.iter().zip(&ay).map(|(a, b)| a * b).sum();
        let lin: f64 = y.iter().zip(self.anchor).map(|(a, b)| a * b).sum();
        anchor_energy + 2.0 * lin + quad
    }

    /// The residual `B y − c` of every point (zero at pinned points).
    pub(super) fn residual(&self, y: &[f64]) -> Vec<f64> {
        let mut r = vec![0.0; self.points() * D];
        self.residual_into(y, &mut r);
        r
    }

    /// [`Penalized::residual`] into `r` (`D` numbers a point).
    fn residual_into(&self, y: &[f64], r: &mut [f64]) {
        self.design
            .residual::<D>(y, self.centres, Some(self.pinned), r);
    }

    /// The longest residual `|(B y)_i − c_i|` (pinned points count as zero) and the points
    /// whose residual is longer than `radius`, with its length, in order: what a round of
    /// [`super::spline::feasible_fit`] needs of the residuals, in parallel pieces without a
    /// vector of every length (at 10⁶ points that vector and the serial pass over it were
    /// two thirds of a round).
    pub(super) fn far_points(&self, y: &[f64], radius: f64) -> (f64, Vec<(usize, f64)>) {
        let (pinned, centres) = (self.pinned, self.centres);
        let parts = map_pieces(self.points(), FAR_PIECE, |points| {
            let mut farthest = 0.0_f64;
            let mut far = Vec::new();
            for i in points {
                if pinned[i] {
                    continue;
                }
                let q = self.design.value::<D>(i, y);
                let len = (0..D)
                    .map(|a| {
                        let r = q[a] - centres[i * D + a];
                        r * r
                    })
                    .sum::<f64>()
                    .sqrt();
                farthest = farthest.max(len);
                if len > radius {
                    far.push((i, len));
                }
            }
            (farthest, far)
        });
        let farthest = parts.iter().fold(0.0_f64, |m, (f, _)| m.max(*f));
        (
            farthest,
            parts.into_iter().flat_map(|(_, far)| far).collect(),
        )
    }

    /// The mean squared residual `(1/free) Σ |(B y)_i − c_i|²` over the free points.
    fn mean_square_residual(&self, y: &[f64]) -> f64 {
        let free = self.pinned.iter().filter(|h| !**h).count().max(1);
        let sum: f64 = match self.design {
            Design::Points { .. } => self.residual(y).iter().map(|r| r * r).sum(),
            Design::Spline(map) => self.sums.iter().map(|s| s.value(map.vars, y)).sum(),
        };
        sum / free as f64
    }

    /// The data weight `μ` of the discrepancy principle: the smallest `μ` (in the bracket)
    /// whose minimiser's mean squared residual is at most `target`, or whose energy reaches
    /// `cap` (`E(s)` is the energy of the reference, the passes' result); the smallest `μ`
    /// of the bracket when that one meets the target already. Whether the reference itself
    /// meets the target does not matter: the rule is about the minimiser, and a reference
    /// held by the band can meet it while it flattens a feature by several σ (a noisy helix
    /// kept its passes' shape, four times as far from the truth). `None` when the smallest
    /// `μ` reaches the cap.
    pub(super) fn discrepancy_weight(
        &self,
        anchor_energy: f64,
        target: f64,
        cap: f64,
    ) -> Result<Option<f64>> {
        let n = self.points() as f64;
        if target.is_nan() || target <= 0.0 || cap.is_nan() || cap <= anchor_energy {
            return Ok(None);
        }
        // In units of the mean spacing a data weight μ smooths over about μ^(-1/6) points:
        // from twice the curve down to a single point, and no lower than rounding of `2A`
        // leaves meaningful.
        let unit = self.unit;
        let (lo, hi) = (
            (unit * (2.0 * n).powi(-6)).max(1e-15 * self.top).ln(),
            unit.ln(),
        );

        // A weight so small that rounding makes the matrix singular (the energy's null space,
        // quadratics in the parameter, rests on `μ` alone) asks for more weight too. `None`:
        // the minimiser's energy reaches the cap. With the verdict, `g = ln(residual/target)`
        // (NaN where unknown), which the search interpolates.
        let verdict = |ln_mu: f64| match self.minimiser(|_| ln_mu.exp(), true) {
            Ok(y) => {
                if self.energy_at(&y, anchor_energy) < cap {
                    let g = (self.mean_square_residual(&y) / target).ln();
                    (Some(g > 0.0), g)
                } else {
                    (None, f64::NAN)
                }
            }
            Err(_) => (Some(true), f64::NAN),
        };
        let (more, g_lo) = verdict(lo);
        match more {
            None => return Ok(None),
            // The smoothest weight that rounding leaves meaningful meets the target already:
            // the reference, held by the band at a few points, is farther from the data than
            // a smooth fit. That weight is the answer (the stage used to be skipped there,
            // and dense noisy curves kept the passes' flattened features).
            Some(false) => return Ok(Some(lo.exp())),
            Some(true) => {}
        }
        // The smallest `μ` that meets the target, to the bracket a bisection of
        // [`BISECTIONS`] steps would leave, by the root finder `mst` searches its `p` with
        // (Chandrupatla's interpolation inside a bracket that only the verdicts move), in
        // `x = −ln μ` so that its feasible end is the lower one. `g` is smooth and monotone
        // here, and 7–10 minimisers replace the bisection's 24.
        let (_, g_hi) = verdict(hi);
        let precision = (hi - lo) / f64::from(1u32 << BISECTIONS);
        let mut bracket = Bracket::new(-hi, g_hi, -lo, g_lo, precision);
        while !bracket.converged() {
            let x = bracket.next();
            let (more, g) = verdict(-x);
            bracket.update(x, more != Some(true), g);
        }
        Ok(Some((-bracket.lo()).exp()))
    }

    /// Raise the data weight where the residual is biased: starting from `μ` everywhere,
    /// each round computes the unconstrained minimiser, averages its residual `y − c` over a
    /// window as long as the smoothing (`μ^(−1/6)` points), and multiplies the weights
    /// around every window whose mean is significant for noise of standard deviation `noise`
    /// per coordinate (`|mean|² · count > z² noise²`) by [`LOCAL_FACTOR`]. The residual of a
    /// smoother fed only noise is high-frequency, so its windowed means stay well under that
    /// threshold; a feature the energy flattens leaves a one-signed residual as long as the
    /// feature, and is found. Stops when no window is significant, after [`LOCAL_ROUNDS`], or
    /// before a round whose energy would pass `cap`. The raised weights, a factor 4 apart
    /// across a window's edge, are then smoothed ([`smooth_log_weights`]; kept unsmoothed if
    /// the smoothed ones would pass `cap`). Returns the weights and the number of points
    /// whose weight was raised.
    pub(super) fn local_weights(
        &self,
        mu: f64,
        anchor_energy: f64,
        cap: f64,
        noise: f64,
        z: f64,
    ) -> Result<(Vec<f64>, usize)> {
        let n = self.points();
        let mut weights = vec![mu; n];
        if z <= 0.0 || noise <= 0.0 || n < 3 {
            return Ok((weights, 0));
        }
        let threshold = z * z * noise * noise;
        // A matrix that rounding leaves indefinite (the energy's null space held by tiny
        // weights alone) ends the raising: the weights are kept as they were.
        let Ok(mut y) = self.minimiser(|i| weights[i], false) else {
            return Ok((weights, 0));
        };
        // The rounds' buffers, made once (at 10⁶ points each round's new ones cost it a few
        // milliseconds of page faults).
        let closed = self.energy.closed;
        let mut flat = vec![0.0; n * D];
        let mut windows = Windows::<D>::empty(closed);
        let mut marked = vec![0; n];
        let mut raise = Marks::new(n, closed);
        let mut trial = Vec::with_capacity(n);
        for _ in 0..LOCAL_ROUNDS {
            // The residual (zero at held points, which the minimiser leaves at their centres).
            self.residual_into(&y, &mut flat);
            windows.refill(&flat, self.pinned);
            windows.significant_into(&weights, self.unit, threshold, &mut marked);
            if marked.iter().all(|h| *h == 0) {
                break;
            }
            raise.clear();
            for (i, &half) in marked.iter().enumerate() {
                if half > 0 {
                    raise.mark(i, half);
                }
            }
            trial.clear();
            trial.extend(weights.iter().zip(raise.marked()).map(|(w, r)| {
                if r {
                    (w * LOCAL_FACTOR).min(self.unit)
                } else {
                    *w
                }
            }));
            let Ok(trial_y) = self.minimiser(|i| trial[i], false) else {
                break;
            };
            if self.energy_at(&trial_y, anchor_energy) > cap {
                break;
            }
            std::mem::swap(&mut weights, &mut trial);
            y = trial_y;
        }
        if weights.iter().any(|w| *w > mu) {
            let smooth =
                smooth_log_weights(&weights, self.unit, self.energy.closed, WEIGHT_SMOOTHING);
            if let Ok(y) = self.minimiser(|i| smooth[i], false)
                && self.energy_at(&y, anchor_energy) <= cap
            {
                weights = smooth;
            }
        }
        let raised = weights.iter().filter(|w| **w > mu).count();
        Ok((weights, raised))
    }
}

/// The data weights with each point's logarithm of its weight averaged over a window of
/// `lengths` of its own smoothing lengths (`(w_i/unit)^(−1/6)` points, as
/// [`Penalized::local_weights`] measures them), cyclic when `closed`, cut at the ends when
/// open; prefix sums, O(n). Equal weights are left equal (to rounding).
///
/// Why: the raising multiplies the weights around a biased window by 4, and the steps of the
/// smoothing length at the window's edges leave waves in the curvature a few smoothing
/// lengths long (a noisy cubic's curvature peak, 1000 points at 0.1 % noise: −2.85 then
/// −4.26 where the truth goes −3.31, −3.89). Averaged over 3 smoothing lengths, the median
/// curvature error of the quality benchmark fell from 0.202 to 0.193 on its tuning split and
/// from 0.204 to 0.193 on its test split, better on about three curves for every one worse.
fn smooth_log_weights(weights: &[f64], unit: f64, closed: bool, lengths: f64) -> Vec<f64> {
    let n = weights.len();
    if n == 0 {
        return Vec::new();
    }
    // The weights come in runs of equal values: each run's logarithm and window taken once.
    let logs: Vec<f64> = per_run(weights, |w| w.ln());
    let reach = (n / 2).max(1);
    let halves: Vec<usize> = per_run(weights, |w| {
        let length = lengths * (w / unit).powf(-1.0 / 6.0);
        ((0.5 * length).round() as usize).clamp(1, reach)
    });
    // Prefix sums of the logarithms three times over, so that cyclic windows are plain
    // ranges (each logarithm taken once), kept from `from` to `to` only, where the windows
    // read them: the middle copy for an open curve, half a copy more on each side for a
    // closed one (the sums themselves run from the start, so they are the same numbers).
    let beyond = if closed { reach } else { 0 };
    let (from, to) = (n - beyond, 2 * n + beyond);
    let mut prefix = Vec::with_capacity(to - from + 1);
    if from == 0 {
        prefix.push(0.0);
    }
    let mut acc = 0.0;
    for (k, l) in logs.iter().chain(&logs).chain(&logs).take(to).enumerate() {
        acc += l;
        if k + 1 >= from {
            prefix.push(acc);
        }
    }
    map_indices(n, |i| {
        let half = halves[i];
        let (lo, hi) = if closed {
            (n + i - half, n + i + half + 1)
        } else {
            (n + i.saturating_sub(half), n + (i + half + 1).min(n))
        };
        ((prefix[hi - from] - prefix[lo - from]) / (hi - lo) as f64).exp()
    })
}

/// `f(w)` for every weight, computed once for each run of equal weights.
fn per_run<T: Copy>(weights: &[f64], f: impl Fn(f64) -> T) -> Vec<T> {
    let mut cache = RunCache::default();
    weights.iter().map(|&w| cache.get(w, &f)).collect()
}

/// The last weight and `f` of it: along weights that come in runs of equal values (as the
/// local weights' rounds leave them), `f` is computed once a run.
struct RunCache<T> {
    last: Option<(f64, T)>,
}

impl<T> Default for RunCache<T> {
    fn default() -> Self {
        RunCache { last: None }
    }
}

impl<T: Copy> RunCache<T> {
    fn get(&mut self, w: f64, f: impl Fn(f64) -> T) -> T {
        match self.last {
            Some((lw, v)) if lw == w => v,
            _ => {
                let v = f(w);
                self.last = Some((w, v));
                v
            }
        }
    }
}

/// One knot span's share of `Σ_i |(B y)_i − c_i|²` over the free points on it, as a
/// quadratic in its four control points: `Σ_kl G_kl y_k·y_l − 2 Σ_k y_k·H_k + γ`. With them
/// the discrepancy's search measures a residual in O(control points), not O(points).
#[derive(Clone, Debug)]
struct SpanSums<const D: usize> {
    first: usize,
    /// The points of the run: from its first free point to its last, plus one.
    points: std::ops::Range<usize>,
    /// `Σ_i b_i b_iᵀ`.
    gram: [[f64; 4]; 4],
    /// `Σ_i b_ik c_i`.
    pull: [[f64; D]; 4],
    /// `Σ_i |c_i|²`.
    constant: f64,
}

impl<const D: usize> SpanSums<D> {
    /// The sums of every run of free points on one knot span.
    fn of(map: &SplineMap, pinned: &[bool], centres: &[f64]) -> Vec<SpanSums<D>> {
        let mut out: Vec<SpanSums<D>> = Vec::new();
        for (i, (&f, b)) in map.first.iter().zip(&map.basis).enumerate() {
            if pinned[i] {
                continue;
            }
            if out.last().is_none_or(|s| s.first != f) {
                out.push(SpanSums {
                    first: f,
                    points: i..i + 1,
                    gram: [[0.0; 4]; 4],
                    pull: [[0.0; D]; 4],
                    constant: 0.0,
                });
            }
            let Some(s) = out.last_mut() else { continue };
            s.points.end = i + 1;
            let c = &centres[i * D..(i + 1) * D];
            // Weight 1: `1·b_k` is `b_k`, the plain sums.
            add_weighted(&mut s.gram, &mut s.pull, 1.0, b, c);
            s.constant += c.iter().map(|v| v * v).sum::<f64>();
        }
        out
    }

    /// The span's share at the control points `y` (flat; `vars` of them, cyclic).
    fn value(&self, vars: usize, y: &[f64]) -> f64 {
        let at = |k: usize| &y[((self.first + k) % vars) * D..((self.first + k) % vars + 1) * D];
        let mut total = self.constant;
        for k in 0..4 {
            let yk = at(k);
            for l in 0..4 {
                let yl = at(l);
                total += self.gram[k][l] * (0..D).map(|a| yk[a] * yl[a]).sum::<f64>();
            }
            total -= 2.0 * (0..D).map(|a| yk[a] * self.pull[k][a]).sum::<f64>();
        }
        total
    }
}

/// `2 BᵀB` on the free unknowns (entries of `held` ones left out), lower entries, from the
/// knot spans' sums: a span's `2 Σ b bᵀ` is its sum of `(2 b) bᵀ` (doubling is exact), so
/// these are the sums [`Design::for_each_weight_lower`] gives at weight 2, bit for bit,
/// without a second sweep over the points. Listed in the order of a band array (offsets
/// `c − r` in `[−bw, bw]`, wrapped for closed curves), zeros left out.
fn span_gram<const D: usize>(
    map: &SplineMap,
    sums: &[SpanSums<D>],
    held: &[bool],
) -> Vec<(usize, usize, f64)> {
    let dim = map.vars * D;
    let bw = 4 * D - 1;
    let width = 2 * bw + 1;
    let mut band = vec![0.0; dim * width];
    for s in sums {
        let doubled = s.gram.map(|row| row.map(|g| 2.0 * g));
        map.add_span_lower::<D>(s.first, &doubled, &mut |r, c, v| {
            if !held[r / D] && !held[c / D] {
                band[r * width + offset(r, c, dim, bw)] += v;
            }
        });
    }
    band_entries(&band, dim, bw)
}

/// The non-zero entries `(r, c, v)` of a band array of `dim` rows of width `2bw + 1` (offsets
/// `c − r` in `[−bw, bw]`, wrapped for closed curves; see [`offset`]), row by row.
fn band_entries(band: &[f64], dim: usize, bw: usize) -> Vec<(usize, usize, f64)> {
    let width = 2 * bw + 1;
    band.iter()
        .enumerate()
        .filter(|(_, v)| **v != 0.0)
        .map(|(k, v)| {
            let r = k / width;
            (r, (r + dim + k % width - bw) % dim, *v)
        })
        .collect()
}

/// `2 Bᵀ (c − B x_held)` over the free points, from the knot spans' sums: on a span
/// `Σ_i b_ik (c_i − Σ_l b_il x_l) = H_k − Σ_l G_kl x_l` (`x` the held unknowns' values,
/// zero elsewhere).
fn span_pull<const D: usize>(map: &SplineMap, sums: &[SpanSums<D>], fixed: &[f64]) -> Vec<f64> {
    let mut pull = vec![0.0; map.vars * D];
    for s in sums {
        let at = four_from(s.first, map.vars);
        for (k, &j) in at.iter().enumerate() {
            for a in 0..D {
                let held_part: f64 = (0..4).map(|l| s.gram[k][l] * fixed[at[l] * D + a]).sum();
                pull[j * D + a] += 2.0 * (s.pull[k][a] - held_part);
            }
        }
    }
    pull
}

/// Add one point's share `w b bᵀ` and `w b cᵀ` (basis values `b`, centre `c`) to a knot
/// span's sums.
fn add_weighted<const D: usize>(
    gram: &mut [[f64; 4]; 4],
    pull: &mut [[f64; D]; 4],
    w: f64,
    b: &[f64; 4],
    c: &[f64],
) {
    for k in 0..4 {
        let wb = w * b[k];
        for l in 0..4 {
            gram[k][l] += wb * b[l];
        }
        for a in 0..D {
            pull[k][a] += wb * c[a];
        }
    }
}

/// The place of `(r, c)` in a band row of width `2bw + 1`: `c − r + bw`, wrapped by `dim`.
fn offset(r: usize, c: usize, dim: usize, bw: usize) -> usize {
    let o = c as isize - r as isize;
    let o = if o < -(bw as isize) {
        o + dim as isize
    } else if o > bw as isize {
        o - dim as isize
    } else {
        o
    };
    (o + bw as isize) as usize
}

/// Points a piece of [`Penalized::far_points`] takes.
const FAR_PIECE: usize = 1 << 14;

/// Windowed sums of the free points' residuals in O(1) each, from prefix sums.
struct Windows<const D: usize> {
    /// `sums[j]`: the residuals of the free points before `j`, summed.
    sums: Vec<[f64; D]>,
    /// `counts[j]`: the free points before `j`.
    counts: Vec<usize>,
    closed: bool,
}

impl<const D: usize> Windows<D> {
    /// The prefix sums of `residual` (flat, `D` numbers a point) over the points not `held`.
    #[cfg(test)]
    fn new(residual: &[f64], held: &[bool], closed: bool) -> Windows<D> {
        let mut w = Windows::empty(closed);
        w.refill(residual, held);
        w
    }

    /// No points yet (see [`Windows::refill`]).
    fn empty(closed: bool) -> Windows<D> {
        Windows {
            sums: Vec::new(),
            counts: Vec::new(),
            closed,
        }
    }

    /// The prefix sums of `residual` over the points not `held`, in the arrays of the last.
    fn refill(&mut self, residual: &[f64], held: &[bool]) {
        let (sums, counts) = (&mut self.sums, &mut self.counts);
        sums.clear();
        counts.clear();
        sums.reserve(held.len() + 1);
        counts.reserve(held.len() + 1);
        let (mut s, mut c) = ([0.0; D], 0);
        sums.push(s);
        counts.push(c);
        for (e, h) in residual.chunks_exact(D).zip(held) {
            if !h {
                for a in 0..D {
                    s[a] += e[a];
                }
                c += 1;
            }
            sums.push(s);
            counts.push(c);
        }
    }

    fn n(&self) -> usize {
        self.counts.len() - 1
    }

    /// For every point, the half-width of its window if the window's mean residual is
    /// significant (`|sum|²/count > threshold`), else 0. The window of point `i` is its
    /// smoothing length `(weights[i]/unit)^(−1/6)` points long ([`Penalized::local_weights`]).
    /// In parallel pieces (each point on its own: the same marks whatever the split); the
    /// half-width is computed once for each run of equal weights (the weights take a few
    /// values, and a power per point was most of a round's time at 10⁶ points).
    #[cfg(test)]
    fn significant(&self, weights: &[f64], unit: f64, threshold: f64) -> Vec<usize> {
        let mut marked = vec![0; self.n()];
        self.significant_into(weights, unit, threshold, &mut marked);
        marked
    }

    /// [`Windows::significant`] into `marked` (one entry a point, overwritten).
    fn significant_into(&self, weights: &[f64], unit: f64, threshold: f64, marked: &mut [usize]) {
        let n = self.n();
        let half_of = |w: f64| self.half_width((w / unit).powf(-1.0 / 6.0));
        let piece = |from: usize, out: &mut [usize]| {
            let mut halves = RunCache::default();
            for (k, o) in out.iter_mut().enumerate() {
                let i = from + k;
                let half = halves.get(weights[i], half_of);
                let (sum, count) = self.sum(i, half);
                let significant =
                    count > 0 && sum.iter().map(|s| s * s).sum::<f64>() / count as f64 > threshold;
                *o = if significant { half } else { 0 };
            }
        };
        if n >= PARALLEL_FROM {
            marked
                .par_chunks_mut(SIGNIFICANT_CHUNK)
                .enumerate()
                .for_each(|(c, out)| piece(c * SIGNIFICANT_CHUNK, out));
        } else {
            piece(0, marked);
        }
    }

    /// The half-width of a window `length` points long: at least 2, and the window no longer
    /// than the curve (at least 1 for the three points a curve has at least).
    fn half_width(&self, length: f64) -> usize {
        let most = if self.closed {
            (self.n() - 1) / 2
        } else {
            self.n() / 2
        };
        ((0.5 * length).round() as usize).max(2).min(most)
    }

    /// The sum over `[lo, hi)` of the prefix arrays, `0 ≤ lo ≤ hi ≤ n`.
    fn between(&self, lo: usize, hi: usize) -> ([f64; D], usize) {
        let mut s = [0.0; D];
        for (a, s) in s.iter_mut().enumerate() {
            *s = self.sums[hi][a] - self.sums[lo][a];
        }
        (s, self.counts[hi] - self.counts[lo])
    }

    /// The residuals summed over the window of half-width `half` about `i` (cyclic when
    /// closed, else cut at the ends), and the number of free points in it.
    fn sum(&self, i: usize, half: usize) -> ([f64; D], usize) {
        let mut total = ([0.0; D], 0);
        for (lo, hi) in spans(i, half, self.n(), self.closed) {
            let (s, c) = self.between(lo, hi);
            for a in 0..D {
                total.0[a] += s[a];
            }
            total.1 += c;
        }
        total
    }
}

/// The window of half-width `half` about `i` on a curve of `n` points as half-open index
/// ranges: one, or two when a closed curve's window wraps (the second may be empty).
fn spans(i: usize, half: usize, n: usize, closed: bool) -> [(usize, usize); 2] {
    if !closed {
        return [(i.saturating_sub(half), (i + half + 1).min(n)), (0, 0)];
    }
    let lo = i as isize - half as isize;
    let hi = i as isize + half as isize + 1;
    let n = n as isize;
    if lo < 0 {
        [((lo + n) as usize, n as usize), (0, hi as usize)]
    } else if hi > n {
        [(lo as usize, n as usize), (0, (hi - n) as usize)]
    } else {
        [(lo as usize, hi as usize), (0, 0)]
    }
}

/// Windows marked on a curve of `n` points, in O(1) each, by a difference array.
struct Marks {
    diff: Vec<isize>,
    closed: bool,
}

impl Marks {
    fn new(n: usize, closed: bool) -> Marks {
        Marks {
            diff: vec![0; n + 1],
            closed,
        }
    }

    /// Mark the window of half-width `half` about `i`.
    fn mark(&mut self, i: usize, half: usize) {
        let n = self.diff.len() - 1;
        for (lo, hi) in spans(i, half, n, self.closed) {
            if lo < hi {
                self.diff[lo] += 1;
                self.diff[hi] -= 1;
            }
        }
    }

    /// No window marked (the array kept for the next round's marks).
    fn clear(&mut self) {
        self.diff.fill(0);
    }

    /// Whether each point lies in a marked window, in order.
    fn marked(&self) -> impl Iterator<Item = bool> + '_ {
        let n = self.diff.len() - 1;
        self.diff[..n].iter().scan(0, |depth, d| {
            *depth += d;
            Some(*depth > 0)
        })
    }

    /// [`Marks::marked`], collected.
    #[cfg(test)]
    fn finish(self) -> Vec<bool> {
        self.marked().collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fair::band::energy::Metric;

    /// The discrepancy weight is the smallest `μ` whose minimiser meets the target, to the
    /// precision of the bisection it replaced: its minimiser meets the target, and one
    /// precision below it does not; the same `μ` as a 24-step bisection, within that
    /// precision. A noisy wave in the point form, at targets across the bracket.
    #[test]
    fn the_discrepancy_weight_is_the_bisections() {
        let n = 200;
        let pts: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let x = i as f64 * 0.05;
                // A deterministic ripple as the noise.
                [x, x.sin() + 0.03 * (7.3 * i as f64).sin()]
            })
            .collect();
        let energy = Energy::build(&pts, false, Metric::Jerk);
        let design = Design::Points { n };
        let (held, pinned) = (vec![false; n], vec![false; n]);
        let zeros = vec![0.0; 2 * n];
        let centres: Vec<f64> = pts.iter().flatten().copied().collect();
        let fit = Penalized::new(
            &energy, 1.0, &design, &held, &pinned, &zeros, &zeros, &centres,
        );
        let msr = |ln_mu: f64| {
            let y = fit.minimiser(|_| ln_mu.exp(), true).unwrap();
            fit.mean_square_residual(&y)
        };
        let (lo, hi) = ((2.0 * n as f64).powi(-6).max(1e-15 * fit.top).ln(), 0.0);
        let precision = (hi - lo) / f64::from(1u32 << BISECTIONS);
        for fraction in [0.05, 0.3, 0.6, 0.9] {
            // A target between the residuals at the two ends of the bracket.
            let target = msr(hi) + fraction * (msr(lo) - msr(hi));
            let mu = fit
                .discrepancy_weight(0.0, target, f64::INFINITY)
                .unwrap()
                .unwrap();
            assert!(
                msr(mu.ln()) <= target,
                "{fraction}: μ {mu} misses the target"
            );
            assert!(
                msr(mu.ln() - precision) > target,
                "{fraction}: μ {mu} not the smallest"
            );
            let (mut a, mut b) = (lo, hi);
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (a + b);
                if msr(mid) > target {
                    a = mid;
                } else {
                    b = mid;
                }
            }
            assert!(
                (mu.ln() - b).abs() <= precision,
                "{fraction}: {mu} against {}",
                b.exp()
            );
        }
    }

    /// Equal weights stay equal; a step of the weights becomes a monotone ramp between its two
    /// levels, as wide as the windows (3 smoothing lengths of each side's weight), open and
    /// closed; a closed curve's weights are smoothed across its seam.
    #[test]
    fn smoothing_the_log_weights_ramps_a_step() {
        let unit = 1.0;
        let flat = vec![1e-6; 50];
        for closed in [false, true] {
            for w in smooth_log_weights(&flat, unit, closed, WEIGHT_SMOOTHING) {
                assert!((w / 1e-6 - 1.0).abs() < 1e-12, "{w}");
            }
        }
        // Smoothing lengths (w/unit)^(-1/6): 10 points at 1e-6, 5 at 6.4e-5 (4³ higher).
        let (low, high) = (1e-6, 6.4e-5);
        let step: Vec<f64> = (0..200).map(|i| if i < 100 { low } else { high }).collect();
        let open = smooth_log_weights(&step, unit, false, WEIGHT_SMOOTHING);
        for pair in open.windows(2) {
            assert!(pair[1] >= pair[0] * (1.0 - 1e-12), "not monotone: {pair:?}");
        }
        assert!(
            open.iter()
                .all(|w| *w >= low * (1.0 - 1e-12) && *w <= high * (1.0 + 1e-12))
        );
        // Half widths: 15 points on the low side, 8 on the high side (3 × 10 / 2, 3 × 5 / 2).
        assert!((open[84] / low - 1.0).abs() < 1e-12 && open[85] > low * 1.01);
        assert!((open[108] / high - 1.0).abs() < 1e-12 && open[107] < high * 0.99);
        let closed = smooth_log_weights(&step, unit, true, WEIGHT_SMOOTHING);
        // Across the seam (point 199, high, next to point 0, low) the ramp goes the other way.
        assert!(closed[0] > low * 1.01 && closed[199] < high * 0.99);
        assert_eq!(&closed[20..80], &open[20..80]);
    }

    /// The smoothed weights are those of the prefix sums over all three copies kept whole
    /// (the first version), bit for bit: short curves, where a window reaches every copy, and
    /// a long one.
    #[test]
    fn smoothing_keeps_only_the_sums_it_reads() {
        fn whole(weights: &[f64], unit: f64, closed: bool, lengths: f64) -> Vec<f64> {
            let n = weights.len();
            let logs: Vec<f64> = weights.iter().map(|w| w.ln()).collect();
            let mut prefix = vec![0.0];
            let mut acc = 0.0;
            for l in logs.iter().chain(&logs).chain(&logs) {
                acc += l;
                prefix.push(acc);
            }
            (0..n)
                .map(|i| {
                    let length = lengths * (weights[i] / unit).powf(-1.0 / 6.0);
                    let half = ((0.5 * length).round() as usize).clamp(1, (n / 2).max(1));
                    let (lo, hi) = if closed {
                        (n + i - half, n + i + half + 1)
                    } else {
                        (n + i.saturating_sub(half), n + (i + half + 1).min(n))
                    };
                    ((prefix[hi] - prefix[lo]) / (hi - lo) as f64).exp()
                })
                .collect()
        }
        for n in [1, 2, 3, 7, 40, PARALLEL_FROM + 777] {
            // Runs of equal weights.
            let weights: Vec<f64> = (0..n)
                .map(|i| 1e-6 * 4f64.powi(((i / 1000 + i / 7) % 4) as i32))
                .collect();
            for closed in [false, true] {
                let got = smooth_log_weights(&weights, 1.0, closed, WEIGHT_SMOOTHING);
                let want = whole(&weights, 1.0, closed, WEIGHT_SMOOTHING);
                assert_eq!(got.len(), n);
                for (i, (g, w)) in got.iter().zip(&want).enumerate() {
                    assert_eq!(
                        g.to_bits(),
                        w.to_bits(),
                        "n {n}, closed {closed}, point {i}"
                    );
                }
            }
        }
    }

    /// The window about `i` by brute force: indices `i − half ..= i + half`, wrapped when
    /// closed, cut at the ends when open.
    fn brute(i: usize, half: usize, n: usize, closed: bool) -> Vec<usize> {
        (i as isize - half as isize..=i as isize + half as isize)
            .filter_map(|j| {
                if closed {
                    Some(j.rem_euclid(n as isize) as usize)
                } else if (0..n as isize).contains(&j) {
                    Some(j as usize)
                } else {
                    None
                }
            })
            .collect()
    }

    /// The span sums give the squared residual the points give.
    #[test]
    fn span_sums_give_the_residual() {
        for closed in [false, true] {
            let map = crate::fair::band::design::tests::map(closed);
            let n = map.first.len();
            let pinned: Vec<bool> = (0..n).map(|i| i == 0 || i % 4 == 3).collect();
            let centres: Vec<f64> = (0..2 * n).map(|k| (k as f64 * 0.37).cos()).collect();
            let y: Vec<f64> = (0..2 * map.vars).map(|k| (k as f64 * 1.1).sin()).collect();
            let design = Design::Spline(map.clone());
            let mut q = vec![0.0; 2 * n];
            design.eval::<2>(&y, &mut q);
            let want: f64 = (0..2 * n)
                .filter(|k| !pinned[k / 2])
                .map(|k| (q[k] - centres[k]).powi(2))
                .sum();
            let got: f64 = SpanSums::<2>::of(&map, &pinned, &centres)
                .iter()
                .map(|s| s.value(map.vars, &y))
                .sum();
            assert!((got - want).abs() < 1e-12 * want, "{got} {want}");
        }
    }

    /// The Gram matrix and the pull taken from the span sums are those of the sweeps over
    /// every point they replace: the Gram matrix bit for bit (the sweep's sums at weight 2,
    /// in the same order), the pull to rounding, with held ends and pinned points.
    #[test]
    fn span_sums_give_the_sweeps_gram_and_pull() {
        for closed in [false, true] {
            let map = crate::fair::band::design::tests::map(closed);
            let (n, vars) = (map.first.len(), map.vars);
            let pinned: Vec<bool> = (0..n).map(|i| i == 0 || i % 4 == 3).collect();
            let held: Vec<bool> = (0..vars)
                .map(|j| !closed && (j == 0 || j + 1 == vars))
                .collect();
            let centres: Vec<f64> = (0..2 * n).map(|k| (k as f64 * 0.37).cos()).collect();
            let fixed: Vec<f64> = (0..2 * vars)
                .map(|k| {
                    if held[k / 2] {
                        (k as f64 * 0.9).sin()
                    } else {
                        0.0
                    }
                })
                .collect();
            let sums = SpanSums::<2>::of(&map, &pinned, &centres);
            let design = Design::Spline(map.clone());
            let dim = 2 * vars;
            let (bw, width) = (7, 15);
            let mut band = vec![0.0; dim * width];
            design.for_each_weight_lower::<2>(
                |_| 2.0,
                &pinned,
                |r, c, v| {
                    if !held[r / 2] && !held[c / 2] {
                        band[r * width + offset(r, c, dim, bw)] += v;
                    }
                },
            );
            let swept = band_entries(&band, dim, bw);
            assert_eq!(span_gram(&map, &sums, &held), swept, "closed {closed}");
            let mut shifted = vec![0.0; 2 * n];
            design.eval_then::<2>(&fixed, &mut shifted, |i, q| {
                if pinned[i] {
                    [0.0; 2]
                } else {
                    std::array::from_fn(|a| 2.0 * (centres[i * 2 + a] - q[a]))
                }
            });
            let mut want = vec![0.0; dim];
            design.eval_t_add::<2>(&shifted, &mut want);
            let got = span_pull(&map, &sums, &fixed);
            for (g, w) in got.iter().zip(&want) {
                assert!((g - w).abs() <= 1e-13, "closed {closed}: {g} {w}");
            }
        }
    }

    #[test]
    fn window_sums_and_marks_match_brute_force() {
        for closed in [false, true] {
            for n in [3, 4, 7, 20] {
                let residual: Vec<[f64; 2]> = (0..n)
                    .map(|i| [(i as f64 * 0.7).sin(), (i as f64 * 1.3).cos()])
                    .collect();
                let held: Vec<bool> = (0..n).map(|i| i % 5 == 1).collect();
                let windows = Windows::<2>::new(residual.as_flattened(), &held, closed);
                for length in [0.0, 3.0, 6.0, 11.0, 100.0] {
                    let half = windows.half_width(length);
                    assert!(2 * half < n + usize::from(!closed), "{n} {half}");
                    for i in 0..n {
                        let (sum, count) = windows.sum(i, half);
                        let idx = brute(i, half, n, closed);
                        let free: Vec<usize> = idx.iter().copied().filter(|j| !held[*j]).collect();
                        assert_eq!(count, free.len(), "{closed} {n} {i} {half}");
                        for a in 0..2 {
                            let want: f64 = free.iter().map(|j| residual[*j][a]).sum();
                            assert!((sum[a] - want).abs() < 1e-12);
                        }
                        let mut marks = Marks::new(n, closed);
                        marks.mark(i, half);
                        let got = marks.finish();
                        for (j, g) in got.iter().enumerate() {
                            assert_eq!(*g, idx.contains(&j), "{closed} {n} {i} {half} {j}");
                        }
                    }
                }
            }
        }
    }

    /// The parallel scan for significant windows marks what the per-point rule marks, with
    /// weights in runs (as the rounds leave them) and unevenly, open and closed, below and
    /// above the size from which it runs in pieces.
    #[test]
    fn significant_windows_match_the_per_point_rule() {
        for closed in [false, true] {
            for n in [50, PARALLEL_FROM + 1234] {
                let residual: Vec<f64> = (0..2 * n)
                    .map(|k| (k as f64 * 0.37).sin() + 0.6 * ((k / 2) as f64 * 0.02).sin())
                    .collect();
                let held: Vec<bool> = (0..n).map(|i| i % 97 == 3).collect();
                let unit = 1.0;
                let weights: Vec<f64> = (0..n)
                    .map(|i| {
                        if i % 7 == 0 {
                            1e-3 * (1.0 + i as f64 / n as f64)
                        } else {
                            1e-4 * 4.0_f64.powi(((i / 1000) % 3) as i32)
                        }
                    })
                    .collect();
                let windows = Windows::<2>::new(&residual, &held, closed);
                let threshold = 1.0;
                let got = windows.significant(&weights, unit, threshold);
                let mut count = 0;
                for i in 0..n {
                    let half = windows.half_width((weights[i] / unit).powf(-1.0 / 6.0));
                    let (sum, c) = windows.sum(i, half);
                    let hit = c > 0 && (sum[0] * sum[0] + sum[1] * sum[1]) / c as f64 > threshold;
                    assert_eq!(got[i], if hit { half } else { 0 }, "{closed} {n} {i}");
                    count += usize::from(hit);
                }
                assert!(count > 0 && count < n, "{count} of {n}");
            }
        }
    }
}
