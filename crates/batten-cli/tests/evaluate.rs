//! `batten evaluate`: Kuragano & Yamaguchi's fairness evaluation through the CLI.

#![allow(clippy::unwrap_used)]

use std::fs;
use std::process::Command;

fn spiral_csv() -> String {
    // A logarithmic spiral r = e^{0.15 t}: its radius of curvature is linear in arc length.
    let mut s = String::from("x,y\n");
    for i in 0..40 {
        let t = 3.0 * i as f64 / 39.0;
        let r = (0.15 * t).exp();
        s.push_str(&format!("{},{}\n", r * t.cos(), r * t.sin()));
    }
    s
}

#[test]
fn evaluate_json_has_the_documented_shape() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("spiral.csv");
    fs::write(&input, spiral_csv()).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_batten"))
        .args(["evaluate", input.to_str().unwrap(), "--json"])
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let degrees = v["degrees"].as_array().unwrap();
    assert_eq!(degrees.len(), 6);
    for (k, d) in degrees.iter().enumerate() {
        assert_eq!(d["degree"], k + 1);
        assert_eq!(d["applicable"], true, "a spiral has positive ρ everywhere");
        let c = d["correlation"].as_f64().unwrap();
        let a = d["angle_deg"].as_f64().unwrap();
        assert!((c.acos().to_degrees() - a).abs() < 1e-9);
    }
    let best = v["best_degree"].as_u64().unwrap() as usize;
    let fairness = v["fairness"].as_f64().unwrap();
    assert_eq!(fairness, degrees[best - 1]["correlation"].as_f64().unwrap());
    assert!(fairness > 0.999, "{fairness}");
    // The best degree is the lowest within ROC_TIE_TOLERANCE of the largest correlation.
    let max = degrees
        .iter()
        .map(|d| d["correlation"].as_f64().unwrap())
        .fold(0.0, f64::max);
    let lowest = degrees
        .iter()
        .position(|d| {
            d["correlation"].as_f64().unwrap() >= max - batten::analysis::ROC_TIE_TOLERANCE
        })
        .unwrap();
    assert_eq!(best, lowest + 1);
}

#[test]
fn evaluate_bad_input_is_one_line_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("bad.csv");
    fs::write(&input, "x,y\n0,0\n1,abc\n2,1\n3,0\n").unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_batten"))
        .args(["evaluate", input.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("bad.csv:3"), "{err}");
    assert!(o.stdout.is_empty());
}
