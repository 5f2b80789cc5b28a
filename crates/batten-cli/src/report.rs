//! `batten report`: run several methods on one input and write one self-contained HTML page:
//! the input's metrics and plots, the table of `batten compare`, and for every method the
//! faired curve's comb and κ(s) drawn over the input's.
//!
//! The methods are run by the library's [`batten::fair::compare`], as in `batten compare`
//! (the same runs, options and table); the page has inline SVG and CSS only: no scripts,
//! fonts or other resources to fetch.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use batten::fair::{self, ComparisonOutcome, ComparisonRow};
use batten::io::{self, format_f64};
use batten::plot::{PlotKind, PlotOptions, auto_comb_scale, render};
use batten::{FairOptions, FairnessMetrics, PointSeq};
use clap::Args;

use crate::compare::{self, COLUMNS, Table};
use crate::failure::Failure;
use crate::input;
use crate::output::sig;
use crate::plot::{check_output, render_failure};

/// Significant digits of the metrics table.
const DIGITS: usize = 4;
/// Size of each plot on the page, in pixels: two fit side by side in a 1200 px window.
const PLOT_SIZE: (f64, f64) = (570.0, 430.0);

/// Arguments of `batten report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// Point file (.csv, .txt or .json), or a B-spline surface (.json; then the methods are
    /// the surface methods and the page shows curvature maps, isophotes and zebra)
    #[arg(value_name = "INPUT")]
    input: PathBuf,
    /// Where to write the page (.html). Never the input file
    #[arg(short, long, value_name = "report.html")]
    output: PathBuf,
    /// Methods to run, comma-separated [default: all]; as in `batten compare`, mst runs at the
    /// max displacement of the first method listed unless it is first itself
    #[arg(long, value_delimiter = ',', value_name = "A,B,...")]
    methods: Vec<String>,
    #[command(flatten)]
    bounds: input::BoundArgs,
    /// The points form a closed curve
    #[arg(long)]
    closed: bool,
}

/// Run `batten report`.
///
/// # Errors
/// Usage errors and bad input (exit 2, nothing written); a failed analysis, plot or write
/// (exit 1). Methods that fail are reported on the page and make the exit code 1.
pub fn run(args: &ReportArgs) -> Result<ExitCode, Failure> {
    if crate::surface_report::is_surface_file(&args.input) {
        return crate::surface_report::run(&crate::surface_report::SurfaceReportArgs {
            input: &args.input,
            output: &args.output,
            methods: &args.methods,
            tolerance: args.bounds.tolerance,
            curve_options: args.bounds.fix_ends.is_some() || args.closed,
        });
    }
    let methods = compare::resolve(&args.methods)?;
    let base = input::options(
        args.bounds.tolerance,
        args.bounds.fix_ends.unwrap_or_default(),
        None,
        BTreeMap::new(),
    );
    base.validate().map_err(|e| Failure::from_batten("", e))?;
    check_output(&args.output, &["html", "htm"], &[args.input.as_path()])?;
    let data = input::read(&args.input, args.closed)?;
    let name = crate::formats::display_name(&args.input)
        .display()
        .to_string();
    let before = FairnessMetrics::of_seq(&data.seq)
        .map_err(|e| Failure::from_batten(&format!("{name}: cannot analyse"), e))?;

    let comparison = fair::compare(&methods, &data.seq, &base);
    let rows = &comparison.rows;
    let table = compare::table(&name, &data.seq, &base, &before, rows);
    let page = page(&name, &data.seq, &base, &before, rows, &table)?;
    io::write_atomic(&args.output, page.as_bytes()).map_err(Failure::failed)?;
    Ok(compare::exit_code(&name, &comparison))
}

/// The page's style sheet.
const CSS: &str = "\
body{font-family:sans-serif;color:#222;margin:24px auto;max-width:1180px;padding:0 12px}\
h1{font-size:24px;margin-bottom:4px}h2{font-size:19px;margin-top:32px;border-bottom:1px solid #ddd}\
p.meta{color:#555;margin-top:0}\
table{border-collapse:collapse;margin:8px 0}\
th,td{border:1px solid #ccc;padding:3px 9px;font-size:14px}\
th{background:#f3f3f3}td.r,th.r{text-align:right}td.c,th.c{text-align:center}\
.plots{display:flex;flex-wrap:wrap;gap:10px}.plots svg{border:1px solid #ddd;max-width:100%;height:auto}\
ol.notes{font-size:13px;color:#444}p.note{color:#8a1c10}";

/// Escape text for HTML.
fn esc(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            c => out.push(c),
        }
    }
    out
}

/// The HTML page.
fn page(
    name: &str,
    seq: &PointSeq,
    base: &FairOptions,
    before: &FairnessMetrics,
    rows: &[ComparisonRow],
    table: &Table,
) -> Result<String, Failure> {
    // One faired point sequence per method that ran (or why there is none).
    let faired: Vec<Result<PointSeq, String>> = rows
        .iter()
        .map(|row| match &row.outcome {
            ComparisonOutcome::Ran(f) => seq
                .with_points(f.points.clone())
                .map_err(|e| format!("the faired points cannot be drawn: {e}")),
            ComparisonOutcome::Failed(e) => Err(format!("failed: {e}")),
            ComparisonOutcome::Skipped(why) => Err(format!("skipped: {why}")),
        })
        .collect();
    let drawn: Vec<&PointSeq> = faired.iter().filter_map(|f| f.as_ref().ok()).collect();
    // One comb scale for every picture, so that combs compare across methods.
    let scale = auto_comb_scale(seq, &drawn).map_err(|e| render_failure_named(name, e))?;
    let plot = |faired: Option<&PointSeq>, kind: PlotKind, title: String| {
        let mut o = PlotOptions::DEFAULT
            .with_kind(kind)
            .with_size(PLOT_SIZE.0, PLOT_SIZE.1)
            .with_title(title);
        if scale > 0.0 {
            o = o.with_comb_scale(scale);
        }
        render(seq, faired, &o).map_err(|e| render_failure_named(name, e))
    };

    let mut h = String::with_capacity(256 * 1024);
    let title = format!("batten report: {name}");
    // Writing to a String cannot fail.
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{}</title>\n<style>{CSS}</style>\n</head>\n<body>\n<h1>{}</h1>\n",
        esc(&title),
        esc(&title)
    );
    let _ = writeln!(
        h,
        "<p class=\"meta\">{} points, {}; tolerance {}{}; made by batten {}.</p>",
        seq.len(),
        if seq.is_closed() { "closed" } else { "open" },
        base.tolerance
            .map_or_else(|| "none".to_string(), format_f64),
        if base.fix_ends.is_fixed() {
            format!("; ends fixed ({})", base.fix_ends)
        } else {
            String::new()
        },
        env!("CARGO_PKG_VERSION"),
    );

    h.push_str("<h2>Input</h2>\n");
    h.push_str(&metrics_table(before));
    h.push_str("<div class=\"plots\">\n");
    h.push_str(&plot(None, PlotKind::Comb, "Input: curvature comb".into())?);
    h.push_str(&plot(
        None,
        PlotKind::Curvature,
        "Input: curvature κ(s)".into(),
    )?);
    h.push_str("</div>\n");

    h.push_str("<h2>Comparison</h2>\n");
    h.push_str(&table_html(table));

    for (row, f) in rows.iter().zip(&faired) {
        let _ = writeln!(h, "<h2>{}</h2>", esc(row.method));
        match f {
            Ok(f) => {
                h.push_str(
                    "<p>The faired curve (red) over the input (blue); every comb on this page \
                     has the same scale.</p>\n<div class=\"plots\">\n",
                );
                h.push_str(&plot(
                    Some(f),
                    PlotKind::Comb,
                    format!("{}: curvature comb", row.method),
                )?);
                h.push_str(&plot(
                    Some(f),
                    PlotKind::Curvature,
                    format!("{}: curvature κ(s)", row.method),
                )?);
                h.push_str("</div>\n");
            }
            Err(why) => {
                let _ = writeln!(h, "<p class=\"note\">{}</p>", esc(why));
            }
        }
    }
    h.push_str("</body>\n</html>\n");
    Ok(h)
}

fn render_failure_named(name: &str, e: batten::Error) -> Failure {
    render_failure(std::path::Path::new(name), e)
}

/// The input's metrics as a two-column table.
fn metrics_table(m: &FairnessMetrics) -> String {
    let rows: [(&str, String); 11] = [
        ("points", m.points.to_string()),
        ("closed", if m.closed { "yes" } else { "no" }.to_string()),
        ("length", sig(m.length, DIGITS)),
        ("inflections", m.inflections.to_string()),
        ("curvature vibrations", m.vibrations.to_string()),
        ("curvature extrema", m.curvature_extrema.to_string()),
        ("max |κ|", sig(m.max_curvature, DIGITS)),
        ("strain energy ∫κ² ds", sig(m.strain_energy, DIGITS)),
        (
            "variation energy ∫(dκ/ds)² ds",
            sig(m.variation_energy, DIGITS),
        ),
        ("GFI (Calì)", sig(m.gfi, DIGITS)),
        ("max jump of r‴", sig(m.max_third_derivative_jump, DIGITS)),
    ];
    let mut s = String::from("<table class=\"metrics\">\n<tr><th>metric</th><th>value</th></tr>\n");
    for (k, v) in rows {
        // Writing to a String cannot fail.
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td class=\"r\">{}</td></tr>",
            esc(k),
            esc(&v)
        );
    }
    s.push_str("</table>\n");
    s
}

/// The comparison table as HTML: the caption as a paragraph, the cells (escaped) in a
/// `<table>` with the numbers aligned right, the notes as a numbered list.
fn table_html(table: &Table) -> String {
    let cell = |tag: &str, number: bool, text: &str| {
        if number {
            format!("<{tag} class=\"r\">{}</{tag}>", esc(text))
        } else {
            format!("<{tag}>{}</{tag}>", esc(text))
        }
    };
    let mut out = format!(
        "<p>{}</p>\n<table class=\"compare\">\n<tr>",
        esc(&table.caption)
    );
    for (title, number) in COLUMNS {
        out.push_str(&cell("th", number, title));
    }
    out.push_str("</tr>\n");
    for row in &table.rows {
        out.push_str("<tr>");
        for (text, (_, number)) in row.iter().zip(COLUMNS) {
            out.push_str(&cell("td", number, text));
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</table>\n");
    if !table.notes.is_empty() {
        out.push_str("<ol class=\"notes\">\n");
        for note in &table.notes {
            // Writing to a String cannot fail.
            let _ = writeln!(out, "<li>{}</li>", esc(note));
        }
        out.push_str("</ol>\n");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_becomes_html_cell_by_cell() {
        let html = table_html(&compare::example_table());
        assert!(html.starts_with(
            "<p>a&lt;b&gt;.csv: 4 points, open; tolerance none</p>\n<table class=\"compare\">\n\
             <tr><th>Method</th><th class=\"r\">Infl</th><th class=\"r\">Vib</th>"
        ));
        assert!(
            html.contains("<tr><td>mst [1]</td><td class=\"r\">failed</td><td class=\"r\"></td>")
        );
        assert!(html.contains("<li>mst: failed: p &lt; 0 &amp; &quot;q&quot;</li>"));
        assert_eq!(html.matches("<tr>").count(), 3);
        assert_eq!(html.matches("<td").count(), 14);
    }

    #[test]
    fn escaping() {
        assert_eq!(esc("a<b>&\"c\""), "a&lt;b&gt;&amp;&quot;c&quot;");
    }

    #[test]
    fn drawing_errors_are_one_line_naming_the_input() {
        let f = render_failure_named("x.csv", batten::Error::Degenerate("d".into()));
        assert_eq!(
            f.error.to_string(),
            "x.csv: cannot plot: degenerate geometry: d"
        );
    }
}
