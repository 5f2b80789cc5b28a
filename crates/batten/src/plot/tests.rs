//! Tests of the SVG as a document: it parses, and holds what each panel promises.

use roxmltree::{Document, Node};

use super::*;
use crate::geom::Point;
use crate::{FairOptions, FairnessMetrics, fair};

fn cubic(n: usize) -> PointSeq {
    let pts = (0..n)
        .map(|i| {
            let x = -1.5 + 3.0 * i as f64 / (n - 1) as f64;
            Point::new(x, x * x * x - x)
        })
        .collect();
    PointSeq::open(pts).unwrap()
}

/// A sine with deterministic pseudo-random noise of relative size `noise`.
fn noisy_sine(n: usize, noise: f64) -> PointSeq {
    let pts = (0..n)
        .map(|i| {
            let x = 12.0 * i as f64 / (n - 1) as f64;
            let r = ((i as f64 * 12.9898).sin() * 43758.5453).fract();
            Point::new(x, (x / 2.0).sin() + noise * r)
        })
        .collect();
    PointSeq::open(pts).unwrap()
}

fn ellipse(n: usize) -> PointSeq {
    let pts = (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            Point::new(3.0 * a.cos(), 2.0 * a.sin())
        })
        .collect();
    PointSeq::closed(pts).unwrap()
}

fn parse(svg: &str) -> Document<'_> {
    Document::parse(svg).unwrap_or_else(|e| panic!("not XML: {e}"))
}

fn paths<'a>(doc: &'a Document<'a>) -> Vec<Node<'a, 'a>> {
    doc.descendants()
        .filter(|n| n.has_tag_name("path"))
        .collect()
}

fn series<'a>(doc: &'a Document<'a>, name: &str) -> Vec<Node<'a, 'a>> {
    paths(doc)
        .into_iter()
        .filter(|n| n.attribute("data-series") == Some(name))
        .collect()
}

fn texts(doc: &Document) -> Vec<String> {
    doc.descendants()
        .filter(|n| n.has_tag_name("text"))
        .map(|n| n.text().unwrap_or("").to_string())
        .collect()
}

fn circles(doc: &Document, class: &str) -> usize {
    doc.descendants()
        .filter(|n| n.has_tag_name("circle") && n.attribute("class") == Some(class))
        .count()
}

/// Subpaths (`M` commands) in the `d` of a path: the teeth of a comb path.
fn subpaths(node: &Node) -> usize {
    node.attribute("d").unwrap_or("").matches('M').count()
}

#[test]
fn every_kind_parses_as_svg_with_axes_and_a_title() {
    let seq = noisy_sine(30, 0.05);
    let faired = fair::fair("mst", &seq, &FairOptions::default().with_tolerance(0.1)).unwrap();
    let faired = seq.with_points(faired.points).unwrap();
    for kind in PlotKind::KINDS {
        let svg = render(&seq, Some(&faired), &PlotOptions::DEFAULT.with_kind(kind)).unwrap();
        let doc = parse(&svg);
        let root = doc.root_element();
        assert!(
            root.has_tag_name(("http://www.w3.org/2000/svg", "svg")),
            "{kind}"
        );
        assert_eq!(root.attribute("width"), Some("800"));
        let t = texts(&doc);
        let label = match kind {
            PlotKind::Comb => "y",
            PlotKind::Curvature => "curvature κ",
            PlotKind::Radius => "radius of curvature ρ",
            PlotKind::Xc => "c = y″/6",
            _ => "displacement",
        };
        assert!(t.iter().any(|s| s == label), "{kind}: {label}");
        // Tick labels: at least two per axis of each panel.
        let numeric = t.iter().filter(|s| s.parse::<f64>().is_ok()).count();
        assert!(numeric >= 4, "{kind}: {numeric} tick labels");
        for p in paths(&doc) {
            let d = p.attribute("d").unwrap_or("");
            assert!(
                d.chars().all(|c| "MLh0123456789.- ".contains(c)),
                "{kind}: {d}"
            );
        }
    }
}

#[test]
fn comb_has_a_path_per_series_and_labelled_axes() {
    let seq = noisy_sine(40, 0.03);
    let faired = fair::fair("mst", &seq, &FairOptions::default().with_tolerance(0.1)).unwrap();
    let faired = seq.with_points(faired.points).unwrap();
    let svg = render(&seq, Some(&faired), &PlotOptions::DEFAULT).unwrap();
    let doc = parse(&svg);
    for who in ["input", "faired"] {
        for what in ["curve", "comb teeth", "comb envelope", "points"] {
            assert_eq!(
                series(&doc, &format!("{who} {what}")).len(),
                1,
                "{who} {what}"
            );
        }
    }
    assert_eq!(series(&doc, "displacement").len(), 1);
    let t = texts(&doc);
    for label in ["Curvature comb", "x", "y"] {
        assert!(t.iter().any(|s| s == label), "{label} in {t:?}");
    }
    assert!(t.iter().any(|s| s.starts_with("comb: tooth = ")));
    // One tooth per sample: 39 spans × 16 samples + the end.
    let teeth = series(&doc, "input comb teeth");
    assert_eq!(subpaths(&teeth[0]), 39 * 16 + 1);
}

#[test]
fn graphs_have_their_axis_labels() {
    let seq = noisy_sine(30, 0.05);
    let svg = render(&seq, None, &PlotOptions::DEFAULT.with_kind(PlotKind::All)).unwrap();
    let doc = parse(&svg);
    let t = texts(&doc);
    for label in [
        "arc length s",
        "curvature κ",
        "radius of curvature ρ",
        "c = y″/6",
        "Curvature κ against arc length",
    ] {
        assert!(t.iter().any(|s| s == label), "{label}");
    }
    for name in [
        "input curvature",
        "input radius",
        "input x–c",
        "input curve",
    ] {
        assert_eq!(series(&doc, name).len(), 1, "{name}");
    }
    // No faired curve: no displacement panel.
    assert!(series(&doc, "displacement").is_empty());
    // Panels are stacked: four of them, 520 px each.
    assert_eq!(doc.root_element().attribute("height"), Some("2080"));
}

#[test]
fn inflection_markers_are_the_metrics_inflections() {
    let seq = cubic(41);
    let metrics = FairnessMetrics::of_seq(&seq).unwrap();
    assert_eq!(metrics.inflections, 1);
    let svg = render(&seq, None, &PlotOptions::DEFAULT).unwrap();
    assert_eq!(circles(&parse(&svg), "bt-infl0"), metrics.inflections);
    // On the curvature graph too, and for a wiggly curve.
    let wiggly = noisy_sine(50, 0.08);
    let m = FairnessMetrics::of_seq(&wiggly).unwrap().inflections;
    assert!(m > 5, "{m}");
    for kind in [PlotKind::Comb, PlotKind::Curvature] {
        let svg = render(&wiggly, None, &PlotOptions::DEFAULT.with_kind(kind)).unwrap();
        assert_eq!(circles(&parse(&svg), "bt-infl0"), m, "{kind}");
    }
}

#[test]
fn large_input_is_drawn_light() {
    // 10⁵ points here; `plot_of_a_million_points` below runs 10⁶ in release builds.
    let seq = noisy_sine(100_000, 1e-6);
    let faired = noisy_sine(100_000, 0.0);
    let svg = render(
        &seq,
        Some(&faired),
        &PlotOptions::DEFAULT.with_kind(PlotKind::All),
    )
    .unwrap();
    assert!(svg.len() < 2_000_000, "{} bytes", svg.len());
    let doc = parse(&svg);
    for who in ["input", "faired"] {
        let teeth = series(&doc, &format!("{who} comb teeth"));
        assert!(subpaths(&teeth[0]) <= MAX_TEETH);
        assert!(subpaths(&teeth[0]) >= MAX_TEETH / 2);
        for name in ["curve", "comb envelope", "curvature"] {
            let p = &series(&doc, &format!("{who} {name}"))[0];
            let vertices = p.attribute("d").unwrap_or("").matches(['M', 'L']).count();
            assert!(vertices <= MAX_VERTICES + 2, "{who} {name}: {vertices}");
        }
    }
    let t = texts(&doc);
    assert!(t.iter().any(|s| s == "input points (2000 of 100000 shown)"));
}

/// The size bound of the issue: a curve of 10⁶ points (and its faired version) gives an SVG
/// of at most a few megabytes. Slow without optimisation, so it runs in release builds
/// (`cargo test --release -p batten plot`).
#[test]
#[cfg_attr(debug_assertions, ignore = "10⁶ points: run with --release")]
fn plot_of_a_million_points() {
    let seq = noisy_sine(1_000_000, 1e-7);
    let faired = noisy_sine(1_000_000, 0.0);
    let start = std::time::Instant::now();
    let svg = render(
        &seq,
        Some(&faired),
        &PlotOptions::DEFAULT.with_kind(PlotKind::All),
    )
    .unwrap();
    assert!(svg.len() < 3_000_000, "{} bytes", svg.len());
    assert!(start.elapsed().as_secs_f64() < 60.0);
    let doc = parse(&svg);
    assert!(subpaths(&series(&doc, "input comb teeth")[0]) <= MAX_TEETH);
}

#[test]
fn radius_is_capped_where_straight() {
    // Straight, then a half circle, then straight: ρ is capped on the straight parts.
    let mut pts: Vec<Point> = (0..10)
        .map(|i| Point::new(i as f64 * 0.5 - 5.0, -1.0))
        .collect();
    pts.extend((1..20).map(|i| {
        let a = -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * i as f64 / 20.0;
        Point::new(a.cos(), a.sin())
    }));
    pts.extend((0..10).map(|i| Point::new(-(i as f64) * 0.5, 1.0)));
    let seq = PointSeq::open(pts).unwrap();
    let svg = render(
        &seq,
        None,
        &PlotOptions::DEFAULT
            .with_kind(PlotKind::Radius)
            .with_rho_max(3.0),
    )
    .unwrap();
    let doc = parse(&svg);
    assert_eq!(series(&doc, "input radius").len(), 1);
    assert_eq!(series(&doc, "input radius capped").len(), 1);
    assert_eq!(series(&doc, "+ρmax").len(), 1);
    assert!(texts(&doc).iter().any(|s| s == "ρmax = 3.00"));
}

#[test]
fn straight_line_has_no_teeth_and_a_capped_radius() {
    let pts = (0..10)
        .map(|i| Point::new(i as f64, 2.0 * i as f64))
        .collect();
    let seq = PointSeq::open(pts).unwrap();
    assert_eq!(auto_comb_scale(&seq, &[]).unwrap(), 0.0);
    let svg = render(&seq, None, &PlotOptions::DEFAULT.with_kind(PlotKind::All)).unwrap();
    let doc = parse(&svg);
    assert!(series(&doc, "input comb teeth").is_empty());
    assert_eq!(circles(&doc, "bt-infl0"), 0);
    assert!(!svg.contains("NaN"));
}

#[test]
fn closed_curves_draw_without_an_xc_plot() {
    let seq = ellipse(48);
    let svg = render(&seq, None, &PlotOptions::DEFAULT.with_kind(PlotKind::All)).unwrap();
    let doc = parse(&svg);
    assert!(series(&doc, "input x–c").is_empty());
    assert!(texts(&doc).iter().any(|s| s.starts_with("no x–c plot: ")));
    // The closed curve's polyline ends where it starts.
    let d = series(&doc, "input curve")[0].attribute("d").unwrap_or("");
    let first = d.trim_start_matches('M').split('L').next().unwrap_or("");
    assert_eq!(d.rsplit('L').next(), Some(first));
    let err = render(&seq, None, &PlotOptions::DEFAULT.with_kind(PlotKind::Xc)).unwrap_err();
    assert!(matches!(err, Error::Degenerate(_)), "{err}");
}

#[test]
fn xc_plot_in_the_chord_frame() {
    // A gentle wave turned on its side: x no longer increases, but it does along the chord.
    let pts: Vec<Point> = (0..21)
        .map(|i| {
            let t = 0.15 * i as f64;
            Point::new(-0.3 * t.sin(), t)
        })
        .collect();
    let seq = PointSeq::open(pts).unwrap();
    let svg = render(&seq, None, &PlotOptions::DEFAULT.with_kind(PlotKind::Xc)).unwrap();
    let doc = parse(&svg);
    assert_eq!(series(&doc, "input x–c").len(), 1);
    assert_eq!(series(&doc, "input x–c points").len(), 1);
    assert!(
        texts(&doc)
            .iter()
            .any(|s| s.starts_with("x in the chord frame"))
    );
}

#[test]
fn bad_requests_are_errors() {
    let seq = cubic(20);
    let short = cubic(19);
    assert!(matches!(
        render(&seq, Some(&short), &PlotOptions::DEFAULT),
        Err(Error::LengthMismatch { .. })
    ));
    assert!(matches!(
        render(&ellipse(20), Some(&seq), &PlotOptions::DEFAULT),
        Err(Error::InvalidParameter { .. })
    ));
    assert!(matches!(
        render(
            &seq,
            None,
            &PlotOptions::DEFAULT.with_kind(PlotKind::Displacement)
        ),
        Err(Error::InvalidParameter { .. })
    ));
    for bad in [
        PlotOptions::DEFAULT.with_comb_scale(0.0),
        PlotOptions::DEFAULT.with_comb_scale(f64::NAN),
        PlotOptions::DEFAULT.with_rho_max(-1.0),
        PlotOptions::DEFAULT.with_size(10.0, 500.0),
        PlotOptions::DEFAULT.with_size(800.0, f64::INFINITY),
    ] {
        assert!(matches!(
            render(&seq, None, &bad),
            Err(Error::InvalidParameter { .. })
        ));
    }
    assert_eq!("xc".parse::<PlotKind>().unwrap(), PlotKind::Xc);
    let e = "bar".parse::<PlotKind>().unwrap_err().to_string();
    assert!(
        e.contains("known: comb, curvature, radius, xc, displacement, all"),
        "{e}"
    );
}

#[test]
fn titles_are_escaped_and_placed() {
    let seq = cubic(12);
    let svg = render(
        &seq,
        None,
        &PlotOptions::DEFAULT.with_title("a < b & \"c\""),
    )
    .unwrap();
    let doc = parse(&svg);
    assert!(texts(&doc).iter().any(|s| s == "a < b & \"c\""));
    let svg = render(
        &seq,
        None,
        &PlotOptions::DEFAULT
            .with_kind(PlotKind::All)
            .with_title("heading"),
    )
    .unwrap();
    let t = texts(&parse(&svg));
    assert!(t.iter().any(|s| s == "heading") && t.iter().any(|s| s == "Curvature comb"));
}

#[test]
fn a_fixed_comb_scale_is_used_and_shared() {
    let seq = noisy_sine(30, 0.05);
    let svg = render(&seq, None, &PlotOptions::DEFAULT.with_comb_scale(0.25)).unwrap();
    assert!(
        texts(&parse(&svg))
            .iter()
            .any(|s| s == "comb: tooth = 0.250 × κ")
    );
    let smooth = noisy_sine(30, 0.0);
    let both = auto_comb_scale(&seq, &[&smooth]).unwrap();
    let alone = auto_comb_scale(&seq, &[]).unwrap();
    assert!(both > 0.0 && both <= alone);
}
