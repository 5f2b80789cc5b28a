//! Reading and writing point lists and curves: CSV/whitespace text, JSON, DXF, IGES, SVG.
//!
//! The format follows the file name's extension ([`Format::from_path`]): `.csv` and `.txt`
//! are text (one `x,y` per line, see [Text format](#text-format)), `.json` is JSON, `.dxf`,
//! `.igs`/`.iges` and `.svg` the CAD formats (see [Other formats](#other-formats)).
//!
//! - [`read_points`] reads a point list and validates it into a [`PointSeq`], keeping the
//!   1-based line of every point so that every error names the file and the line:
//!   `data.csv:9: point duplicates the previous one (line 8)`.
//! - [`read_curve_json`] reads a B-spline curve; [`read_points`] refuses one.
//! - [`write_points`] writes atomically (a temporary file beside the target, renamed over it)
//!   and numbers in their shortest exact form: what is written reads back bit for bit.
//!   [`write_atomic_set`] writes several files all or none; [`check_writable`] tells before
//!   any work whether an output can be created; [`remove_temporaries`] cleans up on a signal.
//! - [`ensure_distinct`] refuses an output path that is the input file.
//! - [`format_sig`] rounds a number for people (tables and notes), where [`format_f64`]
//!   writes it exactly.
//!
//! - [`parse_input`] / [`read_input`] read any format from bytes (standard input) or a file,
//!   picking one curve of a file that holds several ([`Pick`]), into points or a B-spline
//!   ([`Source`]) and where it sat ([`Origin`]: z, layer, name), so that
//!   [`format_points`] and [`format_curve`] can write the result back alike.
//! - [`DxfDrawing`] keeps a whole DXF drawing to write it back with several curves replaced.
//!
//! Nothing here prints; every failure is an [`IoError`].
//!
//! # Other formats
//!
//! | format | read | written by [`format_points`] | written by [`format_curve`] |
//! |---|---|---|---|
//! | DXF (`dxf` crate) | `LWPOLYLINE`, `POLYLINE`, `SPLINE` (control points: a B-spline; fit points only: points) | `LWPOLYLINE` | `SPLINE` |
//! | IGES (5.3, fixed form) | entity 126 (B-spline), 106 (copious data) | entity 106 | entity 126 |
//! | SVG (`roxmltree`) | `<path>` (lines: points; Béziers: a cubic B-spline), `<polyline>`, `<polygon>` | a path of the C² cubic through the points | a path of Bézier segments |
//!
//! The curve must be planar (constant z; the z is kept in [`Origin`] and written back) and
//! untransformed; each module's documentation (`io/dxf.rs`, `io/iges.rs`, `io/svg/`) says
//! exactly what it takes and refuses. IGES, SVG, text and JSON read back bit for bit; DXF
//! within the 12 decimal places the `dxf` crate writes.
//!
//! # Text format
//!
//! One point per line as `x,y`, `x;y` or `x y` (spaces or tabs); `#` starts a comment (whole
//! line or trailing); blank lines are skipped; a first line with no number in it (`x,y`) is a
//! header. Written files start with the header `x,y`. See `io/text.rs` for the exact rules.
//!
//! # JSON format
//!
//! `{"points": [[x, y], ...], "closed": false, "tangents": [[dx, dy], ...]}`, `closed` and
//! `tangents` optional; a B-spline as [`BSplineCurve`] serialises. Other keys are errors.
//!
//! ```
//! use batten::io::{read_points, write_points, ReadOptions};
//! # fn main() -> Result<(), batten::io::IoError> {
//! let dir = std::env::temp_dir().join(format!("batten-io-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).map_err(|source| batten::io::IoError::Write {
//!     path: dir.clone(),
//!     source,
//! })?;
//! let path = dir.join("arc.csv");
//! let pts: Vec<batten::Point> = (0..5)
//!     .map(|i| batten::Point::new(i as f64, (i * i) as f64 * 0.1))
//!     .collect();
//! write_points(&path, &pts, false, None)?;
//! let back = read_points(&path, &ReadOptions::default())?;
//! assert_eq!(back.seq.points(), &pts[..]);
//! assert_eq!(back.lines, vec![2, 3, 4, 5, 6]); // line 1 is the header
//! # std::fs::remove_dir_all(&dir).ok();
//! # Ok(())
//! # }
//! ```

mod atomic;
mod dxf;
mod error;
mod iges;
mod json;
mod limits;
mod number;
mod sig;
mod surface;
mod svg;
mod text;

use std::fs;
use std::path::{Path, PathBuf};

pub use atomic::{check_writable, remove_temporaries, write_atomic, write_atomic_set};
pub use dxf::{DxfCurve, DxfDrawing, DxfGeometry};
pub use error::{IoError, Location};
pub use limits::MAX_COORDINATE;
pub use number::format_f64;
pub use sig::format_sig;
pub use surface::{format_surface, parse_surface, read_surface_json, write_surface_json};

use crate::error::Error;
use crate::geom::{Point, PointSeq, SpaceSeq, Vec2, Xyz};
use crate::spline::BSplineCurve;
use text::Coords;

/// A file format, chosen by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Format {
    /// `.csv` or `.txt`: one `x,y` per line.
    Text,
    /// `.json`: a point list object or a B-spline object.
    Json,
    /// `.dxf`: LWPOLYLINE, POLYLINE or SPLINE entities (see [Other formats](#other-formats)).
    Dxf,
    /// `.igs` or `.iges`: entity 126 (rational B-spline curve) or 106 (copious data).
    Iges,
    /// `.svg`: a `<path>`, `<polyline>` or `<polygon>`.
    Svg,
}

impl Format {
    /// The format named by the extension of `path` (case-insensitive): `csv`/`txt` → text,
    /// `json` → JSON.
    ///
    /// # Errors
    /// [`IoError::UnknownFormat`] for any other extension or none.
    pub fn from_path(path: &Path) -> Result<Format, IoError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref().and_then(Format::from_name) {
            Some(f) => Ok(f),
            None => Err(IoError::UnknownFormat {
                path: path.to_path_buf(),
            }),
        }
    }

    /// The format of a name as given to `--format` or as an extension (lower case):
    /// `csv`/`txt`, `json`, `dxf`, `igs`/`iges`, `svg`.
    pub fn from_name(name: &str) -> Option<Format> {
        match name {
            "csv" | "txt" => Some(Format::Text),
            "json" => Some(Format::Json),
            "dxf" => Some(Format::Dxf),
            "igs" | "iges" => Some(Format::Iges),
            "svg" => Some(Format::Svg),
            _ => None,
        }
    }
}

/// How to read a point list.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct ReadOptions {
    /// Treat the points as a closed curve even if the file does not say so (a JSON file
    /// says so with `"closed": true`; a text file cannot).
    ///
    /// Default value: `false`.
    pub closed: bool,
}

impl ReadOptions {
    /// The defaults: closedness as the file says.
    pub const DEFAULT: ReadOptions = ReadOptions { closed: false };

    /// Force (or not) a closed curve.
    pub fn with_closed(mut self, closed: bool) -> ReadOptions {
        self.closed = closed;
        self
    }
}

impl Default for ReadOptions {
    fn default() -> ReadOptions {
        ReadOptions::DEFAULT
    }
}

/// A point list read from a file.
#[derive(Clone, Debug, PartialEq)]
pub struct PointData {
    /// The validated points, closed if the file or the options say so.
    pub seq: PointSeq,
    /// Tangents given with the points (JSON `tangents`), one per point.
    pub tangents: Option<Vec<Vec2>>,
    /// The 1-based line each point starts on, to name it in later messages.
    pub lines: Vec<usize>,
}

/// A space curve's points read from a file (text or JSON with `x, y, z`).
#[derive(Clone, Debug, PartialEq)]
pub struct SpaceData {
    /// The validated points, closed if the file or the options say so.
    pub seq: SpaceSeq,
    /// The 1-based line each point starts on.
    pub lines: Vec<usize>,
}

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
/// [`IoError::TooLarge`] (beyond [`MAX_COORDINATE`]), [`IoError::TooFewPoints`],
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
fn parse_text_or_json(
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
fn validate(
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
fn validate_space(
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

fn read_bytes(path: &Path) -> Result<Vec<u8>, IoError> {
    fs::read(path).map_err(|source| IoError::Read {
        path: path.to_path_buf(),
        source,
    })
}

/// Write a point list (format by extension), atomically (see [`write_atomic`]).
///
/// Text files get the header `x,y` and one row per point; `closed` and `tangents` are
/// written to JSON only (a text file has no place for them). Numbers are written in the
/// shortest form that reads back bit for bit ([`format_f64`] for text; serde_json's, which
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
/// with other files as one set ([`write_atomic_set`]).
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

/// Which curve to take from a file that can hold several (DXF, IGES, SVG), and how.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct Pick {
    /// DXF: the entity's handle (hexadecimal, any case); IGES: the directory entry's
    /// sequence number (`D` line of its first record).
    ///
    /// Default value: `None` (the only curve of the file).
    pub entity: Option<String>,
    /// DXF: the layer name; IGES: the level number.
    ///
    /// Default value: `None`.
    pub layer: Option<String>,
    /// SVG: the `id` of the element.
    ///
    /// Default value: `None`.
    pub id: Option<String>,
    /// SVG: take N points per segment of a path instead of its B-spline.
    ///
    /// Default value: `None`.
    pub sample: Option<usize>,
}

impl Pick {
    /// Pick by DXF handle or IGES directory entry.
    pub fn with_entity(mut self, entity: Option<String>) -> Pick {
        self.entity = entity;
        self
    }
    /// Pick by DXF layer or IGES level.
    pub fn with_layer(mut self, layer: Option<String>) -> Pick {
        self.layer = layer;
        self
    }
    /// Pick an SVG element by id.
    pub fn with_id(mut self, id: Option<String>) -> Pick {
        self.id = id;
        self
    }
    /// Sample SVG paths with N points per segment.
    pub fn with_sample(mut self, sample: Option<usize>) -> Pick {
        self.sample = sample;
        self
    }
}

/// Where a curve sat in its file, so that it can be written back alike.
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct Origin {
    /// The constant z of a planar curve from a 3-D format (DXF, IGES); written back.
    pub z: f64,
    /// The DXF layer (or IGES level) it was on.
    pub layer: Option<String>,
    /// Its name: DXF handle, IGES directory entry, SVG id.
    pub name: Option<String>,
}

/// What an input file holds.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    /// A validated point list.
    Points(PointData),
    /// A B-spline curve.
    Curve(BSplineCurve),
    /// A validated space curve (`x, y, z` points).
    Space(SpaceData),
}

/// A curve read from a file and where it sat.
#[derive(Clone, Debug, PartialEq)]
pub struct Input {
    /// The points or the curve.
    pub source: Source,
    /// Where it came from.
    pub origin: Origin,
}

/// What a format reader hands back before validation.
#[derive(Debug)]
pub(crate) enum Raw {
    /// Points with the 1-based line of each, closed or not.
    Points {
        points: Vec<Point>,
        lines: Vec<usize>,
        closed: bool,
    },
    /// A B-spline.
    Curve(BSplineCurve),
    /// Space points (a 3-D DXF POLYLINE, or SPLINE fit points, whose z varies).
    Space {
        points: Vec<Xyz>,
        lines: Vec<usize>,
        closed: bool,
    },
}

/// Parse any input format held in memory (a file's bytes, or standard input); `path` names
/// it in messages. Points are validated as by [`parse_points`]; a B-spline is returned as
/// it is.
///
/// # Errors
/// Everything [`parse_points`] reports, and [`IoError::Format`] for a malformed DXF, IGES or
/// SVG file, a 3-D curve (z not constant), or a choice the file leaves open.
pub fn parse_input(
    bytes: &[u8],
    format: Format,
    path: &Path,
    options: &ReadOptions,
    pick: &Pick,
) -> Result<Input, IoError> {
    let (raw, origin) = match format {
        Format::Text | Format::Json => {
            return Ok(Input {
                source: parse_text_or_json(bytes, format, path, options)?,
                origin: Origin::default(),
            });
        }
        Format::Dxf => dxf::parse(bytes, path, pick)?,
        Format::Iges => iges::parse(bytes, path, pick)?,
        Format::Svg => svg::parse(bytes, path, pick)?,
    };
    Ok(Input {
        source: validated(raw, path, options)?,
        origin,
    })
}

/// Validate what a format reader gave: points as [`parse_points`] does, a B-spline as it is.
fn validated(raw: Raw, path: &Path, options: &ReadOptions) -> Result<Source, IoError> {
    Ok(match raw {
        Raw::Points {
            points,
            lines,
            closed,
        } => Source::Points(PointData {
            seq: validate(path, points, &lines, closed || options.closed)?,
            tangents: None,
            lines,
        }),
        Raw::Curve(c) => Source::Curve(c),
        Raw::Space {
            points,
            lines,
            closed,
        } => Source::Space(SpaceData {
            seq: validate_space(path, points, &lines, closed || options.closed)?,
            lines,
        }),
    })
}

/// Read any input file (format by extension, or `format` when given).
///
/// # Errors
/// [`IoError::Read`], [`IoError::UnknownFormat`], and everything [`parse_input`] reports.
pub fn read_input(
    path: &Path,
    format: Option<Format>,
    options: &ReadOptions,
    pick: &Pick,
) -> Result<Input, IoError> {
    let format = match format {
        Some(f) => f,
        None => Format::from_path(path)?,
    };
    let bytes = read_bytes(path)?;
    parse_input(&bytes, format, path, options, pick)
}

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

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn parse(text: &str, options: &ReadOptions) -> Result<PointData, IoError> {
        parse_points(
            text.as_bytes(),
            Format::Text,
            Path::new("data.csv"),
            options,
        )
    }

    fn msg(text: &str) -> String {
        match parse(text, &ReadOptions::default()) {
            Ok(_) => panic!("expected an error for {text:?}"),
            Err(e) => e.to_string(),
        }
    }

    fn tempdir() -> PathBuf {
        use std::sync::atomic::{AtomicUsize, Ordering};
        static DIRS: AtomicUsize = AtomicUsize::new(0);
        let n = DIRS.fetch_add(1, Ordering::Relaxed);
        let d = std::env::temp_dir().join(format!("batten-io-test-{}-{n}", std::process::id()));
        fs::create_dir_all(&d).unwrap();
        d
    }

    const SQUARE: &str = "x,y\n0,0\n1,0\n1,1\n0,1\n";

    #[test]
    fn format_from_extension() {
        assert_eq!(Format::from_path(Path::new("a.csv")).unwrap(), Format::Text);
        assert_eq!(Format::from_path(Path::new("a.TXT")).unwrap(), Format::Text);
        assert_eq!(
            Format::from_path(Path::new("d/a.Json")).unwrap(),
            Format::Json
        );
        for bad in ["a.dat", "a", "a.csv.gz", ".csv"] {
            let e = Format::from_path(Path::new(bad)).unwrap_err().to_string();
            assert_eq!(
                e,
                format!(
                    "{bad}: unknown file format (use a .csv, .txt, .json, .dxf, .igs/.iges or .svg file name)"
                )
            );
        }
    }

    #[test]
    fn validation_errors_name_lines() {
        assert_eq!(msg(""), "data.csv: no points");
        assert_eq!(msg("# nothing\nx,y\n\n"), "data.csv: no points");
        assert_eq!(
            msg("x,y\n0,0\n1,1\n2,0\n"),
            "data.csv: 3 points, at least 4 needed"
        );
        assert_eq!(
            msg("x,y\n0,0\n1,1\n2,0\n3,1\n4,0\n# c\n\n4,0\n"),
            "data.csv:9: point duplicates the previous one (line 6)"
        );
        assert_eq!(
            msg("0,0\n1,1\n2,0\n3,1\n4,0\n5,1\n6,0\n7,1\n8,1\n8,1\n"),
            "data.csv:10: point duplicates the previous one (line 9)"
        );
        // A repeated first point is fine for an open curve, not for a closed one.
        let ring = "x,y\n0,0\n1,0\n1,1\n0,1\n0,0\n";
        assert!(parse(ring, &ReadOptions::default()).is_ok());
        let e = parse(ring, &ReadOptions::default().with_closed(true))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "data.csv:6: closed curve repeats its first point (line 2); leave the repeated point out"
        );
    }

    #[test]
    fn closed_from_options_or_json() {
        let d = parse(SQUARE, &ReadOptions::default()).unwrap();
        assert!(!d.seq.is_closed());
        assert_eq!(d.lines, vec![2, 3, 4, 5]);
        let d = parse(SQUARE, &ReadOptions::default().with_closed(true)).unwrap();
        assert!(d.seq.is_closed());
        let j = br#"{"points": [[0,0],[1,0],[1,1],[0,1]], "closed": true}"#;
        let d = parse_points(j, Format::Json, Path::new("c.json"), &ReadOptions::DEFAULT).unwrap();
        assert!(d.seq.is_closed());
    }

    #[test]
    fn json_validation_errors_name_lines() {
        let j = "{\"points\": [\n[0, 0],\n[1, 0],\n[1, 0],\n[2, 1]\n]}";
        let e = parse_points(
            j.as_bytes(),
            Format::Json,
            Path::new("d.json"),
            &ReadOptions::DEFAULT,
        )
        .unwrap_err()
        .to_string();
        assert_eq!(e, "d.json:4: point duplicates the previous one (line 3)");
        let j = "{\"points\": [[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]],\n \"closed\": true}";
        let e = parse_points(
            j.as_bytes(),
            Format::Json,
            Path::new("d.json"),
            &ReadOptions::DEFAULT,
        )
        .unwrap_err()
        .to_string();
        assert_eq!(
            e,
            "d.json:1: closed curve repeats its first point (line 1); leave the repeated point out"
        );
        let j = "{\"points\": [[0, 0], [1, 0], [1, 1], [0, 1]],\n \"tangents\": [[1, 0]]}";
        let e = parse_points(
            j.as_bytes(),
            Format::Json,
            Path::new("d.json"),
            &ReadOptions::DEFAULT,
        )
        .unwrap_err()
        .to_string();
        assert_eq!(e, "d.json: 1 tangent for 4 points");
        let e = parse_points(
            b"{\"points\": []}",
            Format::Json,
            Path::new("d.json"),
            &ReadOptions::DEFAULT,
        )
        .unwrap_err()
        .to_string();
        assert_eq!(e, "d.json: no points");
    }

    #[test]
    fn write_read_round_trip_both_formats() {
        let dir = tempdir();
        let pts = vec![
            Point::new(-0.0, 1e-300),
            Point::new(1e300, 5e-324),
            Point::new(0.1, -1.0 / 3.0),
            Point::new(f64::MIN_POSITIVE / 3.0, -MAX_COORDINATE),
            Point::new(std::f64::consts::PI, -1e-7),
        ];
        let tangents = vec![Vec2::new(0.6, 0.8); 5];
        for name in ["p.csv", "p.txt", "p.json"] {
            let path = dir.join(name);
            write_points(&path, &pts, false, Some(&tangents)).unwrap();
            let back = read_points(&path, &ReadOptions::DEFAULT).unwrap();
            assert_eq!(back.seq.len(), pts.len());
            for (a, b) in pts.iter().zip(back.seq.points()) {
                assert_eq!(a.x.to_bits(), b.x.to_bits(), "{name}");
                assert_eq!(a.y.to_bits(), b.y.to_bits(), "{name}");
            }
            let want_tangents = name.ends_with(".json").then(|| tangents.clone());
            assert_eq!(back.tangents, want_tangents);
        }
        let text = fs::read_to_string(dir.join("p.csv")).unwrap();
        assert!(text.starts_with("x,y\n-0,1e-300\n1e300,5e-324\n"), "{text}");
        // Closed, the last point must not nearly repeat the first (relative to the extent).
        let path = dir.join("closed.json");
        // Closed, these points would be refused: the closing chord, π, is 10⁻³⁰⁸ of the size.
        let square =
            [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].map(|(x, y)| Point::new(x, y));
        write_points(&path, &square, true, None).unwrap();
        assert!(
            read_points(&path, &ReadOptions::DEFAULT)
                .unwrap()
                .seq
                .is_closed()
        );
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn write_rejects_non_finite_and_unknown_format() {
        let dir = tempdir();
        let mut pts = vec![Point::new(0.0, 0.0); 4];
        pts[2].y = f64::NAN;
        let path = dir.join("o.csv");
        let e = write_points(&path, &pts, false, None)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            format!(
                "{}: cannot write point 2: NaN or infinite value",
                path.display()
            )
        );
        assert!(!path.exists());
        let path = dir.join("o.xyz");
        assert!(matches!(
            write_points(&path, &[], false, None),
            Err(IoError::UnknownFormat { .. })
        ));
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn atomic_write_replaces_and_leaves_no_temporaries() {
        let dir = tempdir();
        let path = dir.join("a.csv");
        fs::write(&path, "old").unwrap();
        write_atomic(&path, b"new").unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "new");
        let names: Vec<_> = fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("a.csv")]);
        // Into a missing directory: an error naming the target, nothing created.
        let missing = dir.join("no/such/dir/a.csv");
        let e = write_atomic(&missing, b"x").unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("{}: cannot write: ", missing.display())),
            "{e}"
        );
        // Over a directory: the rename fails and the temporary file is removed.
        fs::create_dir(dir.join("sub.csv")).unwrap();
        assert!(write_atomic(&dir.join("sub.csv"), b"x").is_err());
        let mut names: Vec<_> = fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        names.sort();
        assert_eq!(
            names,
            vec![std::ffi::OsString::from("a.csv"), "sub.csv".into()]
        );
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn ensure_distinct_sees_through_paths_and_links() {
        let dir = tempdir();
        let input = dir.join("in.csv");
        fs::write(&input, SQUARE).unwrap();
        fs::create_dir(dir.join("sub")).unwrap();
        assert!(ensure_distinct(&input, &dir.join("out.csv")).is_ok());
        assert!(ensure_distinct(&input, &dir.join("no/such/out.csv")).is_ok());
        let e = ensure_distinct(&input, &dir.join("sub/../in.csv")).unwrap_err();
        assert!(matches!(e, IoError::SameFile { .. }));
        assert!(e.to_string().starts_with("refusing to write "), "{e}");
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(&input, dir.join("link.csv")).unwrap();
            assert!(ensure_distinct(&input, &dir.join("link.csv")).is_err());
            fs::hard_link(&input, dir.join("hard.csv")).unwrap();
            assert!(ensure_distinct(&input, &dir.join("hard.csv")).is_err());
        }
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn read_errors_name_the_file() {
        let e = read_points(Path::new("/no/such/file.csv"), &ReadOptions::DEFAULT)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("/no/such/file.csv: cannot read: "), "{e}");
        let dir = tempdir();
        let p = dir.join("curve.json");
        fs::write(
            &p,
            r#"{"degree": 2, "knots": [0, 0, 0, 1, 1, 1], "control_points": [[0, 0], [1, 2], [2, 0]]}"#,
        )
        .unwrap();
        assert!(matches!(
            read_points(&p, &ReadOptions::DEFAULT),
            Err(IoError::CurveNotPoints { .. })
        ));
        assert_eq!(read_curve_json(&p).unwrap().degree(), 2);
        let csv = dir.join("c.csv");
        fs::write(&csv, SQUARE).unwrap();
        assert!(matches!(
            read_curve_json(&csv),
            Err(IoError::UnknownFormat { .. })
        ));
        fs::remove_dir_all(&dir).unwrap();
    }
}
