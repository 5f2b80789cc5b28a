//! The parameters of `salvi`: [`SalviParams`] with their defaults, the `--set` table and its
//! parsing (`docs/algorithms/salvi-varady.md`, "Parameters").

use super::target::{DEFAULT_PASSES, MAX_SAMPLES, MIN_SAMPLES, MIN_TARGET_COEFFICIENTS, Smoother};
use serde_json::{Map, Value};

use crate::error::Result;
use crate::fair::local::{CONTROL_POINTS, DEFAULT_TABU_LENGTH, FIT_DEGREE, FREE_ENDS, TABU};
use crate::fair::params::{Auto, Choice, Flag, Number, Param};
use crate::fair::{FairOptions, ParamSpec};

/// Default iteration limit (the paper's Table 1 runs 1000 iterations).
pub(super) const DEFAULT_MAX_ITERATIONS: usize = 1000;

/// Default window M of the stopping rule.
pub(super) const DEFAULT_WINDOW: usize = 50;

/// Stop when Ê fell by less than this fraction of its value M iterations earlier.
pub(super) const WINDOW_MIN_REL_IMPROVEMENT: f64 = 1e-3;

/// Parameters of [`salvi_fair_curve`](crate::fair::salvi_fair_curve). Start from
/// [`SalviParams::DEFAULT`].
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SalviParams {
    /// Number of samples N, at most [`MAX_SAMPLES`]; `None`: `max(200, 8 × non-empty spans)`.
    ///
    /// Default value: `None`.
    pub samples: Option<usize>,
    /// How g is made.
    ///
    /// Default value: [`Smoother::DEFAULT`].
    pub smoother: Smoother,
    /// Make g equal κ at both ends.
    ///
    /// Default value: `false`.
    pub pin_ends: bool,
    /// δ, the largest distance of a control point from its original position; `None`:
    /// `local::DEFAULT_TOLERANCE_REL` × the bounding-box diagonal of the control points.
    ///
    /// Default value: `None`.
    pub tolerance: Option<f64>,
    /// Length R of the recently-moved list.
    ///
    /// Default value: `DEFAULT_TABU_LENGTH` (4).
    pub tabu_length: usize,
    /// Iteration limit.
    ///
    /// Default value: `DEFAULT_MAX_ITERATIONS` (1000).
    pub max_iterations: usize,
    /// Window M of the stopping rule; 0 disables it (run `max_iterations`).
    ///
    /// Default value: `DEFAULT_WINDOW` (50).
    pub window: usize,
    /// Relative improvement over the window below which the run stops.
    ///
    /// Default value: `WINDOW_MIN_REL_IMPROVEMENT` (1e-3).
    pub min_rel_improvement: f64,
    /// Let the first and last control points move.
    ///
    /// Default value: `false`.
    pub free_ends: bool,
    /// Control points held at each end unless `free_ends`: 1 (the end points), 2 (also the
    /// end tangents) or 3 (also the end curvatures); `--fix-ends=tangent` / `curvature`.
    ///
    /// Default value: 1.
    pub held_ends: usize,
    /// Skip a control point whose last search made no progress (relative local improvement
    /// below `STALL_REL_IMPROVEMENT`) until a control point whose support overlaps its own
    /// makes progress; stop when every movable point is skipped. `false` follows
    /// docs/algorithms/salvi-varady.md §3 step 5 literally (see the module documentation).
    ///
    /// Default value: `true`.
    pub skip_stalled: bool,
}

impl SalviParams {
    /// The defaults listed on each field.
    pub const DEFAULT: SalviParams = SalviParams {
        samples: None,
        smoother: Smoother::DEFAULT,
        pin_ends: false,
        tolerance: None,
        tabu_length: DEFAULT_TABU_LENGTH,
        max_iterations: DEFAULT_MAX_ITERATIONS,
        window: DEFAULT_WINDOW,
        min_rel_improvement: WINDOW_MIN_REL_IMPROVEMENT,
        free_ends: false,
        held_ends: 1,
        skip_stalled: true,
    };

    /// Set δ.
    pub fn with_tolerance(mut self, delta: f64) -> SalviParams {
        self.tolerance = Some(delta);
        self
    }

    /// Set N.
    pub fn with_samples(mut self, n: usize) -> SalviParams {
        self.samples = Some(n);
        self
    }

    /// Set the smoother.
    pub fn with_smoother(mut self, smoother: Smoother) -> SalviParams {
        self.smoother = smoother;
        self
    }

    /// Pin (or not) the target to κ at the ends.
    pub fn with_pin_ends(mut self, pin: bool) -> SalviParams {
        self.pin_ends = pin;
        self
    }

    /// Set the iteration limit.
    pub fn with_max_iterations(mut self, n: usize) -> SalviParams {
        self.max_iterations = n;
        self
    }

    /// Set the window M (0: no window rule).
    pub fn with_window(mut self, m: usize) -> SalviParams {
        self.window = m;
        self
    }

    /// Set the tabu length R.
    pub fn with_tabu_length(mut self, r: usize) -> SalviParams {
        self.tabu_length = r;
        self
    }

    /// Free (or fix) the end control points.
    pub fn with_free_ends(mut self, free: bool) -> SalviParams {
        self.free_ends = free;
        self
    }

    /// Hold `k` control points at each end (see [`SalviParams::held_ends`]).
    pub fn with_held_ends(mut self, k: usize) -> SalviParams {
        self.held_ends = k;
        self
    }

    /// Skip stalled control points (default) or follow the spec's selection literally.
    pub fn with_skip_stalled(mut self, skip: bool) -> SalviParams {
        self.skip_stalled = skip;
        self
    }
}

impl Default for SalviParams {
    fn default() -> SalviParams {
        SalviParams::DEFAULT
    }
}

/// N (`auto`: [`super::sample_count`]).
const SAMPLES: Param<Auto<usize>> = Param {
    name: "samples",
    kind: Auto {
        min: MIN_SAMPLES,
        max: MAX_SAMPLES,
    },
    doc: "number of curvature samples N, 4..=20000 (auto: max(200, 8 per knot span))",
};

/// How the target curvature is made ([`Smoother`]).
const SMOOTHER: Param<Choice> = Param {
    name: "smoother",
    kind: Choice {
        default: "average",
        choices: &["average", "bspline"],
    },
    doc: "target curvature: average (moving average) or bspline (least-squares fit of κ(s))",
};

/// The moving average's half-width (`auto`: N / [`super::HALF_WIDTH_DIVISOR`]).
const HALF_WIDTH: Param<Auto<usize>> = Param {
    name: "half_width",
    kind: Auto {
        min: 0,
        max: MAX_SAMPLES,
    },
    doc: "moving-average half-width in samples (auto: N/20; at most 20000)",
};

/// The moving average's passes ([`DEFAULT_PASSES`]).
const PASSES: Param<Number<usize>> = Param {
    name: "passes",
    kind: Number {
        default: DEFAULT_PASSES,
        min: 0,
        max: 1000,
    },
    doc: "moving-average passes",
};

/// The coefficients of the least-squares target (`auto`: from N).
const TARGET_COEFFICIENTS: Param<Auto<usize>> = Param {
    name: "target_coefficients",
    kind: Auto {
        min: MIN_TARGET_COEFFICIENTS,
        max: MAX_SAMPLES,
    },
    doc: "coefficients of the bspline target fit (auto: max(4, N/20); at most 20000)",
};

/// [`SalviParams::pin_ends`].
const PIN_ENDS: Param<Flag> = Param {
    name: "pin_ends",
    kind: Flag {
        default: SalviParams::DEFAULT.pin_ends,
    },
    doc: "make the target equal the curvature at both ends",
};

/// [`SalviParams::window`].
const WINDOW: Param<Number<usize>> = Param {
    name: "window",
    kind: Number {
        default: DEFAULT_WINDOW,
        min: 0,
        max: crate::fair::MAX_ITERATIONS,
    },
    doc: "stop when the measure improved < 0.1% over this many iterations (0: never; at most 1000000)",
};

pub(super) static PARAMS: [ParamSpec; 11] = [
    SAMPLES.spec(),
    SMOOTHER.spec(),
    HALF_WIDTH.spec(),
    PASSES.spec(),
    TARGET_COEFFICIENTS.spec(),
    PIN_ENDS.spec(),
    TABU.spec(),
    WINDOW.spec(),
    FIT_DEGREE.spec(),
    CONTROL_POINTS.spec(),
    FREE_ENDS.spec(),
];

/// The parameters of a run; `tolerance` (δ) and `free_ends` come from the fitted input. The
/// smoother parameters are all checked, whichever smoother is chosen.
pub(super) fn salvi_params(
    options: &FairOptions,
    tolerance: Option<f64>,
    free_ends: bool,
) -> Result<SalviParams> {
    let samples = options.get(&SAMPLES)?;
    let coefficients = options.get(&TARGET_COEFFICIENTS)?;
    let half_width = options.get(&HALF_WIDTH)?;
    let passes = options.get(&PASSES)?;
    let smoother = match options.get(&SMOOTHER)? {
        "bspline" => Smoother::BSplineFit { coefficients },
        _ => Smoother::MovingAverage { half_width, passes },
    };
    let max_iterations = options.iterations_or(DEFAULT_MAX_ITERATIONS);
    Ok(SalviParams {
        samples,
        smoother,
        pin_ends: options.get(&PIN_ENDS)?,
        tolerance,
        tabu_length: options.get(&TABU)?,
        max_iterations,
        window: options.get(&WINDOW)?,
        min_rel_improvement: WINDOW_MIN_REL_IMPROVEMENT,
        free_ends,
        held_ends: options.fix_ends.held().max(1),
        skip_stalled: true,
    })
}

/// The parameters of a run as used, for the report: N as sampled, the smoother, and the
/// values read from the options.
pub(super) fn report_params(
    parameters: &mut Map<String, Value>,
    params: &SalviParams,
    samples: usize,
) {
    SAMPLES.write(parameters, Some(samples));
    let smoother = match params.smoother {
        Smoother::BSplineFit { .. } => "bspline",
        _ => "average",
    };
    SMOOTHER.write(parameters, smoother);
    PIN_ENDS.write(parameters, params.pin_ends);
    TABU.write(parameters, params.tabu_length);
    WINDOW.write(parameters, params.window);
}
