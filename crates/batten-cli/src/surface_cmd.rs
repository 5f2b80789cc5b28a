//! `batten analyze-surface` and `batten fair-surface`: B-spline surfaces as JSON
//! (`{"degree_u", "degree_v", "knots_u", "knots_v", "control_points", "weights"?}` or a
//! `{"grid": ...}` of points to interpolate).

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::anyhow;
use batten::io::{self, Format};
use batten::surface::{
    BoundaryFix, MinMax, SurfaceAnalysis, SurfaceFairOptions, SurfaceMethod, analyze_surface,
    fair_surface,
};
use clap::Args;

use crate::failure::{EXIT_FAILED, Failure};
use crate::fair_cmd::{check_writable, same_path};
use crate::input;
use crate::output::{self, sig};

/// Significant digits in tables.
const DIGITS: usize = 5;

/// Arguments of `batten analyze-surface`.
#[derive(Debug, Args)]
pub struct AnalyzeSurfaceArgs {
    /// Surface file (.json): a B-spline surface or a grid of points
    #[arg(value_name = "INPUT")]
    pub input: PathBuf,
    /// Print a JSON object instead of a table
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `batten fair-surface`.
#[derive(Debug, Args)]
pub struct FairSurfaceArgs {
    /// Surface file (.json): a B-spline surface or a grid of points
    #[arg(value_name = "INPUT")]
    pub input: PathBuf,
    /// Where to write the faired surface (.json; never the input file)
    #[arg(short, long, value_name = "OUTPUT")]
    pub output: PathBuf,
    /// salvi (target principal curvatures) or eck-hadenfeld (thin-plate energy)
    #[arg(long, value_name = "NAME", default_value = "salvi")]
    pub method: String,
    /// Largest distance |S_faired(u,v) − S(u,v)|, in data units [default: 1% of the control
    /// net's bounding-box diagonal]
    #[arg(long, value_name = "D")]
    pub tolerance: Option<f64>,
    /// Hold the boundary: the outer row of control points along every edge (bare
    /// `--fix-boundary`, or `=position`), or the outer two rows (`=tangent`)
    #[arg(long, value_name = "WHAT", num_args = 0..=1, require_equals = true,
          default_missing_value = "position", value_parser = parse_boundary)]
    pub fix_boundary: Option<BoundaryFix>,
    /// Most control-point moves
    #[arg(long, value_name = "N")]
    pub max_iterations: Option<usize>,
    /// Write the fairing report (JSON) to this file
    #[arg(long, value_name = "R.json")]
    pub report: Option<PathBuf>,
    /// A method parameter, KEY=VALUE (salvi: samples_per_span, target_spans, smoothing,
    /// robust_passes, tabu, simplex_evaluations; eck-hadenfeld: tabu)
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

fn parse_boundary(s: &str) -> Result<BoundaryFix, String> {
    match s {
        "position" => Ok(BoundaryFix::Position),
        "tangent" => Ok(BoundaryFix::Tangent),
        "free" => Ok(BoundaryFix::Free),
        _ => Err(format!("'{s}' is not one of position, tangent, free")),
    }
}

/// Run `batten analyze-surface`.
///
/// # Errors
/// Bad input (exit 2).
pub fn analyze(args: &AnalyzeSurfaceArgs) -> Result<ExitCode, Failure> {
    let s = io::read_surface_json(&args.input).map_err(Failure::usage)?;
    let a = analyze_surface(&s);
    let text = if args.json {
        let mut t = crate::json::pretty(&a)
            .map_err(|e| Failure::failed(anyhow!("cannot encode the analysis: {e}")))?;
        t.push('\n');
        t
    } else {
        table(&args.input.display().to_string(), &a)
    };
    output::stdout(&text)?;
    Ok(ExitCode::SUCCESS)
}

fn range(m: Option<MinMax>) -> String {
    m.map_or_else(
        || "-".into(),
        |m| format!("{} .. {}", sig(m.min, DIGITS), sig(m.max, DIGITS)),
    )
}

/// The human-readable table of `analyze-surface`.
fn table(name: &str, a: &SurfaceAnalysis) -> String {
    let mut s = format!(
        "{name}: degree {}x{}, {}x{} control points, sampled on {}x{}\n",
        a.degree_u,
        a.degree_v,
        a.control_points[0],
        a.control_points[1],
        a.samples[0],
        a.samples[1]
    );
    let rows = [
        ("kappa1", range(a.kappa1), "larger principal curvature"),
        ("kappa2", range(a.kappa2), "smaller principal curvature"),
        ("gaussian", range(a.gaussian), "K = kappa1 kappa2"),
        ("mean", range(a.mean), "H = (kappa1 + kappa2)/2"),
        (
            "umbilic fraction",
            sig(a.umbilic_fraction, DIGITS),
            "share of samples with kappa1 = kappa2",
        ),
        (
            "fairness measure",
            sig(a.fairness_measure, DIGITS),
            "Salvi-Varady Pi: sum (kappa - target)^2",
        ),
        (
            "singular samples",
            a.singular_samples.to_string(),
            "where S_u x S_v = 0",
        ),
    ];
    for (label, value, what) in rows {
        // Writing to a String cannot fail.
        let _ = writeln!(s, "  {label:<17} {value:>24}   {what}");
    }
    s
}

/// Run `batten fair-surface`. Options and output paths are checked before the input is read.
///
/// # Errors
/// Usage errors (exit 2); a failed run or write (exit 1). A missed tolerance writes the
/// result and the report and exits 1.
pub fn fair(args: &FairSurfaceArgs) -> Result<ExitCode, Failure> {
    let method = SurfaceMethod::from_name(&args.method).map_err(|e| Failure::from_batten("", e))?;
    let mut options = SurfaceFairOptions::default()
        .with_method(method)
        .with_fix_boundary(args.fix_boundary.unwrap_or_default());
    options.tolerance = args.tolerance;
    options.max_iterations = args.max_iterations;
    options.params = input::parse_sets(&args.set)?;
    options.check().map_err(|e| Failure::from_batten("", e))?;
    for out in std::iter::once(&args.output).chain(args.report.as_ref()) {
        if !matches!(Format::from_path(out), Ok(Format::Json)) {
            return Err(Failure::usage(anyhow!(
                "{}: fair-surface writes JSON: give a .json file",
                out.display()
            )));
        }
        check_writable(out)?;
        io::ensure_distinct(&args.input, out).map_err(Failure::usage)?;
    }
    if let Some(r) = &args.report
        && same_path(r, &args.output)
    {
        return Err(Failure::usage(anyhow!(
            "--report and --output both name {}",
            r.display()
        )));
    }
    let s = io::read_surface_json(&args.input).map_err(Failure::usage)?;
    let name = args.input.display();
    let (faired, report) = fair_surface(&s, &options).map_err(|e| {
        Failure::from_batten(&format!("{name}: method {} failed", method.name()), e)
    })?;
    io::write_surface_json(&args.output, &faired).map_err(Failure::failed)?;
    if let Some(r) = &args.report {
        let mut text = crate::json::pretty(&report)
            .map_err(|e| Failure::failed(anyhow!("cannot encode the report: {e}")))?;
        text.push('\n');
        io::write_atomic(r, text.as_bytes()).map_err(Failure::failed)?;
    }
    output::note(&format!(
        "{name}: {} {} moves, Pi {} -> {}, max displacement {} (tolerance {}{}), {}",
        method.name(),
        report.moves,
        sig(report.before.pi_hat, DIGITS),
        sig(report.after.pi_hat, DIGITS),
        sig(report.max_displacement, DIGITS),
        sig(report.tolerance, DIGITS),
        if report.tolerance_met {
            ", met"
        } else {
            ", MISSED"
        },
        output::seconds(report.time_s),
    ));
    if report.tolerance_met {
        Ok(ExitCode::SUCCESS)
    } else {
        Ok(ExitCode::from(EXIT_FAILED))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boundary_values() {
        assert_eq!(parse_boundary("tangent"), Ok(BoundaryFix::Tangent));
        assert!(parse_boundary("curvature").is_err());
    }
}
