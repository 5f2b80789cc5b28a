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
//! untransformed; each module's documentation (`io/dxf.rs`, `io/iges/`, `io/svg/`) says
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
//! `tangents` optional; a B-spline as [`BSplineCurve`](crate::spline::BSplineCurve) serialises. Other keys are errors.
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
mod input;
mod json;
mod limits;
mod number;
mod output;
mod points;
mod sig;
mod surface;
mod svg;
mod text;

use std::path::Path;

pub use atomic::{
    Staged, check_writable, remove_temporaries, stage, write_atomic, write_atomic_set,
    write_atomic_set_staged,
};
pub use dxf::{DxfCurve, DxfDrawing, DxfGeometry};
pub use error::{IoError, Location};
pub use input::{Input, Origin, Pick, Source, parse_input, read_input};
pub use limits::MAX_COORDINATE;
pub use number::format_f64;
pub use output::{ensure_distinct, format_curve, format_points, format_space_points, svg_can_hold};
pub use points::{
    encode_points, parse_curve_json, parse_points, read_curve_json, read_points, write_points,
};
pub use sig::format_sig;
pub use surface::{format_surface, parse_surface, read_surface_json, write_surface_json};

use crate::geom::{PointSeq, SpaceSeq, Vec2};
use input::{Raw, validated};
use points::read_bytes;

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

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests;
