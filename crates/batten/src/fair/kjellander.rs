//! Kjellander, Poliakoff and the energy-optimal change of position and tangent: fairing a
//! parametric cubic spline by moving its worst point (methods `kjellander`, `poliakoff`,
//! `energy`).
//!
//! Paper: *Improved fairing of non-uniform parametric cubic splines* (Kjellander → Poliakoff →
//! position + tangent), `../shared/papers/kjellander-poliakoff-improved.txt`. The equations
//! are the reconstructed forms of spec §2 (`../shared/spec/ALGORITHMS.md`); nearly every
//! printed equation is damaged by OCR (spec §2.8):
//!
//! - the third-derivative jump `J_k = r'''(t_k+) − r'''(t_k−) = 6(a_{k,3} − a_{k−1,3})` of the
//!   Hermite coefficients of KP eq 6 (spec §2.2);
//! - **Kjellander** (eq 4, uniform parameters): `r_k,new = (r_{k−1} + r_{k+1})/2 +
//!   (r'_{k−1} − r'_{k+1})/4` — the printed equation is unreadable, spec §2.8 gives this form;
//! - **Poliakoff** (eq 8, any parameters, `A = Δ_{k−1}`, `B = Δ_k`): the position that makes
//!   `J_k = 0` with every tangent kept (spec §2.3);
//! - **energy** (eqs 11–12 as **fixed** in spec §2.5): the change `(δ*, η*)` of position and
//!   tangent that minimises the exact energy change `W' − W = 4C·F(δ, η)` of Lemma 1 (eq 14,
//!   with the coefficient repairs of spec §2.8). With `η = 0` the minimiser is
//!   `δ = J3/(2/A³ + 2/B³)`, which is Poliakoff's eq 8 (the corollary): that is the
//!   `mode = position` of the `energy` method and [`KpRule::EnergyPositionOnly`].
//!
//! # The algorithm (spec §2.6)
//!
//! 1. Interpolate the points with the C² cubic spline with natural ends (spec §2.1):
//!    chord-length parameters for `poliakoff` and `energy`, uniform `t_i = i` for `kjellander`.
//!    Closed curves use the periodic spline (as [`ParametricCubic::closed`]): every point is
//!    then interior.
//! 2. The bad point is the interior point with the largest `|J_k|` (Euclidean norm).
//! 3. Stop when `|J_k| ≤ ε`. `ε` is the method parameter `epsilon` when given (in the units of
//!    `J`), otherwise `threshold × max_k |J_k|` of the input spline ([`DEFAULT_THRESHOLD`]):
//!    the paper only says "give a small positive number", and a bound relative to the input's
//!    own jumps is independent of the data's scale and parametrisation.
//! 4. Move the bad point by its rule. Point-only fairing applies the position only: the
//!    `energy` method applies `δ*` and discards `η*` (as the paper does in its examples,
//!    spec §2.6 step 4), since re-interpolation recomputes every tangent.
//! 5. Re-interpolate, recomputing the chord-length parameters from the moved points (the
//!    \[CHOICE\] of spec §2.6 step 5; method parameter `reparametrize = false` keeps the
//!    input's parameters instead). Repeat from 2.
//!
//! With the parameters kept (`kjellander` always, the others with `reparametrize = false`)
//! no move increases `∫|r''|² dt`: the natural (or periodic) spline has the least energy of
//! all interpolants at those parameters, the Hermite curve with `(δ*, η*)` (or with Poliakoff's
//! `δ`, `η = 0`) is one of them, and Lemma 1 gives it the energy `W + 4F ≤ W`. This holds
//! although `δ*` applied with the old tangents alone can raise the energy (`F(δ*, 0) > 0`
//! when a chord ratio exceeds 2 + √3, since `δ*` is Poliakoff's optimum scaled by more than
//! 2). With recomputed parameters the energies are measured in different parametrisations
//! and nothing is guaranteed.
//! 6. Stop after step 3 succeeds, after `max_iterations` moves (default
//!    [`DEFAULT_MOVES_PER_POINT`] × the number of candidate points), or when no bad point can
//!    move within the tolerance.
//!
//! One iteration is one move: `--max-iterations 1` moves exactly one point. Every move is
//! reported in [`Outcome::moves`] (`before`/`after` are `|J_k|` before and after the move,
//! after re-interpolation); the history has one row per move with the largest `|J|` (row 0 is
//! the input).
//!
//! **Tolerance.** The tolerance is a hard bound on each point's distance from its *original*
//! position. A move that would cross it is scaled back along its own direction to end on the
//! bound (less [`TOLERANCE_MARGIN`], so rounding cannot cross it); a move scaled below
//! [`MIN_STEP_FRACTION`] of its length cannot help, so that point is skipped and the next-worst
//! point is tried; the run stops (status `tolerance_limited`) when no bad point can move. A
//! skipped point is tried again once a move nearby has changed its jump by more than
//! [`RETRY_CHANGE_REL`].
//!
//! **Ends.** The end points of an open curve are never bad points (`J` is defined at interior
//! points only), so they never move: `--fix-ends` holds without any extra work. With
//! `--fix-ends=tangent` (`curvature`) the second (and third) point at each end are not
//! candidates either. A closed curve has no ends and `fix_ends` has no effect on it.
//!
//! # Hermite data
//!
//! Where the input carries tangents, [`hermite_step`] computes one move of any rule from
//! `(t, points, tangents)` and returns the moved point and tangent, and [`fair_hermite`] runs
//! the whole algorithm on Hermite data: the parameters and the tangents of the other points
//! are kept (no re-interpolation), the `energy` rule updates the tangent by `η*`, and since
//! only spans `k−1` and `k` change, only the jumps at `k−1, k, k+1` are recomputed. A
//! [`FairMethod`] works on a [`PointSeq`], which has no tangents, hence the separate entry
//! point.
//!
//! # Cost
//!
//! A move changes the C² spline globally, but the change of the tangents decays
//! geometrically away from the moved point: the interpolation system is diagonally dominant
//! with off-diagonal sum half the diagonal, so the influence falls by at least 1/2 per index
//! (2 − √3 ≈ 0.27 for uniform parameters). After a move the tangents are therefore re-solved
//! only on the [`SOLVE_HALF_WIDTH`] points either side of it, with the tangents outside held
//! (truncation error ≤ 2⁻⁶⁴ relative, tested against the full solve to 1e-12), and the bad
//! point is kept in a max-tree (its entries refreshed run by run), so a move costs
//! O([`SOLVE_HALF_WIDTH`] + log n) instead of O(n) for the re-solve alone. Measured with
//! `benches/kp.rs` (release build, 1000 moves, on a shared 2-core machine at load ≈ 11, so
//! the figures are inflated and noisy): 25–37 µs per move for the three methods at n = 10³
//! and 10⁴, no growth with n (at n = 10⁵, 8–24 µs, within the noise of the set-up); the O(n)
//! set-up (interpolation and ranking) costs 0.3–0.8 µs per point.

use serde_json::{Map, Value, json};

use super::{FairMethod, FairOptions, FairStatus, HistoryRow, Move, Outcome, ParamSpec};
use crate::error::{Error, Result};
use crate::geom::{BBox, Point, PointSeq, Vec2};
use crate::numeric::{solve_cyclic_tridiagonal, solve_tridiagonal};
use crate::spline::ParametricCubic;

/// Default relative stopping threshold: the run stops when every `|J_k|` is at most this
/// fraction of the largest jump of the input.
pub const DEFAULT_THRESHOLD: f64 = 1e-3;

/// Default iteration limit, per candidate point (bad points for `kjellander`, `poliakoff`
/// and `energy`; interior knots for `sapidis-farin`): one iteration is one move.
pub const DEFAULT_MOVES_PER_POINT: usize = 10;

/// Half-width of the window of tangents re-solved after a move (see the module docs,
/// "Cost"): the influence of a move decays at least by 1/2 per index, so 64 indices leave
/// a truncation error below 2⁻⁶⁴ ≈ 5e-20 of the tangent change at the moved point.
pub const SOLVE_HALF_WIDTH: usize = 64;

/// A move that the tolerance cuts to less than this fraction of its full length cannot help;
/// the point is skipped and the next-worst point tried.
pub const MIN_STEP_FRACTION: f64 = 1e-2;

/// A point skipped because the tolerance blocks its move is tried again once its jump has
/// changed by more than this fraction (a move nearby changed its neighbourhood); smaller
/// changes, such as the far tail of a windowed re-solve, leave it skipped.
pub const RETRY_CHANGE_REL: f64 = 1e-6;

/// Relative margin kept inside the tolerance when a move is scaled back onto it, so that
/// rounding cannot put a point beyond the tolerance.
pub const TOLERANCE_MARGIN: f64 = 1e-9;

/// A move that would leave a chord to a neighbour shorter than this fraction of the data's
/// size (its bounding-box diagonal) is refused: coincident consecutive points have no
/// chord-length parameter.
pub const MIN_CHORD_REL: f64 = 1e-9;

/// A jump no larger than this fraction of the terms it is computed from is rounding noise
/// and counts as zero (so exactly fair data, e.g. equally spaced collinear points, is left
/// alone instead of being "faired" at the level of rounding errors).
pub const JUMP_ZERO_REL: f64 = 1e-12;

/// Kjellander's rule (eq 4) needs unit parameter steps; steps within this relative distance
/// of 1 count as unit steps.
pub const UNIT_STEP_REL: f64 = 1e-9;

/// The update rule for the bad point (spec §2.2–2.5).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum KpRule {
    /// Kjellander, eq 4: position only, uniform parameters with unit steps.
    Kjellander,
    /// Poliakoff, eq 8: the position that makes `J_k = 0` with all tangents kept.
    Poliakoff,
    /// The energy-optimal change of position and tangent, `(δ*, η*)` of eqs 11–12 (spec §2.5).
    Energy,
    /// The energy-optimal change of position alone (`η = 0`): the corollary of spec §2.5,
    /// equal to Poliakoff's eq 8, computed from the energy quadratic.
    EnergyPositionOnly,
}

/// One move of the bad point `k` of Hermite data (see [`hermite_step`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HermiteMove {
    /// The new position `r_k + δ`.
    pub point: Point,
    /// The new tangent `r'_k + η`.
    pub tangent: Vec2,
    /// The change of position `δ`.
    pub delta: Vec2,
    /// The change of tangent `η` (zero for the position-only rules).
    pub eta: Vec2,
    /// The third-derivative jump `J_k = r'''(t_k+) − r'''(t_k−)` before the move.
    pub jump: Vec2,
}

/// The Hermite data around an interior point k: spans `k−1` (length A) and `k` (length B).
#[derive(Clone, Copy, Debug)]
struct Local {
    a: f64,
    b: f64,
    rp: Point,
    r: Point,
    rn: Point,
    mp: Vec2,
    m: Vec2,
    mn: Vec2,
}

/// KP eq 6: the coefficients `(a2, a3)` of the Hermite span from `(p0, d0)` to `(p1, d1)`
/// of parameter length `h`.
#[inline]
fn hermite_a23(p0: Point, p1: Point, d0: Vec2, d1: Vec2, h: f64) -> (Vec2, Vec2) {
    let dp = p1 - p0;
    let a2 = dp * (3.0 / (h * h)) - (d0 * 2.0 + d1) / h;
    let a3 = dp * (-2.0 / (h * h * h)) + (d0 + d1) / (h * h);
    (a2, a3)
}

impl Local {
    fn spans(&self) -> ((Vec2, Vec2), (Vec2, Vec2)) {
        (
            hermite_a23(self.rp, self.r, self.mp, self.m, self.a),
            hermite_a23(self.r, self.rn, self.m, self.mn, self.b),
        )
    }

    /// `J_k = 6(a_{k,3} − a_{k−1,3})` (spec §2.2).
    fn jump(&self) -> Vec2 {
        let ((_, a3p), (_, a3n)) = self.spans();
        (a3n - a3p) * 6.0
    }

    /// `|J_k|`, or 0 when it is within [`JUMP_ZERO_REL`] of the size of the terms of the two
    /// `a_3` it is the difference of (absolute positions included: their rounding is in the
    /// differences).
    fn badness(&self) -> f64 {
        // L1 norms: an upper bound of the Euclidean ones, and cheap (no hypot in the hot loop).
        let l1 = |v: Vec2| v.x.abs() + v.y.abs();
        let mag = |p0: Point, p1: Point, d0: Vec2, d1: Vec2, h: f64| {
            2.0 * (l1(p0.to_vec2()) + l1(p1.to_vec2())) / (h * h * h) + (l1(d0) + l1(d1)) / (h * h)
        };
        let floor = 6.0
            * JUMP_ZERO_REL
            * (mag(self.rp, self.r, self.mp, self.m, self.a)
                + mag(self.r, self.rn, self.m, self.mn, self.b));
        let j = self.jump().length();
        if j <= floor { 0.0 } else { j }
    }

    /// The change `(δ, η)` of position and tangent by `rule`.
    fn step(&self, rule: KpRule) -> (Vec2, Vec2) {
        let (a, b) = (self.a, self.b);
        match rule {
            KpRule::Kjellander => {
                // Eq 4.
                let new = self.rp.midpoint(self.rn) + (self.mp - self.mn) * 0.25;
                (new - self.r, Vec2::ZERO)
            }
            KpRule::Poliakoff => {
                // Eq 8.
                let (a2, b2) = (a * a, b * b);
                let (a3, b3) = (a2 * a, b2 * b);
                let w = 1.0 / a3 + 1.0 / b3;
                let num = self.rp.to_vec2() / a3 + self.rn.to_vec2() / b3 + self.mp / (2.0 * a2)
                    - self.mn / (2.0 * b2)
                    + self.m * (0.5 * (1.0 / a2 - 1.0 / b2));
                ((num / w).to_point() - self.r, Vec2::ZERO)
            }
            KpRule::Energy => {
                // Eqs 11–12 as fixed in spec §2.5.
                let ((a2p, a3p), (a2n, a3n)) = self.spans();
                let j3 = a3p - a3n;
                let j2 = a2n - a2p - a3p * (3.0 * a);
                let s = a + b;
                let s3 = s * s * s;
                let delta = (j3 * (2.0 * a * b) + j2 * (b - a)) * (a * a * b * b / s3);
                let eta = (j3 * (3.0 * a * b * (b - a)) + j2 * (2.0 * (a * a - a * b + b * b)))
                    * (a * b / s3);
                (delta, eta)
            }
            KpRule::EnergyPositionOnly => {
                // The corollary of spec §2.5: minimise F(δ, 0).
                let ((_, a3p), (_, a3n)) = self.spans();
                let j3 = a3p - a3n;
                (j3 / (2.0 / (a * a * a) + 2.0 / (b * b * b)), Vec2::ZERO)
            }
        }
    }

    /// `F(δ, η)` of Lemma 1 (eq 14, spec §2.5): `W' − W = 4C·F`.
    fn energy_f(&self, delta: Vec2, eta: Vec2) -> f64 {
        let (a, b) = (self.a, self.b);
        let ((a2p, a3p), (a2n, a3n)) = self.spans();
        (a3n - a3p).dot(delta) * 3.0
            + (a2p + a3p * (3.0 * a) - a2n).dot(eta)
            + (3.0 / (a * a * a) + 3.0 / (b * b * b)) * delta.length_squared()
            + (1.0 / a + 1.0 / b) * eta.length_squared()
            + (3.0 / (b * b) - 3.0 / (a * a)) * delta.dot(eta)
    }
}

/// Check Hermite data and pick out the neighbourhood of interior point `k` (0-based).
fn hermite_local(t: &[f64], points: &[Point], tangents: &[Vec2], k: usize) -> Result<Local> {
    check_hermite(t, points, tangents)?;
    let n = points.len();
    if k == 0 || k + 1 >= n {
        return Err(Error::InvalidParameter {
            name: "k".into(),
            reason: format!("point {k} is not an interior point of {n} points"),
        });
    }
    Ok(Local {
        a: t[k] - t[k - 1],
        b: t[k + 1] - t[k],
        rp: points[k - 1],
        r: points[k],
        rn: points[k + 1],
        mp: tangents[k - 1],
        m: tangents[k],
        mn: tangents[k + 1],
    })
}

/// Validate Hermite data: equal lengths, at least 3 points, finite values, increasing `t`.
fn check_hermite(t: &[f64], points: &[Point], tangents: &[Vec2]) -> Result<()> {
    let n = points.len();
    if n < 3 {
        return Err(Error::TooFewPoints { needed: 3, got: n });
    }
    for (what, len) in [("parameters", t.len()), ("tangents", tangents.len())] {
        if len != n {
            return Err(Error::LengthMismatch {
                what,
                got: len,
                expected: n,
            });
        }
    }
    if let Some(index) = points.iter().position(|p| !p.is_finite()) {
        return Err(Error::NonFinite { index });
    }
    if let Some(index) = tangents.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite { index });
    }
    if let Some(index) = t.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite { index });
    }
    if let Some(i) = t.windows(2).position(|w| w[1] <= w[0]) {
        return Err(Error::NotIncreasing { index: i + 1 });
    }
    Ok(())
}

/// Kjellander's eq 4 assumes `t_{i+1} − t_i = 1`.
fn check_unit_steps(t: &[f64]) -> Result<()> {
    if let Some(i) = t
        .windows(2)
        .position(|w| ((w[1] - w[0]) - 1.0).abs() > UNIT_STEP_REL)
    {
        return Err(Error::InvalidParameter {
            name: "t".into(),
            reason: format!(
                "Kjellander's rule (eq 4) needs unit parameter steps; t[{}] − t[{i}] = {}",
                i + 1,
                t[i + 1] - t[i]
            ),
        });
    }
    Ok(())
}

/// One move of the interior point `k` (0-based) of the Hermite data `(t, points, tangents)`
/// by `rule`: the new position and tangent, the changes `δ`, `η` and the jump `J_k` before
/// the move. Nothing else changes: the other points, all other tangents and the parameters
/// are kept (the setting of spec §2.2–2.5).
///
/// Kjellander's and Poliakoff's rules keep the tangent (`η = 0`); [`KpRule::Energy`] returns
/// `(δ*, η*)` of eqs 11–12. For tangents of a C² spline, `δ*` is Poliakoff's move scaled by
/// `4(A³ + B³)/(A + B)³` (spec §2.5).
///
/// # Errors
/// [`Error::TooFewPoints`], [`Error::LengthMismatch`], [`Error::NonFinite`],
/// [`Error::NotIncreasing`] for bad data; [`Error::InvalidParameter`] when `k` is not
/// interior, or for [`KpRule::Kjellander`] when a parameter step is not 1.
pub fn hermite_step(
    rule: KpRule,
    t: &[f64],
    points: &[Point],
    tangents: &[Vec2],
    k: usize,
) -> Result<HermiteMove> {
    let local = hermite_local(t, points, tangents, k)?;
    if rule == KpRule::Kjellander {
        check_unit_steps(t)?;
    }
    let (delta, eta) = local.step(rule);
    Ok(HermiteMove {
        point: local.r + delta,
        tangent: local.m + eta,
        delta,
        eta,
        jump: local.jump(),
    })
}

/// The quadratic `F(δ, η)` of Lemma 1 (eq 14, spec §2.5) at the interior point `k` (0-based)
/// of Hermite data: changing `r_k` by `δ` and `r'_k` by `η`, all other data kept, changes the
/// energy `∫|r''|² dt` by exactly `4F`.
///
/// # Errors
/// As [`hermite_step`].
pub fn energy_change_f(
    t: &[f64],
    points: &[Point],
    tangents: &[Vec2],
    k: usize,
    delta: Vec2,
    eta: Vec2,
) -> Result<f64> {
    Ok(hermite_local(t, points, tangents, k)?.energy_f(delta, eta))
}

/// The parametric energy `∫|r''(t)|² dt` of a cubic spline (spec §0.4, the `W/C` of KP
/// §2.5), in closed form span by span: `4|a2|²Δ + 12(a2·a3)Δ² + 12|a3|²Δ³`.
pub fn parametric_energy(curve: &ParametricCubic) -> f64 {
    let t = curve.knots();
    (0..curve.num_spans())
        .map(|i| {
            let [_, _, a2, a3] = curve.span_coeffs(i);
            let h = t[i + 1] - t[i];
            4.0 * a2.length_squared() * h
                + 12.0 * a2.dot(a3) * h * h
                + 12.0 * a3.length_squared() * h * h * h
        })
        .sum()
}

// ---------------------------------------------------------------------------------------
// The greedy driver shared by the KP methods and sapidis-farin.

/// A max-heap over slots with O(log n) updates: a tournament tree of `(value, slot)`.
/// Absent and blocked slots hold −∞.
#[derive(Clone, Debug)]
pub(super) struct MaxTree {
    size: usize,
    node: Vec<(f64, usize)>,
}

impl MaxTree {
    pub(super) fn new(n: usize) -> MaxTree {
        let size = n.next_power_of_two().max(1);
        let mut node = vec![(f64::NEG_INFINITY, usize::MAX); 2 * size];
        for (i, leaf) in node[size..size + n].iter_mut().enumerate() {
            leaf.1 = i;
        }
        for p in (1..size).rev() {
            node[p] = better(node[2 * p], node[2 * p + 1]);
        }
        MaxTree { size, node }
    }

    /// A tree of `n` slots all holding 0 (built in O(n)).
    pub(super) fn zeros(n: usize) -> MaxTree {
        let mut t = MaxTree::new(n);
        t.set_runs((0..n).map(|i| (i, 0.0)));
        t
    }

    pub(super) fn set(&mut self, i: usize, v: f64) {
        self.set_leaf(i, v);
        self.refresh(i, i);
    }

    /// Set a leaf without updating its ancestors; call [`MaxTree::refresh`] afterwards.
    fn set_leaf(&mut self, i: usize, v: f64) {
        self.node[self.size + i].0 = v;
    }

    /// Recompute the ancestors of the leaves `lo..=hi`: O(hi − lo + log n).
    fn refresh(&mut self, lo: usize, hi: usize) {
        let (mut a, mut b) = (self.size + lo, self.size + hi);
        while a > 1 {
            a /= 2;
            b /= 2;
            for p in a..=b {
                self.node[p] = better(self.node[2 * p], self.node[2 * p + 1]);
            }
        }
    }

    /// Set the leaves `(slot, value)` and refresh their ancestors, one run of consecutive
    /// slots at a time.
    fn set_runs(&mut self, items: impl Iterator<Item = (usize, f64)>) {
        let mut run: Option<(usize, usize)> = None;
        for (i, v) in items {
            self.set_leaf(i, v);
            run = match run {
                Some((lo, hi)) if i == hi + 1 => Some((lo, i)),
                Some((lo, hi)) => {
                    self.refresh(lo, hi);
                    Some((i, i))
                }
                None => Some((i, i)),
            };
        }
        if let Some((lo, hi)) = run {
            self.refresh(lo, hi);
        }
    }

    /// The largest value and its slot, or `None` when every slot is absent.
    pub(super) fn max(&self) -> Option<(usize, f64)> {
        let (v, i) = self.node[1];
        (v > f64::NEG_INFINITY).then_some((i, v))
    }

    /// The value at slot `i`.
    pub(super) fn get(&self, i: usize) -> f64 {
        self.node[self.size + i].0
    }

    /// The largest value, 0 when every slot is absent.
    pub(super) fn max_value(&self) -> f64 {
        self.max().map_or(0.0, |(_, v)| v)
    }
}

/// The larger entry; the left (lower slot) one on ties.
#[inline]
fn better(l: (f64, usize), r: (f64, usize)) -> (f64, usize) {
    if r.0 > l.0 { r } else { l }
}

/// The largest `s ∈ [0, 1]` with `|e + s·w| ≤ radius`, given `|e| ≤ radius` (the point's
/// current offset `e` from its original position, the move `w`).
pub(super) fn max_fraction(e: Vec2, w: Vec2, radius: f64) -> f64 {
    let ww = w.length_squared();
    if ww == 0.0 {
        return 1.0;
    }
    let slack = radius * radius - e.length_squared();
    if slack <= 0.0 {
        // On (or beyond) the bound: only inward moves are allowed, and they end on it again.
        return if e.dot(w) < 0.0 {
            (-2.0 * e.dot(w) / ww).min(1.0)
        } else {
            0.0
        };
    }
    let b = e.dot(w);
    let root = (b * b + ww * slack).sqrt();
    // Positive root of ww s² + 2 b s − slack = 0, in the cancellation-free form.
    let s = if b > 0.0 {
        slack / (b + root)
    } else {
        (root - b) / ww
    };
    s.clamp(0.0, 1.0)
}

/// The stopping threshold ε: relative to the input's largest badness, or absolute.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Threshold {
    /// ε = factor × the largest badness of the input.
    Relative(f64),
    /// ε in the units of the badness measure.
    Absolute(f64),
}

impl Threshold {
    /// Read the `threshold` and `epsilon` method parameters (`epsilon=auto`, the documented
    /// default, is the same as leaving it out).
    pub(super) fn from_options(options: &FairOptions) -> Result<Threshold> {
        let rel = options.param_f64_in("threshold", DEFAULT_THRESHOLD, 0.0, 1.0)?;
        if options.param_is_auto("epsilon") {
            return Ok(Threshold::Relative(rel));
        }
        match options.param_f64("epsilon")? {
            Some(e) if e < 0.0 => Err(Error::InvalidParameter {
                name: "epsilon".into(),
                reason: format!("must be non-negative, got {e}"),
            }),
            Some(e) => Ok(Threshold::Absolute(e)),
            None => Ok(Threshold::Relative(rel)),
        }
    }
}

/// Parameter specs shared by every method of this family.
pub(super) const THRESHOLD_PARAM: ParamSpec = ParamSpec {
    name: "threshold",
    default: "0.001",
    doc: "stop when every third-derivative jump is at most this fraction of the input's largest",
};

/// See [`THRESHOLD_PARAM`].
pub(super) const EPSILON_PARAM: ParamSpec = ParamSpec {
    name: "epsilon",
    default: "auto",
    doc: "absolute stopping bound on the jumps (overrides threshold); auto = threshold x input max",
};

const REPARAMETRIZE_PARAM: ParamSpec = ParamSpec {
    name: "reparametrize",
    default: "true",
    doc: "recompute chord-length parameters after each move (spec 2.6 step 5); false keeps the input's",
};

const MODE_PARAM: ParamSpec = ParamSpec {
    name: "mode",
    default: "position-and-tangent",
    doc: "position-and-tangent: move by delta* (eqs 11-12); position: the eta = 0 optimum (= poliakoff)",
};

/// A local fairing problem for [`drive`]: slots (points or knots) with a badness, and moves
/// that change the badness of a few slots.
pub(super) trait LocalProblem {
    /// Number of slots.
    fn slots(&self) -> usize;
    /// Whether slot `i` may be chosen as the bad one.
    fn is_candidate(&self, i: usize) -> bool;
    /// The badness at slot `i` (the norm of a third-derivative jump).
    fn badness(&self, i: usize) -> f64;
    /// Plan the full move at slot `i`; return the largest fraction of it in [0, 1] that keeps
    /// every point within `tolerance` of its original position, or `None` when the move is
    /// degenerate (not finite, or it would make two consecutive points coincide).
    fn plan(&mut self, i: usize, tolerance: Option<f64>) -> Option<f64>;
    /// Apply the fraction `s` of the move planned at `i`. Push every slot whose badness may
    /// have changed to `changed`; return the index of what moved and how far.
    ///
    /// # Errors
    /// A failed re-solve.
    fn commit(&mut self, i: usize, s: f64, changed: &mut Vec<usize>) -> Result<(usize, f64)>;
    /// The largest distance of a data point from its original position.
    fn max_displacement(&self) -> f64;
    /// Whether applying the fraction `s` of the move planned at `i` would give the curve
    /// more inflections or a higher variation energy near it (the per-move clean-curve
    /// check, `clean.rs`); such a move is refused like one that cannot stay within the
    /// tolerance. The default: no check.
    fn worsens(&self, i: usize, s: f64) -> bool {
        let _ = (i, s);
        false
    }
}

/// What [`drive`] did.
#[derive(Clone, Debug)]
pub(super) struct Driven {
    pub(super) status: FairStatus,
    pub(super) moves: Vec<Move>,
    pub(super) history: Vec<HistoryRow>,
    pub(super) notes: Vec<String>,
    pub(super) epsilon: f64,
    pub(super) initial_max: f64,
}

fn checked_badness(p: &impl LocalProblem, i: usize) -> Result<f64> {
    let b = p.badness(i);
    if b.is_finite() {
        Ok(b)
    } else {
        Err(Error::Degenerate(format!(
            "the third-derivative jump at {i} is not finite"
        )))
    }
}

/// The greedy loop of spec §2.6: move the worst slot until every badness is at most ε, the
/// move limit is reached, or no bad slot can move within the tolerance.
pub(super) fn drive(
    p: &mut impl LocalProblem,
    threshold: Threshold,
    max_moves: usize,
    tolerance: Option<f64>,
) -> Result<Driven> {
    let n = p.slots();
    let mut all = MaxTree::new(n);
    let mut open = MaxTree::new(n);
    let mut values = Vec::with_capacity(n);
    for i in 0..n {
        if p.is_candidate(i) {
            values.push((i, checked_badness(p, i)?));
        }
    }
    all.set_runs(values.iter().copied());
    open.set_runs(values.iter().copied());
    let initial_max = all.max_value();
    let epsilon = match threshold {
        Threshold::Relative(r) => r * initial_max,
        Threshold::Absolute(a) => a,
    };
    let mut moves: Vec<Move> = Vec::new();
    let mut history = vec![HistoryRow {
        iteration: 0,
        measure: initial_max,
        max_distance: 0.0,
    }];
    let (mut scaled, mut skipped, mut refused) = (0usize, 0usize, 0usize);
    let mut blocked = vec![false; n];
    let (mut changed, mut open_values) = (Vec::new(), Vec::new());
    let status = loop {
        let worst = open.max().filter(|&(_, v)| v > epsilon);
        let Some((i, before)) = worst else {
            break if all.max_value() > epsilon {
                FairStatus::ToleranceLimited
            } else if moves.is_empty() {
                FairStatus::NoChange
            } else {
                FairStatus::Converged
            };
        };
        if moves.len() >= max_moves {
            break FairStatus::IterationLimit;
        }
        let s = match p.plan(i, tolerance) {
            Some(s) if s >= MIN_STEP_FRACTION => s,
            _ => {
                open.set(i, f64::NEG_INFINITY);
                blocked[i] = true;
                skipped += 1;
                continue;
            }
        };
        if p.worsens(i, s) {
            open.set(i, f64::NEG_INFINITY);
            blocked[i] = true;
            refused += 1;
            continue;
        }
        if s < 1.0 {
            scaled += 1;
        }
        changed.clear();
        let (index, distance) = p.commit(i, s, &mut changed)?;
        values.clear();
        open_values.clear();
        for &c in &changed {
            if p.is_candidate(c) {
                let b = checked_badness(p, c)?;
                if blocked[c] && (b - all.get(c)).abs() > RETRY_CHANGE_REL * b {
                    blocked[c] = false;
                }
                values.push((c, b));
                open_values.push((c, if blocked[c] { f64::NEG_INFINITY } else { b }));
            }
        }
        all.set_runs(values.iter().copied());
        open.set_runs(open_values.iter().copied());
        let iteration = moves.len() + 1;
        moves.push(Move {
            iteration,
            index,
            distance,
            before,
            after: p.badness(i),
        });
        history.push(HistoryRow {
            iteration,
            measure: all.max_value(),
            max_distance: p.max_displacement(),
        });
    };
    let mut notes = Vec::new();
    if scaled > 0 {
        notes.push(format!(
            "{scaled} move(s) were scaled back to stay within the tolerance"
        ));
    }
    if skipped > 0 {
        notes.push(format!(
            "{skipped} time(s) the worst point could not move within the tolerance and the next-worst was tried"
        ));
    }
    if refused > 0 {
        notes.push(format!(
            "{refused} move(s) were refused because they would have added an inflection or \
             raised the variation energy near the point (the clean-curve check)"
        ));
    }
    match status {
        FairStatus::ToleranceLimited => notes.push(format!(
            "stopped: no point with a jump above epsilon = {epsilon:.6e} can move within the tolerance"
        )),
        FairStatus::IterationLimit => notes.push(format!(
            "stopped after {} move(s) with the largest jump {:.6e} above epsilon = {epsilon:.6e}",
            moves.len(),
            all.max_value()
        )),
        _ => {}
    }
    Ok(Driven {
        status,
        moves,
        history,
        notes,
        epsilon,
        initial_max,
    })
}

// ---------------------------------------------------------------------------------------
// Point-only fairing of a PointSeq: the C² spline kept up to date by windowed re-solves.

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

    /// Row `i` of the interpolation system (spec §2.1): `(sub, diag, sup, rhs)`. The end
    /// rows `2·m₀ + m₁ = 3·(r₁ − r₀)/Δt₀` are multiplied by `Δt₀` so that every row is in
    /// the same units (lengths, on the chord-length spline): otherwise, at coordinates of
    /// 10¹⁴, the end pivots 2 would be below the solver's relative zero next to the
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
        let s = match tolerance {
            None => 1.0,
            Some(tol) => max_fraction(
                self.r[k] - self.origin[k],
                delta,
                tol * (1.0 - TOLERANCE_MARGIN),
            ),
        };
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
            && super::clean::move_is_worse(
                &self.r,
                self.closed,
                &[(k, self.r[k] + self.planned * s)],
            )
    }
}

/// The iteration limit: `max_iterations`, or [`DEFAULT_MOVES_PER_POINT`] per candidate.
pub(super) fn move_limit(options: &FairOptions, candidates: usize) -> usize {
    options.iterations_or(DEFAULT_MOVES_PER_POINT.saturating_mul(candidates.max(1)))
}

/// The common part of the reported parameters.
pub(super) fn driven_parameters(
    d: &Driven,
    threshold: Threshold,
    max_moves: usize,
) -> Map<String, Value> {
    let mut p = Map::new();
    if let Threshold::Relative(r) = threshold {
        p.insert("threshold".into(), json!(r));
    }
    p.insert("epsilon".into(), json!(d.epsilon));
    p.insert("initial_max_jump".into(), json!(d.initial_max));
    p.insert("max_iterations".into(), json!(max_moves));
    p
}

/// The parameters of the point-only KP methods: the threshold and, on the chord-length spline,
/// `reparametrize` (always false on the uniform one). They need no input.
fn point_params(uniform: bool, options: &FairOptions) -> Result<(Threshold, bool)> {
    let threshold = Threshold::from_options(options)?;
    let reparametrize = !uniform && options.param_bool("reparametrize", true)?;
    Ok((threshold, reparametrize))
}

/// The rule of the `energy` method, from its `mode` parameter.
fn energy_rule(options: &FairOptions) -> Result<KpRule> {
    Ok(
        match options.param_choice(
            "mode",
            "position-and-tangent",
            &["position-and-tangent", "position"],
        )? {
            "position" => KpRule::EnergyPositionOnly,
            _ => KpRule::Energy,
        },
    )
}

/// Run one of the point-only KP methods.
fn run_points(
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
        parameters.insert("reparametrize".into(), json!(reparametrize));
    }
    if matches!(rule, KpRule::Energy | KpRule::EnergyPositionOnly) {
        let mode = if rule == KpRule::Energy {
            "position-and-tangent"
        } else {
            "position"
        };
        parameters.insert("mode".into(), json!(mode));
    }
    parameters.insert("solve_half_width".into(), json!(SOLVE_HALF_WIDTH));
    Ok(Outcome {
        solver: None,
        points: state.r,
        status: driven.status,
        iterations: driven.moves.len(),
        moves: driven.moves,
        history: driven.history,
        parameters,
        notes: driven.notes,
        curve: None,
        tangents: None,
        ends_held: Some(super::EndFix::Position),
    })
}

// ---------------------------------------------------------------------------------------
// Hermite data.

/// Hermite data faired in place: parameters fixed, tangents carried.
#[derive(Clone, Debug)]
struct HermiteState {
    rule: KpRule,
    /// Points held at each end (at least the end point; `--fix-ends`).
    held: usize,
    t: Vec<f64>,
    r: Vec<Point>,
    m: Vec<Vec2>,
    origin: Vec<Point>,
    disp: MaxTree,
    min_chord: f64,
    planned: (Vec2, Vec2),
}

impl HermiteState {
    fn local(&self, k: usize) -> Local {
        Local {
            a: self.t[k] - self.t[k - 1],
            b: self.t[k + 1] - self.t[k],
            rp: self.r[k - 1],
            r: self.r[k],
            rn: self.r[k + 1],
            mp: self.m[k - 1],
            m: self.m[k],
            mn: self.m[k + 1],
        }
    }
}

impl LocalProblem for HermiteState {
    fn slots(&self) -> usize {
        self.r.len()
    }

    fn is_candidate(&self, i: usize) -> bool {
        i >= self.held && i + self.held < self.r.len()
    }

    fn badness(&self, i: usize) -> f64 {
        self.local(i).badness()
    }

    fn plan(&mut self, k: usize, tolerance: Option<f64>) -> Option<f64> {
        let (delta, eta) = self.local(k).step(self.rule);
        if !(delta.is_finite() && eta.is_finite()) {
            return None;
        }
        let s = match tolerance {
            None => 1.0,
            Some(tol) => max_fraction(
                self.r[k] - self.origin[k],
                delta,
                tol * (1.0 - TOLERANCE_MARGIN),
            ),
        };
        let new = self.r[k] + delta * s;
        if (new - self.r[k - 1]).length() < self.min_chord
            || (self.r[k + 1] - new).length() < self.min_chord
        {
            return None;
        }
        self.planned = (delta, eta);
        Some(s)
    }

    fn commit(&mut self, k: usize, s: f64, changed: &mut Vec<usize>) -> Result<(usize, f64)> {
        // F(sδ*, sη*) = −Q·s(2 − s) < 0 for s in (0, 1]: a scaled energy move still helps.
        let (delta, eta) = self.planned;
        self.r[k] += delta * s;
        self.m[k] += eta * s;
        self.disp.set(k, (self.r[k] - self.origin[k]).length());
        changed.extend([k - 1, k, k + 1]);
        Ok((k, (delta * s).length()))
    }

    fn max_displacement(&self) -> f64 {
        self.disp.max_value()
    }
}

/// The method parameters [`fair_hermite`] accepts.
pub const HERMITE_PARAMS: &[ParamSpec] = &[THRESHOLD_PARAM, EPSILON_PARAM];

/// Fair Hermite data `(t, points, tangents)` by `rule` (spec §2.6 without re-interpolation):
/// the bad point is the interior point with the largest `|J_k|` of the C¹ Hermite curve, it
/// moves (and, for [`KpRule::Energy`], its tangent changes by `η*`), the parameters and all
/// other data are kept, and only the jumps at `k−1, k, k+1` change. Stopping, tolerance and
/// the report are as for the point methods (module docs); the method parameters are
/// `threshold` and `epsilon` ([`HERMITE_PARAMS`]).
///
/// Returns an [`Outcome`] with the moved points and `tangents: Some(..)`.
///
/// # Errors
/// The data errors of [`hermite_step`]; [`Error::UnknownOption`] or
/// [`Error::InvalidParameter`] for bad options; for [`KpRule::Kjellander`], parameter steps
/// that are not 1.
pub fn fair_hermite(
    rule: KpRule,
    t: &[f64],
    points: &[Point],
    tangents: &[Vec2],
    options: &FairOptions,
) -> Result<Outcome> {
    check_hermite(t, points, tangents)?;
    if rule == KpRule::Kjellander {
        check_unit_steps(t)?;
    }
    options.validate()?;
    if let Some(key) = options
        .params
        .keys()
        .find(|k| !HERMITE_PARAMS.iter().any(|s| s.name == k.as_str()))
    {
        return Err(Error::UnknownOption {
            method: "hermite".into(),
            key: key.clone(),
            known: HERMITE_PARAMS
                .iter()
                .map(|s| s.name)
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    let threshold = Threshold::from_options(options)?;
    let n = points.len();
    let scale = BBox::from_points(points).map_or(0.0, |b| b.diagonal());
    let held = options.fix_ends.held().max(1);
    let mut state = HermiteState {
        rule,
        held,
        t: t.to_vec(),
        r: points.to_vec(),
        m: tangents.to_vec(),
        origin: points.to_vec(),
        disp: MaxTree::zeros(n),
        min_chord: MIN_CHORD_REL * scale,
        planned: (Vec2::ZERO, Vec2::ZERO),
    };
    let max_moves = move_limit(options, n.saturating_sub(2 * held));
    let driven = drive(&mut state, threshold, max_moves, options.tolerance)?;
    let parameters = driven_parameters(&driven, threshold, max_moves);
    Ok(Outcome {
        solver: None,
        points: state.r,
        status: driven.status,
        iterations: driven.moves.len(),
        moves: driven.moves,
        history: driven.history,
        parameters,
        notes: driven.notes,
        curve: None,
        tangents: Some(state.m),
        ends_held: Some(super::EndFix::Position),
    })
}

// ---------------------------------------------------------------------------------------
// The registered methods.

/// Method `kjellander`: uniform parametric cubic, the bad point moved by eq 4 (see the module
/// docs).
#[derive(Clone, Copy, Debug, Default)]
pub struct Kjellander;

/// Method `poliakoff`: chord-length parametric cubic, the bad point moved by eq 8 (see the
/// module docs).
#[derive(Clone, Copy, Debug, Default)]
pub struct Poliakoff;

/// Method `energy`: chord-length parametric cubic, the bad point moved by the energy-optimal
/// `δ*` of eqs 11–12 (spec §2.5), or by the position-only optimum with `mode = position`
/// (see the module docs).
#[derive(Clone, Copy, Debug, Default)]
pub struct Energy;

/// Parameters in data units of `kjellander` and their power of length: the jumps of the
/// uniform spline's third derivative are lengths.
const UNIFORM_LENGTH_PARAMS: &[(&str, i32)] = &[("epsilon", 1), ("initial_max_jump", 1)];

/// Parameters in data units of `poliakoff` and `energy`: on the chord-length spline the
/// third derivative has the unit 1/length².
const CHORD_LENGTH_PARAMS: &[(&str, i32)] = &[("epsilon", -2), ("initial_max_jump", -2)];

impl FairMethod for Kjellander {
    fn name(&self) -> &'static str {
        "kjellander"
    }

    fn description(&self) -> &'static str {
        "Kjellander: uniform cubic spline, worst point moved to zero its third-derivative jump (KP eq 4)"
    }

    fn parameters(&self) -> &'static [ParamSpec] {
        &[THRESHOLD_PARAM, EPSILON_PARAM]
    }

    fn supports_closed(&self) -> bool {
        true
    }

    fn params_at_scale(&self, options: &FairOptions, s: f64) -> Result<FairOptions> {
        Ok(super::guard::length_params_at_scale(
            options,
            UNIFORM_LENGTH_PARAMS,
            s,
        ))
    }

    fn report_params_at_scale(
        &self,
        parameters: &mut serde_json::Map<String, serde_json::Value>,
        s: f64,
    ) {
        super::guard::report_length_params(parameters, UNIFORM_LENGTH_PARAMS, s);
    }

    fn check_params(&self, options: &FairOptions) -> Result<()> {
        point_params(true, options).map(|_| ())
    }

    fn run(&self, input: &PointSeq, options: &FairOptions) -> Result<Outcome> {
        run_points(KpRule::Kjellander, true, input, options)
    }
}

impl FairMethod for Poliakoff {
    fn name(&self) -> &'static str {
        "poliakoff"
    }

    fn description(&self) -> &'static str {
        "Poliakoff: chord-length cubic spline, worst point moved to zero its third-derivative jump (KP eq 8)"
    }

    fn parameters(&self) -> &'static [ParamSpec] {
        &[THRESHOLD_PARAM, EPSILON_PARAM, REPARAMETRIZE_PARAM]
    }

    fn supports_closed(&self) -> bool {
        true
    }

    fn params_at_scale(&self, options: &FairOptions, s: f64) -> Result<FairOptions> {
        Ok(super::guard::length_params_at_scale(
            options,
            CHORD_LENGTH_PARAMS,
            s,
        ))
    }

    fn report_params_at_scale(
        &self,
        parameters: &mut serde_json::Map<String, serde_json::Value>,
        s: f64,
    ) {
        super::guard::report_length_params(parameters, CHORD_LENGTH_PARAMS, s);
    }

    fn check_params(&self, options: &FairOptions) -> Result<()> {
        point_params(false, options).map(|_| ())
    }

    fn run(&self, input: &PointSeq, options: &FairOptions) -> Result<Outcome> {
        run_points(KpRule::Poliakoff, false, input, options)
    }
}

impl FairMethod for Energy {
    fn name(&self) -> &'static str {
        "energy"
    }

    fn description(&self) -> &'static str {
        "improved Kjellander-Poliakoff: worst point moved by the energy-optimal change (KP eqs 11-12)"
    }

    fn parameters(&self) -> &'static [ParamSpec] {
        &[
            THRESHOLD_PARAM,
            EPSILON_PARAM,
            REPARAMETRIZE_PARAM,
            MODE_PARAM,
        ]
    }

    fn supports_closed(&self) -> bool {
        true
    }

    fn params_at_scale(&self, options: &FairOptions, s: f64) -> Result<FairOptions> {
        Ok(super::guard::length_params_at_scale(
            options,
            CHORD_LENGTH_PARAMS,
            s,
        ))
    }

    fn report_params_at_scale(
        &self,
        parameters: &mut serde_json::Map<String, serde_json::Value>,
        s: f64,
    ) {
        super::guard::report_length_params(parameters, CHORD_LENGTH_PARAMS, s);
    }

    fn check_params(&self, options: &FairOptions) -> Result<()> {
        energy_rule(options)?;
        point_params(false, options).map(|_| ())
    }

    fn run(&self, input: &PointSeq, options: &FairOptions) -> Result<Outcome> {
        run_points(energy_rule(options)?, false, input, options)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::spline::{EndCondition, Parametrization, parameters};

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
    fn max_tree_tracks_the_maximum() {
        let mut t = MaxTree::new(5);
        assert!(t.max().is_none());
        t.set(1, 3.0);
        t.set(3, 5.0);
        t.set(4, 5.0);
        assert_eq!(t.max(), Some((3, 5.0)));
        t.set(3, f64::NEG_INFINITY);
        assert_eq!(t.max(), Some((4, 5.0)));
        t.set(4, 1.0);
        assert_eq!(t.max(), Some((1, 3.0)));
    }

    #[test]
    fn max_tree_runs_match_a_scan() {
        let n = 37;
        let mut t = MaxTree::new(n);
        let mut v = vec![f64::NEG_INFINITY; n];
        for round in 0..50usize {
            let start = (round * 11) % n;
            let items: Vec<(usize, f64)> = (0..9)
                .map(|j| {
                    let i = (start + j) % n;
                    (i, ((round * 31 + j * 17) % 23) as f64)
                })
                .collect();
            for &(i, x) in &items {
                v[i] = x;
            }
            t.set_runs(items.into_iter());
            let best = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let (i, x) = t.max().unwrap();
            assert_eq!(x, best);
            assert_eq!(v[i], best);
        }
    }

    #[test]
    fn max_fraction_stops_on_the_bound() {
        let e = Vec2::new(0.5, 0.0);
        let w = Vec2::new(1.0, 0.0);
        assert!((max_fraction(e, w, 1.0) - 0.5).abs() < 1e-15);
        assert_eq!(max_fraction(Vec2::ZERO, w, 2.0), 1.0);
        // On the bound, outward: nothing; inward: up to the far side.
        assert_eq!(max_fraction(Vec2::new(1.0, 0.0), w, 1.0), 0.0);
        assert_eq!(max_fraction(Vec2::new(1.0, 0.0), -w, 1.0), 1.0);
        let s = max_fraction(Vec2::new(0.3, 0.4), Vec2::new(-3.0, 1.0), 0.6);
        let end = Vec2::new(0.3, 0.4) + Vec2::new(-3.0, 1.0) * s;
        assert!((end.length() - 0.6).abs() < 1e-14);
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
