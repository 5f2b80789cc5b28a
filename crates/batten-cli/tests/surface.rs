//! End-to-end tests of `batten analyze-surface` and `batten fair-surface`: the JSON they
//! print and write, the exit codes, and bad input refused with exit 2, one line on stderr and
//! nothing written.

#![allow(clippy::unwrap_used)]

mod common;

use std::fs;
use std::path::Path;

use common::{assert_usage_error, batten, example, s, stderr};
use serde_json::Value;

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

/// Decode a PNG: `(width, height, rgba)`.
fn read_png(path: &Path) -> (u32, u32, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgba);
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

/// The distinct colours inside a rectangle of an RGBA image `width` wide.
fn colours(rgba: &[u8], width: u32, x: std::ops::Range<u32>, y: std::ops::Range<u32>) -> usize {
    let mut seen = std::collections::HashSet::new();
    for j in y {
        for i in x.clone() {
            let k = 4 * (j * width + i) as usize;
            seen.insert([rgba[k], rgba[k + 1], rgba[k + 2]]);
        }
    }
    seen.len()
}

#[test]
fn plot_surface_draws_before_and_after_as_png_and_svg() {
    let dir = tempfile::tempdir().unwrap();
    let (faired, png_out, svg_out) = (
        dir.path().join("f.json"),
        dir.path().join("p.png"),
        dir.path().join("p.svg"),
    );
    let dented = example("hood-dented.json");
    let o = batten(&[
        "fair-surface",
        s(&dented),
        "-o",
        s(&faired),
        "--method",
        "eck-hadenfeld",
        "--fix-boundary",
        "--max-iterations",
        "60",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // One row, two panels of 200 x 150 and a colour bar: the page size of the layout
    // (8-pixel gaps, a 24-pixel title strip, 110 pixels for the bar).
    let o = batten(&[
        "plot-surface",
        s(&dented),
        "--faired",
        s(&faired),
        "--kind",
        "mean",
        "--width",
        "200",
        "--height",
        "150",
        "-o",
        s(&png_out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (w, h, rgba) = read_png(&png_out);
    assert_eq!((w, h), (8 + 2 * 208 + 110, 8 + 24 + 150 + 8));
    // Both panels hold a coloured surface (many colours), not a blank.
    let y = 32..182;
    assert!(colours(&rgba, w, 8..208, y.clone()) > 50);
    assert!(colours(&rgba, w, 216..416, y) > 50);
    // `all` with --faired: seven rows (K, H, kappa1, kappa2, isophotes, zebra, deviation).
    let o = batten(&[
        "plot-surface",
        s(&dented),
        "--faired",
        s(&faired),
        "--width",
        "100",
        "--height",
        "80",
        "-o",
        s(&png_out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(read_png(&png_out).1, 8 + 7 * (24 + 80 + 8));
    // Without --faired: six rows of one panel.
    let o = batten(&[
        "plot-surface",
        s(&dented),
        "--width",
        "100",
        "--height",
        "80",
        "-o",
        s(&png_out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (w, h, _) = read_png(&png_out);
    assert_eq!((w, h), (8 + 108 + 110, 8 + 6 * (24 + 80 + 8)));
    // SVG: the panels embedded as PNG, the title and the bar's numbers as text.
    let o = batten(&[
        "plot-surface",
        s(&dented),
        "--faired",
        s(&faired),
        "--kind",
        "zebra",
        "-o",
        s(&svg_out),
        "--view",
        "0,-1,2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let svg = fs::read_to_string(&svg_out).unwrap();
    assert!(svg.starts_with("<svg"), "{svg:.80}");
    assert_eq!(svg.matches("data:image/png;base64,").count(), 2);
    assert!(svg.contains("zebra - before (left), after (right)"));
    // No colour bar, so no room kept for one: two 480-pixel panels and the gaps.
    assert!(svg.contains("width=\"984\""), "{svg:.200}");
    // Deviation: one panel, a bar from 0 to the largest distance.
    let o = batten(&[
        "plot-surface",
        s(&dented),
        "--faired",
        s(&faired),
        "--kind",
        "deviation",
        "-o",
        s(&svg_out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let svg = fs::read_to_string(&svg_out).unwrap();
    assert_eq!(svg.matches("data:image/png;base64,").count(), 2);
    assert!(svg.contains(">0</text>"), "{svg}");
}

#[test]
fn plot_surface_refuses_bad_requests_without_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("p.png");
    let hood = example("hood.json");
    let bad = dir.path().join("bad.json");
    fs::write(&bad, "{\"degree_u\": 3}").unwrap();
    let other = dir.path().join("other.json");
    fs::write(
        &other,
        "{\"degree_u\": 1, \"degree_v\": 1, \"knots_u\": [0, 0, 2, 2], \"knots_v\": [0, 0, 1, 1], \
         \"control_points\": [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0]]]}",
    )
    .unwrap();
    let gif = dir.path().join("p.gif");
    let missing = dir.path().join("missing").join("p.png");
    let cases: [(Vec<&str>, &[&str]); 6] = [
        (
            vec!["--kind", "deviation"],
            &["--kind deviation needs --faired"],
        ),
        (vec!["--width", "10"], &["--width 10", "64 to 2048"]),
        (vec!["--faired", s(&bad)], &["bad.json", "degree_v"]),
        (vec!["--faired", s(&other)], &["other.json", "domain"]),
        (vec!["-o", s(&missing)], &["missing", "does not exist"]),
        (vec!["-o", s(&gif)], &["p.gif", ".png or .svg"]),
    ];
    for (extra, needles) in cases {
        let mut args = vec!["plot-surface", s(&hood)];
        if !extra.contains(&"-o") {
            args.extend(["-o", s(&out)]);
        }
        args.extend(extra);
        assert_usage_error(&batten(&args), needles);
        assert!(!out.exists());
    }
    // Parse errors come from clap: exit 2, nothing written.
    let o = batten(&["plot-surface", s(&hood), "-o", s(&out), "--view", "0,0,0"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("zero vector"));
    assert!(!out.exists());
}

/// A 7 x 7 grid of a gentle bowl with one raised point: a small surface with a defect.
fn bumpy_grid(path: &Path) {
    let rows: Vec<String> = (0..7)
        .map(|i| {
            let pts: Vec<String> = (0..7)
                .map(|j| {
                    let (x, y) = (f64::from(i), f64::from(j));
                    let bump = if (i, j) == (3, 2) { 0.15 } else { 0.0 };
                    format!(
                        "[{x}, {y}, {}]",
                        0.02 * ((x - 3.0).powi(2) + (y - 3.0).powi(2)) + bump
                    )
                })
                .collect();
            format!("[{}]", pts.join(", "))
        })
        .collect();
    fs::write(path, format!("{{\"grid\": [{}]}}", rows.join(", "))).unwrap();
}

#[test]
fn report_on_a_surface_shows_every_method_before_and_after() {
    let dir = tempfile::tempdir().unwrap();
    let (input, page) = (dir.path().join("bumpy.json"), dir.path().join("r.html"));
    bumpy_grid(&input);
    let o = batten(&["report", s(&input), "-o", s(&page), "--tolerance", "0.2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let html = fs::read_to_string(&page).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>"));
    for needle in [
        "<table class=\"metrics\">",
        "<table class=\"compare\">",
        "<h2>salvi</h2>",
        "<h2>eck-hadenfeld</h2>",
        "7×7 control points",
    ] {
        assert!(html.contains(needle), "{needle} not in the page");
    }
    // One picture of the input and one per method, each a PNG that decodes.
    let prefix = "src=\"data:image/png;base64,";
    let images: Vec<&str> = html
        .split(prefix)
        .skip(1)
        .map(|rest| &rest[..rest.find('"').unwrap()])
        .collect();
    assert_eq!(images.len(), 3);
    for b64 in images {
        // The PNG signature, base64-encoded.
        assert!(b64.starts_with("iVBORw0KGgo"), "{:.20}", b64);
    }
    // Both methods met the tolerance: "(met)" twice in the table.
    assert_eq!(html.matches("(met)").count(), 2, "{html:.3000}");
}

#[test]
fn report_on_a_surface_refuses_curve_options_without_output() {
    let dir = tempfile::tempdir().unwrap();
    let (input, page) = (dir.path().join("bumpy.json"), dir.path().join("r.html"));
    bumpy_grid(&input);
    let cases: [(&[&str], &[&str]); 4] = [
        (
            &["--fix-ends"],
            &["bumpy.json", "--fix-ends and --closed are for curves"],
        ),
        (&["--closed"], &["--fix-ends and --closed are for curves"]),
        (
            &["--tolerance", "auto"],
            &["--tolerance auto is for curves"],
        ),
        (&["--methods", "han"], &["unknown method 'han'"]),
    ];
    for (extra, needles) in cases {
        let mut args = vec!["report", s(&input), "-o", s(&page)];
        args.extend_from_slice(extra);
        assert_usage_error(&batten(&args), needles);
        assert!(!page.exists());
    }
}
