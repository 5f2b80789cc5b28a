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
//!
//! # Files
//!
//! - `params.rs`: the parameters of a run, their defaults and their `--set` parsing;
//! - `responses.rs`: the unit spline responses and the exact update of c (eqs 13–17, §1.6);
//! - `sign.rs`: the sign tests of §1.7.0 under local updates;
//! - `segment.rs`: one function segment, its moves and their bounds (§1.7), and
//!   `segment/cases.rs`: the coarse and fine cases (§1.7.1–§1.7.3);
//! - `partition.rs`: the split of an arbitrary curve into function segments (§1.8);
//! - `pipeline.rs`: the passes (partition, fair every segment, blend; closed curves) and
//!   their log (§1.8.6);
//! - this file: the method itself, its notes, status and report.
//!
//! `docs/algorithms/han.md` gives the formulas with the paper's equation numbers and maps the
//! spec sections cited here to its own.
//!
//! [`ZERO_REL`]: crate::analysis::ZERO_REL
//! [`CubicSplineFn`]: crate::spline::CubicSplineFn

mod params;
mod partition;
mod pipeline;
mod responses;
mod segment;
mod sign;
#[cfg(test)]
mod tests;

use super::{EndFix, FairMethod, FairStatus, Outcome, ParamSpec, clamp_to_tolerance};
use crate::error::Result;
use crate::fair::FairOptions;
use crate::geom::PointSeq;

use params::{HanParams, PARAMS};
use pipeline::{Passes, RunLog, run_passes};
pub use segment::{CaseMove, MoveTag, Segment, SegmentParams};

/// The `han` method: see `docs/algorithms/han.md`, and the module docs of `fair/han/mod.rs` in
/// the source.
#[derive(Clone, Copy, Debug, Default)]
pub struct Han;

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
        let closed = input.is_closed();
        let mut log = RunLog::default();
        let Passes {
            points: mut cur,
            history,
            done: passes_done,
            last_moves: last_pass_moves,
        } = run_passes(input, &params, options, &mut log)?;
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
        notes.extend(log.notes());
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
        Ok(Outcome {
            points: cur,
            status,
            iterations: log.iterations,
            moves: log.moves,
            history,
            parameters: params.report(),
            notes,
            ends_held: Some(EndFix::Position),
            ..Outcome::default()
        })
    }
}
