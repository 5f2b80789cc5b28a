//! `batten analyze`: the fairness metrics of the curve through the points.

use std::fmt::Write as _;
use std::process::ExitCode;

use anyhow::anyhow;
use batten::FairnessMetrics;
use batten::analysis::SpaceMetrics;
use serde::Serialize;

use crate::AnalyzeArgs;
use crate::failure::Failure;
use crate::output::{self, sig};
use crate::spinner::Spinner;
use crate::{formats, input};

/// Significant digits of real numbers in the table.
const DIGITS: usize = 6;

/// Run `batten analyze`.
///
/// # Errors
/// Bad input (exit 2); a metric that cannot be computed (exit 1).
pub fn run(args: &AnalyzeArgs) -> Result<ExitCode, Failure> {
    let name = formats::display_name(&args.input).display().to_string();
    // One spinner from the start: reading 10⁷ points takes seconds too.
    let spinner = Spinner::start(format!("reading {name}"));
    let read = input::read_points_any(&args.input, args.closed, &args.pick)?;
    let failed = |e| Failure::from_batten(&format!("{name}: cannot analyse"), e);
    let text = match read {
        input::Points::Planar(data) => {
            spinner.set_message(format!("analysing {} points", data.seq.len()));
            let metrics = FairnessMetrics::of_seq(&data.seq).map_err(failed)?;
            spinner.finish();
            if args.json {
                json(&metrics)?
            } else {
                table(&name, &metrics)
            }
        }
        input::Points::Space(data) => {
            spinner.set_message(format!("analysing {} points", data.seq.len()));
            let metrics = SpaceMetrics::of_seq(&data.seq).map_err(failed)?;
            spinner.finish();
            if args.json {
                json(&metrics)?
            } else {
                space_table(&name, &metrics)
            }
        }
    };
    output::stdout(&text)?;
    Ok(ExitCode::SUCCESS)
}

/// The metrics as pretty JSON, with a final newline.
fn json(metrics: &impl Serialize) -> Result<String, Failure> {
    let mut s = crate::json::pretty(metrics)
        .map_err(|e| Failure::failed(anyhow!("cannot encode the metrics: {e}")))?;
    s.push('\n');
    Ok(s)
}

/// The human-readable table of a space curve's metrics.
fn space_table(name: &str, m: &SpaceMetrics) -> String {
    let kind = if m.closed { "closed" } else { "open" };
    let rows: [(&str, String, &str); 9] = [
        (
            "curvature extrema",
            m.curvature_extrema.to_string(),
            "local extrema of κ(s)",
        ),
        (
            "torsion changes",
            m.torsion_sign_changes.to_string(),
            "sign changes of τ(s)",
        ),
        (
            "torsion extrema",
            m.torsion_extrema.to_string(),
            "local extrema of τ(s)",
        ),
        ("max curvature", sig(m.max_curvature, DIGITS), "max κ"),
        ("max torsion", sig(m.max_torsion, DIGITS), "max |τ|"),
        ("strain energy", sig(m.strain_energy, DIGITS), "∫ κ² ds"),
        (
            "variation energy",
            sig(m.variation_energy, DIGITS),
            "∫ (dκ/ds)² ds",
        ),
        ("torsion energy", sig(m.torsion_energy, DIGITS), "∫ τ² ds"),
        ("length", sig(m.length, DIGITS), "arc length"),
    ];
    rows_table(
        format!("{name}: {} points, {kind} 3-D curve\n", m.points),
        &rows,
    )
}

/// A heading and one aligned line per row.
fn rows_table(mut s: String, rows: &[(&str, String, &str)]) -> String {
    for (label, value, what) in rows {
        // Writing to a String cannot fail.
        let _ = writeln!(s, "  {label:<18} {value:>14}   {what}");
    }
    s
}

/// The human-readable table.
fn table(name: &str, m: &FairnessMetrics) -> String {
    let kind = if m.closed { "closed" } else { "open" };
    let rows: [(&str, String, &str); 9] = [
        (
            "inflections",
            m.inflections.to_string(),
            "sign changes of κ",
        ),
        (
            "vibrations",
            m.vibrations.to_string(),
            "sign changes of the dκ/ds jumps at the knots",
        ),
        (
            "curvature extrema",
            m.curvature_extrema.to_string(),
            "local extrema of κ(s)",
        ),
        ("strain energy", sig(m.strain_energy, DIGITS), "∫ κ² ds"),
        (
            "variation energy",
            sig(m.variation_energy, DIGITS),
            "∫ (dκ/ds)² ds",
        ),
        ("max curvature", sig(m.max_curvature, DIGITS), "max |κ|"),
        (
            "GFI",
            sig(m.gfi, DIGITS),
            "Calì's global fairness indicator",
        ),
        (
            "max r''' jump",
            sig(m.max_third_derivative_jump, DIGITS),
            "largest third-derivative jump at a knot",
        ),
        ("length", sig(m.length, DIGITS), "arc length"),
    ];
    rows_table(
        format!("{name}: {} points, {kind} curve\n", m.points),
        &rows,
    )
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use batten::{Point, PointSeq};

    use super::*;

    #[test]
    fn table_lists_every_metric() {
        let pts = (0..12)
            .map(|i| {
                let x = f64::from(i) * 0.5;
                Point::new(x, x.sin())
            })
            .collect();
        let m = FairnessMetrics::of_seq(&PointSeq::open(pts).unwrap()).unwrap();
        let t = table("a.csv", &m);
        assert!(t.starts_with("a.csv: 12 points, open curve\n"), "{t}");
        for needle in [
            "inflections",
            "vibrations",
            "curvature extrema",
            "strain energy",
            "variation energy",
            "max curvature",
            "GFI",
            "max r''' jump",
            "length",
            &sig(m.strain_energy, DIGITS),
            &sig(m.length, DIGITS),
        ] {
            assert!(t.contains(needle), "{needle} missing from\n{t}");
        }
        assert_eq!(t.lines().count(), 10);
    }
}
