//! Kjellander, Poliakoff and the energy-optimal change of position and tangent: fairing a
//! parametric cubic spline by moving its worst point (methods `kjellander`, `poliakoff`,
//! `energy`).
//!
//! Paper: *Improved fairing of non-uniform parametric cubic splines* (Kjellander → Poliakoff →
//! position + tangent), `../shared/papers/kjellander-poliakoff-improved.txt`. The equations
//! are the reconstructed forms of docs/algorithms/kjellander-poliakoff.md §2
//! (`../shared/spec/ALGORITHMS.md`); nearly every printed equation is damaged by OCR
//! (docs/algorithms/kjellander-poliakoff.md §2.8):
//!
//! - the third-derivative jump `J_k = r'''(t_k+) − r'''(t_k−) = 6(a_{k,3} − a_{k−1,3})` of the
//!   Hermite coefficients of KP eq 6 (docs/algorithms/kjellander-poliakoff.md §2.2);
//! - **Kjellander** (eq 4, uniform parameters): `r_k,new = (r_{k−1} + r_{k+1})/2 +
//!   (r'_{k−1} − r'_{k+1})/4` — the printed equation is unreadable,
//!   docs/algorithms/kjellander-poliakoff.md §2.8 gives this form;
//! - **Poliakoff** (eq 8, any parameters, `A = Δ_{k−1}`, `B = Δ_k`): the position that makes
//!   `J_k = 0` with every tangent kept (docs/algorithms/kjellander-poliakoff.md §2.3);
//! - **energy** (eqs 11–12 as **fixed** in docs/algorithms/kjellander-poliakoff.md §2.5): the
//!   change `(δ*, η*)` of position and tangent that minimises the exact energy change `W' − W =
//!   4C·F(δ, η)` of Lemma 1 (eq 14, with the coefficient repairs of
//!   docs/algorithms/kjellander-poliakoff.md §2.8). With `η = 0` the minimiser is `δ = J3/(2/A³ +
//!   2/B³)`, which is Poliakoff's eq 8 (the corollary): that is the `mode = position` of the
//!   `energy` method and [`KpRule::EnergyPositionOnly`].
//!
//! # The algorithm (docs/algorithms/kjellander-poliakoff.md §2.6)
//!
//! 1. Interpolate the points with the C² cubic spline with natural ends
//!    (docs/algorithms/kjellander-poliakoff.md §2.1): chord-length parameters for `poliakoff`
//!    and `energy`, uniform `t_i = i` for `kjellander`.
//!    Closed curves use the periodic spline (as [`ParametricCubic::closed`]): every point is
//!    then interior.
//! 2. The bad point is the interior point with the largest `|J_k|` (Euclidean norm).
//! 3. Stop when `|J_k| ≤ ε`. `ε` is the method parameter `epsilon` when given (in the units of
//!    `J`), otherwise `threshold × max_k |J_k|` of the input spline ([`DEFAULT_THRESHOLD`]):
//!    the paper only says "give a small positive number", and a bound relative to the input's
//!    own jumps is independent of the data's scale and parametrisation.
//! 4. Move the bad point by its rule. Point-only fairing applies the position only: the
//!    `energy` method applies `δ*` and discards `η*` (as the paper does in its examples,
//!    docs/algorithms/kjellander-poliakoff.md §2.6 step 4), since re-interpolation recomputes every
//!    tangent.
//! 5. Re-interpolate, recomputing the chord-length parameters from the moved points (the
//!    \[CHOICE\] of docs/algorithms/kjellander-poliakoff.md §2.6 step 5; method parameter
//!    `reparametrize = false` keeps the input's parameters instead). Repeat from 2.
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
//!
//! # Files
//!
//! - `rules.rs`: the jump and the three rules at one point (docs/algorithms/kjellander-poliakoff.md
//!   §2.2–§2.5);
//! - `params.rs`: the `--set` tables beyond ε;
//! - `points.rs`: point-only fairing of a point sequence (windowed re-solves);
//! - `hermite.rs`: fairing of Hermite data;
//! - this file: the three registered methods.
//!
//! `docs/algorithms/kjellander-poliakoff.md` gives the formulas with the paper's equation
//! numbers and maps the spec sections cited here to its own.
//!
//! [`ParametricCubic::closed`]: crate::spline::ParametricCubic::closed

mod hermite;
mod params;
mod points;
mod rules;

use super::{FairMethod, FairOptions, Outcome, ParamSpec};
use crate::error::Result;
use crate::geom::PointSeq;

use super::engine::{EPSILON, JUMP_PARAMS};
pub use hermite::fair_hermite;
use params::{ENERGY_PARAMS, POLIAKOFF_PARAMS, energy_rule, point_params};
use points::run_points;
pub use rules::{HermiteMove, KpRule, energy_change_f, hermite_step, parametric_energy};

/// Method `kjellander`: uniform parametric cubic, the bad point moved by eq 4 (see
/// `docs/algorithms/kjellander-poliakoff.md`, and the module docs of `fair/kjellander/mod.rs`
/// in the source).
#[derive(Clone, Copy, Debug, Default)]
pub struct Kjellander;

/// Method `poliakoff`: chord-length parametric cubic, the bad point moved by eq 8 (see
/// `docs/algorithms/kjellander-poliakoff.md`).
#[derive(Clone, Copy, Debug, Default)]
pub struct Poliakoff;

/// Method `energy`: chord-length parametric cubic, the bad point moved by the energy-optimal
/// `δ*` of eqs 11–12 (docs/algorithms/kjellander-poliakoff.md §2.5), or by the position-only
/// optimum with `mode = position` (see `docs/algorithms/kjellander-poliakoff.md`).
#[derive(Clone, Copy, Debug, Default)]
pub struct Energy;

/// Parameters in data units of `kjellander` and their power of length: the jumps of the
/// uniform spline's third derivative are lengths.
const UNIFORM_LENGTH_PARAMS: &[(&str, i32)] = &[(EPSILON.name, 1), ("initial_max_jump", 1)];

/// Parameters in data units of `poliakoff` and `energy`: on the chord-length spline the
/// third derivative has the unit 1/length².
const CHORD_LENGTH_PARAMS: &[(&str, i32)] = &[(EPSILON.name, -2), ("initial_max_jump", -2)];

impl FairMethod for Kjellander {
    fn name(&self) -> &'static str {
        "kjellander"
    }

    fn description(&self) -> &'static str {
        "Kjellander: uniform cubic spline, worst point moved to zero its third-derivative jump (KP eq 4)"
    }

    fn parameters(&self) -> &'static [ParamSpec] {
        &JUMP_PARAMS
    }

    fn supports_closed(&self) -> bool {
        true
    }

    fn length_params(&self) -> &'static [(&'static str, i32)] {
        UNIFORM_LENGTH_PARAMS
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
        &POLIAKOFF_PARAMS
    }

    fn supports_closed(&self) -> bool {
        true
    }

    fn length_params(&self) -> &'static [(&'static str, i32)] {
        CHORD_LENGTH_PARAMS
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
        &ENERGY_PARAMS
    }

    fn supports_closed(&self) -> bool {
        true
    }

    fn length_params(&self) -> &'static [(&'static str, i32)] {
        CHORD_LENGTH_PARAMS
    }

    fn check_params(&self, options: &FairOptions) -> Result<()> {
        energy_rule(options)?;
        point_params(false, options).map(|_| ())
    }

    fn run(&self, input: &PointSeq, options: &FairOptions) -> Result<Outcome> {
        run_points(energy_rule(options)?, false, input, options)
    }
}
