//! SVG pictures of space curves ([`render_space`]): three orthographic views as in ship
//! lines — **plan** (x–y), **profile** (x–z) and **body plan** (y–z) — each with the curve
//! and its curvature comb, then the graphs **κ(s)** and **τ(s)**, stacked in that order.
//!
//! The comb teeth lie along the principal normal N (towards the centre of curvature),
//! `point + scale·κ·N`, projected into each view; one scale serves every view and both
//! curves, so a tooth foreshortened in one view is seen at full length in another. The
//! envelope through the tooth tips is drawn too. With a faired curve, it is drawn over the
//! input in every panel (series 1, red), as the planar plots do.
//!
//! Everything is measured on [`SpaceCubic::of_seq`], the curve
//! [`SpaceMetrics`](crate::analysis::SpaceMetrics) measures. Torsion is undefined where
//! κ = 0: the τ graph has a gap there. Large inputs are thinned as in the planar plots: the
//! graphs keep each arc-length bin's smallest and largest value in [`super::MAX_VERTICES`]
//! vertices, and each view draws half of [`super::MAX_TEETH`], [`super::MAX_VERTICES`] and
//! [`super::MAX_DOTS`] per curve (there are three views): 10⁶ points and a faired curve give
//! an SVG under a megabyte.

use super::axes::{self, Frame, GRAPH_PAD, LegendItem, Range, Rect, Swatch, sig3};
use super::panels::count_label;
use super::sample::{min_max_indices, select_by_arc_length, stride_indices};
use super::svg::{PathData, Svg};
use super::{MAX_DOTS, MAX_TEETH, MAX_VERTICES, PlotOptions};
use crate::analysis::{SpaceCubic, SpaceSample};
use crate::error::Result;
use crate::geom::{SpaceSeq, Xyz};

/// The most samples per span (as for planar curves).
const MAX_SAMPLES_PER_SPAN: usize = 16;
/// Height of the heading of a picture with a title, in pixels.
const HEADING: f64 = 34.0;
/// Margin added around the geometry of a view, as a fraction of its extent.
const VIEW_PAD: f64 = 0.04;
/// Width of the data-point dots, in pixels.
const DOT_WIDTH: f64 = 2.0;
/// A view draws half the planar limits of vertices, teeth and dots per curve: there are
/// three views, and 10⁶ points must stay under a megabyte of SVG.
const VIEW_VERTICES: usize = MAX_VERTICES / 2;
/// See [`VIEW_VERTICES`].
const VIEW_TEETH: usize = MAX_TEETH / 2;
/// See [`VIEW_VERTICES`].
const VIEW_DOTS: usize = MAX_DOTS / 2;

const CURVE: [&str; 2] = ["bt-curve0", "bt-curve1"];
const TEETH: [&str; 2] = ["bt-teeth0", "bt-teeth1"];
const ENVELOPE: [&str; 2] = ["bt-env0", "bt-env1"];
const DOTS: [&str; 2] = ["bt-dots0", "bt-dots1"];
const NAME: [&str; 2] = ["input", "faired"];

/// The three views: name, the two axes drawn (horizontal, vertical) and their labels.
pub const SPACE_VIEWS: [(&str, [usize; 2], [&str; 2]); 3] = [
    ("Plan (x–y)", [0, 1], ["x", "y"]),
    ("Profile (x–z)", [0, 2], ["x", "z"]),
    ("Body plan (y–z)", [1, 2], ["y", "z"]),
];

/// A space curve as drawn: samples of its analysis curve and the indices drawn.
#[derive(Debug)]
struct SpaceSampled<'a> {
    seq: &'a SpaceSeq,
    samples: Vec<SpaceSample>,
    /// Arc length at each sample.
    s: Vec<f64>,
    /// The samples the comb scale is taken over, chosen by arc length (as for planar curves).
    vertices: Vec<usize>,
    /// The polyline and envelope vertices of a view, chosen by arc length.
    view_vertices: Vec<usize>,
}

impl<'a> SpaceSampled<'a> {
    fn new(seq: &'a SpaceSeq) -> Result<SpaceSampled<'a>> {
        let curve = SpaceCubic::of_seq(seq)?;
        let m = curve.num_spans();
        let per_span = ((MAX_VERTICES - 1) / m.max(1)).clamp(1, MAX_SAMPLES_PER_SPAN);
        let samples = curve.samples(per_span);
        drop(curve);
        let s: Vec<f64> = samples.iter().map(|x| x.s).collect();
        let vertices = select_by_arc_length(&s, MAX_VERTICES);
        let view_vertices = select_by_arc_length(&s, VIEW_VERTICES);
        Ok(SpaceSampled {
            seq,
            samples,
            s,
            vertices,
            view_vertices,
        })
    }

    fn length(&self) -> f64 {
        self.s.last().copied().unwrap_or(0.0)
    }

    /// The largest κ over the drawn vertices, or 0.
    fn max_drawn_curvature(&self) -> f64 {
        self.vertices
            .iter()
            .map(|&i| self.samples[i].curvature)
            .filter(|k| k.is_finite())
            .fold(0.0, f64::max)
    }

    /// The tooth tip of sample `i`.
    fn tip(&self, i: usize, scale: f64) -> Xyz {
        let c = &self.samples[i];
        std::array::from_fn(|k| c.point[k] + scale * c.curvature * c.normal[k])
    }
}

/// The automatic comb scale for drawing `input` and `others` with one scale (see
/// [`super::auto_comb_scale`]): the largest tooth drawn of any of them is
/// `DEFAULT_COMB_FRACTION` of the diagonal of `input`'s bounding box; 0 when all are
/// straight.
///
/// # Errors
/// The analysis curve's errors.
pub fn auto_space_comb_scale(input: &SpaceSeq, others: &[&SpaceSeq]) -> Result<f64> {
    let mut max_k = SpaceSampled::new(input)?.max_drawn_curvature();
    for o in others {
        max_k = max_k.max(SpaceSampled::new(o)?.max_drawn_curvature());
    }
    Ok(space_scale_for(input, max_k))
}

fn space_scale_for(input: &SpaceSeq, max_curvature: f64) -> f64 {
    super::comb_scale_for(input.scale(), max_curvature)
}

/// Draw the space curve `input`, and `faired` over it when given, as an SVG document of
/// five stacked panels (see the module docs): the three views, κ(s) and τ(s). Each
/// panel is [`PlotOptions::height`] high; [`PlotOptions::kind`] and
/// [`PlotOptions::rho_max`] do not apply, [`PlotOptions::comb_scale`] fixes the comb scale
/// and [`PlotOptions::title`] adds a heading.
///
/// # Errors
/// - [`crate::Error::InvalidParameter`] for bad options ([`PlotOptions::validate`]) and a `faired`
///   curve that is closed where the input is open or the other way round;
/// - [`crate::Error::LengthMismatch`] when `faired` has another number of points;
/// - the analysis curve's errors.
pub fn render_space(
    input: &SpaceSeq,
    faired: Option<&SpaceSeq>,
    options: &PlotOptions,
) -> Result<String> {
    options.validate()?;
    super::check_faired(
        faired.map(|f| (f.len(), f.is_closed())),
        (input.len(), input.is_closed()),
    )?;
    let inp = SpaceSampled::new(input)?;
    let fai = faired.map(SpaceSampled::new).transpose()?;
    let series: Vec<&SpaceSampled> = std::iter::once(&inp).chain(fai.as_ref()).collect();
    let scale = options.comb_scale.unwrap_or_else(|| {
        let k = series
            .iter()
            .map(|s| s.max_drawn_curvature())
            .fold(0.0, f64::max);
        space_scale_for(input, k)
    });

    let heading = if options.title.is_some() {
        HEADING
    } else {
        0.0
    };
    let rows = SPACE_VIEWS.len() + 2;
    let mut svg = Svg::new(options.width, heading + options.height * rows as f64);
    if let Some(t) = &options.title {
        svg.text(options.width / 2.0, 24.0, "bt-title", "middle", t);
    }
    let outer = |row: usize| Rect {
        x: 0.0,
        y: heading + options.height * row as f64,
        w: options.width,
        h: options.height,
    };
    for (row, view) in SPACE_VIEWS.iter().enumerate() {
        view_panel(&mut svg, outer(row), &series, scale, view);
    }
    graph_panel(
        &mut svg,
        outer(rows - 2),
        &series,
        "Curvature κ against arc length",
        ("κ", "curvature κ"),
        |x| x.curvature,
    );
    graph_panel(
        &mut svg,
        outer(rows - 1),
        &series,
        "Torsion τ against arc length",
        ("τ", "torsion τ"),
        |x| x.torsion.unwrap_or(f64::NAN),
    );
    Ok(svg.finish())
}

/// Open a panel: its group, title and axes around the frame `frame_of` gives for its plot
/// area; the caller draws, then closes it with [`close_panel`].
fn open_panel(
    svg: &mut Svg,
    outer: Rect,
    title: &str,
    labels: [&str; 2],
    legend: &[LegendItem],
    frame_of: impl FnOnce(Rect) -> Frame,
) -> Frame {
    svg.group_open("bt-panel");
    axes::title(svg, outer, title);
    let frame = frame_of(outer.plot_area(axes::legend_rows(outer, legend)));
    axes::axes(svg, &frame, labels[0], labels[1]);
    frame
}

fn close_panel(svg: &mut Svg, outer: Rect, legend: &[LegendItem]) {
    axes::legend(svg, outer, legend);
    svg.group_close();
}

/// One orthographic view with the curves, their combs and the data points.
fn view_panel(
    svg: &mut Svg,
    outer: Rect,
    series: &[&SpaceSampled],
    scale: f64,
    (title, [a, b], labels): &(&str, [usize; 2], [&str; 2]),
) {
    let (a, b) = (*a, *b);
    let (xr, yr) = Range::of_pairs(series.iter().flat_map(|s| {
        let (lo, hi) = s.seq.bounds();
        let tips = s.view_vertices.iter().map(|&i| s.tip(i, scale));
        tips.chain([lo, hi]).map(|p| (p[a], p[b]))
    }));
    let mut legend = Vec::new();
    for (k, s) in series.iter().enumerate() {
        let n = s.seq.len();
        legend.push(LegendItem::new(
            Swatch::Line(CURVE[k]),
            format!("{} curve", NAME[k]),
        ));
        legend.push(LegendItem::new(
            Swatch::Dot(DOTS[k]),
            count_label(&format!("{} points", NAME[k]), n.min(VIEW_DOTS), n),
        ));
    }
    legend.push(LegendItem::new(
        Swatch::Line(ENVELOPE[0]),
        format!("comb along N: tooth = {} × κ", sig3(scale)),
    ));
    let f = open_panel(svg, outer, title, *labels, &legend, |area| {
        Frame::equal_aspect(area, xr.padded(VIEW_PAD), yr.padded(VIEW_PAD))
    });
    let map = |p: Xyz| f.map(p[a], p[b]);
    for (k, s) in series.iter().enumerate() {
        let mut teeth = PathData::new();
        let mut envelope = PathData::new();
        if scale > 0.0 {
            for i in select_by_arc_length(&s.s, VIEW_TEETH) {
                teeth.segment(map(s.samples[i].point), map(s.tip(i, scale)));
            }
            for &i in &s.view_vertices {
                let (x, y) = map(s.tip(i, scale));
                envelope.line_to(x, y);
            }
        }
        svg.path(&teeth, TEETH[k], &format!("{} comb teeth", NAME[k]));
        svg.path(
            &envelope,
            ENVELOPE[k],
            &format!("{} comb envelope", NAME[k]),
        );
        let mut curve = PathData::new();
        for &i in &s.view_vertices {
            let (x, y) = map(s.samples[i].point);
            curve.line_to(x, y);
        }
        svg.path(&curve, CURVE[k], &format!("{} curve", NAME[k]));
    }
    for (k, s) in series.iter().enumerate() {
        let pts = s.seq.points();
        let mut dots = PathData::new();
        for i in stride_indices(pts.len(), VIEW_DOTS) {
            let (x, y) = map(pts[i]);
            dots.dot(x, y);
        }
        svg.path_with_width(&dots, DOTS[k], &format!("{} points", NAME[k]), DOT_WIDTH);
    }
    close_panel(svg, outer, &legend);
}

/// A graph of `value` against arc length, keeping each bin's smallest and largest value.
fn graph_panel(
    svg: &mut Svg,
    outer: Rect,
    series: &[&SpaceSampled],
    title: &str,
    (symbol, ylabel): (&str, &str),
    value: impl Fn(&SpaceSample) -> f64,
) {
    let drawn: Vec<(Vec<usize>, Vec<f64>)> = series
        .iter()
        .map(|s| {
            let v: Vec<f64> = s.samples.iter().map(&value).collect();
            (min_max_indices(&s.s, &v, MAX_VERTICES / 2), v)
        })
        .collect();
    let sr = series
        .iter()
        .map(|s| Range {
            lo: 0.0,
            hi: s.length(),
        })
        .fold(Range { lo: 0.0, hi: 0.0 }, Range::union);
    let vr = drawn
        .iter()
        .filter_map(|(idx, v)| Range::of(idx.iter().map(|&i| v[i])))
        .fold(Range { lo: 0.0, hi: 0.0 }, Range::union);
    let legend: Vec<LegendItem> = (0..series.len())
        .map(|k| LegendItem::new(Swatch::Line(CURVE[k]), format!("{} {symbol}(s)", NAME[k])))
        .collect();
    let f = open_panel(
        svg,
        outer,
        title,
        ["arc length s", ylabel],
        &legend,
        |area| Frame::new(area, sr.padded(0.0), vr.padded(GRAPH_PAD)),
    );
    let mut zero = PathData::new();
    zero.segment((f.area.x, f.py(0.0)), (f.area.x + f.area.w, f.py(0.0)));
    svg.path(&zero, "bt-zero", &format!("{symbol} = 0"));
    for (k, (s, (idx, v))) in series.iter().zip(&drawn).enumerate() {
        let mut d = PathData::new();
        for &i in idx {
            let (x, y) = f.map(s.s[i], v[i]);
            d.line_to(x, y);
        }
        svg.path(&d, CURVE[k], &format!("{} {symbol}", NAME[k]));
    }
    close_panel(svg, outer, &legend);
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use roxmltree::Document;

    use super::*;
    use crate::error::Error;

    fn helix(n: usize, wobble: f64) -> SpaceSeq {
        let pts = (0..n)
            .map(|i| {
                let t = 12.0 * i as f64 / (n - 1) as f64;
                let r = ((i as f64 * 12.9898).sin() * 43758.5453).fract();
                [t.cos(), t.sin(), 0.2 * t + wobble * r]
            })
            .collect();
        SpaceSeq::new(pts, false).unwrap()
    }

    fn with_series<'a>(doc: &'a Document<'a>, name: &str) -> usize {
        doc.descendants()
            .filter(|n| n.has_tag_name("path") && n.attribute("data-series") == Some(name))
            .count()
    }

    #[test]
    fn draws_three_views_and_two_graphs() {
        let seq = helix(200, 1e-3);
        let faired = helix(200, 0.0);
        let svg = render_space(
            &seq,
            Some(&faired),
            &PlotOptions::DEFAULT.with_title("helix"),
        )
        .unwrap();
        let doc = Document::parse(&svg).unwrap();
        let texts: Vec<&str> = doc
            .descendants()
            .filter(|n| n.has_tag_name("text"))
            .filter_map(|n| n.text())
            .collect();
        for (title, _, _) in SPACE_VIEWS {
            assert!(texts.contains(&title), "{title}");
        }
        assert!(texts.contains(&"Curvature κ against arc length"));
        assert!(texts.contains(&"Torsion τ against arc length"));
        let panels = doc
            .descendants()
            .filter(|n| n.attribute("class") == Some("bt-panel"))
            .count();
        assert_eq!(panels, 5);
        for name in ["input", "faired"] {
            assert_eq!(with_series(&doc, &format!("{name} curve")), 3);
            assert_eq!(with_series(&doc, &format!("{name} comb teeth")), 3);
            assert_eq!(with_series(&doc, &format!("{name} comb envelope")), 3);
            assert_eq!(with_series(&doc, &format!("{name} κ")), 1);
            assert_eq!(with_series(&doc, &format!("{name} τ")), 1);
        }
        // One scale for both curves and every view.
        let s = auto_space_comb_scale(&seq, &[&faired]).unwrap();
        assert!(svg.contains(&format!("tooth = {} × κ", sig3(s))));
    }

    #[test]
    fn rejects_mismatched_curves_and_draws_a_straight_line() {
        let a = helix(50, 0.0);
        let b = helix(51, 0.0);
        assert!(matches!(
            render_space(&a, Some(&b), &PlotOptions::DEFAULT),
            Err(Error::LengthMismatch { .. })
        ));
        let line: Vec<Xyz> = (0..5).map(|i| [i as f64, 0.5 * i as f64, 0.0]).collect();
        let line = SpaceSeq::new(line, true).unwrap();
        // A closed "line" folds back on itself: still drawn, no panic.
        let svg = render_space(&line, None, &PlotOptions::DEFAULT).unwrap();
        assert!(Document::parse(&svg).is_ok());
    }

    /// 10⁶ points and a faired curve: thinned to an SVG under a megabyte (about 2 s in the
    /// test profile).
    #[test]
    fn space_plot_of_a_million_points() {
        let seq = helix(1_000_000, 1e-7);
        let faired = helix(1_000_000, 0.0);
        let start = std::time::Instant::now();
        let svg = render_space(&seq, Some(&faired), &PlotOptions::DEFAULT).unwrap();
        assert!(svg.len() < 1_000_000, "{} bytes", svg.len());
        assert!(start.elapsed().as_secs_f64() < 60.0);
        let doc = Document::parse(&svg).unwrap();
        let teeth = doc
            .descendants()
            .filter(|n| n.attribute("data-series") == Some("input comb teeth"))
            .map(|n| n.attribute("d").unwrap_or("").matches('M').count())
            .max()
            .unwrap_or(0);
        assert!(teeth <= VIEW_TEETH);
    }
}
