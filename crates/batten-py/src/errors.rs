//! Library errors as Python exceptions, with the CLI's one-line messages.
//!
//! What the CLI reports as bad input or usage (exit 2) is a `ValueError`; what it reports as a
//! failed computation (exit 1) is a `batten.FairError`. A missed tolerance is neither: the
//! report says so (`report["tolerance_met"]` is false), as the CLI's report does.

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;

create_exception!(
    batten,
    FairError,
    PyException,
    "A fairing (or an analysis) that failed on valid input: a singular system, degenerate \
     geometry, no convergence. The message is the CLI's."
);

/// Whether the CLI treats `e` as bad input or usage (exit 2) rather than a failed
/// computation (exit 1): the same split as `batten-cli`'s `Failure::from_batten`.
fn is_usage(e: &batten::Error) -> bool {
    use batten::Error as E;
    matches!(
        e,
        E::UnknownMethod { .. }
            | E::UnknownOption { .. }
            | E::InvalidParameter { .. }
            | E::ClosedUnsupported { .. }
            | E::PlanarOnly { .. }
            | E::TooFewPoints { .. }
            | E::NonFinite { .. }
            | E::DuplicatePoint { .. }
            | E::NearDuplicate { .. }
    )
}

/// `e` as a Python exception, its message prefixed with `what` (`method mst failed`) unless
/// that is empty.
pub fn library(what: &str, e: &batten::Error) -> PyErr {
    let message = if what.is_empty() {
        e.to_string()
    } else {
        format!("{what}: {e}")
    };
    if is_usage(e) {
        PyValueError::new_err(message)
    } else {
        FairError::new_err(message)
    }
}

/// A `ValueError` with `message`.
pub fn value(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

/// `err` with `prefix: ` put in front of its message, same type (for `curves[3]: ...`).
pub fn prefixed(py: Python<'_>, prefix: &str, err: PyErr) -> PyErr {
    let message = err.value(py).to_string();
    if err.is_instance_of::<FairError>(py) {
        FairError::new_err(format!("{prefix}: {message}"))
    } else if err.is_instance_of::<PyValueError>(py) {
        PyValueError::new_err(format!("{prefix}: {message}"))
    } else {
        err
    }
}
