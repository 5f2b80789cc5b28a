//! `han`: the explicit fairing indicator of Han, Zhang, Dong and Liu, *An explicit fairing
//! indicator for 2D curves* (`shared/papers/han-explicit-fairing-indicator.txt`), implemented as
//! specified in `shared/spec/ALGORITHMS.md` §1.
//!
//! # The method
//!
//! The points are split into overlapping pieces that are functions `Y(X)` in a rotated frame
//! (§1.8). Each piece is represented by the cubic spline function with HAN's end condition
//! `c_1 = c_2`, `c_{n−1} = c_n` ([`CubicSplineFn`], eqs 2–10), whose x–c plot `(x_i, c_i)`,
//! `c_i = y''(x_i)/6`, stands in for the curvature plot. Because the spline is linear in `y`,
//! moving `y_j` by `γ_j` changes every `c_i` by `γ_j c̃_i^j` exactly (eq 13), where `c̃^j` is the
//! spline through `(x_i, δ_ij)` ([`UnitResponses`], eqs 14–17). The fairing moves are closed-form
//! solutions of small linear systems in these responses: a coarse phase removes vibrations of
//! the indicator `e_i` (the turning of the x–c plot, eq 18) and a fine phase removes spurious
//! sign changes of `c` (inflections). See [`Segment`] for the cases.
//!
//! # Spec fixes and choices used
//!
//! - eq 4: the three-moment equation reads `… + h_i c_{i+1} = d_i` (\[FIX\], §1.2);
//! - eq 9: `h_j = x_{j+1} − x_j` in the numerator; eq 10: the forward relation below j (\[FIX\]);
//! - eqs 14–15 at j = 2 and j = n−1: `ā_{j−1} = 0`, `ā*_{j+1} = 0` in the numerator and
//!   `c̃_1^2 = c̃_2^2`, `c̃_n^{n−1} = c̃_{n−1}^{n−1}` (\[FIX\], §1.6);
//! - `e_1 = e_n = 0` (flat ends, \[CHOICE\] §1.5); sign tests with `sgn0` and
//!   [`ZERO_REL`] `= 1e-12` relative to the largest |value| of the
//!   current array (\[CHOICE\] §1.7.0), and also values within [`ROUNDING_FLOOR_FACTOR`]
//!   times the noise that rounding the coordinates puts into c and e counted as 0 (\[CHOICE\],
//!   not in the spec: on densely sampled data every e is rounding noise, which a relative test
//!   cannot recognise; see [`Segment::c_floor`]). The floors depend on the coordinates'
//!   magnitude, so a translation can change a sign test on a value at its floor, as rounding
//!   can at the relative threshold;
//! - coarse case 2 end rule `e_2 e_3 < 0 ∧ e_2 e_4 < 0` and its mirror (\[CHOICE/FIX\] §1.7.1);
//! - coarse case 3 end rule with `e_2 e_4 < 0`, `e_2 e_5 < 0` (\[FIX\] §1.7.1);
//! - fine-phase α rule: a fifth of the smaller-magnitude neighbour, left on a tie (\[CHOICE\]
//!   §1.7.2, reflection invariant);
//! - fine case 2 unknowns `γ_{i−1} = −λ_f σ, γ_i = σ, γ_{i+1} = τ, γ_{i+2} = −λ_f τ`: the printed
//!   unknowns give a singular system for mirror-symmetric spacing (\[FIX/CHOICE\] §1.7.2);
//! - one iteration runs C1, C2 (+ends), C3 (+ends), F1, F2 (+ends) (\[CHOICE\] §1.7.3), and in
//!   the `han` method then F3 (below);
//! - **fine case 3, an extension not in the paper** ([`Segment::fine_case3`],
//!   [`SegmentParams::fine_run3`], [`DEFAULT_FINE_RUN3`]): a run of three points of one sign of
//!   c between opposite neighbours is set to 0 (then α) by moving five points, built like fine
//!   case 2. The paper's fine cases remove runs of one and two points only; runs of three near
//!   a true inflection were what left `han` with more spurious inflections than csaps on the
//!   noisy sine of the peer comparison. A [`Segment`] runs the paper's cases unless asked; the
//!   `han` method runs F3 by default, and `--set fine_run3=false` gives the paper's method;
//! - unwrapped turning angles, first s with range > `max_turn`, segment `P_b..P_{s−1}`, minimum
//!   segment length k + 2, k shared points, bisector frame from argmax/argmin (\[FIX\]/\[CHOICE\]
//!   §1.8); segments of one pass are faired independently from the same points and blended
//!   with weights `q/(K+1)` (\[CHOICE\] §1.8.6).
//!
//! # Cost
//!
//! Everything is O(n) per iteration. The unit responses are *not* stored as an n×n matrix:
//! [`UnitResponses`] keeps `c̃_{j−1}^j, c̃_j^j, c̃_{j+1}^j` per column (3n numbers) and generates
//! the rest from the geometric recurrences eqs 16–17 (`c̃_i^j = −a_i c̃_{i+1}^j` to the left,
//! `−a*_i c̃_{i−1}^j` to the right, `0 < a_i, a*_i < 1/2`). After every move, `c` is updated by
//! adding the response columns (eq 13) — the summed column of a move obeys the same
//! recurrences outside the moved points, so it is walked outward once and cut off when it
//! falls below [`RESPONSE_CUTOFF_REL`] of its largest entry (at most ~57 steps since each step
//! at least halves it, ~30 on a uniform grid). `e` is recomputed from `c` on the changed range.
//! The sign tests need max|c| and max|e| only to tell rounding residue from real values: an
//! upper bound (raised by every written value) and a lower bound (one tracked entry) decide
//! every test except one on a value between `ZERO_REL·lower` and `ZERO_REL·upper`, which
//! rescans for the exact maximum, so the tests are exactly those of the spec. A move
//! therefore costs O(57) at worst and a sweep O(n), with no re-solve of the spline.
//! The segments of a pass are faired in parallel (rayon); blending and the report follow the
//! curve's order, so the result does not depend on the number of threads.
//! Measured (release, `benches/han.rs`, the spiral with a 1 % wobble): see `BENCHMARKS.md`;
//! about 0.2 s for 10⁵ points and 2 s for 10⁶ on 2 cores with the default 3 passes × 10
//! iterations, some 16 million moves at 10⁶. The cost is linear in the sweeps (10⁶ points:
//! 1.0 s for one pass of 10 iterations, 1.1 s for 3 × 3).
//!
//! # Common options
//!
//! - **Ends.** The paper fixes `P_1` and `P_N` and so does `han`, whatever `fix_ends` says
//!   (its report says `fixed_ends: position` at least).
//!   `--fix-ends=tangent` (`curvature`) also holds the second (and third) point at each end
//!   of an open curve: they get zero-width bounds, so a move that would shift one is not made.
//! - **Tolerance.** A hard bound: every move is scaled back (as a whole, keeping its shape) so
//!   that no point leaves the disc of radius D around its *input* position; blending is a convex
//!   combination, which keeps points inside the disc.
//! - **`max_iterations`** is T, the iterations per segment and pass (default 10). The
//!   report's `iterations` is in the same unit: the most iterations any segment ran in a
//!   pass (an iteration that moved nothing ends a segment's pass), so it never exceeds
//!   `--max-iterations`; the passes are the report's `history`, one row each.
//! - **Closed curves** are supported seam-aware: pass p cuts the cycle at point
//!   `⌊p·N/passes⌋`, fairs the open sequence from that point round to itself (the cut point
//!   repeated at the end, both copies fixed), and writes the result back. Successive passes cut
//!   at different points, so with two or more passes every point is faired; with one pass the
//!   cut point (point 0) stays where it is.
//! - **`max_turn`** defaults to π/2, the value the spec recommends, not the paper's π
//!   (\[CHOICE\], [`DEFAULT_MAX_TURN`]; `--set max_turn=pi` restores the paper's). With π a
//!   densely sampled segment's end chords are nearly vertical in its frame, and on the peer
//!   comparison π leaves more spurious inflections than csaps in 6 of 10 cases, π/2 in 1 of 15
//!   (and none with fine case 3 too).
//! - A segment that is not a function in its bisector frame, or has a chord steeper than
//!   [`MAX_LOCAL_SLOPE`] there (\[CHOICE\] guard), is re-partitioned with half the turning
//!   threshold, down to [`MIN_FALLBACK_TURN`] = π/8, and otherwise left as it is; both are
//!   reported in the notes. This happens with `max_turn = π` at the ends of segments of
//!   densely sampled curves (their end chords approach the vertical), and when the minimum
//!   segment length extends a segment round a tight loop.

use std::f64::consts::{FRAC_PI_2, PI};
use std::ops::Range;

use rayon::prelude::*;

use super::{
    EndFix, FairMethod, FairStatus, HistoryRow, Move, Outcome, ParamSpec, clamp_to_tolerance,
};
use crate::analysis::{ZERO_REL, count_sign_changes, sgn0};
use crate::error::{Error, Result};
use crate::fair::FairOptions;
use crate::geom::{Point, PointSeq, Vec2, max_abs_coordinate};
use crate::spline::{CubicSplineFn, FnEndCondition};

/// Default damping of coarse case 1, `λ_c` \[PAPER\].
pub const DEFAULT_LAMBDA_COARSE: f64 = 0.8;
/// Default weight of the outer points in the fine cases, `λ_f` \[PAPER\].
pub const DEFAULT_LAMBDA_FINE: f64 = 0.75;
/// Default factor of the fine-phase α rule, `α = factor · v` \[PAPER: 1/5\].
pub const DEFAULT_ALPHA_FACTOR: f64 = 0.2;
/// Whether the `han` method runs fine case 3 ([`SegmentParams::fine_run3`]), an extension
/// not in the paper \[CHOICE\]: on the peer comparison it is what makes `han` leave no more
/// spurious inflections than csaps in every case (`fine_run3=false` gives the paper's method).
pub const DEFAULT_FINE_RUN3: bool = true;
/// Default number of points shared by consecutive segments, k \[PAPER\].
pub const DEFAULT_OVERLAP: usize = 5;

/// Largest `overlap` accepted: an overlap beyond a segment's length changes nothing, and this
/// is more points than any segment holds in practice.
pub const MAX_OVERLAP: usize = 1_000_000;
/// Default number of pipeline passes (partition, fair, blend) \[CHOICE\].
pub const DEFAULT_PASSES: usize = 3;
/// The paper's turning threshold of the partition, π \[PAPER\] (`--set max_turn=pi`).
pub const PAPER_MAX_TURN: f64 = PI;
/// Default turning threshold of the partition, π/2 \[CHOICE\]: the value the spec recommends
/// (§1.8 note). Segments then stay far from vertical local slopes, where the function-spline
/// proxy breaks down; with the paper's π the end chords of a densely sampled segment are
/// nearly vertical in its frame. Measured on the peer comparison (`bench/compare_peers.py`),
/// π/2 (with fine case 3) is what makes `han` leave no more spurious inflections than csaps.
pub const DEFAULT_MAX_TURN: f64 = FRAC_PI_2;
/// The recommended turning threshold: the default, π/2.
pub const RECOMMENDED_MAX_TURN: f64 = DEFAULT_MAX_TURN;
/// A segment that is too steep in its frame is re-partitioned with half the turning
/// threshold, down to this one; below it the segment is left unfaired (\[CHOICE\]).
pub const MIN_FALLBACK_TURN: f64 = PI / 8.0;
/// Default iterations per segment, T \[CHOICE §1.7.3\].
pub const DEFAULT_ITERATIONS: usize = 10;
/// The fewest points a function segment must have to be faired (spec §1.7).
pub const MIN_SEGMENT_POINTS: usize = 5;
/// The summed response column of a move is walked outward until its entries fall to this
/// fraction of its largest entry. Below half an ulp of the largest change, so the truncated
/// update equals eq 13 to rounding.
pub const RESPONSE_CUTOFF_REL: f64 = 1e-17;
/// Rounding-noise floor of the sign tests \[CHOICE\]. Rounding the coordinates (magnitude R) to
/// double precision puts noise of up to about `0.4·ε·R/h²` into c and `4·0.4·ε·R/h³` into e
/// (measured on 10⁶ samples of a sine, offset by 100, with spacing h): on dense data every e,
/// and the c near a true inflection, can be pure noise, which the spec's relative zero test
/// (§1.7.0) cannot tell from signal. Values of c at most `F·ε·R/h²` and of e at most
/// `4F·ε·R/h³` (h the shorter chord at the point) count as 0 in the sign tests, with this F
/// — the factor of the curve metrics' floor. It changes nothing on data whose noise is above
/// rounding; on a clean curve it keeps `han` from fairing rounding noise (a clean 10⁶-point
/// spiral made 5.4 million moves without it, none with it).
pub const ROUNDING_FLOOR_FACTOR: f64 = 64.0;
/// A 2×2 system is treated as singular (the move is skipped) when `|det|` is at most this
/// fraction of `|a11 a22| + |a12 a21|`. The systems of coarse case 3 and fine case 2 have
/// condition numbers below 30 on sane grids (spec §1.7).
pub const SINGULAR_REL: f64 = 1e-12;
/// A segment with a chord steeper than this in its bisector frame (`|ΔY/ΔX|`, ≈ 89.4°) is
/// re-partitioned with half the turning threshold, down to π/8, and left unfaired only past
/// that (\[CHOICE\] guard). The function-spline proxy assumes moderate slopes (spec §1.8
/// note: up to 76 seen on the strophoid with `max_turn = π`, faired with some drift). Steeper
/// segments come from the minimum-length rule extending a segment round a tight loop until it
/// turns by almost π; their spacing ratios reach 1e-6, the unit responses are huge and the
/// moves diverge (we saw a point thrown 500 curve sizes away). With `max_turn = π/2` segments
/// have slopes ≤ 1 unless extended.
pub const MAX_LOCAL_SLOPE: f64 = 100.0;
/// At most this many moves are listed in the report; later moves are counted, not listed.
pub const MAX_RECORDED_MOVES: usize = 10_000;
/// The tolerance is shrunk by this relative amount before use, so that rounding in the frame
/// changes cannot push a point over the bound.
const TOLERANCE_SAFETY_REL: f64 = 1e-9;
/// … and by this many ulps of the largest coordinate (rounding of absolute positions).
const TOLERANCE_SAFETY_ULPS: f64 = 16.0;

// ---------------------------------------------------------------------------------------------
// Unit responses
// ---------------------------------------------------------------------------------------------

/// HAN's unit spline responses `c̃_i^j` (spec §1.6, eqs 14–17 with the end fix) and the
/// derived `ẽ_i^j`, for the end condition `c_1 = c_2`, `c_{n−1} = c_n`. They depend on x only.
///
/// Storage is O(n): `c̃_{j−1}^j, c̃_j^j, c̃_{j+1}^j` for each interior j plus the sweep
/// coefficients; farther entries come from `c̃_i^j = −a_i c̃_{i+1}^j` (i ≤ j−2) and
/// `c̃_i^j = −a*_i c̃_{i−1}^j` (i ≥ j+2), O(|i−j|) each. Indices are 0-based; the columns are
/// the interior points `1..=n−2`.
#[derive(Clone, Debug, PartialEq)]
pub struct UnitResponses {
    h: Vec<f64>,
    inv_h: Vec<f64>,
    /// Forward sweep `a`, length n − 1 (`a[0] = −1`).
    a: Vec<f64>,
    /// Backward sweep `a*`, length n; `a_star[0]` is unused (0).
    a_star: Vec<f64>,
    diag: Vec<f64>,
    left: Vec<f64>,
    right: Vec<f64>,
    /// `ẽ_{j−1}^j, ẽ_j^j, ẽ_{j+1}^j` per column j (0 outside the interior): the entries the
    /// coarse cases use, computed once.
    e_near: Vec<[f64; 3]>,
}

impl UnitResponses {
    /// The responses for abscissae `x` (strictly increasing, at least 3 values).
    ///
    /// # Errors
    /// As [`CubicSplineFn::try_new`].
    pub fn new(x: &[f64]) -> Result<UnitResponses> {
        let s = CubicSplineFn::try_new(x.to_vec(), vec![0.0; x.len()], FnEndCondition::Han)?;
        UnitResponses::from_spline(&s)
    }

    /// The responses for the abscissae of `spline` (which must use [`FnEndCondition::Han`]),
    /// reusing its sweep coefficients.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for another end condition.
    pub fn from_spline(spline: &CubicSplineFn) -> Result<UnitResponses> {
        if spline.end_condition() != FnEndCondition::Han {
            return Err(Error::InvalidParameter {
                name: "end condition".into(),
                reason: "unit responses are defined for the Han end condition".into(),
            });
        }
        let n = spline.len();
        let h = spline.h().to_vec();
        let a = spline.forward_a().to_vec();
        let mut a_star = vec![0.0; n];
        a_star[1..].copy_from_slice(spline.backward_a());
        let mut diag = vec![0.0; n];
        let mut left = vec![0.0; n];
        let mut right = vec![0.0; n];
        for j in 1..n - 1 {
            let (h0, h1) = (h[j - 1], h[j]);
            let a_bar = if j >= 2 { a[j - 1] } else { 0.0 };
            let a_star_bar = if j + 2 < n { a_star[j + 1] } else { 0.0 };
            let den = 2.0 * (h0 + h1) - a[j - 1] * h0 - a_star[j + 1] * h1;
            let d = -((1.0 + a_bar) / h0 + (1.0 + a_star_bar) / h1) / den; // eq 14
            diag[j] = d;
            left[j] = if j >= 2 {
                a[j - 1] * (1.0 / (h0 * h0) - d)
            } else {
                d
            }; // eq 15
            right[j] = if j + 2 < n {
                a_star[j + 1] * (1.0 / (h1 * h1) - d)
            } else {
                d
            };
        }
        let mut resp = UnitResponses {
            inv_h: h.iter().map(|v| 1.0 / v).collect(),
            h,
            a,
            a_star,
            diag,
            left,
            right,
            e_near: Vec::new(),
        };
        let mut e_near = vec![[0.0; 3]; n];
        for (j, near) in e_near.iter_mut().enumerate().take(n - 1).skip(1) {
            *near = [
                resp.e_walk(j - 1, j),
                resp.e_walk(j, j),
                resp.e_walk(j + 1, j),
            ];
        }
        resp.e_near = e_near;
        Ok(resp)
    }

    /// Number of points n.
    pub fn len(&self) -> usize {
        self.diag.len()
    }

    /// Always false (n ≥ 3).
    pub fn is_empty(&self) -> bool {
        self.diag.is_empty()
    }

    /// `c̃_i^j`: the change of `c_i` per unit move of `y_j`, for `i < n` and an interior j.
    /// O(|i − j|).
    ///
    /// # Panics
    /// When j is not interior or i is out of range.
    pub fn c(&self, i: usize, j: usize) -> f64 {
        let n = self.len();
        assert!(
            j >= 1 && j + 1 < n && i < n,
            "unit response ({i}, {j}) out of range (n = {n})"
        );
        self.c_at(i, j)
    }

    /// [`UnitResponses::c`] for indices the caller has checked (the hot path).
    #[inline]
    fn c_at(&self, i: usize, j: usize) -> f64 {
        debug_assert!(j >= 1 && j + 1 < self.len() && i < self.len());
        if i == j {
            self.diag[j]
        } else if i + 1 == j {
            self.left[j]
        } else if i == j + 1 {
            self.right[j]
        } else if i < j {
            // Walk outward from j so that c̃_0^j = c̃_1^j holds bit for bit (−a_0 = 1).
            let mut v = self.left[j];
            for k in (i..=j - 2).rev() {
                v *= -self.a[k];
            }
            v
        } else {
            let mut v = self.right[j];
            for k in j + 2..=i {
                v *= -self.a_star[k];
            }
            v
        }
    }

    /// `ẽ_i^j = (c̃_{i+1}^j − c̃_i^j)/h_i − (c̃_i^j − c̃_{i−1}^j)/h_{i−1}`, 0 at the end points
    /// (spec §1.6). O(|i − j|).
    ///
    /// # Panics
    /// As [`UnitResponses::c`].
    pub fn e(&self, i: usize, j: usize) -> f64 {
        let n = self.len();
        assert!(
            j >= 1 && j + 1 < n && i < n,
            "unit response ({i}, {j}) out of range (n = {n})"
        );
        self.e_at(i, j)
    }

    /// [`UnitResponses::e`] for indices the caller has checked (the hot path).
    #[inline]
    fn e_at(&self, i: usize, j: usize) -> f64 {
        debug_assert!(j >= 1 && j + 1 < self.len() && i < self.len());
        if i + 1 >= j && i <= j + 1 {
            return self.e_near[j][i + 1 - j];
        }
        self.e_walk(i, j)
    }

    /// `ẽ_i^j` from the column entries (for valid indices).
    fn e_walk(&self, i: usize, j: usize) -> f64 {
        if i == 0 || i == self.len() - 1 {
            return 0.0;
        }
        let (cm, c0, cp) = (self.c_at(i - 1, j), self.c_at(i, j), self.c_at(i + 1, j));
        (cp - c0) / self.h[i] - (c0 - cm) / self.h[i - 1]
    }

    /// The whole column `c̃^j` (length n), by the recurrences. O(n); for inspection and tests.
    ///
    /// # Panics
    /// As [`UnitResponses::c`].
    pub fn column_c(&self, j: usize) -> Vec<f64> {
        let n = self.len();
        let mut col = vec![0.0; n];
        col[j] = self.c(j, j);
        col[j - 1] = self.left[j];
        col[j + 1] = self.right[j];
        for i in (0..j.saturating_sub(1)).rev() {
            col[i] = -self.a[i] * col[i + 1];
        }
        for i in j + 2..n {
            col[i] = -self.a_star[i] * col[i - 1];
        }
        col
    }

    /// The whole column `ẽ^j` (length n). O(n); for inspection and tests.
    ///
    /// # Panics
    /// As [`UnitResponses::c`].
    pub fn column_e(&self, j: usize) -> Vec<f64> {
        let c = self.column_c(j);
        let n = c.len();
        let mut e = vec![0.0; n];
        for i in 1..n - 1 {
            e[i] = (c[i + 1] - c[i]) / self.h[i] - (c[i] - c[i - 1]) / self.h[i - 1];
        }
        e
    }

    /// Eq 13 for a move of the consecutive interior points `start, start+1, …` by `gammas`:
    /// `c ← c + Σ γ_j c̃^j`. Returns the inclusive index range of `c` that changed and the
    /// largest new |c_i| on it. Entries below [`RESPONSE_CUTOFF_REL`] of the largest change
    /// are not added. O(57 + len²).
    ///
    /// # Panics
    /// When the moved points are not all interior or `c` has the wrong length.
    pub fn add_columns(&self, start: usize, gammas: &[f64], c: &mut [f64]) -> Changed {
        let n = self.len();
        assert_eq!(c.len(), n, "add_columns: c has the wrong length");
        assert!(
            start >= 1 && !gammas.is_empty() && start + gammas.len() < n,
            "add_columns: moved points must be interior"
        );
        let end = start + gammas.len() - 1;
        let (lo, hi) = (start - 1, end + 1);
        // The summed column on lo..=hi, in a fixed order (bitwise c̃_0 = c̃_1 preserved).
        let mut core = [0.0_f64; 8];
        let width = hi - lo + 1;
        for (k, &g) in gammas.iter().enumerate() {
            // Column j on lo..=hi, walked outward from j with the same products as `c_at`;
            // every entry of `core` sums the columns in the order of `gammas`.
            let j = start + k;
            core[j - lo] += g * self.diag[j];
            let mut v = self.left[j];
            core[j - 1 - lo] += g * v;
            for i in (lo..j - 1).rev() {
                v *= -self.a[i];
                core[i - lo] += g * v;
            }
            let mut v = self.right[j];
            core[j + 1 - lo] += g * v;
            for i in j + 2..=hi {
                v *= -self.a_star[i];
                core[i - lo] += g * v;
            }
        }
        let big = abs_max(&core[..width]);
        let (mut first, mut last) = (lo, hi);
        for (ci, d) in c[lo..=hi].iter_mut().zip(&core[..width]) {
            *ci += d;
        }
        let cut = RESPONSE_CUTOFF_REL * big;
        // Left of the moved points every column obeys c̃_i = −a_i c̃_{i+1}, so the sum does.
        let mut d = core[0];
        let mut i = lo;
        while i > 0 {
            i -= 1;
            d *= -self.a[i];
            if d.abs() <= cut {
                break;
            }
            c[i] += d;
            first = i;
        }
        let mut d = core[width - 1];
        let mut i = hi;
        while i + 1 < n {
            i += 1;
            d *= -self.a_star[i];
            if d.abs() <= cut {
                break;
            }
            c[i] += d;
            last = i;
        }
        Changed::of(c, first, last)
    }
}

/// The entries of an array that a local update rewrote: `lo..=hi`, and the largest new
/// magnitude among them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Changed {
    /// First rewritten index.
    pub lo: usize,
    /// Last rewritten index (inclusive).
    pub hi: usize,
    /// Largest |v_i| on `lo..=hi` after the update.
    pub max: f64,
}

impl Changed {
    /// The entries `lo..=hi` of `values`, rewritten.
    fn of(values: &[f64], lo: usize, hi: usize) -> Changed {
        Changed {
            lo,
            hi,
            max: abs_max(&values[lo..=hi]),
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Exact sign tests under local updates
// ---------------------------------------------------------------------------------------------

/// `sgn0(v, max_k |v_k|)` (spec §1.7.0) for an array under local updates, without keeping the
/// maximum itself exact: an upper bound (raised by every written value) and a lower bound (the
/// magnitude of one tracked entry) decide almost every test; only a value between
/// `ZERO_REL·lower` and `ZERO_REL·upper` needs the exact maximum, which is then rescanned and
/// both bounds are reset to it. The result is the same as with the exact maximum.
#[derive(Clone, Debug)]
struct SignScale {
    /// At least max |v_k|.
    upper: f64,
    /// `|v[at]|`, so at most max |v_k|.
    lower: f64,
    at: usize,
    /// Number of full rescans (for tests and tuning).
    rescans: usize,
}

impl SignScale {
    fn new(values: &[f64]) -> SignScale {
        let (at, m) = abs_argmax(values);
        SignScale {
            upper: m,
            lower: m,
            at,
            rescans: 0,
        }
    }

    /// The entries `w.lo..=w.hi` of `values` were rewritten.
    fn wrote(&mut self, values: &[f64], w: Changed) {
        if w.max > self.upper {
            self.upper = w.max;
        }
        if (w.lo..=w.hi).contains(&self.at) {
            self.lower = values[self.at].abs();
        }
        if w.max > self.lower {
            self.lower = w.max;
            self.at = w.lo + abs_argmax(&values[w.lo..=w.hi]).0;
        }
    }

    /// `sgn0(values[i], max |values|)`, and 0 when `|values[i]| ≤ floor[i]`.
    #[inline]
    fn sign(&mut self, values: &[f64], floor: &[f64], i: usize) -> i8 {
        let v = values[i];
        let a = v.abs();
        if a <= ZERO_REL * self.lower || a <= floor[i] {
            return 0;
        }
        if a > ZERO_REL * self.upper {
            return if v > 0.0 { 1 } else { -1 };
        }
        self.rescan(values);
        sgn0(v, self.upper)
    }

    #[cold]
    fn rescan(&mut self, values: &[f64]) {
        let (at, m) = abs_argmax(values);
        self.upper = m;
        self.lower = m;
        self.at = at;
        self.rescans += 1;
    }
}

/// The index and magnitude of the largest |v| of a slice of finite values ((0, 0) when empty).
fn abs_argmax(v: &[f64]) -> (usize, f64) {
    let m = abs_max(v);
    (v.iter().position(|x| x.abs() == m).unwrap_or(0), m)
}

/// max |v| of a slice of finite values (0 for an empty one), with independent accumulators so
/// that the reduction vectorises; max is exact, so the order does not matter. A plain
/// comparison replaces `f64::max`, whose NaN handling costs here and is not needed.
fn abs_max(v: &[f64]) -> f64 {
    let bigger = |m: f64, x: f64| if x > m { x } else { m };
    let mut acc = [0.0_f64; 4];
    let mut chunks = v.chunks_exact(4);
    for ch in &mut chunks {
        for (a, x) in acc.iter_mut().zip(ch) {
            *a = bigger(*a, x.abs());
        }
    }
    let tail = chunks
        .remainder()
        .iter()
        .fold(0.0_f64, |m, x| bigger(m, x.abs()));
    acc.iter().fold(tail, |m, a| bigger(m, *a))
}

// ---------------------------------------------------------------------------------------------
// One function segment
// ---------------------------------------------------------------------------------------------

/// The parameters of the fairing of one function segment.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct SegmentParams {
    /// Damping `λ_c` of coarse case 1.
    ///
    /// Default value: [`DEFAULT_LAMBDA_COARSE`] (0.8).
    pub lambda_coarse: f64,
    /// Weight `λ_f` of the outer points in the fine cases.
    ///
    /// Default value: [`DEFAULT_LAMBDA_FINE`] (0.75).
    pub lambda_fine: f64,
    /// Factor of the α rule of the fine cases.
    ///
    /// Default value: [`DEFAULT_ALPHA_FACTOR`] (0.2).
    pub alpha_factor: f64,
    /// Also run fine case 3 ([`Segment::fine_case3`]) after fine case 2 in every iteration:
    /// an extension, not in the paper, for runs of three points of one sign of c, which
    /// neither fine case removes.
    ///
    /// Default value: false here (the paper's method); the `han` method turns it on.
    pub fine_run3: bool,
}

impl SegmentParams {
    /// The paper's values.
    pub const DEFAULT: SegmentParams = SegmentParams {
        lambda_coarse: DEFAULT_LAMBDA_COARSE,
        lambda_fine: DEFAULT_LAMBDA_FINE,
        alpha_factor: DEFAULT_ALPHA_FACTOR,
        fine_run3: false,
    };

    /// Set `λ_c`.
    pub fn with_lambda_coarse(mut self, v: f64) -> SegmentParams {
        self.lambda_coarse = v;
        self
    }

    /// Set `λ_f`.
    pub fn with_lambda_fine(mut self, v: f64) -> SegmentParams {
        self.lambda_fine = v;
        self
    }

    /// Set the α factor.
    pub fn with_alpha_factor(mut self, v: f64) -> SegmentParams {
        self.alpha_factor = v;
        self
    }

    /// Run fine case 3 too (see [`SegmentParams::fine_run3`]).
    pub fn with_fine_run3(mut self, on: bool) -> SegmentParams {
        self.fine_run3 = on;
        self
    }

    fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("lambda_coarse", self.lambda_coarse),
            ("lambda_fine", self.lambda_fine),
            ("alpha_factor", self.alpha_factor),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(Error::InvalidParameter {
                    name: name.into(),
                    reason: format!("{v} is outside [0, 1]"),
                });
            }
        }
        Ok(())
    }
}

impl Default for SegmentParams {
    fn default() -> SegmentParams {
        SegmentParams::DEFAULT
    }
}

/// The rule that made a move (the spec's tags, §7).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MoveTag {
    /// Coarse case 1, small vibration: `y_i += λ_c σ`, `y_{i+1} −= λ_c σ`.
    C1,
    /// Coarse case 2, medium vibration: `e_i` set to 0 by moving `y_i`.
    C2,
    /// Coarse case 2 end rule (i = 2 or n−1, 1-based).
    C2End,
    /// Coarse case 3, large vibration: `e_i = e_{i+1} = 0` by moving `y_i`, `y_{i+1}`.
    C3,
    /// Coarse case 3 end rule.
    C3End,
    /// Fine case 1, isolated sign of `c_i`; made once with α = 0 and possibly again.
    F1,
    /// Fine case 2, two-point inflection pair.
    F2,
    /// Fine case 2 end rule: `c_1 = c_2` (or `c_{n−1} = c_n`) set to 0.
    F2End,
    /// Fine case 3 (an extension, not in the paper): a three-point run of one sign of c.
    F3,
}

impl MoveTag {
    /// The tag as written in the test vectors: `C1`, `C2`, `C2end`, `C3`, `C3end`, `F1`,
    /// `F2`, `F2end`.
    pub fn as_str(self) -> &'static str {
        match self {
            MoveTag::C1 => "C1",
            MoveTag::C2 => "C2",
            MoveTag::C2End => "C2end",
            MoveTag::C3 => "C3",
            MoveTag::C3End => "C3end",
            MoveTag::F1 => "F1",
            MoveTag::F2 => "F2",
            MoveTag::F2End => "F2end",
            MoveTag::F3 => "F3",
        }
    }

    /// True for the fine-phase tags (they target `c`), false for the coarse ones (`e`).
    pub fn is_fine(self) -> bool {
        matches!(
            self,
            MoveTag::F1 | MoveTag::F2 | MoveTag::F2End | MoveTag::F3
        )
    }
}

/// One move of a segment: consecutive points `start..start+len` displaced in y.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CaseMove {
    /// The rule.
    pub tag: MoveTag,
    /// The point the rule was tested at (0-based): i of the case, 1 or n−2 for end rules.
    pub i: usize,
    /// The first displaced point (0-based).
    pub start: usize,
    len: usize,
    gammas: [f64; 5],
    /// The targeted indicator at `i` before the move: `e_i` for coarse rules, `c_i` for fine.
    pub before: f64,
    /// The same value after the move.
    pub after: f64,
    /// Fraction of the proposed move that was applied: 1, or less when the tolerance bounds
    /// cut it back.
    pub scale: f64,
}

impl CaseMove {
    /// The applied displacements of points `start, start+1, …`.
    pub fn gammas(&self) -> &[f64] {
        &self.gammas[..self.len]
    }

    /// The displaced points.
    pub fn points(&self) -> Range<usize> {
        self.start..self.start + self.len
    }

    /// The displacement of point `p`, if this move displaced it.
    pub fn gamma_at(&self, p: usize) -> Option<f64> {
        self.points()
            .contains(&p)
            .then(|| self.gammas[p - self.start])
    }

    /// Largest |γ|.
    pub fn max_abs(&self) -> f64 {
        self.gammas().iter().fold(0.0, |m, g| m.max(g.abs()))
    }
}

/// The five case procedures of one iteration, in the spec's order (§1.7.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Procedure {
    /// Coarse case 1 ([`Segment::coarse_case1`]).
    CoarseCase1,
    /// Coarse case 2 with its end rules ([`Segment::coarse_case2`]).
    CoarseCase2,
    /// Coarse case 3 with its end rules ([`Segment::coarse_case3`]).
    CoarseCase3,
    /// Fine case 1 ([`Segment::fine_case1`]).
    FineCase1,
    /// Fine case 2 with its end rules ([`Segment::fine_case2`]).
    FineCase2,
    /// Fine case 3 ([`Segment::fine_case3`]), an extension run after fine case 2 when
    /// [`SegmentParams::fine_run3`] is set.
    FineCase3,
}

impl Procedure {
    /// One iteration: phase 1 (cases 1, 2, 3), then phase 2 (cases 1, 2).
    pub const ITERATION: [Procedure; 5] = [
        Procedure::CoarseCase1,
        Procedure::CoarseCase2,
        Procedure::CoarseCase3,
        Procedure::FineCase1,
        Procedure::FineCase2,
    ];
}

/// A function segment `(x_i, y_i)`, i = 1..n, being faired by HAN's two phases (spec §1.7).
///
/// It holds y, the spline coefficients c, the indicator e and the unit responses, and keeps
/// c and e exact after every move (eq 13, see the module docs). Only `y_2..y_{n−1}` move; the
/// x values and the end values never change. Indices are 0-based (point k is the paper's
/// k + 1).
///
/// ```
/// use batten::fair::han::Segment;
///
/// let x: Vec<f64> = (0..30).map(|i| i as f64 * 0.4).collect();
/// let y: Vec<f64> = x.iter().enumerate()
///     .map(|(i, v)| (v / 2.0).sin() + if i % 2 == 0 { 0.02 } else { -0.02 })
///     .collect();
/// let mut seg = Segment::new(x, y).unwrap();
/// let before = seg.inflection_count();
/// seg.fair(10, |_| {});
/// assert!(seg.inflection_count() < before);
/// ```
#[derive(Clone, Debug)]
pub struct Segment {
    x: Vec<f64>,
    y: Vec<f64>,
    c: Vec<f64>,
    e: Vec<f64>,
    resp: UnitResponses,
    c_scale: SignScale,
    e_scale: SignScale,
    /// Rounding-noise floors of c and e per point ([`ROUNDING_FLOOR_FACTOR`]).
    c_floor: Vec<f64>,
    e_floor: Vec<f64>,
    params: SegmentParams,
    bounds: Option<(Vec<f64>, Vec<f64>)>,
    limited: bool,
    /// Refuse moves that give the points more inflections or a higher variation energy near
    /// them (the per-move clean-curve check, [`Segment::with_keep_clean`]).
    keep_clean: bool,
    /// Moves refused by that check.
    refused: usize,
}

impl Segment {
    /// A segment through `(x[k], y[k])` with the default parameters and no bounds.
    ///
    /// # Errors
    /// [`Error::TooFewPoints`] below [`MIN_SEGMENT_POINTS`], and the errors of
    /// [`CubicSplineFn::try_new`] (length mismatch, NaN, x not strictly increasing).
    pub fn new(x: Vec<f64>, y: Vec<f64>) -> Result<Segment> {
        if x.len() < MIN_SEGMENT_POINTS {
            return Err(Error::TooFewPoints {
                needed: MIN_SEGMENT_POINTS,
                got: x.len(),
            });
        }
        let spline = CubicSplineFn::try_new(x, y, FnEndCondition::Han)?;
        let resp = UnitResponses::from_spline(&spline)?;
        let n = spline.len();
        let mut c = spline.c().to_vec();
        // The end condition holds exactly, so that the end tests are exact too.
        c[n - 1] = c[n - 2];
        let mut seg = Segment {
            x: spline.x().to_vec(),
            y: spline.y().to_vec(),
            e: vec![0.0; n],
            c_scale: SignScale::new(&c),
            e_scale: SignScale::new(&[]),
            c_floor: Vec::new(),
            e_floor: Vec::new(),
            c,
            resp,
            params: SegmentParams::DEFAULT,
            bounds: None,
            limited: false,
            keep_clean: false,
            refused: 0,
        };
        seg.refresh_e(1, n - 2);
        seg.e_scale = SignScale::new(&seg.e);
        seg.set_floors(0.0);
        Ok(seg)
    }

    /// Refuse (`true`) or allow (`false`, the default) moves that give the polyline's
    /// chord-length cubic more inflections or a higher variation energy `∫(dκ/ds)² ds`
    /// near them. The check is local (a few points either side of a move) and, the cubic
    /// being invariant under rigid motion, the same in the segment's frame as in the
    /// plane. `Han` turns it on unless [`FairOptions::keep_clean`] is false.
    pub fn with_keep_clean(mut self, keep: bool) -> Segment {
        self.keep_clean = keep;
        self
    }

    /// Moves refused by the clean-curve check so far.
    pub fn refused_moves(&self) -> usize {
        self.refused
    }

    /// Declare that the points carry the rounding of coordinates of magnitude up to
    /// `magnitude` (e.g. those of the whole curve, before the segment was moved into its
    /// frame), not only of their own: the rounding-noise floors of the sign tests
    /// ([`ROUNDING_FLOOR_FACTOR`]) are raised accordingly. A non-finite or negative value is
    /// ignored.
    pub fn with_coordinate_scale(mut self, magnitude: f64) -> Segment {
        if magnitude.is_finite() && magnitude > 0.0 {
            self.set_floors(magnitude);
        }
        self
    }

    /// The rounding-noise floors `F·ε·R/h²` of c and `4F·ε·R/h³` of e at each point, with R
    /// the larger of `magnitude` and the segment's own largest coordinate, and h the shorter
    /// of the point's two chords (\[CHOICE\], see [`ROUNDING_FLOOR_FACTOR`]).
    fn set_floors(&mut self, magnitude: f64) {
        let n = self.len();
        let own = self
            .x
            .iter()
            .chain(&self.y)
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        let scale = ROUNDING_FLOOR_FACTOR * f64::EPSILON * own.max(magnitude);
        self.c_floor = Vec::with_capacity(n);
        self.e_floor = Vec::with_capacity(n);
        for i in 0..n {
            let left = if i > 0 {
                self.x[i] - self.x[i - 1]
            } else {
                f64::INFINITY
            };
            let right = if i + 1 < n {
                self.x[i + 1] - self.x[i]
            } else {
                f64::INFINITY
            };
            let h = left.min(right);
            let c = scale / (h * h);
            self.c_floor.push(c);
            self.e_floor.push(4.0 * c / h);
        }
    }

    /// Use other parameters.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when a parameter is outside [0, 1] or NaN.
    pub fn with_params(mut self, params: SegmentParams) -> Result<Segment> {
        params.validate()?;
        self.params = params;
        Ok(self)
    }

    /// Bound every point: `lo[k] ≤ y[k] ≤ hi[k]` must hold after every move. A move that would
    /// leave the bounds is scaled back as a whole ([`CaseMove::scale`]).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`]; [`Error::InvalidParameter`] when the current y is outside
    /// its bounds (or a bound is NaN).
    pub fn with_bounds(mut self, lo: Vec<f64>, hi: Vec<f64>) -> Result<Segment> {
        let n = self.len();
        for (what, v) in [("lower bounds", &lo), ("upper bounds", &hi)] {
            if v.len() != n {
                return Err(Error::LengthMismatch {
                    what,
                    got: v.len(),
                    expected: n,
                });
            }
        }
        if let Some(k) = (0..n).find(|&k| !(lo[k] <= self.y[k] && self.y[k] <= hi[k])) {
            return Err(Error::InvalidParameter {
                name: "bounds".into(),
                reason: format!("y[{k}] = {} is outside [{}, {}]", self.y[k], lo[k], hi[k]),
            });
        }
        self.bounds = Some((lo, hi));
        Ok(self)
    }

    /// Number of points n.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Always false (n ≥ 5).
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// The abscissae.
    pub fn x(&self) -> &[f64] {
        &self.x
    }

    /// The current ordinates.
    pub fn y(&self) -> &[f64] {
        &self.y
    }

    /// The current `c_i = y''(x_i)/6` (the x–c plot).
    pub fn c(&self) -> &[f64] {
        &self.c
    }

    /// The current indicator `e` (`e_1 = e_n = 0`).
    pub fn e(&self) -> &[f64] {
        &self.e
    }

    /// The unit responses of the segment's abscissae.
    pub fn responses(&self) -> &UnitResponses {
        &self.resp
    }

    /// The rounding-noise floor of each `c_i` ([`ROUNDING_FLOOR_FACTOR`]).
    pub fn c_floor(&self) -> &[f64] {
        &self.c_floor
    }

    /// The rounding-noise floor of each `e_i` ([`ROUNDING_FLOOR_FACTOR`]).
    pub fn e_floor(&self) -> &[f64] {
        &self.e_floor
    }

    /// The parameters in use.
    pub fn params(&self) -> SegmentParams {
        self.params
    }

    /// True when some move was scaled back by the bounds.
    pub fn was_limited(&self) -> bool {
        self.limited
    }

    /// HAN's `Infl_num = #{i : c_i c_{i+1} < 0}` with the zero tolerance of §1.7.0.
    pub fn inflection_count(&self) -> usize {
        count_strict_changes(&self.c, &self.c_floor, abs_max(&self.c))
    }

    /// HAN's `Vib_num = #{i : e_i e_{i+1} < 0}` with the zero tolerance of §1.7.0.
    pub fn vibration_count(&self) -> usize {
        count_strict_changes(&self.e, &self.e_floor, abs_max(&self.e))
    }

    /// Run `iterations` iterations of [`Procedure::ITERATION`], calling `on_move` for every
    /// move. Stops early when an iteration makes no move (the state is then a fixed point).
    /// Returns the number of iterations that made at least one move.
    pub fn fair(&mut self, iterations: usize, mut on_move: impl FnMut(&CaseMove)) -> usize {
        let mut active = 0;
        for _ in 0..iterations {
            let mut moved = false;
            for p in Procedure::ITERATION {
                self.run_procedure(p, &mut |m: &CaseMove| {
                    moved = true;
                    on_move(m);
                });
            }
            if self.params.fine_run3 {
                self.run_procedure(Procedure::FineCase3, &mut |m: &CaseMove| {
                    moved = true;
                    on_move(m);
                });
            }
            if !moved {
                break;
            }
            active += 1;
        }
        active
    }

    /// Run one case procedure over the segment, calling `on_move` for every move.
    pub fn run_procedure(&mut self, p: Procedure, on_move: &mut impl FnMut(&CaseMove)) {
        match p {
            Procedure::CoarseCase1 => self.coarse_case1_with(on_move),
            Procedure::CoarseCase2 => self.coarse_case2_with(on_move),
            Procedure::CoarseCase3 => self.coarse_case3_with(on_move),
            Procedure::FineCase1 => self.fine_case1_with(on_move),
            Procedure::FineCase2 => self.fine_case2_with(on_move),
            Procedure::FineCase3 => self.fine_case3_with(on_move),
        }
    }

    /// Move the consecutive interior points `start..start+gammas.len()` (one to five of them, as many as a case move
    /// displaces)
    /// by `gammas`, with c and e updated exactly by eq 13 as after a case move, and the bounds
    /// applied the same way. Returns the fraction of the move that was applied (0 when the
    /// bounds or the resolution of y left nothing to do).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when a moved point is not interior or there are not one to
    /// five displacements; [`Error::NonFinite`] for a non-finite displacement.
    pub fn displace(&mut self, start: usize, gammas: &[f64]) -> Result<f64> {
        if gammas.is_empty() || gammas.len() > 5 || start == 0 || start + gammas.len() >= self.len()
        {
            return Err(Error::InvalidParameter {
                name: "displace".into(),
                reason: format!(
                    "points {start}..{} are not 1 to 5 interior points of {}",
                    start + gammas.len(),
                    self.len()
                ),
            });
        }
        if let Some(index) = gammas.iter().position(|g| !g.is_finite()) {
            return Err(Error::NonFinite { index });
        }
        Ok(self
            .move_points(start, gammas)
            .map_or(0.0, |(scale, _)| scale))
    }

    /// Coarse case 1 (small vibration, spec §1.7.1): for i = 2..n−2 (1-based) with
    /// `e_i e_{i+1} < 0`, move `y_i += λ_c σ`, `y_{i+1} −= λ_c σ` with σ the smaller root of
    /// `ẽ_i ẽ_{i+1} = 0`. Returns the moves.
    pub fn coarse_case1(&mut self) -> Vec<CaseMove> {
        self.collect(Procedure::CoarseCase1)
    }

    /// Coarse case 2 (medium vibration, §1.7.1): `e_i` of the other sign than both neighbours
    /// is set to 0 by moving `y_i`, i = 3..n−2; then the end rules at i = 2 and n−1.
    pub fn coarse_case2(&mut self) -> Vec<CaseMove> {
        self.collect(Procedure::CoarseCase2)
    }

    /// Coarse case 3 (large vibration, §1.7.1): a same-sign pair `e_i, e_{i+1}` between two
    /// opposite neighbours on each side is set to 0 by moving `y_i, y_{i+1}`; then the end
    /// rules (n ≥ 6).
    pub fn coarse_case3(&mut self) -> Vec<CaseMove> {
        self.collect(Procedure::CoarseCase3)
    }

    /// Fine case 1 (§1.7.2): `c_i` of the other sign than both neighbours is set to 0, then, if
    /// the neighbours kept their signs, to α.
    pub fn fine_case1(&mut self) -> Vec<CaseMove> {
        self.collect(Procedure::FineCase1)
    }

    /// Fine case 2 (§1.7.2): a same-sign pair `c_i, c_{i+1}` with opposite `c_{i−1}`,
    /// `c_{i+2}`, `c_{i+3}` is set to 0 (then α); then the end rules.
    pub fn fine_case2(&mut self) -> Vec<CaseMove> {
        self.collect(Procedure::FineCase2)
    }

    /// Fine case 3, an extension not in the paper ([`SegmentParams::fine_run3`]): a run
    /// `c_i, c_{i+1}, c_{i+2}` of one sign between `c_{i−1}` and `c_{i+3}, c_{i+4}` of the other
    /// is set to 0 (then α) by moving `y_{i−1}..y_{i+3}`, the outer two by `−λ_f` times their
    /// neighbours, as fine case 2 does for a pair.
    pub fn fine_case3(&mut self) -> Vec<CaseMove> {
        self.collect(Procedure::FineCase3)
    }

    fn collect(&mut self, p: Procedure) -> Vec<CaseMove> {
        let mut moves = Vec::new();
        self.run_procedure(p, &mut |m: &CaseMove| moves.push(*m));
        moves
    }

    // --- sign tests --------------------------------------------------------------------------

    #[inline]
    fn e_sign(&mut self, i: usize) -> i8 {
        self.e_scale.sign(&self.e, &self.e_floor, i)
    }

    #[inline]
    fn c_sign(&mut self, i: usize) -> i8 {
        self.c_scale.sign(&self.c, &self.c_floor, i)
    }

    /// `sgn0(u)·sgn0(v) < 0` on e.
    #[inline]
    fn e_opp(&mut self, i: usize, k: usize) -> bool {
        self.e_sign(i) * self.e_sign(k) < 0
    }

    /// `sgn0(u)·sgn0(v) > 0` on e.
    #[inline]
    fn e_same(&mut self, i: usize, k: usize) -> bool {
        self.e_sign(i) * self.e_sign(k) > 0
    }

    #[inline]
    fn c_opp(&mut self, i: usize, k: usize) -> bool {
        self.c_sign(i) * self.c_sign(k) < 0
    }

    #[inline]
    fn c_same(&mut self, i: usize, k: usize) -> bool {
        self.c_sign(i) * self.c_sign(k) > 0
    }

    /// The α rule: a fraction of whichever neighbour value has the smaller magnitude (left on
    /// a tie).
    fn alpha(&self, left: usize, right: usize) -> f64 {
        let v = if self.c[right].abs() < self.c[left].abs() {
            self.c[right]
        } else {
            self.c[left]
        };
        self.params.alpha_factor * v
    }

    // --- the procedures ----------------------------------------------------------------------

    fn coarse_case1_with(&mut self, on_move: &mut impl FnMut(&CaseMove)) {
        let n = self.len();
        let lc = self.params.lambda_coarse;
        for i in 1..=n - 3 {
            if !self.e_opp(i, i + 1) {
                continue;
            }
            let r = &self.resp;
            let p = r.e_at(i, i) - r.e_at(i, i + 1);
            let q = r.e_at(i + 1, i) - r.e_at(i + 1, i + 1);
            let s1 = -self.e[i] / p;
            let s2 = -self.e[i + 1] / q;
            let sigma = if s1.abs() <= s2.abs() { s1 } else { s2 };
            self.apply(MoveTag::C1, i, i, &[lc * sigma, -lc * sigma], on_move);
        }
    }

    fn coarse_case2_with(&mut self, on_move: &mut impl FnMut(&CaseMove)) {
        let n = self.len();
        for i in 2..=n - 3 {
            if self.e_opp(i, i - 1) && self.e_opp(i, i + 1) {
                let g = -self.e[i] / self.resp.e_at(i, i);
                self.apply(MoveTag::C2, i, i, &[g], on_move);
            }
        }
        // End rules: the isolated sign has two neighbours on the only available side.
        if self.e_opp(1, 2) && self.e_opp(1, 3) {
            let g = -self.e[1] / self.resp.e_at(1, 1);
            self.apply(MoveTag::C2End, 1, 1, &[g], on_move);
        }
        let m = n - 2;
        if self.e_opp(m, m - 1) && self.e_opp(m, m - 2) {
            let g = -self.e[m] / self.resp.e_at(m, m);
            self.apply(MoveTag::C2End, m, m, &[g], on_move);
        }
    }

    /// Solve `ẽ_i = ẽ_k = 0` for the moves of points i and k.
    fn zero_two_e(&self, i: usize, k: usize) -> Option<(f64, f64)> {
        let r = &self.resp;
        solve2(
            r.e_at(i, i),
            r.e_at(i, k),
            r.e_at(k, i),
            r.e_at(k, k),
            -self.e[i],
            -self.e[k],
        )
    }

    fn coarse_case3_with(&mut self, on_move: &mut impl FnMut(&CaseMove)) {
        let n = self.len();
        if n < 6 {
            return;
        }
        for i in 2..=n - 4 {
            let fires = self.e_same(i, i + 1)
                && self.e_opp(i, i - 1)
                && self.e_opp(i, i + 2)
                && self.e_opp(i, i - 2)
                && self.e_opp(i, i + 3);
            if fires && let Some((s, t)) = self.zero_two_e(i, i + 1) {
                self.apply(MoveTag::C3, i, i, &[s, t], on_move);
            }
        }
        if self.e_same(1, 2)
            && self.e_opp(1, 3)
            && self.e_opp(1, 4)
            && let Some((s, t)) = self.zero_two_e(1, 2)
        {
            self.apply(MoveTag::C3End, 1, 1, &[s, t], on_move);
        }
        let m = n - 2;
        if self.e_same(m, m - 1)
            && self.e_opp(m, m - 2)
            && self.e_opp(m, m - 3)
            && let Some((s, t)) = self.zero_two_e(m, m - 1)
        {
            self.apply(MoveTag::C3End, m, m - 1, &[t, s], on_move);
        }
    }

    fn fine_case1_with(&mut self, on_move: &mut impl FnMut(&CaseMove)) {
        let n = self.len();
        let lf = self.params.lambda_fine;
        // i = 2 and n−1 (1-based) never fire: c_1 = c_2 and c_{n−1} = c_n hold exactly.
        for i in 2..=n - 3 {
            if !(self.c_opp(i, i - 1) && self.c_opp(i, i + 1)) {
                continue;
            }
            let (sl, sr) = (self.c_sign(i - 1), self.c_sign(i + 1));
            let r = &self.resp;
            let k = r.c_at(i, i) - lf * (r.c_at(i, i - 1) + r.c_at(i, i + 1));
            let sigma = -self.c[i] / k;
            self.apply(
                MoveTag::F1,
                i,
                i - 1,
                &[-lf * sigma, sigma, -lf * sigma],
                on_move,
            );
            if self.c_sign(i - 1) == sl && self.c_sign(i + 1) == sr {
                let sigma = (self.alpha(i - 1, i + 1) - self.c[i]) / k;
                self.apply(
                    MoveTag::F1,
                    i,
                    i - 1,
                    &[-lf * sigma, sigma, -lf * sigma],
                    on_move,
                );
            }
        }
    }

    /// Solve fine case 2's system `c̃_i = c̃_{i+1} = α` for (σ, τ).
    fn fine_pair(&self, i: usize, alpha: f64) -> Option<(f64, f64)> {
        let lf = self.params.lambda_fine;
        let r = &self.resp;
        solve2(
            r.c_at(i, i) - lf * r.c_at(i, i - 1),
            r.c_at(i, i + 1) - lf * r.c_at(i, i + 2),
            r.c_at(i + 1, i) - lf * r.c_at(i + 1, i - 1),
            r.c_at(i + 1, i + 1) - lf * r.c_at(i + 1, i + 2),
            alpha - self.c[i],
            alpha - self.c[i + 1],
        )
    }

    fn fine_case2_with(&mut self, on_move: &mut impl FnMut(&CaseMove)) {
        let n = self.len();
        let lf = self.params.lambda_fine;
        // i = 2 (1-based) never fires (c_1 = c_2) and would move the end point.
        for i in 2..=n.saturating_sub(4) {
            let fires = self.c_same(i, i + 1)
                && self.c_opp(i, i - 1)
                && self.c_opp(i, i + 2)
                && self.c_opp(i, i + 3);
            if !fires {
                continue;
            }
            let (sl, sr) = (self.c_sign(i - 1), self.c_sign(i + 2));
            let Some((s, t)) = self.fine_pair(i, 0.0) else {
                continue;
            };
            self.apply(MoveTag::F2, i, i - 1, &[-lf * s, s, t, -lf * t], on_move);
            if self.c_sign(i - 1) == sl
                && self.c_sign(i + 2) == sr
                && let Some((s, t)) = self.fine_pair(i, self.alpha(i - 1, i + 2))
            {
                self.apply(MoveTag::F2, i, i - 1, &[-lf * s, s, t, -lf * t], on_move);
            }
        }
        if self.c_opp(0, 2) && self.c_opp(0, 3) {
            let g = -self.c[1] / self.resp.c_at(1, 1);
            self.apply(MoveTag::F2End, 1, 1, &[g], on_move);
        }
        let m = n - 1;
        if self.c_opp(m, m - 2) && self.c_opp(m, m - 3) {
            let g = -self.c[m - 1] / self.resp.c_at(m - 1, m - 1);
            self.apply(MoveTag::F2End, m - 1, m - 1, &[g], on_move);
        }
    }

    /// Fine case 3 (extension): unknowns `γ_{i−1} = −λ_f σ, γ_i = σ, γ_{i+1} = τ, γ_{i+2} = ρ,
    /// γ_{i+3} = −λ_f ρ`, solved for `c_i = c_{i+1} = c_{i+2} = α`; α = 0 first, then the α
    /// rule from `c_{i−1}, c_{i+3}` if both kept their signs, as in fine case 2.
    fn fine_case3_with(&mut self, on_move: &mut impl FnMut(&CaseMove)) {
        let n = self.len();
        let lf = self.params.lambda_fine;
        if n < 8 {
            return;
        }
        for i in 2..=n - 6 {
            // The most selective tests first (on smooth stretches neighbours share a sign).
            let fires = self.c_opp(i, i - 1)
                && self.c_opp(i, i + 3)
                && self.c_same(i, i + 1)
                && self.c_same(i, i + 2)
                && self.c_opp(i, i + 4);
            if !fires {
                continue;
            }
            let (sl, sr) = (self.c_sign(i - 1), self.c_sign(i + 3));
            for pass in 0..2 {
                let alpha = if pass == 0 {
                    0.0
                } else {
                    self.alpha(i - 1, i + 3)
                };
                let r = &self.resp;
                let m = nalgebra::Matrix3::from_fn(|row, col| {
                    let k = i + row;
                    match col {
                        0 => r.c_at(k, i) - lf * r.c_at(k, i - 1),
                        1 => r.c_at(k, i + 1),
                        _ => r.c_at(k, i + 2) - lf * r.c_at(k, i + 3),
                    }
                });
                let rhs = nalgebra::Vector3::new(
                    alpha - self.c[i],
                    alpha - self.c[i + 1],
                    alpha - self.c[i + 2],
                );
                let Some(sol) = m.lu().solve(&rhs) else {
                    break;
                };
                let (s, t, q) = (sol[0], sol[1], sol[2]);
                self.apply(MoveTag::F3, i, i - 1, &[-lf * s, s, t, q, -lf * q], on_move);
                if !(self.c_sign(i - 1) == sl && self.c_sign(i + 3) == sr) {
                    break;
                }
            }
        }
    }

    // --- applying a move ---------------------------------------------------------------------

    /// Move points `start..start+gammas.len()` by `gammas` (scaled back to the bounds), update
    /// c by eq 13 and e on the changed range, and report the move.
    fn apply(
        &mut self,
        tag: MoveTag,
        i: usize,
        start: usize,
        gammas: &[f64],
        on_move: &mut impl FnMut(&CaseMove),
    ) {
        let before = if tag.is_fine() { self.c[i] } else { self.e[i] };
        if let Some((scale, applied)) = self.move_points(start, gammas) {
            let after = if tag.is_fine() { self.c[i] } else { self.e[i] };
            let len = gammas.len();
            on_move(&CaseMove {
                tag,
                i,
                start,
                len,
                gammas: applied,
                before,
                after,
                scale,
            });
        }
    }

    /// Move points `start..start+gammas.len()` (interior, at most 5: fine case 3) by `gammas`, scaled back
    /// to the bounds, and update c (eq 13), e and their maxima on the changed range. Returns
    /// the scale and the applied displacements, or `None` when nothing moved.
    fn move_points(&mut self, start: usize, gammas: &[f64]) -> Option<(f64, [f64; 5])> {
        let len = gammas.len();
        if gammas.iter().any(|g| !g.is_finite()) || gammas.iter().all(|g| *g == 0.0) {
            return None;
        }
        let mut scale = 1.0_f64;
        if let Some((lo, hi)) = &self.bounds {
            for (k, &g) in gammas.iter().enumerate() {
                let p = start + k;
                if g > 0.0 {
                    scale = scale.min((hi[p] - self.y[p]) / g);
                } else if g < 0.0 {
                    scale = scale.min((lo[p] - self.y[p]) / g);
                }
            }
            scale = scale.max(0.0);
            if scale < 1.0 {
                self.limited = true;
            }
            if scale == 0.0 {
                return None;
            }
        }
        let mut targets = [0.0; 5];
        let mut applied = [0.0; 5];
        for (k, &g) in gammas.iter().enumerate() {
            let p = start + k;
            let mut target = self.y[p] + scale * g;
            if let Some((lo, hi)) = &self.bounds {
                target = target.clamp(lo[p], hi[p]);
            }
            targets[k] = target;
            applied[k] = target - self.y[p];
        }
        // A move below the resolution of y (e.g. one driven by rounding noise in c or e on
        // exactly fair data) changes nothing and is not made.
        if applied[..len].iter().all(|d| *d == 0.0) {
            return None;
        }
        if self.keep_clean {
            let moved: Vec<(usize, Point)> = (0..len)
                .map(|k| (start + k, Point::new(self.x[start + k], targets[k])))
                .collect();
            let (x, y) = (&self.x, &self.y);
            if super::clean::move_is_worse_by(x.len(), false, |i| Point::new(x[i], y[i]), &moved) {
                self.refused += 1;
                return None;
            }
        }
        self.y[start..start + len].copy_from_slice(&targets[..len]);
        let w = self.resp.add_columns(start, &applied[..len], &mut self.c);
        self.c_scale.wrote(&self.c, w);
        let (elo, ehi) = (
            w.lo.saturating_sub(1).max(1),
            (w.hi + 1).min(self.len() - 2),
        );
        let we = self.refresh_e(elo, ehi);
        self.e_scale.wrote(&self.e, we);
        Some((scale, applied))
    }

    /// Recompute `e_i = s_i − s_{i−1}`, `s_i = (c_{i+1} − c_i)/h_i`, from c for `lo..=hi`
    /// (interior indices); each slope is computed once. Returns what changed.
    fn refresh_e(&mut self, lo: usize, hi: usize) -> Changed {
        let c = &self.c[lo - 1..=hi + 1];
        let h = &self.resp.inv_h[lo - 1..=hi];
        let e = &mut self.e[lo..=hi];
        let mut prev = (c[1] - c[0]) * h[0];
        for (k, ek) in e.iter_mut().enumerate() {
            let next = (c[k + 2] - c[k + 1]) * h[k + 1];
            *ek = next - prev;
            prev = next;
        }
        Changed::of(&self.e, lo, hi)
    }
}

/// `#{i : sgn0(v_i)·sgn0(v_{i+1}) < 0}`, with values at or below their floor counted as 0.
fn count_strict_changes(v: &[f64], floor: &[f64], scale: f64) -> usize {
    let sign = |i: usize| {
        if v[i].abs() <= floor[i] {
            0
        } else {
            sgn0(v[i], scale)
        }
    };
    (1..v.len()).filter(|&i| sign(i - 1) * sign(i) < 0).count()
}

/// Solve `[a11 a12; a21 a22] (s, t) = (r1, r2)` by Cramer's rule, `None` when singular.
fn solve2(a11: f64, a12: f64, a21: f64, a22: f64, r1: f64, r2: f64) -> Option<(f64, f64)> {
    let det = a11 * a22 - a12 * a21;
    let size = (a11 * a22).abs() + (a12 * a21).abs();
    if !(det.is_finite() && det.abs() > SINGULAR_REL * size) {
        return None;
    }
    let s = (r1 * a22 - a12 * r2) / det;
    let t = (a11 * r2 - a21 * r1) / det;
    (s.is_finite() && t.is_finite()).then_some((s, t))
}

// ---------------------------------------------------------------------------------------------
// Partition of arbitrary curves (§1.8)
// ---------------------------------------------------------------------------------------------

/// A function segment of a point sequence: points `start..=end` (0-based, inclusive) and the
/// direction θ (radians) of its local x axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Span {
    /// First point.
    pub start: usize,
    /// Last point (inclusive).
    pub end: usize,
    /// Local x-axis direction: the bisector of the extreme chord directions.
    pub theta: f64,
}

impl Span {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.end + 1 - self.start
    }

    /// Always false: a span has at least two points.
    pub fn is_empty(&self) -> bool {
        self.end < self.start
    }
}

/// Chord directions `φ_i = atan2(P_{i+1} − P_i)`, i = 0..N−2.
///
/// # Errors
/// [`Error::NonFinite`], [`Error::DuplicatePoint`] (zero chord).
pub fn chord_angles(points: &[Point]) -> Result<Vec<f64>> {
    if let Some(index) = points.iter().position(|p| !p.is_finite()) {
        return Err(Error::NonFinite { index });
    }
    points
        .windows(2)
        .enumerate()
        .map(|(i, w)| {
            let d = w[1] - w[0];
            if d == Vec2::ZERO {
                Err(Error::DuplicatePoint { index: i + 1 })
            } else {
                Ok(d.atan2())
            }
        })
        .collect()
}

/// Unwrapped turning angles (spec §1.8 step 2, \[FIX\]): `α_0 = 0`,
/// `α_i = α_{i−1} + wrap(φ_i − φ_{i−1})` with wrap into (−π, π]; one per chord. `α_{N−2}` is
/// the total turning of the polyline.
///
/// # Errors
/// As [`chord_angles`].
pub fn turning_angles(points: &[Point]) -> Result<Vec<f64>> {
    let phi = chord_angles(points)?;
    Ok(unwrap_turning(&phi))
}

fn unwrap_turning(phi: &[f64]) -> Vec<f64> {
    let mut alpha = Vec::with_capacity(phi.len());
    let mut acc = 0.0;
    for (i, &p) in phi.iter().enumerate() {
        if i > 0 {
            acc += wrap_angle(p - phi[i - 1]);
        }
        alpha.push(acc);
    }
    alpha
}

/// Wrap into (−π, π].
fn wrap_angle(a: f64) -> f64 {
    let w = a - (a / std::f64::consts::TAU).round() * std::f64::consts::TAU;
    if w <= -PI {
        w + std::f64::consts::TAU
    } else {
        w
    }
}

/// Split a point sequence into overlapping function segments (spec §1.8 step 3): from b, the
/// first chord s whose inclusion makes `max α − min α > max_turn` ends the segment at
/// `P_{s−1}` (0-based: points `b..=s−1`); segments have at least `overlap + 2` points (capped
/// at the end); the next starts `overlap − 1` points before the end, so neighbours share
/// `overlap` points. Each span carries its bisector frame angle (step 4).
///
/// # Errors
/// [`Error::TooFewPoints`] for fewer than 2 points, [`Error::InvalidParameter`] for a
/// `max_turn` outside (0, π] or `overlap` = 0, and the errors of [`chord_angles`].
pub fn partition(points: &[Point], max_turn: f64, overlap: usize) -> Result<Vec<Span>> {
    if points.len() < 2 {
        return Err(Error::TooFewPoints {
            needed: 2,
            got: points.len(),
        });
    }
    check_max_turn(max_turn)?;
    if overlap == 0 {
        return Err(Error::InvalidParameter {
            name: "overlap".into(),
            reason: "segments must share at least one point".into(),
        });
    }
    let phi = chord_angles(points)?;
    let alpha = unwrap_turning(&phi);
    let n = points.len();
    let mut spans = Vec::new();
    let mut b = 0;
    loop {
        let (mut hi, mut lo) = (alpha[b], alpha[b]);
        let mut end = n - 1;
        for (s, &a) in alpha.iter().enumerate().take(n - 1).skip(b + 1) {
            hi = hi.max(a);
            lo = lo.min(a);
            if hi - lo > max_turn {
                end = s - 1;
                break;
            }
        }
        end = end.max(b + overlap + 1).min(n - 1);
        spans.push(Span {
            start: b,
            end,
            theta: frame_angle(&phi, &alpha, b, end),
        });
        if end == n - 1 {
            return Ok(spans);
        }
        b = end + 1 - overlap;
    }
}

/// θ = φ_a + (α_u + α_l)/2 − α_a over the chords a..end−1 (spec §1.8 step 4, \[FIX\]).
fn frame_angle(phi: &[f64], alpha: &[f64], a: usize, end: usize) -> f64 {
    let chords = &alpha[a..end];
    let (hi, lo) = chords
        .iter()
        .fold((f64::NEG_INFINITY, f64::INFINITY), |(h, l), &v| {
            (h.max(v), l.min(v))
        });
    phi[a] + (hi + lo) / 2.0 - alpha[a]
}

fn check_max_turn(max_turn: f64) -> Result<()> {
    if max_turn > 0.0 && max_turn <= PI {
        Ok(())
    } else {
        Err(Error::InvalidParameter {
            name: "max_turn".into(),
            reason: format!("{max_turn} is outside (0, π]"),
        })
    }
}

// ---------------------------------------------------------------------------------------------
// The method
// ---------------------------------------------------------------------------------------------

/// The `han` method: see the module documentation.
#[derive(Clone, Copy, Debug, Default)]
pub struct Han;

static PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "lambda_coarse",
        default: "0.8",
        doc: "damping λ_c of coarse case 1 (small vibrations), in [0, 1]",
    },
    ParamSpec {
        name: "lambda_fine",
        default: "0.75",
        doc: "weight λ_f of the outer points of the fine (inflection) moves, in [0, 1]",
    },
    ParamSpec {
        name: "overlap",
        default: "5",
        doc: "points shared by consecutive function segments (k), 1 to 1000000",
    },
    ParamSpec {
        name: "passes",
        default: "3",
        doc: "pipeline passes (partition, fair, blend)",
    },
    ParamSpec {
        name: "max_turn",
        default: "pi/2",
        doc: "turning range of a segment in radians, in (0, π]; accepts pi and pi/N; the \
              paper's value is pi; pi/2 (the spec's recommendation) keeps segments away from \
              vertical slopes",
    },
    ParamSpec {
        name: "fine_run3",
        default: "true",
        doc: "extension, not in the paper: also remove runs of three points of one sign of c \
              (fine case 3); false gives the paper's method",
    },
    ParamSpec {
        name: "alpha_factor",
        default: "0.2",
        doc: "fine phase target α = factor × the smaller-magnitude neighbour of c, in [0, 1]",
    },
];

/// Parameters of a run, parsed from the options.
#[derive(Clone, Copy, Debug)]
struct HanParams {
    segment: SegmentParams,
    overlap: usize,
    passes: usize,
    max_turn: f64,
    iterations: usize,
}

impl HanParams {
    fn from_options(o: &FairOptions) -> Result<HanParams> {
        let segment = SegmentParams::DEFAULT
            .with_lambda_coarse(o.param_f64_in("lambda_coarse", DEFAULT_LAMBDA_COARSE, 0.0, 1.0)?)
            .with_lambda_fine(o.param_f64_in("lambda_fine", DEFAULT_LAMBDA_FINE, 0.0, 1.0)?)
            .with_alpha_factor(o.param_f64_in("alpha_factor", DEFAULT_ALPHA_FACTOR, 0.0, 1.0)?);
        let segment = segment.with_fine_run3(o.param_bool("fine_run3", DEFAULT_FINE_RUN3)?);
        segment.validate()?;
        Ok(HanParams {
            segment,
            overlap: o.param_usize_in("overlap", DEFAULT_OVERLAP, 1, MAX_OVERLAP)?,
            passes: o.param_usize_in("passes", DEFAULT_PASSES, 1, 10_000)?,
            max_turn: param_angle(o, "max_turn", DEFAULT_MAX_TURN)?,
            iterations: o.iterations_or(DEFAULT_ITERATIONS),
        })
    }
}

/// An angle parameter: a number of radians, `pi`/`π`, or `pi/N`.
fn param_angle(o: &FairOptions, key: &str, default: f64) -> Result<f64> {
    let Some(text) = o.params.get(key) else {
        return Ok(default);
    };
    let t = text.trim().to_ascii_lowercase().replace('π', "pi");
    let bad = || Error::InvalidParameter {
        name: key.into(),
        reason: format!("'{text}' is not an angle (radians, pi or pi/N)"),
    };
    let v = if t == "pi" {
        PI
    } else if let Some(d) = t.strip_prefix("pi/") {
        PI / d.trim().parse::<f64>().map_err(|_| bad())?
    } else {
        t.parse::<f64>().map_err(|_| bad())?
    };
    check_max_turn(v)?;
    Ok(v)
}

/// Bookkeeping of a run.
#[derive(Debug, Default)]
struct RunLog {
    moves: Vec<Move>,
    total_moves: usize,
    limited: bool,
    skipped: Vec<(usize, usize)>,
    /// Segments that were too steep in their frame and were re-partitioned.
    refined: usize,
    /// Moves refused by the clean-curve check.
    refused: usize,
    /// The most iterations one segment ran in one pass with a move (at most T,
    /// `--max-iterations`): the report's `iterations`, in the unit the option bounds.
    iterations: usize,
}

impl RunLog {
    fn record(&mut self, pass: usize, index: usize, m: &CaseMove) {
        self.total_moves += 1;
        if m.scale < 1.0 {
            self.limited = true;
        }
        if self.moves.len() < MAX_RECORDED_MOVES {
            self.moves.push(Move {
                iteration: pass,
                index,
                distance: m.max_abs(),
                before: m.before,
                after: m.after,
            });
        }
    }

    /// Append the log of a later piece of work, keeping the first [`MAX_RECORDED_MOVES`]
    /// moves, as if it had been recorded here.
    fn append(&mut self, later: RunLog) {
        let room = MAX_RECORDED_MOVES.saturating_sub(self.moves.len());
        self.moves.extend(later.moves.into_iter().take(room));
        self.total_moves += later.total_moves;
        self.limited |= later.limited;
        self.skipped.extend(later.skipped);
        self.refined += later.refined;
        self.refused += later.refused;
        self.iterations = self.iterations.max(later.iterations);
    }
}

/// Maps a position in a sequence being faired to the caller's point index.
type IndexMap<'a> = &'a (dyn Fn(usize) -> usize + Sync);

/// Shared inputs of the passes.
struct PassCtx<'a> {
    params: &'a HanParams,
    tolerance: Option<f64>,
    pass: usize,
    /// The largest coordinate magnitude of the input (for the rounding-noise floors).
    coord: f64,
    /// Points of the (open) input held at each end by `--fix-ends` beyond the first and the
    /// last, which han never moves: 0, 1 (tangent) or 2 (curvature); and the point count.
    held: usize,
    points: usize,
    /// Refuse moves that make the curve worse near them ([`FairOptions::keep_clean`]).
    keep_clean: bool,
}

/// Fair one open sequence `cur` (whose input positions are `orig`) in place: partition with
/// the turning threshold `max_turn`, fair every segment from the same points, blend.
/// `index_of` maps a position in `cur` to the caller's point index. Returns the number of
/// moves.
fn open_pass(
    cur: &mut [Point],
    orig: &[Point],
    max_turn: f64,
    ctx: &PassCtx<'_>,
    index_of: IndexMap<'_>,
    log: &mut RunLog,
) -> Result<usize> {
    if cur.len() < MIN_SEGMENT_POINTS {
        return Ok(0);
    }
    let spans = partition(cur, max_turn, ctx.params.overlap)?;
    // The segments of a pass are faired independently from the same points, so in parallel;
    // blending and the logs then follow the curve's order, so the result does not depend on
    // the number of threads.
    let results: Vec<Result<(Vec<Point>, usize, RunLog)>> = spans
        .par_iter()
        .map(|span| {
            let range = span.start..span.end + 1;
            let sub_index = |m: usize| index_of(span.start + m);
            let mut sub_log = RunLog::default();
            let (pts, m) = fair_span(
                &cur[range.clone()],
                &orig[range],
                span,
                max_turn,
                ctx,
                &sub_index,
                &mut sub_log,
            )?;
            Ok((pts, m, sub_log))
        })
        .collect();
    let mut out = cur.to_vec();
    let mut moves = 0;
    let mut covered_to: Option<usize> = None;
    for (span, result) in spans.iter().zip(results) {
        let (faired, m, sub_log) = result?;
        log.append(sub_log);
        moves += m;
        // Blend the points shared with what is already there (spec §1.8.6): w_q = q/(K+1).
        let shared = covered_to.map_or(0, |c| (c + 1).saturating_sub(span.start));
        for (q, p) in faired.iter().enumerate() {
            let idx = span.start + q;
            out[idx] = if q < shared {
                let w = (q + 1) as f64 / (shared + 1) as f64;
                out[idx].lerp(*p, w)
            } else {
                *p
            };
        }
        covered_to = Some(span.end);
    }
    cur.copy_from_slice(&out);
    Ok(moves)
}

/// Fair the points of one span (partitioned with `max_turn`) in its local frame; returns the
/// new points and the number of moves. `index_of` maps a position in the span to the caller's
/// point index. A span that is not a function in its frame, or too steep there, is
/// re-partitioned with half the threshold (down to [`MIN_FALLBACK_TURN`]) and otherwise left
/// unchanged, as are spans that are too short.
fn fair_span(
    pts: &[Point],
    orig: &[Point],
    span: &Span,
    max_turn: f64,
    ctx: &PassCtx<'_>,
    index_of: IndexMap<'_>,
    log: &mut RunLog,
) -> Result<(Vec<Point>, usize)> {
    if pts.len() < MIN_SEGMENT_POINTS {
        return Ok((pts.to_vec(), 0));
    }
    let origin = pts[0];
    let u = Vec2::from_angle(span.theta);
    let v = u.perp();
    let xs: Vec<f64> = pts.iter().map(|p| (*p - origin).dot(u)).collect();
    let ys: Vec<f64> = pts.iter().map(|p| (*p - origin).dot(v)).collect();
    let too_steep = xs
        .windows(2)
        .zip(ys.windows(2))
        .any(|(x, y)| !(x[1] > x[0] && (y[1] - y[0]).abs() <= MAX_LOCAL_SLOPE * (x[1] - x[0])));
    if too_steep {
        let half = max_turn / 2.0;
        if half >= MIN_FALLBACK_TURN && pts.len() > ctx.params.overlap + 2 {
            // Dense sampling puts the end chords of a segment that turns by almost max_turn
            // close to ±max_turn/2 in its frame: with the paper's π, nearly vertical. Halving
            // the threshold brings them down to ±π/4.
            log.refined += 1;
            let mut sub = pts.to_vec();
            let moves = open_pass(&mut sub, orig, half, ctx, index_of, log)?;
            return Ok((sub, moves));
        }
        log.skipped.push((index_of(0), index_of(pts.len() - 1)));
        return Ok((pts.to_vec(), 0));
    }
    let mut seg = Segment::new(xs.clone(), ys.clone())?
        .with_params(ctx.params.segment)?
        .with_coordinate_scale(ctx.coord)
        .with_keep_clean(ctx.keep_clean);
    // Points held by --fix-ends (the second and third at each end of the curve).
    let held = |k: usize| {
        let g = index_of(k);
        ctx.held > 0 && (g <= ctx.held || g + 1 + ctx.held >= ctx.points)
    };
    let any_held = ctx.held > 0 && (0..pts.len()).any(held);
    if ctx.tolerance.is_some() || any_held {
        // Moving along v keeps X; the point stays within d of its input position o while
        // (Y − o_y)² ≤ d² − (X − o_x)².
        let mut lo = Vec::with_capacity(pts.len());
        let mut hi = Vec::with_capacity(pts.len());
        for (k, o) in orig.iter().enumerate() {
            if held(k) {
                lo.push(ys[k]);
                hi.push(ys[k]);
                continue;
            }
            let Some(d) = ctx.tolerance else {
                lo.push(f64::NEG_INFINITY);
                hi.push(f64::INFINITY);
                continue;
            };
            let (ox, oy) = ((*o - origin).dot(u), (*o - origin).dot(v));
            let dx = xs[k] - ox;
            let r = (d * d - dx * dx).max(0.0).sqrt();
            lo.push((oy - r).min(ys[k]));
            hi.push((oy + r).max(ys[k]));
        }
        seg = seg.with_bounds(lo, hi)?;
    }
    let mut moves = 0;
    let active = seg.fair(ctx.params.iterations, |m| {
        moves += 1;
        log.record(ctx.pass, index_of(m.i), m);
    });
    log.iterations = log.iterations.max(active);
    log.refused += seg.refused_moves();
    let faired = pts
        .iter()
        .zip(seg.y().iter().zip(&ys))
        .map(|(p, (yn, y0))| *p + v * (yn - y0));
    Ok((faired.collect(), moves))
}

/// The tolerance actually enforced: a hair below the one asked for, so that rounding in the
/// frame changes cannot exceed it. `coord` is the largest coordinate magnitude.
fn effective_tolerance(d: f64, coord: f64) -> f64 {
    (d * (1.0 - TOLERANCE_SAFETY_REL) - TOLERANCE_SAFETY_ULPS * f64::EPSILON * coord).max(0.0)
}

/// Sign changes of the turning direction of the polyline (discrete inflections), the measure
/// of the pass history.
fn discrete_inflections(pts: &[Point], closed: bool) -> usize {
    let n = pts.len();
    let turn = |i: usize| {
        let (a, b, c) = (pts[(i + n - 1) % n], pts[i], pts[(i + 1) % n]);
        (b - a).cross(c - b)
    };
    let t: Vec<f64> = if closed {
        (0..n).map(turn).collect()
    } else {
        (1..n - 1).map(turn).collect()
    };
    count_sign_changes(&t, closed)
}

impl FairMethod for Han {
    fn name(&self) -> &'static str {
        "han"
    }

    fn description(&self) -> &'static str {
        "Han et al.: explicit fairing indicator (x–c plot of a cubic spline function) with \
         closed-form local moves on overlapping function segments"
    }

    fn parameters(&self) -> &'static [ParamSpec] {
        PARAMS
    }

    fn supports_closed(&self) -> bool {
        true
    }

    fn check_params(&self, options: &FairOptions) -> Result<()> {
        HanParams::from_options(options).map(|_| ())
    }

    fn run(&self, input: &PointSeq, options: &FairOptions) -> Result<Outcome> {
        let params = HanParams::from_options(options)?;
        let orig = input.points();
        let n = orig.len();
        let closed = input.is_closed();
        let coord = max_abs_coordinate(orig);
        let tolerance = options.tolerance.map(|d| effective_tolerance(d, coord));
        let mut cur = orig.to_vec();
        let mut log = RunLog::default();
        let mut history = Vec::with_capacity(params.passes);
        let mut passes_done = 0;
        let mut last_pass_moves = 0;
        for pass in 0..params.passes {
            let ctx = PassCtx {
                params: &params,
                tolerance,
                pass: pass + 1,
                coord,
                held: if closed {
                    0
                } else {
                    options.fix_ends.held().saturating_sub(1)
                },
                points: n,
                keep_clean: options.keep_clean,
            };
            let moves = if closed {
                // Cut the cycle at a point that moves from pass to pass (see the module docs).
                let cut = pass * n / params.passes;
                let mut open: Vec<Point> = (0..=n).map(|m| cur[(cut + m) % n]).collect();
                let open_orig: Vec<Point> = (0..=n).map(|m| orig[(cut + m) % n]).collect();
                let index_of = move |m: usize| (cut + m) % n;
                let moves = open_pass(
                    &mut open,
                    &open_orig,
                    params.max_turn,
                    &ctx,
                    &index_of,
                    &mut log,
                )?;
                for (m, p) in open.iter().take(n).enumerate() {
                    cur[(cut + m) % n] = *p;
                }
                moves
            } else {
                open_pass(&mut cur, orig, params.max_turn, &ctx, &|m| m, &mut log)?
            };
            passes_done += 1;
            last_pass_moves = moves;
            let max_distance = orig
                .iter()
                .zip(&cur)
                .fold(0.0_f64, |m, (a, b)| m.max(a.distance(*b)));
            history.push(HistoryRow {
                iteration: pass + 1,
                measure: discrete_inflections(&cur, closed) as f64,
                max_distance,
            });
            if moves == 0 && !closed {
                break;
            }
        }
        let mut notes = Vec::new();
        // A safety net against the tolerance asked for. The moves already keep every point
        // inside the slightly smaller `tolerance`, so clamping to that one would only move
        // points that sit on its boundary by an ulp.
        if let Some(d) = options.tolerance {
            let pulled = clamp_to_tolerance(orig, &mut cur, d);
            if pulled > 0 {
                log.limited = true;
                notes.push(format!("{pulled} points were pulled back to the tolerance"));
            }
        }
        if !closed && !options.fix_ends.is_fixed() {
            notes.push("han keeps the end points fixed (as the paper does)".into());
        }
        if closed && params.passes == 1 {
            notes.push("closed curve faired in one pass: point 0 (the cut) was kept".into());
        }
        if !log.skipped.is_empty() {
            let list: Vec<String> = log
                .skipped
                .iter()
                .take(10)
                .map(|(a, b)| format!("[{a}, {b}]"))
                .collect();
            notes.push(format!(
                "{} segments were too steep in their frame (X not increasing or a chord steeper \
                 than {MAX_LOCAL_SLOPE}:1) even with max_turn halved down to pi/8, and were left \
                 unfaired: {}{}",
                log.skipped.len(),
                list.join(", "),
                if log.skipped.len() > 10 { ", …" } else { "" }
            ));
        }
        if log.refused > 0 {
            notes.push(format!(
                "{} moves were refused because they would have added an inflection or raised \
                 the variation energy near the moved points (the clean-curve check)",
                log.refused
            ));
        }
        if log.refined > 0 {
            notes.push(format!(
                "{} segments were too steep in their frame and were re-partitioned with half \
                 the turning threshold",
                log.refined
            ));
        }
        if log.total_moves > log.moves.len() {
            notes.push(format!(
                "{} moves were made; the first {} are listed",
                log.total_moves,
                log.moves.len()
            ));
        }
        let status = if log.total_moves == 0 {
            FairStatus::NoChange
        } else if log.limited {
            FairStatus::ToleranceLimited
        } else if last_pass_moves == 0 {
            FairStatus::Converged
        } else {
            notes.push(format!(
                "han has no convergence test: it stopped after {passes_done} passes of {} \
                 iterations per segment (the paper's schedule)",
                params.iterations
            ));
            FairStatus::IterationLimit
        };
        let mut parameters = serde_json::Map::new();
        let num = |v: f64| serde_json::Value::from(v);
        parameters.insert("lambda_coarse".into(), num(params.segment.lambda_coarse));
        parameters.insert("lambda_fine".into(), num(params.segment.lambda_fine));
        parameters.insert("alpha_factor".into(), num(params.segment.alpha_factor));
        parameters.insert("fine_run3".into(), params.segment.fine_run3.into());
        parameters.insert("overlap".into(), params.overlap.into());
        parameters.insert("passes".into(), params.passes.into());
        parameters.insert("max_turn".into(), num(params.max_turn));
        parameters.insert("iterations".into(), params.iterations.into());
        parameters.insert("fix_ends".into(), true.into());
        Ok(Outcome {
            points: cur,
            status,
            iterations: log.iterations,
            moves: log.moves,
            history,
            parameters,
            notes,
            ends_held: Some(EndFix::Position),
            ..Outcome::default()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sign_scale_agrees_with_the_exact_maximum() {
        // Random local rewrites, some to values right at ZERO_REL times the maximum: every
        // sign equals sgn0 with the exact maximum, and rescans stay rare.
        let n = 300;
        let mut state = 12345_u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            state >> 11
        };
        let mut v: Vec<f64> = (0..n).map(|_| (next() % 2000) as f64 - 1000.0).collect();
        let mut sc = SignScale::new(&v);
        let mut checks = 0;
        let no_floor = vec![0.0; n];
        for round in 0..5000 {
            let lo = next() as usize % n;
            let hi = (lo + next() as usize % 20).min(n - 1);
            let exact_before = abs_max(&v);
            for i in lo..=hi {
                let r = next();
                v[i] = match r % 5 {
                    0 => 0.0,
                    1 => ZERO_REL * exact_before * if r % 2 == 0 { 1.0 } else { -1.0 },
                    2 => ZERO_REL * exact_before * 1.5,
                    _ => ((r >> 8) % 2000) as f64 * 0.37 * (1.0 + (round % 7) as f64) - 400.0,
                };
            }
            sc.wrote(&v, Changed::of(&v, lo, hi));
            let exact = abs_max(&v);
            for _ in 0..5 {
                let i = next() as usize % n;
                assert_eq!(
                    sc.sign(&v, &no_floor, i),
                    sgn0(v[i], exact),
                    "round {round}, index {i}"
                );
                checks += 1;
            }
            assert!(sc.lower <= exact && exact <= sc.upper);
        }
        assert!(sc.rescans < checks / 2, "{} rescans", sc.rescans);
        let mut zeros = SignScale::new(&[0.0, 0.0]);
        assert_eq!(zeros.sign(&[0.0, 0.0], &[0.0, 0.0], 1), 0);
        let mut floored = SignScale::new(&[1.0, 1e-3]);
        assert_eq!(floored.sign(&[1.0, 1e-3], &[0.0, 1e-3], 1), 0);
        assert_eq!(floored.sign(&[1.0, 1e-3], &[0.0, 0.5e-3], 1), 1);
    }

    #[test]
    fn wrap_is_half_open() {
        assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(0.25) - 0.25).abs() < 1e-16);
        assert!((wrap_angle(-2.0 * PI + 0.1) - 0.1).abs() < 1e-12);
    }

    #[test]
    fn solve2_rejects_singular() {
        assert_eq!(solve2(1.0, 2.0, 2.0, 4.0, 1.0, 1.0), None);
        let (s, t) = solve2(2.0, 1.0, 1.0, 3.0, 3.0, 4.0).unwrap_or((f64::NAN, f64::NAN));
        assert!((s - 1.0).abs() < 1e-15 && (t - 1.0).abs() < 1e-15);
    }

    #[test]
    fn angle_parameter_forms() {
        let o = |v: &str| FairOptions::default().with_param("max_turn", v);
        assert_eq!(param_angle(&o("pi"), "max_turn", 1.0).ok(), Some(PI));
        assert_eq!(
            param_angle(&o("π/2"), "max_turn", 1.0).ok(),
            Some(FRAC_PI_2)
        );
        assert_eq!(param_angle(&o(" 1.25 "), "max_turn", 1.0).ok(), Some(1.25));
        assert!(param_angle(&o("4"), "max_turn", 1.0).is_err());
        assert!(param_angle(&o("pi/x"), "max_turn", 1.0).is_err());
        assert!(param_angle(&o("0"), "max_turn", 1.0).is_err());
    }

    #[test]
    fn add_columns_keeps_end_condition_bitwise() {
        let x: Vec<f64> = (0..12).map(|i| (i as f64).powf(1.3)).collect();
        let y: Vec<f64> = x.iter().map(|v| (v * 0.7).sin()).collect();
        let mut seg = Segment::new(x, y).unwrap_or_else(|e| panic!("{e}"));
        let n = seg.len();
        for start in 1..n - 1 {
            let len = (n - 1 - start).min(4);
            let g: Vec<f64> = (0..len).map(|k| 0.01 * (k as f64 + 1.0)).collect();
            seg.apply(MoveTag::C1, start, start, &g, &mut |_| {});
            assert_eq!(seg.c[0], seg.c[1]);
            assert_eq!(seg.c[n - 1], seg.c[n - 2]);
        }
    }
}
