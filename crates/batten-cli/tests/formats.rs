//! DXF, IGES and SVG through `batten fair`, standard input and output (`-`), `--format`, and
//! the picking flags: results read back with the library, and bad files refused in one
//! line with exit code 2 and nothing written.

#![allow(clippy::unwrap_used)]

mod common;

use std::fs;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use batten::io::{self, Pick, ReadOptions, Source};
use batten::spline::BSplineCurve;
use batten::{Curve, Point};
use common::{batten, s};

/// Run with `stdin` piped in.
fn batten_stdin(args: &[&str], stdin: &[u8]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_batten"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(stdin).unwrap();
    child.wait_with_output().unwrap()
}

fn sine_csv() -> String {
    let mut t = String::from("x,y\n");
    for i in 0..30 {
        let x = i as f64 * 4.0 * std::f64::consts::PI / 29.0;
        let noise = 0.03 * (((i * 7919) % 13) as f64 / 6.0 - 1.0);
        t.push_str(&format!("{x},{}\n", (x / 2.0).sin() + noise));
    }
    t
}

fn noisy_sine(dir: &Path) -> PathBuf {
    let p = dir.join("sine.csv");
    fs::write(&p, sine_csv()).unwrap();
    p
}

fn read(path: &Path, pick: &Pick) -> io::Input {
    io::read_input(path, None, &ReadOptions::default(), pick).unwrap()
}

fn points(path: &Path) -> Vec<Point> {
    match read(path, &Pick::default()).source {
        Source::Points(d) => d.seq.points().to_vec(),
        other => panic!("{}: not points: {other:?}", path.display()),
    }
}

fn curve(path: &Path) -> BSplineCurve {
    match read(path, &Pick::default()).source {
        Source::Curve(c) => c,
        other => panic!("{}: not a curve: {other:?}", path.display()),
    }
}

fn ok(o: &Output) {
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Exit 2, one line on stderr that contains every needle.
fn refused(o: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    for n in needles {
        assert!(err.contains(n), "{n:?} not in {err}");
    }
}

/// The largest distance between two curves sampled at the same fractions of their domains
/// (a DXF file rounds the knots to 12 decimals).
fn curve_gap(a: &BSplineCurve, b: &BSplineCurve) -> f64 {
    let ((a0, a1), (b0, b1)) = (a.domain(), b.domain());
    (0..=200)
        .map(|i| {
            let f = f64::from(i) / 200.0;
            a.eval(a0 + (a1 - a0) * f)
                .distance(b.eval(b0 + (b1 - b0) * f))
        })
        .fold(0.0, f64::max)
}

/// The largest distance between a curve and its SVG form, whose Bézier segment i runs over
/// [i, i + 1] where the curve's knot span i runs over [uᵢ, uᵢ₊₁].
fn bezier_gap(curve: &BSplineCurve, svg: &BSplineCurve) -> f64 {
    let mut knots =
        curve.knots().as_slice()[curve.degree()..=curve.control_points().len()].to_vec();
    knots.dedup();
    let mut gap: f64 = 0.0;
    for (i, w) in knots.windows(2).enumerate() {
        for j in 0..=10 {
            let f = f64::from(j) / 10.0;
            let p = curve.eval(w[0] + (w[1] - w[0]) * f);
            gap = gap.max(p.distance(svg.eval(i as f64 + f)));
        }
    }
    gap
}

#[test]
fn faired_points_in_every_format_are_the_same_points() {
    let dir = tempfile::tempdir().unwrap();
    let input = noisy_sine(dir.path());
    let reference = dir.path().join("o.csv");
    let run = |out: &Path| {
        ok(&batten(&[
            "fair",
            s(&input),
            "-o",
            s(out),
            "--method",
            "mst",
            "--tolerance",
            "0.1",
        ]));
    };
    run(&reference);
    let want = points(&reference);
    for ext in ["json", "dxf", "igs"] {
        let out = dir.path().join(format!("o.{ext}"));
        run(&out);
        let got = points(&out);
        assert_eq!(got.len(), want.len(), "{ext}");
        for (a, b) in got.iter().zip(&want) {
            // DXF keeps 12 decimals; the others are bit for bit.
            assert!(a.distance(*b) <= 1e-12, "{ext}: {a:?} vs {b:?}");
        }
    }
    // SVG holds the C² cubic through the faired points: its Bézier segments start at them.
    let out = dir.path().join("o.svg");
    run(&out);
    let c = curve(&out);
    assert_eq!(c.control_points().len(), 3 * (want.len() - 1) + 1);
    for (i, p) in want.iter().enumerate() {
        assert!(c.control_points()[3 * i].distance(*p) <= 1e-12, "{i}");
    }
}

#[test]
fn curve_out_in_every_format_is_the_json_curve() {
    let dir = tempfile::tempdir().unwrap();
    let input = noisy_sine(dir.path());
    let mut curves = Vec::new();
    for ext in ["json", "dxf", "igs", "svg"] {
        let c = dir.path().join(format!("c.{ext}"));
        ok(&batten(&[
            "fair",
            s(&input),
            "-o",
            s(&dir.path().join(format!("o-{ext}.csv"))),
            "--method",
            "mst",
            "--tolerance",
            "0.1",
            "--curve-out",
            s(&c),
        ]));
        curves.push((
            ext,
            io::read_input(&c, None, &ReadOptions::default(), &Pick::default()),
        ));
    }
    let json = match &curves[0].1.as_ref().unwrap().source {
        Source::Curve(c) => c.clone(),
        other => panic!("not a curve: {other:?}"),
    };
    for (ext, got) in &curves[1..] {
        let Source::Curve(c) = &got.as_ref().unwrap().source else {
            panic!("{ext}: points")
        };
        let gap = if *ext == "svg" {
            bezier_gap(&json, c)
        } else {
            curve_gap(&json, c)
        };
        assert!(gap <= 1e-11, "{ext}: {gap}");
        if *ext == "igs" {
            assert_eq!(c, &json, "IGES is bit for bit");
        }
    }
}

#[test]
fn pipes_read_stdin_and_write_stdout() {
    let o = batten_stdin(
        &[
            "fair",
            "-",
            "-o",
            "-",
            "--method",
            "mst",
            "--tolerance",
            "0.1",
        ],
        sine_csv().as_bytes(),
    );
    ok(&o);
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(text.starts_with("x,y\n"), "{text}");
    assert_eq!(text.lines().count(), 31);
    // The summary goes to stderr, never into the piped data.
    assert!(!o.stderr.is_empty());

    // --format for both ends of the pipe: a DXF in, a DXF out.
    let dir = tempfile::tempdir().unwrap();
    let dxf_in = dir.path().join("in.dxf");
    ok(&batten(&[
        "fair",
        s(&noisy_sine(dir.path())),
        "-o",
        s(&dxf_in),
        "--method",
        "mst",
        "--tolerance",
        "0.01",
    ]));
    let o = batten_stdin(
        &[
            "fair",
            "-",
            "-o",
            "-",
            "--format",
            "dxf",
            "--method",
            "mst",
            "--tolerance",
            "0.1",
        ],
        &fs::read(&dxf_in).unwrap(),
    );
    ok(&o);
    let back = io::parse_input(
        &o.stdout,
        io::Format::Dxf,
        Path::new("out"),
        &ReadOptions::default(),
        &Pick::default(),
    )
    .unwrap();
    let Source::Points(d) = back.source else {
        panic!("curve")
    };
    assert_eq!(d.seq.len(), 30);

    // A bad pipe is named <stdin>, exit 2, nothing on stdout.
    let o = batten_stdin(
        &["fair", "-", "-o", "-", "--format", "json"],
        b"{\"points\": [[0, 0]",
    );
    refused(&o, &["<stdin>"]);
    assert!(o.stdout.is_empty());
}

#[test]
fn format_flag_names_a_file_without_a_known_extension() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("sine.dat");
    fs::write(&input, sine_csv()).unwrap();
    let out = dir.path().join("o.csv");
    let o = batten(&["fair", s(&input), "-o", s(&out)]);
    refused(&o, &["sine.dat", "unknown file format"]);
    assert!(!out.exists());
    ok(&batten(&[
        "fair",
        s(&input),
        "-o",
        s(&out),
        "--format",
        "csv",
        "--method",
        "mst",
        "--tolerance",
        "0.1",
    ]));
    assert_eq!(points(&out).len(), 30);
}

/// A hand-written minimal DXF (an ENTITIES section only, as many scripts write them) with
/// two LWPOLYLINEs: handle A1 on layer HULL at z = 2.5, handle B2 on layer DECK.
fn two_layer_dxf(dir: &Path) -> PathBuf {
    let p = dir.join("two.dxf");
    fs::write(&p, dxf_text(false)).unwrap();
    p
}

/// The entities of [`two_layer_dxf`], and with `spline` a cubic SPLINE with control points,
/// handle C3 on layer CURVES.
fn dxf_text(spline: bool) -> String {
    let mut t = String::from("  0\nSECTION\n  2\nENTITIES\n");
    if spline {
        t.push_str("  0\nSPLINE\n  5\nC3\n  8\nCURVES\n 70\n8\n 71\n3\n 72\n9\n 73\n5\n 74\n0\n");
        for k in [0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0] {
            t.push_str(&format!(" 40\n{k}\n"));
        }
        for (x, y) in [(0.0, 0.0), (1.0, 1.0), (2.0, -1.0), (3.0, 0.5), (4.0, 0.0)] {
            t.push_str(&format!(" 10\n{x}\n 20\n{y}\n 30\n0.0\n"));
        }
    }
    for (handle, layer, z, amp) in [("A1", "HULL", "2.5", 0.03), ("B2", "DECK", "0.0", 0.05)] {
        t.push_str(&format!(
            "  0\nLWPOLYLINE\n  5\n{handle}\n  8\n{layer}\n 90\n30\n 70\n0\n 38\n{z}\n"
        ));
        for i in 0..30 {
            let x = f64::from(i) * 0.4;
            let y = (x / 2.0).sin() + amp * f64::from((i * 7919) % 13 - 6) / 6.0;
            t.push_str(&format!(" 10\n{x}\n 20\n{y}\n"));
        }
    }
    t.push_str("  0\nENDSEC\n  0\nEOF\n");
    t
}

#[test]
fn batch_fairs_every_dxf_entity_into_one_dxf() {
    let dir = tempfile::tempdir().unwrap();
    let (inputs, out) = (dir.path().join("in"), dir.path().join("out"));
    fs::create_dir(&inputs).unwrap();
    let input = inputs.join("lines.dxf");
    fs::write(&input, dxf_text(true)).unwrap();
    let summary = dir.path().join("summary.json");
    let o = batten(&[
        "batch",
        s(&inputs),
        "-o",
        s(&out),
        "--method",
        "mst",
        "--tolerance",
        "0.05",
        "--summary",
        s(&summary),
    ]);
    // The SPLINE is a B-spline, which mst does not take: an invalid row, exit 2.
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains(
            "lines.dxf#C3: SPLINE with control points is a B-spline; method mst takes points"
        ),
        "{err}"
    );
    assert!(
        err.contains(
            "batch: 1 file, 3 curves: 2 ok, 0 tolerance exceeded, 0 failed, 1 invalid input"
        ),
        "{err}"
    );
    let rows: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(&summary).unwrap()).unwrap();
    let status: Vec<(&str, &str)> = rows
        .as_array()
        .unwrap()
        .iter()
        .map(|r| (r["file"].as_str().unwrap(), r["status"].as_str().unwrap()))
        .collect();
    let name = input.display().to_string();
    assert_eq!(
        status,
        [
            (format!("{name}#C3").as_str(), "invalid_input"),
            (format!("{name}#A1").as_str(), "ok"),
            (format!("{name}#B2").as_str(), "ok"),
        ]
    );
    // One DXF back: handles, layers and z kept, the polylines faired, the spline as it was.
    let written = out.join("lines.dxf");
    let before = io::DxfDrawing::read(&input)
        .unwrap()
        .curves(&ReadOptions::default());
    let after = io::DxfDrawing::read(&written)
        .unwrap()
        .curves(&ReadOptions::default());
    assert_eq!(before.len(), 3);
    for (b, a) in before.iter().zip(&after) {
        assert_eq!(a.origin, b.origin);
        assert_eq!(a.kind, b.kind);
        match (b.source.as_ref().unwrap(), a.source.as_ref().unwrap()) {
            (Source::Curve(cb), Source::Curve(ca)) => assert_eq!(ca, cb),
            (Source::Points(pb), Source::Points(pa)) => {
                assert_eq!(pa.seq.len(), pb.seq.len());
                let moved = pa
                    .seq
                    .points()
                    .iter()
                    .zip(pb.seq.points())
                    .map(|(p, q)| p.distance(*q));
                let max = moved.fold(0.0, f64::max);
                assert!(max > 0.0 && max <= 0.05 + 1e-12, "{max}");
            }
            _ => panic!("kind changed"),
        }
    }
    assert_eq!(after[1].origin.z, 2.5);
    let reports: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(out.join("lines.report.json")).unwrap()).unwrap();
    let handles: Vec<&str> = reports
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["handle"].as_str().unwrap())
        .collect();
    assert_eq!(handles, ["A1", "B2"]);
    assert_eq!(reports[0]["layer"], "HULL");
    assert_eq!(reports[0]["report"]["tolerance_met"], true);

    // salvi takes the SPLINE as a B-spline: knots and degree kept, control points moved.
    let o = batten(&[
        "batch",
        s(&inputs),
        "-o",
        s(&out),
        "--method",
        "eck-hadenfeld",
        "--tolerance",
        "0.05",
    ]);
    ok(&o);
    let after = io::DxfDrawing::read(&written)
        .unwrap()
        .curves(&ReadOptions::default());
    let (Ok(Source::Curve(cb)), Ok(Source::Curve(ca))) = (&before[0].source, &after[0].source)
    else {
        panic!("spline")
    };
    assert_eq!(ca.knots(), cb.knots());
    assert_ne!(ca.control_points(), cb.control_points());
}

#[test]
fn dxf_entities_are_picked_by_layer_or_handle_and_written_back_alike() {
    let dir = tempfile::tempdir().unwrap();
    let input = two_layer_dxf(dir.path());
    let out = dir.path().join("o.dxf");
    let o = batten(&["fair", s(&input), "-o", s(&out)]);
    refused(
        &o,
        &[
            "two.dxf",
            "2 curve entities",
            "--entity HANDLE or --layer NAME",
            "on layer HULL",
            "on layer DECK",
        ],
    );
    assert!(!out.exists());

    ok(&batten(&[
        "fair",
        s(&input),
        "-o",
        s(&out),
        "--layer",
        "HULL",
        "--method",
        "mst",
        "--tolerance",
        "0.1",
    ]));
    let back = read(&out, &Pick::default());
    assert_eq!(back.origin.layer.as_deref(), Some("HULL"));
    assert_eq!(back.origin.z, 2.5);

    ok(&batten(&[
        "fair",
        s(&input),
        "-o",
        s(&out),
        "--entity",
        "b2",
        "--method",
        "mst",
        "--tolerance",
        "0.1",
    ]));
    assert_eq!(
        read(&out, &Pick::default()).origin.layer.as_deref(),
        Some("DECK")
    );

    let o = batten(&["fair", s(&input), "-o", s(&out), "--layer", "NONE"]);
    refused(&o, &["two.dxf: no curve entity on layer NONE"]);
    let o = batten(&["fair", s(&input), "-o", s(&out), "--select", "x"]);
    refused(&o, &["--select applies to an SVG input"]);
}

#[test]
fn svg_beziers_are_a_curve_or_sampled_points() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("glyph.svg");
    fs::write(
        &input,
        "<svg xmlns=\"http://www.w3.org/2000/svg\">\n\
         <rect id=\"frame\" width=\"10\" height=\"10\"/>\n\
         <path id=\"stem\" d=\"M0 0 C1 1.2 2 0.9 3 0.1 S5 -1.1 6 0 s2 1 3 0.05 Q10 -1 11 0\"/>\n\
         </svg>\n",
    )
    .unwrap();
    let (out, c) = (dir.path().join("o.svg"), dir.path().join("c.json"));
    ok(&batten(&[
        "fair",
        s(&input),
        "-o",
        s(&out),
        "--method",
        "eck-hadenfeld",
        "--tolerance",
        "0.2",
        "--curve-out",
        s(&c),
    ]));
    let faired = curve(&c);
    let written = curve(&out);
    // The faired cubic is written as Bézier segments: the same curve.
    assert!(curve_gap(&faired, &written) <= 1e-12);
    let o = batten(&["fair", s(&input), "-o", s(&out), "--method", "mst"]);
    refused(&o, &["glyph.svg", "salvi"]);
    let pts = dir.path().join("p.csv");
    ok(&batten(&[
        "fair",
        s(&input),
        "-o",
        s(&pts),
        "--method",
        "mst",
        "--tolerance",
        "0.05",
        "--sample",
        "8",
    ]));
    // Four segments (C, S, s, Q), eight points each, and the end point.
    assert_eq!(points(&pts).len(), 4 * 8 + 1);
    let o = batten(&[
        "fair",
        s(&input),
        "-o",
        s(&pts),
        "--select",
        "frame",
        "--method",
        "mst",
    ]);
    refused(&o, &["glyph.svg:2: element 'frame' is a <rect>"]);
}

#[test]
fn bad_cad_files_are_one_line_exit_2_and_nothing_written() {
    let dir = tempfile::tempdir().unwrap();
    for (name, text, needles) in [
        (
            "bad.igs",
            "not iges\n",
            &["bad.igs:1: record too short"][..],
        ),
        (
            "bad.dxf",
            "  0\nSECTION\n  2\nENTITIES\n  0\nLINE\n 10\nabc\n",
            &["bad.dxf: malformed DXF"][..],
        ),
        (
            "bad.svg",
            "<svg><path d=\"M0 0 L1\"/></svg>",
            &["bad.svg:1:", "expected a number"][..],
        ),
        (
            "arc.svg",
            "<svg><path d=\"M0 0 A1 1 0 0 1 2 2\"/></svg>",
            &["arc.svg:1:", "elliptical arcs"][..],
        ),
    ] {
        let input = dir.path().join(name);
        fs::write(&input, text).unwrap();
        let (out, rep) = (dir.path().join("o.csv"), dir.path().join("r.json"));
        let o = batten(&["fair", s(&input), "-o", s(&out), "--report", s(&rep)]);
        refused(&o, needles);
        assert!(!out.exists() && !rep.exists(), "{name}");
    }
}

#[test]
fn analyze_reads_stdin_and_picks_a_dxf_entity() {
    let o = batten_stdin(&["analyze", "-", "--json"], sine_csv().as_bytes());
    ok(&o);
    let from_pipe: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let o = batten(&["analyze", s(&noisy_sine(dir.path())), "--json"]);
    ok(&o);
    let from_file: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(from_pipe, from_file);

    let dxf = two_layer_dxf(dir.path());
    let o = batten(&["analyze", s(&dxf), "--layer", "DECK", "--json"]);
    ok(&o);
    let m: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(m["points"], 30);
    refused(
        &batten(&["analyze", s(&dxf)]),
        &["two.dxf: 2 curve entities"],
    );
    refused(
        &batten(&["analyze", s(&dxf), "--sample", "3"]),
        &["--sample applies to an SVG input"],
    );
}
