//! The parameters of the Kjellander–Poliakoff family: the stopping threshold ε (relative or
//! absolute, shared with `sapidis-farin`), the move limit, and the `--set` table of each method
//! (`docs/algorithms/kjellander-poliakoff.md`, "Parameters").

use crate::error::{Error, Result};
use crate::fair::{FairOptions, ParamSpec};

use super::rules::KpRule;

/// Default relative stopping threshold: the run stops when every `|J_k|` is at most this
/// fraction of the largest jump of the input.
pub const DEFAULT_THRESHOLD: f64 = 1e-3;

/// Default iteration limit, per candidate point (bad points for `kjellander`, `poliakoff`
/// and `energy`; interior knots for `sapidis-farin`): one iteration is one move.
pub const DEFAULT_MOVES_PER_POINT: usize = 10;

/// The stopping threshold ε: relative to the input's largest badness, or absolute.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(in crate::fair) enum Threshold {
    /// ε = factor × the largest badness of the input.
    Relative(f64),
    /// ε in the units of the badness measure.
    Absolute(f64),
}

impl Threshold {
    /// Read the `threshold` and `epsilon` method parameters (`epsilon=auto`, the documented
    /// default, is the same as leaving it out).
    pub(in crate::fair) fn from_options(options: &FairOptions) -> Result<Threshold> {
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
pub(in crate::fair) const THRESHOLD_PARAM: ParamSpec = ParamSpec {
    name: "threshold",
    default: "0.001",
    doc: "stop when every third-derivative jump is at most this fraction of the input's largest",
};

/// See [`THRESHOLD_PARAM`].
pub(in crate::fair) const EPSILON_PARAM: ParamSpec = ParamSpec {
    name: "epsilon",
    default: "auto",
    doc: "absolute stopping bound on the jumps (overrides threshold); auto = threshold x input max",
};

pub(super) const REPARAMETRIZE_PARAM: ParamSpec = ParamSpec {
    name: "reparametrize",
    default: "true",
    doc: "recompute chord-length parameters after each move (spec 2.6 step 5); false keeps the input's",
};

pub(super) const MODE_PARAM: ParamSpec = ParamSpec {
    name: "mode",
    default: "position-and-tangent",
    doc: "position-and-tangent: move by delta* (eqs 11-12); position: the eta = 0 optimum (= poliakoff)",
};

/// The iteration limit: `max_iterations`, or [`DEFAULT_MOVES_PER_POINT`] per candidate.
pub(in crate::fair) fn move_limit(options: &FairOptions, candidates: usize) -> usize {
    options.iterations_or(DEFAULT_MOVES_PER_POINT.saturating_mul(candidates.max(1)))
}

/// The parameters of the point-only KP methods: the threshold and, on the chord-length spline,
/// `reparametrize` (always false on the uniform one). They need no input.
pub(super) fn point_params(uniform: bool, options: &FairOptions) -> Result<(Threshold, bool)> {
    let threshold = Threshold::from_options(options)?;
    let reparametrize = !uniform && options.param_bool("reparametrize", true)?;
    Ok((threshold, reparametrize))
}

/// The rule of the `energy` method, from its `mode` parameter.
pub(super) fn energy_rule(options: &FairOptions) -> Result<KpRule> {
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
