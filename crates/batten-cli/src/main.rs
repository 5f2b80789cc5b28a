//! `batten`: analyse, fair and compare planar curves given as point files.
//!
//! Exit codes: 0 success; 1 a fairing that failed, or did not meet its tolerance (output and
//! report are still written then), or an output that could not be written; 2 bad input or
//! usage (unreadable or malformed input file, unknown method, unknown or malformed `--set`,
//! bad option values), with exactly one line on stderr naming the file, the line and the
//! problem. clap's own usage errors also exit 2.
//!
//! Output goes through explicit handles ([`output`]), never `println!`: a closed pipe
//! (`batten methods | head -1`) must end the program quietly, where `println!` panics. So the
//! crate needs no `allow` for the workspace's `print_stdout`/`print_stderr` lints.

mod analyze;
mod batch;
mod compare;
mod evaluate;
mod failure;
mod fair_cmd;
mod fair_space_cmd;
mod figure;
mod formats;
mod input;
mod json;
mod methods;
mod output;
mod plot;
mod report;
mod signals;
mod spinner;
mod surface_cmd;
mod surface_plot;
mod surface_report;
mod usage;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand, ValueEnum};

/// Fair planar curves: measure the curvature of the curve through a list of points, move the
/// points as little as possible until it is fair, and compare the published methods.
///
/// Point files are chosen by extension: .csv/.txt (one "x,y" per line; comma, semicolon or
/// whitespace separators; # comments; an optional header line) or .json
/// ({"points": [[x, y], ...], "closed": false}).
#[derive(Debug, Parser)]
#[command(name = "batten", version, max_term_width = 100)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Print the fairness metrics of the curve through the points
    Analyze(AnalyzeArgs),
    /// Fair the points and write them (same count and order) to OUTPUT
    Fair(FairArgs),
    /// List the fairing methods, their descriptions and parameters
    Methods(methods::MethodsArgs),
    /// Run several methods on the same input and tabulate the results (Han et al.'s Table 1)
    Compare(CompareArgs),
    /// Draw the curvature comb, κ(s), ρ(s) or x–c plot as SVG, the faired curve over the input
    Plot(plot::PlotArgs),
    /// Run several methods and write one HTML page: metrics, the comparison table, combs, κ(s)
    Report(report::ReportArgs),
    /// Fair many point files in parallel into OUT_DIR, with a report each and a summary
    Batch(batch::BatchArgs),
    /// Kuragano & Yamaguchi's fairness evaluation: which polynomial ρ(s) the curve follows best
    Evaluate(evaluate::EvaluateArgs),
    /// Curvature ranges, umbilics and the fairness measure of a B-spline surface (JSON)
    AnalyzeSurface(surface_cmd::AnalyzeSurfaceArgs),
    /// Fair a B-spline surface (JSON) within a tolerance: salvi or eck-hadenfeld
    FairSurface(surface_cmd::FairSurfaceArgs),
    /// Curvature maps, isophotes, zebra and deviation of a B-spline surface (PNG or SVG)
    PlotSurface(surface_plot::PlotSurfaceArgs),
}

/// Arguments of `batten analyze`.
#[derive(Debug, Args)]
struct AnalyzeArgs {
    /// Point file (.csv, .txt, .json, .dxf, .igs, .svg; `-` reads standard input)
    #[arg(value_name = "INPUT")]
    input: PathBuf,
    /// Print a JSON object instead of a table
    #[arg(long)]
    json: bool,
    /// The points form a closed curve (the last connects to the first; do not repeat it)
    #[arg(long)]
    closed: bool,
    #[command(flatten)]
    pick: formats::PickArgs,
}

/// Arguments of `batten fair`.
#[derive(Debug, Args)]
struct FairArgs {
    /// Point file (.csv, .txt, .json, .dxf, .igs, .svg; `-` reads standard input), or a
    /// B-spline (JSON {"degree", "knots", "control_points", "weights"}, a DXF SPLINE, IGES
    /// entity 126, SVG Béziers) for the methods that work on control points
    #[arg(value_name = "INPUT")]
    input: PathBuf,
    /// Where to write the faired points; the format follows the extension (.csv, .txt, .json,
    /// .dxf, .igs, .svg); `-` writes standard output. Never the input file
    #[arg(short, long, value_name = "OUTPUT")]
    output: PathBuf,
    #[command(flatten)]
    how: input::MethodArgs,
    #[command(flatten)]
    bounds: input::BoundArgs,
    /// Write the fairing report (JSON) to this file
    #[arg(long, value_name = "R.json")]
    report: Option<PathBuf>,
    /// Also write the faired curve as a B-spline (.json: degree, knots, control_points; .dxf:
    /// SPLINE; .igs: entity 126; .svg: Bézier path): the method's own curve, or the C² cubic
    /// through the faired points for point methods
    #[arg(long, value_name = "FILE")]
    curve_out: Option<PathBuf>,
    /// The points form a closed curve (a JSON file can say so with "closed": true)
    #[arg(long)]
    closed: bool,
    #[command(flatten)]
    pick: formats::PickArgs,
}

/// Output format of `batten compare`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum TableFormat {
    /// A Markdown table
    Md,
    /// A JSON object
    Json,
    /// CSV with a header row
    Csv,
}

/// Arguments of `batten compare`.
#[derive(Debug, Args)]
struct CompareArgs {
    /// Point file (.csv, .txt or .json)
    #[arg(value_name = "INPUT")]
    input: PathBuf,
    /// Methods to run, comma-separated [default: all]. As in Han et al., mst runs at the max
    /// displacement of the first method listed, unless it is first itself
    #[arg(long, value_delimiter = ',', value_name = "A,B,...")]
    methods: Vec<String>,
    #[command(flatten)]
    bounds: input::BoundArgs,
    /// Output format
    #[arg(long, value_enum, default_value_t = TableFormat::Md)]
    format: TableFormat,
    /// The points form a closed curve
    #[arg(long)]
    closed: bool,
}

fn main() -> ExitCode {
    let argv: Vec<String> = std::env::args_os()
        .map(|a| a.to_string_lossy().into_owned())
        .collect();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => match usage::classify(e, &argv) {
            usage::ClapOutcome::Print(e) => e.exit(),
            usage::ClapOutcome::Usage(message) => {
                output::error_line(&message);
                return ExitCode::from(failure::EXIT_USAGE);
            }
        },
    };
    signals::install();
    let result = match cli.command {
        Command::Analyze(a) => analyze::run(&a),
        Command::Fair(a) => fair_cmd::run(&a),
        Command::Methods(a) => methods::run(&a),
        Command::Compare(a) => compare::run(&a),
        Command::Plot(a) => plot::run(&a),
        Command::Report(a) => report::run(&a),
        Command::Batch(a) => batch::run(&a),
        Command::Evaluate(a) => evaluate::run(&a),
        Command::AnalyzeSurface(a) => surface_cmd::analyze(&a),
        Command::FairSurface(a) => surface_cmd::fair(&a),
        Command::PlotSurface(a) => surface_plot::run(&a),
    };
    match result {
        Ok(code) => code,
        Err(f) => {
            output::error_line(&f.error.to_string());
            f.exit_code()
        }
    }
}

#[cfg(test)]
mod tests {
    use clap::CommandFactory as _;

    use super::Cli;

    #[test]
    fn clap_definition_is_consistent() {
        Cli::command().debug_assert();
    }
}
