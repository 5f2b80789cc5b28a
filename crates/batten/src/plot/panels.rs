//! The panels: comb, κ(s), ρ(s), HAN's x–c plot, displacements. Series 0 is the input,
//! series 1 the faired points.

use super::axes::{self, Frame, GRAPH_PAD, LegendItem, Range, Rect, Swatch, sig3};
use super::sample::{Sampled, XcData, min_max_indices, stride_indices};
use super::svg::{PathData, Svg};
use super::{MAX_DOTS, MAX_TEETH, MAX_VERTICES};
use crate::geom::Point;

const CURVE: [&str; 2] = ["bt-curve0", "bt-curve1"];
const TEETH: [&str; 2] = ["bt-teeth0", "bt-teeth1"];
const ENVELOPE: [&str; 2] = ["bt-env0", "bt-env1"];
const DOTS: [&str; 2] = ["bt-dots0", "bt-dots1"];
const CAPPED: [&str; 2] = ["bt-cap0", "bt-cap1"];
const INFLECTION: [&str; 2] = ["bt-infl0", "bt-infl1"];
const NAME: [&str; 2] = ["input", "faired"];

/// Radius of an inflection marker on the curve, in pixels.
const MARKER_R: f64 = 4.5;
/// Radius of an inflection marker on a graph's zero line, in pixels.
const GRAPH_MARKER_R: f64 = 3.5;
/// Diameter of the data-point dots as a fraction of their spacing along the curve ...
const DOT_SPACING_FRACTION: f64 = 0.5;
/// ... but no less than this many pixels ...
const DOT_MIN: f64 = 1.2;
/// ... and no more.
const DOT_MAX: f64 = 3.5;
/// Margin added around the geometry of the comb panel, as a fraction of its extent.
const COMB_PAD: f64 = 0.04;

/// A legend label for `shown` of `total` things.
pub(super) fn count_label(what: &str, shown: usize, total: usize) -> String {
    if shown < total {
        format!("{what} ({shown} of {total} shown)")
    } else {
        format!("{what} ({total})")
    }
}

/// Draw a panel's title, axes and legend around `body`, which draws the data in the frame.
fn panel(
    svg: &mut Svg,
    outer: Rect,
    title: &str,
    labels: (&str, &str),
    legend: &[LegendItem],
    frame_of: impl FnOnce(Rect) -> Frame,
    body: impl FnOnce(&mut Svg, &Frame),
) {
    svg.group_open("bt-panel");
    axes::title(svg, outer, title);
    let frame = frame_of(outer.plot_area(axes::legend_rows(outer, legend)));
    axes::axes(svg, &frame, labels.0, labels.1);
    body(svg, &frame);
    axes::legend(svg, outer, legend);
    svg.group_close();
}

/// The tooth tip of comb sample `i`: `point + scale·κ·normal` (the convention of
/// [`crate::analysis::CombSample`]); not finite where the curvature is not.
fn tip(s: &Sampled, i: usize, scale: f64) -> Point {
    let c = &s.comb[i];
    c.point + c.normal * (scale * c.curvature)
}

/// The largest |κ| over the samples a comb draws (envelope vertices), or 0.
pub(crate) fn max_drawn_curvature(s: &Sampled) -> f64 {
    s.by_arc_length(MAX_VERTICES)
        .into_iter()
        .map(|i| s.comb[i].curvature.abs())
        .filter(|k| k.is_finite())
        .fold(0.0, f64::max)
}

/// The curve with its curvature comb, data points and inflections; with two series, the
/// displacement of every point as a segment from old to new.
pub(crate) fn comb(svg: &mut Svg, outer: Rect, series: &[&Sampled], scale: f64, title: &str) {
    let env: Vec<Vec<usize>> = series
        .iter()
        .map(|s| s.by_arc_length(MAX_VERTICES))
        .collect();
    let (xr, yr) = Range::of_pairs(series.iter().zip(&env).flat_map(|(s, idx)| {
        let b = s.seq.bbox();
        idx.iter()
            .flat_map(|&i| [s.comb[i].point, tip(s, i, scale)])
            .chain([b.min, b.max])
            .map(|p| (p.x, p.y))
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
            count_label(&format!("{} points", NAME[k]), n.min(MAX_DOTS), n),
        ));
        legend.push(LegendItem::new(
            Swatch::Marker(INFLECTION[k]),
            count_label(
                &format!("{} inflections", NAME[k]),
                s.inflections.len(),
                s.inflection_count,
            ),
        ));
    }
    legend.push(LegendItem::new(
        Swatch::Line(ENVELOPE[0]),
        format!("comb: tooth = {} × κ", sig3(scale)),
    ));
    if series.len() > 1 {
        legend.push(LegendItem::new(
            Swatch::Line("bt-disp"),
            "displacement (old → new)",
        ));
    }
    panel(
        svg,
        outer,
        title,
        ("x", "y"),
        &legend,
        |area| Frame::equal_aspect(area, xr.padded(COMB_PAD), yr.padded(COMB_PAD)),
        |svg, f| {
            for (k, (s, idx)) in series.iter().zip(&env).enumerate() {
                let mut teeth = PathData::new();
                if scale > 0.0 {
                    for i in s.by_arc_length(MAX_TEETH) {
                        let (p, q) = (s.comb[i].point, tip(s, i, scale));
                        teeth.segment(f.map(p.x, p.y), f.map(q.x, q.y));
                    }
                }
                svg.path(&teeth, TEETH[k], &format!("{} comb teeth", NAME[k]));
                let mut envelope = PathData::new();
                let mut curve = PathData::new();
                for &i in idx {
                    let (p, q) = (s.comb[i].point, tip(s, i, scale));
                    let (x, y) = f.map(q.x, q.y);
                    envelope.line_to(x, y);
                    let (x, y) = f.map(p.x, p.y);
                    curve.line_to(x, y);
                }
                if scale > 0.0 {
                    svg.path(
                        &envelope,
                        ENVELOPE[k],
                        &format!("{} comb envelope", NAME[k]),
                    );
                }
                svg.path(&curve, CURVE[k], &format!("{} curve", NAME[k]));
            }
            if let [a, b] = series {
                let (pa, pb) = (a.seq.points(), b.seq.points());
                let mut d = PathData::new();
                for i in stride_indices(pa.len().min(pb.len()), MAX_DOTS) {
                    let (p, q) = (pa[i], pb[i]);
                    d.segment(f.map(p.x, p.y), f.map(q.x, q.y));
                    if p == q {
                        let (x, y) = f.map(p.x, p.y);
                        d.dot(x, y);
                    }
                }
                svg.path(&d, "bt-disp", "displacement");
            }
            for (k, s) in series.iter().enumerate() {
                let pts = s.seq.points();
                let shown = stride_indices(pts.len(), MAX_DOTS);
                let mut dots = PathData::new();
                for &i in &shown {
                    let (x, y) = f.map(pts[i].x, pts[i].y);
                    dots.dot(x, y);
                }
                // Dots no wider than a fraction of their spacing along the curve, so that
                // dense points do not merge into a band hiding the curve.
                let spacing = s.length * f.area.w / f.x.span() / shown.len().max(1) as f64;
                let width = (DOT_SPACING_FRACTION * spacing).clamp(DOT_MIN, DOT_MAX);
                svg.path_with_width(&dots, DOTS[k], &format!("{} points", NAME[k]), width);
            }
            for (k, s) in series.iter().enumerate() {
                for (p, _) in &s.inflections {
                    let (x, y) = f.map(p.x, p.y);
                    svg.circle(x, y, MARKER_R, INFLECTION[k]);
                }
            }
        },
    );
}

/// Inflection markers of every series on the zero line of a graph against arc length.
fn zero_line_markers(svg: &mut Svg, f: &Frame, series: &[&Sampled], y: f64) {
    for (k, s) in series.iter().enumerate() {
        for &(_, at) in &s.inflections {
            let (x, y) = f.map(at, y);
            svg.circle(x, y, GRAPH_MARKER_R, INFLECTION[k]);
        }
    }
}

/// A dashed horizontal line across the frame at data `y`.
fn hline(svg: &mut Svg, f: &Frame, y: f64, class: &str, name: &str) {
    let mut d = PathData::new();
    d.segment((f.area.x, f.py(y)), (f.area.x + f.area.w, f.py(y)));
    svg.path(&d, class, name);
}

/// Signed curvature against arc length.
pub(crate) fn curvature(svg: &mut Svg, outer: Rect, series: &[&Sampled], title: &str) {
    let idx: Vec<Vec<usize>> = series.iter().map(|s| s.graph_indices()).collect();
    let sr = series
        .iter()
        .map(|s| Range {
            lo: 0.0,
            hi: s.length,
        })
        .fold(Range { lo: 0.0, hi: 0.0 }, Range::union);
    let kr = series
        .iter()
        .zip(&idx)
        .filter_map(|(s, idx)| Range::of(idx.iter().map(|&i| s.comb[i].curvature)))
        .fold(Range { lo: 0.0, hi: 0.0 }, Range::union);
    let mut legend = Vec::new();
    for (k, s) in series.iter().enumerate() {
        legend.push(LegendItem::new(
            Swatch::Line(CURVE[k]),
            format!("{} κ(s)", NAME[k]),
        ));
        legend.push(LegendItem::new(
            Swatch::Marker(INFLECTION[k]),
            count_label(
                &format!("{} inflections", NAME[k]),
                s.inflections.len(),
                s.inflection_count,
            ),
        ));
    }
    panel(
        svg,
        outer,
        title,
        ("arc length s", "curvature κ"),
        &legend,
        |area| Frame::new(area, sr.padded(0.0), kr.padded(GRAPH_PAD)),
        |svg, f| {
            hline(svg, f, 0.0, "bt-zero", "κ = 0");
            for (k, (s, idx)) in series.iter().zip(&idx).enumerate() {
                let mut d = PathData::new();
                for &i in idx {
                    let (x, y) = f.map(s.s[i], s.comb[i].curvature);
                    d.line_to(x, y);
                }
                svg.path(&d, CURVE[k], &format!("{} curvature", NAME[k]));
            }
            zero_line_markers(svg, f, series, 0.0);
        },
    );
}

/// A polyline that is solid where `|ρ| ≤ ρ_max` and dashed, at ±ρ_max, where it is capped.
#[derive(Debug, Default)]
struct CappedPolyline {
    solid: PathData,
    capped: PathData,
    /// The last vertex added to each path, to continue it rather than start anew.
    last_solid: Option<(f64, f64)>,
    last_capped: Option<(f64, f64)>,
}

impl CappedPolyline {
    fn add(path: &mut PathData, last: &mut Option<(f64, f64)>, a: (f64, f64), b: (f64, f64)) {
        if *last != Some(a) {
            path.move_to(a.0, a.1);
        }
        path.line_to(b.0, b.1);
        *last = Some(b);
    }

    fn solid(&mut self, a: (f64, f64), b: (f64, f64)) {
        Self::add(&mut self.solid, &mut self.last_solid, a, b);
    }

    fn capped(&mut self, a: (f64, f64), b: (f64, f64)) {
        Self::add(&mut self.capped, &mut self.last_capped, a, b);
    }
}

/// ρ = 1/κ capped at ±ρ_max: the drawn value and whether it is capped.
fn capped_rho(kappa: f64, rho_max: f64) -> (f64, bool) {
    let limit = 1.0 / rho_max;
    if kappa.abs() > limit {
        (1.0 / kappa, false)
    } else if kappa < 0.0 {
        (-rho_max, true)
    } else {
        (rho_max, true)
    }
}

/// Radius of curvature against arc length, capped at ±`rho_max` where the curve is (nearly)
/// straight; capped parts dashed, the limits drawn.
pub(crate) fn radius(svg: &mut Svg, outer: Rect, series: &[&Sampled], rho_max: f64, title: &str) {
    let idx: Vec<Vec<usize>> = series.iter().map(|s| s.graph_indices()).collect();
    let sr = series
        .iter()
        .map(|s| Range {
            lo: 0.0,
            hi: s.length,
        })
        .fold(Range { lo: 0.0, hi: 0.0 }, Range::union);
    let mut any_capped = false;
    let mut rr: Option<Range> = None;
    for (s, idx) in series.iter().zip(&idx) {
        for &i in idx {
            let k = s.comb[i].curvature;
            if !k.is_finite() {
                continue;
            }
            let (r, capped) = capped_rho(k, rho_max);
            any_capped |= capped;
            rr = Some(rr.map_or(Range { lo: r, hi: r }, |x| x.including(r)));
        }
    }
    let rr = rr.unwrap_or(Range {
        lo: -rho_max,
        hi: rho_max,
    });
    let mut legend = Vec::new();
    for k in 0..series.len() {
        legend.push(LegendItem::new(
            Swatch::Line(CURVE[k]),
            format!("{} ρ(s)", NAME[k]),
        ));
        legend.push(LegendItem::new(
            Swatch::Line(CAPPED[k]),
            format!("{} capped at ±ρmax", NAME[k]),
        ));
    }
    legend.push(LegendItem::new(
        Swatch::Line("bt-limit"),
        format!("ρmax = {}", sig3(rho_max)),
    ));
    panel(
        svg,
        outer,
        title,
        ("arc length s", "radius of curvature ρ"),
        &legend,
        |area| Frame::new(area, sr.padded(0.0), rr.padded(GRAPH_PAD)),
        |svg, f| {
            if any_capped {
                for (y, name) in [(rho_max, "+ρmax"), (-rho_max, "−ρmax")] {
                    if y >= rr.lo && y <= rr.hi {
                        hline(svg, f, y, "bt-limit", name);
                        svg.text(
                            f.area.x + f.area.w - 4.0,
                            f.py(y) - 4.0,
                            "bt-note",
                            "end",
                            name,
                        );
                    }
                }
            }
            for (k, (s, idx)) in series.iter().zip(&idx).enumerate() {
                let mut line = CappedPolyline::default();
                let finite: Vec<usize> = idx
                    .iter()
                    .copied()
                    .filter(|&i| s.comb[i].curvature.is_finite())
                    .collect();
                for w in finite.windows(2) {
                    let (i, j) = (w[0], w[1]);
                    let (ka, kb) = (s.comb[i].curvature, s.comb[j].curvature);
                    let (ra, ca) = capped_rho(ka, rho_max);
                    let (rb, cb) = capped_rho(kb, rho_max);
                    let a = f.map(s.s[i], ra);
                    let b = f.map(s.s[j], rb);
                    match (ca, cb) {
                        (false, false) => line.solid(a, b),
                        (true, true) => line.capped(a, b),
                        _ => {
                            // Where |κ| passes 1/ρ_max, κ taken linear between the samples.
                            let (k_free, k_cap) = if ca { (kb, ka) } else { (ka, kb) };
                            let target = k_free.signum() / rho_max;
                            let frac = ((target - k_free) / (k_cap - k_free)).clamp(0.0, 1.0);
                            let (s_free, s_cap) = if ca {
                                (s.s[j], s.s[i])
                            } else {
                                (s.s[i], s.s[j])
                            };
                            let c =
                                f.map(s_free + frac * (s_cap - s_free), k_free.signum() * rho_max);
                            if ca {
                                line.capped(a, c);
                                line.solid(c, b);
                            } else {
                                line.solid(a, c);
                                line.capped(c, b);
                            }
                        }
                    }
                }
                svg.path(
                    &line.capped,
                    CAPPED[k],
                    &format!("{} radius capped", NAME[k]),
                );
                svg.path(&line.solid, CURVE[k], &format!("{} radius", NAME[k]));
            }
        },
    );
}

/// HAN's x–c plot: the polyline `(x_i, c_i)`, `c_i = y''(x_i)/6`, one per series.
pub(crate) fn xc(
    svg: &mut Svg,
    outer: Rect,
    series: &[(usize, &XcData)],
    chord_frame: bool,
    title: &str,
) {
    let idx: Vec<Vec<usize>> = series
        .iter()
        .map(|(_, d)| min_max_indices(&d.x, &d.c, MAX_VERTICES / 2))
        .collect();
    let xr = series
        .iter()
        .filter_map(|(_, d)| Range::of(d.x.iter().copied()))
        .fold(None, |a: Option<Range>, r| {
            Some(a.map_or(r, |a| a.union(r)))
        })
        .unwrap_or(Range { lo: 0.0, hi: 1.0 });
    let cr = series
        .iter()
        .zip(&idx)
        .filter_map(|((_, d), idx)| Range::of(idx.iter().map(|&i| d.c[i])))
        .fold(Range { lo: 0.0, hi: 0.0 }, Range::union);
    let mut legend = Vec::new();
    for &(k, d) in series {
        legend.push(LegendItem::new(
            Swatch::Line(CURVE[k]),
            format!("{} c_i", NAME[k]),
        ));
        if d.x.len() <= MAX_DOTS {
            legend.push(LegendItem::new(
                Swatch::Dot(DOTS[k]),
                format!("{} (x_i, c_i)", NAME[k]),
            ));
        }
    }
    let xlabel = if chord_frame {
        "x in the chord frame (first point → last point)"
    } else {
        "x"
    };
    panel(
        svg,
        outer,
        title,
        (xlabel, "c = y″/6"),
        &legend,
        |area| Frame::new(area, xr.padded(0.0), cr.padded(GRAPH_PAD)),
        |svg, f| {
            hline(svg, f, 0.0, "bt-zero", "c = 0");
            for ((k, d), idx) in series.iter().zip(&idx) {
                let mut line = PathData::new();
                for &i in idx {
                    let (x, y) = f.map(d.x[i], d.c[i]);
                    line.line_to(x, y);
                }
                svg.path(&line, CURVE[*k], &format!("{} x–c", NAME[*k]));
                if d.x.len() <= MAX_DOTS {
                    let mut dots = PathData::new();
                    for (&x, &c) in d.x.iter().zip(&d.c) {
                        let (x, y) = f.map(x, c);
                        dots.dot(x, y);
                    }
                    svg.path(&dots, DOTS[*k], &format!("{} x–c points", NAME[*k]));
                }
            }
        },
    );
}

/// The distance each point moved, against its index: a bar per point, or the largest
/// and smallest per bin when there are more than [`MAX_TEETH`] points.
pub(crate) fn displacement(
    svg: &mut Svg,
    outer: Rect,
    before: &[Point],
    after: &[Point],
    title: &str,
) {
    let d: Vec<f64> = before
        .iter()
        .zip(after)
        .map(|(p, q)| p.distance(*q))
        .collect();
    let (argmax, max) = d
        .iter()
        .copied()
        .enumerate()
        .fold((0, 0.0_f64), |a, (i, v)| if v > a.1 { (i, v) } else { a });
    let n = d.len();
    let xr = Range {
        lo: 0.0,
        hi: n.saturating_sub(1) as f64,
    };
    let yr = Range { lo: 0.0, hi: max };
    let legend = vec![LegendItem::new(
        Swatch::Line("bt-bar"),
        if max > 0.0 {
            format!("|moved| per point; largest {} at point {argmax}", sig3(max))
        } else {
            "|moved| per point: no point moved".to_string()
        },
    )];
    panel(
        svg,
        outer,
        title,
        ("point index", "displacement"),
        &legend,
        |area| {
            let y = if max > 0.0 {
                Range {
                    lo: 0.0,
                    hi: max * (1.0 + GRAPH_PAD),
                }
            } else {
                Range { lo: 0.0, hi: 1.0 }
            };
            Frame::new(area, xr.padded(0.02), y.including(yr.hi))
        },
        |svg, f| {
            let mut p = PathData::new();
            if n <= MAX_TEETH {
                for (i, &v) in d.iter().enumerate() {
                    p.segment(f.map(i as f64, 0.0), f.map(i as f64, v));
                }
            } else {
                let x: Vec<f64> = (0..n).map(|i| i as f64).collect();
                for i in min_max_indices(&x, &d, MAX_VERTICES / 2) {
                    let (x, y) = f.map(i as f64, d[i]);
                    p.line_to(x, y);
                }
            }
            svg.path(&p, "bt-bar", "displacement");
        },
    );
}
