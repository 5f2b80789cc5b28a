//! The parameters of the Kjellander–Poliakoff methods: the `--set` table of each method beyond
//! the engine's `threshold` and `epsilon`, and their parsing
//! (`docs/algorithms/kjellander-poliakoff.md`, "Parameters").

use crate::error::Result;
use crate::fair::engine::{EPSILON, THRESHOLD, Threshold};
use crate::fair::params::{Choice, Flag, Param};
use crate::fair::{FairOptions, ParamSpec};

use super::rules::KpRule;

/// Recompute the chord-length parameters after each move (`poliakoff`, `energy`).
pub(super) const REPARAMETRIZE: Param<Flag> = Param {
    name: "reparametrize",
    kind: Flag { default: true },
    doc: "recompute chord-length parameters after each move (spec 2.6 step 5); false keeps the input's",
};

/// The rule of `energy`: the position and tangent move, or the position alone.
pub(super) const MODE: Param<Choice> = Param {
    name: "mode",
    kind: Choice {
        default: "position-and-tangent",
        choices: &["position-and-tangent", "position"],
    },
    doc: "position-and-tangent: move by delta* (eqs 11-12); position: the eta = 0 optimum (= poliakoff)",
};

/// The parameters of `poliakoff`.
pub(super) static POLIAKOFF_PARAMS: [ParamSpec; 3] =
    [THRESHOLD.spec(), EPSILON.spec(), REPARAMETRIZE.spec()];

/// The parameters of `energy`.
pub(super) static ENERGY_PARAMS: [ParamSpec; 4] = [
    THRESHOLD.spec(),
    EPSILON.spec(),
    REPARAMETRIZE.spec(),
    MODE.spec(),
];

/// The parameters of the point-only KP methods: the threshold and, on the chord-length spline,
/// `reparametrize` (always false on the uniform one). They need no input.
pub(super) fn point_params(uniform: bool, options: &FairOptions) -> Result<(Threshold, bool)> {
    let threshold = Threshold::from_options(options)?;
    let reparametrize = !uniform && options.get(&REPARAMETRIZE)?;
    Ok((threshold, reparametrize))
}

/// The rule of the `energy` method, from its `mode` parameter.
pub(super) fn energy_rule(options: &FairOptions) -> Result<KpRule> {
    Ok(match options.get(&MODE)? {
        "position" => KpRule::EnergyPositionOnly,
        _ => KpRule::Energy,
    })
}
