//! End-to-end tests of `batten plot` and `batten report`: the SVG and HTML they write, and
//! bad input refused with exit 2, one line on stderr and no output.

#![allow(clippy::unwrap_used)]

mod common;

use common::{assert_usage_error, batten, code, example, s, stderr};
use std::fs;

/// An SVG document as `batten plot` writes it: one `<svg>` element, closed.
fn assert_svg(text: &str) {
    assert!(
        text.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\""),
        "{}",
        &text[..80.min(text.len())]
    );
    assert!(text.trim_end().ends_with("</svg>"));
    assert_eq!(text.matches("<svg").count(), 1);
    assert!(!text.contains("NaN"));
}

#[test]
fn plot_every_kind() {
    let dir = tempfile::tempdir().unwrap();
    let input = example("sine-noisy.csv");
    for kind in ["comb", "curvature", "radius", "xc", "all"] {
        let out = dir.path().join(format!("{kind}.svg"));
        let o = batten(&["plot", s(&input), "--kind", kind, "-o", s(&out)]);
        assert_eq!(code(&o), 0, "{kind}: {}", stderr(&o));
        assert!(o.stdout.is_empty() && o.stderr.is_empty());
        let svg = fs::read_to_string(&out).unwrap();
        assert_svg(&svg);
        let series = match kind {
            "comb" => "input comb teeth",
            "curvature" => "input curvature",
            "radius" => "input radius",
            "xc" => "input x–c",
            _ => "input curve",
        };
        assert!(svg.contains(&format!("data-series=\"{series}\"")), "{kind}");
        assert!(!svg.contains("data-series=\"faired"), "{kind}");
    }
    // Options reach the picture.
    let out = dir.path().join("scaled.svg");
    let o = batten(&[
        "plot",
        s(&input),
        "--comb-scale",
        "0.5",
        "--width",
        "640",
        "--title",
        "Sine <noisy>",
        "-o",
        s(&out),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let svg = fs::read_to_string(&out).unwrap();
    assert!(svg.contains("width=\"640\""));
    assert!(svg.contains("comb: tooth = 0.500 × κ"));
    assert!(svg.contains("Sine &lt;noisy&gt;"));
}

#[test]
fn plot_faired_over_the_input() {
    let dir = tempfile::tempdir().unwrap();
    let input = example("sine-noisy.csv");
    let faired = dir.path().join("faired.csv");
    let o = batten(&["fair", s(&input), "-o", s(&faired), "--tolerance", "0.1"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    for kind in ["comb", "all", "displacement"] {
        let out = dir.path().join(format!("overlay-{kind}.svg"));
        let o = batten(&[
            "plot",
            s(&input),
            "--faired",
            s(&faired),
            "--kind",
            kind,
            "-o",
            s(&out),
        ]);
        assert_eq!(code(&o), 0, "{kind}: {}", stderr(&o));
        let svg = fs::read_to_string(&out).unwrap();
        assert_svg(&svg);
        assert!(svg.contains("data-series=\"displacement\""), "{kind}");
        if kind != "displacement" {
            assert!(svg.contains("data-series=\"input curve\""));
            assert!(svg.contains("data-series=\"faired curve\""));
            assert!(svg.contains("data-series=\"faired comb teeth\""));
        }
    }
}

#[test]
fn plot_closed_curve() {
    let dir = tempfile::tempdir().unwrap();
    let input = example("ellipse-noisy.json");
    let out = dir.path().join("ellipse.svg");
    let o = batten(&["plot", s(&input), "--kind", "all", "-o", s(&out)]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let svg = fs::read_to_string(&out).unwrap();
    assert_svg(&svg);
    assert!(svg.contains("no x–c plot: "));
    // An x–c plot alone of a closed curve is a request the data cannot meet.
    let out = dir.path().join("xc.svg");
    let o = batten(&["plot", s(&input), "--kind", "xc", "-o", s(&out)]);
    assert_usage_error(&o, &["ellipse-noisy.json", "cannot plot", "closed"]);
    assert!(!out.exists());
}

#[test]
fn plot_refuses_bad_input_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.csv");
    fs::write(&bad, "x,y\n0,0\n1,1\n2,zero\n3,1\n4,0\n").unwrap();
    let out = dir.path().join("out.svg");
    let o = batten(&["plot", s(&bad), "-o", s(&out)]);
    assert_usage_error(&o, &["bad.csv:4"]);
    assert!(!out.exists());
    // An existing output is left alone.
    fs::write(&out, "keep").unwrap();
    let o = batten(&["plot", s(&bad), "--kind", "all", "-o", s(&out)]);
    assert_usage_error(&o, &["bad.csv:4"]);
    assert_eq!(fs::read_to_string(&out).unwrap(), "keep");

    let input = example("sine-noisy.csv");
    // A faired file with another point count.
    let short = dir.path().join("short.csv");
    fs::write(&short, "x,y\n0,0\n1,1\n2,0\n3,1\n4,0\n").unwrap();
    let out2 = dir.path().join("o2.svg");
    let o = batten(&["plot", s(&input), "--faired", s(&short), "-o", s(&out2)]);
    assert_usage_error(&o, &["short.csv", "5 points", "30"]);
    assert!(!out2.exists());
    // A bad faired file names its own line.
    let o = batten(&["plot", s(&input), "--faired", s(&bad), "-o", s(&out2)]);
    assert_usage_error(&o, &["bad.csv:4"]);
    // Displacement without a faired curve, a bad scale, a non-SVG output, a missing
    // directory, the input itself as output.
    let o = batten(&["plot", s(&input), "--kind", "displacement", "-o", s(&out2)]);
    assert_usage_error(&o, &["--faired"]);
    let o = batten(&["plot", s(&input), "--comb-scale", "0", "-o", s(&out2)]);
    assert_usage_error(&o, &["comb scale"]);
    let o = batten(&["plot", s(&input), "-o", s(&dir.path().join("o.png"))]);
    assert_usage_error(&o, &["o.png", ".svg"]);
    let o = batten(&[
        "plot",
        s(&input),
        "-o",
        s(&dir.path().join("no/such/o.svg")),
    ]);
    assert_usage_error(&o, &["does not exist"]);
    // Never the input, even under another name.
    let copy = dir.path().join("in.csv");
    fs::copy(&input, &copy).unwrap();
    #[cfg(unix)]
    {
        let link = dir.path().join("link.svg");
        std::os::unix::fs::symlink(&copy, &link).unwrap();
        let o = batten(&["plot", s(&copy), "-o", s(&link)]);
        assert_usage_error(&o, &["refusing to write"]);
        assert_eq!(fs::read(&copy).unwrap(), fs::read(&input).unwrap());
    }
    assert!(!out2.exists());
}

#[test]
fn report_is_one_html_page_with_the_table_and_inline_svg() {
    let dir = tempfile::tempdir().unwrap();
    let input = example("cubic-noisy.csv");
    let out = dir.path().join("report.html");
    let o = batten(&[
        "report",
        s(&input),
        "--methods",
        "han,mst",
        "--tolerance",
        "0.05",
        "-o",
        s(&out),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let html = fs::read_to_string(&out).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>"));
    assert!(html.trim_end().ends_with("</html>"));
    // Self-contained: no scripts, no links to fetch.
    for banned in ["<script", "<link", "http://", "https://", "@import", "url("] {
        let hits = html.matches(banned).count();
        // The only URL is each inline SVG's namespace.
        let allowed = if banned == "http://" {
            html.matches("xmlns=\"http://www.w3.org/2000/svg\"").count()
        } else {
            0
        };
        assert_eq!(hits, allowed, "{banned}");
    }
    // The metrics table, the comparison table (as `batten compare` prints it) and the plots:
    // input comb and κ(s), then comb and κ(s) for each of the two methods.
    assert!(html.contains("<table class=\"metrics\">"));
    assert!(html.contains("<table class=\"compare\">"));
    assert!(html.contains("<th>Method</th>"));
    assert!(html.contains("<td>input</td>"));
    assert!(html.contains("<h2>han</h2>") && html.contains("<h2>mst</h2>"));
    assert_eq!(html.matches("<svg ").count(), 6);
    assert_eq!(html.matches("data-series=\"faired comb teeth\"").count(), 2);
    assert_eq!(html.matches("data-series=\"faired curvature\"").count(), 2);
    // As in `batten compare`, mst ran at han's largest displacement: the note says so.
    assert!(html.contains("(as in Han et al.)"));
    // One comb scale for the whole page.
    let scales: Vec<&str> = html
        .match_indices("comb: tooth = ")
        .map(|(i, _)| &html[i..i + 30])
        .collect();
    assert_eq!(scales.len(), 3);
    assert!(scales.iter().all(|s| *s == scales[0]), "{scales:?}");
}

#[test]
fn report_of_a_closed_curve_says_which_methods_were_skipped() {
    let dir = tempfile::tempdir().unwrap();
    let input = example("ellipse-noisy.json");
    let out = dir.path().join("r.html");
    let o = batten(&["report", s(&input), "--methods", "mst,cali", "-o", s(&out)]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let html = fs::read_to_string(&out).unwrap();
    assert!(html.contains("skipped: does not support closed curves"));
    assert_eq!(html.matches("<svg ").count(), 4);
}

#[test]
fn report_refuses_bad_input_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("dup.csv");
    fs::write(&bad, "x,y\n0,0\n1,1\n1,1\n3,1\n4,0\n").unwrap();
    let out = dir.path().join("r.html");
    let o = batten(&["report", s(&bad), "-o", s(&out)]);
    assert_usage_error(&o, &["dup.csv:4", "duplicates"]);
    assert!(!out.exists());
    let input = example("sine-noisy.csv");
    let o = batten(&["report", s(&input), "--methods", "nope", "-o", s(&out)]);
    assert_usage_error(&o, &["unknown method 'nope'"]);
    let o = batten(&["report", s(&input), "--tolerance", "0", "-o", s(&out)]);
    assert_usage_error(&o, &["tolerance"]);
    let o = batten(&["report", s(&input), "-o", s(&dir.path().join("r.svg"))]);
    assert_usage_error(&o, &[".html"]);
    assert!(!out.exists());
}
