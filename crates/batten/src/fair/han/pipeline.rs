//! The passes of the `han` method: partition the curve, fair every segment in its frame from
//! the same points (in parallel), blend the shared points; closed curves are cut at a point
//! that moves from pass to pass (`docs/algorithms/han.md`, "Fairing arbitrary curves", spec
//! §1.8.6). Also the run's log and the notes it gives.

use std::f64::consts::PI;

use rayon::prelude::*;

use super::params::HanParams;
use super::partition::{Span, partition};
use super::segment::{CaseMove, MIN_SEGMENT_POINTS, Segment};
use crate::analysis::count_sign_changes;
use crate::error::Result;
use crate::fair::{FairOptions, HistoryRow, Move};
use crate::geom::{Point, PointSeq, Vec2, max_abs_coordinate};

/// A segment that is too steep in its frame is re-partitioned with half the turning
/// threshold, down to this one; below it the segment is left unfaired (\[CHOICE\]).
pub(super) const MIN_FALLBACK_TURN: f64 = PI / 8.0;
/// A segment with a chord steeper than this in its bisector frame (`|ΔY/ΔX|`, ≈ 89.4°) is
/// re-partitioned with half the turning threshold, down to π/8, and left unfaired only past
/// that (\[CHOICE\] guard). The function-spline proxy assumes moderate slopes
/// (docs/algorithms/han.md §1.8 note: up to 76 seen on the strophoid with `max_turn = π`, faired
/// with some drift). Steeper segments come from the minimum-length rule extending a segment round a
/// tight loop until it turns by almost π; their spacing ratios reach 1e-6, the unit responses are
/// huge and the moves diverge (we saw a point thrown 500 curve sizes away). With `max_turn = π/2`
/// segments have slopes ≤ 1 unless extended.
pub(super) const MAX_LOCAL_SLOPE: f64 = 100.0;
/// At most this many moves are listed in the report; later moves are counted, not listed.
pub(super) const MAX_RECORDED_MOVES: usize = 10_000;
/// The tolerance is shrunk by this relative amount before use, so that rounding in the frame
/// changes cannot push a point over the bound.
const TOLERANCE_SAFETY_REL: f64 = 1e-9;
/// … and by this many ulps of the largest coordinate (rounding of absolute positions).
const TOLERANCE_SAFETY_ULPS: f64 = 16.0;

/// Bookkeeping of a run.
#[derive(Debug, Default)]
pub(super) struct RunLog {
    pub(super) moves: Vec<Move>,
    pub(super) total_moves: usize,
    pub(super) limited: bool,
    skipped: Vec<(usize, usize)>,
    /// Segments that were too steep in their frame and were re-partitioned.
    refined: usize,
    /// Moves refused by the clean-curve check.
    refused: usize,
    /// The most iterations one segment ran in one pass with a move (at most T,
    /// `--max-iterations`): the report's `iterations`, in the unit the option bounds.
    pub(super) iterations: usize,
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

    /// The notes the log gives: segments left unfaired, moves refused by the clean-curve
    /// check, segments re-partitioned, and moves made beyond those listed.
    pub(super) fn notes(&self) -> Vec<String> {
        let mut notes = Vec::new();
        if !self.skipped.is_empty() {
            let list: Vec<String> = self
                .skipped
                .iter()
                .take(10)
                .map(|(a, b)| format!("[{a}, {b}]"))
                .collect();
            notes.push(format!(
                "{} segments were too steep in their frame (X not increasing or a chord steeper \
                 than {MAX_LOCAL_SLOPE}:1) even with max_turn halved down to pi/8, and were left \
                 unfaired: {}{}",
                self.skipped.len(),
                list.join(", "),
                if self.skipped.len() > 10 { ", …" } else { "" }
            ));
        }
        if self.refused > 0 {
            notes.push(format!(
                "{} moves were refused because they would have added an inflection or raised \
                 the variation energy near the moved points (the clean-curve check)",
                self.refused
            ));
        }
        if self.refined > 0 {
            notes.push(format!(
                "{} segments were too steep in their frame and were re-partitioned with half \
                 the turning threshold",
                self.refined
            ));
        }
        if self.total_moves > self.moves.len() {
            notes.push(format!(
                "{} moves were made; the first {} are listed",
                self.total_moves,
                self.moves.len()
            ));
        }
        notes
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
        // Blend the points shared with what is already there (docs/algorithms/han.md §1.8.6): w_q =
        // q/(K+1).
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

/// What the passes of a run did.
pub(super) struct Passes {
    /// The faired points.
    pub(super) points: Vec<Point>,
    /// One row per pass: the discrete inflections and the largest displacement after it.
    pub(super) history: Vec<HistoryRow>,
    /// The passes run.
    pub(super) done: usize,
    /// The moves of the last pass run (0: the run converged).
    pub(super) last_moves: usize,
}

/// Run the passes over the whole curve: an open curve as it is (stopping after a pass that
/// made no move), a closed one cut at a point that moves from pass to pass (see the module
/// docs of `han`).
pub(super) fn run_passes(
    input: &PointSeq,
    params: &HanParams,
    options: &FairOptions,
    log: &mut RunLog,
) -> Result<Passes> {
    let orig = input.points();
    let n = orig.len();
    let closed = input.is_closed();
    let coord = max_abs_coordinate(orig);
    let tolerance = options.tolerance.map(|d| effective_tolerance(d, coord));
    let mut cur = orig.to_vec();
    let mut history = Vec::with_capacity(params.passes);
    let mut passes_done = 0;
    let mut last_pass_moves = 0;
    for pass in 0..params.passes {
        let ctx = PassCtx {
            params,
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
            let moves = open_pass(&mut open, &open_orig, params.max_turn, &ctx, &index_of, log)?;
            for (m, p) in open.iter().take(n).enumerate() {
                cur[(cut + m) % n] = *p;
            }
            moves
        } else {
            open_pass(&mut cur, orig, params.max_turn, &ctx, &|m| m, log)?
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
    Ok(Passes {
        points: cur,
        history,
        done: passes_done,
        last_moves: last_pass_moves,
    })
}
