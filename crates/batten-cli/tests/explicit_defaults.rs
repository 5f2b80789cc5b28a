//! Passing every parameter's default explicitly, `--set KEY=DEFAULT` with the defaults that
//! `batten methods --json` lists, gives byte for byte the output of passing none: the faired
//! points, the curve, the report (but for its clock) and what is said on stdout and stderr,
//! for every method, on an open curve, a closed one where the method fairs closed curves, a
//! B-spline where it takes one, and a space curve (refused alike by the planar methods).

#![allow(clippy::unwrap_used)]

mod common;

use std::fs;
use std::path::Path;

use common::{batten, code, example, s};
use serde_json::Value;

/// Everything a `batten fair` run gave, its report's `elapsed_seconds` blanked.
#[derive(Debug, PartialEq)]
struct Run {
    code: i32,
    stdout: Vec<u8>,
    stderr: String,
    files: Vec<(String, String)>,
}

fn fair(dir: &Path, input: &Path, method: &str, sets: &[String], curve: bool) -> Run {
    if dir.exists() {
        fs::remove_dir_all(dir).unwrap();
    }
    fs::create_dir_all(dir).unwrap();
    let ext = input.extension().unwrap().to_str().unwrap();
    let (out, report, curve_out) = (
        dir.join(format!("out.{ext}")),
        dir.join("report.json"),
        dir.join("curve.json"),
    );
    let mut args = vec![
        "fair",
        s(input),
        "--method",
        method,
        "-o",
        s(&out),
        "--report",
        s(&report),
    ];
    if curve {
        args.extend(["--curve-out", s(&curve_out)]);
    }
    for kv in sets {
        args.extend(["--set", kv.as_str()]);
    }
    let o = batten(&args);
    let mut files = Vec::new();
    for p in [&out, &report, &curve_out] {
        if let Ok(text) = fs::read_to_string(p) {
            let text: Vec<String> = text
                .lines()
                .map(|l| {
                    if l.trim_start().starts_with("\"elapsed_seconds\":") {
                        "\"elapsed_seconds\": (clock)".to_string()
                    } else {
                        l.to_string()
                    }
                })
                .collect();
            files.push((
                p.file_name().unwrap().to_string_lossy().into(),
                text.join("\n"),
            ));
        }
    }
    Run {
        code: code(&o),
        stdout: o.stdout,
        stderr: String::from_utf8_lossy(&o.stderr).into_owned(),
        files,
    }
}

#[test]
fn every_default_given_explicitly_changes_no_byte() {
    let dir = tempfile::tempdir().unwrap();
    let listed = batten(&["methods", "--json"]);
    assert_eq!(code(&listed), 0);
    let methods: Value = serde_json::from_slice(&listed.stdout).unwrap();
    let methods = methods.as_array().unwrap();
    assert_eq!(methods.len(), batten::fair::methods().len());

    // A B-spline for the methods that take one: mst's curve through a noisy sine.
    let bspline = dir.path().join("sine-curve.json");
    let o = batten(&[
        "fair",
        s(&example("sine-noisy.csv")),
        "--method",
        "mst",
        "-o",
        s(&dir.path().join("sine-mst.csv")),
        "--curve-out",
        s(&bspline),
    ]);
    assert_eq!(code(&o), 0, "{}", common::stderr(&o));

    let mut faired = 0;
    for m in methods {
        let name = m["name"].as_str().unwrap();
        let sets: Vec<String> = m["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| {
                format!(
                    "{}={}",
                    p["name"].as_str().unwrap(),
                    p["default"].as_str().unwrap()
                )
            })
            .collect();
        let mut inputs = vec![
            (example("strophoid-noisy.csv"), true),
            (example("helix-noisy.csv"), false),
        ];
        if m["closed_curves"] == true {
            inputs.push((example("ellipse-noisy.json"), true));
        }
        if m["bspline_input"] == true {
            inputs.push((bspline.clone(), true));
        }
        for (input, curve) in inputs {
            let what = format!("{name} on {}", input.display());
            // The same paths for both runs, which the output may name.
            let run = dir.path().join("run");
            let none = fair(&run, &input, name, &[], curve);
            let all = fair(&run, &input, name, &sets, curve);
            assert_eq!(none, all, "{what}: {sets:?}");
            if none.code == 0 {
                faired += 1;
                let expected = if curve { 3 } else { 2 };
                assert_eq!(none.files.len(), expected, "{what}: {:?}", none.files);
            }
        }
    }
    // Every method fairs at least the open curve; band and mst the space curve too.
    assert!(faired > methods.len(), "{faired} runs faired");
}
