//! B-spline surfaces as JSON.
//!
//! ```text
//! {"degree_u": 3, "degree_v": 3, "knots_u": [...], "knots_v": [...],
//!  "control_points": [[[x, y, z], ...], ...], "weights": [[w, ...], ...]}
//! ```
//!
//! The outer list of `control_points` runs along u, each inner list along v; `weights`
//! (optional) has the same shape without the coordinates. Instead of a surface, a file may
//! hold a regular grid of points, `{"grid": [[[x, y, z], ...], ...]}`, which is interpolated
//! by [`crate::surface::interpolate_grid`] (bicubic where the grid has four or more points in a
//! direction). Any other key is an error, as are rows of unequal length, points without
//! exactly three coordinates and weights of the wrong shape; every message names the file
//! and the row.

use std::fmt::Write as _;
use std::path::Path;

use serde::Deserialize;

use super::IoError;
use super::json::{json_error, utf8};
use super::{Format, read_bytes, write_atomic};
use crate::spline::KnotVector;
use crate::surface::{BSplineSurface, Xyz, interpolate_grid};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SurfaceJson {
    degree_u: Option<usize>,
    degree_v: Option<usize>,
    knots_u: Option<Vec<f64>>,
    knots_v: Option<Vec<f64>>,
    control_points: Option<Vec<Vec<Vec<f64>>>>,
    weights: Option<Vec<Vec<f64>>>,
    grid: Option<Vec<Vec<Vec<f64>>>>,
}

/// Keys of a surface given by its control net.
const NET_KEYS: [&str; 5] = [
    "degree_u",
    "degree_v",
    "knots_u",
    "knots_v",
    "control_points",
];

/// Read a surface (or a grid to interpolate) from a `.json` file.
///
/// # Errors
/// [`IoError::Read`], [`IoError::UnknownFormat`], [`IoError::NotUtf8`], [`IoError::Json`]
/// (malformed, unknown key, wrong type), [`IoError::JsonContent`] (wrong shape, missing key,
/// a grid mixed with a control net), [`IoError::Invalid`] (the library refuses the knots,
/// weights or grid).
pub fn read_surface_json(path: &Path) -> Result<BSplineSurface, IoError> {
    if Format::from_path(path)? != Format::Json {
        return Err(IoError::UnknownFormat {
            path: path.to_path_buf(),
        });
    }
    let bytes = read_bytes(path)?;
    parse_surface(&bytes, path)
}

/// Parse the bytes of a surface JSON file; `path` names it in errors.
///
/// # Errors
/// As [`read_surface_json`], without the read.
pub fn parse_surface(bytes: &[u8], path: &Path) -> Result<BSplineSurface, IoError> {
    let text = utf8(bytes, path)?;
    let value: serde_json::Value = serde_json::from_str(text).map_err(|e| json_error(path, &e))?;
    let content = |message: String| IoError::JsonContent {
        path: path.to_path_buf(),
        message,
    };
    if !value.is_object() {
        return Err(content(
            "expected an object: a surface {\"degree_u\", \"degree_v\", \"knots_u\", \
             \"knots_v\", \"control_points\"} or a grid {\"grid\": [[[x, y, z], ...], ...]}"
                .into(),
        ));
    }
    let s: SurfaceJson = serde_json::from_str(text).map_err(|e| json_error(path, &e))?;
    let invalid = |source| IoError::Invalid {
        path: path.to_path_buf(),
        source,
    };
    if let Some(grid) = s.grid {
        let given: Vec<&str> = NET_KEYS
            .iter()
            .copied()
            .filter(|k| value.get(*k).is_some())
            .chain(s.weights.as_ref().map(|_| "weights"))
            .collect();
        if !given.is_empty() {
            return Err(content(format!(
                "\"grid\" cannot be combined with {}",
                given.join(", ")
            )));
        }
        let rows = rows_of_points(&grid, "grid").map_err(content)?;
        return interpolate_grid(&rows).map_err(invalid);
    }
    let missing = |k: &str| content(format!("missing key \"{k}\" (or give a \"grid\")"));
    let du = s.degree_u.ok_or_else(|| missing("degree_u"))?;
    let dv = s.degree_v.ok_or_else(|| missing("degree_v"))?;
    let ku = s.knots_u.ok_or_else(|| missing("knots_u"))?;
    let kv = s.knots_v.ok_or_else(|| missing("knots_v"))?;
    let net = s.control_points.ok_or_else(|| missing("control_points"))?;
    let rows = rows_of_points(&net, "control_points").map_err(content)?;
    let (nu, nv) = (rows.len(), rows[0].len());
    let weights = match s.weights {
        None => None,
        Some(w) => {
            if w.len() != nu {
                return Err(content(format!(
                    "weights has {} rows, control_points {nu}",
                    w.len()
                )));
            }
            if let Some(i) = w.iter().position(|r| r.len() != nv) {
                return Err(content(format!(
                    "weights row {i} has {} entries, expected {nv}",
                    w[i].len()
                )));
            }
            Some(w.into_iter().flatten().collect())
        }
    };
    let ku = KnotVector::try_new(ku).map_err(|e| content(format!("knots_u: {e}")))?;
    let kv = KnotVector::try_new(kv).map_err(|e| content(format!("knots_v: {e}")))?;
    let control = rows.into_iter().flatten().collect();
    BSplineSurface::try_new((du, dv), (ku, kv), (nu, nv), control, weights).map_err(invalid)
}

/// Check a nested list of points: non-empty, rows of equal length, three coordinates each.
fn rows_of_points(net: &[Vec<Vec<f64>>], key: &str) -> Result<Vec<Vec<Xyz>>, String> {
    if net.is_empty() || net[0].is_empty() {
        return Err(format!("{key} is empty"));
    }
    let nv = net[0].len();
    let mut out = Vec::with_capacity(net.len());
    for (i, row) in net.iter().enumerate() {
        if row.len() != nv {
            return Err(format!(
                "{key} row {i} has {} points, row 0 has {nv}",
                row.len()
            ));
        }
        let mut r = Vec::with_capacity(nv);
        for (j, p) in row.iter().enumerate() {
            if p.len() != 3 {
                return Err(format!(
                    "{key}[{i}][{j}] has {} coordinates, expected 3 (x, y, z)",
                    p.len()
                ));
            }
            r.push([p[0], p[1], p[2]]);
        }
        out.push(r);
    }
    Ok(out)
}

/// One number in the shortest form that reads back bit for bit.
fn number(x: f64) -> String {
    serde_json::Value::from(x).to_string()
}

/// The JSON text of a surface: one row of control points per line. All values are finite
/// (the surface was validated), so the text reads back bit for bit.
pub fn format_surface(s: &BSplineSurface) -> String {
    let (nu, nv) = s.size();
    let (ku, kv) = s.knots();
    let list = |xs: &[f64]| xs.iter().map(|x| number(*x)).collect::<Vec<_>>().join(", ");
    let mut out = String::with_capacity(64 + nu * nv * 64);
    let (du, dv) = s.degree();
    let _ = writeln!(out, "{{\n  \"degree_u\": {du},\n  \"degree_v\": {dv},");
    let _ = writeln!(out, "  \"knots_u\": [{}],", list(ku.as_slice()));
    let _ = writeln!(out, "  \"knots_v\": [{}],", list(kv.as_slice()));
    out.push_str("  \"control_points\": [\n");
    let cp = s.control_points();
    for i in 0..nu {
        let row: Vec<String> = cp[i * nv..(i + 1) * nv]
            .iter()
            .map(|c| format!("[{}]", list(c)))
            .collect();
        let sep = if i + 1 < nu { "," } else { "" };
        let _ = writeln!(out, "    [{}]{sep}", row.join(", "));
    }
    out.push_str("  ]");
    if let Some(w) = s.weights() {
        out.push_str(",\n  \"weights\": [\n");
        for i in 0..nu {
            let sep = if i + 1 < nu { "," } else { "" };
            let _ = writeln!(out, "    [{}]{sep}", list(&w[i * nv..(i + 1) * nv]));
        }
        out.push_str("  ]");
    }
    out.push_str("\n}\n");
    out
}

/// Write a surface as JSON, atomically.
///
/// # Errors
/// [`IoError::UnknownFormat`] (not `.json`), [`IoError::Write`].
pub fn write_surface_json(path: &Path, s: &BSplineSurface) -> Result<(), IoError> {
    if Format::from_path(path)? != Format::Json {
        return Err(IoError::UnknownFormat {
            path: path.to_path_buf(),
        });
    }
    write_atomic(path, format_surface(s).as_bytes())
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<BSplineSurface, IoError> {
        parse_surface(text.as_bytes(), Path::new("s.json"))
    }

    const GOOD: &str = r#"{"degree_u": 1, "degree_v": 2, "knots_u": [0, 0, 1, 1],
        "knots_v": [0, 0, 0, 1, 1, 1],
        "control_points": [[[0,0,0],[0,1,0.1],[0,2,0]], [[1,0,0.3],[1,1,0.7],[1,2,0.2]]],
        "weights": [[1, 0.5, 1], [1, 2, 1]]}"#;

    #[test]
    fn round_trip_is_exact() {
        let s = parse(GOOD).unwrap();
        assert_eq!(s.size(), (2, 3));
        assert_eq!(s.control_point(1, 1), [1.0, 1.0, 0.7]);
        // Awkward numbers survive bit for bit.
        let mut cp = s.control_points().to_vec();
        cp[2] = [0.1 + 0.2, 1e-300, -std::f64::consts::PI];
        let s = s.with_control_points(cp).unwrap();
        let back = parse(&format_surface(&s)).unwrap();
        assert_eq!(back, s);
    }

    fn err(text: &str) -> String {
        parse(text).unwrap_err().to_string()
    }

    #[test]
    fn bad_files_get_one_line_naming_the_problem() {
        let cases = [
            (
                GOOD.replace("\"weights\"", "\"wieghts\""),
                "unknown field `wieghts`",
            ),
            (
                GOOD.replace("[1,2,0.2]", "[1,2]"),
                "control_points[1][2] has 2 coordinates",
            ),
            (
                GOOD.replace(",[1,2,0.2]]", "]"),
                "control_points row 1 has 2 points",
            ),
            (
                GOOD.replace("[1, 2, 1]", "[1, 2]"),
                "weights row 1 has 2 entries",
            ),
            (
                GOOD.replace("[1, 2, 1]", "[1, -2, 1]"),
                "weight [1][1] must be positive",
            ),
            (
                GOOD.replace("[0, 0, 1, 1]", "[0, 0, 1]"),
                "knots_u has 3 knots",
            ),
            (
                GOOD.replace("[0, 0, 1, 1]", "[0, 1, 0, 1]"),
                "knots_u: invalid knot vector",
            ),
            (
                GOOD.replace("\"degree_v\": 2,", ""),
                "missing key \"degree_v\"",
            ),
            ("[1, 2]".to_string(), "expected an object"),
            (
                "{\"grid\": [[[0,0,0],[1,0,0]]]}".to_string(),
                "too few points",
            ),
            (
                "{\"grid\": [[[0,0,0]]], \"degree_u\": 3}".to_string(),
                "cannot be combined",
            ),
            ("{\"degree_u\": 3,".to_string(), "malformed JSON"),
        ];
        for (text, want) in cases {
            let e = err(&text);
            assert!(e.starts_with("s.json"), "{e}");
            assert!(e.contains(want), "{e} lacks {want}");
            assert!(!e.contains('\n'), "{e}");
        }
    }

    #[test]
    fn a_grid_is_interpolated() {
        let mut rows = Vec::new();
        for i in 0..6 {
            let mut row = Vec::new();
            for j in 0..5 {
                let (x, y) = (i as f64 * 0.4, j as f64 * 0.3 + 0.05 * i as f64);
                row.push(format!("[{x}, {y}, {}]", (x * 1.3).sin() * y.cos()));
            }
            rows.push(format!("[{}]", row.join(", ")));
        }
        let text = format!("{{\"grid\": [{}]}}", rows.join(", "));
        let s = parse(&text).unwrap();
        assert_eq!(s.degree(), (3, 3));
        assert_eq!(s.size(), (6, 5));
        // Corners are interpolated at the domain corners.
        let p = s.point(1.0, 1.0);
        let (x, y) = (2.0, 1.2 + 0.25);
        assert!((p[0] - x).abs() < 1e-12 && (p[1] - y).abs() < 1e-12);
        assert!((p[2] - (x * 1.3).sin() * y.cos()).abs() < 1e-12);
    }
}
