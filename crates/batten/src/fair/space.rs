//! Fairing space curves: the methods that work in any dimension (`band`, `mst`) on a
//! [`SpaceSeq`], with the same hard tolerance, now in 3-D distance.
//!
//! The other methods are planar by nature (signed curvature, inflections, a plane's normal)
//! and refuse a space curve with [`Error::PlanarOnly`].

use serde::Serialize;
use serde_json::{Map, Value};

use std::time::Instant;

use super::{
    EndFix, FairMethod, FairOptions, FairStatus, HistoryRow, Outcome, Ran, SolverInfo,
    ToleranceSource, guard,
};
use crate::analysis::{Displacement, NoiseMeasure, SpaceMetrics, Spread};
use crate::error::{Error, Result};
use crate::geom::{SpaceSeq, Xyz, unit_scale_xyz};

/// What a method computed on a space curve, before the common parts of the report.
#[derive(Clone, Debug, Default)]
#[non_exhaustive]
pub struct SpaceOutcome {
    /// The faired points: same count and order as the input.
    pub points: Vec<Xyz>,
    /// How the run ended.
    pub status: FairStatus,
    /// Iterations (as the method documents).
    pub iterations: usize,
    /// A per-iteration trace of the method's own measure.
    pub history: Vec<HistoryRow>,
    /// Parameters as actually used.
    pub parameters: Map<String, Value>,
    /// Things the user should know.
    pub notes: Vec<String>,
    /// The solver's figures (`band`).
    pub solver: Option<SolverInfo>,
    /// As [`Outcome::pressed`].
    pub pressed: Option<usize>,
}

/// The report of fairing a space curve: the planar report's keys that make sense in space,
/// with [`SpaceMetrics`] before and after, and `"dimension": 3`.
#[derive(Clone, Debug, Serialize)]
#[non_exhaustive]
pub struct SpaceFairReport {
    /// Always 3.
    pub dimension: usize,
    /// Method name.
    pub method: String,
    /// How it ended.
    pub status: FairStatus,
    /// Iterations performed (the method's unit).
    pub iterations: usize,
    /// Indices (0-based) of the points whose position changed, increasing.
    pub moved_points: Vec<usize>,
    /// Largest point displacement (3-D distance).
    pub max_displacement: f64,
    /// Index of the point with the largest displacement.
    pub max_displacement_index: usize,
    /// Sum of point displacements.
    pub sum_displacement: f64,
    /// The tolerance used, if any.
    pub tolerance: Option<f64>,
    /// Where the tolerance came from.
    pub tolerance_source: Option<ToleranceSource>,
    /// The noise estimate σ̂ of the input points.
    pub noise_sigma: Option<f64>,
    /// True when no point moved farther than the tolerance (always true without one).
    pub tolerance_met: bool,
    /// Whether end points were held.
    pub fix_ends: bool,
    /// What was kept at the ends.
    pub fixed_ends: EndFix,
    /// Metrics of the input.
    pub before: SpaceMetrics,
    /// Metrics of the result.
    pub after: SpaceMetrics,
    /// Wall-clock time of the method itself, in seconds.
    pub elapsed_seconds: f64,
    /// Parameters as used.
    pub parameters: Map<String, Value>,
    /// Per-iteration trace.
    pub history: Vec<HistoryRow>,
    /// The solver's figures (`band`).
    pub solver: Option<SolverInfo>,
    /// Remarks for the user.
    pub notes: Vec<String>,
}

/// The result of [`fair_space`].
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct FairedSpace {
    /// The faired points, same count and order as the input.
    pub points: Vec<Xyz>,
    /// What was done.
    pub report: SpaceFairReport,
}

impl SpaceOutcome {
    /// The space outcome of a method that computed its points in any dimension and filled
    /// the rest into a planar [`Outcome`] (whose points and planar-only parts are dropped).
    pub(crate) fn from_parts(points: Vec<Xyz>, o: Outcome) -> SpaceOutcome {
        SpaceOutcome {
            points,
            status: o.status,
            iterations: o.iterations,
            history: o.history,
            parameters: o.parameters,
            notes: o.notes,
            solver: o.solver,
            pressed: o.pressed,
        }
    }
}

/// Fair a space curve with the method called `name` (`band` or `mst`): the space counterpart
/// of [`super::fair`], with the same contract (ARCHITECTURE.md, "The fairing contract"):
/// the options checked, the tolerance given or `k·σ̂` ([`crate::analysis::noise_sigma_space`]),
/// the method run on coordinates divided by a power of two when their scale is extreme,
/// every point held → the input unchanged, the clean-curve guard on [`SpaceMetrics`]
/// (curvature extrema, torsion sign changes, variation energy; not for `mst`), and
/// displacements measured as 3-D distances by `hypot`, by which `max_displacement ≤
/// tolerance` is checked.
///
/// # Errors
/// [`Error::UnknownMethod`], [`Error::PlanarOnly`] for a planar method, the option errors of
/// [`super::check_options`], the method's own errors.
pub fn fair_space(name: &str, input: &SpaceSeq, options: &FairOptions) -> Result<FairedSpace> {
    let m = super::method(name)?;
    if !m.run_space_supported() {
        return Err(planar_only(name));
    }
    super::check_options(m, input.is_closed(), options)?;
    let unit_scale = unit_scale_xyz(input.points());
    // The input's measures and the method are independent (no space method checks single
    // moves).
    let (before, ran) = super::measures_beside(
        m,
        input.len(),
        || std::borrow::Cow::Owned(scaled_seq(input, 1.0 / unit_scale)),
        |scaled: &Result<SpaceSeq>| SpaceMetrics::of_seq(scaled.as_ref().map_err(Clone::clone)?),
        || run_method(m, input, options, unit_scale),
    );
    let before = before?;
    let Ran {
        outcome,
        options,
        start,
        source,
        sigma,
    } = ran?;
    finish_space(
        m,
        input,
        (before, unit_scale),
        &options,
        outcome,
        start,
        (source, sigma),
    )
}

/// The noise estimate, the tolerance and the method's run on `input` (widened where an
/// automatic tolerance proves too narrow), unless the input is to be left as it is;
/// `unit_scale` is the input's ([`unit_scale_xyz`]).
fn run_method(
    m: &dyn FairMethod,
    input: &SpaceSeq,
    options: &FairOptions,
    unit_scale: f64,
) -> Result<Ran<SpaceOutcome>> {
    let start = Instant::now();
    let closed = input.is_closed();
    let noise = NoiseMeasure::of(input.points(), closed);
    let sigma = noise.sigma(Spread::of_space(input.points()));
    let (mut resolved, source) =
        super::resolve_tolerance(m, options, sigma, input.scale(), input.len())?;
    let unchanged = super::left_as_is(&resolved, source, input.len(), closed, || {
        noise.correlation()
    });
    drop(noise);
    resolved.measured_noise = Some(sigma);
    let outcome = if let Some(note) = unchanged {
        SpaceOutcome {
            points: input.points().to_vec(),
            status: FairStatus::NoChange,
            notes: vec![note],
            ..SpaceOutcome::default()
        }
    } else {
        let s = guard::method_scale_of(unit_scale);
        let run_once = |options: &FairOptions| -> Result<SpaceOutcome> {
            if s == 1.0 {
                run(m, input, options)
            } else {
                let unit_options = guard::unit_options(m, options, s)?;
                let mut o = run(m, &scaled_seq(input, 1.0 / s)?, &unit_options)?;
                o.points = scale_xyz(&o.points, s);
                guard::trace_from_unit(m, &mut o.history, &mut o.parameters, &mut o.notes, s);
                Ok(o)
            }
        };
        let edge = |o: &SpaceOutcome| o.pressed;
        let (mut outcome, note) =
            super::run_widening(&mut resolved, source, input.len(), edge, run_once)?;
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

/// [`FairMethod::run_space`], or [`Error::PlanarOnly`] where the method has none.
fn run(m: &dyn FairMethod, input: &SpaceSeq, options: &FairOptions) -> Result<SpaceOutcome> {
    m.run_space(input, options)
        .unwrap_or_else(|| Err(planar_only(m.name())))
}

fn planar_only(name: &str) -> Error {
    Error::PlanarOnly {
        method: name.to_string(),
    }
}

/// The common part of the report, as the planar path's: the clean-curve guard,
/// displacements, metrics after, the tolerance verdict. `before` is measured on the input
/// divided by `unit_scale`.
fn finish_space(
    m: &dyn FairMethod,
    input: &SpaceSeq,
    (before, unit_scale): (SpaceMetrics, f64),
    options: &FairOptions,
    mut outcome: SpaceOutcome,
    start: Instant,
    (tolerance_source, noise_sigma): (Option<ToleranceSource>, f64),
) -> Result<FairedSpace> {
    let elapsed = start.elapsed();
    if outcome.points.len() != input.len() {
        return Err(Error::LengthMismatch {
            what: "faired points",
            got: outcome.points.len(),
            expected: input.len(),
        });
    }
    let faired = input.with_points(outcome.points.clone())?;
    let mut after = SpaceMetrics::of_seq(&scaled_seq(&faired, 1.0 / unit_scale)?)?;
    if options.keep_clean
        && m.keeps_clean()
        && let Some(why) = guard::worse_space(&before, &after)
    {
        outcome.points = input.points().to_vec();
        outcome.status = FairStatus::NoChange;
        outcome.solver = None;
        outcome.notes.push(guard::guard_note(&why));
        after = before.clone();
    }
    let disp = displacement_space(input.points(), &outcome.points);
    let mut status = outcome.status;
    let mut notes = outcome.notes;
    let tolerance_met = super::verdict(
        options,
        input.is_closed(),
        disp.max,
        &mut status,
        &mut notes,
    );
    let report = SpaceFairReport {
        dimension: 3,
        method: m.name().to_string(),
        status,
        iterations: outcome.iterations,
        moved_points: disp.moved,
        max_displacement: disp.max,
        max_displacement_index: disp.argmax,
        sum_displacement: disp.sum,
        tolerance: options.tolerance,
        tolerance_source,
        noise_sigma: Some(noise_sigma),
        tolerance_met,
        fix_ends: options.fix_ends.is_fixed(),
        fixed_ends: options.fix_ends,
        before: before.rescaled(unit_scale),
        after: after.rescaled(unit_scale),
        elapsed_seconds: elapsed.as_secs_f64(),
        parameters: outcome.parameters,
        history: outcome.history,
        solver: outcome.solver,
        notes,
    };
    Ok(FairedSpace {
        points: outcome.points,
        report,
    })
}

/// The 3-D distance the contract measures displacements by: `hypot` over the coordinates, as
/// `band` measures its band (so its guarantee holds by this measure), and in the plane
/// `z = 0` the planar [`crate::geom::Point::distance`] bit for bit.
pub(crate) fn distance(a: &Xyz, b: &Xyz) -> f64 {
    (a[0] - b[0]).abs().hypot(a[1] - b[1]).hypot(a[2] - b[2])
}

/// The displacements from `a` to `b` (equal lengths), as [`crate::analysis::displacement`]
/// gives them for planar points.
fn displacement_space(a: &[Xyz], b: &[Xyz]) -> Displacement {
    let d: Vec<f64> = a.iter().zip(b).map(|(p, q)| distance(p, q)).collect();
    let (argmax, max) = d.iter().enumerate().fold(
        (0, 0.0),
        |(i, m), (j, &v)| if v > m { (j, v) } else { (i, m) },
    );
    Displacement {
        max,
        argmax,
        sum: d.iter().fold(0.0, |s, v| s + v),
        moved: (0..d.len()).filter(|&i| d[i] > 0.0).collect(),
    }
}

/// The points multiplied by `factor` (exact for a power of two without over- or underflow).
fn scale_xyz(points: &[Xyz], factor: f64) -> Vec<Xyz> {
    points.iter().map(|p| p.map(|c| c * factor)).collect()
}

/// `seq` multiplied by `factor`.
fn scaled_seq(seq: &SpaceSeq, factor: f64) -> Result<SpaceSeq> {
    if factor == 1.0 {
        return Ok(seq.clone());
    }
    seq.with_points(scale_xyz(seq.points(), factor))
}

/// The methods that fair space curves: those that implement [`FairMethod::run_space`]
/// (checked against the registry by a test).
pub const SPACE_METHODS: &[&str] = &["band", "mst"];

/// [`Error::PlanarOnly`] unless `name` fairs space curves ([`FairMethod::run_space`]);
/// [`Error::UnknownMethod`] for a name that is no method.
///
/// # Errors
/// [`Error::PlanarOnly`], [`Error::UnknownMethod`].
pub fn check_space_method(name: &str) -> Result<()> {
    if super::method(name)?.run_space_supported() {
        Ok(())
    } else {
        Err(planar_only(name))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn space_methods_are_the_registry_s() {
        let registered: Vec<&str> = super::super::methods()
            .iter()
            .filter(|m| m.run_space_supported())
            .map(|m| m.name())
            .collect();
        assert_eq!(registered, SPACE_METHODS);
        for m in super::super::methods() {
            assert_eq!(
                check_space_method(m.name()).is_ok(),
                SPACE_METHODS.contains(&m.name())
            );
        }
        assert!(matches!(
            check_space_method("nope"),
            Err(Error::UnknownMethod { .. })
        ));
    }
}
