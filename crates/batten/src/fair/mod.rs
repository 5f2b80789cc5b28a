//! Fairing methods behind one interface.
//!
//! Every method is a pure function of a validated [`PointSeq`] and immutable [`FairOptions`];
//! it returns the faired points and a [`FairReport`] of what it did (params in, result and
//! report out, as in faer's `CgParams`/`CgInfo`). The [`fair`] entry point looks the method up
//! in the registry ([`methods`]), checks the options it was given, runs it, and fills in what
//! every report has in common: displacements, metrics before and after, whether the tolerance
//! held, elapsed time.
//!
//! Adding a method: implement [`FairMethod`] in a file of its own under `fair/`, declare each
//! of its parameters once as a `Param` constant (`params.rs`: key, kind with default and
//! range, doc) and list it in [`methods`].
//!
//! # What this namespace exports
//!
//! The files below are private modules; what is public is re-exported here by name, the names
//! of one method prefixed with it where they would be ambiguous:
//!
//! - the interface: [`fair`], [`fair_with`], [`fair_curve`] (B-spline input), [`fair_space`]
//!   (space curves, [`SPACE_METHODS`]), [`method`], [`methods`], [`default_method`],
//!   [`check_options`], [`catalogue`] ([`MethodInfo`], [`ParamInfo`]); [`FairOptions`],
//!   [`EndFix`]; what comes back: [`Faired`] with its [`FairReport`] ([`FairStatus`],
//!   [`Move`], [`HistoryRow`], [`SolverInfo`], [`EndChanges`], [`ToleranceSource`]);
//!   Han et al.'s comparison protocol [`compare`] ([`Comparison`]);
//! - the methods, one unit struct each, for [`FairMethod::run`] without the registry:
//!   [`Mst`], [`Han`], [`Kjellander`], [`Poliakoff`], [`Energy`], [`SapidisFarin`],
//!   [`Cali`], [`Salvi`], [`EckHadenfeld`], [`Kuragano`], [`Band`]. Each method's equations,
//!   choices and departures from its paper are in `docs/algorithms/` and in its module's
//!   documentation in the source (`fair/han/mod.rs`, `fair/salvi/mod.rs`, …);
//! - the methods' own entry points, with typed parameters: the smoothing spline
//!   [`SmoothingSpline`] ([`Smoothing`], [`SmoothingInfo`]); [`salvi_fair_curve`]
//!   ([`SalviParams`], [`SalviSmoother`], [`SalviReport`]) and [`eck_hadenfeld_fair_curve`]
//!   ([`EckHadenfeldParams`], [`LocalReport`]) on a B-spline; [`fair_hermite`],
//!   [`hermite_step`] ([`KpRule`], [`HermiteMove`]), [`energy_change_f`] and
//!   [`parametric_energy`] on Hermite data; [`remove_reinsert_knot`] (Sapidis–Farin);
//! - two building blocks, for measurements: [`HanSegment`], `han` on one function segment
//!   ([`HanSegmentParams`], its moves [`HanCaseMove`]), and [`LocalIndicators`], Calì's
//!   local fairness indicators with their local updates ([`IndicatorTrial`]);
//! - the documented bounds and factors the methods use ([`MAX_ITERATIONS`],
//!   [`AUTO_TOLERANCE_K`], [`SALVI_MAX_SAMPLES`], [`BISECTION_REL_PRECISION`], …).

mod band;
mod cali;
mod catalogue;
mod clean;
mod compare;
mod eck_hadenfeld;
mod engine;
mod guard;
mod han;
mod kjellander;
mod kuragano;
// The local-move helpers the surface methods share with `salvi` and `eck-hadenfeld`.
pub(crate) mod local;
mod options;
pub(crate) mod params;
mod periodic;
mod report;
mod salvi;
mod sapidis_farin;
mod smoothing;
mod space;

use std::borrow::Cow;
use std::time::Instant;

pub use band::{Band, auto_k as band_tolerance_factor};
pub use cali::{Cali, LocalIndicators, Trial as IndicatorTrial};
pub use catalogue::{MethodInfo, ParamInfo, catalogue};
pub use clean::LOCAL_CHECK_HALF_WIDTH;
pub use compare::{Comparison, ComparisonOutcome, ComparisonRow, compare};
pub use eck_hadenfeld::{EckHadenfeld, EckHadenfeldParams, fair_curve as eck_hadenfeld_fair_curve};
pub use guard::{CLEAN_SLACK_REL, METHOD_SCALE_RANGE_LOG2};
pub use han::{
    CaseMove as HanCaseMove, Han, MoveTag as HanMoveTag, Segment as HanSegment,
    SegmentParams as HanSegmentParams,
};
pub use kjellander::{
    Energy, HermiteMove, Kjellander, KpRule, Poliakoff, energy_change_f, fair_hermite,
    hermite_step, parametric_energy,
};
pub use kuragano::Kuragano;
pub use local::LocalReport;
pub use options::{AUTO_TOLERANCE_K, EndFix, FairOptions, MAX_ITERATIONS};
pub use params::{ParamDefault, ParamSpec, ParamType};
pub use report::{
    EndChanges, FairReport, FairStatus, HistoryRow, Move, SolverInfo, ToleranceSource,
};
pub use salvi::{
    MAX_SAMPLES as SALVI_MAX_SAMPLES, Salvi, SalviParams, SalviReport, Smoother as SalviSmoother,
    fair_curve as salvi_fair_curve,
};
pub use sapidis_farin::{SapidisFarin, remove_reinsert_knot};
pub use smoothing::{
    BISECTION_REL_PRECISION, Mst, Smoothing, SmoothingInfo, SmoothingSpline, SmoothingTrial,
};
pub use space::{
    FairedSpace, SPACE_METHODS, SpaceFairReport, SpaceOutcome, check_space_method, fair_space,
};

use crate::analysis::{FairnessMetrics, NoiseMeasure, Spread, displacement};
use crate::error::{Error, Result};
use crate::geom::{Point, PointSeq, SpaceSeq, Vec2};
use crate::spline::BSplineCurve;

/// What a method computed, before the common parts of the report are filled in.
#[derive(Clone, Debug, Default)]
#[non_exhaustive]
pub struct Outcome {
    /// The faired points: same count and order as the input.
    pub points: Vec<Point>,
    /// How the run ended.
    pub status: FairStatus,
    /// Iterations (sweeps, moves or passes, as the method documents).
    pub iterations: usize,
    /// The individual moves, in the order they were made (for local methods).
    pub moves: Vec<Move>,
    /// A per-iteration trace of the method's own measure (for the papers' tables and figures).
    pub history: Vec<HistoryRow>,
    /// Parameters as actually used (defaults filled in, values chosen by search).
    pub parameters: serde_json::Map<String, serde_json::Value>,
    /// Things the user should know (e.g. why the tolerance could not be met).
    pub notes: Vec<String>,
    /// The faired curve as a B-spline, for methods that work on one.
    pub curve: Option<BSplineCurve>,
    /// Updated tangents, for methods that carry tangents (Hermite data).
    pub tangents: Option<Vec<Vec2>>,
    /// The solver's figures, for methods that solve an optimisation problem.
    pub solver: Option<SolverInfo>,
    /// For a result fitted back towards the data inside the tolerance band (`band` after its
    /// debiasing stage, its `k` automatic): how many points press the band's edge. An
    /// automatic tolerance checks its noise model by it (see `run_widening`); `None` where
    /// the band is not what decides the fit's distance from the data, or its width was
    /// chosen (`--set k=`).
    pub pressed: Option<usize>,
    /// What the method held at the ends of an open curve when that is more than
    /// `--fix-ends` asked (`han` and `cali` always keep the end points); the report's
    /// `fix_ends` and `fixed_ends` say what was held.
    pub ends_held: Option<EndFix>,
}

/// A fairing method. Implementations are stateless unit structs.
pub trait FairMethod: Sync {
    /// The name used on the command line (`--method NAME`).
    fn name(&self) -> &'static str;
    /// One line for `batten methods`.
    fn description(&self) -> &'static str;
    /// The method parameters it accepts through [`FairOptions::params`], with defaults.
    fn parameters(&self) -> &'static [ParamSpec];
    /// Whether it can fair closed curves.
    fn supports_closed(&self) -> bool;
    /// Check the values of the method's parameters in `options`, before any input is read
    /// (their names are checked by [`check_options`]), so that a batch run refuses a bad
    /// value before it starts. Only checks that need the input (e.g. a control-point count
    /// against the number of points) are left to [`FairMethod::run`].
    ///
    /// # Errors
    /// [`Error::InvalidParameter`].
    fn check_params(&self, options: &FairOptions) -> Result<()>;
    /// Run the method. `input` has passed validation; unknown parameters were rejected.
    ///
    /// # Errors
    /// Whatever makes the method fail (a parameter out of range, degenerate geometry).
    fn run(&self, input: &PointSeq, options: &FairOptions) -> Result<Outcome>;

    /// Fair a B-spline curve as it is (B-spline in, B-spline out), for methods that work on
    /// control points. Returns the points the result is measured against (the input curve at
    /// the method's data parameters) and the outcome, whose points are the faired curve at the
    /// same parameters. `None` (the default): the method takes point input only.
    fn run_curve(
        &self,
        curve: &BSplineCurve,
        options: &FairOptions,
    ) -> Option<Result<(PointSeq, Outcome)>> {
        let _ = (curve, options);
        None
    }

    /// Whether [`FairMethod::run_curve`] is implemented (B-spline input accepted).
    fn run_curve_supported(&self) -> bool {
        false
    }

    /// Fair a space curve ([`fair_space`]): the faired 3-D points and what the method did.
    /// `options` carries the resolved tolerance, as for [`FairMethod::run`]. `None` (the
    /// default): the method is planar by nature.
    fn run_space(&self, input: &SpaceSeq, options: &FairOptions) -> Option<Result<SpaceOutcome>> {
        let _ = (input, options);
        None
    }

    /// Whether [`FairMethod::run_space`] is implemented (space curves accepted).
    fn run_space_supported(&self) -> bool {
        false
    }

    /// Whether the method takes an automatic tolerance `k·σ̂` when none is given, as if
    /// [`FairOptions::auto_tolerance`] were set. `false` (the default): no tolerance means
    /// no bound.
    fn auto_tolerance_by_default(&self) -> bool {
        false
    }

    /// The factor `k` of an automatic tolerance `k·σ̂` for these options and `n` input
    /// points: [`AUTO_TOLERANCE_K`] unless the method has a parameter for it.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a bad value of that parameter.
    fn auto_tolerance_factor(&self, options: &FairOptions, n: usize) -> Result<f64> {
        let _ = (options, n);
        Ok(AUTO_TOLERANCE_K)
    }

    /// Whether the clean-curve guard applies ([`FairOptions::keep_clean`]): `true` (the
    /// default) for every method but the csaps baseline `mst`.
    fn keeps_clean(&self) -> bool {
        true
    }

    /// Whether the method checks its single moves against the input's own fairness (the
    /// per-move part of the clean-curve guard, [`FairOptions::keep_clean`], which applies only
    /// to an input without inflections or vibrations): the common path then measures the
    /// input before the method runs. `true` (the default); methods without such a check
    /// return `false`, and a long input (from `MEASURE_BESIDE_FROM` = 16 384 points) is
    /// measured while they run.
    fn checks_moves(&self) -> bool {
        true
    }

    /// Whether the input's measures, when they run while the method does (see
    /// [`FairMethod::checks_moves`]), run in the background, at the lowest scheduling
    /// priority on the cores the method leaves idle: for a method whose run is long and
    /// mostly serial with parallel stretches (`band`'s interior point), which the measures
    /// beside it at the same priority would slow. `false` (the default): beside it at the
    /// same priority, which suits a short run (`mst`: its 10⁶-point fair took 0.50 s either
    /// way in the foreground and 0.52 s with its measures in the background).
    fn measures_in_background(&self) -> bool {
        false
    }

    /// The method's parameters given in data units, as `(name, power of length)` pairs: the
    /// default [`params_at_scale`](FairMethod::params_at_scale) and
    /// [`report_params_at_scale`](FairMethod::report_params_at_scale) convert them. The
    /// default: none.
    fn length_params(&self) -> &'static [(&'static str, i32)] {
        &[]
    }

    /// The options for a run on the coordinates divided by `s` (a power of two, see
    /// [`METHOD_SCALE_RANGE_LOG2`]): parameters given in data units converted. The common
    /// path divides the tolerance itself. The default converts the
    /// [`length_params`](FairMethod::length_params).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a value that cannot be converted.
    fn params_at_scale(&self, options: &FairOptions, s: f64) -> Result<FairOptions> {
        Ok(guard::length_params_at_scale(
            options,
            self.length_params(),
            s,
        ))
    }

    /// Convert the reported parameters of a run on the coordinates divided by `s` back to
    /// data units, where the method has some in data units. The default converts the
    /// [`length_params`](FairMethod::length_params).
    fn report_params_at_scale(
        &self,
        parameters: &mut serde_json::Map<String, serde_json::Value>,
        s: f64,
    ) {
        guard::report_length_params(parameters, self.length_params(), s);
    }
}

/// The result of [`fair`]: the faired points and the report.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct Faired {
    /// The faired points, same count and order as the input.
    pub points: Vec<Point>,
    /// What was done.
    pub report: FairReport,
    /// The faired curve as a B-spline, where the method works on one.
    pub curve: Option<BSplineCurve>,
    /// Updated tangents, where the method carries them.
    pub tangents: Option<Vec<Vec2>>,
}

static BAND: Band = Band;
static MST: Mst = Mst;
static CALI: Cali = Cali;
static HAN: Han = Han;
static SALVI: Salvi = Salvi;
static ECK_HADENFELD: EckHadenfeld = EckHadenfeld;
static KJELLANDER: Kjellander = Kjellander;
static POLIAKOFF: Poliakoff = Poliakoff;
static ENERGY: Energy = Energy;
static SAPIDIS_FARIN: SapidisFarin = SapidisFarin;
static KURAGANO: kuragano::Kuragano = kuragano::Kuragano;

/// The registered methods, the default first: `band`, which on the quality benchmark
/// (`bench/quality.py`, 360 noisy curves with exact curvature) leaves 345 spurious inflections
/// against `han`'s 45 668 and a median relative curvature error of 0.34 against 41, as issue
/// #18 asks before it becomes the default. `han`, the paper's method, is second.
static REGISTRY: &[&dyn FairMethod] = &[
    &BAND,
    &HAN,
    &MST,
    &CALI,
    &SALVI,
    &ECK_HADENFELD,
    &KJELLANDER,
    &POLIAKOFF,
    &ENERGY,
    &SAPIDIS_FARIN,
    &KURAGANO,
];

/// Every registered method, the default first.
pub fn methods() -> &'static [&'static dyn FairMethod] {
    REGISTRY
}

/// The name of the default method: the best the project has.
pub fn default_method() -> &'static str {
    REGISTRY[0].name()
}

/// Look a method up by name.
///
/// # Errors
/// [`Error::UnknownMethod`] listing the known names.
pub fn method(name: &str) -> Result<&'static dyn FairMethod> {
    REGISTRY
        .iter()
        .copied()
        .find(|m| m.name() == name)
        .ok_or_else(|| Error::UnknownMethod {
            name: name.to_string(),
            known: REGISTRY
                .iter()
                .map(|m| m.name())
                .collect::<Vec<_>>()
                .join(", "),
        })
}

/// Check `options` against what `method` accepts: known parameter names and their values
/// ([`FairMethod::check_params`]), a positive finite tolerance, closed-curve support.
///
/// # Errors
/// [`Error::UnknownOption`], [`Error::InvalidParameter`], [`Error::ClosedUnsupported`].
pub fn check_options(
    method: &dyn FairMethod,
    input_closed: bool,
    options: &FairOptions,
) -> Result<()> {
    if input_closed && !method.supports_closed() {
        return Err(Error::ClosedUnsupported {
            method: method.name().to_string(),
        });
    }
    options.validate()?;
    let specs = method.parameters();
    for key in options.params.keys() {
        if !specs.iter().any(|s| s.name == key) {
            return Err(Error::UnknownOption {
                method: method.name().to_string(),
                key: key.clone(),
                known: if specs.is_empty() {
                    "none".to_string()
                } else {
                    specs.iter().map(|s| s.name).collect::<Vec<_>>().join(", ")
                },
            });
        }
    }
    method.check_params(options)
}

/// Fair `input` with the method called `name`.
///
/// # Errors
/// [`Error::UnknownMethod`], option errors (see [`check_options`]), and the method's own
/// errors. Not meeting the tolerance is not an error: the report says so in
/// [`FairReport::tolerance_met`] and [`FairReport::status`].
pub fn fair(name: &str, input: &PointSeq, options: &FairOptions) -> Result<Faired> {
    let m = method(name)?;
    fair_with(m, input, options)
}

/// As [`fair`], with the method given directly.
///
/// # Errors
/// As [`fair`].
pub fn fair_with(m: &dyn FairMethod, input: &PointSeq, options: &FairOptions) -> Result<Faired> {
    fair_with_beside(m, input, options, |_| ()).map(|(faired, (), _)| faired)
}

/// A method's result before it is measured and the clean-curve guard has seen it: what
/// [`fair_with_beside`] shows its `beside` closure.
#[derive(Clone, Copy, Debug)]
#[non_exhaustive]
pub struct Provisional<'a> {
    /// The faired points.
    pub points: &'a [Point],
    /// The faired curve, where the method works on one.
    pub curve: Option<&'a BSplineCurve>,
    /// Updated tangents, where the method carries them.
    pub tangents: Option<&'a [Vec2]>,
}

/// As [`fair_with`], with `beside` run on the method's result while the result is measured:
/// for a caller that writes the result, so that the writing overlaps the measuring (on long
/// curves; short ones run one after the other). The result `beside` saw is the final one
/// unless the clean-curve guard returned the input instead; the flag says whether it is
/// (`true`: the points, curve and tangents of the [`Faired`] are those `beside` saw).
///
/// # Errors
/// As [`fair`]. `beside` has run by then (unless the method failed): what it made is
/// dropped.
pub fn fair_with_beside<T: Send>(
    m: &dyn FairMethod,
    input: &PointSeq,
    options: &FairOptions,
    beside: impl FnOnce(Provisional<'_>) -> T + Send,
) -> Result<(Faired, T, bool)> {
    check_options(m, input.is_closed(), options)?;
    let unit_scale = crate::geom::unit_scale(input.points());
    let measure = || FairnessMetrics::of_seq(&in_unit(input, unit_scale));
    let (before, ran) = if m.checks_moves() {
        let before = measure()?;
        let ran = run_method(m, input, options, Some(&before));
        (before, ran)
    } else {
        // The input's measures and the method are independent.
        let (before, ran) = measures_beside(
            m,
            input.len(),
            || in_unit(input, unit_scale),
            FairnessMetrics::of_seq,
            || run_method(m, input, options, None),
        );
        (before?, ran)
    };
    let Ran {
        outcome,
        options,
        start,
        source,
        sigma,
    } = ran?;
    finish(
        m,
        (input, None),
        (before, unit_scale),
        &options,
        outcome,
        start,
        (source, Some(sigma)),
        beside,
    )
}

/// From this many points the measures run beside the method and the writing
/// ([`beside_if_long`]): below it the two are short, and many small curves already keep every
/// core busy (`fair_many`).
const MEASURE_BESIDE_FROM: usize = 1 << 14;

/// `a()` and `b()`: side by side (`rayon::join`) for a curve of `n` points from
/// [`MEASURE_BESIDE_FROM`] on, where a measure's parallel pieces take the core a method's
/// serial solve or a write leaves idle; one after the other below.
fn beside_if_long<A: Send, B: Send>(
    n: usize,
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B + Send,
) -> (A, B) {
    if n < MEASURE_BESIDE_FROM {
        (a(), b())
    } else {
        rayon::join(a, b)
    }
}

/// The input's measures, `measure` of `data()` (the input in the units it is measured in),
/// and `m`'s run `method()` on a curve of `n` points, side by side: in the background for a
/// method that asks for it ([`FairMethod::measures_in_background`], from
/// [`MEASURE_BESIDE_FROM`] points on; `crate::numeric::beside_in_background`, which takes
/// the data owned), else in the foreground ([`beside_if_long`], on the data as it comes).
/// For the planar and the space fair alike.
fn measures_beside<'a, T, A, B>(
    m: &dyn FairMethod,
    n: usize,
    data: impl FnOnce() -> Cow<'a, T> + Send,
    measure: fn(&T) -> A,
    method: impl FnOnce() -> B + Send,
) -> (A, B)
where
    T: Clone + Send + Sync + 'static,
    A: Send + 'static,
    B: Send,
{
    if m.measures_in_background() && n >= MEASURE_BESIDE_FROM {
        crate::numeric::beside_in_background(data().into_owned(), measure, method)
    } else {
        beside_if_long(n, || measure(&data()), method)
    }
}

/// What a method's run did (`run_method` here and in `space.rs`): the method's outcome,
/// the options with the tolerance it used, when it started (the noise estimate counts),
/// where the tolerance came from, and σ̂.
struct Ran<O> {
    outcome: O,
    options: FairOptions,
    start: Instant,
    source: Option<ToleranceSource>,
    sigma: f64,
}

/// The noise estimate, the tolerance, and the method's run on `input` (widened where an
/// automatic tolerance proves too narrow), unless the input is to be left as it is. `before`,
/// the input's measures, is given to methods that check single moves against it
/// ([`FairMethod::checks_moves`]).
fn run_method(
    m: &dyn FairMethod,
    input: &PointSeq,
    options: &FairOptions,
    before: Option<&FairnessMetrics>,
) -> Result<Ran<Outcome>> {
    let start = Instant::now();
    let xy: Vec<[f64; 2]> = input.points().iter().map(|p| [p.x, p.y]).collect();
    let noise = NoiseMeasure::of(&xy, input.is_closed());
    let sigma = noise.sigma(Spread::OneD);
    let (mut resolved, source) =
        resolve_tolerance(m, options, sigma, input.bbox().diagonal(), input.len())?;
    let unchanged = left_as_is(&resolved, source, input.len(), input.is_closed(), || {
        noise.correlation()
    });
    drop(noise);
    drop(xy);
    resolved.measured_noise = Some(sigma);
    let outcome = if let Some(note) = unchanged {
        Outcome {
            points: input.points().to_vec(),
            status: FairStatus::NoChange,
            notes: vec![note],
            ..Outcome::default()
        }
    } else {
        let s = guard::method_scale(input);
        let run = |options: &FairOptions| -> Result<Outcome> {
            let run_options = match before {
                Some(before) => guard::per_move_options(options, before),
                None => options.clone(),
            };
            if s == 1.0 {
                m.run(input, &run_options)
            } else {
                let (unit, unit_options) = guard::to_unit(m, input, &run_options, s)?;
                let mut outcome = m.run(&unit, &unit_options)?;
                guard::from_unit(m, &mut outcome, s)?;
                Ok(outcome)
            }
        };
        let edge = |o: &Outcome| o.pressed;
        let (mut outcome, note) = run_widening(&mut resolved, source, input.len(), edge, run)?;
        outcome.notes.extend(note);
        outcome
    };
    Ok(Ran {
        outcome,
        options: resolved,
        start,
        source,
        sigma,
    })
}

/// The smallest automatic tolerance, relative to the bounding-box diagonal: below it the
/// noise estimate is rounding noise, and `k·σ̂` is raised to it so that the tolerance stays
/// a positive number a method can scale by.
const AUTO_TOLERANCE_FLOOR_REL: f64 = 1e-12;

/// Above this lag-one correlation of the noise estimate's differences
/// ([`difference_correlation`]) `--tolerance auto` finds no noise in the input. Independent
/// noise gives −0.83 (fifth differences); on the quality benchmark's 360 noisy test curves
/// (30 to 1000 points, noise 0.1 to 1 % of the diagonal) the largest value was −0.04 (1000
/// points at 0.1 %: there the curve's own differences weigh most), while exact samples of the
/// bundled sine, clothoid and strophoid give 0.90 to 1.0. Exact samples whose differences are
/// rounding (an arc, a cubic) give about −0.8, and their σ̂, at the level of rounding, moves
/// nothing anyway.
pub(crate) const NO_NOISE_CORRELATION: f64 = 0.5;

/// For an automatic tolerance: when the points show no noise (their noise estimate's
/// differences vary smoothly along the curve, [`NO_NOISE_CORRELATION`]), the note that says
/// so. σ̂ then measures the curve's own shape, and a band of `k·σ̂` would only move a clean
/// curve towards the energy's optimum (the bundled `sine-truth.csv`: its curvature error
/// against the truth went from 0.0059 to 0.0093, its end inflections lost).
fn no_noise(correlation: Option<f64>) -> Option<String> {
    let r = correlation?;
    (r > NO_NOISE_CORRELATION).then(|| {
        format!(
            "--tolerance auto found no noise: the differences it measures the noise by vary \
             smoothly along the curve (lag-one correlation {r:.2}; noise gives -0.83), so they \
             are the curve's own shape and nothing was moved; give --tolerance to fair the \
             curve within a distance of your choice"
        )
    })
}

/// Points that may press the band's edge before an automatic tolerance is taken as too
/// narrow: at least this many, and at least [`EDGE_ALLOWANCE_FRACTION`] of the points.
const EDGE_ALLOWANCE_MIN: usize = 2;
/// See [`EDGE_ALLOWANCE_MIN`].
const EDGE_ALLOWANCE_FRACTION: f64 = 0.003;
/// The factor by which each round widens an automatic tolerance.
const WIDEN_FACTOR: f64 = 1.2;
/// The most rounds of widening (`1.2¹⁰ ≈ 6.2`).
const MAX_WIDENINGS: i32 = 10;

/// Run the method (`run`) with `options`, and for an automatic tolerance check the result
/// against the noise model the tolerance came from. `k·σ̂` with `k = √(2 ln n)` leaves
/// about one true point outside the band for Gaussian noise of the same σ in every
/// direction, so a fit near the truth touches the band's edge at a point or two (`edge`
/// says how many, for methods that fit back towards the data inside a band:
/// [`Outcome::pressed`]). Where it presses the edge at more than `max(2, 0.3 % of the
/// points)`, the model is wrong for these data (noise with heavier tails than Gaussian's,
/// outliers, or noise in one direction, whose part along the curve the estimate along the
/// normal does not see), and the band forces the curve towards the noise: the tolerance is
/// widened by 1.2 and the method run again, at most 10 times. `options` keeps the tolerance
/// used; the note says what was widened and why.
fn run_widening<O>(
    options: &mut FairOptions,
    source: Option<ToleranceSource>,
    n: usize,
    edge: impl Fn(&O) -> Option<usize>,
    mut run: impl FnMut(&FairOptions) -> Result<O>,
) -> Result<(O, Option<String>)> {
    let mut outcome = run(options)?;
    let (Some(ToleranceSource::Auto), Some(first)) = (source, options.tolerance) else {
        return Ok((outcome, None));
    };
    let allowance = EDGE_ALLOWANCE_MIN.max((EDGE_ALLOWANCE_FRACTION * n as f64) as usize);
    let Some(pressed) = edge(&outcome).filter(|&e| e > allowance) else {
        return Ok((outcome, None));
    };
    let mut rounds = 0;
    while rounds < MAX_WIDENINGS && edge(&outcome).is_some_and(|e| e > allowance) {
        rounds += 1;
        options.tolerance = Some(first * WIDEN_FACTOR.powi(rounds));
        outcome = run(options)?;
    }
    let last = options.tolerance.unwrap_or(first);
    let now = edge(&outcome).unwrap_or(0);
    let note = format!(
        "--tolerance auto widened k·σ̂ = {first:.6e} to {last:.6e} ({WIDEN_FACTOR}^{rounds}): \
         {pressed} points pressed the band's edge where Gaussian noise of the estimated size \
         allows {allowance} (noise with heavier tails, outliers, or noise in one direction); \
         {now} press it now (see docs/algorithms/band.md, The tolerance)"
    );
    Ok((outcome, Some(note)))
}

/// Why the input comes back as it is without running the method, if it does: every point
/// held ([`all_held`]), or an automatic tolerance that finds no noise ([`no_noise`];
/// `correlation` gives the noise differences' correlation, asked for only then).
fn left_as_is(
    options: &FairOptions,
    source: Option<ToleranceSource>,
    n: usize,
    closed: bool,
    correlation: impl FnOnce() -> Option<f64>,
) -> Option<String> {
    all_held(options, n, closed).or_else(|| {
        (source == Some(ToleranceSource::Auto))
            .then(|| no_noise(correlation()))
            .flatten()
    })
}

/// When `fix_ends` holds every point of an open curve of `n` points: the note that says so
/// (nothing may move, the input is returned unchanged).
fn all_held(options: &FairOptions, n: usize, closed: bool) -> Option<String> {
    let held = options.fix_ends.held();
    (!closed && 2 * held >= n).then(|| {
        format!(
            "--fix-ends={} holds {held} points at each end, so all {n} points stay",
            options.fix_ends
        )
    })
}

/// The options with the tolerance the run uses, and where it came from: the given one, or
/// `k·σ̂` when [`FairOptions::auto_tolerance`] is set (or the method defaults to it) and no
/// tolerance was given. `diagonal` (the bounding box's) and `n` are the input's.
fn resolve_tolerance(
    m: &dyn FairMethod,
    options: &FairOptions,
    sigma: f64,
    diagonal: f64,
    n: usize,
) -> Result<(FairOptions, Option<ToleranceSource>)> {
    let mut resolved = options.clone();
    if options.tolerance.is_some() {
        return Ok((resolved, Some(ToleranceSource::Given)));
    }
    if !(options.auto_tolerance || m.auto_tolerance_by_default()) {
        return Ok((resolved, None));
    }
    let k = m.auto_tolerance_factor(options, n)?;
    let floor = AUTO_TOLERANCE_FLOOR_REL * diagonal.max(f64::MIN_POSITIVE);
    resolved.tolerance = Some((k * sigma).max(floor));
    resolved.auto_tolerance = false;
    Ok((resolved, Some(ToleranceSource::Auto)))
}

/// The change of the discrete end tangents and curvatures from `input` to `output` (open
/// curves of at least three points): the direction of the end chords and the signed
/// curvature of the circle through the three end points.
fn end_changes(input: &PointSeq, output: &PointSeq) -> Option<EndChanges> {
    let (a, b) = (input.points(), output.points());
    let n = a.len();
    if input.is_closed() || n < 3 {
        return None;
    }
    let angle = |u: Vec2, v: Vec2| u.cross(v).atan2(u.dot(v)).abs();
    let menger = |p: Point, q: Point, r: Point| {
        let (u, v, w) = (q - p, r - q, r - p);
        2.0 * u.cross(v) / (u.length() * v.length() * w.length())
    };
    Some(EndChanges {
        tangent_angle: [
            angle(a[1] - a[0], b[1] - b[0]),
            angle(a[n - 1] - a[n - 2], b[n - 1] - b[n - 2]),
        ],
        curvature: [
            menger(b[0], b[1], b[2]) - menger(a[0], a[1], a[2]),
            menger(b[n - 3], b[n - 2], b[n - 1]) - menger(a[n - 3], a[n - 2], a[n - 1]),
        ],
    })
}

/// Fair a B-spline curve with the method called `name` (B-spline in, B-spline out: knots and
/// degree kept). Only methods that work on control points accept it (`salvi`,
/// `eck-hadenfeld`); [`Faired::curve`] is the faired curve, and [`Faired::points`] the faired
/// curve at the input curve's Greville abscissae, which the report's displacements and metrics
/// are measured on.
///
/// # Errors
/// As [`fair`]; [`Error::InvalidParameter`] for a method that takes point input only.
pub fn fair_curve(name: &str, curve: &BSplineCurve, options: &FairOptions) -> Result<Faired> {
    let m = method(name)?;
    check_options(m, false, options)?;
    if options.tolerance.is_none() && options.auto_tolerance {
        return Err(Error::InvalidParameter {
            name: "tolerance".into(),
            reason:
                "auto takes its noise estimate from points; give a tolerance for a B-spline curve"
                    .into(),
        });
    }
    let source = options.tolerance.map(|_| ToleranceSource::Given);
    let start = Instant::now();
    let Some(run) = m.run_curve(curve, options) else {
        let takes: Vec<&str> = REGISTRY
            .iter()
            .filter(|x| x.run_curve_supported())
            .map(|x| x.name())
            .collect();
        return Err(Error::InvalidParameter {
            name: "input".into(),
            reason: format!(
                "method {} takes points, not a B-spline curve (B-spline input: {})",
                m.name(),
                takes.join(", ")
            ),
        });
    };
    let (input, outcome) = run?;
    let unit_scale = crate::geom::unit_scale(input.points());
    let before = FairnessMetrics::of_seq(&in_unit(&input, unit_scale))?;
    finish(
        m,
        (&input, Some(curve)),
        (before, unit_scale),
        options,
        outcome,
        start,
        (source, None),
        |_| (),
    )
    .map(|(faired, (), _)| faired)
}

/// `seq` divided by `s` (exact: `s` is a power of two).
fn in_unit(seq: &PointSeq, s: f64) -> Cow<'_, PointSeq> {
    if s == 1.0 {
        return Cow::Borrowed(seq);
    }
    Cow::Owned(seq.scaled_to_unit(1.0 / s))
}

/// The common part of every report: the clean-curve guard, displacements, metrics after,
/// the tolerance verdict. `before` is measured on the input divided by `unit_scale`, and
/// `curve` is the input curve of [`fair_curve`].
#[allow(clippy::too_many_arguments)]
fn finish<T: Send>(
    m: &dyn FairMethod,
    (input, curve): (&PointSeq, Option<&BSplineCurve>),
    (before, unit_scale): (FairnessMetrics, f64),
    options: &FairOptions,
    mut outcome: Outcome,
    start: Instant,
    (tolerance_source, noise_sigma): (Option<ToleranceSource>, Option<f64>),
    beside: impl FnOnce(Provisional<'_>) -> T + Send,
) -> Result<(Faired, T, bool)> {
    let elapsed = start.elapsed();
    if outcome.points.len() != input.len() {
        return Err(Error::LengthMismatch {
            what: "faired points",
            got: outcome.points.len(),
            expected: input.len(),
        });
    }
    // The result checked as a point sequence and measured, beside `beside`.
    let measure = || -> Result<(PointSeq, FairnessMetrics)> {
        let faired = input.with_points(outcome.points.clone())?;
        let after = FairnessMetrics::of_seq(&in_unit(&faired, unit_scale))?;
        Ok((faired, after))
    };
    let provisional = Provisional {
        points: &outcome.points,
        curve: outcome.curve.as_ref(),
        tangents: outcome.tangents.as_deref(),
    };
    let (measured, side) = beside_if_long(input.len(), measure, || beside(provisional));
    let (mut faired, mut after) = measured?;
    let mut kept = true;
    if options.keep_clean
        && m.keeps_clean()
        && let Some(why) = guard::worse(&before, &after)
    {
        outcome = Outcome {
            points: input.points().to_vec(),
            status: FairStatus::NoChange,
            iterations: outcome.iterations,
            history: outcome.history,
            parameters: outcome.parameters,
            notes: {
                let mut notes = outcome.notes;
                notes.push(guard::guard_note(&why));
                notes
            },
            curve: curve.cloned(),
            ..Outcome::default()
        };
        faired = input.clone();
        after = before.clone();
        kept = false;
    }
    let (before, after) = (before.rescaled(unit_scale), after.rescaled(unit_scale));
    let end_changes = end_changes(input, &faired);
    let disp = displacement(input.points(), &outcome.points)?;
    let mut status = outcome.status;
    let mut notes = outcome.notes;
    let tolerance_met = verdict(
        options,
        input.is_closed(),
        disp.max,
        &mut status,
        &mut notes,
    );
    let fixed_ends = if input.is_closed() {
        options.fix_ends
    } else {
        options.fix_ends.max(outcome.ends_held.unwrap_or_default())
    };
    let report = FairReport {
        method: m.name().to_string(),
        status,
        iterations: outcome.iterations,
        moved_points: disp.moved,
        moves: outcome.moves,
        max_displacement: disp.max,
        max_displacement_index: disp.argmax,
        sum_displacement: disp.sum,
        tolerance: options.tolerance,
        tolerance_source,
        noise_sigma,
        tolerance_met,
        fix_ends: fixed_ends.is_fixed(),
        fixed_ends,
        end_changes,
        before,
        after,
        elapsed_seconds: elapsed.as_secs_f64(),
        parameters: outcome.parameters,
        history: outcome.history,
        solver: outcome.solver,
        notes,
    };
    let faired = Faired {
        points: outcome.points,
        report,
        curve: outcome.curve,
        tangents: outcome.tangents,
    };
    Ok((faired, side, kept))
}

/// The tolerance verdict every report shares: whether the largest displacement `max` is
/// within the tolerance (always without one); when not, the status becomes
/// `tolerance_exceeded` and a note says by how much. A note also says that `fix_ends` does
/// nothing on a closed curve.
fn verdict(
    options: &FairOptions,
    closed: bool,
    max: f64,
    status: &mut FairStatus,
    notes: &mut Vec<String>,
) -> bool {
    let met = options.tolerance.is_none_or(|d| max <= d);
    if closed && options.fix_ends.is_fixed() {
        notes.push("fix_ends has no effect on a closed curve (it has no ends)".to_string());
    }
    if !met {
        *status = FairStatus::ToleranceExceeded;
        notes.push(format!(
            "the largest displacement {:.6e} exceeds the tolerance {:.6e}",
            max,
            options.tolerance.unwrap_or(f64::NAN)
        ));
    }
    met
}

/// Scale a proposed set of moves back so that no point ends farther than `tolerance` from its
/// original position: each point `p` becomes `orig + (p − orig)·min(1, tolerance/|p − orig|)`.
/// Returns the number of points that were pulled back. Shared by the methods that honour the
/// tolerance as a hard bound point by point.
pub fn clamp_to_tolerance(original: &[Point], points: &mut [Point], tolerance: f64) -> usize {
    let mut clamped = 0;
    for (p, o) in points.iter_mut().zip(original) {
        let d = *p - *o;
        let len = d.length();
        if len > tolerance {
            *p = *o + d * (tolerance / len);
            clamped += 1;
        }
    }
    clamped
}
