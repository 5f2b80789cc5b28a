//! The parameters of the Kjellander–Poliakoff methods: the `--set` table of each method beyond
//! the engine's `threshold` and `epsilon`, and their parsing
//! (`docs/algorithms/kjellander-poliakoff.md`, "Parameters").

use crate::error::Result;
use crate::fair::FairOptions;
use crate::fair::ParamSpec;
use crate::fair::engine::Threshold;

use super::rules::KpRule;

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
