//! A DXF file in `batten batch`: every curve entity faired on its own, one row each
//! (`FILE#HANDLE`), and the drawing written back once with each faired entity replaced in
//! place, beside a list of the entities' reports.

use batten::FairOptions;
use batten::fair::{self, FairMethod, FairReport, SpaceFairReport};
use batten::io::{self, DxfCurve, DxfDrawing, ReadOptions, Source, SpaceData};
use serde::Serialize;

use super::plan::Job;
use super::summary::{Row, Status, failed_status, not_met, space_row};
use crate::failure::Failure;
use crate::input;

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
pub(super) fn fair_dxf(job: &Job, method: &dyn FairMethod, options: &FairOptions) -> Vec<Row> {
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
        let (row, done) = fair_entity(job, &file, c, &mut drawing, method, options);
        rows.push(row);
        if let Some(done) = done {
            faired_all.push((c, done));
        }
    }
    if faired_all.is_empty() {
        return rows;
    }
    if let Err(message) = write_dxf(job, &drawing, &faired_all) {
        for r in &mut rows {
            if matches!(r.status, Status::Ok | Status::ToleranceExceeded) {
                r.status = Status::Failed;
                r.error = Some(message.clone());
            }
        }
    }
    rows
}

/// A row of an entity of a DXF file: as [`Row::new`], named `label` (`FILE#HANDLE`).
fn entity_row(
    job: &Job,
    label: &str,
    status: Status,
    error: Option<String>,
    points: Option<usize>,
    report: Option<&FairReport>,
) -> Row {
    let mut r = Row::new(job, status, error, points, report);
    r.file = label.to_string();
    r
}

/// Fair one curve entity of the DXF file `file` and replace it in `drawing`: its row, and
/// what was faired when it was replaced.
fn fair_entity(
    job: &Job,
    file: &str,
    c: &DxfCurve,
    drawing: &mut DxfDrawing,
    method: &dyn FairMethod,
    options: &FairOptions,
) -> (Row, Option<Done>) {
    let handle = c.origin.name.clone().unwrap_or_default();
    let label = format!("{file}#{handle}");
    let row =
        |status, error, points, report| entity_row(job, &label, status, error, points, report);
    let source = match &c.source {
        Ok(s) => s,
        Err(e) => {
            return (
                row(Status::InvalidInput, Some(e.to_string()), None, None),
                None,
            );
        }
    };
    let (result, points) = match source {
        Source::Points(d) => {
            if let Err(f) = input::check(method, d.seq.is_closed(), options) {
                let message = format!("{label}: {}", f.error);
                let r = row(Status::InvalidInput, Some(message), Some(d.seq.len()), None);
                return (r, None);
            }
            (fair::fair_with(method, &d.seq, options), d.seq.len())
        }
        Source::Space(d) => {
            return fair_space_entity(job, &label, &handle, d, drawing, method, options);
        }
        Source::Curve(curve) => {
            if !method.run_curve_supported() {
                let message = format!(
                    "{label}: {} with control points is a B-spline; method {} takes points",
                    c.kind,
                    method.name()
                );
                return (row(Status::InvalidInput, Some(message), None, None), None);
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
            let f = Failure::from_batten(&format!("{label}: method {} failed", method.name()), e);
            let r = row(
                failed_status(&f),
                Some(f.error.to_string()),
                Some(points),
                None,
            );
            return (r, None);
        }
    };
    let geometry = match (source, &faired.curve) {
        (Source::Curve(_), Some(curve)) => io::DxfGeometry::Curve(curve),
        _ => io::DxfGeometry::Points(&faired.points),
    };
    if let Err(e) = drawing.replace(&handle, geometry) {
        return (
            row(Status::Failed, Some(e.to_string()), Some(points), None),
            None,
        );
    }
    let report = &faired.report;
    let (status, error) = if report.tolerance_met {
        (Status::Ok, None)
    } else {
        (
            Status::ToleranceExceeded,
            Some(not_met(&label, report.tolerance, report.max_displacement)),
        )
    };
    let r = row(status, error, Some(points), Some(report));
    (r, Some(Done::Planar(faired)))
}

/// [`fair_entity`] for a 3-D entity: `band` and `mst` only.
fn fair_space_entity(
    job: &Job,
    label: &str,
    handle: &str,
    d: &SpaceData,
    drawing: &mut DxfDrawing,
    method: &dyn FairMethod,
    options: &FairOptions,
) -> (Row, Option<Done>) {
    let checked = fair::check_space_method(method.name())
        .and_then(|()| fair::check_options(method, d.seq.is_closed(), options))
        .and_then(|()| fair::fair_space(method.name(), &d.seq, options));
    let faired = match checked {
        Ok(f) => f,
        Err(e) => {
            let what = format!("{label}: method {} failed", method.name());
            let f = Failure::from_batten(&what, e);
            let status = failed_status(&f);
            let error = Some(f.error.to_string());
            let r = entity_row(job, label, status, error, Some(d.seq.len()), None);
            return (r, None);
        }
    };
    if let Err(e) = drawing.replace(handle, io::DxfGeometry::Space(&faired.points)) {
        let error = Some(e.to_string());
        let r = entity_row(job, label, Status::Failed, error, Some(d.seq.len()), None);
        return (r, None);
    }
    let mut r = space_row(job, &faired.report, d.seq.len());
    r.file = label.to_string();
    (r, Some(Done::Space(faired)))
}

/// Write the drawing and the list of the faired entities' reports as one set, the reports
/// first (as `batten fair` does).
///
/// # Errors
/// Why the drawing or the reports could not be encoded or written.
fn write_dxf(job: &Job, drawing: &DxfDrawing, faired: &[(&DxfCurve, Done)]) -> Result<(), String> {
    let reports: Vec<EntityReport<'_>> = faired
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
    drawing.to_bytes().map_err(|e| e.to_string()).and_then(|b| {
        let mut json =
            crate::json::pretty(&reports).map_err(|e| format!("cannot encode the reports: {e}"))?;
        json.push('\n');
        io::write_atomic_set(&[(&job.report, json.as_bytes()), (&job.output, &b)])
            .map_err(|e| e.to_string())
    })
}
