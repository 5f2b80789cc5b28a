//! Reading point lists and B-spline curves from text and JSON, validating them, and writing
//! point lists.

use std::fs;
use std::path::Path;

use super::input::{Origin, Pick, Source, parse_input};
use super::output::format_points;
use super::text::Coords;
use super::{Format, IoError, PointData, ReadOptions, SpaceData, json, limits, text, write_atomic};
use crate::error::Error;
use crate::geom::{Point, PointSeq, SpaceSeq, Vec2, Xyz};
use crate::spline::BSplineCurve;

/// Read a point list (format by extension) and validate it.
///
/// # Errors
/// [`IoError::Read`], [`IoError::UnknownFormat`], and everything [`parse_points`] reports.
pub fn read_points(path: &Path, options: &ReadOptions) -> Result<PointData, IoError> {
    let format = Format::from_path(path)?;
    let bytes = read_bytes(path)?;
    parse_points(&bytes, format, path, options)
}

/// Parse and validate a point list held in memory; `path` names it in messages.
///
/// # Errors
/// One error naming the line, for the first problem met: [`IoError::NotUtf8`],
/// [`IoError::FieldCount`], [`IoError::NotANumber`], [`IoError::NonFinite`], [`IoError::Json`],
/// [`IoError::CurveNotPoints`]; then, for the whole list, [`IoError::Empty`],
/// [`IoError::TooLarge`] (beyond [`MAX_COORDINATE`](super::MAX_COORDINATE)), [`IoError::TooFewPoints`],
/// [`IoError::DuplicatePoint`], [`IoError::RepeatsFirst`], [`IoError::NearDuplicate`]
/// (closer than [`crate::geom::NEAR_DUPLICATE_REL`] of the bounding box's larger side),
/// [`IoError::TangentCount`].
pub fn parse_points(
    bytes: &[u8],
    format: Format,
    path: &Path,
    options: &ReadOptions,
) -> Result<PointData, IoError> {
    let source = match format {
        Format::Text | Format::Json => parse_text_or_json(bytes, format, path, options)?,
        Format::Dxf | Format::Iges | Format::Svg => {
            parse_input(bytes, format, path, options, &Pick::default())?.source
        }
    };
    match source {
        Source::Points(d) => Ok(d),
        Source::Curve(_) => Err(IoError::CurveNotPoints {
            path: path.to_path_buf(),
        }),
        Source::Space(_) => Err(IoError::SpaceNotPlanar {
            path: path.to_path_buf(),
        }),
    }
}

/// A text or JSON file: planar points (with their tangents), space points, or (JSON) a
/// B-spline.
pub(super) fn parse_text_or_json(
    bytes: &[u8],
    format: Format,
    path: &Path,
    options: &ReadOptions,
) -> Result<Source, IoError> {
    let (coords, lines, closed, tangents, tangent_lines) = if format == Format::Json {
        match json::parse_points(bytes, path) {
            Ok(j) => (j.coords, j.lines, j.closed, j.tangents, j.tangent_lines),
            Err(IoError::CurveNotPoints { .. }) => {
                return Ok(Source::Curve(json::parse_curve(bytes, path)?));
            }
            Err(e) => return Err(e),
        }
    } else {
        let t = text::parse(bytes, path)?;
        (t.coords, t.lines, false, None, Vec::new())
    };
    let closed = closed || options.closed;
    let points = match coords {
        Coords::Planar(points) => points,
        Coords::Space(points) => {
            return Ok(Source::Space(SpaceData {
                seq: validate_space(path, points, &lines, closed)?,
                lines,
            }));
        }
    };
    let seq = validate(path, points, &lines, closed)?;
    if let Some(t) = &tangents {
        if t.len() != seq.len() {
            return Err(IoError::TangentCount {
                path: path.to_path_buf(),
                got: t.len(),
                expected: seq.len(),
            });
        }
        if let Some(i) = t.iter().position(|v| !v.is_finite()) {
            return Err(IoError::NonFinite {
                path: path.to_path_buf(),
                line: tangent_lines.get(i).copied().unwrap_or(1),
            });
        }
    }
    Ok(Source::Points(PointData {
        seq,
        tangents,
        lines,
    }))
}

/// Wrap the points in a [`PointSeq`], turning its index-based errors into line-based ones.
pub(super) fn validate(
    path: &Path,
    points: Vec<Point>,
    lines: &[usize],
    closed: bool,
) -> Result<PointSeq, IoError> {
    if points.is_empty() {
        return Err(IoError::Empty {
            path: path.to_path_buf(),
        });
    }
    limits::check_magnitudes(path, &points, lines)?;
    // What tells a repeated neighbour from a closed curve's repeated first point, noted before
    // the points move into the sequence (rather than validating a copy: 16 MB at 10⁶ points).
    let n = points.len();
    let last_repeats_previous = n >= 2 && points[n - 1] == points[n - 2];
    PointSeq::new(points, closed)
        .map_err(|e| seq_error(path, lines, closed, n, last_repeats_previous, e))
}

/// [`validate`] for a space curve: the same rules, the same messages.
pub(super) fn validate_space(
    path: &Path,
    points: Vec<Xyz>,
    lines: &[usize],
    closed: bool,
) -> Result<SpaceSeq, IoError> {
    if points.is_empty() {
        return Err(IoError::Empty {
            path: path.to_path_buf(),
        });
    }
    limits::check_coordinates(path, points.iter().copied(), lines)?;
    let n = points.len();
    let last_repeats_previous = n >= 2 && points[n - 1] == points[n - 2];
    SpaceSeq::new(points, closed)
        .map_err(|e| seq_error(path, lines, closed, n, last_repeats_previous, e))
}

/// A point sequence's index-based error as a line-based one.
fn seq_error(
    path: &Path,
    lines: &[usize],
    closed: bool,
    n: usize,
    last_repeats_previous: bool,
    error: Error,
) -> IoError {
    let line = |i: usize| lines.get(i).copied().unwrap_or(1);
    match error {
        Error::TooFewPoints { needed, got } => IoError::TooFewPoints {
            path: path.to_path_buf(),
            got,
            needed,
        },
        Error::NonFinite { index } => IoError::NonFinite {
            path: path.to_path_buf(),
            line: line(index),
        },
        Error::DuplicatePoint { index }
            if index > 0 && (index + 1 < n || !closed || last_repeats_previous) =>
        {
            IoError::DuplicatePoint {
                path: path.to_path_buf(),
                line: line(index),
                previous: line(index - 1),
            }
        }
        Error::DuplicatePoint { index } => IoError::RepeatsFirst {
            path: path.to_path_buf(),
            line: line(index),
            first: line(0),
        },
        Error::NearDuplicate {
            index,
            previous,
            relative,
        } => {
            // The closing chord of a closed curve comes as (first, last): name the later line.
            let (a, b) = (line(index), line(previous));
            IoError::NearDuplicate {
                path: path.to_path_buf(),
                line: a.max(b),
                other: a.min(b),
                relative,
            }
        }
        source => IoError::Invalid {
            path: path.to_path_buf(),
            source,
        },
    }
}

/// Read a B-spline curve from a JSON file.
///
/// # Errors
/// [`IoError::Read`], [`IoError::UnknownFormat`] (not `.json`), [`IoError::Json`] (malformed,
/// or a curve the library rejects, e.g. a knot vector of the wrong length),
/// [`IoError::PointsNotCurve`].
pub fn read_curve_json(path: &Path) -> Result<BSplineCurve, IoError> {
    if Format::from_path(path)? != Format::Json {
        return Err(IoError::UnknownFormat {
            path: path.to_path_buf(),
        });
    }
    let bytes = read_bytes(path)?;
    json::parse_curve(&bytes, path)
}

/// Parse a B-spline curve held in memory as JSON; `path` names it in messages.
///
/// # Errors
/// As [`read_curve_json`], less the reading.
pub fn parse_curve_json(bytes: &[u8], path: &Path) -> Result<BSplineCurve, IoError> {
    json::parse_curve(bytes, path)
}

pub(super) fn read_bytes(path: &Path) -> Result<Vec<u8>, IoError> {
    fs::read(path).map_err(|source| IoError::Read {
        path: path.to_path_buf(),
        source,
    })
}

/// Write a point list (format by extension), atomically (see [`write_atomic`]).
///
/// Text files get the header `x,y` and one row per point; `closed` and `tangents` are
/// written to JSON only (a text file has no place for them). Numbers are written in the
/// shortest form that reads back bit for bit ([`format_f64`](super::format_f64) for text; serde_json's, which
/// is the same digits, for JSON).
///
/// # Errors
/// [`IoError::UnknownFormat`], [`IoError::NonFiniteOutput`], [`IoError::Write`].
pub fn write_points(
    path: &Path,
    points: &[Point],
    closed: bool,
    tangents: Option<&[Vec2]>,
) -> Result<(), IoError> {
    let contents = encode_points(path, points, closed, tangents)?;
    write_atomic(path, &contents)
}

/// The text [`write_points`] would write to `path` (format by extension), to write it later
/// with other files as one set ([`write_atomic_set`](super::write_atomic_set)).
///
/// # Errors
/// [`IoError::UnknownFormat`], [`IoError::NonFiniteOutput`].
pub fn encode_points(
    path: &Path,
    points: &[Point],
    closed: bool,
    tangents: Option<&[Vec2]>,
) -> Result<Vec<u8>, IoError> {
    let format = Format::from_path(path)?;
    format_points(format, path, points, closed, tangents, &Origin::default())
}
