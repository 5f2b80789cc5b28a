//! One point file of `batten batch`: read, fair and write it (with its report) on its own,
//! every problem a row of the summary; a DXF file goes to [`super::dxf`].

use std::panic::{self, AssertUnwindSafe};

use batten::FairOptions;
use batten::fair::{self, FairMethod, FairReport, SpaceFairReport};
use batten::io::{self, Format, SpaceData};
use serde::Serialize;

use super::dxf::fair_dxf;
use super::plan::Job;
use super::summary::{Row, Status, failed_status, not_met, space_row};
use crate::failure::Failure;
use crate::{fair_cmd, input};

/// Read, fair and write one file: one row, or one per curve entity of a DXF file. Never
/// fails: every problem becomes a row's status and error. A panic in the library is caught
/// so that one bad curve cannot end the batch.
pub(super) fn fair_one(job: &Job, method: &dyn FairMethod, options: &FairOptions) -> Vec<Row> {
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

/// Read, fair and write a point file other than DXF: its one row.
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
    Row::new(
        job,
        failed_status(&f),
        Some(f.error.to_string()),
        points,
        None,
    )
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
            Some(not_met(
                &job.input.display(),
                report.tolerance(),
                report.max_displacement(),
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
