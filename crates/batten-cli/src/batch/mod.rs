//! `batten batch`: fair many point files in parallel into one output directory.
//!
//! Every check that does not need the curves runs first, so a usage error leaves nothing
//! behind: the method, the options, the summary's format and directory, the input list, the
//! output names (two inputs may not write the same file) and the output directory (never an
//! input's directory). Then each file is read, faired and written on its own: a file that
//! fails is a row of the summary and a line on stderr, not the end of the batch.
//!
//! Parameter values (`--set p=2`) are among those first checks (`FairMethod::check_params`).
//! Only the few ranges that depend on the data (`control_points` at most the number of
//! points) are checked per file, when the method runs. A file that fails writes nothing, and
//! does not remove what an earlier run wrote under its name: the summary tells which results
//! are from this run.
//!
//! A DXF file gives one row per curve entity (`FILE#HANDLE`) and one DXF back, each faired
//! entity replaced in place ([`batten::io::DxfDrawing`]), with a list of reports.
//!
//! Exit codes: 0 when every file was faired within its tolerance; 2 when an input was
//! unreadable or invalid (or on a usage error); otherwise 1 when a fairing failed, missed its
//! tolerance, or an output could not be written.

use std::collections::HashMap;
use std::ffi::OsString;
use std::fmt::Write as _;
use std::fs;
use std::io::IsTerminal as _;
use std::panic::{self, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::{Arc, Mutex};

use anyhow::anyhow;
use batten::FairOptions;
use batten::fair::{self, FairMethod, FairReport, SpaceFairReport};
use batten::io::{self, Format, IoError, ReadOptions, Source, SpaceData, format_f64};
use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use serde::Serialize;

use crate::compare::{csv_field, csv_num};
use crate::failure::{EXIT_FAILED, EXIT_USAGE, Failure};
use crate::output::{self, sig};
use crate::{fair_cmd, input, signals};

/// Significant digits of displacements in messages.
const DIGITS: usize = 4;

/// Most files faired at once (`--jobs`): each is a thread with its own curve in memory, and
/// thousands of threads only cost time to start (30000 took minutes for one file).
const MAX_JOBS: usize = 1024;

/// `--jobs N` (clap value parser): 1 to [`MAX_JOBS`].
fn parse_jobs(s: &str) -> Result<usize, String> {
    input::parse_count(s, MAX_JOBS)
}

/// Suffix of the report written beside each output: `NAME.csv` → `NAME.report.json`.
const REPORT_SUFFIX: &str = ".report.json";

/// Arguments of `batten batch`.
#[derive(Debug, Args)]
pub struct BatchArgs {
    /// Point files, directories (their .csv, .txt, .json, .dxf, .igs and .svg files, by name;
    /// not recursive), or quoted patterns with * and ? in the file name ("hull/frame-*.csv").
    /// A DXF file is faired entity by entity into one DXF
    #[arg(value_name = "INPUT", required = true)]
    inputs: Vec<PathBuf>,
    /// Directory for the faired points (same file names and formats) and the reports
    /// (NAME.report.json); created if missing. Never an input's directory
    #[arg(short, long = "output", value_name = "OUT_DIR")]
    out_dir: PathBuf,
    #[command(flatten)]
    how: input::MethodArgs,
    #[command(flatten)]
    bounds: input::BoundArgs,
    /// Write one row per input, in input order (file, status, error, points, iterations,
    /// displacements, metrics before and after) to this .json or .csv file
    #[arg(long, value_name = "FILE")]
    summary: Option<PathBuf>,
    /// Files faired at once, 1 to 1024 and never more than the files [default: one per core;
    /// more can help where writes wait for a slow disk, as every file is synced]
    #[arg(long, value_name = "N", value_parser = parse_jobs)]
    jobs: Option<usize>,
}

/// How one input ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
enum Status {
    /// Faired within the tolerance; output and report written.
    Ok,
    /// Faired, but a point moved farther than the tolerance; output and report written.
    ToleranceExceeded,
    /// The method failed, or the output or report could not be written.
    Failed,
    /// The file could not be read, or its data or its closedness was rejected.
    InvalidInput,
    /// The batch was interrupted (SIGINT, SIGTERM) before this file finished; nothing of it
    /// was written. Only in the summary an interrupted batch leaves.
    Interrupted,
}

impl Status {
    /// The name used in the summary.
    fn name(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::ToleranceExceeded => "tolerance_exceeded",
            Status::Failed => "failed",
            Status::InvalidInput => "invalid_input",
            Status::Interrupted => "interrupted",
        }
    }
}

/// One input: where it is read from and where its results go.
#[derive(Clone, Debug)]
struct Job {
    input: PathBuf,
    output: PathBuf,
    report: PathBuf,
}

/// One row of the summary. Fields that are not known for a row (the metrics of a file that
/// could not be read) are `null` in JSON and empty in CSV.
#[derive(Clone, Debug, Serialize)]
struct Row {
    file: String,
    status: Status,
    error: Option<String>,
    points: Option<usize>,
    iterations: Option<usize>,
    max_displacement: Option<f64>,
    sum_displacement: Option<f64>,
    tolerance_met: Option<bool>,
    inflections_before: Option<usize>,
    inflections_after: Option<usize>,
    vibrations_before: Option<usize>,
    vibrations_after: Option<usize>,
    strain_energy_before: Option<f64>,
    strain_energy_after: Option<f64>,
    gfi_before: Option<f64>,
    gfi_after: Option<f64>,
    /// The larger of the two end chords' turns (radians; open curves).
    end_tangent_change: Option<f64>,
    /// The larger |change| of the two end curvatures (open curves).
    end_curvature_change: Option<f64>,
}

impl Row {
    /// A row with the given outcome; the numbers come from the report when there is one.
    fn new(
        job: &Job,
        status: Status,
        error: Option<String>,
        points: Option<usize>,
        report: Option<&FairReport>,
    ) -> Row {
        Row {
            file: job.input.display().to_string(),
            status,
            error,
            points,
            iterations: report.map(|r| r.iterations),
            max_displacement: report.map(|r| r.max_displacement),
            sum_displacement: report.map(|r| r.sum_displacement),
            tolerance_met: report.map(|r| r.tolerance_met),
            inflections_before: report.map(|r| r.before.inflections),
            inflections_after: report.map(|r| r.after.inflections),
            vibrations_before: report.map(|r| r.before.vibrations),
            vibrations_after: report.map(|r| r.after.vibrations),
            strain_energy_before: report.map(|r| r.before.strain_energy),
            strain_energy_after: report.map(|r| r.after.strain_energy),
            gfi_before: report.map(|r| r.before.gfi),
            gfi_after: report.map(|r| r.after.gfi),
            end_tangent_change: report
                .and_then(|r| r.end_changes)
                .map(|e| e.tangent_angle[0].max(e.tangent_angle[1])),
            end_curvature_change: report
                .and_then(|r| r.end_changes)
                .map(|e| e.curvature[0].abs().max(e.curvature[1].abs())),
        }
    }
}

/// Run `batten batch`.
///
/// # Errors
/// Usage errors found before any file is faired (exit 2); a failure to create the output
/// directory or to start the worker threads (exit 1). Problems with single files are not
/// errors: they are rows of the summary and decide the exit code.
pub fn run(args: &BatchArgs) -> Result<ExitCode, Failure> {
    let name = args
        .how
        .method
        .as_deref()
        .unwrap_or_else(|| fair::default_method());
    let method = input::method(name)?;
    let params = input::parse_sets(&args.how.set)?;
    let options = input::options(
        args.bounds.tolerance,
        args.bounds.fix_ends.unwrap_or_default(),
        args.how.max_iterations,
        params,
    );
    input::check(method, false, &options)?;
    let summary_format = match &args.summary {
        Some(path) => Some(summary_format(path)?),
        None => None,
    };

    let inputs = expand(&args.inputs)?;
    let jobs = plan(&inputs, &args.out_dir)?;
    check_out_dir(&jobs, &args.out_dir)?;
    if let Some(path) = &args.summary {
        check_summary(path, &jobs, &args.out_dir)?;
    }
    create_out_dir(&args.out_dir, args.summary.as_deref())?;

    let pool = rayon::ThreadPoolBuilder::new()
        // More threads than files would only idle.
        .num_threads(args.jobs.map_or(0, |n| n.min(jobs.len())))
        .build()
        .map_err(|e| Failure::failed(anyhow!("cannot start worker threads: {e}")))?;
    let bar = progress_bar(jobs.len());
    // The rows of the files that have finished (a DXF file gives one per curve), for the
    // summary an interrupt leaves.
    let finished: Arc<Mutex<Vec<Option<Vec<Row>>>>> = Arc::new(Mutex::new(vec![None; jobs.len()]));
    if let (Some(path), Some(format)) = (&args.summary, summary_format) {
        let (finished, jobs, path) = (Arc::clone(&finished), jobs.clone(), path.clone());
        signals::set_last_word(move || {
            let slots = std::mem::take(&mut *finished.lock().unwrap_or_else(|e| e.into_inner()));
            let done = slots.iter().filter(|r| r.is_some()).count();
            let files = slots.len();
            let rows: Vec<Row> = slots
                .into_iter()
                .zip(&jobs)
                .flat_map(|(rows, job)| {
                    rows.unwrap_or_else(|| {
                        let why = "batch interrupted before this file finished".to_string();
                        vec![Row::new(job, Status::Interrupted, Some(why), None, None)]
                    })
                })
                .collect();
            let text = match format {
                SummaryFormat::Json => summary_json(&rows),
                SummaryFormat::Csv => Ok(summary_csv(&rows)),
            };
            Some(
                match text
                    .and_then(|t| io::write_atomic(&path, t.as_bytes()).map_err(|e| e.to_string()))
                {
                    Ok(()) => format!(
                        "summary of the {done} of {} that finished written to {}, the others \
                         marked interrupted",
                        output::count(files, "file"),
                        path.display()
                    ),
                    Err(e) => format!("summary not written: {e}"),
                },
            )
        });
    }
    let rows: Vec<Row> = pool.install(|| {
        let per_job: Vec<Vec<Row>> = jobs
            .par_iter()
            .enumerate()
            .map(|(i, job)| {
                let rows = fair_one(job, method, &options);
                if let Some(slot) = finished
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .get_mut(i)
                {
                    *slot = Some(rows.clone());
                }
                bar.inc(1);
                rows
            })
            .collect();
        per_job.into_iter().flatten().collect()
    });
    bar.finish_and_clear();

    let summary_written = match (&args.summary, summary_format) {
        (Some(path), Some(format)) => {
            let text = match format {
                SummaryFormat::Json => summary_json(&rows),
                SummaryFormat::Csv => Ok(summary_csv(&rows)),
            };
            text.and_then(|t| io::write_atomic(path, t.as_bytes()).map_err(|e| e.to_string()))
        }
        _ => Ok(()),
    };
    for row in &rows {
        if let Some(message) = &row.error {
            output::error_line(message);
        }
    }
    signals::clear_last_word();
    let summary_failed = summary_written.is_err();
    if let Err(message) = summary_written {
        output::error_line(&message);
    }
    let count = |s: Status| rows.iter().filter(|r| r.status == s).count();
    let (ok, exceeded) = (count(Status::Ok), count(Status::ToleranceExceeded));
    let (failed, invalid) = (count(Status::Failed), count(Status::InvalidInput));
    // A DXF file gives a row per curve entity.
    let curves = if rows.len() == jobs.len() {
        String::new()
    } else {
        format!(", {} curves", rows.len())
    };
    output::note(&format!(
        "batch: {}{curves}: {ok} ok, {exceeded} tolerance exceeded, {failed} failed, \
         {invalid} invalid input; results in {}",
        output::count(jobs.len(), "file"),
        args.out_dir.display()
    ));
    Ok(if invalid > 0 {
        ExitCode::from(EXIT_USAGE)
    } else if exceeded > 0 || failed > 0 || summary_failed {
        ExitCode::from(EXIT_FAILED)
    } else {
        ExitCode::SUCCESS
    })
}

/// Create the output directory (and its parents) and check that a file can be written in it,
/// and that the summary can be written once the directory exists. On failure, every
/// directory this created is removed again: a usage error leaves nothing behind.
///
/// # Errors
/// [`Failure::usage`] (exit 2) naming the directory or the summary.
fn create_out_dir(out_dir: &Path, summary: Option<&Path>) -> Result<(), Failure> {
    // The first missing ancestor: what to remove if a check fails.
    let mut created = None;
    let mut p = out_dir;
    while !p.as_os_str().is_empty() && !p.exists() {
        created = Some(p.to_path_buf());
        p = p.parent().unwrap_or(Path::new(""));
    }
    let checked = fs::create_dir_all(out_dir)
        .map_err(|e| {
            Failure::usage(anyhow!(
                "{}: cannot write: cannot create the directory: {e}",
                out_dir.display()
            ))
        })
        .and_then(|()| {
            fair_cmd::check_writable(&out_dir.join("probe.json")).map_err(|_| {
                Failure::usage(anyhow!(
                    "{}: cannot write: no file can be created in the directory",
                    out_dir.display()
                ))
            })
        })
        .and_then(|()| summary.map_or(Ok(()), fair_cmd::check_writable));
    if checked.is_err()
        && let Some(top) = created
    {
        // Best effort: only directories this run created, and only when still empty.
        let mut d = out_dir.to_path_buf();
        while fs::remove_dir(&d).is_ok() && d != top {
            if !d.pop() {
                break;
            }
        }
    }
    checked
}

/// A progress bar on stderr, hidden when stderr is not a terminal (tests, CI, logs).
fn progress_bar(len: usize) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(
        Some(u64::try_from(len).unwrap_or(u64::MAX)),
        ProgressDrawTarget::stderr(),
    );
    if let Ok(style) =
        ProgressStyle::with_template("{bar:40} {pos}/{len} files [{elapsed_precise}, eta {eta}]")
    {
        bar.set_style(style);
    }
    bar
}

/// Read, fair and write one file: one row, or one per curve entity of a DXF file. Never
/// fails: every problem becomes a row's status and error. A panic in the library is caught
/// so that one bad curve cannot end the batch.
fn fair_one(job: &Job, method: &dyn FairMethod, options: &FairOptions) -> Vec<Row> {
    let run = || {
        if Format::from_path(&job.input).ok() == Some(Format::Dxf) {
            fair_dxf(job, method, options)
        } else {
            vec![fair_one_inner(job, method, options)]
        }
    };
    match panic::catch_unwind(AssertUnwindSafe(run)) {
        Ok(rows) => rows,
        Err(payload) => {
            let why = payload
                .downcast_ref::<&str>()
                .map(|s| (*s).to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown cause".to_string());
            let message = format!(
                "{}: method {} failed: internal error (panic: {why})",
                job.input.display(),
                method.name()
            );
            vec![Row::new(job, Status::Failed, Some(message), None, None)]
        }
    }
}

/// The report of one entity of a DXF file, in the file's `NAME.report.json` list.
#[derive(Serialize)]
struct EntityReport<'a> {
    handle: &'a str,
    layer: Option<&'a str>,
    kind: &'a str,
    report: AnyReport<'a>,
}

/// A planar or a space curve's report, serialised as it is.
#[derive(Serialize)]
#[serde(untagged)]
enum AnyReport<'a> {
    Planar(&'a FairReport),
    Space(&'a SpaceFairReport),
}

/// What was faired of one DXF entity.
enum Done {
    Planar(batten::Faired),
    Space(batten::fair::FairedSpace),
}

/// Fair every curve entity of a DXF file and write the drawing back once, each faired
/// entity's geometry replaced in place (handle, layer, z and every other entity kept), with
/// `NAME.report.json` holding a list of `{handle, layer, kind, report}`. One row per entity,
/// named `FILE#HANDLE`; an entity that cannot be taken or faired is a row and stays as it was
/// in the output. Nothing is written when no entity was faired.
fn fair_dxf(job: &Job, method: &dyn FairMethod, options: &FairOptions) -> Vec<Row> {
    let file = job.input.display().to_string();
    let mut drawing = match io::DxfDrawing::read(&job.input) {
        Ok(d) => d,
        Err(e) => {
            return vec![Row::new(
                job,
                Status::InvalidInput,
                Some(e.to_string()),
                None,
                None,
            )];
        }
    };
    let curves = drawing.curves(&ReadOptions::default());
    if curves.is_empty() {
        let message = format!("{file}: no LWPOLYLINE, POLYLINE or SPLINE entity");
        return vec![Row::new(
            job,
            Status::InvalidInput,
            Some(message),
            None,
            None,
        )];
    }
    let mut rows = Vec::with_capacity(curves.len());
    let mut faired_all = Vec::new();
    for c in &curves {
        let handle = c.origin.name.clone().unwrap_or_default();
        let label = format!("{file}#{handle}");
        let row = |status, error, points, report| {
            let mut r = Row::new(job, status, error, points, report);
            r.file.clone_from(&label);
            r
        };
        let source = match &c.source {
            Ok(s) => s,
            Err(e) => {
                rows.push(row(Status::InvalidInput, Some(e.to_string()), None, None));
                continue;
            }
        };
        let (result, points) = match source {
            Source::Points(d) => {
                if let Err(f) = input::check(method, d.seq.is_closed(), options) {
                    let message = format!("{label}: {}", f.error);
                    rows.push(row(
                        Status::InvalidInput,
                        Some(message),
                        Some(d.seq.len()),
                        None,
                    ));
                    continue;
                }
                (fair::fair_with(method, &d.seq, options), d.seq.len())
            }
            Source::Space(d) => {
                let checked = fair::check_space_method(method.name())
                    .and_then(|()| fair::check_options(method, d.seq.is_closed(), options))
                    .and_then(|()| fair::fair_space(method.name(), &d.seq, options));
                let faired = match checked {
                    Ok(f) => f,
                    Err(e) => {
                        let what = format!("{label}: method {} failed", method.name());
                        let f = Failure::from_batten(&what, e);
                        let status = if f.exit_code() == ExitCode::from(EXIT_USAGE) {
                            Status::InvalidInput
                        } else {
                            Status::Failed
                        };
                        rows.push(row(
                            status,
                            Some(f.error.to_string()),
                            Some(d.seq.len()),
                            None,
                        ));
                        continue;
                    }
                };
                if let Err(e) = drawing.replace(&handle, io::DxfGeometry::Space(&faired.points)) {
                    rows.push(row(
                        Status::Failed,
                        Some(e.to_string()),
                        Some(d.seq.len()),
                        None,
                    ));
                    continue;
                }
                let mut r = space_row(job, &faired.report, d.seq.len());
                r.file.clone_from(&label);
                rows.push(r);
                faired_all.push((c, Done::Space(faired)));
                continue;
            }
            Source::Curve(curve) => {
                if !method.run_curve_supported() {
                    let message = format!(
                        "{label}: {} with control points is a B-spline; method {} takes points",
                        c.kind,
                        method.name()
                    );
                    rows.push(row(Status::InvalidInput, Some(message), None, None));
                    continue;
                }
                (
                    fair::fair_curve(method.name(), curve, options),
                    curve.control_points().len(),
                )
            }
        };
        let faired = match result {
            Ok(f) => f,
            Err(e) => {
                let f =
                    Failure::from_batten(&format!("{label}: method {} failed", method.name()), e);
                let status = if f.exit_code() == ExitCode::from(EXIT_USAGE) {
                    Status::InvalidInput
                } else {
                    Status::Failed
                };
                rows.push(row(status, Some(f.error.to_string()), Some(points), None));
                continue;
            }
        };
        let geometry = match (source, &faired.curve) {
            (Source::Curve(_), Some(curve)) => io::DxfGeometry::Curve(curve),
            _ => io::DxfGeometry::Points(&faired.points),
        };
        if let Err(e) = drawing.replace(&handle, geometry) {
            rows.push(row(Status::Failed, Some(e.to_string()), Some(points), None));
            continue;
        }
        let report = &faired.report;
        let (status, error) = if report.tolerance_met {
            (Status::Ok, None)
        } else {
            (
                Status::ToleranceExceeded,
                Some(format!(
                    "{label}: tolerance {} not met: a point moved {}; output and report written anyway",
                    report.tolerance.map_or_else(String::new, format_f64),
                    sig(report.max_displacement, DIGITS),
                )),
            )
        };
        rows.push(row(status, error, Some(points), Some(report)));
        faired_all.push((c, Done::Planar(faired)));
    }
    if faired_all.is_empty() {
        return rows;
    }
    let reports: Vec<EntityReport<'_>> = faired_all
        .iter()
        .map(|(c, f)| EntityReport {
            handle: c.origin.name.as_deref().unwrap_or_default(),
            layer: c.origin.layer.as_deref(),
            kind: c.kind,
            report: match f {
                Done::Planar(f) => AnyReport::Planar(&f.report),
                Done::Space(f) => AnyReport::Space(&f.report),
            },
        })
        .collect();
    // The reports and the drawing as one set, the reports first (as `batten fair` does).
    let written = drawing.to_bytes().map_err(|e| e.to_string()).and_then(|b| {
        let mut json = serde_json::to_string_pretty(&reports)
            .map_err(|e| format!("cannot encode the reports: {e}"))?;
        json.push('\n');
        io::write_atomic_set(&[(&job.report, json.as_bytes()), (&job.output, &b)])
            .map_err(|e| e.to_string())
    });
    if let Err(message) = written {
        for r in &mut rows {
            if matches!(r.status, Status::Ok | Status::ToleranceExceeded) {
                r.status = Status::Failed;
                r.error = Some(message.clone());
            }
        }
    }
    rows
}

fn fair_one_inner(job: &Job, method: &dyn FairMethod, options: &FairOptions) -> Row {
    let file = job.input.display();
    let data = match input::read_points_any(&job.input, false, &Default::default()) {
        Ok(input::Points::Planar(d)) => d,
        Ok(input::Points::Space(d)) => return fair_space_file(job, method, options, &d),
        Err(f) => {
            let message = f.error.to_string();
            return Row::new(job, Status::InvalidInput, Some(message), None, None);
        }
    };
    let points = Some(data.seq.len());
    // A JSON file can make the curve closed: check the method against that.
    if let Err(f) = input::check(method, data.seq.is_closed(), options) {
        let message = format!("{file}: {}", f.error);
        return Row::new(job, Status::InvalidInput, Some(message), points, None);
    }
    let faired = match fair::fair_with(method, &data.seq, options) {
        Ok(f) => f,
        Err(e) => return method_failed(job, method, e, points),
    };
    let report = &faired.report;
    // Tangents: the method's, else the input's carried through (as `batten fair` does).
    let tangents = faired.tangents.as_deref().or(data.tangents.as_deref());
    let written = io::encode_points(&job.output, &faired.points, data.seq.is_closed(), tangents)
        .map_err(|e| e.to_string());
    let (status, error) = write_with_report(job, written, report, report.tolerance_met);
    Row::new(job, status, error, points, Some(report))
}

/// A row for a method that failed on a file.
fn method_failed(
    job: &Job,
    method: &dyn FairMethod,
    e: batten::Error,
    points: Option<usize>,
) -> Row {
    let file = job.input.display();
    let f = Failure::from_batten(&format!("{file}: method {} failed", method.name()), e);
    let status = if f.exit_code() == ExitCode::from(EXIT_USAGE) {
        Status::InvalidInput
    } else {
        Status::Failed
    };
    Row::new(job, status, Some(f.error.to_string()), points, None)
}

/// Write a file's report and encoded points as one set, the report first (as `batten fair`
/// does), and say how the file ended.
fn write_with_report<R: Serialize + Tolerance>(
    job: &Job,
    points: Result<Vec<u8>, String>,
    report: &R,
    met: bool,
) -> (Status, Option<String>) {
    let written = points.and_then(|points| {
        let report = fair_cmd::report_json(report).map_err(|f| f.error.to_string())?;
        io::write_atomic_set(&[
            (&job.report, report.as_bytes()),
            (&job.output, points.as_slice()),
        ])
        .map_err(|e| e.to_string())
    });
    match written {
        Err(message) => (Status::Failed, Some(message)),
        Ok(()) if met => (Status::Ok, None),
        Ok(()) => (
            Status::ToleranceExceeded,
            Some(format!(
                "{}: tolerance {} not met: a point moved {}; output and report written anyway",
                job.input.display(),
                report.tolerance().map_or_else(String::new, format_f64),
                sig(report.max_displacement(), DIGITS),
            )),
        ),
    }
}

/// What the batch reads of a planar or a space report.
trait Tolerance {
    fn tolerance(&self) -> Option<f64>;
    fn max_displacement(&self) -> f64;
}

impl Tolerance for FairReport {
    fn tolerance(&self) -> Option<f64> {
        self.tolerance
    }
    fn max_displacement(&self) -> f64 {
        self.max_displacement
    }
}

impl Tolerance for SpaceFairReport {
    fn tolerance(&self) -> Option<f64> {
        self.tolerance
    }
    fn max_displacement(&self) -> f64 {
        self.max_displacement
    }
}

/// Fair a space curve's file: `band` and `mst` only (others: an invalid-input row).
fn fair_space_file(
    job: &Job,
    method: &dyn FairMethod,
    options: &FairOptions,
    data: &SpaceData,
) -> Row {
    let file = job.input.display();
    let points = Some(data.seq.len());
    let checked = fair::check_space_method(method.name())
        .and_then(|()| fair::check_options(method, data.seq.is_closed(), options));
    if let Err(e) = checked {
        let f = Failure::from_batten(&file.to_string(), e);
        return Row::new(
            job,
            Status::InvalidInput,
            Some(f.error.to_string()),
            points,
            None,
        );
    }
    let faired = match fair::fair_space(method.name(), &data.seq, options) {
        Ok(f) => f,
        Err(e) => return method_failed(job, method, e, points),
    };
    let report = &faired.report;
    let format = Format::from_path(&job.output).unwrap_or(Format::Text);
    let written = io::format_space_points(
        format,
        &job.output,
        &faired.points,
        data.seq.is_closed(),
        &io::Origin::default(),
    )
    .map_err(|e| e.to_string());
    let (status, error) = write_with_report(job, written, report, report.tolerance_met);
    let mut row = space_row(job, report, data.seq.len());
    (row.status, row.error) = (status, error);
    row
}

/// The summary row of a faired space curve: what its report has of the summary's columns
/// (no inflections, vibrations, GFI or end changes in space).
fn space_row(job: &Job, report: &SpaceFairReport, points: usize) -> Row {
    let (status, error) = if report.tolerance_met {
        (Status::Ok, None)
    } else {
        (
            Status::ToleranceExceeded,
            Some(format!(
                "{}: tolerance {} not met: a point moved {}; output and report written anyway",
                job.input.display(),
                report.tolerance.map_or_else(String::new, format_f64),
                sig(report.max_displacement, DIGITS),
            )),
        )
    };
    let mut row = Row::new(job, status, error, Some(points), None);
    row.iterations = Some(report.iterations);
    row.max_displacement = Some(report.max_displacement);
    row.sum_displacement = Some(report.sum_displacement);
    row.tolerance_met = Some(report.tolerance_met);
    row.strain_energy_before = Some(report.before.strain_energy);
    row.strain_energy_after = Some(report.after.strain_energy);
    row
}

/// The summary's format, from its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum SummaryFormat {
    Json,
    Csv,
}

fn summary_format(path: &Path) -> Result<SummaryFormat, Failure> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("json") => Ok(SummaryFormat::Json),
        Some("csv") => Ok(SummaryFormat::Csv),
        _ => Err(Failure::usage(anyhow!(
            "{}: unknown summary format (use a .json or .csv file name)",
            path.display()
        ))),
    }
}

/// The inputs as listed: files as given, directories expanded to their point files sorted by
/// name, patterns to the point files they match sorted by name.
///
/// # Errors
/// [`Failure::usage`] for a directory that cannot be listed, a pattern that matches nothing,
/// or no input file at all.
fn expand(args: &[PathBuf]) -> Result<Vec<PathBuf>, Failure> {
    let mut inputs = Vec::new();
    for arg in args {
        if arg.is_dir() {
            inputs.extend(list_dir(arg, None)?);
        } else if let Some(pattern) = pattern(arg) {
            let dir = arg.parent().unwrap_or(Path::new(""));
            let found = list_dir(dir, Some(pattern))?;
            if found.is_empty() {
                return Err(Failure::usage(anyhow!(
                    "{}: matches no .csv, .txt, .json, .dxf, .igs or .svg file",
                    arg.display()
                )));
            }
            inputs.extend(found);
        } else if !arg.exists() && Format::from_path(arg).is_err() {
            // Not a point file by name, and nothing there: most likely a folder that is not
            // there (`scans/`). Say so, rather than "unknown file format" for each.
            return Err(Failure::usage(anyhow!(
                "{}: no such file or directory",
                arg.display()
            )));
        } else {
            // A file, or a point file that does not exist: reading it reports what is wrong,
            // as a row of the summary.
            inputs.push(arg.clone());
        }
    }
    if inputs.is_empty() {
        return Err(Failure::usage(anyhow!(
            "no .csv, .txt, .json, .dxf, .igs or .svg files in {}",
            args.iter()
                .map(|a| a.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    Ok(inputs)
}

/// The file-name pattern of `path`, when it names no existing file and its last component
/// holds `*` or `?`.
fn pattern(path: &Path) -> Option<&str> {
    if path.exists() {
        return None;
    }
    let name = path.file_name()?.to_str()?;
    name.contains(['*', '?']).then_some(name)
}

/// The point files (known extension, not hidden, regular files or links to them) of `dir`
/// whose names match `pattern` (all, without one), sorted by name.
fn list_dir(dir: &Path, pattern: Option<&str>) -> Result<Vec<PathBuf>, Failure> {
    let read_from = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let cannot = |e: std::io::Error| {
        Failure::usage(anyhow!(
            "{}: cannot read directory: {e}",
            read_from.display()
        ))
    };
    let mut names: Vec<OsString> = Vec::new();
    for entry in fs::read_dir(read_from).map_err(cannot)? {
        let name = entry.map_err(cannot)?.file_name();
        let lossy = name.to_string_lossy();
        let shown = match pattern {
            Some(p) => wildcard_match(p, &lossy) && (p.starts_with('.') || !lossy.starts_with('.')),
            None => !lossy.starts_with('.'),
        };
        let path = dir.join(&name);
        if shown && Format::from_path(&path).is_ok() && path.is_file() {
            names.push(name);
        }
    }
    names.sort();
    Ok(names.into_iter().map(|n| dir.join(n)).collect())
}

/// Whether `name` matches `pattern`, where `*` matches any run of characters and `?` any one
/// character. Greedy, backtracking to the last `*` only: O(pattern × name), never exponential.
fn wildcard_match(pattern: &str, name: &str) -> bool {
    let p: Vec<char> = pattern.chars().collect();
    let n: Vec<char> = name.chars().collect();
    let (mut pi, mut ni) = (0, 0);
    // The last `*` seen and the name position it is currently matched up to.
    let mut star: Option<(usize, usize)> = None;
    while let Some(&c) = n.get(ni) {
        match p.get(pi) {
            Some('*') => {
                star = Some((pi, ni));
                pi += 1;
            }
            Some(&q) if q == '?' || q == c => {
                pi += 1;
                ni += 1;
            }
            _ => match star {
                Some((sp, sn)) => {
                    star = Some((sp, sn + 1));
                    pi = sp + 1;
                    ni = sn + 1;
                }
                None => return false,
            },
        }
    }
    p.iter().skip(pi).all(|&c| c == '*')
}

/// The output and report paths of every input.
///
/// # Errors
/// [`Failure::usage`] when an input has no file name, or two inputs would write the same file
/// (compared ignoring ASCII case, as on case-insensitive file systems): the same file given
/// twice, `a/x.csv` and `b/x.csv`, or `x.csv` and `x.json` (both report to `x.report.json`).
fn plan(inputs: &[PathBuf], out_dir: &Path) -> Result<Vec<Job>, Failure> {
    let mut writers: HashMap<String, &Path> = HashMap::new();
    let mut jobs = Vec::with_capacity(inputs.len());
    for input in inputs {
        let (Some(name), Some(stem)) = (input.file_name(), input.file_stem()) else {
            return Err(Failure::usage(anyhow!(
                "{}: not a file name",
                input.display()
            )));
        };
        let mut report = stem.to_os_string();
        report.push(REPORT_SUFFIX);
        for out_name in [name, report.as_os_str()] {
            let key = out_name.to_string_lossy().to_ascii_lowercase();
            if let Some(other) = writers.insert(key, input) {
                let target = out_dir.join(out_name);
                return Err(Failure::usage(if other == input.as_path() {
                    anyhow!("{} is given more than once", input.display())
                } else {
                    anyhow!(
                        "{} and {} would both write {}",
                        other.display(),
                        input.display(),
                        target.display()
                    )
                }));
            }
        }
        jobs.push(Job {
            input: input.clone(),
            output: out_dir.join(name),
            report: out_dir.join(report),
        });
    }
    Ok(jobs)
}

/// Refuse an output directory that is not a directory, or that holds an input (by the path
/// given or, through links, by the file's real place), so that no input is ever replaced.
fn check_out_dir(jobs: &[Job], out_dir: &Path) -> Result<(), Failure> {
    if !out_dir.exists() {
        return Ok(());
    }
    if !out_dir.is_dir() {
        return Err(Failure::usage(anyhow!(
            "{}: not a directory",
            out_dir.display()
        )));
    }
    let Ok(out_real) = fs::canonicalize(out_dir) else {
        return Ok(());
    };
    let mut parents: HashMap<PathBuf, Option<PathBuf>> = HashMap::new();
    for job in jobs {
        let parent = match job.input.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let given = parents
            .entry(parent.to_path_buf())
            .or_insert_with(|| fs::canonicalize(parent).ok());
        let real = fs::canonicalize(&job.input).ok();
        let real_parent = real.as_deref().and_then(Path::parent);
        if given.as_deref() == Some(out_real.as_path()) || real_parent == Some(out_real.as_path()) {
            return Err(Failure::usage(anyhow!(
                "refusing to write into {}: it is the directory of the input {}",
                out_dir.display(),
                job.input.display()
            )));
        }
    }
    Ok(())
}

/// The summary goes into an existing directory or the output directory, and replaces neither
/// an input nor an output of the batch.
fn check_summary(path: &Path, jobs: &[Job], out_dir: &Path) -> Result<(), Failure> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let in_out_dir = fair_cmd::same_path(dir, out_dir)
        || matches!(
            (fs::canonicalize(dir), fs::canonicalize(out_dir)),
            (Ok(a), Ok(b)) if a == b
        );
    if path.is_dir() || !in_out_dir {
        fair_cmd::check_writable(path)?;
    }
    if let Ok(real) = fs::canonicalize(path) {
        for job in jobs {
            if fs::canonicalize(&job.input).is_ok_and(|i| i == real) {
                return Err(Failure::usage(IoError::SameFile {
                    input: job.input.clone(),
                    output: path.to_path_buf(),
                }));
            }
        }
    }
    if in_out_dir && let Some(name) = path.file_name() {
        let key = name.to_string_lossy().to_ascii_lowercase();
        let clash = jobs.iter().find(|j| {
            [&j.output, &j.report].iter().any(|p| {
                p.file_name()
                    .is_some_and(|n| n.to_string_lossy().to_ascii_lowercase() == key)
            })
        });
        if let Some(job) = clash {
            return Err(Failure::usage(anyhow!(
                "--summary {} would replace a result of {}",
                path.display(),
                job.input.display()
            )));
        }
    }
    Ok(())
}

/// The summary as a pretty JSON array, one object per row, keys in [`Row`]'s order.
fn summary_json(rows: &[Row]) -> Result<String, String> {
    let mut json = serde_json::to_string_pretty(rows)
        .map_err(|e| format!("cannot encode the summary: {e}"))?;
    json.push('\n');
    Ok(json)
}

/// The summary as CSV with a header row; unknown and non-finite numbers are empty cells.
fn summary_csv(rows: &[Row]) -> String {
    let mut s = String::from(
        "file,status,error,points,iterations,max_displacement,sum_displacement,tolerance_met,\
         inflections_before,inflections_after,vibrations_before,vibrations_after,\
         strain_energy_before,strain_energy_after,gfi_before,gfi_after,end_tangent_change,\
         end_curvature_change\n",
    );
    let int = |n: Option<usize>| n.map(|n| n.to_string()).unwrap_or_default();
    let num = |x: Option<f64>| x.map(csv_num).unwrap_or_default();
    for r in rows {
        // Writing to a String cannot fail.
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            csv_field(&r.file),
            r.status.name(),
            csv_field(r.error.as_deref().unwrap_or_default()),
            int(r.points),
            int(r.iterations),
            num(r.max_displacement),
            num(r.sum_displacement),
            r.tolerance_met.map(|b| b.to_string()).unwrap_or_default(),
            int(r.inflections_before),
            int(r.inflections_after),
            int(r.vibrations_before),
            int(r.vibrations_after),
            num(r.strain_energy_before),
            num(r.strain_energy_after),
            num(r.gfi_before),
            num(r.gfi_after),
            num(r.end_tangent_change),
            num(r.end_curvature_change),
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wildcards() {
        for (p, n) in [
            ("*.csv", "a.csv"),
            ("*.csv", ".csv"),
            ("frame-??.csv", "frame-07.csv"),
            ("*", ""),
            ("a*b*c", "aXbYbZc"),
            ("**x", "x"),
            ("é?.json", "éz.json"),
        ] {
            assert!(wildcard_match(p, n), "{p} should match {n}");
        }
        for (p, n) in [
            ("*.csv", "a.csv.bak"),
            ("frame-??.csv", "frame-7.csv"),
            ("a*b*c", "aXbYbZ"),
            ("?", ""),
            ("x", "xx"),
        ] {
            assert!(!wildcard_match(p, n), "{p} should not match {n}");
        }
        // Backtracking on the last star stays linear.
        let long = "a".repeat(10_000);
        assert!(!wildcard_match("*a*a*a*b", &long));
    }

    #[test]
    fn status_names_match_serde() {
        for s in [
            Status::Ok,
            Status::ToleranceExceeded,
            Status::Failed,
            Status::InvalidInput,
        ] {
            assert_eq!(
                serde_json::to_value(s)
                    .ok()
                    .and_then(|v| v.as_str().map(String::from)),
                Some(s.name().to_string())
            );
        }
    }

    #[test]
    fn output_names_may_not_collide() {
        let out = Path::new("out");
        let jobs = plan(&[PathBuf::from("a/x.csv"), PathBuf::from("b/y.json")], out);
        let jobs = jobs.map_err(|f| f.error.to_string());
        assert!(jobs.is_ok(), "{jobs:?}");
        let err = |inputs: &[&str]| {
            let v: Vec<PathBuf> = inputs.iter().map(PathBuf::from).collect();
            plan(&v, out).err().map(|f| f.error.to_string())
        };
        assert_eq!(
            err(&["a/x.csv", "b/X.CSV"]).as_deref(),
            Some(
                format!(
                    "a/x.csv and b/X.CSV would both write {}",
                    out.join("X.CSV").display()
                )
                .as_str()
            )
        );
        assert!(err(&["x.csv", "x.json"]).is_some_and(|e| e.ends_with("x.report.json")));
        assert!(err(&["x.csv", "x.report.json"]).is_some());
        assert_eq!(
            err(&["d/x.csv", "d/x.csv"]).as_deref(),
            Some("d/x.csv is given more than once")
        );
        assert_eq!(err(&[".."]).as_deref(), Some("..: not a file name"));
    }
}
