//! [`IoError`]: what can go wrong reading or writing a point file.

use std::path::PathBuf;

use thiserror::Error;

/// An error of the I/O layer. Every variant names the file; those about one place in it also
/// name the 1-based line, so that the message reads as one line such as
/// `data.csv:7: field 2 'abc' is not a number`.
///
/// Bad input is rejected, never repaired: no rows are dropped, sorted or merged.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum IoError {
    /// The file could not be opened or read.
    #[error("{}: cannot read: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        #[source]
        source: std::io::Error,
    },
    /// The file could not be written (or the temporary file beside it could not be created or
    /// renamed over it).
    #[error("{}: cannot write: {source}", path.display())]
    Write {
        /// The file that was to be written.
        path: PathBuf,
        /// What the operating system said.
        #[source]
        source: std::io::Error,
    },
    /// The file name's extension names no supported format.
    #[error(
        "{}: unknown file format (use a .csv, .txt, .json, .dxf, .igs/.iges or .svg file name)",
        path.display()
    )]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// A line of a text file is not valid UTF-8.
    #[error("{}:{line}: not valid UTF-8 text", path.display())]
    NotUtf8 {
        /// The file.
        path: PathBuf,
        /// The 1-based line holding the first invalid byte.
        line: usize,
    },
    /// The file holds no points at all (it is empty, or only comments, blank lines and a
    /// header; or a JSON `points` array is empty).
    #[error("{}: no points", path.display())]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// A row (a text line, or one JSON point or tangent) does not have exactly two fields.
    #[error("{}:{line}: expected {expected}, found {found}", path.display())]
    FieldCount {
        /// The file.
        path: PathBuf,
        /// The 1-based line of the row.
        line: usize,
        /// How many fields the row has.
        found: usize,
        /// What the row must hold (`2 fields (x, y)`, `3 fields (x, y, z)`, or either).
        expected: &'static str,
    },
    /// A field is not a number.
    #[error("{}:{line}: field {field} '{text}' is not a number", path.display())]
    NotANumber {
        /// The file.
        path: PathBuf,
        /// The 1-based line of the row.
        line: usize,
        /// The 1-based position of the field in the row.
        field: usize,
        /// The field as written (control characters escaped, long fields shortened).
        text: String,
    },
    /// A coordinate is NaN or infinite (including numbers too large for an `f64`, which
    /// parse as infinity).
    #[error("{}:{line}: NaN or infinite value", path.display())]
    NonFinite {
        /// The file.
        path: PathBuf,
        /// The 1-based line of the point.
        line: usize,
    },
    /// A coordinate beyond [`super::MAX_COORDINATE`] in magnitude.
    #[error(
        "{}:{line}: coordinate {} is beyond ±1e300, the largest magnitude batten takes \
         (rescale the data)",
        path.display(),
        super::format_f64(*value)
    )]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// The 1-based line of the point.
        line: usize,
        /// The coordinate.
        value: f64,
    },
    /// A point nearly duplicates its neighbour: closer than
    /// [`crate::geom::NEAR_DUPLICATE_REL`] times the larger side of the bounding box (the
    /// library's [`crate::Error::NearDuplicate`], with lines).
    #[error(
        "{}:{line}: point nearly duplicates the one on line {other} ({relative:.1e} of the \
         curve's size apart, under {limit:e}); remove one of them",
        path.display(),
        limit = crate::geom::NEAR_DUPLICATE_REL
    )]
    NearDuplicate {
        /// The file.
        path: PathBuf,
        /// The 1-based line of the later point.
        line: usize,
        /// The 1-based line of the point it nearly repeats.
        other: usize,
        /// Their distance over the larger side of the bounding box.
        relative: f64,
    },
    /// Fewer points than batten needs ([`crate::PointSeq::MIN_POINTS`]).
    #[error("{}: {got} point{}, at least {needed} needed", path.display(), plural(*got))]
    TooFewPoints {
        /// The file.
        path: PathBuf,
        /// How many points the file holds.
        got: usize,
        /// The minimum.
        needed: usize,
    },
    /// A point equals the one before it (a zero-length chord).
    #[error(
        "{}:{line}: point duplicates the previous one (line {previous})",
        path.display()
    )]
    DuplicatePoint {
        /// The file.
        path: PathBuf,
        /// The 1-based line of the repeated point.
        line: usize,
        /// The 1-based line of the point it repeats.
        previous: usize,
    },
    /// A closed curve ends with a copy of its first point. Closed curves are given without
    /// the repeated point: the closing chord is implied.
    #[error(
        "{}:{line}: closed curve repeats its first point (line {first}); leave the repeated point out",
        path.display()
    )]
    RepeatsFirst {
        /// The file.
        path: PathBuf,
        /// The 1-based line of the last point.
        line: usize,
        /// The 1-based line of the first point.
        first: usize,
    },
    /// The JSON is malformed or does not have the expected shape. `message` is serde_json's,
    /// prefixed with "malformed JSON: " for syntax errors.
    #[error("{}:{line}:{column}: {message}", path.display())]
    Json {
        /// The file.
        path: PathBuf,
        /// The 1-based line serde_json reported.
        line: usize,
        /// The 1-based column serde_json reported.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// The JSON is well formed and has the expected keys, but a value is rejected where
    /// serde_json cannot say where (a B-spline the library refuses, e.g. a knot vector of the
    /// wrong length).
    #[error("{}: {message}", path.display())]
    JsonContent {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A DXF, IGES or SVG file is malformed, holds something batten does not take (a 3-D
    /// curve, an arc, a transform), or does not say which of its curves to take. `message`
    /// names the entity (DXF handle, IGES directory entry, SVG element) where there is one.
    #[error("{}{at}: {message}", path.display())]
    Format {
        /// The file.
        path: PathBuf,
        /// Where in the file, as far as the format can tell.
        at: Location,
        /// What is wrong.
        message: String,
    },
    /// A JSON point list whose `tangents` array has a different length than `points`.
    #[error(
        "{}: {got} tangent{} for {expected} point{}",
        path.display(),
        plural(*got),
        plural(*expected)
    )]
    TangentCount {
        /// The file.
        path: PathBuf,
        /// Number of tangents.
        got: usize,
        /// Number of points.
        expected: usize,
    },
    /// A point list was asked for, but the JSON file holds a B-spline curve.
    #[error(
        "{}: the file holds a B-spline curve (degree, knots, control_points), not a point list",
        path.display()
    )]
    CurveNotPoints {
        /// The file.
        path: PathBuf,
    },
    /// Planar points were asked for, and the file holds a space curve.
    #[error(
        "{}: the file holds a 3-D curve (x, y, z points), not a planar one",
        path.display()
    )]
    SpaceNotPlanar {
        /// The file.
        path: PathBuf,
    },
    /// A B-spline curve was asked for, but the JSON file holds a point list.
    #[error("{}: the file holds a point list, not a B-spline curve", path.display())]
    PointsNotCurve {
        /// The file.
        path: PathBuf,
    },
    /// The data parsed, but the library rejected it for a reason that has no single line.
    #[error("{}: {source}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The library's reason.
        #[source]
        source: crate::Error,
    },
    /// A point to be written is NaN or infinite; it could not be read back.
    #[error("{}: cannot write point {index}: NaN or infinite value", path.display())]
    NonFiniteOutput {
        /// The file that was to be written.
        path: PathBuf,
        /// The 0-based index of the point (or tangent).
        index: usize,
    },
    /// The output path is the input file (after resolving links), which is never overwritten.
    #[error(
        "refusing to write {}: it is the input file {}",
        output.display(),
        input.display()
    )]
    SameFile {
        /// The input path as given.
        input: PathBuf,
        /// The output path as given.
        output: PathBuf,
    },
}

/// The plural ending of a count: "1 point", "2 points".
fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}

/// A place in a file, for [`IoError::Format`]: displayed as nothing, `:LINE` or
/// `:LINE:COLUMN` after the file name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Location {
    /// The file as a whole (the message names the entity).
    File,
    /// A 1-based line.
    Line(usize),
    /// A 1-based line and column.
    LineColumn(usize, usize),
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Location::File => Ok(()),
            Location::Line(l) => write!(f, ":{l}"),
            Location::LineColumn(l, c) => write!(f, ":{l}:{c}"),
        }
    }
}

/// A message from another crate on one line: control characters (a newline it quotes from
/// the file) written as escapes.
pub(crate) fn one_line(message: &str) -> String {
    message
        .chars()
        .flat_map(|c| {
            let escaped: Vec<char> = if c.is_control() {
                c.escape_default().collect()
            } else {
                vec![c]
            };
            escaped
        })
        .collect()
}
