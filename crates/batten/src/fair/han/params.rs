//! `han`'s parameters: their defaults, the table `batten methods` shows, and the typed values
//! of a run parsed from the options (`docs/algorithms/han.md`, "Parameters").

use std::f64::consts::{FRAC_PI_2, PI};

use super::partition::check_max_turn;
use super::segment::SegmentParams;
use crate::error::{Error, Result};
use crate::fair::{FairOptions, ParamSpec};

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
/// Default iterations per segment, T \[CHOICE §1.7.3\].
pub const DEFAULT_ITERATIONS: usize = 10;

pub(super) static PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "lambda_coarse",
        default: crate::fair::ParamDefault::text(&"0.8"),
        doc: "damping λ_c of coarse case 1 (small vibrations), in [0, 1]",
    },
    ParamSpec {
        name: "lambda_fine",
        default: crate::fair::ParamDefault::text(&"0.75"),
        doc: "weight λ_f of the outer points of the fine (inflection) moves, in [0, 1]",
    },
    ParamSpec {
        name: "overlap",
        default: crate::fair::ParamDefault::text(&"5"),
        doc: "points shared by consecutive function segments (k), 1 to 1000000",
    },
    ParamSpec {
        name: "passes",
        default: crate::fair::ParamDefault::text(&"3"),
        doc: "pipeline passes (partition, fair, blend)",
    },
    ParamSpec {
        name: "max_turn",
        default: crate::fair::ParamDefault::text(&"pi/2"),
        doc: "turning range of a segment in radians, in (0, π]; accepts pi and pi/N; the \
              paper's value is pi; pi/2 (the spec's recommendation) keeps segments away from \
              vertical slopes",
    },
    ParamSpec {
        name: "fine_run3",
        default: crate::fair::ParamDefault::text(&"true"),
        doc: "extension, not in the paper: also remove runs of three points of one sign of c \
              (fine case 3); false gives the paper's method",
    },
    ParamSpec {
        name: "alpha_factor",
        default: crate::fair::ParamDefault::text(&"0.2"),
        doc: "fine phase target α = factor × the smaller-magnitude neighbour of c, in [0, 1]",
    },
];

/// Parameters of a run, parsed from the options.
#[derive(Clone, Copy, Debug)]
pub(super) struct HanParams {
    pub(super) segment: SegmentParams,
    pub(super) overlap: usize,
    pub(super) passes: usize,
    pub(super) max_turn: f64,
    pub(super) iterations: usize,
}

impl HanParams {
    pub(super) fn from_options(o: &FairOptions) -> Result<HanParams> {
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

    /// The parameters as used, for the report.
    pub(super) fn report(&self) -> serde_json::Map<String, serde_json::Value> {
        let mut parameters = serde_json::Map::new();
        let num = |v: f64| serde_json::Value::from(v);
        parameters.insert("lambda_coarse".into(), num(self.segment.lambda_coarse));
        parameters.insert("lambda_fine".into(), num(self.segment.lambda_fine));
        parameters.insert("alpha_factor".into(), num(self.segment.alpha_factor));
        parameters.insert("fine_run3".into(), self.segment.fine_run3.into());
        parameters.insert("overlap".into(), self.overlap.into());
        parameters.insert("passes".into(), self.passes.into());
        parameters.insert("max_turn".into(), num(self.max_turn));
        parameters.insert("iterations".into(), self.iterations.into());
        parameters.insert("fix_ends".into(), true.into());
        parameters
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
