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
//! so a bisection on `log μ` finds it, each step one banded solve, O(n). Where `σ̂`
//! underestimates the noise the target cannot be met; the energy is then capped at
//! [`ENERGY_CAP`] times the passes' optimum, so the stage never returns to the noise.
//! Where one `μ` still flattens a feature, [`Penalized::local_weights`] raises it there, from
//! the residual's windowed means (see `docs/algorithms/band.md`, local data weights).
//! The constrained problem is then solved once with those weights by the interior point.

use super::energy::Energy;
use crate::error::Result;
use crate::numeric::{CyclicSymBanded, SymBanded};

/// The most the debiased energy may exceed the passes' optimum, as a factor.
pub(super) const ENERGY_CAP: f64 = 4.0;

/// Rounds of [`Penalized::local_weights`].
const LOCAL_ROUNDS: usize = 6;
/// The factor by which a round raises the data weight around a biased window.
const LOCAL_FACTOR: f64 = 4.0;

/// Bisection steps on `log μ` (the bracket spans 6·ln(2n) in `ln μ`, under 90 for 10⁶ points; 24 halvings
/// leave `μ` within 1e-5 of itself, far below what the residual sees).
const BISECTIONS: usize = 24;

/// The matrix `2A` with the held points' rows and columns replaced by the identity, before
/// the data weight is added.
enum Base {
    Open(SymBanded),
    Closed(CyclicSymBanded),
}

/// The penalised problem, in the solver's units (see `solver.rs`): `y` relative to the
/// reference `s`, ball centres `c`. Everything that does not depend on `μ` is assembled once
/// by [`Penalized::new`]; each `μ` of the bisection then costs one copy, one diagonal and
/// one banded factorisation.
pub(super) struct Penalized<'a, const D: usize> {
    energy: &'a Energy<D>,
    held: &'a [bool],
    /// `A s`.
    anchor: &'a [f64],
    /// `c = a − s`.
    centres: &'a [f64],
    base: Base,
    /// `A` applied to the held points' centres (zero elsewhere): their columns, moved to the
    /// right-hand side.
    coupling: Vec<f64>,
    /// The largest entry `2A` reports on the diagonal (one window's), the scale of rounding.
    top: f64,
}

impl<'a, const D: usize> Penalized<'a, D> {
    pub fn new(
        energy: &'a Energy<D>,
        held: &'a [bool],
        anchor: &'a [f64],
        centres: &'a [f64],
    ) -> Penalized<'a, D> {
        let dim = energy.n * D;
        // Held points sit at their centres: their columns go to the right-hand side.
        let fixed: Vec<f64> = (0..dim)
            .map(|k| if held[k / D] { centres[k] } else { 0.0 })
            .collect();
        let mut coupling = vec![0.0; dim];
        energy.apply_add(&fixed, &mut coupling);
        let bw = 4 * D - 1;
        let base = if energy.closed {
            let mut m = CyclicSymBanded::zeros(dim, bw);
            energy.for_each_lower(2.0, |r, c, v| m.add(r, c, v));
            Base::Closed(m)
        } else {
            let mut m = SymBanded::zeros(dim, bw);
            energy.for_each_lower(2.0, |r, c, v| {
                if !held[r / D] && !held[c / D] {
                    m.add(r, c, v);
                }
            });
            for k in (0..dim).filter(|k| held[k / D]) {
                m.add(k, k, 1.0);
            }
            Base::Open(m)
        };
        let mut top = 0.0_f64;
        energy.for_each_lower(2.0, |r, c, v| {
            if r == c {
                top = top.max(v.abs());
            }
        });
        Penalized {
            energy,
            held,
            anchor,
            centres,
            base,
            coupling,
            top,
        }
    }

    /// The unconstrained minimiser of `E(s + y) + Σ μ_i |y_i − c_i|²` with held points at `c`:
    /// `(2A + 2 diag μ) y = 2 μ c − 2 A s` on the free rows (`weight(i)` gives `μ_i`).
    fn minimiser(&self, weight: impl Fn(usize) -> f64) -> Result<Vec<f64>> {
        let held = self.held;
        let mut y: Vec<f64> = (0..self.energy.n * D)
            .map(|k| {
                if held[k / D] {
                    self.centres[k]
                } else {
                    2.0 * weight(k / D) * self.centres[k]
                        - 2.0 * self.anchor[k]
                        - 2.0 * self.coupling[k]
                }
            })
            .collect();
        match &self.base {
            Base::Closed(base) => {
                let mut m = base.clone();
                for k in 0..y.len() {
                    m.add(k, k, 2.0 * weight(k / D));
                }
                m.factorize()?;
                m.solve_in_place(&mut y)?;
            }
            Base::Open(base) => {
                let mut m = base.clone();
                for k in (0..y.len()).filter(|k| !held[k / D]) {
                    m.add(k, k, 2.0 * weight(k / D));
                }
                m.factorize()?;
                m.solve_in_place(&mut y)?;
            }
        }
        Ok(y)
    }

    /// `E(s + y)` from `A s` and `E(s)`.
    fn energy_at(&self, y: &[f64], anchor_energy: f64) -> f64 {
        let mut ay = vec![0.0; y.len()];
        self.energy.apply_add(y, &mut ay);
        let quad: f64 = y.iter().zip(&ay).map(|(a, b)| a * b).sum();
        let lin: f64 = y.iter().zip(self.anchor).map(|(a, b)| a * b).sum();
        anchor_energy + 2.0 * lin + quad
    }

    /// The mean squared residual `(1/free) Σ |y_i − c_i|²` over the free points.
    fn mean_square_residual(&self, y: &[f64]) -> f64 {
        let free = self.held.iter().filter(|h| !**h).count().max(1);
        let sum: f64 = y
            .iter()
            .zip(self.centres)
            .map(|(a, c)| (a - c) * (a - c))
            .sum();
        sum / free as f64
    }

    /// The data weight `μ` of the discrepancy principle: the smallest `μ` (in the bracket)
    /// whose minimiser's mean squared residual is at most `target`, or whose energy reaches
    /// `cap` (`E(s)` is the energy of the reference, the passes' result). `None` when the
    /// reference already meets the target (nothing to debias) or no `μ` helps.
    pub fn discrepancy_weight(
        &self,
        anchor_energy: f64,
        target: f64,
        cap: f64,
    ) -> Result<Option<f64>> {
        let n = self.energy.n as f64;
        let reference_residual = self.mean_square_residual(&vec![0.0; self.centres.len()]);
        if target.is_nan()
            || target <= 0.0
            || reference_residual <= target
            || cap.is_nan()
            || cap <= anchor_energy
        {
            return Ok(None);
        }
        // In units of the mean spacing a data weight μ smooths over about μ^(-1/6) points:
        // from twice the curve down to a single point, and no lower than rounding of `2A`
        // leaves meaningful.
        let (mut lo, mut hi) = ((2.0 * n).powi(-6).max(1e-15 * self.top).ln(), 1.0_f64.ln());

        // A weight so small that rounding makes the matrix singular (the energy's null space,
        // quadratics in the parameter, rests on `μ` alone) asks for more weight too.
        let more_data = |ln_mu: f64| match self.minimiser(|_| ln_mu.exp()) {
            Ok(y) => {
                self.mean_square_residual(&y) > target && self.energy_at(&y, anchor_energy) < cap
            }
            Err(_) => true,
        };
        if !more_data(lo) {
            return Ok(None);
        }
        for _ in 0..BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if more_data(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Ok(Some(hi.exp()))
    }

    /// Raise the data weight where the residual is biased: starting from `μ` everywhere,
    /// each round computes the unconstrained minimiser, averages its residual `y − c` over a
    /// window as long as the smoothing (`μ^(−1/6)` points), and multiplies the weights
    /// around every window whose mean is significant for noise of standard deviation `noise`
    /// per coordinate (`|mean|² · count > z² noise²`) by [`LOCAL_FACTOR`]. The residual of a
    /// smoother fed only noise is high-frequency, so its windowed means stay well under that
    /// threshold; a feature the energy flattens leaves a one-signed residual as long as the
    /// feature, and is found. Stops when no window is significant, after [`LOCAL_ROUNDS`], or
    /// before a round whose energy would pass `cap`. Returns the weights and the number of
    /// points whose weight was raised.
    pub fn local_weights(
        &self,
        mu: f64,
        anchor_energy: f64,
        cap: f64,
        noise: f64,
        z: f64,
    ) -> Result<(Vec<f64>, usize)> {
        let n = self.energy.n;
        let mut weights = vec![mu; n];
        if z <= 0.0 || noise <= 0.0 || n < 3 {
            return Ok((weights, 0));
        }
        let threshold = z * z * noise * noise;
        let mut y = self.minimiser(|i| weights[i])?;
        for _ in 0..LOCAL_ROUNDS {
            // The residual (zero at held points, which the minimiser leaves at their centres).
            let residual: Vec<[f64; D]> = (0..n)
                .map(|i| std::array::from_fn(|a| y[i * D + a] - self.centres[i * D + a]))
                .collect();
            let windows = Windows::new(&residual, self.held, self.energy.closed);
            let mut raise = Marks::new(n, self.energy.closed);
            let mut any = false;
            for i in 0..n {
                let half = windows.half_width(weights[i].powf(-1.0 / 6.0));
                let (sum, count) = windows.sum(i, half);
                if count == 0 {
                    continue;
                }
                let norm2: f64 = sum.iter().map(|s| s * s).sum::<f64>() / count as f64;
                if norm2 > threshold {
                    any = true;
                    raise.mark(i, half);
                }
            }
            if !any {
                break;
            }
            let raise = raise.finish();
            let trial: Vec<f64> = weights
                .iter()
                .zip(&raise)
                .map(|(w, r)| if *r { (w * LOCAL_FACTOR).min(1.0) } else { *w })
                .collect();
            let trial_y = self.minimiser(|i| trial[i])?;
            if self.energy_at(&trial_y, anchor_energy) > cap {
                break;
            }
            weights = trial;
            y = trial_y;
        }
        let raised = weights.iter().filter(|w| **w > mu).count();
        Ok((weights, raised))
    }
}

/// Windowed sums of the free points' residuals in O(1) each, from prefix sums.
struct Windows<const D: usize> {
    /// `sums[j]`: the residuals of the free points before `j`, summed.
    sums: Vec<[f64; D]>,
    /// `counts[j]`: the free points before `j`.
    counts: Vec<usize>,
    closed: bool,
}

impl<const D: usize> Windows<D> {
    fn new(residual: &[[f64; D]], held: &[bool], closed: bool) -> Windows<D> {
        let mut sums = Vec::with_capacity(residual.len() + 1);
        let mut counts = Vec::with_capacity(residual.len() + 1);
        let (mut s, mut c) = ([0.0; D], 0);
        sums.push(s);
        counts.push(c);
        for (e, h) in residual.iter().zip(held) {
            if !h {
                for a in 0..D {
                    s[a] += e[a];
                }
                c += 1;
            }
            sums.push(s);
            counts.push(c);
        }
        Windows {
            sums,
            counts,
            closed,
        }
    }

    fn n(&self) -> usize {
        self.counts.len() - 1
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

    /// Whether each point lies in a marked window.
    fn finish(self) -> Vec<bool> {
        let n = self.diff.len() - 1;
        let mut depth = 0;
        (0..n)
            .map(|j| {
                depth += self.diff[j];
                depth > 0
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn window_sums_and_marks_match_brute_force() {
        for closed in [false, true] {
            for n in [3, 4, 7, 20] {
                let residual: Vec<[f64; 2]> = (0..n)
                    .map(|i| [(i as f64 * 0.7).sin(), (i as f64 * 1.3).cos()])
                    .collect();
                let held: Vec<bool> = (0..n).map(|i| i % 5 == 1).collect();
                let windows = Windows::new(&residual, &held, closed);
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
}
