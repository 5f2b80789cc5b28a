//! `batten fair` on a space curve (`x, y, z` points): `band` or `mst`, the tolerance in 3-D
//! distance, the points written as text, JSON or a DXF 3-D POLYLINE.

use std::process::ExitCode;

use anyhow::anyhow;
use batten::FairOptions;
use batten::fair::{self, FairMethod};
use batten::io::{self, Format, SpaceData};

use crate::FairArgs;
use crate::failure::Failure;
use crate::fair_cmd::{self, SummaryFigures};
use crate::formats;
use crate::output;
use crate::spinner::Spinner;

/// Fair the space curve `data` read from `args.input`; the outputs were checked writable and
/// distinct from the input by the caller.
///
/// # Errors
/// Usage errors (exit 2: a planar method, `--curve-out`, an output format that holds planar
/// curves only); a method failure or a failed write (exit 1).
pub fn run(
    args: &FairArgs,
    method: &dyn FairMethod,
    options: &FairOptions,
    data: &SpaceData,
    origin: &io::Origin,
    out_format: Format,
) -> Result<ExitCode, Failure> {
    let input_name = formats::display_name(&args.input).display().to_string();
    fair::check_space_method(method.name())
        .and_then(|()| fair::check_options(method, data.seq.is_closed(), options))
        .map_err(|e| Failure::from_batten(&input_name, e))?;
    if let Some(curve_out) = &args.curve_out {
        return Err(Failure::usage(anyhow!(
            "{}: --curve-out writes a planar B-spline; the input is a 3-D curve",
            curve_out.display()
        )));
    }
    if !matches!(
        out_format,
        Format::Text | Format::Json | Format::Dxf | Format::Iges
    ) {
        return Err(Failure::usage(anyhow!(
            "{}: a 3-D curve is written as .csv, .txt, .json, .dxf or .igs",
            formats::display_name(&args.output).display()
        )));
    }
    let spinner = Spinner::start(format!("fairing with {}", method.name()));
    let faired = fair::fair_space(method.name(), &data.seq, options).map_err(|e| {
        Failure::from_batten(&format!("{input_name}: method {} failed", method.name()), e)
    })?;
    let out_name = formats::display_name(&args.output);
    let bytes = io::format_space_points(
        out_format,
        &out_name,
        &faired.points,
        data.seq.is_closed(),
        origin,
    )
    .map_err(Failure::failed)?;
    let report = match &args.report {
        Some(_) => Some(fair_cmd::report_json(&faired.report)?.into_bytes()),
        None => None,
    };
    fair_cmd::write_outputs(args, report.as_deref(), None, (&bytes, None), spinner)?;
    let r = &faired.report;
    let figures = SummaryFigures {
        method: &r.method,
        status: r.status,
        iterations: r.iterations,
        max_displacement: r.max_displacement,
        index: r.max_displacement_index,
        tolerance: r.tolerance,
        met: r.tolerance_met,
    };
    output::note(&fair_cmd::summary_line(&figures, Some(&data.lines)));
    Ok(fair_cmd::verdict(&figures, args.report.is_some()))
}
