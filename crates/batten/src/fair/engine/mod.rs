//! What the local methods share, below them and knowing none of them: the greedy move engine
//! (the worst slot first; plan a move, cut it to the tolerance, accept or refuse it; the
//! stopping rules and the status) and the tolerance budget of a move. `kjellander`,
//! `poliakoff` and `energy` (point sequences and Hermite data) and `sapidis-farin` (the knots
//! of a cubic B-spline) run on it, each with its own [`LocalProblem`].
//!
//! - `greedy.rs`: [`LocalProblem`], [`drive`], the max-tree, the stopping threshold ε and the
//!   move limit;
//! - `budget.rs`: how far a planned move may go within the tolerance.

mod budget;
mod greedy;

pub(super) use budget::MIN_CHORD_REL;
pub(crate) use budget::{max_fraction, step_fraction, tolerance_radius};
pub(super) use greedy::JUMP_ZERO_REL;
pub(crate) use greedy::{
    EPSILON, JUMP_PARAMS, LocalProblem, MaxTree, THRESHOLD, Threshold, drive, driven_parameters,
    move_limit,
};
