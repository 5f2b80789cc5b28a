//! Point lists and B-spline curves as JSON (`.json`).
//!
//! A point list is `{"points": [[x, y], ...], "closed": false, "tangents": [[dx, dy], ...]}`
//! (a space curve: `[x, y, z]` points, every point alike, no tangents);
//! `closed` (default `false`) and `tangents` (one per point, for Hermite methods) are optional
//! and any other key is an error (a misspelt `"close": true` must not be ignored). A B-spline
//! is the object [`BSplineCurve`] serialises to: `{"degree": p, "knots": [...],
//! "control_points": [[x, y], ...], "weights": [...]}`.
//!
//! serde_json reports where malformed JSON goes wrong but not where each array element
//! starts; [`element_lines`] finds the line of every point so that validation errors name it.

use std::fmt::Write as _;
use std::path::Path;

use serde::Deserialize;

use super::IoError;
use super::text::Coords;
use crate::geom::{Point, Vec2, Xyz};
use crate::spline::{BSplineCurve, KnotVector};

/// Keys that mark a B-spline object.
const CURVE_KEYS: [&str; 3] = ["degree", "knots", "control_points"];

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PointsJson {
    // Not `[f64; 2]`: serde_json calls a third coordinate "trailing characters". The length
    // is checked against the element lines instead.
    points: Vec<Vec<f64>>,
    #[serde(default)]
    closed: bool,
    #[serde(default)]
    tangents: Option<Vec<Vec<f64>>>,
}

/// A B-spline as read, before validation: unknown keys refused, control points of any
/// length so that a 3-D point is named with its line (see [`PointsJson`]).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CurveJson {
    degree: usize,
    knots: Vec<f64>,
    control_points: Vec<Vec<f64>>,
    #[serde(default)]
    weights: Option<Vec<f64>>,
}

/// A parsed JSON point list, not yet validated as a [`crate::PointSeq`].
pub(crate) struct ParsedJson {
    pub coords: Coords,
    pub lines: Vec<usize>,
    pub closed: bool,
    pub tangents: Option<Vec<Vec2>>,
    pub tangent_lines: Vec<usize>,
}

/// What the top-level object looks like.
enum Shape {
    Points,
    Curve,
    /// An object with neither kind of key (serde names the missing key).
    Other,
}

/// Convert a serde_json error into one that names the file, line and column.
pub(super) fn json_error(path: &Path, e: &serde_json::Error) -> IoError {
    let full = e.to_string();
    if e.line() == 0 {
        return IoError::JsonContent {
            path: path.to_path_buf(),
            message: full,
        };
    }
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let bare = full.strip_suffix(&suffix).unwrap_or(&full);
    let message = if e.is_syntax() || e.is_eof() {
        format!("malformed JSON: {bare}")
    } else {
        bare.to_string()
    };
    IoError::Json {
        path: path.to_path_buf(),
        line: e.line(),
        column: e.column(),
        message,
    }
}

/// Parse the text as JSON (for syntax errors with positions) and tell what it holds.
fn shape(text: &str, path: &Path) -> Result<Shape, IoError> {
    let value: serde_json::Value = serde_json::from_str(text).map_err(|e| json_error(path, &e))?;
    let Some(o) = value.as_object() else {
        // serde would read a struct from an array too, with a baffling message.
        return Err(IoError::JsonContent {
            path: path.to_path_buf(),
            message: "expected an object: {\"points\": [[x, y], ...]} or a B-spline \
                      {\"degree\": p, \"knots\": [...], \"control_points\": [...]}"
                .into(),
        });
    };
    Ok(if o.contains_key("points") {
        Shape::Points
    } else if CURVE_KEYS.iter().any(|k| o.contains_key(*k)) {
        Shape::Curve
    } else {
        Shape::Other
    })
}

pub(super) fn utf8<'a>(bytes: &'a [u8], path: &Path) -> Result<&'a str, IoError> {
    std::str::from_utf8(bytes).map_err(|e| IoError::NotUtf8 {
        path: path.to_path_buf(),
        line: 1 + bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count(),
    })
}

/// Parse a JSON point list.
pub(crate) fn parse_points(bytes: &[u8], path: &Path) -> Result<ParsedJson, IoError> {
    let text = utf8(bytes, path)?;
    if let Shape::Curve = shape(text, path)? {
        return Err(IoError::CurveNotPoints {
            path: path.to_path_buf(),
        });
    }
    let raw: PointsJson = serde_json::from_str(text).map_err(|e| json_error(path, &e))?;
    let lines = lines_or_first(element_lines(text, "points"), raw.points.len());
    let space = raw.points.first().is_some_and(|p| p.len() == 3);
    let coords = if space {
        Coords::Space(triples(raw.points, &lines, path)?)
    } else {
        Coords::Planar(
            pairs(raw.points, &lines, path)?
                .into_iter()
                .map(|(x, y)| Point::new(x, y))
                .collect(),
        )
    };
    if space && raw.tangents.is_some() {
        return Err(IoError::JsonContent {
            path: path.to_path_buf(),
            message: "tangents are taken with planar points only, not with [x, y, z] points".into(),
        });
    }
    let (tangents, tangent_lines) = match raw.tangents {
        Some(t) => {
            let tl = lines_or_first(element_lines(text, "tangents"), t.len());
            let v = pairs(t, &tl, path)?
                .into_iter()
                .map(|(x, y)| Vec2::new(x, y))
                .collect();
            (Some(v), tl)
        }
        None => (None, Vec::new()),
    };
    Ok(ParsedJson {
        coords,
        lines,
        closed: raw.closed,
        tangents,
        tangent_lines,
    })
}

/// Check that every element has two coordinates.
fn pairs(raw: Vec<Vec<f64>>, lines: &[usize], path: &Path) -> Result<Vec<(f64, f64)>, IoError> {
    raw.into_iter()
        .zip(lines)
        .map(|(v, &line)| match v[..] {
            [x, y] => Ok((x, y)),
            _ => Err(IoError::FieldCount {
                path: path.to_path_buf(),
                line,
                found: v.len(),
                expected: "2 fields (x, y)",
            }),
        })
        .collect()
}

/// Check that every element has three coordinates (a space curve: the first point had three).
fn triples(raw: Vec<Vec<f64>>, lines: &[usize], path: &Path) -> Result<Vec<Xyz>, IoError> {
    raw.into_iter()
        .zip(lines)
        .map(|(v, &line)| match v[..] {
            [x, y, z] => Ok([x, y, z]),
            _ => Err(IoError::FieldCount {
                path: path.to_path_buf(),
                line,
                found: v.len(),
                expected: "3 fields (x, y, z), as the first point",
            }),
        })
        .collect()
}

/// The element lines if the scan found one per element; otherwise line 1 for all. The scan
/// runs on text serde_json has just accepted, so the fallback is not expected to happen.
fn lines_or_first(found: Option<Vec<usize>>, n: usize) -> Vec<usize> {
    match found {
        Some(l) if l.len() == n => l,
        _ => vec![1; n],
    }
}

/// Parse a JSON B-spline curve.
pub(crate) fn parse_curve(bytes: &[u8], path: &Path) -> Result<BSplineCurve, IoError> {
    let text = utf8(bytes, path)?;
    if let Shape::Points = shape(text, path)? {
        return Err(IoError::PointsNotCurve {
            path: path.to_path_buf(),
        });
    }
    let raw: CurveJson = serde_json::from_str(text).map_err(|e| json_error(path, &e))?;
    let lines = lines_or_first(
        element_lines(text, "control_points"),
        raw.control_points.len(),
    );
    let control_points = pairs(raw.control_points, &lines, path)?
        .into_iter()
        .map(|(x, y)| Point::new(x, y))
        .collect();
    let knots = KnotVector::try_new(raw.knots).map_err(|source| IoError::Invalid {
        path: path.to_path_buf(),
        source,
    })?;
    BSplineCurve::try_new(raw.degree, knots, control_points, raw.weights).map_err(|source| {
        IoError::Invalid {
            path: path.to_path_buf(),
            source,
        }
    })
}

/// One number as serde_json writes it: shortest round-trip digits (`1.0`, `1e300`, `-0.0`).
fn number(x: f64) -> String {
    serde_json::Value::from(x).to_string()
}

/// The JSON text of a space curve's points, one point per line.
pub(crate) fn format_space(points: &[Xyz], closed: bool) -> String {
    let mut out = String::with_capacity(32 + points.len() * 64);
    out.push_str("{\n  \"points\": [\n");
    for (i, p) in points.iter().enumerate() {
        if i > 0 {
            out.push_str(",\n");
        }
        // Writing to a String cannot fail.
        let _ = write!(
            out,
            "    [{}, {}, {}]",
            number(p[0]),
            number(p[1]),
            number(p[2])
        );
    }
    let _ = write!(out, "\n  ],\n  \"closed\": {closed}\n}}\n");
    out
}

/// The JSON text of a point list, one point per line (so that read-back errors name it).
/// All values must be finite.
pub(crate) fn format(points: &[Point], closed: bool, tangents: Option<&[Vec2]>) -> String {
    let mut out = String::with_capacity(32 + points.len() * 48);
    let pairs = |out: &mut String, xy: &mut dyn Iterator<Item = (f64, f64)>| {
        let mut first = true;
        for (x, y) in xy {
            if !first {
                out.push_str(",\n");
            }
            first = false;
            // Writing to a String cannot fail.
            let _ = write!(out, "    [{}, {}]", number(x), number(y));
        }
        out.push('\n');
    };
    out.push_str("{\n  \"points\": [\n");
    pairs(&mut out, &mut points.iter().map(|p| (p.x, p.y)));
    let _ = write!(out, "  ],\n  \"closed\": {closed}");
    if let Some(t) = tangents {
        out.push_str(",\n  \"tangents\": [\n");
        pairs(&mut out, &mut t.iter().map(|v| (v.x, v.y)));
        out.push_str("  ]");
    }
    out.push_str("\n}\n");
    out
}

/// The 1-based line on which each element of the array under the top-level key `key` starts,
/// or `None` when the text is not an object holding such an array.
///
/// A small scanner over JSON that serde_json has already accepted: it tracks strings (with
/// escapes) and nesting to find the array, then notes the line of each element's first byte.
pub(crate) fn element_lines(text: &str, key: &str) -> Option<Vec<usize>> {
    let mut s = Scanner {
        b: text.as_bytes(),
        i: 0,
        line: 1,
    };
    s.ws();
    s.expect(b'{')?;
    loop {
        s.ws();
        if s.peek()? == b'}' {
            return None;
        }
        let k = s.string()?;
        s.ws();
        s.expect(b':')?;
        s.ws();
        if k == key {
            s.expect(b'[')?;
            let mut lines = Vec::new();
            loop {
                s.ws();
                if s.peek()? == b']' {
                    return Some(lines);
                }
                lines.push(s.line);
                s.value()?;
                s.ws();
                if s.peek()? == b',' {
                    s.i += 1;
                }
            }
        }
        s.value()?;
        s.ws();
        if s.peek()? == b',' {
            s.i += 1;
        }
    }
}

struct Scanner<'a> {
    b: &'a [u8],
    i: usize,
    line: usize,
}

impl Scanner<'_> {
    fn peek(&self) -> Option<u8> {
        self.b.get(self.i).copied()
    }

    fn ws(&mut self) {
        while let Some(c) = self.peek() {
            match c {
                b'\n' => self.line += 1,
                b' ' | b'\t' | b'\r' => {}
                _ => return,
            }
            self.i += 1;
        }
    }

    fn expect(&mut self, c: u8) -> Option<()> {
        (self.peek()? == c).then(|| self.i += 1)
    }

    /// A string; returns its decoded text.
    fn string(&mut self) -> Option<String> {
        let start = self.i;
        self.expect(b'"')?;
        loop {
            match self.peek()? {
                b'\\' => self.i += 2,
                b'"' => {
                    self.i += 1;
                    let raw = std::str::from_utf8(self.b.get(start..self.i)?).ok()?;
                    return serde_json::from_str(raw).ok();
                }
                _ => self.i += 1,
            }
        }
    }

    /// Skip one value of any kind.
    fn value(&mut self) -> Option<()> {
        match self.peek()? {
            b'"' => self.string().map(|_| ()),
            open @ (b'[' | b'{') => {
                let close = if open == b'[' { b']' } else { b'}' };
                self.i += 1;
                loop {
                    self.ws();
                    match self.peek()? {
                        c if c == close => {
                            self.i += 1;
                            return Some(());
                        }
                        b',' | b':' => self.i += 1,
                        _ => self.value()?,
                    }
                }
            }
            _ => {
                // A number, true, false or null: up to the next delimiter.
                let start = self.i;
                while let Some(c) = self.peek() {
                    if matches!(c, b',' | b']' | b'}' | b' ' | b'\t' | b'\r' | b'\n') {
                        break;
                    }
                    self.i += 1;
                }
                (self.i > start).then_some(())
            }
        }
    }
}

#[cfg(test)]
impl ParsedJson {
    /// The planar points (none for a space curve).
    fn points(&self) -> &[Point] {
        match &self.coords {
            Coords::Planar(p) => p,
            Coords::Space(_) => &[],
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn path() -> &'static Path {
        Path::new("data.json")
    }

    fn err(s: &str) -> String {
        match parse_points(s.as_bytes(), path()) {
            Ok(_) => panic!("expected an error for {s}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn element_lines_pretty_and_compact() {
        let t = "{\n \"name\": \"a \\\" ] [ b\",\n \"nested\": {\"points\": [[9, 9]]},\n \"points\": [\n  [0, 1],\n  [2, 3], [4, 5],\n\n  [6, 7]\n ]\n}";
        assert_eq!(element_lines(t, "points"), Some(vec![5, 6, 6, 8]));
        assert_eq!(element_lines(t, "tangents"), None);
        let t = r#"{"closed":true,"points":[[0,1],[2,3]],"tangents":[]}"#;
        assert_eq!(element_lines(t, "points"), Some(vec![1, 1]));
        assert_eq!(element_lines(t, "tangents"), Some(vec![]));
        assert_eq!(element_lines("[1, 2]", "points"), None);
        assert_eq!(element_lines("{\"points\": 3}", "points"), None);
        assert_eq!(element_lines("{\"points\": [1, 2", "points"), None);
    }

    #[test]
    fn reads_points_closed_tangents() {
        let t = "{\"points\": [[0, 0], [1, 0.5], [2, 1e-3]],\n\"closed\": true,\n\"tangents\": [[1, 0], [1, 0], [1, 0]]}";
        let p = parse_points(t.as_bytes(), path()).unwrap();
        assert_eq!(p.points()[1], Point::new(1.0, 0.5));
        assert!(p.closed);
        assert_eq!(p.tangents.unwrap().len(), 3);
        assert_eq!(p.lines, vec![1, 1, 1]);
        assert_eq!(p.tangent_lines, vec![3, 3, 3]);
        let p = parse_points(b"{\"points\": [[0, 0]]}", path()).unwrap();
        assert!(!p.closed);
        assert!(p.tangents.is_none());
    }

    #[test]
    fn malformed_json_gives_line_and_column() {
        assert_eq!(
            err("{\"points\": [\n  [0, 0],\n  [1, 2\n]}"),
            "data.json:4:2: malformed JSON: expected `,` or `]`"
        );
        assert_eq!(
            err("{\"points\": [[0, 0],"),
            "data.json:1:19: malformed JSON: EOF while parsing a value"
        );
        assert_eq!(
            err("{\"points\": [[0, NaN]]}"),
            "data.json:1:17: malformed JSON: expected value"
        );
        let m = err("{\"points\": [[0, 1e400]]}");
        assert!(m.starts_with("data.json:1:"), "{m}");
        assert!(m.contains("out of range"), "{m}");
    }

    #[test]
    fn wrong_shapes_are_errors() {
        assert_eq!(
            err("{\"points\": [[0, 0]], \"close\": true}"),
            "data.json:1:28: unknown field `close`, expected one of `points`, `closed`, `tangents`"
        );
        assert_eq!(
            err("{\"points\": [[0, \"a\"]]}"),
            "data.json:1:19: invalid type: string \"a\", expected f64"
        );
        assert_eq!(
            err("{\"points\": [[0, 1],\n [0, 1, 2]]}"),
            "data.json:2: expected 2 fields (x, y), found 3"
        );
        assert_eq!(
            err("{\"points\": [[0, 1], [2, 3]],\n\"tangents\": [[1, 0],\n[1]]}"),
            "data.json:3: expected 2 fields (x, y), found 1"
        );
        assert_eq!(
            err("[[0, 1]]"),
            "data.json: expected an object: {\"points\": [[x, y], ...]} or a B-spline \
             {\"degree\": p, \"knots\": [...], \"control_points\": [...]}"
        );
        assert!(parse_curve(b"[1]", path()).is_err());
        assert_eq!(err("{}"), "data.json:1:2: missing field `points`");
    }

    #[test]
    fn curve_is_not_a_point_list_and_back() {
        let curve = r#"{"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0], [1, 1]]}"#;
        assert_eq!(
            err(curve),
            "data.json: the file holds a B-spline curve (degree, knots, control_points), not a point list"
        );
        let c = parse_curve(curve.as_bytes(), path()).unwrap();
        assert_eq!(c.degree(), 1);
        assert_eq!(c.control_points()[1], Point::new(1.0, 1.0));
        let e = parse_curve(b"{\"points\": [[0, 0]]}", path())
            .err()
            .unwrap();
        assert_eq!(
            e.to_string(),
            "data.json: the file holds a point list, not a B-spline curve"
        );
        let bad = r#"{"degree": 1, "knots": [0, 0, 1], "control_points": [[0, 0], [1, 1]]}"#;
        let e = parse_curve(bad.as_bytes(), path())
            .err()
            .unwrap()
            .to_string();
        assert_eq!(
            e,
            "data.json: invalid knot vector: 3 knots for 2 control points of degree 1: expected 4"
        );
    }

    #[test]
    fn format_reads_back_bit_exact() {
        let pts = vec![
            Point::new(-0.0, 1e-300),
            Point::new(1e300, 5e-324),
            Point::new(0.1, f64::MAX),
            Point::new(f64::MIN_POSITIVE / 7.0, -1.0 / 3.0),
        ];
        let tans = vec![Vec2::new(1.0, 0.0); 4];
        let text = format(&pts, true, Some(&tans));
        let p = parse_points(text.as_bytes(), path()).unwrap();
        assert!(p.closed);
        assert_eq!(p.lines, vec![3, 4, 5, 6]);
        assert_eq!(p.tangent_lines, vec![10, 11, 12, 13]);
        for (a, b) in pts.iter().zip(p.points()) {
            assert_eq!(a.x.to_bits(), b.x.to_bits(), "{a:?} {b:?}");
            assert_eq!(a.y.to_bits(), b.y.to_bits(), "{a:?} {b:?}");
        }
        assert_eq!(p.tangents.unwrap(), tans);
        let text = format(&pts, false, None);
        assert!(!text.contains("tangents"));
        assert!(text.contains("\"closed\": false"));
    }
}
