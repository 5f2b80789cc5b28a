//! End-to-end tests of the `batten` binary: exit codes, one-line error messages that name the
//! file and line, outputs that are (or are not) written, and the shape of every output.

#![allow(clippy::unwrap_used)]

mod common;

use std::fs;
use std::path::Path;

use common::{assert_usage_error, batten, code, file, s, stderr, stdout};
use serde_json::Value;

/// A noisy sine, `n` points, as CSV text with a header. The "noise" is a fixed pattern.
fn noisy_sine(n: usize) -> String {
    let mut t = String::from("x,y\n");
    for i in 0..n {
        let x = i as f64 * 4.0 * std::f64::consts::PI / (n - 1) as f64;
        let noise = 0.03 * (((i * 7919) % 13) as f64 / 6.0 - 1.0);
        t.push_str(&format!("{x},{}\n", (x / 2.0).sin() + noise));
    }
    t
}

/// Bad input files: each must fail with exit 2 and one line naming the file and the line,
/// in every subcommand that reads input, and write nothing.
#[test]
fn bad_inputs_exit_2_with_one_line_naming_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cases: &[(&str, &str, &str)] = &[
        ("empty.csv", "", "empty.csv: no points"),
        (
            "comments-only.csv",
            "# nothing here\nx,y\n\n",
            "comments-only.csv: no points",
        ),
        (
            "three.csv",
            "x,y\n0,0\n1,1\n2,0\n",
            "three.csv: 3 points, at least 4 needed",
        ),
        (
            "nan.csv",
            "0,0\n1,1\n2,0\n3,1\nNaN,0\n5,1\n",
            "nan.csv:5: NaN or infinite value",
        ),
        (
            "inf.csv",
            "0,0\n1,1\n2,inf\n3,1\n4,0\n",
            "inf.csv:3: NaN or infinite value",
        ),
        (
            "huge.csv",
            "0,0\n1,1\n2,1e999\n3,1\n4,0\n",
            "huge.csv:3: NaN or infinite value",
        ),
        (
            "dup.csv",
            "x,y\n0,0\n1,1\n2,0\n3,1\n4,0\n5,1\n6,0\n6,0\n7,1\n",
            "dup.csv:9: point duplicates the previous one (line 8)",
        ),
        (
            "text.csv",
            "0,0\n1,1\n2,0\n3,1\n4,0\n5,1\n6,abc\n",
            "text.csv:7: field 2 'abc' is not a number",
        ),
        (
            "fields.csv",
            "0,0\n1,1\n2,0\n3,1,4\n4,0\n",
            "fields.csv:4: expected 2 fields (x, y), found 3",
        ),
        (
            "one-field.txt",
            "0 0\n1 1\n2\n3 1\n",
            "one-field.txt:3: expected 2 fields (x, y), found 1",
        ),
        (
            "bad.json",
            "{\"points\": [\n  [0, 0],\n  [1, 1]\n  [2, 0]\n]}\n",
            "bad.json:4:3: malformed JSON",
        ),
        (
            "nan.json",
            "{\"points\": [[0, 0], [1, NaN], [2, 0], [3, 1]]}",
            "nan.json:1:",
        ),
        (
            "dup.json",
            "{\"points\": [\n[0, 0],\n[1, 1],\n[1, 1],\n[2, 0]\n]}",
            "dup.json:4: point duplicates the previous one (line 3)",
        ),
        (
            "ring.json",
            "{\"points\": [\n[0, 0],\n[1, 0],\n[1, 1],\n[0, 1],\n[0, 0]\n], \"closed\": true}",
            "ring.json:6: closed curve repeats its first point (line 2)",
        ),
        (
            "typo.json",
            "{\"points\": [[0, 0], [1, 0], [1, 1], [0, 1]], \"close\": true}",
            "typo.json:1:",
        ),
        (
            "curve.json",
            r#"{"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0], [1, 1]]}"#,
            "curve.json: the file holds a B-spline curve",
        ),
        (
            "points.dat",
            "0 0\n1 1\n2 0\n3 1\n",
            "points.dat: unknown file format",
        ),
    ];
    for (name, contents, want) in cases {
        let input = file(d, name, contents);
        let out = d.join(format!("out-{name}.csv"));
        let report = d.join(format!("report-{name}.json"));
        let o = batten(&["fair", s(&input), "-o", s(&out), "--report", s(&report)]);
        assert_usage_error(&o, &[want]);
        assert!(!out.exists(), "{name}: output written");
        assert!(!report.exists(), "{name}: report written");
        assert_usage_error(&batten(&["analyze", s(&input)]), &[want]);
        assert_usage_error(&batten(&["analyze", "--json", s(&input)]), &[want]);
        assert_usage_error(&batten(&["compare", s(&input)]), &[want]);
    }
    // Nothing but the inputs is left in the directory.
    assert_eq!(fs::read_dir(d).unwrap().count(), cases.len());
}

#[test]
fn missing_input_file_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.csv");
    let out = dir.path().join("out.csv");
    let o = batten(&["fair", s(&missing), "-o", s(&out)]);
    assert_usage_error(&o, &["missing.csv: cannot read: "]);
    assert!(!out.exists());
}

#[test]
fn bad_options_exit_2_before_anything_runs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let input = file(d, "in.csv", &noisy_sine(30));
    let out = d.join("out.csv");
    let report = d.join("r.json");
    let fair = |extra: &[&str]| {
        let mut args = vec!["fair", s(&input), "-o", s(&out), "--report", s(&report)];
        args.extend_from_slice(extra);
        batten(&args)
    };
    let cases: &[(&[&str], &[&str])] = &[
        (&["--method", "nope"], &["unknown method 'nope'", "mst"]),
        // The default method, band.
        (
            &["--set", "bogus=1"],
            &["unknown option 'bogus' for method band", "known: k, energy"],
        ),
        (
            &["--set", "lambda_fine"],
            &["malformed --set 'lambda_fine': expected KEY=VALUE"],
        ),
        (&["--set", "=1"], &["malformed --set '=1'"]),
        (
            &["--set", "lambda_fine=0.5", "--set", "lambda_fine=0.6"],
            &["--set lambda_fine is given more than once"],
        ),
        (&["--tolerance=-1"], &["tolerance", "positive"]),
        (&["--tolerance", "nan"], &["tolerance", "positive"]),
        (&["--set", "eps=abc"], &["'abc' is not a finite number"]),
        (&["--set", "eps=20"], &["20 is outside [0, 10]"]),
        // Another method's parameters.
        (
            &["--method", "mst", "--set", "bogus=1"],
            &["unknown option 'bogus' for method mst", "known: p"],
        ),
        (
            &["--method", "mst", "--set", "p=2"],
            &["2 is outside [0, 1]"],
        ),
    ];
    for (extra, want) in cases {
        let o = fair(extra);
        assert_usage_error(&o, want);
        assert!(!out.exists(), "{extra:?}: output written");
        assert!(!report.exists(), "{extra:?}: report written");
    }
    // An output name with no known extension is refused before fairing.
    let o = batten(&["fair", s(&input), "-o", s(&d.join("out.xyz"))]);
    assert_usage_error(&o, &["out.xyz: unknown file format"]);
    assert!(!d.join("out.xyz").exists());
    // An output or report in a directory that does not exist is refused before fairing.
    let nowhere = d.join("no/such/dir/out.csv");
    let o = batten(&["fair", s(&input), "-o", s(&nowhere)]);
    assert_usage_error(&o, &["out.csv: cannot write: directory", "does not exist"]);
    let o = batten(&["fair", s(&input), "-o", s(&out), "--report", s(&nowhere)]);
    assert_usage_error(&o, &["does not exist"]);
    assert!(!out.exists());
    // compare: unknown or repeated methods.
    assert_usage_error(
        &batten(&["compare", s(&input), "--methods", "mst,nope"]),
        &["unknown method 'nope'"],
    );
    assert_usage_error(
        &batten(&["compare", s(&input), "--methods", "mst,mst"]),
        &["--methods lists mst more than once"],
    );
    assert_usage_error(
        &batten(&["compare", s(&input), "--tolerance=0"]),
        &["tolerance"],
    );
}

#[test]
fn clap_usage_errors_exit_2() {
    for args in [
        &["fair", "in.csv"][..],
        &["frobnicate"],
        &["fair", "in.csv", "-o", "o.csv", "--tolerance", "abc"],
        &["compare", "in.csv", "--format", "xml"],
        &["analyze", "in.csv", "--bogus"],
    ] {
        let o = batten(args);
        assert_eq!(code(&o), 2, "{args:?}: {}", stderr(&o));
    }
    let o = batten(&["--help"]);
    assert_eq!(code(&o), 0);
    for cmd in ["analyze", "fair", "methods", "compare"] {
        assert!(stdout(&o).contains(cmd), "{cmd} not in --help");
    }
}

#[test]
fn refuses_to_overwrite_the_input() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::create_dir(d.join("sub")).unwrap();
    let text = noisy_sine(30);
    let input = file(d, "in.csv", &text);
    let same = [input.clone(), d.join("sub/../in.csv"), d.join("./in.csv")];
    for out in &same {
        let o = batten(&["fair", s(&input), "-o", s(out)]);
        assert_usage_error(&o, &["refusing to write", "in.csv", "it is the input file"]);
        assert_eq!(fs::read_to_string(&input).unwrap(), text);
    }
    // The report may not overwrite it either.
    let out = d.join("out.csv");
    let o = batten(&["fair", s(&input), "-o", s(&out), "--report", s(&input)]);
    assert_usage_error(&o, &["refusing to write"]);
    assert!(!out.exists());
    assert_eq!(fs::read_to_string(&input).unwrap(), text);
    #[cfg(unix)]
    {
        let link = d.join("link.csv");
        std::os::unix::fs::symlink(&input, &link).unwrap();
        let o = batten(&["fair", s(&input), "-o", s(&link)]);
        assert_usage_error(&o, &["refusing to write"]);
        assert_eq!(fs::read_to_string(&input).unwrap(), text);
    }
}

fn read_csv_points(path: &Path) -> Vec<(f64, f64)> {
    let text = fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("x,y"), "header");
    lines
        .map(|l| {
            let (x, y) = l.split_once(',').unwrap();
            (x.parse().unwrap(), y.parse().unwrap())
        })
        .collect()
}

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&fs::read_to_string(path).unwrap()).unwrap()
}

fn json_points(v: &Value) -> Vec<(f64, f64)> {
    v["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
        .collect()
}

#[test]
fn fair_round_trip_writes_points_and_report() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let input = file(d, "in.csv", &noisy_sine(30));
    let out = d.join("out.csv");
    let report = d.join("report.json");
    let o = batten(&["fair", s(&input), "-o", s(&out), "--report", s(&report)]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let err = stderr(&o);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.starts_with("band: "), "{err}");
    assert!(err.contains("max displacement"), "{err}");
    assert!(o.stdout.is_empty());
    assert_eq!(read_csv_points(&out).len(), 30);
    let r = read_json(&report);
    for key in [
        "method",
        "iterations",
        "max_displacement",
        "sum_displacement",
        "tolerance_met",
        "before",
        "after",
        "status",
        "moved_points",
    ] {
        assert!(r.get(key).is_some(), "report lacks {key}: {r}");
    }
    assert_eq!(r["method"], "band");
    assert_eq!(r["tolerance_met"], true);
    assert_eq!(r["before"]["points"], 30);
    assert_eq!(r["after"]["points"], 30);
    // The output reads back as input for another run.
    let o = batten(&["analyze", s(&out)]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    // No temporary files are left behind.
    let mut names: Vec<String> = fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(names, ["in.csv", "out.csv", "report.json"]);
}

#[test]
fn tolerance_is_respected_and_reported() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let input = file(d, "in.csv", &noisy_sine(40));
    for tol in ["0.05", "0.01"] {
        let out = d.join(format!("out-{tol}.json"));
        let report = d.join(format!("r-{tol}.json"));
        let o = batten(&[
            "fair",
            s(&input),
            "-o",
            s(&out),
            "--tolerance",
            tol,
            "--report",
            s(&report),
        ]);
        assert_eq!(code(&o), 0, "{}", stderr(&o));
        assert!(
            stderr(&o).contains(&format!("tolerance {tol} met")),
            "{}",
            stderr(&o)
        );
        let r = read_json(&report);
        let t: f64 = tol.parse().unwrap();
        assert_eq!(r["tolerance"].as_f64(), Some(t));
        assert_eq!(r["tolerance_met"], true);
        assert!(r["max_displacement"].as_f64().unwrap() <= t);
        // Every point is within the tolerance of its input position.
        let before: Vec<(f64, f64)> = fs::read_to_string(&input)
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| {
                let (x, y) = l.split_once(',').unwrap();
                (x.parse().unwrap(), y.parse().unwrap())
            })
            .collect();
        let after = json_points(&read_json(&out));
        assert_eq!(after.len(), before.len());
        for (a, b) in before.iter().zip(&after) {
            assert!((a.0 - b.0).hypot(a.1 - b.1) <= t);
        }
    }
}

#[test]
fn tolerance_not_met_exits_1_but_writes_output() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let input = file(d, "in.csv", &noisy_sine(30));
    let out = d.join("out.csv");
    let report = d.join("r.json");
    // A fixed p does not look at the tolerance, so a tiny one is missed.
    let o = batten(&[
        "fair",
        s(&input),
        "-o",
        s(&out),
        "--method",
        "mst",
        "--set",
        "p=0.5",
        "--tolerance",
        "1e-9",
        "--report",
        s(&report),
    ]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("NOT met"), "{err}");
    assert!(err.contains("error: tolerance 1e-9 not met"), "{err}");
    assert_eq!(read_csv_points(&out).len(), 30);
    assert_eq!(read_json(&report)["tolerance_met"], false);
}

#[test]
fn method_failure_exits_1_without_output() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Back and forth along a line: Calì's curvature at the cusps is not finite.
    let input = file(d, "zigzag.csv", "0,0\n1,0\n0,0\n1,0\n0,0\n");
    let out = d.join("out.csv");
    let o = batten(&["fair", s(&input), "-o", s(&out), "--method", "cali"]);
    let err = stderr(&o);
    assert_eq!(code(&o), 1, "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("zigzag.csv: method cali failed: "), "{err}");
    assert!(!out.exists());
}

#[test]
fn csv_output_reads_back_bit_exact() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let input = file(d, "in.csv", &noisy_sine(50));
    let csv = d.join("out.csv");
    let json = d.join("out.json");
    for out in [&csv, &json] {
        let o = batten(&["fair", s(&input), "-o", s(out), "--tolerance", "0.02"]);
        assert_eq!(code(&o), 0, "{}", stderr(&o));
    }
    // Both outputs of the same (deterministic) run carry the same doubles, bit for bit.
    let a = read_csv_points(&csv);
    let b = json_points(&read_json(&json));
    assert_eq!(a.len(), 50);
    for (p, q) in a.iter().zip(&b) {
        assert_eq!(p.0.to_bits(), q.0.to_bits());
        assert_eq!(p.1.to_bits(), q.1.to_bits());
    }
    // Faring the output again from CSV and from JSON gives identical metrics.
    let m1 = stdout(&batten(&["analyze", "--json", s(&csv)]));
    let m2 = stdout(&batten(&["analyze", "--json", s(&json)]));
    assert_eq!(m1, m2);
}

#[test]
fn analyze_json_has_every_key() {
    let dir = tempfile::tempdir().unwrap();
    let input = file(dir.path(), "in.csv", &noisy_sine(30));
    let o = batten(&["analyze", s(&input), "--json"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(o.stderr.is_empty());
    let v: Value = serde_json::from_str(&stdout(&o)).unwrap();
    for key in [
        "points",
        "closed",
        "inflections",
        "vibrations",
        "curvature_extrema",
        "strain_energy",
        "variation_energy",
        "max_curvature",
        "gfi",
    ] {
        assert!(v.get(key).is_some(), "{key} missing: {v}");
    }
    assert_eq!(v["points"], 30);
    assert_eq!(v["closed"], false);
    // The table names the same things.
    let t = stdout(&batten(&["analyze", s(&input)]));
    assert!(
        t.starts_with(&format!("{}: 30 points, open curve", s(&input))),
        "{t}"
    );
    for label in ["inflections", "vibrations", "strain energy", "GFI"] {
        assert!(t.contains(label), "{label} missing: {t}");
    }
}

#[test]
fn input_styles_are_equivalent() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let pts: Vec<(f64, f64)> = (0..12)
        .map(|i| {
            let x = f64::from(i) * 0.5;
            (x, (x * 0.8).sin() + if i % 3 == 0 { 0.01 } else { 0.0 })
        })
        .collect();
    let rows = |sep: &str| -> String {
        pts.iter()
            .map(|(x, y)| format!("{x}{sep}{y}\n"))
            .collect::<String>()
    };
    let plain = file(d, "plain.csv", &rows(","));
    let styled = [
        file(d, "header.csv", &format!("x,y\n{}", rows(","))),
        file(
            d,
            "comments.csv",
            &format!("# a comment\n\nX , Y # header\n{}# end\n", rows(", ")),
        ),
        file(d, "semicolon.csv", &format!("x;y\n{}", rows(";"))),
        file(d, "spaces.txt", &rows("   ")),
        file(d, "tabs.txt", &format!("x\ty\n{}", rows("\t"))),
        file(d, "crlf.csv", &rows(",").replace('\n', "\r\n")),
        file(
            d,
            "points.json",
            &format!(
                "{{\"points\": [{}]}}",
                pts.iter()
                    .map(|(x, y)| format!("[{x}, {y}]"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ),
    ];
    let want = stdout(&batten(&["analyze", "--json", s(&plain)]));
    assert!(want.contains("\"points\": 12"), "{want}");
    for f in &styled {
        let o = batten(&["analyze", "--json", s(f)]);
        assert_eq!(code(&o), 0, "{}: {}", s(f), stderr(&o));
        assert_eq!(stdout(&o), want, "{}", s(f));
    }
}

fn ellipse_json(closed: bool) -> String {
    let pts: Vec<String> = (0..24)
        .map(|k| {
            let t = f64::from(k) * std::f64::consts::TAU / 24.0;
            let wobble = if k % 2 == 0 { 0.01 } else { -0.01 };
            format!("[{}, {}]", 3.0 * t.cos() + wobble, 2.0 * t.sin())
        })
        .collect();
    format!(
        "{{\"points\": [\n{}\n], \"closed\": {closed}}}\n",
        pts.join(",\n")
    )
}

#[test]
fn closed_curves_from_json_or_flag() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let closed = file(d, "ellipse.json", &ellipse_json(true));
    let v: Value =
        serde_json::from_str(&stdout(&batten(&["analyze", "--json", s(&closed)]))).unwrap();
    assert_eq!(v["closed"], true);
    assert_eq!(v["points"], 24);
    // The same points marked closed by the flag.
    let open = file(d, "open.json", &ellipse_json(false));
    let v2: Value = serde_json::from_str(&stdout(&batten(&[
        "analyze",
        "--json",
        "--closed",
        s(&open),
    ])))
    .unwrap();
    assert_eq!(v, v2);
    let v3: Value =
        serde_json::from_str(&stdout(&batten(&["analyze", "--json", s(&open)]))).unwrap();
    assert_eq!(v3["closed"], false);
    // Fairing a closed curve writes a closed curve.
    let out = d.join("out.json");
    let o = batten(&["fair", s(&closed), "-o", s(&out), "--tolerance", "0.02"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let r = read_json(&out);
    assert_eq!(r["closed"], true);
    assert_eq!(json_points(&r).len(), 24);
}

#[test]
fn tangents_are_carried_through() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let n = 12;
    let pts: Vec<String> = (0..n)
        .map(|i| format!("[{}, {}]", i, if i % 2 == 0 { 0.01 } else { 0.0 }))
        .collect();
    let tans = vec!["[1, 0]"; n].join(", ");
    let input = file(
        d,
        "hermite.json",
        &format!(
            "{{\"points\": [{}], \"tangents\": [{tans}]}}",
            pts.join(", ")
        ),
    );
    let out = d.join("out.json");
    let o = batten(&["fair", s(&input), "-o", s(&out), "--tolerance", "0.01"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let r = read_json(&out);
    assert_eq!(r["tangents"].as_array().map(Vec::len), Some(n));
    // A tangent count that does not match is an input error.
    let bad = file(
        d,
        "bad-tangents.json",
        &format!(
            "{{\"points\": [{}], \"tangents\": [[1, 0]]}}",
            pts.join(", ")
        ),
    );
    assert_usage_error(
        &batten(&["analyze", s(&bad)]),
        &["bad-tangents.json: 1 tangent for 12 points"],
    );
}

#[test]
fn methods_lists_mst_with_parameters() {
    let o = batten(&["methods"]);
    assert_eq!(code(&o), 0);
    let t = stdout(&o);
    assert!(
        t.starts_with("mst (default)\n") || t.contains("\nmst"),
        "{t}"
    );
    assert!(t.contains("p=auto"), "{t}");
    assert!(t.contains("closed curves: "), "{t}");
}

#[test]
fn compare_in_three_formats() {
    let dir = tempfile::tempdir().unwrap();
    let input = file(dir.path(), "in.csv", &noisy_sine(30));
    let base = ["compare", s(&input), "--tolerance", "0.05"];

    let o = batten(&base);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let md = stdout(&o);
    assert!(
        md.contains("| Method | Infl | Vib | S_d/M_d | E_s | GFI | time |"),
        "{md}"
    );
    assert!(md.contains("\n| input | "), "{md}");
    assert!(md.contains("\n| mst"), "{md}");

    let mut args = base.to_vec();
    args.extend(["--format", "json"]);
    let o = batten(&args);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let v: Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["before"]["points"], 30);
    let rows = v["rows"].as_array().unwrap();
    let names: Vec<&str> = rows.iter().map(|r| r["method"].as_str().unwrap()).collect();
    assert!(names.contains(&"mst"), "{names:?}");
    for r in rows
        .iter()
        .filter(|r| r["status"] != "failed" && r["status"] != "skipped")
    {
        for key in [
            "inflections",
            "vibrations",
            "sum_displacement",
            "max_displacement",
            "strain_energy",
            "gfi",
            "seconds",
        ] {
            assert!(r.get(key).is_some(), "{key} missing in {r}");
        }
        assert!(r["max_displacement"].as_f64().unwrap() <= 0.05, "{r}");
    }

    let mut args = base.to_vec();
    args.extend(["--format", "csv"]);
    let o = batten(&args);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let csv = stdout(&o);
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some(
            "method,inflections,vibrations,sum_displacement,max_displacement,strain_energy,gfi,\
             seconds,tolerance,tolerance_met,status,note"
        )
    );
    assert!(lines.next().unwrap().starts_with("input,"));
    assert_eq!(lines.count(), rows.len());
}

#[test]
fn compare_runs_mst_at_the_first_methods_displacement() {
    let dir = tempfile::tempdir().unwrap();
    let input = file(dir.path(), "in.csv", &noisy_sine(30));
    let o = batten(&[
        "compare",
        s(&input),
        "--methods",
        "han,mst",
        "--format",
        "json",
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let v: Value = serde_json::from_str(&stdout(&o)).unwrap();
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows[0]["method"], "han");
    assert_eq!(rows[1]["method"], "mst");
    let md = rows[0]["max_displacement"].as_f64().unwrap();
    assert!(md > 0.0);
    assert_eq!(rows[1]["tolerance"].as_f64(), Some(md));
    assert!(rows[1]["max_displacement"].as_f64().unwrap() <= md);
    assert!(rows[1]["note"].as_str().unwrap().contains("han"));
    // mst first: it runs with the options given (no tolerance here).
    let o = batten(&[
        "compare",
        s(&input),
        "--methods",
        "mst,han",
        "--format",
        "json",
    ]);
    let v: Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["rows"][0]["tolerance"], Value::Null);
    assert_eq!(v["rows"][0]["note"], Value::Null);
}

#[test]
fn bundled_examples_are_valid_inputs() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/data");
    let (mut n, mut surfaces) = (0, 0);
    for entry in fs::read_dir(&data).unwrap() {
        let p = entry.unwrap().path();
        let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
        if !matches!(ext, "csv" | "json") {
            continue;
        }
        let name = p.file_name().unwrap().to_str().unwrap();
        if name.starts_with("hood") {
            // The B-spline surfaces (examples/data/README.md).
            let o = batten(&["analyze-surface", "--json", s(&p)]);
            assert_eq!(code(&o), 0, "{}: {}", s(&p), stderr(&o));
            surfaces += 1;
            continue;
        }
        let o = batten(&["analyze", "--json", s(&p)]);
        assert_eq!(code(&o), 0, "{}: {}", s(&p), stderr(&o));
        let v: Value = serde_json::from_str(&stdout(&o)).unwrap();
        assert_eq!(v["closed"], name.starts_with("ellipse"), "{name}");
        // The helix is the space curve.
        assert_eq!(v["dimension"] == 3, name.starts_with("helix"), "{name}");
        n += 1;
    }
    assert_eq!(n, 14, "seven curves, noisy and truth");
    assert_eq!(surfaces, 2, "the hood and the dented hood");
}

/// `--fix-ends` alone is the position; `--fix-ends=tangent|curvature` holds more, and the
/// report says what was held and what the ends did.
#[test]
fn fix_ends_levels() {
    let dir = tempfile::tempdir().unwrap();
    let input = file(dir.path(), "in.csv", &noisy_sine(30));
    let before = read_csv_points(&input);
    for (flag, held, name) in [
        ("--fix-ends", 1, "position"),
        ("--fix-ends=position", 1, "position"),
        ("--fix-ends=tangent", 2, "tangent"),
        ("--fix-ends=curvature", 3, "curvature"),
    ] {
        for method in ["han", "mst", "kjellander"] {
            let out = dir.path().join("out.csv");
            let rep = dir.path().join("r.json");
            // The bare flag must not take the input file as its value.
            let o = batten(&[
                "fair",
                flag,
                s(&input),
                "-o",
                s(&out),
                "--method",
                method,
                "--report",
                s(&rep),
            ]);
            assert_eq!(code(&o), 0, "{flag} {method}: {}", stderr(&o));
            let after = read_csv_points(&out);
            let n = before.len();
            for i in (0..held).chain(n - held..n) {
                assert_eq!(after[i], before[i], "{flag} {method}: point {i}");
            }
            let r = read_json(&rep);
            assert_eq!(r["fixed_ends"], name);
            assert_eq!(r["fix_ends"], true);
            let angles = r["end_changes"]["tangent_angle"].as_array().unwrap();
            assert_eq!(angles.len(), 2);
            if held >= 2 {
                assert!(
                    angles.iter().all(|a| a.as_f64() == Some(0.0)),
                    "{flag} {method}"
                );
            }
        }
    }
    let out = dir.path().join("never.csv");
    let o = batten(&["fair", s(&input), "-o", s(&out), "--fix-ends=sideways"]);
    assert_eq!(code(&o), 2);
    assert!(
        stderr(&o).contains("position, tangent, curvature"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
}

/// The faired points are written into their temporary file while the result is measured;
/// when the clean-curve guard then returns the input instead, that file is dropped: the
/// output holds the input's points, and no temporary file is left beside it.
#[test]
fn points_written_ahead_are_dropped_when_the_guard_returns_the_input() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let input = common::example("arc-truth.csv");
    let (out, rep) = (d.join("out.csv"), d.join("r.json"));
    let o = batten(&[
        "fair",
        s(&input),
        "--method",
        "band",
        "--tolerance",
        "0.01",
        "-o",
        s(&out),
        "--report",
        s(&rep),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let report: Value = serde_json::from_str(&fs::read_to_string(&rep).unwrap()).unwrap();
    assert_eq!(report["status"], "no_change", "{report}");
    let numbers = |path: &Path| -> Vec<f64> {
        fs::read_to_string(path)
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with('x') && !l.trim().is_empty())
            .flat_map(|l| {
                l.split(',')
                    .map(|v| v.trim().parse::<f64>().unwrap())
                    .collect::<Vec<_>>()
            })
            .collect()
    };
    assert_eq!(numbers(&out), numbers(&input));
    assert_eq!(common::names(d), vec!["out.csv", "r.json"]);
}
