//! The comparison protocol of Han et al. (their Table 1): several methods on one curve, the
//! smoothing spline `mst` at the largest displacement of the first. [`compare`] runs it; the
//! CLI's `batten compare` and `batten report` tabulate its rows.

use rayon::prelude::*;

use super::{FairMethod, FairOptions, FairReport, Faired, fair_with};
use crate::error::Error;
use crate::geom::PointSeq;
use crate::io::format_sig;

/// The method run at the first method's largest displacement: the smoothing spline.
const BASELINE: &str = "mst";

/// Significant digits of the tolerance written in the baseline's note.
const NOTE_DIGITS: usize = 4;

/// The result of [`compare`]: one row per method, in the order given.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct Comparison {
    /// The rows, in the order the methods were given.
    pub rows: Vec<ComparisonRow>,
}

impl Comparison {
    /// The methods that failed, with their errors, in order.
    pub fn failures(&self) -> impl Iterator<Item = (&'static str, &Error)> {
        self.rows.iter().filter_map(|row| match &row.outcome {
            ComparisonOutcome::Failed(e) => Some((row.method, e)),
            _ => None,
        })
    }
}

/// One method's run in a [`Comparison`].
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct ComparisonRow {
    /// The method's name ([`FairMethod::name`]).
    pub method: &'static str,
    /// The tolerance the method was given: the options' one, or for `mst` the first
    /// method's largest displacement.
    pub tolerance: Option<f64>,
    /// Why the method's options differ from the ones given, if they do (`mst`'s tolerance).
    pub note: Option<String>,
    /// How the run ended.
    pub outcome: ComparisonOutcome,
}

impl ComparisonRow {
    /// The faired points and report, when the method ran.
    pub fn faired(&self) -> Option<&Faired> {
        match &self.outcome {
            ComparisonOutcome::Ran(f) => Some(f),
            _ => None,
        }
    }

    /// The report, when the method ran.
    pub fn report(&self) -> Option<&FairReport> {
        self.faired().map(|f| &f.report)
    }
}

/// How one method's run in a [`Comparison`] ended. Exhaustive: a method runs, fails or is not
/// run, and a table has a way to show each.
#[derive(Clone, Debug)]
pub enum ComparisonOutcome {
    /// The method ran: the faired points and the report ([`fair_with`]'s result). A missed
    /// tolerance is a run; its report says so.
    Ran(Box<Faired>),
    /// The method returned an error.
    Failed(Error),
    /// The method was not run, and why (a closed curve for a method that fairs only open
    /// ones).
    Skipped(String),
}

/// Run `methods` on `input` with `options` and compare them as Han et al. do (Table 1): one
/// row per method, in the order given; an empty list gives an empty comparison.
///
/// A smoother curve costs displacement, so methods compare fairly only at the same
/// displacement. Han et al. run the smoothing spline at the largest displacement of their
/// method, and so does this: every method runs with `options`, except `mst` (the smoothing
/// spline) when another method is listed first. `mst` then runs with `tolerance` = that
/// method's largest displacement and no method parameters, which makes it search its
/// smoothing parameter for the smoothest spline within it ([`SmoothingSpline`](crate::fair::SmoothingSpline)), and its
/// row's [`note`](ComparisonRow::note) says so. When the first method fails, is skipped or
/// moves no point, `mst` runs with `options` and the note says why.
///
/// The first method runs first (`mst` waits for its displacement), then the others in
/// parallel (rayon). A method that cannot take the input (a closed curve for a method that
/// fairs only open ones) is [skipped](ComparisonOutcome::Skipped), and a method that fails is
/// a [row](ComparisonOutcome::Failed) too: one bad method does not stop the comparison.
/// `options.params` go to every method as [`fair_with`] takes them (a key a method does not
/// know fails its row), except to `mst` at the first method's displacement.
///
/// ```
/// use batten::fair::{self, FairMethod};
/// use batten::{FairOptions, Point, PointSeq};
///
/// let pts: Vec<Point> = (0..60)
///     .map(|i| {
///         let x = 0.1 * i as f64;
///         Point::new(x, x.sin() + 0.01 * ((i * 7919 % 13) as f64 / 6.0 - 1.0))
///     })
///     .collect();
/// let input = PointSeq::open(pts)?;
/// let methods: Vec<&dyn FairMethod> = vec![fair::method("han")?, fair::method("mst")?];
/// let table = fair::compare(&methods, &input, &FairOptions::default());
/// let (Some(han), Some(mst)) = (table.rows[0].report(), table.rows[1].report()) else {
///     panic!("both ran");
/// };
/// // mst ran at han's largest displacement, and stayed within it.
/// assert_eq!(table.rows[1].tolerance, Some(han.max_displacement));
/// assert!(mst.max_displacement <= han.max_displacement);
/// # Ok::<(), batten::Error>(())
/// ```
pub fn compare(methods: &[&dyn FairMethod], input: &PointSeq, options: &FairOptions) -> Comparison {
    let Some((&first, rest)) = methods.split_first() else {
        return Comparison { rows: Vec::new() };
    };
    if first.name() == BASELINE || !rest.iter().any(|m| m.name() == BASELINE) {
        let rows = methods
            .par_iter()
            .map(|&m| run_one(m, input, options.clone(), None))
            .collect();
        return Comparison { rows };
    }
    let first_row = run_one(first, input, options.clone(), None);
    let (baseline_options, baseline_note) = match first_row.report() {
        Some(r) if r.max_displacement > 0.0 => {
            let mut o = options.clone();
            o.tolerance = Some(r.max_displacement);
            o.params.clear();
            let note = format!(
                "run at tolerance {}, the max displacement of {} (as in Han et al.)",
                format_sig(r.max_displacement, NOTE_DIGITS),
                first.name()
            );
            (o, note)
        }
        Some(_) => (
            options.clone(),
            format!(
                "{} moved no point, so {BASELINE} ran with the options given",
                first.name()
            ),
        ),
        None => (
            options.clone(),
            format!(
                "{} did not run, so {BASELINE} ran with the options given",
                first.name()
            ),
        ),
    };
    let mut rows = vec![first_row];
    rows.par_extend(rest.par_iter().map(|&m| {
        if m.name() == BASELINE {
            run_one(
                m,
                input,
                baseline_options.clone(),
                Some(baseline_note.clone()),
            )
        } else {
            run_one(m, input, options.clone(), None)
        }
    }));
    Comparison { rows }
}

/// One method's row: skipped for a closed curve it cannot take, else run.
fn run_one(
    m: &dyn FairMethod,
    input: &PointSeq,
    options: FairOptions,
    note: Option<String>,
) -> ComparisonRow {
    let outcome = if input.is_closed() && !m.supports_closed() {
        ComparisonOutcome::Skipped("does not support closed curves".to_string())
    } else {
        match fair_with(m, input, &options) {
            Ok(f) => ComparisonOutcome::Ran(Box::new(f)),
            Err(e) => ComparisonOutcome::Failed(e),
        }
    };
    ComparisonRow {
        method: m.name(),
        tolerance: options.tolerance,
        note,
        outcome,
    }
}
