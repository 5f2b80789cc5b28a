//! `batten compare`: several methods on one input, tabulated like Table 1 of Han et al.
//! (`Infl_num`, `Vib_num`, `S_d/M_d`, `E_s`), with Calì's GFI and the run time added.
//!
//! The runs are the library's comparison protocol ([`fair::compare`]: as in the paper, the
//! smoothing spline `mst` at the same largest displacement as the first method listed); this
//! module resolves `--methods` and formats the rows.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::process::ExitCode;

use anyhow::anyhow;
use batten::fair::{self, Comparison, ComparisonOutcome, ComparisonRow, EndFix, FairMethod};
use batten::io::format_f64;
use batten::{FairOptions, FairReport, FairnessMetrics, PointSeq};
use serde::Serialize;

use crate::failure::{EXIT_FAILED, Failure};
use crate::input;
use crate::output::{self, seconds, sig};
use crate::{CompareArgs, TableFormat};

/// Significant digits of real numbers in the Markdown table.
const DIGITS: usize = 4;

/// Run `batten compare`.
///
/// # Errors
/// Usage errors (exit 2); analysing the input failed (exit 1). Methods that fail are rows
/// of the table, and make the exit code 1 after it is printed.
pub fn run(args: &CompareArgs) -> Result<ExitCode, Failure> {
    let methods = resolve(&args.methods)?;
    let base = input::options(
        args.bounds.tolerance,
        args.bounds.fix_ends.unwrap_or_default(),
        None,
        BTreeMap::new(),
    );
    base.validate().map_err(|e| Failure::from_batten("", e))?;
    let data = input::read(&args.input, args.closed)?;
    let name = crate::formats::display_name(&args.input)
        .display()
        .to_string();
    let before = FairnessMetrics::of_seq(&data.seq)
        .map_err(|e| Failure::from_batten(&format!("{name}: cannot analyse"), e))?;

    let comparison = fair::compare(&methods, &data.seq, &base);
    let rows = &comparison.rows;
    let text = match args.format {
        TableFormat::Md => markdown(&table(&name, &data.seq, &base, &before, rows)),
        TableFormat::Csv => csv(&before, rows),
        TableFormat::Json => {
            let mut s = crate::json::pretty(&to_json(&name, &base, &before, rows))
                .map_err(|e| Failure::failed(anyhow!("cannot encode the table: {e}")))?;
            s.push('\n');
            s
        }
    };
    output::stdout(&text)?;
    Ok(exit_code(&name, &comparison))
}

/// One error line per method that failed; exit code 1 if one did, else 0.
pub(crate) fn exit_code(name: &str, comparison: &Comparison) -> ExitCode {
    let mut failed = false;
    for (method, e) in comparison.failures() {
        output::error_line(&format!("{name}: method {method} failed: {e}"));
        failed = true;
    }
    if failed {
        ExitCode::from(EXIT_FAILED)
    } else {
        ExitCode::SUCCESS
    }
}

/// The methods named (all registered when none), each once.
pub(crate) fn resolve(names: &[String]) -> Result<Vec<&'static dyn FairMethod>, Failure> {
    if names.is_empty() {
        return Ok(fair::methods().to_vec());
    }
    let mut out: Vec<&'static dyn FairMethod> = Vec::with_capacity(names.len());
    for n in names {
        let m = input::method(n.trim())?;
        if out.iter().any(|o| o.name() == m.name()) {
            return Err(Failure::usage(anyhow!(
                "--methods lists {} more than once",
                m.name()
            )));
        }
        out.push(m);
    }
    Ok(out)
}

/// Remarks under the table: why options differ, failures, missed tolerances.
fn remarks(row: &ComparisonRow) -> Vec<String> {
    let mut v: Vec<String> = row.note.iter().cloned().collect();
    match &row.outcome {
        ComparisonOutcome::Ran(f) if !f.report.tolerance_met => v.push(format!(
            "tolerance {} not met",
            f.report.tolerance.map_or_else(String::new, format_f64)
        )),
        ComparisonOutcome::Ran(_) => {}
        ComparisonOutcome::Failed(e) => v.push(format!("failed: {e}")),
        ComparisonOutcome::Skipped(why) => v.push(format!("skipped: {why}")),
    }
    v
}

/// The table's columns: title, and whether its cells are numbers (aligned right).
pub(crate) const COLUMNS: [(&str, bool); 7] = [
    ("Method", false),
    ("Infl", true),
    ("Vib", true),
    ("S_d/M_d", true),
    ("E_s", true),
    ("GFI", true),
    ("time", true),
];

/// The comparison table as text cells: what the Markdown of `batten compare` and the HTML of
/// `batten report` both show.
pub(crate) struct Table {
    /// The line above the table: the input, its size, the tolerance, the ends held.
    pub(crate) caption: String,
    /// The input's row, then one per method: a cell per column of [`COLUMNS`] (empty when a
    /// method did not run). A method with remarks has their number after its name (`mst [1]`).
    pub(crate) rows: Vec<[String; COLUMNS.len()]>,
    /// The remarks, numbered from 1 in order: `method: remark; remark`.
    pub(crate) notes: Vec<String>,
}

/// The table of `rows`, after a row of the input's metrics `before`.
pub(crate) fn table(
    name: &str,
    seq: &PointSeq,
    base: &FairOptions,
    before: &FairnessMetrics,
    rows: &[ComparisonRow],
) -> Table {
    let caption = format!(
        "{name}: {} points, {}; tolerance {}{}",
        seq.len(),
        if seq.is_closed() { "closed" } else { "open" },
        base.tolerance
            .map_or_else(|| "none".to_string(), format_f64),
        if base.fix_ends.is_fixed() {
            format!(", ends fixed ({})", base.fix_ends)
        } else {
            String::new()
        },
    );
    let mut cells = vec![[
        "input".to_string(),
        before.inflections.to_string(),
        before.vibrations.to_string(),
        "–".to_string(),
        sig(before.strain_energy, DIGITS),
        sig(before.gfi, DIGITS),
        "–".to_string(),
    ]];
    let mut notes = Vec::new();
    for row in rows {
        let r = remarks(row);
        let method = if r.is_empty() {
            row.method.to_string()
        } else {
            notes.push(format!("{}: {}", row.method, r.join("; ")));
            format!("{} [{}]", row.method, notes.len())
        };
        let not_run = |status: &str| {
            let mut c: [String; COLUMNS.len()] = Default::default();
            c[0] = method.clone();
            c[1] = status.to_string();
            c
        };
        cells.push(match &row.outcome {
            ComparisonOutcome::Ran(f) => {
                let rep = &f.report;
                [
                    method.clone(),
                    rep.after.inflections.to_string(),
                    rep.after.vibrations.to_string(),
                    format!(
                        "{}/{}",
                        sig(rep.sum_displacement, DIGITS),
                        sig(rep.max_displacement, DIGITS)
                    ),
                    sig(rep.after.strain_energy, DIGITS),
                    sig(rep.after.gfi, DIGITS),
                    seconds(rep.elapsed_seconds),
                ]
            }
            ComparisonOutcome::Failed(_) => not_run("failed"),
            ComparisonOutcome::Skipped(_) => not_run("skipped"),
        });
    }
    Table {
        caption,
        rows: cells,
        notes,
    }
}

/// The table as Markdown: the caption, a pipe table, the numbered notes.
pub(crate) fn markdown(table: &Table) -> String {
    let mut s = format!("{}\n\n", table.caption);
    s.push_str(&pipe_row(COLUMNS.iter().map(|c| c.0)));
    s.push_str(&pipe_row(
        COLUMNS.iter().map(|c| if c.1 { "--:" } else { ":--" }),
    ));
    for row in &table.rows {
        s.push_str(&pipe_row(row.iter().map(String::as_str)));
    }
    if !table.notes.is_empty() {
        s.push('\n');
        for (i, note) in table.notes.iter().enumerate() {
            // Writing to a String cannot fail.
            let _ = writeln!(s, "[{}] {note}", i + 1);
        }
    }
    s
}

/// One line of a Markdown pipe table: `| a | b |`, an empty cell as `| |`.
fn pipe_row<'a>(cells: impl Iterator<Item = &'a str>) -> String {
    let mut s = String::from("|");
    for c in cells {
        s.push(' ');
        if !c.is_empty() {
            s.push_str(c);
            s.push(' ');
        }
        s.push('|');
    }
    s.push('\n');
    s
}

/// A CSV field, quoted when it must be.
pub fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// A number for CSV: exact, or empty when not finite.
pub fn csv_num(x: f64) -> String {
    if x.is_finite() {
        format_f64(x)
    } else {
        String::new()
    }
}

fn csv(before: &FairnessMetrics, rows: &[ComparisonRow]) -> String {
    let mut s = String::from(
        "method,inflections,vibrations,sum_displacement,max_displacement,strain_energy,gfi,\
         seconds,tolerance,tolerance_met,status,note\n",
    );
    // Writing to a String cannot fail.
    let _ = writeln!(
        s,
        "input,{},{},,,{},{},,,,,",
        before.inflections,
        before.vibrations,
        csv_num(before.strain_energy),
        csv_num(before.gfi)
    );
    for row in rows {
        let tol = row.tolerance.map(csv_num).unwrap_or_default();
        let note = csv_field(&row.note.clone().unwrap_or_default());
        let _ = match &row.outcome {
            ComparisonOutcome::Ran(f) => {
                let r = &f.report;
                writeln!(
                    s,
                    "{},{},{},{},{},{},{},{},{tol},{},{},{note}",
                    row.method,
                    r.after.inflections,
                    r.after.vibrations,
                    csv_num(r.sum_displacement),
                    csv_num(r.max_displacement),
                    csv_num(r.after.strain_energy),
                    csv_num(r.after.gfi),
                    csv_num(r.elapsed_seconds),
                    r.tolerance_met,
                    status_name(r),
                )
            }
            ComparisonOutcome::Failed(e) => writeln!(
                s,
                "{},,,,,,,,{tol},,failed,{}",
                row.method,
                csv_field(&join_note(row.note.as_deref(), &e.to_string()))
            ),
            ComparisonOutcome::Skipped(why) => writeln!(
                s,
                "{},,,,,,,,{tol},,skipped,{}",
                row.method,
                csv_field(&join_note(row.note.as_deref(), why))
            ),
        };
    }
    s
}

fn join_note(note: Option<&str>, extra: &str) -> String {
    match note {
        Some(n) => format!("{n}; {extra}"),
        None => extra.to_string(),
    }
}

/// The report's status as serialised (`converged`, `tolerance_exceeded`, ...).
fn status_name(r: &FairReport) -> String {
    r.status.to_string()
}

/// The `--format json` document. Structs rather than `json!` so that keys keep this order.
#[derive(Serialize)]
struct CompareJson<'a> {
    input: &'a str,
    tolerance: Option<f64>,
    fix_ends: bool,
    fixed_ends: EndFix,
    before: &'a FairnessMetrics,
    rows: Vec<RowJson<'a>>,
}

/// One row: what was asked, how it ended, and for a run the table's numbers, the parameters
/// used and the full metrics after fairing.
#[derive(Serialize)]
struct RowJson<'a> {
    method: &'a str,
    tolerance: Option<f64>,
    note: Option<&'a str>,
    status: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    error: Option<String>,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    result: Option<RunJson<'a>>,
}

#[derive(Serialize)]
struct RunJson<'a> {
    inflections: usize,
    vibrations: usize,
    sum_displacement: f64,
    max_displacement: f64,
    strain_energy: f64,
    gfi: f64,
    seconds: f64,
    tolerance_met: bool,
    iterations: usize,
    parameters: &'a serde_json::Map<String, serde_json::Value>,
    after: &'a FairnessMetrics,
}

fn to_json<'a>(
    name: &'a str,
    base: &FairOptions,
    before: &'a FairnessMetrics,
    rows: &'a [ComparisonRow],
) -> CompareJson<'a> {
    let rows = rows
        .iter()
        .map(|row| {
            let (status, error, result) = match &row.outcome {
                ComparisonOutcome::Ran(f) => {
                    let r = &f.report;
                    (
                        status_name(r),
                        None,
                        Some(RunJson {
                            inflections: r.after.inflections,
                            vibrations: r.after.vibrations,
                            sum_displacement: r.sum_displacement,
                            max_displacement: r.max_displacement,
                            strain_energy: r.after.strain_energy,
                            gfi: r.after.gfi,
                            seconds: r.elapsed_seconds,
                            tolerance_met: r.tolerance_met,
                            iterations: r.iterations,
                            parameters: &r.parameters,
                            after: &r.after,
                        }),
                    )
                }
                ComparisonOutcome::Failed(e) => ("failed".to_string(), Some(e.to_string()), None),
                ComparisonOutcome::Skipped(why) => ("skipped".to_string(), Some(why.clone()), None),
            };
            RowJson {
                method: row.method,
                tolerance: row.tolerance,
                note: row.note.as_deref(),
                status,
                error,
                result,
            }
        })
        .collect();
    CompareJson {
        input: name,
        tolerance: base.tolerance,
        fix_ends: base.fix_ends.is_fixed(),
        fixed_ends: base.fix_ends,
        before,
        rows,
    }
}

/// A small table for the tests of its Markdown here and its HTML in `report`: an input row,
/// a failed method, and text that HTML must escape.
#[cfg(test)]
pub(crate) fn example_table() -> Table {
    Table {
        caption: "a<b>.csv: 4 points, open; tolerance none".to_string(),
        rows: vec![
            ["input", "3", "1", "–", "2.000", "5.000", "–"].map(String::from),
            ["mst [1]", "failed", "", "", "", "", ""].map(String::from),
        ],
        notes: vec!["mst: failed: p < 0 & \"q\"".to_string()],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markdown_of_a_table() {
        assert_eq!(
            markdown(&example_table()),
            "a<b>.csv: 4 points, open; tolerance none\n\n\
             | Method | Infl | Vib | S_d/M_d | E_s | GFI | time |\n\
             | :-- | --: | --: | --: | --: | --: | --: |\n\
             | input | 3 | 1 | – | 2.000 | 5.000 | – |\n\
             | mst [1] | failed | | | | | |\n\
             \n\
             [1] mst: failed: p < 0 & \"q\"\n"
        );
    }
}
