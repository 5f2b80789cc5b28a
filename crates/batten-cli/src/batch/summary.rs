//! The summary of `batten batch`: one row per input (per curve entity of a DXF file), as
//! JSON or CSV, written at the end, or by the signal handler with the rows of the files that
//! finished when the batch is interrupted.

use std::fmt::{Display, Write as _};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::anyhow;
use batten::fair::{FairReport, SpaceFairReport};
use batten::io::{self, format_f64};
use serde::Serialize;

use super::Finished;
use super::plan::Job;
use crate::compare::{csv_field, csv_num};
use crate::failure::{EXIT_USAGE, Failure};
use crate::output::{self, sig};
use crate::signals;

/// Significant digits of displacements in messages.
const DIGITS: usize = 4;

/// How one input ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum Status {
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

/// One row of the summary. Fields that are not known for a row (the metrics of a file that
/// could not be read) are `null` in JSON and empty in CSV.
#[derive(Clone, Debug, Serialize)]
pub(super) struct Row {
    pub(super) file: String,
    pub(super) status: Status,
    pub(super) error: Option<String>,
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
    pub(super) fn new(
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

/// The summary row of a faired space curve: what its report has of the summary's columns
/// (no inflections, vibrations, GFI or end changes in space).
pub(super) fn space_row(job: &Job, report: &SpaceFairReport, points: usize) -> Row {
    let (status, error) = if report.tolerance_met {
        (Status::Ok, None)
    } else {
        (
            Status::ToleranceExceeded,
            Some(not_met(
                &job.input.display(),
                report.tolerance,
                report.max_displacement,
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

/// The error of a row whose curve was faired and written but missed the tolerance; `name`
/// is the file, or `FILE#HANDLE` for an entity of a DXF file.
pub(super) fn not_met(name: &dyn Display, tolerance: Option<f64>, max_displacement: f64) -> String {
    format!(
        "{name}: tolerance {} not met: a point moved {}; output and report written anyway",
        tolerance.map_or_else(String::new, format_f64),
        sig(max_displacement, DIGITS),
    )
}

/// The status of a row whose method failed: invalid input for an error about the request
/// (one that exits 2 in `batten fair`), failed for an error of the computation.
pub(super) fn failed_status(f: &Failure) -> Status {
    if f.exit_code() == ExitCode::from(EXIT_USAGE) {
        Status::InvalidInput
    } else {
        Status::Failed
    }
}

/// The summary's format, from its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum SummaryFormat {
    Json,
    Csv,
}

pub(super) fn summary_format(path: &Path) -> Result<SummaryFormat, Failure> {
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
/// Write the summary of `rows` to `path`, atomically.
///
/// # Errors
/// Why the summary could not be encoded or written.
pub(super) fn write(path: &Path, format: SummaryFormat, rows: &[Row]) -> Result<(), String> {
    let text = match format {
        SummaryFormat::Json => summary_json(rows),
        SummaryFormat::Csv => Ok(summary_csv(rows)),
    };
    text.and_then(|t| io::write_atomic(path, t.as_bytes()).map_err(|e| e.to_string()))
}

/// Have an interrupt (see [`signals`]) write the summary to `path`: the rows of the files
/// that finished, and one `interrupted` row for each of the others.
pub(super) fn write_on_interrupt(
    path: PathBuf,
    format: SummaryFormat,
    jobs: Vec<Job>,
    finished: Finished,
) {
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
        Some(match write(&path, format, &rows) {
            Ok(()) => format!(
                "summary of the {done} of {} that finished written to {}, the others marked \
                 interrupted",
                output::count(files, "file"),
                path.display()
            ),
            Err(e) => format!("summary not written: {e}"),
        })
    });
}

/// The summary as a pretty JSON array, one object per row, keys in [`Row`]'s order.
fn summary_json(rows: &[Row]) -> Result<String, String> {
    let mut json =
        crate::json::pretty(rows).map_err(|e| format!("cannot encode the summary: {e}"))?;
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
}
