//! B-spline curves through the CLI: `batten fair --curve-out`, and B-spline JSON input for the
//! methods that work on control points.

#![allow(clippy::unwrap_used)]

mod common;

use std::fs;
use std::path::{Path, PathBuf};

use batten::Curve;
use batten::io::{ReadOptions, read_curve_json, read_points};
use common::{batten, s};

fn noisy_sine(dir: &Path) -> PathBuf {
    let mut t = String::from("x,y\n");
    for i in 0..30 {
        let x = i as f64 * 4.0 * std::f64::consts::PI / 29.0;
        let noise = 0.03 * (((i * 7919) % 13) as f64 / 6.0 - 1.0);
        t.push_str(&format!("{x},{}\n", (x / 2.0).sin() + noise));
    }
    let p = dir.join("sine.csv");
    fs::write(&p, t).unwrap();
    p
}

const BUMPED: &str = r#"{"degree": 3,
 "knots": [0, 0, 0, 0, 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875, 1, 1, 1, 1],
 "control_points": [[0, 0], [1, 0.3], [2, 0.55], [3, 0.7], [4, 0.8], [5, 1.3],
                    [6, 0.8], [7, 0.7], [8, 0.55], [9, 0.3], [10, 0]]}"#;

#[test]
fn curve_out_for_a_point_method_interpolates_the_faired_points() {
    let dir = tempfile::tempdir().unwrap();
    let input = noisy_sine(dir.path());
    let (out, curve) = (dir.path().join("o.csv"), dir.path().join("c.json"));
    let o = batten(&[
        "fair",
        s(&input),
        "-o",
        s(&out),
        "--method",
        "mst",
        "--tolerance",
        "0.1",
        "--curve-out",
        s(&curve),
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let c = read_curve_json(&curve).unwrap();
    assert_eq!(c.degree(), 3);
    let pts = read_points(&out, &ReadOptions::default()).unwrap();
    // The curve passes through every faired point (it is their C² cubic).
    for p in pts.seq.points() {
        let best = (0..=3000)
            .map(|i| c.eval(c.domain().0 + (c.domain().1 - c.domain().0) * i as f64 / 3000.0))
            .map(|q| q.distance(*p))
            .fold(f64::INFINITY, f64::min);
        assert!(best < 0.01, "{best}");
    }
}

#[test]
fn bspline_input_is_faired_as_a_curve_by_control_point_methods() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("bumped.json");
    fs::write(&input, BUMPED).unwrap();
    for method in ["salvi", "eck-hadenfeld"] {
        let (out, curve, rep) = (
            dir.path().join(format!("{method}.csv")),
            dir.path().join(format!("{method}-curve.json")),
            dir.path().join(format!("{method}.report.json")),
        );
        let o = batten(&[
            "fair",
            s(&input),
            "-o",
            s(&out),
            "--method",
            method,
            "--tolerance",
            "0.3",
            "--curve-out",
            s(&curve),
            "--report",
            s(&rep),
        ]);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{method}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let original = read_curve_json(&input).unwrap();
        let faired = read_curve_json(&curve).unwrap();
        assert_eq!(faired.knots(), original.knots(), "{method}");
        assert_eq!(faired.degree(), original.degree(), "{method}");
        let pts = read_points(&out, &ReadOptions::default()).unwrap();
        assert_eq!(pts.seq.len(), original.control_points().len(), "{method}");
        let report: serde_json::Value =
            serde_json::from_str(&fs::read_to_string(&rep).unwrap()).unwrap();
        assert_eq!(report["tolerance_met"], true, "{method}");
        assert!(
            report["max_displacement"].as_f64().unwrap() <= 0.3,
            "{method}"
        );
    }
}

#[test]
fn bspline_input_with_a_point_method_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("bumped.json");
    fs::write(&input, BUMPED).unwrap();
    let out = dir.path().join("o.csv");
    let o = batten(&["fair", s(&input), "-o", s(&out), "--method", "mst"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("bumped.json") && err.contains("salvi"),
        "{err}"
    );
    assert!(!out.exists());
}

#[test]
fn curve_out_must_be_json_and_distinct() {
    let dir = tempfile::tempdir().unwrap();
    let input = noisy_sine(dir.path());
    for (out, curve, needle) in [
        ("o.csv", "c.csv", "json"),
        ("o.json", "o.json", "another output"),
    ] {
        let (out, c) = (dir.path().join(out), dir.path().join(curve));
        let o = batten(&["fair", s(&input), "-o", s(&out), "--curve-out", s(&c)]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(err.contains(needle), "{err}");
        assert!(!out.exists());
    }
}
