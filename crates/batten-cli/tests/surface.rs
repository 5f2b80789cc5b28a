//! End-to-end tests of `batten analyze-surface` and `batten fair-surface`: the JSON they
//! print and write, the exit codes, and bad input refused with exit 2, one line on stderr and
//! nothing written.

#![allow(clippy::unwrap_used)]

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

fn batten(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_batten"))
        .args(args)
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/data")
        .join(name)
}

fn assert_usage_error(o: &Output, needles: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "stderr: {err}");
    assert_eq!(err.lines().count(), 1, "not one line: {err:?}");
    assert!(err.starts_with("error: "), "{err}");
    for n in needles {
        assert!(err.contains(n), "{n:?} not in {err:?}");
    }
}

#[test]
fn analyze_surface_prints_the_documented_keys() {
    let o = batten(&["analyze-surface", s(&example("hood.json")), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["degree_u"], 3);
    assert_eq!(v["control_points"], serde_json::json!([12, 12]));
    for k in ["kappa1", "kappa2", "gaussian", "mean"] {
        let (lo, hi) = (v[k]["min"].as_f64().unwrap(), v[k]["max"].as_f64().unwrap());
        assert!(lo <= hi, "{k}");
    }
    assert!(v["umbilic_fraction"].as_f64().unwrap() >= 0.0);
    assert!(v["fairness_measure"].as_f64().unwrap() >= 0.0);
    let o = batten(&["analyze-surface", s(&example("hood-dented.json"))]);
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(text.contains("fairness measure"), "{text}");
}

#[test]
fn fair_surface_writes_a_surface_and_a_report() {
    let dir = tempfile::tempdir().unwrap();
    let (out, rep) = (dir.path().join("f.json"), dir.path().join("r.json"));
    let o = batten(&[
        "fair-surface",
        s(&example("hood-dented.json")),
        "-o",
        s(&out),
        "--tolerance",
        "0.05",
        "--fix-boundary=tangent",
        "--max-iterations",
        "40",
        "--report",
        s(&rep),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let r: Value = serde_json::from_str(&fs::read_to_string(&rep).unwrap()).unwrap();
    assert_eq!(r["method"], "salvi");
    assert_eq!(r["tolerance_met"], true);
    assert_eq!(r["fix_boundary"], "tangent");
    assert!(r["max_displacement"].as_f64().unwrap() <= 0.05);
    let (b, a) = (
        r["before"]["pi_hat"].as_f64().unwrap(),
        r["after"]["pi_hat"].as_f64().unwrap(),
    );
    assert!(a < b, "{b} -> {a}");
    assert!(r["moves"].as_u64().unwrap() > 0);
    assert!(r["time_s"].as_f64().unwrap() >= 0.0);
    // The output is a surface batten reads back, with the same net size.
    let o = batten(&["analyze-surface", s(&out), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["control_points"], serde_json::json!([12, 12]));
    // eck-hadenfeld too.
    let o = batten(&[
        "fair-surface",
        s(&example("hood-dented.json")),
        "-o",
        s(&out),
        "--method",
        "eck-hadenfeld",
        "--fix-boundary",
        "--max-iterations",
        "50",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn bad_surface_input_is_refused_without_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("f.json");
    let bad = dir.path().join("bad.json");
    let cases: [(&str, &[&str]); 4] = [
        (
            "{\"degree_u\": 3}",
            &["bad.json", "missing key \"degree_v\""],
        ),
        (
            "{\"grid\": [[[0,0,0],[1,0,0]],[[0,1,0]]]}",
            &["bad.json", "grid row 1 has 1 points"],
        ),
        (
            "{\"grid\": [[[0,0,0],[1,0,0]],[[0,1,0],[1,1,1]]], \"colour\": 1}",
            &["unknown field `colour`"],
        ),
        ("{\"degree_u\": 3,", &["malformed JSON"]),
    ];
    for (text, needles) in cases {
        fs::write(&bad, text).unwrap();
        assert_usage_error(&batten(&["analyze-surface", s(&bad)]), needles);
        assert_usage_error(&batten(&["fair-surface", s(&bad), "-o", s(&out)]), needles);
        assert!(!out.exists());
    }
    let hood = example("hood.json");
    assert_usage_error(
        &batten(&["fair-surface", s(&hood), "-o", s(&out), "--method", "han"]),
        &["unknown method 'han'"],
    );
    assert_usage_error(
        &batten(&["fair-surface", s(&hood), "-o", s(&out), "--set", "tabu=x"]),
        &["tabu"],
    );
    assert_usage_error(
        &batten(&["fair-surface", s(&hood), "-o", s(&out), "--tolerance=-1"]),
        &["tolerance"],
    );
    assert_usage_error(
        &batten(&["fair-surface", s(&hood), "-o", s(&hood)]),
        &["refusing to write"],
    );
    assert!(!out.exists());
}

#[test]
fn a_plane_comes_back_unchanged_with_exit_0() {
    // A plane is already fair (every curvature 0, Π̂ = 0): both methods leave it alone.
    let dir = tempfile::tempdir().unwrap();
    let (plane, out, rep) = (
        dir.path().join("plane.json"),
        dir.path().join("f.json"),
        dir.path().join("r.json"),
    );
    let rows: Vec<String> = (0..5)
        .map(|i| {
            let pts: Vec<String> = (0..4)
                .map(|j| format!("[{i}, {j}, {}]", 0.5 * f64::from(i) - 0.25 * f64::from(j)))
                .collect();
            format!("[{}]", pts.join(", "))
        })
        .collect();
    fs::write(&plane, format!("{{\"grid\": [{}]}}", rows.join(", "))).unwrap();
    for method in ["salvi", "eck-hadenfeld"] {
        let o = batten(&[
            "fair-surface",
            s(&plane),
            "-o",
            s(&out),
            "--method",
            method,
            "--report",
            s(&rep),
        ]);
        assert_eq!(o.status.code(), Some(0), "{method}: {}", stderr(&o));
        let r: Value = serde_json::from_str(&fs::read_to_string(&rep).unwrap()).unwrap();
        assert_eq!(r["tolerance_met"], true, "{method}");
        assert!(
            r["max_displacement"].as_f64().unwrap() < 1e-9,
            "{method}: {r}"
        );
        let a: Value =
            serde_json::from_slice(&batten(&["analyze-surface", s(&out), "--json"]).stdout)
                .unwrap();
        for k in ["kappa1", "kappa2", "gaussian", "mean"] {
            for e in ["min", "max"] {
                assert!(a[k][e].as_f64().unwrap().abs() < 1e-9, "{method} {k}: {a}");
            }
        }
    }
}
