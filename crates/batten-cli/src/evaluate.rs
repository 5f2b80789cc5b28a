//! `batten evaluate`: the fairness evaluation of Kuragano & Yamaguchi (docs/algorithms/kuragano.md
//! §5.6) of the curve through the points (their uniform quintic interpolant) or of a B-spline JSON
//! file, printed like the paper's Tables 3 and 4, or as JSON.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::anyhow;
use batten::analysis::{
    self, DEFAULT_METHOD_GRADIENT_FRACTION, DesignEnds, KuraganoOptions, RhoResidual, RocEvaluation,
};
use batten::io;
use clap::{Args, ValueEnum};

use crate::failure::Failure;
use crate::output;

/// Decimals of the angle as the paper prints it (truncated, not rounded: Table 4).
const PAPER_ANGLE_DECIMALS: u32 = 2;

/// Decimals of the correlation cosine (the paper's text quotes six).
const COSINE_DECIMALS: usize = 6;

/// The paper's names of the six polynomial degrees (Tables 2–4).
const DEGREE_NAMES: [&str; 6] = ["linear", "quadratic", "cubic", "quartic", "quintic", "six"];

/// Ends of the quintic interpolant of a point file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum EndsArg {
    /// Gradients at points 0, 1, m−2, m−1 estimated from the points (one end chord long)
    Gradients,
    /// R'' = 0 and R'''' = 0 at both ends (ρ is infinite there)
    Natural,
}

/// Residual of the shape modification.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ResidualArg {
    /// ρ − ρ̂, with the curvature form where ρ is infinite
    Rho,
    /// κ − 1/ρ̂
    Kappa,
}

/// Arguments of `batten evaluate`.
#[derive(Debug, Args)]
pub struct EvaluateArgs {
    /// Point file (.csv, .txt or .json) or a B-spline curve (.json)
    #[arg(value_name = "INPUT")]
    input: PathBuf,
    /// Print a JSON object instead of a table
    #[arg(long)]
    json: bool,
    /// Number of ρ samples along the normalised arc length, at most 100000 [default: max(41, 10 per segment + 1)]
    #[arg(long, value_name = "N")]
    samples: Option<usize>,
    /// Cap on |ρ| in data units [default: 100 × the curve length]
    #[arg(long, value_name = "R")]
    rho_max: Option<f64>,
    /// Residual of the shape modification
    #[arg(long, value_enum, default_value_t = ResidualArg::Rho)]
    residual: ResidualArg,
    /// Ends of the quintic through the points (ignored for a curve file)
    #[arg(long, value_enum, default_value_t = EndsArg::Gradients)]
    ends: EndsArg,
}

/// Run `batten evaluate`.
///
/// # Errors
/// Bad input or options (exit 2); an evaluation that cannot be computed (exit 1).
pub fn run(args: &EvaluateArgs) -> Result<ExitCode, Failure> {
    let name = crate::formats::display_name(&args.input)
        .display()
        .to_string();
    let mut opts = KuraganoOptions::default()
        .with_residual(match args.residual {
            ResidualArg::Rho => RhoResidual::Rho,
            ResidualArg::Kappa => RhoResidual::Kappa,
        })
        .with_ends(match args.ends {
            EndsArg::Gradients => DesignEnds::Gradients {
                fraction: DEFAULT_METHOD_GRADIENT_FRACTION,
            },
            EndsArg::Natural => DesignEnds::Natural,
        });
    if let Some(n) = args.samples {
        opts = opts.with_samples(n);
    }
    if let Some(r) = args.rho_max {
        opts = opts.with_rho_max(r);
    }
    let what = format!("{name}: cannot evaluate");
    // A B-spline (JSON, DXF SPLINE, IGES 126, SVG Béziers) or a point list.
    let format = crate::formats::format_of(&args.input, None)?;
    let source =
        crate::formats::read_input(&args.input, format, false, &io::Pick::default())?.source;
    let evaluation = match source {
        io::Source::Space(_) => return Err(crate::input::space_not_planar(&args.input)),
        io::Source::Curve(c) => analysis::evaluate_roc_fairness(&c, &opts),
        io::Source::Points(data) => {
            if data.seq.is_closed() {
                return Err(Failure::usage(anyhow!(
                    "{name}: the fairness evaluation needs an open curve"
                )));
            }
            analysis::evaluate_roc_fairness(data.seq.points(), &opts)
        }
    }
    .map_err(|e| Failure::from_batten(&what, e))?;
    let text = if args.json {
        let mut s = crate::json::pretty(&evaluation)
            .map_err(|e| Failure::failed(anyhow!("cannot encode the evaluation: {e}")))?;
        s.push('\n');
        s
    } else {
        table(&name, &evaluation)
    };
    output::stdout(&text)?;
    Ok(ExitCode::SUCCESS)
}

/// The table: one row per degree as in the paper's Tables 3 (cosine) and 4 (angle, truncated
/// to two decimals), with the full angle beside it.
fn table(name: &str, e: &RocEvaluation) -> String {
    let mut s = format!("{name}: fairness evaluation (Kuragano & Yamaguchi)\n");
    // Writing to a String cannot fail.
    let _ = writeln!(
        s,
        "  {:<13} {:<10} {:>11} {:>9} {:>14}",
        "degree", "applicable", "correlation", "angle °", "angle ° (full)"
    );
    for d in &e.degrees {
        let label = DEGREE_NAMES
            .get(d.degree.wrapping_sub(1))
            .copied()
            .unwrap_or("?");
        let (cos, short, full) = match (d.correlation, d.angle_deg) {
            (Some(c), Some(a)) => (
                format!("{c:.COSINE_DECIMALS$}"),
                format!("{:.2}", analysis::truncate_angle(a, PAPER_ANGLE_DECIMALS)),
                format!("{a:.10}"),
            ),
            _ => ("-".to_string(), "-".to_string(), "-".to_string()),
        };
        let _ = writeln!(
            s,
            "  {:<13} {:<10} {cos:>11} {short:>9} {full:>14}",
            format!("{} ({})", label, d.degree),
            if d.applicable { "yes" } else { "no" },
        );
    }
    match (e.best_degree, e.fairness) {
        (Some(d), Some(f)) => {
            let label = DEGREE_NAMES.get(d.wrapping_sub(1)).copied().unwrap_or("?");
            let _ = write!(
                s,
                "  best: {label} (degree {d}), fairness {f:.COSINE_DECIMALS$}"
            );
            let max = e
                .degrees
                .iter()
                .filter_map(|r| r.correlation)
                .fold(f64::NEG_INFINITY, f64::max);
            if max > f {
                // A tie (analysis::ROC_TIE_TOLERANCE) went to the lower degree: say so.
                let _ = write!(
                    s,
                    " (the lowest degree within {:e} of the largest correlation, \
                     {max:.COSINE_DECIMALS$})",
                    analysis::ROC_TIE_TOLERANCE
                );
            }
            let _ = writeln!(s);
        }
        _ => {
            let _ = writeln!(
                s,
                "  best: none (no degree is applicable: the curve has an inflection, is \
                 straight, or every fitted radius of curvature changes sign)"
            );
        }
    }
    s
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use batten::analysis::DegreeResult;

    use super::*;

    fn row(degree: usize, cos: Option<f64>) -> DegreeResult {
        DegreeResult::from_correlation(degree, cos)
    }

    #[test]
    fn table_prints_truncated_and_full_angles() {
        // Curve F of the paper: six degrees, 0.999800 → 1.1459°, printed 1.14.
        let e = RocEvaluation::from_rows(vec![
            row(1, Some(0.969)),
            row(2, Some(0.990)),
            row(3, None),
            row(4, Some(0.998)),
            row(5, Some(0.998)),
            row(6, Some(0.9998)),
        ]);
        assert_eq!((e.best_degree, e.fairness), (Some(6), Some(0.9998)));
        let t = table("f.csv", &e);
        assert!(t.starts_with("f.csv: fairness evaluation"), "{t}");
        assert_eq!(t.lines().count(), 9, "{t}");
        let six = t.lines().find(|l| l.contains("six (6)")).unwrap();
        assert!(
            six.contains("0.999800") && six.contains(" 1.14 ") && six.contains("1.1459"),
            "{six}"
        );
        let cubic = t.lines().find(|l| l.contains("cubic (3)")).unwrap();
        assert!(cubic.contains(" no ") && cubic.contains('-'), "{cubic}");
        assert!(t.contains("best: six (degree 6), fairness 0.999800"), "{t}");
    }

    #[test]
    fn table_without_a_best_degree() {
        let e = RocEvaluation::from_rows((1..=6).map(|d| row(d, None)).collect());
        assert_eq!((e.best_degree, e.fairness), (None, None));
        assert!(table("s.csv", &e).contains("best: none"));
    }
}
