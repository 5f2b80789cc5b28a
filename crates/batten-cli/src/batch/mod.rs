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
//!
//! Here: the arguments and the run (checks, thread pool, progress, conclusion). The checks
//! before any work are in [`plan`], one point file in [`mod@file`], a DXF file in [`dxf`], the
//! summary's rows and files (also when interrupted) in [`summary`].

mod dxf;
mod file;
mod plan;
mod summary;

use std::io::IsTerminal as _;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::{Arc, Mutex};

use anyhow::anyhow;
use batten::FairOptions;
use batten::fair::FairMethod;
use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

use crate::failure::{EXIT_FAILED, EXIT_USAGE, Failure};
use crate::{input, output, signals};
use plan::Job;
use summary::{Row, Status};

/// Most files faired at once (`--jobs`): each is a thread with its own curve in memory, and
/// thousands of threads only cost time to start (30000 took minutes for one file).
const MAX_JOBS: usize = 1024;

/// `--jobs N` (clap value parser): 1 to [`MAX_JOBS`].
fn parse_jobs(s: &str) -> Result<usize, String> {
    input::parse_count(s, MAX_JOBS)
}

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

/// The rows of the files that have finished, in input order (a DXF file gives one per
/// curve), for the summary an interrupt leaves.
type Finished = Arc<Mutex<Vec<Option<Vec<Row>>>>>;

/// Run `batten batch`.
///
/// # Errors
/// Usage errors found before any file is faired (exit 2); a failure to create the output
/// directory or to start the worker threads (exit 1). Problems with single files are not
/// errors: they are rows of the summary and decide the exit code.
pub fn run(args: &BatchArgs) -> Result<ExitCode, Failure> {
    // Checked for an open curve; a file that says it is closed is checked again when read.
    let (method, options) = input::method_options(&args.how, &args.bounds, false)?;
    let summary_format = match &args.summary {
        Some(path) => Some(summary::summary_format(path)?),
        None => None,
    };
    let jobs = checked_jobs(args)?;

    let pool = rayon::ThreadPoolBuilder::new()
        // More threads than files would only idle.
        .num_threads(args.jobs.map_or(0, |n| n.min(jobs.len())))
        .build()
        .map_err(|e| Failure::failed(anyhow!("cannot start worker threads: {e}")))?;
    let bar = progress_bar(jobs.len());
    let finished: Finished = Arc::new(Mutex::new(vec![None; jobs.len()]));
    if let (Some(path), Some(format)) = (&args.summary, summary_format) {
        summary::write_on_interrupt(path.clone(), format, jobs.clone(), Arc::clone(&finished));
    }
    let rows = pool.install(|| fair_all(&jobs, method, &options, &finished, &bar));
    bar.finish_and_clear();

    let summary_written = match (&args.summary, summary_format) {
        (Some(path), Some(format)) => summary::write(path, format, &rows),
        _ => Ok(()),
    };
    Ok(conclude(args, &rows, jobs.len(), summary_written))
}

/// The jobs of the inputs, once every check that needs no curve has passed and the output
/// directory exists (see [`plan`]).
fn checked_jobs(args: &BatchArgs) -> Result<Vec<Job>, Failure> {
    let inputs = plan::expand(&args.inputs)?;
    let jobs = plan::plan(&inputs, &args.out_dir)?;
    plan::check_out_dir(&jobs, &args.out_dir)?;
    if let Some(path) = &args.summary {
        plan::check_summary(path, &jobs, &args.out_dir)?;
    }
    plan::create_out_dir(&args.out_dir, args.summary.as_deref())?;
    Ok(jobs)
}

/// Fair every job on the current thread pool; each file's rows go into `finished` as soon as
/// it is done. The rows of all files, in input order.
fn fair_all(
    jobs: &[Job],
    method: &dyn FairMethod,
    options: &FairOptions,
    finished: &Finished,
    bar: &ProgressBar,
) -> Vec<Row> {
    let per_job: Vec<Vec<Row>> = jobs
        .par_iter()
        .enumerate()
        .map(|(i, job)| {
            let rows = file::fair_one(job, method, options);
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
}

/// Say how the batch ended, once its summary is written (or failed to be): each file's
/// error, then the summary's, then the count of each status; the exit code.
fn conclude(
    args: &BatchArgs,
    rows: &[Row],
    files: usize,
    summary_written: Result<(), String>,
) -> ExitCode {
    for row in rows {
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
    let curves = if rows.len() == files {
        String::new()
    } else {
        format!(", {} curves", rows.len())
    };
    output::note(&format!(
        "batch: {}{curves}: {ok} ok, {exceeded} tolerance exceeded, {failed} failed, \
         {invalid} invalid input; results in {}",
        output::count(files, "file"),
        args.out_dir.display()
    ));
    if invalid > 0 {
        ExitCode::from(EXIT_USAGE)
    } else if exceeded > 0 || failed > 0 || summary_failed {
        ExitCode::from(EXIT_FAILED)
    } else {
        ExitCode::SUCCESS
    }
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
