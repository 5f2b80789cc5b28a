//! The greedy move engine: move the worst slot (a point or a knot) until every badness is at
//! most ε, the move limit is reached, or no bad slot can move within the tolerance; the
//! max-tree that keeps the worst slot, the stopping threshold ε and the move limit
//! (`docs/algorithms/kjellander-poliakoff.md`, "The algorithm",
//! docs/algorithms/kjellander-poliakoff.md §2.6, and "What `sapidis-farin` borrows").

use serde_json::{Map, Value, json};

use crate::error::{Error, Result};
use crate::fair::params::{Auto, Number, Param};
use crate::fair::{EndFix, FairOptions, FairStatus, HistoryRow, Move, Outcome, ParamSpec};
use crate::geom::Point;

/// Default relative stopping threshold: the run stops when every `|J_k|` is at most this
/// fraction of the largest jump of the input.
pub(super) const DEFAULT_THRESHOLD: f64 = 1e-3;

/// Default iteration limit, per candidate point (bad points for `kjellander`, `poliakoff`
/// and `energy`; interior knots for `sapidis-farin`): one iteration is one move.
pub(super) const DEFAULT_MOVES_PER_POINT: usize = 10;

/// A move that the tolerance cuts to less than this fraction of its full length cannot help;
/// the point is skipped and the next-worst point tried.
pub(super) const MIN_STEP_FRACTION: f64 = 1e-2;

/// A point skipped because the tolerance blocks its move is tried again once its jump has
/// changed by more than this fraction (a move nearby changed its neighbourhood); smaller
/// changes, such as the far tail of a windowed re-solve, leave it skipped.
pub(super) const RETRY_CHANGE_REL: f64 = 1e-6;

/// A jump no larger than this fraction of the terms it is computed from is rounding noise
/// and counts as zero (so exactly fair data, e.g. equally spaced collinear points, is left
/// alone instead of being "faired" at the level of rounding errors).
pub(crate) const JUMP_ZERO_REL: f64 = 1e-12;

/// The stopping threshold ε: relative to the input's largest badness, or absolute.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Threshold {
    /// ε = factor × the largest badness of the input.
    Relative(f64),
    /// ε in the units of the badness measure.
    Absolute(f64),
}

impl Threshold {
    /// Read the `threshold` and `epsilon` method parameters (`epsilon=auto`, the documented
    /// default, is the same as leaving it out).
    pub(crate) fn from_options(options: &FairOptions) -> Result<Threshold> {
        let rel = options.get(&THRESHOLD)?;
        Ok(match options.get(&EPSILON)? {
            Some(e) => Threshold::Absolute(e),
            None => Threshold::Relative(rel),
        })
    }
}

/// The relative stopping threshold ([`Threshold::Relative`]).
pub(crate) const THRESHOLD: Param<Number<f64>> = Param {
    name: "threshold",
    kind: Number {
        default: DEFAULT_THRESHOLD,
        min: 0.0,
        max: 1.0,
    },
    doc: "stop when every third-derivative jump is at most this fraction of the input's largest",
};

/// The absolute stopping threshold ([`Threshold::Absolute`]); `auto`: the relative one.
pub(crate) const EPSILON: Param<Auto<f64>> = Param {
    name: "epsilon",
    kind: Auto {
        min: 0.0,
        max: f64::MAX,
    },
    doc: "absolute stopping bound on the jumps (overrides threshold); auto = threshold x input max",
};

/// The parameters of every method that runs on the engine.
pub(crate) const JUMP_PARAMS: [ParamSpec; 2] = [THRESHOLD.spec(), EPSILON.spec()];

/// The iteration limit: `max_iterations`, or [`DEFAULT_MOVES_PER_POINT`] per candidate.
pub(crate) fn move_limit(options: &FairOptions, candidates: usize) -> usize {
    options.iterations_or(DEFAULT_MOVES_PER_POINT.saturating_mul(candidates.max(1)))
}

/// A max-heap over slots with O(log n) updates: a tournament tree of `(value, slot)`.
/// Absent and blocked slots hold −∞.
#[derive(Clone, Debug)]
pub(crate) struct MaxTree {
    size: usize,
    node: Vec<(f64, usize)>,
}

impl MaxTree {
    pub(crate) fn new(n: usize) -> MaxTree {
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
    pub(crate) fn zeros(n: usize) -> MaxTree {
        let mut t = MaxTree::new(n);
        t.set_runs((0..n).map(|i| (i, 0.0)));
        t
    }

    pub(crate) fn set(&mut self, i: usize, v: f64) {
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
    pub(crate) fn max(&self) -> Option<(usize, f64)> {
        let (v, i) = self.node[1];
        (v > f64::NEG_INFINITY).then_some((i, v))
    }

    /// The value at slot `i`.
    pub(crate) fn get(&self, i: usize) -> f64 {
        self.node[self.size + i].0
    }

    /// The largest value, 0 when every slot is absent.
    pub(crate) fn max_value(&self) -> f64 {
        self.max().map_or(0.0, |(_, v)| v)
    }
}

/// The larger entry; the left (lower slot) one on ties.
#[inline]
fn better(l: (f64, usize), r: (f64, usize)) -> (f64, usize) {
    if r.0 > l.0 { r } else { l }
}

/// A local fairing problem for [`drive`]: slots (points or knots) with a badness, and moves
/// that change the badness of a few slots.
pub(crate) trait LocalProblem {
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
pub(crate) struct Driven {
    pub(crate) status: FairStatus,
    pub(crate) moves: Vec<Move>,
    pub(crate) history: Vec<HistoryRow>,
    pub(crate) notes: Vec<String>,
    pub(crate) epsilon: f64,
    pub(crate) initial_max: f64,
}

impl Driven {
    /// The method's outcome: `points` faired by these moves, with the method's report
    /// `parameters`; the end points held (the engine never moves them), no curve, no
    /// tangents (a caller with either sets it).
    pub(crate) fn into_outcome(
        self,
        points: Vec<Point>,
        parameters: Map<String, Value>,
    ) -> Outcome {
        Outcome {
            solver: None,
            pressed: None,
            points,
            status: self.status,
            iterations: self.moves.len(),
            moves: self.moves,
            history: self.history,
            parameters,
            notes: self.notes,
            curve: None,
            tangents: None,
            ends_held: Some(EndFix::Position),
        }
    }
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

/// The greedy loop of docs/algorithms/kjellander-poliakoff.md §2.6: move the worst slot until every
/// badness is at most ε, the move limit is reached, or no bad slot can move within the tolerance.
pub(crate) fn drive(
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
    let mut tally = Tally::default();
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
                tally.skipped += 1;
                continue;
            }
        };
        if p.worsens(i, s) {
            open.set(i, f64::NEG_INFINITY);
            blocked[i] = true;
            tally.refused += 1;
            continue;
        }
        if s < 1.0 {
            tally.scaled += 1;
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
    let notes = tally.notes(status, epsilon, moves.len(), all.max_value());
    Ok(Driven {
        status,
        moves,
        history,
        notes,
        epsilon,
        initial_max,
    })
}

/// What [`drive`] counted on the way: moves scaled back, worst slots skipped (blocked by the
/// tolerance) and moves refused (the clean-curve check).
#[derive(Clone, Copy, Debug, Default)]
struct Tally {
    scaled: usize,
    skipped: usize,
    refused: usize,
}

impl Tally {
    /// The notes of a run that ended with `status` after `moves` moves, its largest badness
    /// `largest` against the bound `epsilon`.
    fn notes(&self, status: FairStatus, epsilon: f64, moves: usize, largest: f64) -> Vec<String> {
        let Tally {
            scaled,
            skipped,
            refused,
        } = *self;
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
                "stopped after {moves} move(s) with the largest jump {largest:.6e} above epsilon = {epsilon:.6e}"
            )),
            _ => {}
        }
        notes
    }
}

/// The common part of the reported parameters.
pub(crate) fn driven_parameters(
    d: &Driven,
    threshold: Threshold,
    max_moves: usize,
) -> Map<String, Value> {
    let mut p = Map::new();
    if let Threshold::Relative(r) = threshold {
        THRESHOLD.write(&mut p, r);
    }
    EPSILON.write(&mut p, Some(d.epsilon));
    p.insert("initial_max_jump".into(), json!(d.initial_max));
    p.insert("max_iterations".into(), json!(max_moves));
    p
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

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
}
