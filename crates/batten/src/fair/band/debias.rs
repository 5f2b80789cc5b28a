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
//! The constrained problem is then solved once with that `μ` by the interior point.

use super::energy::Energy;
use crate::error::Result;
use crate::numeric::{CyclicSymBanded, SymBanded};

/// The most the debiased energy may exceed the passes' optimum, as a factor.
pub(super) const ENERGY_CAP: f64 = 4.0;

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

    /// The unconstrained minimiser of `E(s + y) + μ |y − c|²` with held points at `c`:
    /// `(2A + 2μ I) y = 2μ c − 2 A s` on the free rows.
    fn minimiser(&self, mu: f64) -> Result<Vec<f64>> {
        let held = self.held;
        let mut y: Vec<f64> = (0..self.energy.n * D)
            .map(|k| {
                if held[k / D] {
                    self.centres[k]
                } else {
                    2.0 * mu * self.centres[k] - 2.0 * self.anchor[k] - 2.0 * self.coupling[k]
                }
            })
            .collect();
        match &self.base {
            Base::Closed(base) => {
                let mut m = base.clone();
                for k in 0..y.len() {
                    m.add(k, k, 2.0 * mu);
                }
                m.factorize()?;
                m.solve_in_place(&mut y)?;
            }
            Base::Open(base) => {
                let mut m = base.clone();
                for k in (0..y.len()).filter(|k| !held[k / D]) {
                    m.add(k, k, 2.0 * mu);
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
        let more_data = |ln_mu: f64| match self.minimiser(ln_mu.exp()) {
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
}
