//! SVG (`.svg`): curves from `<path>`, `<polyline>` and `<polygon>`, and the faired curve
//! written back as a path of Bézier segments.
//!
//! Reading. The XML is parsed by `roxmltree`; the path data by [`path_data`]. Which element:
//! the one whose `id` is [`Pick::id`], else the only curve element of the file (several are
//! an error that lists them). What it gives:
//! - a polyline, a polygon (closed) or a path of straight segments only: its vertices as
//!   points (`Z` closes the curve; a last vertex equal to the first is left out);
//! - a path with Bézier segments: a cubic B-spline with one knot interval of length 1 per
//!   segment and every interior knot of multiplicity 3, so its control points are the
//!   Bézier points (quadratics and straight segments are degree-elevated exactly);
//! - with [`Pick::sample`] = N, any path as points: N per segment at t = i/N, plus the end
//!   point of an open path.
//!
//! Coordinates are taken as written: SVG's y axis points down, and batten does not flip it,
//! so a curve written back lands where it was read. Elements under a `transform` attribute
//! are refused (the coordinates would not be where the drawing shows them), as are arcs and
//! paths with more than one subpath.
//!
//! Writing. A non-rational B-spline of degree 1 to 3 with clamped ends is cut into its Bézier
//! segments (every interior knot inserted up to multiplicity p) and written as one `<path>`:
//! `M`, then `L`, `Q` or `C` per span, `Z` for a closed curve. Numbers are written in the
//! shortest form that reads back bit for bit, so a curve read from batten's own SVG has the
//! same control points.

mod path_data;

use std::fmt::Write as _;
use std::path::Path;

use roxmltree::{Document, Node};

use super::error::one_line;
use super::{IoError, Location, Origin, Pick, Raw, format_f64};
use crate::geom::{BBox, Point};
use crate::spline::{BSplineCurve, KnotVector};
use path_data::{Seg, Subpath};

/// Elements that hold a curve.
const CURVE_ELEMENTS: [&str; 3] = ["path", "polyline", "polygon"];

/// Margin around the curve in a written SVG, as a fraction of its larger extent.
const VIEW_MARGIN: f64 = 0.05;

/// Stroke width of a written SVG, as a fraction of the larger extent of its view box.
const STROKE_FRACTION: f64 = 0.002;

fn format_err(path: &Path, at: Location, message: impl Into<String>) -> IoError {
    IoError::Format {
        path: path.to_path_buf(),
        at,
        message: message.into(),
    }
}

/// A short description of an element for messages: `path#hull (line 4)`.
fn describe(doc: &Document<'_>, n: Node<'_, '_>) -> String {
    let line = doc.text_pos_at(n.range().start).row;
    match n.attribute("id") {
        Some(id) => format!("{}#{id} (line {line})", n.tag_name().name()),
        None => format!("{} (line {line})", n.tag_name().name()),
    }
}

/// Read the curve of an SVG file.
pub(crate) fn parse(bytes: &[u8], path: &Path, pick: &Pick) -> Result<(Raw, Origin), IoError> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let line = 1 + bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        IoError::NotUtf8 {
            path: path.to_path_buf(),
            line,
        }
    })?;
    let doc = Document::parse(text).map_err(|e| {
        let p = e.pos();
        format_err(
            path,
            Location::LineColumn(p.row as usize, p.col as usize),
            format!("malformed XML: {}", one_line(&e.to_string())),
        )
    })?;
    let root = doc.root_element();
    if root.tag_name().name() != "svg" {
        return Err(format_err(
            path,
            Location::Line(doc.text_pos_at(root.range().start).row as usize),
            format!(
                "the root element is <{}>, not <svg>",
                root.tag_name().name()
            ),
        ));
    }
    let node = choose(&doc, root, pick, path)?;
    if let Some(t) = node
        .ancestors()
        .find(|a| a.is_element() && a.attribute("transform").is_some())
    {
        return Err(format_err(
            path,
            Location::Line(line_of(&doc, t)),
            format!(
                "{} has a transform attribute, which batten does not apply; flatten the transform in your editor",
                describe(&doc, t)
            ),
        ));
    }
    let origin = Origin {
        z: 0.0,
        layer: None,
        name: node.attribute("id").map(str::to_string),
    };
    let raw = match node.tag_name().name() {
        "path" => from_path(&doc, node, path, pick)?,
        name => from_points_attribute(&doc, node, path, name == "polygon")?,
    };
    Ok((raw, origin))
}

/// The curve element `pick` names, or the only one there is.
fn choose<'a, 'input>(
    doc: &Document<'input>,
    root: Node<'a, 'input>,
    pick: &Pick,
    path: &Path,
) -> Result<Node<'a, 'input>, IoError> {
    let candidates: Vec<Node<'_, '_>> = root
        .descendants()
        .filter(|n| n.is_element() && CURVE_ELEMENTS.contains(&n.tag_name().name()))
        .collect();
    Ok(match &pick.id {
        Some(id) => {
            let Some(n) = root
                .descendants()
                .find(|n| n.is_element() && n.attribute("id") == Some(id.as_str()))
            else {
                let ids: Vec<&str> = candidates
                    .iter()
                    .filter_map(|n| n.attribute("id"))
                    .collect();
                return Err(format_err(
                    path,
                    Location::File,
                    format!(
                        "no element with id '{id}' (curve elements with an id: {})",
                        if ids.is_empty() {
                            "none".to_string()
                        } else {
                            ids.join(", ")
                        }
                    ),
                ));
            };
            if !CURVE_ELEMENTS.contains(&n.tag_name().name()) {
                return Err(format_err(
                    path,
                    Location::Line(line_of(doc, n)),
                    format!(
                        "element '{id}' is a <{}>, not a <path>, <polyline> or <polygon>",
                        n.tag_name().name()
                    ),
                ));
            }
            n
        }
        None => match candidates.as_slice() {
            [] => {
                return Err(format_err(
                    path,
                    Location::File,
                    "no <path>, <polyline> or <polygon> element",
                ));
            }
            [n] => *n,
            many => {
                let list: Vec<String> = many.iter().map(|n| describe(doc, *n)).collect();
                return Err(format_err(
                    path,
                    Location::File,
                    format!(
                        "{} curve elements, pick one with --select ID: {}",
                        many.len(),
                        list.join(", ")
                    ),
                ));
            }
        },
    })
}

fn line_of(doc: &Document<'_>, n: Node<'_, '_>) -> usize {
    doc.text_pos_at(n.range().start).row as usize
}

/// The `d` of a `<path>`.
fn from_path(
    doc: &Document<'_>,
    n: Node<'_, '_>,
    path: &Path,
    pick: &Pick,
) -> Result<Raw, IoError> {
    let Some(attr) = n.attributes().find(|a| a.name() == "d") else {
        return Err(format_err(
            path,
            Location::Line(line_of(doc, n)),
            format!("{} has no d attribute", describe(doc, n)),
        ));
    };
    let d = attr.value();
    let value_start = attr.range_value().start;
    // The position of an offset into the value (exact unless the value has entity
    // references before it).
    let pos = |at: usize| {
        let p = doc.text_pos_at(value_start + at);
        (p.row as usize, p.col as usize)
    };
    let subpaths = path_data::parse(d).map_err(|e| {
        let (l, c) = pos(e.at);
        format_err(
            path,
            Location::LineColumn(l, c),
            format!("path data: {}", e.message),
        )
    })?;
    let sp: Subpath = match <[Subpath; 1]>::try_from(subpaths) {
        Ok([sp]) => sp,
        Err(v) => {
            let (l, c) = pos(v[1].at);
            return Err(format_err(
                path,
                Location::LineColumn(l, c),
                format!(
                    "{} has {} subpaths; batten fairs one curve: split the path",
                    describe(doc, n),
                    v.len()
                ),
            ));
        }
    };
    if sp.segs.is_empty() {
        let (l, c) = pos(sp.at);
        return Err(format_err(
            path,
            Location::LineColumn(l, c),
            format!("{} has no segments", describe(doc, n)),
        ));
    }
    let all_lines = sp.segs.iter().all(|s| matches!(s, Seg::Line { .. }));
    if let Some(per) = pick.sample {
        return Ok(sampled(&sp, per, &pos));
    }
    if all_lines {
        return Ok(corners(sp, &pos));
    }
    let curve = bezier_spline(&sp).map_err(|e| {
        format_err(
            path,
            Location::Line(line_of(doc, n)),
            format!("{}: {e}", describe(doc, n)),
        )
    })?;
    Ok(Raw::Curve(curve))
}

/// `--sample`: `per` points along each segment (and the end of an open path).
fn sampled(sp: &Subpath, per: usize, pos: &dyn Fn(usize) -> (usize, usize)) -> Raw {
    let per = per.max(1);
    let mut points = Vec::with_capacity(sp.segs.len() * per + 1);
    let mut lines = Vec::with_capacity(points.capacity());
    for s in &sp.segs {
        let line = pos(s.at()).0;
        for i in 0..per {
            // i and per are small counts: exact in f64.
            points.push(s.eval(i as f64 / per as f64));
            lines.push(line);
        }
    }
    if !sp.closed
        && let Some(last) = sp.segs.last()
    {
        points.push(last.end());
        lines.push(pos(last.at()).0);
    }
    Raw::Points {
        points,
        lines,
        closed: sp.closed,
    }
}

/// A path of lines: its corner points (a closed path's repeated start left out).
fn corners(sp: Subpath, pos: &dyn Fn(usize) -> (usize, usize)) -> Raw {
    let mut points = vec![sp.start];
    let mut lines = vec![pos(sp.at).0];
    for s in &sp.segs {
        points.push(s.end());
        lines.push(pos(s.at()).0);
    }
    if sp.closed && points.len() > 1 && points.last() == points.first() {
        points.pop();
        lines.pop();
    }
    Raw::Points {
        points,
        lines,
        closed: sp.closed,
    }
}

/// A path with curves: the cubic B-spline of its segments as Béziers (integer knots, each
/// interior one triple).
fn bezier_spline(sp: &Subpath) -> crate::Result<BSplineCurve> {
    let m = sp.segs.len();
    let mut ctrl = Vec::with_capacity(3 * m + 1);
    ctrl.push(sp.start);
    for s in &sp.segs {
        let b = s.to_cubic();
        ctrl.extend_from_slice(&b[1..]);
    }
    let mut knots = vec![0.0; 4];
    for i in 1..m {
        // Segment counts are far below 2^53: exact.
        knots.extend([i as f64; 3]);
    }
    knots.extend([m as f64; 4]);
    KnotVector::try_new(knots).and_then(|k| BSplineCurve::try_new(3, k, ctrl, None))
}

/// The `points` of a `<polyline>` or `<polygon>`.
fn from_points_attribute(
    doc: &Document<'_>,
    n: Node<'_, '_>,
    path: &Path,
    closed: bool,
) -> Result<Raw, IoError> {
    let line = line_of(doc, n);
    let Some(text) = n.attribute("points") else {
        return Err(format_err(
            path,
            Location::Line(line),
            format!("{} has no points attribute", describe(doc, n)),
        ));
    };
    let mut values = Vec::new();
    for (i, field) in text
        .split(|c: char| c == ',' || c.is_ascii_whitespace())
        .filter(|f| !f.is_empty())
        .enumerate()
    {
        match field.parse::<f64>() {
            Ok(v) if v.is_finite() => values.push(v),
            _ => {
                return Err(format_err(
                    path,
                    Location::Line(line),
                    format!(
                        "{}: number {} of points, '{}', is not a finite number",
                        describe(doc, n),
                        i + 1,
                        field.escape_debug()
                    ),
                ));
            }
        }
    }
    if values.len() % 2 == 1 {
        return Err(format_err(
            path,
            Location::Line(line),
            format!(
                "{}: points has an odd count of numbers ({})",
                describe(doc, n),
                values.len()
            ),
        ));
    }
    let mut points: Vec<Point> = values
        .chunks_exact(2)
        .map(|c| Point::new(c[0], c[1]))
        .collect();
    if closed && points.len() > 1 && points.last() == points.first() {
        points.pop();
    }
    let lines = vec![line; points.len()];
    Ok(Raw::Points {
        points,
        lines,
        closed,
    })
}

/// The Bézier segments of a non-rational clamped B-spline of degree 1–3, each as its
/// `degree + 1` control points.
///
/// # Errors
/// A message saying why the curve cannot be a path.
pub(crate) fn bezier_segments(curve: &BSplineCurve) -> Result<Vec<Vec<Point>>, String> {
    let p = curve.degree();
    if p > 3 {
        return Err(format!(
            "an SVG path holds Bézier segments of degree 3 at most; this curve has degree {p}"
        ));
    }
    if curve
        .weights()
        .is_some_and(|w| w.iter().any(|&x| x != w[0]))
    {
        return Err("an SVG path cannot hold a rational curve (weights)".into());
    }
    let u = curve.knots().as_slice();
    let n = curve.control_points().len();
    let clamped = u[..=p].iter().all(|&k| k == u[0]) && u[n..].iter().all(|&k| k == u[n + p]);
    if !clamped {
        return Err(
            "an SVG path needs a B-spline with clamped ends (end knots of multiplicity degree + 1)"
                .into(),
        );
    }
    let mut c = curve.clone();
    let mut interior: Vec<f64> = u[p + 1..n].to_vec();
    interior.dedup();
    for k in interior {
        let s = c.knots().multiplicity(k);
        if s < p {
            c = c.insert_knot(k, p - s).map_err(|e| e.to_string())?;
        }
    }
    let pts = c.control_points();
    // Equal weights are a scale of the non-rational curve: the control points are the same.
    Ok(pts
        .windows(p + 1)
        .step_by(p)
        .map(<[Point]>::to_vec)
        .collect())
}

/// An SVG document with the curve as one `<path>`.
pub(crate) fn format_curve(
    curve: &BSplineCurve,
    closed: bool,
    origin: &Origin,
    path: &Path,
) -> Result<String, IoError> {
    let segs = bezier_segments(curve)
        .map_err(|m| format_err(path, Location::File, format!("cannot write the curve: {m}")))?;
    let mut d = String::new();
    let num = |d: &mut String, p: Point| {
        let _ = write!(d, " {} {}", format_f64(p.x), format_f64(p.y));
    };
    if let Some(first) = segs.first().and_then(|s| s.first()) {
        d.push('M');
        num(&mut d, *first);
    }
    for s in &segs {
        d.push_str(match s.len() {
            2 => " L",
            3 => " Q",
            _ => " C",
        });
        for &q in &s[1..] {
            num(&mut d, q);
        }
    }
    if closed {
        d.push_str(" Z");
    }
    let bbox = BBox::from_points(curve.control_points()).unwrap_or(BBox {
        min: Point::new(0.0, 0.0),
        max: Point::new(0.0, 0.0),
    });
    let extent = bbox.width().max(bbox.height());
    let extent = if extent > 0.0 { extent } else { 1.0 };
    let margin = VIEW_MARGIN * extent;
    let (x0, y0) = (bbox.min.x - margin, bbox.min.y - margin);
    let (w, h) = (bbox.width() + 2.0 * margin, bbox.height() + 2.0 * margin);
    let id = origin.name.as_deref().unwrap_or("faired");
    let mut out = String::new();
    out.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"{} {} {} {}\">",
        format_f64(x0),
        format_f64(y0),
        format_f64(w),
        format_f64(h)
    );
    let _ = writeln!(
        out,
        "  <path id=\"{}\" fill=\"none\" stroke=\"black\" stroke-width=\"{}\" d=\"{}\"/>",
        escape_attr(id),
        format_f64(STROKE_FRACTION * w.max(h)),
        d.trim_start()
    );
    out.push_str("</svg>\n");
    Ok(out)
}

fn escape_attr(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn read(svg: &str, pick: &Pick) -> Result<(Raw, Origin), String> {
        parse(svg.as_bytes(), Path::new("g.svg"), pick).map_err(|e| e.to_string())
    }

    fn wrap(body: &str) -> String {
        format!("<svg xmlns=\"http://www.w3.org/2000/svg\">\n{body}\n</svg>")
    }

    #[test]
    fn polyline_polygon_and_line_paths_give_points() {
        let (r, _) = read(
            &wrap("<polyline points=\"0,0 1,0 1,1 2 1\"/>"),
            &Pick::default(),
        )
        .unwrap();
        let Raw::Points {
            points,
            closed,
            lines,
        } = r
        else {
            panic!()
        };
        assert_eq!(points.len(), 4);
        assert!(!closed);
        assert_eq!(lines, vec![2; 4]);
        let (r, _) = read(
            &wrap("<polygon points=\"0,0 1,0 1,1 0,1 0,0\"/>"),
            &Pick::default(),
        )
        .unwrap();
        let Raw::Points { points, closed, .. } = r else {
            panic!()
        };
        assert_eq!(points.len(), 4);
        assert!(closed);
        let (r, o) = read(
            &wrap("<path id=\"p\" d=\"M0 0 H2 V2\nH0 Z\"/>"),
            &Pick::default(),
        )
        .unwrap();
        let Raw::Points {
            points,
            closed,
            lines,
        } = r
        else {
            panic!()
        };
        assert_eq!(
            points,
            vec![
                Point::new(0.0, 0.0),
                Point::new(2.0, 0.0),
                Point::new(2.0, 2.0),
                Point::new(0.0, 2.0)
            ]
        );
        assert!(closed);
        assert_eq!(lines, vec![2, 2, 2, 3]);
        assert_eq!(o.name.as_deref(), Some("p"));
    }

    #[test]
    fn beziers_give_a_cubic_bspline_through_the_segment_ends() {
        let (r, _) = read(
            &wrap("<path d=\"M0 0 C1 1 2 1 3 0 Q4 -1 5 0 L6 0\"/>"),
            &Pick::default(),
        )
        .unwrap();
        let Raw::Curve(c) = r else { panic!() };
        assert_eq!(c.degree(), 3);
        assert_eq!(
            c.knots().as_slice(),
            &[0., 0., 0., 0., 1., 1., 1., 2., 2., 2., 3., 3., 3., 3.]
        );
        assert_eq!(c.control_points().len(), 10);
        use crate::curve::Curve as _;
        for (t, want) in [
            (0.0, (0.0, 0.0)),
            (1.0, (3.0, 0.0)),
            (2.0, (5.0, 0.0)),
            (3.0, (6.0, 0.0)),
        ] {
            let p = c.eval(t);
            assert!(p.distance(Point::new(want.0, want.1)) < 1e-14, "{t}: {p:?}");
        }
        // The midpoint of the first segment: the cubic's de Casteljau value.
        assert!(c.eval(0.5).distance(Point::new(1.5, 0.75)) < 1e-14);
    }

    #[test]
    fn sampling_takes_points_per_segment() {
        let pick = Pick {
            sample: Some(4),
            ..Pick::default()
        };
        let (r, _) = read(&wrap("<path d=\"M0 0 C1 1 2 1 3 0 L4 0\"/>"), &pick).unwrap();
        let Raw::Points { points, closed, .. } = r else {
            panic!()
        };
        assert!(!closed);
        assert_eq!(points.len(), 9);
        assert_eq!(points[4], Point::new(3.0, 0.0));
        assert_eq!(points[6], Point::new(3.5, 0.0));
        assert_eq!(points[8], Point::new(4.0, 0.0));
    }

    #[test]
    fn selection_and_its_errors() {
        let svg = wrap(
            "<g><path id=\"a\" d=\"M0 0 L1 1 L2 0 L3 1\"/></g>\n<polyline id=\"b\" points=\"0 0 1 1 2 0 3 3\"/>\n<rect id=\"r\"/>",
        );
        let e = read(&svg, &Pick::default()).unwrap_err();
        assert_eq!(
            e,
            "g.svg: 2 curve elements, pick one with --select ID: path#a (line 2), polyline#b (line 3)"
        );
        let pick = |id: &str| Pick {
            id: Some(id.into()),
            ..Pick::default()
        };
        assert!(matches!(
            read(&svg, &pick("b")).unwrap().0,
            Raw::Points { .. }
        ));
        assert_eq!(
            read(&svg, &pick("x")).unwrap_err(),
            "g.svg: no element with id 'x' (curve elements with an id: a, b)"
        );
        assert_eq!(
            read(&svg, &pick("r")).unwrap_err(),
            "g.svg:4: element 'r' is a <rect>, not a <path>, <polyline> or <polygon>"
        );
        assert_eq!(
            read(&wrap(""), &Pick::default()).unwrap_err(),
            "g.svg: no <path>, <polyline> or <polygon> element"
        );
    }

    #[test]
    fn bad_files_name_the_place() {
        let e = read(
            &wrap("<path d=\"M0 0 L1 1 A 1 1 0 0 1 2 2\"/>"),
            &Pick::default(),
        )
        .unwrap_err();
        assert!(
            e.starts_with("g.svg:2:20: path data: elliptical arcs (A) are not supported"),
            "{e}"
        );
        let e = read(&wrap("<path d=\"M0 0 L1\"/>"), &Pick::default()).unwrap_err();
        assert_eq!(
            e,
            "g.svg:2:17: path data: expected a number (lineto x, y), found the end of the path data"
        );
        let e = read(&wrap("<path d=\"M0 0 L1 1 M2 2 L3 3\"/>"), &Pick::default()).unwrap_err();
        assert_eq!(
            e,
            "g.svg:2:20: path (line 2) has 2 subpaths; batten fairs one curve: split the path"
        );
        let e = read(
            &wrap("<g transform=\"scale(2)\"><path d=\"M0 0 L1 1\"/></g>"),
            &Pick::default(),
        )
        .unwrap_err();
        assert!(
            e.starts_with("g.svg:2: g (line 2) has a transform attribute"),
            "{e}"
        );
        let e = read("<svg><path d=\"M0 0\"></svg>", &Pick::default()).unwrap_err();
        assert!(e.starts_with("g.svg:1:"), "{e}");
        assert!(e.contains("malformed XML"), "{e}");
        let e = read("<html/>", &Pick::default()).unwrap_err();
        assert_eq!(e, "g.svg:1: the root element is <html>, not <svg>");
        let e = read(&wrap("<polyline points=\"0 0 1\"/>"), &Pick::default()).unwrap_err();
        assert_eq!(
            e,
            "g.svg:2: polyline (line 2): points has an odd count of numbers (3)"
        );
        let e = read(&wrap("<polyline points=\"0 0 1 nan\"/>"), &Pick::default()).unwrap_err();
        assert_eq!(
            e,
            "g.svg:2: polyline (line 2): number 4 of points, 'nan', is not a finite number"
        );
    }

    #[test]
    fn written_curve_reads_back_bit_for_bit() {
        let ctrl = vec![
            Point::new(0.1, -1.0 / 3.0),
            Point::new(1e-7, 2.5),
            Point::new(3.0, 1e5 / 7.0),
            Point::new(4.0, 0.0),
            Point::new(5.0, -2.0),
            Point::new(6.0, 1.0),
            Point::new(7.25, 0.5),
        ];
        let knots = KnotVector::try_new(vec![0., 0., 0., 0., 1., 1., 1., 2., 2., 2., 2.]).unwrap();
        let c = BSplineCurve::try_new(3, knots, ctrl.clone(), None).unwrap();
        let svg = format_curve(&c, false, &Origin::default(), Path::new("o.svg")).unwrap();
        let (r, o) = read(&svg, &Pick::default()).unwrap();
        assert_eq!(o.name.as_deref(), Some("faired"));
        let Raw::Curve(back) = r else { panic!() };
        for (a, b) in ctrl.iter().zip(back.control_points()) {
            assert_eq!(
                (a.x.to_bits(), a.y.to_bits()),
                (b.x.to_bits(), b.y.to_bits())
            );
        }
    }

    #[test]
    fn bezier_segments_of_simple_knots_match_the_curve() {
        use crate::curve::Curve as _;
        let knots = KnotVector::clamped_uniform(3, 7).unwrap();
        let ctrl: Vec<Point> = (0..7)
            .map(|i| Point::new(i as f64, ((i * i) % 5) as f64))
            .collect();
        let c = BSplineCurve::try_new(3, knots, ctrl, None).unwrap();
        let segs = bezier_segments(&c).unwrap();
        let (a, b) = c.domain();
        assert_eq!(segs.len(), 4);
        for (i, s) in segs.iter().enumerate() {
            let bez = Seg::Cubic {
                p: [s[0], s[1], s[2], s[3]],
                at: 0,
            };
            for j in 0..=4 {
                let t = f64::from(j) / 4.0;
                let u = a + (b - a) * (i as f64 + t) / 4.0;
                assert!(bez.eval(t).distance(c.eval(u)) < 1e-12);
            }
        }
        let quintic = BSplineCurve::try_new(
            5,
            KnotVector::clamped_uniform(5, 6).unwrap(),
            (0..6).map(|i| Point::new(i as f64, 0.0)).collect(),
            None,
        )
        .unwrap();
        assert!(bezier_segments(&quintic).unwrap_err().contains("degree 5"));
    }
}
