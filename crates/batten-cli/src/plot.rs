//! `batten plot`: draw a curve's curvature comb, κ(s), ρ(s), HAN's x–c plot or all of them
//! as SVG, optionally with the faired points over the input.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::anyhow;
use batten::io;
use batten::plot::{PlotKind, PlotOptions, render, render_space};
use clap::{Args, ValueEnum};

use crate::failure::Failure;
use crate::input;

/// What `batten plot` draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Kind {
    /// The curve with its curvature comb, data points and inflections
    Comb,
    /// Signed curvature κ against arc length
    Curvature,
    /// Radius of curvature ρ = 1/κ against arc length, capped at ±ρ_max
    Radius,
    /// Han's x–c plot of a function segment (c = y''/6 of the cubic spline function)
    Xc,
    /// Displacement of each point against its index (needs --faired)
    Displacement,
    /// Every panel that applies, stacked
    All,
}

impl Kind {
    fn to_plot_kind(self) -> PlotKind {
        match self {
            Kind::Comb => PlotKind::Comb,
            Kind::Curvature => PlotKind::Curvature,
            Kind::Radius => PlotKind::Radius,
            Kind::Xc => PlotKind::Xc,
            Kind::Displacement => PlotKind::Displacement,
            Kind::All => PlotKind::All,
        }
    }
}

/// Arguments of `batten plot`.
#[derive(Debug, Args)]
pub struct PlotArgs {
    /// Point file (.csv, .txt or .json)
    #[arg(value_name = "INPUT")]
    input: PathBuf,
    /// Where to write the SVG (.svg). Never the input file
    #[arg(short, long, value_name = "OUT.svg")]
    output: PathBuf,
    /// Faired points (same count and order as INPUT) to draw over the input, in another colour,
    /// with each point's displacement
    #[arg(long, value_name = "FAIRED")]
    faired: Option<PathBuf>,
    /// What to draw
    #[arg(long, value_enum, default_value_t = Kind::Comb)]
    kind: Kind,
    /// Comb tooth length per unit curvature, in data units [default: the largest tooth is 15% of
    /// the bounding-box diagonal]
    #[arg(long, value_name = "S")]
    comb_scale: Option<f64>,
    /// Cap on |ρ| in the radius plot, in data units [default: the bounding-box diagonal]
    #[arg(long, value_name = "R")]
    rho_max: Option<f64>,
    /// Width of the picture in pixels
    #[arg(long, value_name = "PX", default_value_t = PlotOptions::DEFAULT.width)]
    width: f64,
    /// Height of one panel in pixels (--kind all stacks several)
    #[arg(long, value_name = "PX", default_value_t = PlotOptions::DEFAULT.height)]
    height: f64,
    /// Title of the picture
    #[arg(long)]
    title: Option<String>,
    /// The points form a closed curve (a JSON file can say so with "closed": true)
    #[arg(long)]
    closed: bool,
}

/// Run `batten plot`. Everything is checked before anything is written: bad input leaves no
/// file behind.
///
/// # Errors
/// Usage errors and bad input (exit 2); a failed write (exit 1).
pub fn run(args: &PlotArgs) -> Result<ExitCode, Failure> {
    let mut options = PlotOptions::DEFAULT
        .with_kind(args.kind.to_plot_kind())
        .with_size(args.width, args.height);
    options.comb_scale = args.comb_scale;
    options.rho_max = args.rho_max;
    options.title = args.title.clone();
    options
        .validate()
        .map_err(|e| Failure::from_batten("", e))?;
    if args.kind == Kind::Displacement && args.faired.is_none() {
        return Err(Failure::usage(anyhow!(
            "--kind displacement needs --faired"
        )));
    }
    let mut inputs = vec![args.input.as_path()];
    inputs.extend(args.faired.as_deref());
    check_output(&args.output, &["svg"], &inputs)?;

    let data = match input::read_points_any(&args.input, args.closed, &Default::default())? {
        input::Points::Planar(d) => d,
        input::Points::Space(d) => return plot_space(args, &options, &d.seq),
    };
    let faired = match &args.faired {
        None => None,
        Some(path) => {
            let f = input::read(path, data.seq.is_closed())?;
            check_faired(args, path, f.seq.len(), f.seq.is_closed(), &data.seq)?;
            Some(f.seq)
        }
    };
    let svg =
        render(&data.seq, faired.as_ref(), &options).map_err(|e| render_failure(&args.input, e))?;
    io::write_atomic(&args.output, svg.as_bytes()).map_err(Failure::failed)?;
    Ok(ExitCode::SUCCESS)
}

/// The faired curve must match the input point for point, open or closed alike.
fn check_faired(
    args: &PlotArgs,
    path: &Path,
    len: usize,
    closed: bool,
    input: &batten::PointSeq,
) -> Result<(), Failure> {
    check_faired_shape(args, path, (len, closed), (input.len(), input.is_closed()))
}

/// [`check_faired`] on counts and closedness: `(len, closed)` of the faired file and of the
/// input.
fn check_faired_shape(
    args: &PlotArgs,
    path: &Path,
    faired: (usize, bool),
    input: (usize, bool),
) -> Result<(), Failure> {
    if faired.0 != input.0 {
        return Err(Failure::usage(anyhow!(
            "{}: {} points, but {} has {}; the faired points must match the input one for one",
            path.display(),
            faired.0,
            args.input.display(),
            input.0
        )));
    }
    if faired.1 != input.1 {
        return Err(Failure::usage(anyhow!(
            "{}: a closed curve, but {} is open; pass --closed to read both as closed",
            path.display(),
            args.input.display()
        )));
    }
    Ok(())
}

/// A space curve: its three orthographic views with combs, κ(s) and τ(s) (`--kind comb`,
/// `curvature` or `all`; the other kinds are planar).
fn plot_space(
    args: &PlotArgs,
    options: &PlotOptions,
    input: &batten::SpaceSeq,
) -> Result<ExitCode, Failure> {
    if !matches!(args.kind, Kind::Comb | Kind::Curvature | Kind::All) {
        return Err(Failure::usage(anyhow!(
            "{}: a 3-D curve is drawn as its plan, profile and body plan with combs, and κ(s) \
             and τ(s) (--kind all); --kind radius, xc and displacement are for planar curves",
            args.input.display()
        )));
    }
    let faired = match &args.faired {
        None => None,
        Some(path) => match input::read_points_any(path, input.is_closed(), &Default::default())? {
            input::Points::Space(f) => {
                check_faired_shape(
                    args,
                    path,
                    (f.seq.len(), f.seq.is_closed()),
                    (input.len(), input.is_closed()),
                )?;
                Some(f.seq)
            }
            input::Points::Planar(_) => {
                return Err(Failure::usage(anyhow!(
                    "{}: a planar curve, but {} is a 3-D curve",
                    path.display(),
                    args.input.display()
                )));
            }
        },
    };
    let svg = render_space(input, faired.as_ref(), options)
        .map_err(|e| render_failure(&args.input, e))?;
    io::write_atomic(&args.output, svg.as_bytes()).map_err(Failure::failed)?;
    Ok(ExitCode::SUCCESS)
}

/// A drawing error, named after the input. A plot the data do not allow (an x–c plot of a
/// closed curve or of points that are not a function segment) is a bad request: exit 2.
pub(crate) fn render_failure(input: &Path, e: batten::Error) -> Failure {
    let what = format!("{}: cannot plot", input.display());
    match e {
        batten::Error::Degenerate(_) | batten::Error::LengthMismatch { .. } => {
            Failure::usage(anyhow!("{what}: {e}"))
        }
        e => Failure::from_batten(&what, e),
    }
}

/// Check an output path before any work: its extension is one of `extensions`
/// (case-insensitive), its directory exists, and it is none of the `inputs`.
///
/// # Errors
/// [`Failure::usage`] naming the path and the problem.
pub(crate) fn check_output(
    output: &Path,
    extensions: &[&str],
    inputs: &[&Path],
) -> Result<(), Failure> {
    let ext = output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !ext.is_some_and(|e| extensions.contains(&e.as_str())) {
        return Err(Failure::usage(anyhow!(
            "{}: the output must be a .{} file",
            output.display(),
            extensions.join(" or .")
        )));
    }
    crate::fair_cmd::check_writable(output)?;
    for input in inputs {
        io::ensure_distinct(input, output).map_err(Failure::usage)?;
    }
    Ok(())
}
