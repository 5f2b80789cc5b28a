//! 3-D curves end to end: `analyze`, `fair` with band and mst, `plot`, `batch`, a DXF 3-D
//! POLYLINE, and the one-line refusals (planar methods, planar-only outputs and commands).

#![allow(clippy::unwrap_used)]

mod common;

use std::fs;

use batten::io::{Format, Pick, ReadOptions, Source};
use common::{assert_usage_error, batten, code, example, names, s, stderr, stdout};
use serde_json::Value;

fn json(text: &str) -> Value {
    serde_json::from_str(text).unwrap()
}

/// The points of a text or JSON file holding a space curve.
fn space_points(path: &std::path::Path) -> Vec<[f64; 3]> {
    let format = Format::from_path(path).unwrap();
    let input = batten::io::read_input(
        path,
        Some(format),
        &ReadOptions::default(),
        &Pick::default(),
    )
    .unwrap();
    match input.source {
        Source::Space(d) => d.seq.points().to_vec(),
        other => panic!("not a space curve: {other:?}"),
    }
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1]).hypot(a[2] - b[2])
}

#[test]
fn analyze_reports_dimension_three_and_torsion() {
    let o = batten(&["analyze", s(&example("helix-truth.csv")), "--json"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let m = json(&stdout(&o));
    assert_eq!(m["dimension"], 3);
    assert_eq!(m["points"], 80);
    // x = 2 cos t, y = 2 sin t, z = t/2: κ = 2/4.25, τ = 0.5/4.25.
    let kappa = m["max_curvature"].as_f64().unwrap();
    let tau = m["max_torsion"].as_f64().unwrap();
    assert!((kappa - 2.0 / 4.25).abs() < 0.02 * 2.0 / 4.25, "{kappa}");
    assert!((tau - 0.5 / 4.25).abs() < 0.05 * 0.5 / 4.25, "{tau}");
    assert_eq!(m["torsion_sign_changes"], 0);
    for key in [
        "curvature_extrema",
        "torsion_extrema",
        "strain_energy",
        "variation_energy",
        "torsion_energy",
        "length",
    ] {
        assert!(m.get(key).is_some(), "{key}");
    }
    assert!(m.get("inflections").is_none());
    let o = batten(&["analyze", s(&example("helix-noisy.csv"))]);
    assert_eq!(code(&o), 0);
    assert!(stdout(&o).contains("open 3-D curve"), "{}", stdout(&o));
    assert!(stdout(&o).contains("torsion changes"));
}

#[test]
fn fair_a_space_curve_with_band_and_mst() {
    let dir = tempfile::tempdir().unwrap();
    let input = example("helix-noisy.csv");
    let before = space_points(&input);
    let truth = space_points(&example("helix-truth.csv"));
    for (method, tolerance) in [("band", "0.09"), ("mst", "0.09")] {
        let out = dir.path().join(format!("{method}.csv"));
        let report = dir.path().join(format!("{method}.json"));
        let o = batten(&[
            "fair",
            s(&input),
            "-o",
            s(&out),
            "--method",
            method,
            "--tolerance",
            tolerance,
            "--report",
            s(&report),
        ]);
        assert_eq!(code(&o), 0, "{}", stderr(&o));
        assert!(
            stderr(&o).starts_with(&format!("{method}: ")),
            "{}",
            stderr(&o)
        );
        let r = json(&fs::read_to_string(&report).unwrap());
        assert_eq!(r["dimension"], 3);
        assert_eq!(r["tolerance_met"], true);
        let after = space_points(&out);
        let max = after
            .iter()
            .zip(&before)
            .map(|(a, b)| distance(*a, *b))
            .fold(0.0, f64::max);
        assert!(max <= 0.09);
        assert_eq!(r["max_displacement"].as_f64().unwrap(), max);
        // Fairer than the input, and nearer the helix it was sampled from.
        assert!(
            r["after"]["variation_energy"].as_f64().unwrap()
                < 0.01 * r["before"]["variation_energy"].as_f64().unwrap()
        );
        let rms = |p: &[[f64; 3]]| {
            (p.iter()
                .zip(&truth)
                .map(|(a, b)| distance(*a, *b).powi(2))
                .sum::<f64>()
                / p.len() as f64)
                .sqrt()
        };
        assert!(rms(&after) < rms(&before), "{method}");
    }
    // band's automatic tolerance, JSON out, closedness kept.
    let out = dir.path().join("auto.json");
    let o = batten(&["fair", s(&input), "-o", s(&out)]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let written = json(&fs::read_to_string(&out).unwrap());
    assert_eq!(written["points"][0].as_array().unwrap().len(), 3);
    assert_eq!(written["closed"], false);
}

#[test]
fn planar_methods_and_outputs_are_refused_in_one_line_nothing_written() {
    let dir = tempfile::tempdir().unwrap();
    let input = example("helix-noisy.csv");
    let out = dir.path().join("out.csv");
    let o = batten(&["fair", s(&input), "-o", s(&out), "--method", "han"]);
    assert_usage_error(&o, &["han fairs planar curves only", "band or mst"]);
    let svg = dir.path().join("out.svg");
    let o = batten(&["fair", s(&input), "-o", s(&svg)]);
    assert_usage_error(
        &o,
        &["a 3-D curve is written as .csv, .txt, .json, .dxf or .igs"],
    );
    let curve = dir.path().join("c.json");
    let o = batten(&["fair", s(&input), "-o", s(&out), "--curve-out", s(&curve)]);
    assert_usage_error(&o, &["--curve-out writes a planar B-spline"]);
    for args in [vec!["compare", s(&input)], vec!["evaluate", s(&input)]] {
        let o = batten(&args);
        assert_usage_error(&o, &["holds a 3-D curve", "3-D curves are taken by"]);
    }
    let o = batten(&["plot", s(&input), "-o", s(&svg), "--kind", "xc"]);
    assert_usage_error(&o, &["for planar curves"]);
    assert!(names(dir.path()).is_empty(), "{:?}", names(dir.path()));
    // A mixed file: the first row decides, the others must match.
    let bad = dir.path().join("bad.csv");
    fs::write(&bad, "x,y,z\n0,0,0\n1,0,1\n2,1\n3,1,1\n").unwrap();
    let o = batten(&["fair", s(&bad), "-o", s(&out)]);
    assert_usage_error(&o, &["bad.csv:4: expected 3 fields (x, y, z), found 2"]);
    assert!(!out.exists());
}

#[test]
fn plot_draws_three_views_and_the_torsion() {
    let dir = tempfile::tempdir().unwrap();
    let faired = dir.path().join("f.csv");
    let o = batten(&[
        "fair",
        s(&example("helix-noisy.csv")),
        "-o",
        s(&faired),
        "--tolerance",
        "0.09",
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let svg = dir.path().join("h.svg");
    let o = batten(&[
        "plot",
        s(&example("helix-noisy.csv")),
        "--faired",
        s(&faired),
        "-o",
        s(&svg),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let text = fs::read_to_string(&svg).unwrap();
    for title in ["Plan (x–y)", "Profile (x–z)", "Body plan (y–z)", "torsion"] {
        assert!(text.contains(title), "{title}");
    }
    // A planar faired file over a 3-D input is refused.
    let planar = dir.path().join("p.csv");
    fs::write(&planar, "x,y\n0,0\n1,1\n2,0\n3,1\n").unwrap();
    let o = batten(&[
        "plot",
        s(&example("helix-noisy.csv")),
        "--faired",
        s(&planar),
        "-o",
        s(&dir.path().join("x.svg")),
    ]);
    assert_usage_error(&o, &["a planar curve, but"]);
}

#[test]
fn batch_fairs_space_files_beside_planar_ones() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let summary = dir.path().join("summary.json");
    let o = batten(&[
        "batch",
        s(&example("helix-noisy.csv")),
        s(&example("sine-noisy.csv")),
        "-o",
        s(&out),
        "--tolerance",
        "0.1",
        "--summary",
        s(&summary),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let rows = json(&fs::read_to_string(&summary).unwrap());
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), 2);
    let helix = rows
        .iter()
        .find(|r| r["file"].as_str().unwrap().ends_with("helix-noisy.csv"))
        .unwrap();
    assert_eq!(helix["status"], "ok");
    assert_eq!(helix["points"], 80);
    assert!(helix["inflections_before"].is_null());
    assert!(helix["strain_energy_after"].as_f64().unwrap() > 0.0);
    let faired = out.join("helix-noisy.csv");
    assert_eq!(space_points(&faired).len(), 80);
    // With a planar method the space file is a row, not the end of the batch.
    let o = batten(&[
        "batch",
        s(&example("helix-noisy.csv")),
        s(&example("sine-noisy.csv")),
        "-o",
        s(&dir.path().join("out2")),
        "--method",
        "han",
        "--tolerance",
        "0.1",
    ]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    assert!(
        stderr(&o).contains("han fairs planar curves only"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn a_dxf_3d_polyline_is_faired_in_space_and_written_back() {
    let dir = tempfile::tempdir().unwrap();
    let dxf = dir.path().join("helix.dxf");
    let o = batten(&[
        "fair",
        s(&example("helix-noisy.csv")),
        "-o",
        s(&dxf),
        "--method",
        "mst",
        "--set",
        "p=1",
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let json_out = dir.path().join("faired.json");
    let o = batten(&["fair", s(&dxf), "-o", s(&json_out), "--tolerance", "0.09"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert_eq!(space_points(&json_out).len(), 80);
    // batch replaces the entity in place: one DXF back, its report a list.
    let out = dir.path().join("out");
    let o = batten(&["batch", s(&dxf), "-o", s(&out), "--tolerance", "0.09"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let back = out.join("helix.dxf");
    assert_eq!(space_points(&back).len(), 80);
    let reports = json(&fs::read_to_string(out.join("helix.report.json")).unwrap());
    assert_eq!(reports[0]["kind"], "POLYLINE");
    assert_eq!(reports[0]["report"]["dimension"], 3);
}
