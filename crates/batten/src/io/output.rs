//! Writing points and curves in any format, and refusing to overwrite the input.

use std::fs;
use std::path::{Path, PathBuf};

use super::input::Origin;
use super::{Format, IoError, Location, dxf, iges, json, svg, text};
use crate::geom::{Point, Vec2, Xyz};
use crate::spline::BSplineCurve;

/// The bytes of a point list in `format`: text, JSON, a DXF LWPOLYLINE, an IGES copious-data
/// entity (106, form 11 or 63 when closed), or an SVG path of the C² cubic through the
/// points (chord-length parameters, not-a-knot ends, or periodic when closed). `origin`
/// gives the z, layer and name for the formats that hold them; `path` names the output in
/// messages.
///
/// # Errors
/// [`IoError::NonFiniteOutput`]; [`IoError::Format`] when the cubic through the points
/// cannot be built (SVG).
pub fn format_points(
    format: Format,
    path: &Path,
    points: &[Point],
    closed: bool,
    tangents: Option<&[Vec2]>,
    origin: &Origin,
) -> Result<Vec<u8>, IoError> {
    let bad_point = points.iter().position(|p| !p.is_finite());
    let bad_tangent = tangents.and_then(|t| t.iter().position(|v| !v.is_finite()));
    if let Some(index) = bad_point.or(bad_tangent) {
        return Err(IoError::NonFiniteOutput {
            path: path.to_path_buf(),
            index,
        });
    }
    Ok(match format {
        Format::Text => text::format(points).into_bytes(),
        Format::Json => json::format(points, closed, tangents).into_bytes(),
        Format::Dxf => dxf::format_points(points, closed, origin, path)?,
        Format::Iges => iges::format_points(points, closed, origin).into_bytes(),
        Format::Svg => {
            let curve = cubic_through(points, closed).map_err(|e| IoError::Format {
                path: path.to_path_buf(),
                at: Location::File,
                message: format!("cannot build the cubic through the points: {e}"),
            })?;
            svg::format_curve(&curve, closed, origin, path)?.into_bytes()
        }
    })
}

/// The bytes of a space curve's points in `format`: text (`x,y,z`), JSON, a DXF 3-D
/// `POLYLINE` on the origin's layer, or IGES copious data (entity 106 form 12). SVG holds
/// planar curves only.
///
/// # Errors
/// [`IoError::NonFiniteOutput`]; [`IoError::Format`] for a format that takes planar curves
/// only.
pub fn format_space_points(
    format: Format,
    path: &Path,
    points: &[Xyz],
    closed: bool,
    origin: &Origin,
) -> Result<Vec<u8>, IoError> {
    if let Some(index) = points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(IoError::NonFiniteOutput {
            path: path.to_path_buf(),
            index,
        });
    }
    match format {
        Format::Text => Ok(text::format_space(points).into_bytes()),
        Format::Json => Ok(json::format_space(points, closed).into_bytes()),
        Format::Dxf => dxf::format_space_points(points, closed, origin, path),
        Format::Iges => Ok(iges::format_space_points(points, closed, origin).into_bytes()),
        Format::Svg => Err(IoError::Format {
            path: path.to_path_buf(),
            at: Location::File,
            message: "a 3-D curve is written as .csv, .txt, .json, .dxf or .igs".into(),
        }),
    }
}

/// The C² cubic through the points as a B-spline (the analysis curve of `crate::analysis`).
fn cubic_through(points: &[Point], closed: bool) -> crate::Result<BSplineCurve> {
    use crate::spline::{EndCondition, ParametricCubic, Parametrization};
    let c = if closed {
        ParametricCubic::closed(points, Parametrization::ChordLength)?
    } else {
        ParametricCubic::interpolate(points, Parametrization::ChordLength, EndCondition::NotAKnot)?
    };
    BSplineCurve::from_parametric_cubic(&c)
}

/// Whether [`format_curve`] can write `curve` as SVG (non-rational, degree 1 to 3, clamped).
pub fn svg_can_hold(curve: &BSplineCurve) -> bool {
    svg::bezier_segments(curve).is_ok()
}

/// The bytes of a B-spline curve in `format`: JSON as [`BSplineCurve`] serialises, a DXF
/// SPLINE, an IGES entity 126, or an SVG path of Bézier segments.
///
/// # Errors
/// [`IoError::Format`] for text (which holds no curve), a curve SVG cannot hold, or one
/// that does not serialise.
pub fn format_curve(
    format: Format,
    path: &Path,
    curve: &BSplineCurve,
    closed: bool,
    origin: &Origin,
) -> Result<Vec<u8>, IoError> {
    let fail = |message: String| IoError::Format {
        path: path.to_path_buf(),
        at: Location::File,
        message,
    };
    Ok(match format {
        Format::Text => {
            return Err(fail(
                "a text file holds points, not a B-spline: use .json, .dxf, .igs or .svg".into(),
            ));
        }
        Format::Json => {
            let mut json = serde_json::to_string_pretty(curve)
                .map_err(|e| fail(format!("cannot encode the curve: {e}")))?;
            json.push('\n');
            json.into_bytes()
        }
        Format::Dxf => dxf::format_curve(curve, closed, origin, path)?,
        Format::Iges => iges::format_curve(curve, closed, origin).into_bytes(),
        Format::Svg => svg::format_curve(curve, closed, origin, path)?.into_bytes(),
    })
}

/// Refuse to write `output` when it is the file `input` (the same file after resolving `.`,
/// `..` and symbolic links, or, on Unix, another hard link to it).
///
/// Paths that cannot be resolved (an input that does not exist, an output in a missing
/// directory) are not the same file; writing will report its own error.
///
/// # Errors
/// [`IoError::SameFile`].
pub fn ensure_distinct(input: &Path, output: &Path) -> Result<(), IoError> {
    let same = IoError::SameFile {
        input: input.to_path_buf(),
        output: output.to_path_buf(),
    };
    let Ok(input_real) = fs::canonicalize(input) else {
        return Ok(());
    };
    match resolve(output) {
        Some(out) if out == input_real => return Err(same),
        _ => {}
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt as _;
        if let (Ok(a), Ok(b)) = (fs::metadata(input), fs::metadata(output))
            && a.dev() == b.dev()
            && a.ino() == b.ino()
        {
            return Err(same);
        }
    }
    Ok(())
}

/// The canonical path `path` names or would name once created.
fn resolve(path: &Path) -> Option<PathBuf> {
    if let Ok(p) = fs::canonicalize(path) {
        return Some(p);
    }
    let name = path.file_name()?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    Some(fs::canonicalize(dir).ok()?.join(name))
}
