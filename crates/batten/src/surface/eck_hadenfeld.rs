//! `eck-hadenfeld` for surfaces: J. Hadenfeld's local energy fairing of B-spline surfaces
//! (the surface form of M. Eck and J. Hadenfeld, *Local energy fairing of B-spline curves*,
//! 1995, reviewed by Salvi & Várady, `../shared/papers/salvi-varady-local-fairing.txt` §3.2),
//! the baseline for [`super::salvi`].
//!
//! The thin-plate energy `E = ∬ |S_uu|² + 2|S_uv|² + |S_vv|² du dv` of a non-rational surface
//! is a quadratic form in the control points, `E = Σ_r Σ_s G_rs d_r·d_s`, with the
//! tensor-product Gram matrix
//!
//! ```text
//! G_(ij),(kl) = G2u_ik G0v_jl + 2 G1u_ik G1v_jl + G0u_ik G2v_jl,   Gd_ab = ∫ N_a^{(d)} N_b^{(d)}
//! ```
//!
//! (1-D Gram matrices by exact Gauss–Legendre quadrature span by span). As a function of one
//! control point, `E = G_rr |d_r − d_r*|² + const` with the closed-form minimiser
//! `d_r* = −(Σ_{s≠r} G_rs d_s)/G_rr`. Each move takes the movable point, not in the
//! recently-moved list, whose move to `d_r*` clamped into the ball `|d_r − d_r⁰| ≤ δ`
//! (eq 11, in 3-D) lowers E most; the quadratic is isotropic, so the clamped point is the
//! minimiser over the ball and a move never raises E. The run stops when no move lowers E by
//! more than [`MIN_REL_DECREASE`] of its value, or after `max_iterations` moves (default
//! [`DEFAULT_MAX_ITERATIONS`]).
//!
//! Rational surfaces are refused: their energy is not a quadratic form in the control points.

use std::collections::BTreeMap;

use nalgebra::DMatrix;
use serde_json::json;

use super::fairing::{MethodRun, Problem};
use super::patch::{BSplineSurface, Xyz, dot, sub};
use super::target::gram_of_degree;
use crate::error::{Error, Result};
use crate::fair::FairStatus;
use crate::fair::local::{DEFAULT_TABU_LENGTH, RecentList, clamp_to_original, select_candidate};

/// Default move budget.
pub(super) const DEFAULT_MAX_ITERATIONS: usize = 2000;

/// Stop when the best move lowers the energy by less than this fraction of it.
pub(super) const MIN_REL_DECREASE: f64 = 1e-9;

/// The 1-D Gram matrices of a surface, in u and v.
struct Grams {
    u: [DMatrix<f64>; 3],
    v: [DMatrix<f64>; 3],
    nu: usize,
    nv: usize,
    p: usize,
    q: usize,
}

impl Grams {
    fn of(s: &BSplineSurface) -> Grams {
        let (nu, nv) = s.size();
        let (p, q) = s.degree();
        let (ku, kv) = s.knots();
        Grams {
            u: gram_of_degree(ku, p, nu),
            v: gram_of_degree(kv, q, nv),
            nu,
            nv,
            p,
            q,
        }
    }

    /// `G_(ij),(kl)`.
    fn entry(&self, i: usize, j: usize, k: usize, l: usize) -> f64 {
        self.u[2][(i, k)] * self.v[0][(j, l)]
            + 2.0 * self.u[1][(i, k)] * self.v[1][(j, l)]
            + self.u[0][(i, k)] * self.v[2][(j, l)]
    }

    /// `(G d)_r` without the diagonal term, and `G_rr`, for `r = (i, j)`.
    fn off_diagonal(&self, c: &[Xyz], i: usize, j: usize) -> (Xyz, f64) {
        let mut sum = [0.0; 3];
        let mut diag = 0.0;
        for k in i.saturating_sub(self.p)..(i + self.p + 1).min(self.nu) {
            for l in j.saturating_sub(self.q)..(j + self.q + 1).min(self.nv) {
                let g = self.entry(i, j, k, l);
                if k == i && l == j {
                    diag = g;
                    continue;
                }
                let d = c[k * self.nv + l];
                for x in 0..3 {
                    sum[x] += g * d[x];
                }
            }
        }
        (sum, diag)
    }

    fn energy(&self, c: &[Xyz]) -> f64 {
        let mut e = 0.0;
        for i in 0..self.nu {
            for j in 0..self.nv {
                let (off, diag) = self.off_diagonal(c, i, j);
                let d = c[i * self.nv + j];
                e += dot(d, off) + diag * dot(d, d);
            }
        }
        e
    }
}

/// The thin-plate energy `∬ |S_uu|² + 2|S_uv|² + |S_vv|² du dv` of the polynomial surface
/// with the control points of `s` (for a rational surface, of its control net taken as a
/// polynomial surface).
pub(super) fn thin_plate_energy(s: &BSplineSurface) -> f64 {
    Grams::of(s).energy(s.control_points())
}

/// Run the method (called by [`super::fair_surface`]).
pub(crate) fn run(p: &Problem<'_>) -> Result<MethodRun> {
    let s = p.surface;
    if s.weights().is_some() {
        return Err(Error::InvalidParameter {
            name: "method".into(),
            reason: "eck-hadenfeld needs a non-rational surface (no weights)".into(),
        });
    }
    let g = Grams::of(s);
    let (nu, nv) = s.size();
    let original = s.control_points().to_vec();
    let mut control = original.clone();
    let max_iter = p.max_iterations.unwrap_or(DEFAULT_MAX_ITERATIONS);
    let tabu = p.common.tabu.unwrap_or(DEFAULT_TABU_LENGTH);
    let mut recent = RecentList::new(tabu);
    let mut energy = g.energy(&control);
    let mut history = vec![energy];
    let mut moves = 0;
    let mut status = FairStatus::IterationLimit;
    let proposal = |control: &[Xyz], k: usize| -> (Xyz, f64) {
        let (i, j) = (k / nv, k % nv);
        let (off, diag) = g.off_diagonal(control, i, j);
        if diag <= 0.0 {
            return (control[k], 0.0);
        }
        let star = [-off[0] / diag, -off[1] / diag, -off[2] / diag];
        let (to, _) = clamp_to_original(&original[k], &star, p.delta);
        let here = sub(control[k], star);
        let there = sub(to, star);
        (to, diag * (dot(here, here) - dot(there, there)))
    };
    for _ in 0..max_iter {
        let gains: Vec<f64> = (0..nu * nv)
            .map(|k| {
                if p.movable[k] {
                    proposal(&control, k).1
                } else {
                    0.0
                }
            })
            .collect();
        let best = gains.iter().fold(0.0f64, |m, &x| m.max(x));
        // NaN energies stop the run too.
        let worth_it = best > MIN_REL_DECREASE * energy;
        if !worth_it || p.delta <= 0.0 {
            status = if moves == 0 {
                FairStatus::NoChange
            } else {
                FairStatus::Converged
            };
            break;
        }
        let Some(k) = select_candidate(&gains, &p.movable, &mut recent) else {
            break;
        };
        recent.push(k);
        let (to, gain) = proposal(&control, k);
        if gain > 0.0 {
            control[k] = to;
            energy = g.energy(&control);
            moves += 1;
        }
        history.push(energy);
    }
    let mut parameters = BTreeMap::new();
    parameters.insert("tabu".into(), json!(tabu));
    parameters.insert("max_iterations".into(), json!(max_iter));
    Ok(MethodRun {
        control,
        moves,
        rejected: history.len() - 1 - moves,
        status: Some(status),
        history,
        parameters,
    })
}
