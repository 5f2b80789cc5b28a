//! `han`'s parameters: their defaults, the table `batten methods` shows, and the typed values
//! of a run parsed from the options (`docs/algorithms/han.md`, "Parameters").

use std::f64::consts::FRAC_PI_2;

use serde_json::{Map, Value};

use super::segment::SegmentParams;
use crate::error::Result;
use crate::fair::params::{Angle, Flag, Number, Param};
use crate::fair::{FairOptions, ParamSpec};

/// Default damping of coarse case 1, `λ_c` \[PAPER\].
pub(super) const DEFAULT_LAMBDA_COARSE: f64 = 0.8;
/// Default weight of the outer points in the fine cases, `λ_f` \[PAPER\].
pub(super) const DEFAULT_LAMBDA_FINE: f64 = 0.75;
/// Default factor of the fine-phase α rule, `α = factor · v` \[PAPER: 1/5\].
pub(super) const DEFAULT_ALPHA_FACTOR: f64 = 0.2;
/// Whether the `han` method runs fine case 3 ([`SegmentParams::fine_run3`]), an extension
/// not in the paper \[CHOICE\]: on the peer comparison it is what makes `han` leave no more
/// spurious inflections than csaps in every case (`fine_run3=false` gives the paper's method).
pub(super) const DEFAULT_FINE_RUN3: bool = true;
/// Default number of points shared by consecutive segments, k \[PAPER\].
pub(super) const DEFAULT_OVERLAP: usize = 5;

/// Largest `overlap` accepted: an overlap beyond a segment's length changes nothing, and this
/// is more points than any segment holds in practice.
pub(super) const MAX_OVERLAP: usize = 1_000_000;
/// Default number of pipeline passes (partition, fair, blend) \[CHOICE\].
pub(super) const DEFAULT_PASSES: usize = 3;
/// Default turning threshold of the partition, π/2 \[CHOICE\]: the value the spec recommends
/// (§1.8 note). Segments then stay far from vertical local slopes, where the function-spline
/// proxy breaks down; with the paper's π the end chords of a densely sampled segment are
/// nearly vertical in its frame. Measured on the peer comparison (`bench/compare_peers.py`),
/// π/2 (with fine case 3) is what makes `han` leave no more spurious inflections than csaps.
pub(super) const DEFAULT_MAX_TURN: f64 = FRAC_PI_2;
/// Default iterations per segment, T \[CHOICE §1.7.3\].
pub(super) const DEFAULT_ITERATIONS: usize = 10;

/// `λ_c` ([`DEFAULT_LAMBDA_COARSE`]).
pub(super) const LAMBDA_COARSE: Param<Number<f64>> = Param {
    name: "lambda_coarse",
    kind: Number {
        default: DEFAULT_LAMBDA_COARSE,
        min: 0.0,
        max: 1.0,
    },
    doc: "damping λ_c of coarse case 1 (small vibrations), in [0, 1]",
};

/// `λ_f` ([`DEFAULT_LAMBDA_FINE`]).
pub(super) const LAMBDA_FINE: Param<Number<f64>> = Param {
    name: "lambda_fine",
    kind: Number {
        default: DEFAULT_LAMBDA_FINE,
        min: 0.0,
        max: 1.0,
    },
    doc: "weight λ_f of the outer points of the fine (inflection) moves, in [0, 1]",
};

/// k ([`DEFAULT_OVERLAP`]).
pub(super) const OVERLAP: Param<Number<usize>> = Param {
    name: "overlap",
    kind: Number {
        default: DEFAULT_OVERLAP,
        min: 1,
        max: MAX_OVERLAP,
    },
    doc: "points shared by consecutive function segments (k), 1 to 1000000",
};

/// The pipeline passes ([`DEFAULT_PASSES`]).
pub(super) const PASSES: Param<Number<usize>> = Param {
    name: "passes",
    kind: Number {
        default: DEFAULT_PASSES,
        min: 1,
        max: 10_000,
    },
    doc: "pipeline passes (partition, fair, blend)",
};

/// The partition's turning threshold ([`DEFAULT_MAX_TURN`]).
pub(super) const MAX_TURN: Param<Angle> = Param {
    name: "max_turn",
    kind: Angle {
        default: DEFAULT_MAX_TURN,
    },
    doc: "turning range of a segment in radians, in (0, π]; accepts pi and pi/N; the paper's \
          value is pi; pi/2 (the spec's recommendation) keeps segments away from vertical slopes",
};

/// Fine case 3 ([`DEFAULT_FINE_RUN3`]).
pub(super) const FINE_RUN3: Param<Flag> = Param {
    name: "fine_run3",
    kind: Flag {
        default: DEFAULT_FINE_RUN3,
    },
    doc: "extension, not in the paper: also remove runs of three points of one sign of c (fine \
          case 3); false gives the paper's method",
};

/// The fine phase's α factor ([`DEFAULT_ALPHA_FACTOR`]).
pub(super) const ALPHA_FACTOR: Param<Number<f64>> = Param {
    name: "alpha_factor",
    kind: Number {
        default: DEFAULT_ALPHA_FACTOR,
        min: 0.0,
        max: 1.0,
    },
    doc: "fine phase target α = factor × the smaller-magnitude neighbour of c, in [0, 1]",
};

/// The parameter table (`batten methods`).
pub(super) static PARAMS: &[ParamSpec] = &[
    LAMBDA_COARSE.spec(),
    LAMBDA_FINE.spec(),
    OVERLAP.spec(),
    PASSES.spec(),
    MAX_TURN.spec(),
    FINE_RUN3.spec(),
    ALPHA_FACTOR.spec(),
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
            .with_lambda_coarse(o.get(&LAMBDA_COARSE)?)
            .with_lambda_fine(o.get(&LAMBDA_FINE)?)
            .with_alpha_factor(o.get(&ALPHA_FACTOR)?)
            .with_fine_run3(o.get(&FINE_RUN3)?);
        segment.validate()?;
        Ok(HanParams {
            segment,
            overlap: o.get(&OVERLAP)?,
            passes: o.get(&PASSES)?,
            max_turn: o.get(&MAX_TURN)?,
            iterations: o.iterations_or(DEFAULT_ITERATIONS),
        })
    }

    /// The parameters as used, for the report.
    pub(super) fn report(&self) -> Map<String, Value> {
        let mut parameters = Map::new();
        let p = &mut parameters;
        LAMBDA_COARSE.write(p, self.segment.lambda_coarse);
        LAMBDA_FINE.write(p, self.segment.lambda_fine);
        ALPHA_FACTOR.write(p, self.segment.alpha_factor);
        FINE_RUN3.write(p, self.segment.fine_run3);
        OVERLAP.write(p, self.overlap);
        PASSES.write(p, self.passes);
        MAX_TURN.write(p, self.max_turn);
        p.insert("iterations".into(), self.iterations.into());
        p.insert("fix_ends".into(), true.into());
        parameters
    }
}
