//! `batten fair`: fair a point file, write the result and the report.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::anyhow;
use batten::fair::{self, FairMethod, FairReport, FairStatus};
use batten::io::{self, Format, IoError, PointData, format_f64};
use batten::spline::BSplineCurve;
use batten::{FairOptions, Faired, Point, PointSeq, Vec2, analysis};

use crate::FairArgs;
use crate::failure::{EXIT_FAILED, Failure};
use crate::output::{self, sig};
use crate::spinner::Spinner;
use crate::{formats, input};

/// Significant digits in the summary line.
const DIGITS: usize = 4;

/// Run `batten fair`. Everything that can be checked before fairing is checked first, so a
/// usage error never leaves a partial result behind.
///
/// # Errors
/// Usage errors (exit 2); a method failure or a failed write (exit 1).
pub fn run(args: &FairArgs) -> Result<ExitCode, Failure> {
    let (method, options) = input::method_options(&args.how, &args.bounds, args.closed)?;
    let in_format = formats::format_of(&args.input, args.pick.format)?;
    let out_format = formats::format_of(&args.output, args.pick.format)?;
    let input_name = formats::display_name(&args.input);
    args.pick
        .check(in_format, &input_name.display().to_string())?;
    let to_stdout = formats::is_stdio(&args.output);
    if !to_stdout {
        check_writable(&args.output)?;
    }
    if let Some(report) = &args.report {
        check_writable(report)?;
    }
    let curve_format = match &args.curve_out {
        None => None,
        Some(curve_out) => Some(check_curve_out(args, curve_out)?),
    };

    // A B-spline (JSON, DXF SPLINE, IGES 126, SVG Béziers) is faired as a curve
    // (control-point methods only); a space curve by the methods that take one.
    // One spinner from the start: reading 10⁷ points takes seconds too.
    let spinner = Spinner::start(format!("reading {}", input_name.display()));
    let read = formats::read_input(&args.input, in_format, args.closed, &args.pick.pick())?;
    let origin = read.origin;
    let source = match read.source {
        io::Source::Points(d) => Source::Points(d),
        io::Source::Curve(c) => Source::Curve(c),
        io::Source::Space(d) => {
            // The space command keeps its own spinner.
            drop(spinner);
            check_distinct(args, to_stdout)?;
            return crate::fair_space_cmd::run(args, method, &options, &d, &origin, out_format);
        }
    };
    check_source(&source, method, &options, &input_name)?;
    check_distinct(args, to_stdout)?;

    let input_name = input_name.display();
    let failed =
        |e| Failure::from_batten(&format!("{input_name}: method {} failed", method.name()), e);
    spinner.set_message(format!("fairing with {}", method.name()));
    let out_name = formats::display_name(&args.output);
    // Faired points for a file are written into its temporary file while the result is
    // measured (`io::stage`); kept only when the clean-curve guard kept them. A staging that
    // fails is dropped: the points are then written with the rest, which reports the error.
    let (faired, staged) = match &source {
        Source::Curve(curve) => (
            fair::fair_curve(method.name(), curve, &options).map_err(failed)?,
            None,
        ),
        // The scope joins the writing thread whatever happens, so that a staged file not
        // kept is removed (its `Staged` dropped) before the command ends.
        Source::Points(d) => std::thread::scope(|scope| {
            let stage = |pre: fair::Provisional<'_>| {
                if to_stdout {
                    return None;
                }
                let tangents = pre.tangents.or(d.tangents.as_deref());
                let pts = (pre.points, pre.curve, d.seq.is_closed(), tangents);
                let bytes = points_bytes(out_format, &out_name, pts, &origin).ok()?;
                // The write and its flush to disk (tens of milliseconds at 10⁶ points) on a
                // thread of their own: on a worker of the thread pool, the wait for the disk
                // would leave the measures that run meanwhile one core.
                let output = &args.output;
                Some(scope.spawn(move || io::stage(output, &bytes).ok()))
            };
            let (faired, staged, kept) =
                fair::fair_with_beside(method, &d.seq, &options, stage).map_err(failed)?;
            let staged = staged
                .filter(|_| kept)
                .and_then(|writing| writing.join().ok().flatten());
            Ok::<_, Failure>((faired, staged))
        })?,
    };
    let data = match &source {
        Source::Points(d) => Some(d),
        Source::Curve(_) => None,
    };
    let closed = data.is_some_and(|d| d.seq.is_closed());

    // Tangents: the method's, else the input's carried through.
    let tangents = faired
        .tangents
        .as_deref()
        .or(data.and_then(|d| d.tangents.as_deref()));
    let bytes = match staged {
        Some(_) => Vec::new(),
        None => output_bytes(out_format, &out_name, &faired, closed, tangents, &origin)?,
    };
    // One set, all or none: the report and the curve first, the points last, so that a
    // faired file beside an older report cannot happen (see `io::write_atomic_set`). Points
    // for standard output go there once the files are written.
    let report = match &args.report {
        Some(path) => Some((path, report_json(&faired.report)?.into_bytes())),
        None => None,
    };
    let curve = match (&args.curve_out, curve_format) {
        (Some(path), Some(format)) => {
            Some((path, curve_bytes(path, format, &faired, closed, &origin)?))
        }
        _ => None,
    };
    write_outputs(
        args,
        report.as_ref().map(|(_, b)| b.as_slice()),
        curve.as_ref().map(|(p, b)| (p.as_path(), b.as_slice())),
        (&bytes, staged),
        spinner,
    )?;
    let figures = figures(&faired.report);
    output::note(&summary_line(&figures, data.map(|d| d.lines.as_slice())));
    Ok(verdict(&figures, args.report.is_some()))
}

/// The format of `--curve-out`, once it is known to take a B-spline, to be writable, and to
/// name neither the input nor another output.
///
/// # Errors
/// [`Failure::usage`] naming the file and what is wrong with it.
fn check_curve_out(args: &FairArgs, curve_out: &Path) -> Result<Format, Failure> {
    let f = Format::from_path(curve_out)
        .ok()
        .filter(|f| *f != Format::Text);
    let Some(f) = f else {
        return Err(Failure::usage(anyhow!(
            "{}: --curve-out writes a B-spline: give a .json, .dxf, .igs or .svg file",
            curve_out.display()
        )));
    };
    check_writable(curve_out)?;
    if !formats::is_stdio(&args.input) {
        io::ensure_distinct(&args.input, curve_out).map_err(Failure::usage)?;
    }
    let clash = same_path(curve_out, &args.output)
        || args
            .report
            .as_deref()
            .is_some_and(|r| same_path(curve_out, r));
    if clash {
        return Err(Failure::usage(anyhow!(
            "--curve-out {} names another output too",
            curve_out.display()
        )));
    }
    Ok(f)
}

/// Check what was read against the method: points against its options again (a JSON file
/// can make the curve closed), a B-spline against the methods that take one.
///
/// # Errors
/// [`Failure::usage`] naming the input (`input_name`).
fn check_source(
    source: &Source,
    method: &dyn FairMethod,
    options: &FairOptions,
    input_name: &Path,
) -> Result<(), Failure> {
    match source {
        // A JSON file can make the curve closed: check the method against that too.
        Source::Points(d) => fair::check_options(method, d.seq.is_closed(), options)
            .map_err(|e| Failure::from_batten(&input_name.display().to_string(), e))?,
        Source::Curve(_) if !method.run_curve_supported() => {
            return Err(Failure::usage(anyhow!(
                "{}; method {} takes points (B-spline input: {})",
                IoError::CurveNotPoints {
                    path: input_name.to_path_buf()
                },
                method.name(),
                fair::methods()
                    .iter()
                    .filter(|m| m.run_curve_supported())
                    .map(|m| m.name())
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
        Source::Curve(_) => {}
    }
    Ok(())
}

/// The faired points, encoded as `format` for the output named `out_name`.
///
/// # Errors
/// [`Failure::failed`] when the points cannot be encoded.
fn output_bytes(
    format: Format,
    out_name: &Path,
    faired: &Faired,
    closed: bool,
    tangents: Option<&[Vec2]>,
    origin: &io::Origin,
) -> Result<Vec<u8>, Failure> {
    let pts = (
        faired.points.as_slice(),
        faired.curve.as_ref(),
        closed,
        tangents,
    );
    points_bytes(format, out_name, pts, origin)
}

/// The faired points (or the curve, where the format holds it), closed or not, with their
/// tangents, as the bytes of `format`.
fn points_bytes(
    format: Format,
    out_name: &Path,
    (points, curve, closed, tangents): (&[Point], Option<&BSplineCurve>, bool, Option<&[Vec2]>),
    origin: &io::Origin,
) -> Result<Vec<u8>, Failure> {
    match (format, curve) {
        // SVG holds the faired B-spline itself when it can (a method's cubic).
        (Format::Svg, Some(c)) if io::svg_can_hold(c) => {
            io::format_curve(format, out_name, c, closed, origin)
        }
        _ => io::format_points(format, out_name, points, closed, tangents, origin),
    }
    .map_err(Failure::failed)
}

/// Write the report, the curve and the points as one set, all or none, the points last (see
/// `io::write_atomic_set`); points for standard output go there once the files are written.
///
/// # Errors
/// [`Failure::failed`] for a write that failed.
pub fn write_outputs(
    args: &FairArgs,
    report: Option<&[u8]>,
    curve: Option<(&Path, &[u8])>,
    (bytes, staged): (&[u8], Option<io::Staged>),
    spinner: Spinner,
) -> Result<(), Failure> {
    let to_stdout = formats::is_stdio(&args.output);
    let mut set: Vec<(&Path, &[u8])> = Vec::with_capacity(3);
    if let (Some(path), Some(b)) = (&args.report, report) {
        set.push((path.as_path(), b));
    }
    set.extend(curve);
    match staged {
        // The points, written already, renamed last.
        Some(staged) => io::write_atomic_set_staged(&set, staged),
        None => {
            if !to_stdout {
                set.push((&args.output, bytes));
            }
            io::write_atomic_set(&set)
        }
    }
    .map_err(Failure::failed)?;
    spinner.finish();
    if to_stdout {
        formats::write_output(&args.output, bytes)?;
    }
    Ok(())
}

/// The exit code of a fair whose outputs are written: success, or (with a line on stderr)
/// exit 1 when the tolerance was not met.
pub fn verdict(r: &SummaryFigures<'_>, with_report: bool) -> ExitCode {
    if r.met {
        return ExitCode::SUCCESS;
    }
    output::error_line(&format!(
        "tolerance {} not met: a point moved {}; output{} written anyway",
        r.tolerance.map_or_else(String::new, format_f64),
        sig(r.max_displacement, DIGITS),
        if with_report { " and report" } else { "" },
    ));
    ExitCode::from(EXIT_FAILED)
}

/// Refuse outputs that are the input file, and a report that is the output.
///
/// # Errors
/// [`Failure::usage`].
pub fn check_distinct(args: &FairArgs, to_stdout: bool) -> Result<(), Failure> {
    if !formats::is_stdio(&args.input) && !to_stdout {
        io::ensure_distinct(&args.input, &args.output).map_err(Failure::usage)?;
    }
    if let Some(report) = &args.report {
        if !formats::is_stdio(&args.input) {
            io::ensure_distinct(&args.input, report).map_err(Failure::usage)?;
        }
        if same_path(report, &args.output) {
            return Err(Failure::usage(anyhow!(
                "--report and --output both name {}",
                report.display()
            )));
        }
    }
    Ok(())
}

/// Whether an output can be written (not a directory, in a directory that exists and takes
/// new files), checked before any work so that "cannot write" is a usage error (exit 2)
/// that leaves nothing behind.
///
/// # Errors
/// [`Failure::usage`] naming the path and what stands in the way.
pub fn check_writable(path: &Path) -> Result<(), Failure> {
    io::check_writable(path).map_err(Failure::usage)
}

/// Whether two paths name the same file, as far as can be told before either exists.
pub fn same_path(a: &Path, b: &Path) -> bool {
    let abs = |p: &Path| -> PathBuf { std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf()) };
    abs(a) == abs(b)
}

/// What `batten fair` read: a point list, or a B-spline curve (JSON).
enum Source {
    Points(PointData),
    Curve(BSplineCurve),
}

/// The faired curve (JSON, DXF SPLINE, IGES 126 or SVG) as bytes: the method's own
/// B-spline, or the analysis curve (the C² cubic through the faired points) converted
/// exactly to B-spline form.
fn curve_bytes(
    path: &Path,
    format: Format,
    faired: &Faired,
    closed: bool,
    origin: &io::Origin,
) -> Result<Vec<u8>, Failure> {
    let converted;
    let curve = match &faired.curve {
        Some(c) => c,
        None => {
            let c = PointSeq::new(faired.points.clone(), closed)
                .and_then(|s| analysis::analysis_curve(&s))
                .and_then(|c| BSplineCurve::from_parametric_cubic(&c))
                .map_err(|e| {
                    Failure::failed(anyhow!("{}: cannot build the curve: {e}", path.display()))
                })?;
            converted = c;
            &converted
        }
    };
    match io::format_curve(format, path, curve, closed, origin) {
        Ok(b) => Ok(b),
        // SVG holds Béziers of degree 3 at most: the C² cubic through the faired points.
        Err(_) if format == Format::Svg => {
            io::format_points(format, path, &faired.points, closed, None, origin)
                .map_err(Failure::failed)
        }
        Err(e) => Err(Failure::failed(e)),
    }
}

/// The report as pretty JSON.
pub fn report_json(report: &impl serde::Serialize) -> Result<String, Failure> {
    let mut json = crate::json::pretty(report)
        .map_err(|e| Failure::failed(anyhow!("cannot encode the report: {e}")))?;
    json.push('\n');
    Ok(json)
}

/// What the summary line and the verdict say of a planar report.
fn figures(r: &FairReport) -> SummaryFigures<'_> {
    SummaryFigures {
        method: &r.method,
        status: r.status,
        iterations: r.iterations,
        max_displacement: r.max_displacement,
        index: r.max_displacement_index,
        tolerance: r.tolerance,
        met: r.tolerance_met,
    }
}

/// What the summary line says, from a planar or a space report.
pub struct SummaryFigures<'a> {
    /// The method.
    pub method: &'a str,
    /// How it ended.
    pub status: FairStatus,
    /// Its iterations.
    pub iterations: usize,
    /// The largest displacement.
    pub max_displacement: f64,
    /// The point that moved most.
    pub index: usize,
    /// The tolerance, if any.
    pub tolerance: Option<f64>,
    /// Whether it was met.
    pub met: bool,
}

/// The one-line summary; `lines` gives the input line of each point.
pub fn summary_line(r: &SummaryFigures<'_>, lines: Option<&[usize]>) -> String {
    let at = match lines.and_then(|l| l.get(r.index)) {
        Some(line) if r.max_displacement > 0.0 => {
            format!(" at point {} (line {line})", r.index)
        }
        _ => String::new(),
    };
    let tolerance = match r.tolerance {
        None => "no tolerance".to_string(),
        Some(t) if r.met => format!("tolerance {} met", format_f64(t)),
        Some(t) => format!("tolerance {} NOT met", format_f64(t)),
    };
    format!(
        "{}: {}, {}, max displacement {}{at}, {tolerance}",
        r.method,
        r.status,
        output::count(r.iterations, "iteration"),
        sig(r.max_displacement, DIGITS),
    )
}
