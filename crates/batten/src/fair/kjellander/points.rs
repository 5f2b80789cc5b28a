//! Point-only fairing of a [`PointSeq`] by the KP rules: the C² interpolating cubic (natural
//! or periodic) of the current points, kept up to date by windowed re-solves of its tangents
//! after every move (`docs/algorithms/kjellander-poliakoff.md`, "The interpolating spline" and
//! "The algorithm", docs/algorithms/kjellander-poliakoff.md §2.1 and §2.6; the cost is in the
//! module docs of `kjellander`).

use serde_json::json;

use super::params::{MODE, REPARAMETRIZE, point_params};
use super::rules::{KpRule, Local};
use crate::error::{Error, Result};
use crate::fair::engine::{
    LocalProblem, MIN_CHORD_REL, MaxTree, drive, driven_parameters, move_limit, step_fraction,
};
use crate::fair::{FairOptions, Outcome};
use crate::geom::{BBox, Point, PointSeq, Vec2};
use crate::numeric::{solve_cyclic_tridiagonal, solve_tridiagonal};

/// Half-width of the window of tangents re-solved after a move (see the module docs,
/// "Cost"): the influence of a move decays at least by 1/2 per index, so 64 indices leave
/// a truncation error below 2⁻⁶⁴ ≈ 5e-20 of the tangent change at the moved point.
pub(super) const SOLVE_HALF_WIDTH: usize = 64;

/// The C² interpolating cubic (natural or periodic) of the current points, with its
/// tangents, spans and the original points.
#[derive(Clone, Debug)]
struct SplineState {
    rule: KpRule,
    closed: bool,
    /// Points held at each end of an open curve (at least the end point; `--fix-ends`).
    held: usize,
    /// Recompute the parameter steps from the chords after each move (chord-length only).
    reparametrize: bool,
    r: Vec<Point>,
    m: Vec<Vec2>,
    /// Span lengths: n − 1 (open) or n (closed).
    dt: Vec<f64>,
    origin: Vec<Point>,
    disp: MaxTree,
    min_chord: f64,
    planned: Vec2,
    /// Refuse moves that make the curve worse near them ([`FairOptions::keep_clean`]).
    keep_clean: bool,
    sub: Vec<f64>,
    diag: Vec<f64>,
    sup: Vec<f64>,
    rhs: Vec<Vec2>,
}

impl SplineState {
    fn new(
        points: &[Point],
        closed: bool,
        chord: bool,
        reparametrize: bool,
        rule: KpRule,
    ) -> Result<SplineState> {
        let n = points.len();
        let spans = if closed { n } else { n - 1 };
        let dt = (0..spans)
            .map(|i| {
                let d = (points[(i + 1) % n] - points[i]).length();
                match (chord, d > 0.0) {
                    (_, false) => Err(Error::DuplicatePoint { index: (i + 1) % n }),
                    (true, true) => Ok(d),
                    (false, true) => Ok(1.0),
                }
            })
            .collect::<Result<Vec<f64>>>()?;
        let scale = BBox::from_points(points).map_or(0.0, |b| b.diagonal());
        let mut s = SplineState {
            rule,
            closed,
            held: 1,
            keep_clean: false,
            reparametrize: chord && reparametrize,
            r: points.to_vec(),
            m: vec![Vec2::ZERO; n],
            dt,
            origin: points.to_vec(),
            disp: MaxTree::zeros(n),
            min_chord: MIN_CHORD_REL * scale,
            planned: Vec2::ZERO,
            sub: Vec::new(),
            diag: Vec::new(),
            sup: Vec::new(),
            rhs: Vec::new(),
        };
        s.solve_full()?;
        Ok(s)
    }

    fn n(&self) -> usize {
        self.r.len()
    }

    fn prev(&self, i: usize) -> usize {
        if i == 0 { self.n() - 1 } else { i - 1 }
    }

    fn next(&self, i: usize) -> usize {
        if i + 1 == self.n() { 0 } else { i + 1 }
    }

    fn local(&self, k: usize) -> Local {
        let (p, q) = (self.prev(k), self.next(k));
        Local {
            a: self.dt[p],
            b: self.dt[k],
            rp: self.r[p],
            r: self.r[k],
            rn: self.r[q],
            mp: self.m[p],
            m: self.m[k],
            mn: self.m[q],
        }
    }

    /// Row `i` of the interpolation system (docs/algorithms/kjellander-poliakoff.md §2.1): `(sub,
    /// diag, sup, rhs)`. The end rows `2·m₀ + m₁ = 3·(r₁ − r₀)/Δt₀` are multiplied by `Δt₀` so that
    /// every row is in the same units (lengths, on the chord-length spline): otherwise, at
    /// coordinates of 10¹⁴, the end pivots 2 would be below the solver's relative zero next to the
    /// interior ones `2·(Δt_{i−1} + Δt_i)`.
    fn row(&self, i: usize) -> (f64, f64, f64, Vec2) {
        let n = self.n();
        if !self.closed && i == 0 {
            let d = self.dt[0];
            return (0.0, 2.0 * d, d, (self.r[1] - self.r[0]) * 3.0);
        }
        if !self.closed && i == n - 1 {
            let d = self.dt[n - 2];
            return (d, 2.0 * d, 0.0, (self.r[n - 1] - self.r[n - 2]) * 3.0);
        }
        let (p, q) = (self.prev(i), self.next(i));
        let (a, b) = (self.dt[p], self.dt[i]);
        let rhs = ((self.r[i] - self.r[p]) * (b / a) + (self.r[q] - self.r[i]) * (a / b)) * 3.0;
        (b, 2.0 * (a + b), a, rhs)
    }

    fn clear_scratch(&mut self) {
        self.sub.clear();
        self.diag.clear();
        self.sup.clear();
        self.rhs.clear();
    }

    /// Re-solve the tangents of the `len` consecutive rows from `start` (cyclically for a
    /// closed curve), the tangents outside held fixed.
    fn solve_window(&mut self, start: usize, len: usize) -> Result<()> {
        let n = self.n();
        self.clear_scratch();
        for j in 0..len {
            let i = (start + j) % n;
            let (mut a, d, mut c, mut rhs) = self.row(i);
            if j == 0 && (self.closed || i > 0) {
                rhs -= self.m[self.prev(i)] * a;
                a = 0.0;
            }
            if j + 1 == len && (self.closed || i + 1 < n) {
                rhs -= self.m[self.next(i)] * c;
                c = 0.0;
            }
            self.sub.push(a);
            self.diag.push(d);
            self.sup.push(c);
            self.rhs.push(rhs);
        }
        solve_tridiagonal(&self.sub, &self.diag, &self.sup, &mut self.rhs)?;
        for j in 0..len {
            self.m[(start + j) % n] = self.rhs[j];
        }
        Ok(())
    }

    /// Solve for every tangent.
    fn solve_full(&mut self) -> Result<()> {
        let n = self.n();
        if !self.closed {
            return self.solve_window(0, n);
        }
        self.clear_scratch();
        for i in 0..n {
            let (a, d, c, rhs) = self.row(i);
            self.sub.push(a);
            self.diag.push(d);
            self.sup.push(c);
            self.rhs.push(rhs);
        }
        solve_cyclic_tridiagonal(&self.sub, &self.diag, &self.sup, &mut self.rhs)?;
        self.m.copy_from_slice(&self.rhs);
        Ok(())
    }

    /// After a move of point `k`: re-solve the tangents near it and list the points whose
    /// jump may have changed.
    fn resolve_around(&mut self, k: usize, changed: &mut Vec<usize>) -> Result<()> {
        let n = self.n();
        let w = SOLVE_HALF_WIDTH;
        if self.closed {
            if n >= 2 * w + 3 {
                let start = (k + n - w) % n;
                self.solve_window(start, 2 * w + 1)?;
                // Jumps depend on the tangents either side: one more point each way.
                changed.extend((0..2 * w + 3).map(|j| (start + n - 1 + j) % n));
            } else {
                self.solve_full()?;
                changed.extend(0..n);
            }
        } else {
            let lo = k.saturating_sub(w);
            let hi = (k + w).min(n - 1);
            self.solve_window(lo, hi - lo + 1)?;
            changed.extend(lo.saturating_sub(1)..=(hi + 1).min(n - 1));
        }
        Ok(())
    }

    /// The tangents, for tests of the windowed solve.
    #[cfg(test)]
    fn tangents(&self) -> &[Vec2] {
        &self.m
    }
}

impl LocalProblem for SplineState {
    fn slots(&self) -> usize {
        self.n()
    }

    fn is_candidate(&self, i: usize) -> bool {
        self.closed || (i >= self.held && i + self.held < self.n())
    }

    fn badness(&self, i: usize) -> f64 {
        self.local(i).badness()
    }

    fn plan(&mut self, k: usize, tolerance: Option<f64>) -> Option<f64> {
        let (delta, _) = self.local(k).step(self.rule);
        if !delta.is_finite() {
            return None;
        }
        let s = step_fraction(self.r[k] - self.origin[k], delta, tolerance);
        let new = self.r[k] + delta * s;
        let (p, q) = (self.prev(k), self.next(k));
        if (new - self.r[p]).length() < self.min_chord
            || (self.r[q] - new).length() < self.min_chord
        {
            return None;
        }
        self.planned = delta;
        Some(s)
    }

    fn commit(&mut self, k: usize, s: f64, changed: &mut Vec<usize>) -> Result<(usize, f64)> {
        let step = self.planned * s;
        self.r[k] += step;
        if self.reparametrize {
            let (p, q) = (self.prev(k), self.next(k));
            self.dt[p] = (self.r[k] - self.r[p]).length();
            self.dt[k] = (self.r[q] - self.r[k]).length();
        }
        self.disp.set(k, (self.r[k] - self.origin[k]).length());
        self.resolve_around(k, changed)?;
        Ok((k, step.length()))
    }

    fn max_displacement(&self) -> f64 {
        self.disp.max_value()
    }

    fn worsens(&self, k: usize, s: f64) -> bool {
        self.keep_clean
            && crate::fair::clean::move_is_worse(
                &self.r,
                self.closed,
                &[(k, self.r[k] + self.planned * s)],
            )
    }
}

/// Run one of the point-only KP methods.
pub(super) fn run_points(
    rule: KpRule,
    uniform: bool,
    input: &PointSeq,
    options: &FairOptions,
) -> Result<Outcome> {
    let (threshold, reparametrize) = point_params(uniform, options)?;
    let closed = input.is_closed();
    let mut state = SplineState::new(input.points(), closed, !uniform, reparametrize, rule)?;
    state.held = options.fix_ends.held().max(1);
    state.keep_clean = options.keep_clean;
    let candidates = if closed {
        input.len()
    } else {
        input.len().saturating_sub(2 * state.held)
    };
    let max_moves = move_limit(options, candidates);
    let driven = drive(&mut state, threshold, max_moves, options.tolerance)?;
    let mut parameters = driven_parameters(&driven, threshold, max_moves);
    parameters.insert(
        "parametrization".into(),
        json!(if uniform { "uniform" } else { "chord-length" }),
    );
    parameters.insert(
        "end_condition".into(),
        json!(if closed { "periodic" } else { "natural" }),
    );
    if !uniform {
        REPARAMETRIZE.write(&mut parameters, reparametrize);
    }
    if matches!(rule, KpRule::Energy | KpRule::EnergyPositionOnly) {
        let mode = if rule == KpRule::Energy {
            "position-and-tangent"
        } else {
            "position"
        };
        MODE.write(&mut parameters, mode);
    }
    parameters.insert("solve_half_width".into(), json!(SOLVE_HALF_WIDTH));
    Ok(driven.into_outcome(state.r, parameters))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::spline::{EndCondition, ParametricCubic, Parametrization, parameters};

    fn wiggly(n: usize) -> Vec<Point> {
        (0..n)
            .map(|i| {
                let x = i as f64 * 0.37 + 0.05 * ((i * 7919) % 13) as f64;
                let y = (x * 0.8).sin() + 0.03 * (((i * 104_729) % 17) as f64 - 8.0) / 8.0;
                Point::new(x, y)
            })
            .collect()
    }

    #[test]
    fn windowed_solve_matches_full_solve() {
        let pts = wiggly(400);
        for rule in [KpRule::Poliakoff, KpRule::Energy] {
            let mut s = SplineState::new(&pts, false, true, true, rule).unwrap();
            let mut changed = Vec::new();
            for step in 0..300 {
                let k = 1 + (step * 131) % 398;
                s.plan(k, None).unwrap();
                s.commit(k, 1.0, &mut changed).unwrap();
            }
            let t = parameters(&s.r, Parametrization::ChordLength, false).unwrap();
            let full = ParametricCubic::interpolate_at(&t, &s.r, EndCondition::Natural).unwrap();
            for (a, b) in s.tangents().iter().zip(full.tangents()) {
                assert!((*a - *b).length() < 1e-12, "{a:?} vs {b:?}");
            }
        }
    }

    #[test]
    fn windowed_closed_solve_matches_full_solve() {
        let n = 300;
        let pts: Vec<Point> = (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                let r = 2.0 + 0.01 * ((i * 7) % 5) as f64;
                Point::new(r * a.cos(), 1.5 * r * a.sin())
            })
            .collect();
        for chord in [true, false] {
            let mut s = SplineState::new(&pts, true, chord, true, KpRule::Poliakoff).unwrap();
            let mut changed = Vec::new();
            for step in 0..200 {
                let k = (step * 97 + 3) % n;
                s.plan(k, None).unwrap();
                s.commit(k, 1.0, &mut changed).unwrap();
            }
            let par = if chord {
                Parametrization::ChordLength
            } else {
                Parametrization::Uniform
            };
            let full = ParametricCubic::closed(&s.r, par).unwrap();
            for (a, b) in s.tangents().iter().zip(full.tangents()) {
                assert!((*a - *b).length() < 1e-12, "{a:?} vs {b:?}");
            }
        }
    }

    #[test]
    fn jumps_match_the_spline() {
        let pts = wiggly(30);
        let s = SplineState::new(&pts, false, true, true, KpRule::Poliakoff).unwrap();
        let full =
            ParametricCubic::interpolate(&pts, Parametrization::ChordLength, EndCondition::Natural)
                .unwrap();
        for (k, j) in full.third_derivative_jumps().iter().enumerate() {
            assert!((s.local(k + 1).jump() - *j).length() < 1e-9 * j.length().max(1.0));
        }
    }

    #[test]
    fn refuses_a_move_onto_a_neighbour() {
        let pts = wiggly(10);
        let mut s = SplineState::new(&pts, false, true, true, KpRule::Poliakoff).unwrap();
        // Eq 4 with r'_5 = 0 and r'_3 = 2(r_5 − r_3) moves r_4 exactly onto r_5.
        s.rule = KpRule::Kjellander;
        s.m[5] = Vec2::ZERO;
        s.m[3] = (s.r[5] - s.r[3]) * 2.0;
        assert_eq!(s.plan(4, None), None);
        // Half of that move is allowed.
        s.m[3] = (s.r[5] - s.r[3]) * 1.0;
        assert_eq!(s.plan(4, None), Some(1.0));
    }
}
