//! End-to-end tests of `batten batch`: outputs and reports per file, summary rows in input
//! order whatever the completion order, exit codes 0/1/2, and usage errors that write nothing.

#![allow(clippy::unwrap_used)]

mod common;

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;

use common::{assert_usage_error, batten, code, file, names, s, stderr};
use serde_json::Value;

/// A noisy sine of `n` points as CSV with a header; `phase` makes the curves differ. The
/// "noise" is a fixed pattern.
fn noisy_sine(n: usize, phase: f64) -> String {
    let mut t = String::from("x,y\n");
    for i in 0..n {
        let x = i as f64 * 4.0 * std::f64::consts::PI / (n - 1) as f64;
        let noise = 0.03 * (((i * 7919) % 13) as f64 / 6.0 - 1.0);
        t.push_str(&format!("{x},{}\n", (x / 2.0 + phase).sin() + noise));
    }
    t
}

/// The same curve as a JSON point list.
fn noisy_sine_json(n: usize, phase: f64) -> String {
    let rows: Vec<String> = noisy_sine(n, phase)
        .lines()
        .skip(1)
        .map(|l| format!("[{l}]"))
        .collect();
    format!("{{\"points\": [{}]}}\n", rows.join(", "))
}

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&fs::read_to_string(path).unwrap()).unwrap()
}

/// The last line of stderr: the counts.
fn last_line(o: &Output) -> String {
    stderr(o).lines().last().unwrap_or_default().to_string()
}

/// Split one CSV line into fields (RFC 4180 quoting, no embedded newlines).
fn csv_fields(line: &str) -> Vec<String> {
    let mut fields = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                chars.next();
                fields.last_mut().unwrap().push('"');
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(String::new()),
            _ => fields.last_mut().unwrap().push(c),
        }
    }
    fields
}

/// Five good curves (one of them JSON) and one with a NaN, plus files batch must skip.
fn mixed_dir(d: &Path) -> PathBuf {
    let inp = d.join("in");
    fs::create_dir(&inp).unwrap();
    file(&inp, "a.csv", &noisy_sine(30, 0.0));
    file(&inp, "b.csv", &noisy_sine(31, 0.1));
    // Line 5 (the header is line 1) holds a NaN.
    let mut bad: Vec<String> = noisy_sine(30, 0.2).lines().map(String::from).collect();
    bad[4] = "0.5,NaN".to_string();
    file(&inp, "c-bad.csv", &(bad.join("\n") + "\n"));
    file(&inp, "d.json", &noisy_sine_json(32, 0.3));
    file(&inp, "e.txt", &noisy_sine(33, 0.4));
    file(&inp, "f.csv", &noisy_sine(34, 0.5));
    // Not inputs: another extension, a hidden file, a subdirectory.
    file(&inp, "README.md", "not a curve\n");
    file(&inp, ".hidden.csv", "garbage\n");
    fs::create_dir(inp.join("sub.csv")).unwrap();
    inp
}

const GOOD: [&str; 5] = ["a.csv", "b.csv", "d.json", "e.txt", "f.csv"];

#[test]
fn mixed_directory_writes_good_files_and_reports_the_bad_one() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let inp = mixed_dir(d);
    let out = d.join("out");
    let summary = d.join("summary.json");
    let o = batten(&[
        "batch",
        s(&inp),
        "-o",
        s(&out),
        "--summary",
        s(&summary),
        "--jobs",
        "3",
        "--tolerance",
        "0.1",
    ]);
    let err = stderr(&o);
    assert_eq!(code(&o), 2, "{err}");
    assert!(o.stdout.is_empty());

    // 5 outputs and 5 reports, nothing for the bad file, no temporaries.
    let mut want: Vec<String> = GOOD.iter().map(|n| n.to_string()).collect();
    for n in GOOD {
        let stem = n.rsplit_once('.').unwrap().0;
        want.push(format!("{stem}.report.json"));
    }
    want.sort();
    assert_eq!(names(&out), want);
    // Each output has its input's point count and format; each report is the fair report.
    for (n, count) in [("a.csv", 30), ("b.csv", 31), ("e.txt", 33), ("f.csv", 34)] {
        let text = fs::read_to_string(out.join(n)).unwrap();
        assert!(text.starts_with("x,y\n"), "{n}");
        assert_eq!(text.lines().count(), count + 1, "{n}");
    }
    let json = read_json(&out.join("d.json"));
    assert_eq!(json["points"].as_array().unwrap().len(), 32);
    let report = read_json(&out.join("a.report.json"));
    assert_eq!(report["method"], "band");
    assert_eq!(report["tolerance_met"], true);
    assert_eq!(report["before"]["points"], 30);

    // Summary rows in input (name) order, the bad one invalid with its file:line error.
    let rows = read_json(&summary);
    let rows = rows.as_array().unwrap();
    let files: Vec<&str> = rows.iter().map(|r| r["file"].as_str().unwrap()).collect();
    let order = ["a.csv", "b.csv", "c-bad.csv", "d.json", "e.txt", "f.csv"];
    let expected: Vec<String> = order.iter().map(|n| s(&inp.join(n)).to_string()).collect();
    assert_eq!(files, expected);
    let bad = &rows[2];
    assert_eq!(bad["status"], "invalid_input");
    let msg = bad["error"].as_str().unwrap();
    assert_eq!(
        msg,
        format!("{}:5: NaN or infinite value", s(&inp.join("c-bad.csv")))
    );
    assert!(bad["points"].is_null() && bad["iterations"].is_null());
    for (row, points) in [0, 1, 3, 4, 5]
        .iter()
        .map(|&i| &rows[i])
        .zip([30, 31, 32, 33, 34])
    {
        assert_eq!(row["status"], "ok", "{row}");
        assert!(row["error"].is_null());
        assert_eq!(row["points"], points);
        assert_eq!(row["tolerance_met"], true);
        assert!(row["max_displacement"].as_f64().unwrap() <= 0.1);
        assert!(row["iterations"].as_u64().is_some());
        for key in [
            "sum_displacement",
            "strain_energy_before",
            "strain_energy_after",
        ] {
            assert!(row[key].as_f64().unwrap() > 0.0, "{key}: {row}");
        }
        for key in [
            "gfi_before",
            "gfi_after",
            "end_tangent_change",
            "end_curvature_change",
        ] {
            assert!(row[key].as_f64().is_some(), "{key}: {row}");
        }
        for key in [
            "inflections_before",
            "inflections_after",
            "vibrations_before",
            "vibrations_after",
        ] {
            assert!(row[key].as_u64().is_some(), "{key}: {row}");
        }
        // Fairing the noise away removes inflections.
        assert!(row["inflections_after"].as_u64() < row["inflections_before"].as_u64());
    }
    // The keys of every row, in this order (serde_json::Value sorts them, so read the text).
    let text = fs::read_to_string(&summary).unwrap();
    let first = &text[..text.find('}').unwrap()];
    let mut keys: Vec<(usize, &str)> = rows[0]
        .as_object()
        .unwrap()
        .keys()
        .map(|k| (first.find(&format!("\"{k}\":")).unwrap(), k.as_str()))
        .collect();
    keys.sort();
    assert_eq!(
        keys.iter().map(|k| k.1).collect::<Vec<_>>(),
        [
            "file",
            "status",
            "error",
            "points",
            "iterations",
            "max_displacement",
            "sum_displacement",
            "tolerance_met",
            "inflections_before",
            "inflections_after",
            "vibrations_before",
            "vibrations_after",
            "strain_energy_before",
            "strain_energy_after",
            "gfi_before",
            "gfi_after",
            "end_tangent_change",
            "end_curvature_change"
        ]
    );

    // stderr: the bad file's error, then the counts.
    assert_eq!(err.lines().count(), 2, "{err}");
    assert!(err.starts_with(&format!("error: {msg}\n")), "{err}");
    assert!(
        last_line(&o).contains("6 files: 5 ok, 0 tolerance exceeded, 0 failed, 1 invalid input"),
        "{err}"
    );
}

#[test]
fn all_good_exits_0_and_rerun_replaces_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let inp = d.join("in");
    fs::create_dir(&inp).unwrap();
    for (i, n) in ["x.csv", "y.csv", "z.json"].iter().enumerate() {
        let phase = i as f64 / 10.0;
        let text = if n.ends_with(".json") {
            noisy_sine_json(25, phase)
        } else {
            noisy_sine(25, phase)
        };
        file(&inp, n, &text);
    }
    let out = d.join("new/out");
    for _ in 0..2 {
        let o = batten(&["batch", s(&inp), "-o", s(&out), "--method", "mst"]);
        assert_eq!(code(&o), 0, "{}", stderr(&o));
        assert_eq!(stderr(&o).lines().count(), 1, "{}", stderr(&o));
        assert!(last_line(&o).contains("3 files: 3 ok, 0 tolerance exceeded"));
        assert_eq!(
            names(&out),
            [
                "x.csv",
                "x.report.json",
                "y.csv",
                "y.report.json",
                "z.json",
                "z.report.json"
            ]
        );
    }
}

#[test]
fn files_and_patterns_as_inputs_keep_argument_order() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = d.join("a");
    let b = d.join("b");
    fs::create_dir(&a).unwrap();
    fs::create_dir(&b).unwrap();
    file(&a, "frame-01.csv", &noisy_sine(20, 0.0));
    file(&a, "frame-02.csv", &noisy_sine(20, 0.1));
    file(&a, "frame-10.csv", &noisy_sine(20, 0.2));
    file(&a, "other.csv", &noisy_sine(20, 0.3));
    let single = file(&b, "single.csv", &noisy_sine(20, 0.4));
    let out = d.join("out");
    let summary = d.join("s.json");
    let pattern = a.join("frame-0?.csv");
    let o = batten(&[
        "batch",
        s(&single),
        s(&pattern),
        "-o",
        s(&out),
        "--summary",
        s(&summary),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let rows = read_json(&summary);
    let files: Vec<&str> = rows
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["file"].as_str().unwrap())
        .collect();
    assert_eq!(
        files,
        [
            s(&single),
            s(&a.join("frame-01.csv")),
            s(&a.join("frame-02.csv"))
        ]
    );
    // A pattern that matches nothing is a usage error; nothing is written.
    let o = batten(&["batch", s(&a.join("nope-*.csv")), "-o", s(&d.join("out2"))]);
    assert_usage_error(
        &o,
        &["nope-*.csv: matches no .csv, .txt, .json, .dxf, .igs or .svg file"],
    );
    assert!(!d.join("out2").exists());
    // A missing file given by name is a row, not the end of the batch.
    let missing = d.join("missing.csv");
    let o = batten(&[
        "batch",
        s(&missing),
        s(&single),
        "-o",
        s(&d.join("out3")),
        "--summary",
        s(&summary),
    ]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    let rows = read_json(&summary);
    assert_eq!(rows[0]["status"], "invalid_input");
    let e = rows[0]["error"].as_str().unwrap();
    assert!(
        e.starts_with(&format!("{}: cannot read: ", s(&missing))),
        "{e}"
    );
    assert_eq!(rows[1]["status"], "ok");
    assert_eq!(names(&d.join("out3")), ["single.csv", "single.report.json"]);
}

#[test]
fn failures_and_missed_tolerances_exit_1() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let inp = d.join("in");
    fs::create_dir(&inp).unwrap();
    file(&inp, "good.csv", &noisy_sine(30, 0.0));
    // Back and forth along a line: Calì's curvature at the cusps is not finite.
    file(&inp, "zigzag.csv", "0,0\n1,0\n0,0\n1,0\n0,0\n");
    let out = d.join("out");
    let summary = d.join("s.csv");
    let o = batten(&[
        "batch",
        s(&inp),
        "-o",
        s(&out),
        "--method",
        "cali",
        "--summary",
        s(&summary),
    ]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    let text = fs::read_to_string(&summary).unwrap();
    let rows: Vec<Vec<String>> = text.lines().skip(1).map(csv_fields).collect();
    assert_eq!(rows[0][1], "ok", "{text}");
    assert_eq!(rows[1][1], "failed", "{text}");
    assert!(
        rows[1][2].starts_with(&format!(
            "{}: method cali failed: ",
            s(&inp.join("zigzag.csv"))
        )),
        "{text}"
    );
    assert_eq!(rows[1][3], "5", "the points are known: {text}");
    assert_eq!(names(&out), ["good.csv", "good.report.json"]);
    assert!(last_line(&o).contains("2 files: 1 ok, 0 tolerance exceeded, 1 failed, 0 invalid"));

    // A fixed p does not look at the tolerance, so a tiny one is missed: exit 1, outputs
    // and reports written anyway.
    fs::remove_file(inp.join("zigzag.csv")).unwrap();
    let o = batten(&[
        "batch",
        s(&inp),
        "-o",
        s(&out),
        "--method",
        "mst",
        "--set",
        "p=0.5",
        "--tolerance",
        "1e-9",
        "--summary",
        s(&summary),
    ]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("good.csv: tolerance 1e-9 not met"), "{err}");
    let text = fs::read_to_string(&summary).unwrap();
    let row = csv_fields(text.lines().nth(1).unwrap());
    assert_eq!(row[1], "tolerance_exceeded", "{text}");
    assert_eq!(row[7], "false", "{text}");
    assert_eq!(
        read_json(&out.join("good.report.json"))["tolerance_met"],
        false
    );
}

#[test]
fn bad_options_exit_2_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let inp = mixed_dir(d);
    let out = d.join("out");
    let summary = d.join("summary.json");
    let cases: &[(&[&str], &[&str])] = &[
        (&["--method", "nope"], &["unknown method 'nope'", "mst"]),
        (
            &["--set", "bogus=1"],
            &["unknown option 'bogus' for method band"],
        ),
        (&["--set", "p"], &["malformed --set 'p'"]),
        (&["--tolerance=-1"], &["tolerance", "positive"]),
        (&["--tolerance", "nan"], &["tolerance", "positive"]),
        // Parameter values are checked up front too, before any file is read.
        (
            &["--method", "mst", "--set", "p=2"],
            &["invalid value for p: 2 is outside [0, 1]"],
        ),
        (
            &["--method", "han", "--set", "max_turn=7"],
            &["invalid value for max_turn"],
        ),
    ];
    for (extra, want) in cases {
        let mut args = vec!["batch", s(&inp), "-o", s(&out), "--summary", s(&summary)];
        args.extend_from_slice(extra);
        let o = batten(&args);
        assert_usage_error(&o, want);
        assert!(!out.exists(), "{extra:?}: output directory created");
        assert!(!summary.exists(), "{extra:?}: summary written");
    }
    // A summary of unknown format, or in a missing directory.
    let o = batten(&["batch", s(&inp), "-o", s(&out), "--summary", "s.xml"]);
    assert_usage_error(&o, &["s.xml: unknown summary format"]);
    let nowhere = d.join("no/such/s.json");
    let o = batten(&["batch", s(&inp), "-o", s(&out), "--summary", s(&nowhere)]);
    assert_usage_error(&o, &["does not exist"]);
    let dir_json = d.join("dir.json");
    fs::create_dir(&dir_json).unwrap();
    let o = batten(&["batch", s(&inp), "-o", s(&out), "--summary", s(&dir_json)]);
    assert_usage_error(&o, &["is a directory"]);
    // --jobs 0 is clap's usage error.
    let o = batten(&["batch", s(&inp), "-o", s(&out), "--jobs", "0"]);
    assert_eq!(code(&o), 2);
    // An output "directory" that is a file.
    let f = file(d, "plain.csv", "x\n");
    let o = batten(&["batch", s(&inp), "-o", s(&f)]);
    assert_usage_error(&o, &["not a directory"]);
    // Two inputs that would write the same file.
    let other = d.join("other");
    fs::create_dir(&other).unwrap();
    file(&other, "a.csv", &noisy_sine(20, 0.0));
    let o = batten(&["batch", s(&inp), s(&other), "-o", s(&out)]);
    assert_usage_error(&o, &["would both write", "a.csv"]);
    // A directory without point files.
    let empty = d.join("empty");
    fs::create_dir(&empty).unwrap();
    let o = batten(&["batch", s(&empty), "-o", s(&out)]);
    assert_usage_error(&o, &["no .csv, .txt, .json, .dxf, .igs or .svg files in"]);
    assert!(!out.exists());
}

#[test]
fn refuses_to_write_into_an_input_directory() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let inp = mixed_dir(d);
    let before: Vec<(String, String)> = names(&inp)
        .into_iter()
        .filter(|n| n != "sub.csv")
        .map(|n| (n.clone(), fs::read_to_string(inp.join(&n)).unwrap()))
        .collect();
    let same = [inp.clone(), inp.join("."), d.join("in/../in")];
    for out in &same {
        let o = batten(&["batch", s(&inp), "-o", s(out)]);
        assert_usage_error(
            &o,
            &["refusing to write into", "it is the directory of the input"],
        );
    }
    // A file given by name from the output directory.
    let top = file(d, "top.csv", &noisy_sine(20, 0.0));
    let o = batten(&["batch", s(&top), "-o", s(d)]);
    assert_usage_error(&o, &["refusing to write into"]);
    let o = batten(&["batch", s(&d.join("in/../top.csv")), "-o", s(d)]);
    assert_usage_error(&o, &["refusing to write into"]);
    let o = batten(&["batch", s(&inp.join("a.csv")), "-o", s(&inp)]);
    assert_usage_error(&o, &["refusing to write into"]);
    #[cfg(unix)]
    {
        // Through a link to the input directory.
        let link = d.join("link");
        std::os::unix::fs::symlink(&inp, &link).unwrap();
        let o = batten(&["batch", s(&inp), "-o", s(&link)]);
        assert_usage_error(&o, &["refusing to write into"]);
    }
    // The summary may not replace an input either.
    let o = batten(&[
        "batch",
        s(&inp),
        "-o",
        s(&d.join("out")),
        "--summary",
        s(&inp.join("a.csv")),
    ]);
    assert_usage_error(&o, &["refusing to write", "it is the input file"]);
    // Nor a result of the batch.
    let o = batten(&[
        "batch",
        s(&inp),
        "-o",
        s(&d.join("out")),
        "--summary",
        s(&d.join("out/b.csv")),
    ]);
    assert_usage_error(&o, &["would replace a result of"]);
    assert!(!d.join("out").exists());
    for (n, text) in before {
        assert_eq!(
            fs::read_to_string(inp.join(&n)).unwrap(),
            text,
            "{n} changed"
        );
    }
}

#[test]
fn summary_csv_has_one_row_per_input_in_order() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let inp = mixed_dir(d);
    // A name with a comma and a quote must be quoted in CSV.
    file(&inp, "g,\"h\".csv", &noisy_sine(20, 0.6));
    let out = d.join("out");
    let summary = out.join("summary.csv");
    let o = batten(&["batch", s(&inp), "-o", s(&out), "--summary", s(&summary)]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    let text = fs::read_to_string(&summary).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some(
            "file,status,error,points,iterations,max_displacement,sum_displacement,\
             tolerance_met,inflections_before,inflections_after,vibrations_before,\
             vibrations_after,strain_energy_before,strain_energy_after,gfi_before,gfi_after,\
             end_tangent_change,end_curvature_change"
        )
    );
    let rows: Vec<Vec<String>> = lines.map(csv_fields).collect();
    assert_eq!(rows.len(), 7, "{text}");
    let order = [
        "a.csv",
        "b.csv",
        "c-bad.csv",
        "d.json",
        "e.txt",
        "f.csv",
        "g,\"h\".csv",
    ];
    for (row, n) in rows.iter().zip(order) {
        assert_eq!(row.len(), 18, "{row:?}");
        assert_eq!(row[0], s(&inp.join(n)));
    }
    let statuses: Vec<&str> = rows.iter().map(|r| r[1].as_str()).collect();
    assert_eq!(
        statuses,
        ["ok", "ok", "invalid_input", "ok", "ok", "ok", "ok"]
    );
    let bad = &rows[2];
    assert!(bad[2].ends_with(": NaN or infinite value"), "{bad:?}");
    assert!(bad[3..].iter().all(String::is_empty), "{bad:?}");
    let good = &rows[0];
    assert!(good[2].is_empty());
    assert_eq!(good[3], "30");
    assert_eq!(good[7], "true");
    for cell in &good[4..] {
        assert!(!cell.is_empty(), "{good:?}");
    }
    // Numbers are written exactly: the CSV agrees with the report.
    let report = read_json(&out.join("a.report.json"));
    assert_eq!(
        good[5].parse::<f64>().unwrap(),
        report["max_displacement"].as_f64().unwrap()
    );
    assert_eq!(
        good[14].parse::<f64>().unwrap(),
        report["before"]["gfi"].as_f64().unwrap()
    );
    // The output directory holds the 6 results, their reports and the summary.
    assert_eq!(names(&out).len(), 13, "{:?}", names(&out));
}
