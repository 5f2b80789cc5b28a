//! Constraint generation for the spline form of `band`.
//!
//! Dense points carry hundreds of points per knot span, and at the optimum only a few of them
//! touch the band's edge (21 of 10⁵ on a noisy half ellipse, none on a debiased sine). Every
//! interior-point iteration over all the points would sweep them all several times for
//! constraints that play no part. The spline form therefore solves the band problem on a
//! working set `S` of points and checks the others:
//!
//! 1. The debiasing stage's data term `Σ μ_i |(B y)_i − c_i|²` covers every point; it is
//!    folded into the quadratic once (per knot span `Σ μ_i b_i b_iᵀ`, written as up to four
//!    rank-one windows of the energy, and its linear and constant parts), so the working set
//!    carries only constraints.
//! 2. `S` starts with, in every run of points on one knot span, the point farthest from the
//!    reference (which keeps the quadratics of the energy's null space bounded), and every
//!    point farther than [`SELECT`] tolerances from it.
//! 3. The interior point solves the problem on `S`. When a point outside `S` is outside its
//!    ball, every point outside `S` farther than [`ADD`] from its input point joins `S`, and
//!    the next round starts on the segment from the strictly feasible start to the last
//!    solution, as far along as keeps the new points strictly inside. The points outside `S`
//!    are checked when the round's relative gap first falls below 1e-1, and again below 1e-2
//!    ([`CHECK_GAPS_REL`](super::solver::CHECK_GAPS_REL); one sweep over the points each,
//!    for a set of at least [`CHECK_SET_FRACTION`]th of them): if one is outside its ball
//!    already, the round ends there, since its last iterations would only refine a solution
//!    the next round replaces (with the check at 1e-2 alone, the dense quality splits: 10 856
//!    → 10 493 and 10 905 → 10 560 iterations, the same results; #14's sine 100 → 89; with
//!    the check at 1e-1 first, the sine 89 → 79).
//!
//! When no point is outside its ball the working set's optimum is the full problem's (it
//! minimises over a larger set and is feasible), with multipliers zero at the points outside
//! `S`. `S` only grows, so the rounds end; after [`MAX_ROUNDS`] the full problem is solved from the
//! last start with what is left of the iteration budget.

use super::design::{Design, SplineMap};
use super::energy::{Energy, Window};
use super::solver::{Problem, Solution, solve_all, solve_all_checked};
use crate::error::Result;
use crate::numeric::PARALLEL_FROM;
use rayon::prelude::*;

/// Points farther than this from the reference (in tolerances) start in the working set.
const SELECT: f64 = 0.8;
/// After a round that left points outside their balls, the points outside the working set
/// farther than this from their input points join it.
const ADD: f64 = 0.9;
/// The distance (in tolerances) at which a point that joins the working set starts the next
/// round, at most.
const RESTART_RADIUS: f64 = 0.95;
/// A round is checked before it converges ([`solve_all_checked`]) when its set holds at least
/// this fraction (as `1/x`) of the points: the check is one sweep over every point, and an
/// iteration on the set a dozen sweeps over the set and a factorisation. #14's sine (sets of
/// 28 000–52 000 of 10⁶ points) saves 11 of 100 iterations; a 10⁶-point half ellipse (sets
/// of 260–1 900) would sweep its million points once a round to save iterations that cost
/// less than that sweep.
const CHECK_SET_FRACTION: usize = 64;
/// The least piece of the sweeps over every point that run in parallel.
const PIECE: usize = 1 << 14;
/// Rounds before the full problem is solved instead.
const MAX_ROUNDS: usize = 30;
/// Pivots of a knot span's data Gram matrix below this fraction of its largest diagonal
/// entry are rounding (the matrix is semi-definite) and dropped.
const PIVOT_FLOOR_REL: f64 = 1e-14;

/// Solve the band problem `p` of the spline design `map` from the strictly feasible `start`
/// on a working set of its points (see the module's documentation).
pub(super) fn solve<const D: usize>(
    p: &Problem<'_, D>,
    map: &SplineMap,
    start: &[f64],
) -> Result<Solution> {
    let n = map.first.len();
    let folded = fold_data(p, map);
    let (energy, anchor, anchor_energy) = match &folded {
        Some((e, a, c)) => (e, a.as_slice(), *c),
        None => (p.energy, p.anchor.as_slice(), p.anchor_energy),
    };
    let mut in_set = initial_set::<D>(map, &p.centres, p.pinned);
    let mut y_start = start.to_vec();
    let mut iterations = 0;
    let mut r = vec![0.0; n * D];
    for _ in 0..MAX_ROUNDS {
        let set: Vec<usize> = (0..n).filter(|&i| in_set[i]).collect();
        let design = Design::Spline(SplineMap {
            vars: map.vars,
            first: set.iter().map(|&i| map.first[i]).collect(),
            basis: set.iter().map(|&i| map.basis[i]).collect(),
        });
        let centres: Vec<f64> = set
            .iter()
            .flat_map(|&i| p.centres[i * D..(i + 1) * D].iter().copied())
            .collect();
        let pinned = vec![false; set.len()];
        let sub = Problem {
            energy,
            anchor: anchor.to_vec(),
            anchor_energy,
            design: &design,
            centres,
            held: p.held,
            pinned: &pinned,
            start: Some(y_start.clone()),
            max_iterations: p.max_iterations.saturating_sub(iterations),
            gap_rel: p.gap_rel,
            fidelity: Vec::new(),
        };
        // Once the round is well on its way, a point outside the set already outside its ball
        // ends it there: its last iterations would only refine a solution the next round
        // replaces. The check sweeps every point, so only a set of at least
        // 1/[`CHECK_SET_FRACTION`] of them, whose iterations cost more, is checked.
        let check = set.len() * CHECK_SET_FRACTION >= n;
        // Point `i`, residual `ri`, is outside the set and outside its ball.
        let escaped = |i: usize, ri: &[f64]| !in_set[i] && !p.pinned[i] && norm2(ri) > 1.0;
        let sol = solve_all_checked(&sub, |y| {
            check
                && p.design.any_point::<D>(y, |i, q| {
                    let ri: [f64; D] = std::array::from_fn(|a| q[a] - p.centres[i * D + a]);
                    escaped(i, &ri)
                })
        })?;
        iterations += sol.iterations;
        p.design
            .residual::<D>(&sol.y, &p.centres, Some(p.pinned), &mut r);
        let outside = (0..n)
            .into_par_iter()
            .with_min_len(PIECE)
            .any(|i| escaped(i, &r[i * D..(i + 1) * D]));
        if !outside {
            #[cfg(test)]
            let multipliers = {
                let mut all = vec![0.0; n];
                for (k, &i) in set.iter().enumerate() {
                    all[i] = sol.multipliers[k];
                }
                all
            };
            return Ok(Solution {
                r,
                y: sol.y,
                objective: sol.objective,
                iterations,
                gap: sol.gap,
                converged: sol.converged,
                #[cfg(test)]
                multipliers,
            });
        }
        // The points that join, and how far along the segment from the start to this
        // solution the next round may start.
        let mut theta = 1.0_f64;
        for i in 0..n {
            let ri = &r[i * D..(i + 1) * D];
            if in_set[i] || p.pinned[i] || norm2(ri) <= ADD * ADD {
                continue;
            }
            in_set[i] = true;
            // The point's residual at the start (the same sums as a sweep's).
            let q = p.design.value::<D>(i, start);
            let a: [f64; D] = std::array::from_fn(|k| q[k] - p.centres[i * D + k]);
            let d: [f64; D] = std::array::from_fn(|k| ri[k] - a[k]);
            let a2 = norm2(&a);
            let radius2 = (RESTART_RADIUS * RESTART_RADIUS).max(0.5 * (a2 + 1.0));
            theta = theta.min(segment_exit(&a, &d, radius2));
        }
        for (y, (s, x)) in y_start.iter_mut().zip(start.iter().zip(&sol.y)) {
            *y = s + theta * (x - s);
        }
    }
    // The full problem, from the last start (strictly feasible for every point), with what
    // is left of the iteration budget.
    let full = Problem {
        energy: p.energy,
        anchor: p.anchor.clone(),
        anchor_energy: p.anchor_energy,
        design: p.design,
        centres: p.centres.clone(),
        held: p.held,
        pinned: p.pinned,
        start: Some(y_start),
        max_iterations: p.max_iterations.saturating_sub(iterations),
        gap_rel: p.gap_rel,
        fidelity: p.fidelity.clone(),
    };
    let mut sol = solve_all(&full)?;
    sol.iterations += iterations;
    Ok(sol)
}

fn norm2(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum()
}

/// The largest `θ ∈ [0, 1]` with `|a + θ d|² ≤ radius2`, for `|a|² < radius2`.
fn segment_exit(a: &[f64], d: &[f64], radius2: f64) -> f64 {
    let qa = norm2(d);
    if qa == 0.0 {
        return 1.0;
    }
    let qb: f64 = 2.0 * a.iter().zip(d).map(|(x, y)| x * y).sum::<f64>();
    let qc = norm2(a) - radius2;
    // The positive root of qa θ² + qb θ + qc (qc < 0), in the form that does not cancel.
    let disc = (qb * qb - 4.0 * qa * qc).max(0.0).sqrt();
    let root = if qb >= 0.0 {
        -2.0 * qc / (qb + disc)
    } else {
        (disc - qb) / (2.0 * qa)
    };
    root.clamp(0.0, 1.0)
}

/// The first working set: in every run of points on one knot span the point farthest from
/// the reference (`|c_i|`), and every point farther than [`SELECT`]; pinned points never.
/// In parallel pieces cut where a knot span begins (each run whole in one piece).
fn initial_set<const D: usize>(map: &SplineMap, centres: &[f64], pinned: &[bool]) -> Vec<bool> {
    let n = map.first.len();
    if n < PARALLEL_FROM {
        return initial_set_of::<D>(map, centres, pinned, 0..n);
    }
    let cuts = map.span_cuts(PIECE);
    let pieces: Vec<Vec<bool>> = cuts
        .par_windows(2)
        .map(|w| initial_set_of::<D>(map, centres, pinned, w[0]..w[1]))
        .collect();
    pieces.concat()
}

/// [`initial_set`] of the points `points` (whole runs), in order.
fn initial_set_of<const D: usize>(
    map: &SplineMap,
    centres: &[f64],
    pinned: &[bool],
    points: std::ops::Range<usize>,
) -> Vec<bool> {
    let (start, n) = (points.start, points.end);
    let mut in_set = vec![false; n - start];
    let mut i = start;
    while i < n {
        let f = map.first[i];
        let mut best: Option<(usize, f64)> = None;
        let mut j = i;
        while j < n && map.first[j] == f {
            if !pinned[j] {
                let d = norm2(&centres[j * D..(j + 1) * D]);
                if best.is_none_or(|(_, b)| d > b) {
                    best = Some((j, d));
                }
                in_set[j - start] |= d > SELECT * SELECT;
            }
            j += 1;
        }
        if let Some((k, _)) = best {
            in_set[k - start] = true;
        }
        i = j;
    }
    in_set
}

/// The problem's data term `Σ μ_i |(B y)_i − c_i|²` (free points) folded into its quadratic:
/// the energy with the data's windows added, `A s − Σ μ_i B_iᵀ c_i` and `E(s) + Σ μ_i |c_i|²`.
/// `None` when it has no data term.
fn fold_data<const D: usize>(
    p: &Problem<'_, D>,
    map: &SplineMap,
) -> Option<(Energy<D>, Vec<f64>, f64)> {
    if p.fidelity.is_empty() {
        return None;
    }
    let mut windows = p.energy.windows.clone();
    let mut anchor = p.anchor.clone();
    let mut constant = p.anchor_energy;
    let mut gram = [[0.0; 4]; 4];
    let mut current: Option<usize> = None;
    for (i, (&f, b)) in map.first.iter().zip(&map.basis).enumerate() {
        let mu = p.fidelity[i];
        if p.pinned[i] || mu == 0.0 {
            continue;
        }
        if current != Some(f) {
            if let Some(g) = current {
                rank_one_windows::<D>(g, &gram, &mut windows);
            }
            gram = [[0.0; 4]; 4];
            current = Some(f);
        }
        for k in 0..4 {
            for l in 0..4 {
                gram[k][l] += mu * b[k] * b[l];
            }
        }
        let c = &p.centres[i * D..(i + 1) * D];
        for (k, bk) in b.iter().enumerate() {
            let j = (f + k) % map.vars;
            for a in 0..D {
                anchor[j * D + a] -= mu * bk * c[a];
            }
        }
        constant += mu * norm2(c);
    }
    if let Some(g) = current {
        rank_one_windows::<D>(g, &gram, &mut windows);
    }
    let energy = Energy {
        n: p.energy.n,
        closed: p.energy.closed,
        windows,
    };
    Some((energy, anchor, constant))
}

/// Append `G ⊗ I` (`G` a symmetric positive semi-definite 4×4 on the control points from
/// `first`) as rank-one windows: `G = L diag(d) Lᵀ`, one window `√d_j L_{·j}` per pivot.
fn rank_one_windows<const D: usize>(first: usize, g: &[[f64; 4]; 4], out: &mut Vec<Window<D>>) {
    let top = (0..4).fold(0.0_f64, |m, k| m.max(g[k][k]));
    if top <= 0.0 {
        return;
    }
    let mut s = *g;
    let identity: [[f64; D]; D] =
        std::array::from_fn(|a| std::array::from_fn(|c| if a == c { 1.0 } else { 0.0 }));
    for j in 0..4 {
        let d = s[j][j];
        if d <= PIVOT_FLOOR_REL * top {
            // Semi-definite: the rest of this column is rounding too.
            continue;
        }
        let mut coef = [0.0; 4];
        for k in j..4 {
            coef[k] = s[k][j] / d.sqrt();
        }
        for k in j + 1..4 {
            for l in j + 1..4 {
                s[k][l] -= s[k][j] * s[l][j] / d;
            }
        }
        out.push(Window {
            first,
            coef,
            metric: identity,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The windows of a span's Gram matrix add up to it, rank-deficient ones included.
    #[test]
    fn rank_one_windows_reproduce_the_gram_matrix() {
        let points: [&[[f64; 4]]; 3] = [
            &[[0.1, 0.6, 0.3, 0.0]],
            &[[0.2, 0.5, 0.25, 0.05], [0.0, 0.3, 0.6, 0.1]],
            &[
                [0.2, 0.5, 0.25, 0.05],
                [0.0, 0.3, 0.6, 0.1],
                [0.1, 0.2, 0.3, 0.4],
                [0.7, 0.1, 0.1, 0.1],
            ],
        ];
        for basis in points {
            let mut g = [[0.0; 4]; 4];
            for (i, b) in basis.iter().enumerate() {
                let mu = 1.0 + i as f64;
                for k in 0..4 {
                    for l in 0..4 {
                        g[k][l] += mu * b[k] * b[l];
                    }
                }
            }
            let mut windows = Vec::<Window<2>>::new();
            rank_one_windows(3, &g, &mut windows);
            assert!(windows.len() >= basis.len().min(4));
            for k in 0..4 {
                for l in 0..4 {
                    let sum: f64 = windows.iter().map(|w| w.coef[k] * w.coef[l]).sum();
                    assert!((sum - g[k][l]).abs() < 1e-14, "{k} {l}: {sum} {}", g[k][l]);
                }
            }
        }
    }

    #[test]
    fn segment_exit_finds_the_sphere() {
        let a = [0.3, -0.2];
        let d = [1.0, 2.0];
        let theta = segment_exit(&a, &d, 0.81);
        let p = [a[0] + theta * d[0], a[1] + theta * d[1]];
        assert!((norm2(&p) - 0.81).abs() < 1e-12);
        assert_eq!(segment_exit(&a, &[0.01, 0.0], 0.81), 1.0);
    }
}
