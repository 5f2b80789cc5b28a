//! The library's error type. Every fallible public function returns [`Result`].

use thiserror::Error;

/// Everything that can go wrong in batten. Bad input is reported, never "repaired".
///
/// Indices in messages are 0-based positions in the slice that was passed in; the I/O layer
/// maps them back to file lines.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// Fewer points (or control points) than the operation needs.
    #[error("too few points: {needed} needed, {got} given")]
    TooFewPoints {
        /// The minimum the operation needs.
        needed: usize,
        /// How many were given.
        got: usize,
    },
    /// A coordinate or parameter is NaN or infinite.
    #[error("point {index} is not finite (NaN or infinity)")]
    NonFinite {
        /// Index of the offending point or value.
        index: usize,
    },
    /// Two consecutive points coincide, so the chord between them has zero length.
    #[error("point {index} duplicates the point before it (zero-length chord)")]
    DuplicatePoint {
        /// Index of the second of the two equal points.
        index: usize,
    },
    /// Two consecutive points are closer than [`crate::geom::NEAR_DUPLICATE_REL`] of the
    /// curve's size: their chord is rounding, not shape.
    #[error(
        "points {previous} and {index} (counting from 0) are {relative:.1e} of the curve's size \
         apart, closer than {limit:e}: near-duplicate points",
        limit = crate::geom::NEAR_DUPLICATE_REL
    )]
    NearDuplicate {
        /// Index of the second of the two points.
        index: usize,
        /// Index of the first (the point before it, or the last of a closed curve).
        previous: usize,
        /// Their distance over the larger side of the bounding box.
        relative: f64,
    },
    /// Abscissae of a function spline are not strictly increasing.
    #[error("x values must be strictly increasing: x[{index}] <= x[{prev}]", prev = index - 1)]
    NotIncreasing {
        /// Index of the first value that is not larger than its predecessor.
        index: usize,
    },
    /// A knot vector is invalid (NaN, decreasing, wrong length, too high multiplicity).
    #[error("invalid knot vector: {0}")]
    InvalidKnots(String),
    /// Two arrays that must have equal length do not.
    #[error("length mismatch: {what} has {got} entries, expected {expected}")]
    LengthMismatch {
        /// Which array is wrong.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The length it should have.
        expected: usize,
    },
    /// A parameter value is outside its allowed range or malformed.
    #[error("invalid value for {name}: {reason}")]
    InvalidParameter {
        /// Name of the parameter.
        name: String,
        /// Why the value is rejected.
        reason: String,
    },
    /// An option that the chosen method does not know.
    #[error("unknown option '{key}' for method {method} (known: {known})")]
    UnknownOption {
        /// The method.
        method: String,
        /// The unknown key.
        key: String,
        /// Comma-separated list of the keys the method accepts.
        known: String,
    },
    /// A method name that is not in the registry.
    #[error("unknown method '{name}' (known: {known})")]
    UnknownMethod {
        /// The name asked for.
        name: String,
        /// Comma-separated list of registered methods.
        known: String,
    },
    /// The method fairs planar curves only, and the input is a space curve.
    #[error(
        "method {method} fairs planar curves only; a 3-D curve is faired by band or mst \
         (--method band)"
    )]
    PlanarOnly {
        /// The method.
        method: String,
    },
    /// The method cannot handle closed curves.
    #[error("method {method} does not support closed curves")]
    ClosedUnsupported {
        /// The method.
        method: String,
    },
    /// A linear system was singular or too ill-conditioned to solve reliably.
    #[error("singular system: {0}")]
    Singular(String),
    /// The input geometry does not allow the operation (e.g. a segment that is not a function
    /// in any frame, a curve with zero length).
    #[error("degenerate geometry: {0}")]
    Degenerate(String),
    /// An iterative computation did not converge.
    #[error("no convergence: {0}")]
    NoConvergence(String),
}

/// Shorthand for `std::result::Result<T, batten::Error>`.
pub type Result<T> = std::result::Result<T, Error>;
