//! `batten._batten`: the Python extension of the `batten` package (PyO3 + numpy).
//!
//! A thin wrapper over the library: every function here converts its arguments, calls the
//! library, and converts the result back; no fairing, analysis or checking of its own beyond
//! what the CLI's flags do. The names and JSON keys are the CLI's:
//!
//! - `fair(points, method=None, tolerance=None, fix_ends=None, max_iterations=None,
//!   closed=False, **params)` is `batten fair` (the report is `--report`'s JSON as a dict);
//! - `fair_many(curves, ...)` fairs a list of curves in parallel (rayon), the GIL released;
//! - `analyze(points, closed=False)` is `batten analyze --json`;
//! - points are an `(n, 2)` array, or `(n, 3)` for a space curve (`band`, `mst`, `analyze`);
//! - `methods()` is `batten methods --json`;
//! - `BSpline` carries B-spline curves in and out; `FairError` is a failed fair.
//!
//! The Python side (`python/batten/`) re-exports these, adds `batten.dask`, and ships the
//! type stubs.

mod bspline;
mod convert;
mod errors;
mod options;
mod result;

use batten::FairnessMetrics;
use batten::fair as library;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;

use crate::bspline::BSpline;
use crate::errors::FairError;
use crate::options::{Input, Refused, Request};
use crate::result::FairResult;

/// Fair one curve; see the package docs (`batten.fair`).
#[pyfunction]
#[pyo3(signature = (points, method = None, tolerance = None, fix_ends = None,
                    max_iterations = None, closed = false, **params))]
#[allow(clippy::too_many_arguments)] // the Python signature, keyword by keyword
fn fair(
    py: Python<'_>,
    points: &Bound<'_, PyAny>,
    method: Option<&str>,
    tolerance: Option<&Bound<'_, PyAny>>,
    fix_ends: Option<&Bound<'_, PyAny>>,
    max_iterations: Option<&Bound<'_, PyAny>>,
    closed: bool,
    params: Option<&Bound<'_, PyDict>>,
) -> PyResult<FairResult> {
    let request = Request::new(method, tolerance, fix_ends, max_iterations, closed, params)?;
    let input = request.input(points, closed)?;
    let faired = py
        .detach(|| request.run(&input))
        .map_err(|e| request.error(&e))?;
    FairResult::new(py, faired)
}

/// Fair many curves in parallel; see the package docs (`batten.fair_many`).
#[pyfunction]
#[pyo3(signature = (curves, method = None, tolerance = None, fix_ends = None,
                    max_iterations = None, closed = false, **params))]
#[allow(clippy::too_many_arguments)] // the Python signature, keyword by keyword
fn fair_many(
    py: Python<'_>,
    curves: &Bound<'_, PyAny>,
    method: Option<&str>,
    tolerance: Option<&Bound<'_, PyAny>>,
    fix_ends: Option<&Bound<'_, PyAny>>,
    max_iterations: Option<&Bound<'_, PyAny>>,
    closed: bool,
    params: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<FairResult>> {
    let request = Request::new(method, tolerance, fix_ends, max_iterations, closed, params)?;
    // Read every curve (with Python), then validate them all (without it, in parallel), and
    // raise the first problem in the list's order, as one loop reading and validating each
    // curve in turn would.
    let mut reads = Vec::new();
    let mut unread = None;
    for (i, obj) in curves.try_iter()?.enumerate() {
        match obj.and_then(|obj| {
            request
                .read(&obj, closed)
                .map_err(|e| errors::prefixed(py, &format!("curves[{i}]"), e))
        }) {
            Ok(read) => reads.push(read),
            Err(e) => {
                unread = Some(e);
                break;
            }
        }
    }
    let checked: Vec<Result<Input, Refused>> = py.detach(|| {
        reads
            .into_par_iter()
            .map(|read| request.validate(read, closed))
            .collect()
    });
    let mut inputs: Vec<Input> = Vec::with_capacity(checked.len());
    for (i, input) in checked.into_iter().enumerate() {
        match input {
            Ok(input) => inputs.push(input),
            Err(refused) => {
                return Err(errors::prefixed(
                    py,
                    &format!("curves[{i}]"),
                    refused.to_py(),
                ));
            }
        }
    }
    if let Some(e) = unread {
        return Err(e);
    }
    let outcomes: Vec<Result<options::Output, batten::Error>> =
        py.detach(|| inputs.par_iter().map(|input| request.run(input)).collect());
    outcomes
        .into_iter()
        .enumerate()
        .map(|(i, outcome)| match outcome {
            Ok(faired) => FairResult::new(py, faired),
            Err(e) => Err(errors::prefixed(
                py,
                &format!("curves[{i}]"),
                request.error(&e),
            )),
        })
        .collect()
}

/// For the bench (`bench/python_speed.py`): the library's own time per call, in seconds, of
/// fairing the same input `repeat` times with these options, with no conversion to or from
/// Python inside the loop. `batten.fair`'s time minus this is the binding's overhead.
#[pyfunction]
#[pyo3(signature = (points, repeat, method = None, tolerance = None, fix_ends = None,
                    max_iterations = None, closed = false, **params))]
#[allow(clippy::too_many_arguments)] // the Python signature, keyword by keyword
fn _rust_seconds_per_call(
    py: Python<'_>,
    points: &Bound<'_, PyAny>,
    repeat: usize,
    method: Option<&str>,
    tolerance: Option<&Bound<'_, PyAny>>,
    fix_ends: Option<&Bound<'_, PyAny>>,
    max_iterations: Option<&Bound<'_, PyAny>>,
    closed: bool,
    params: Option<&Bound<'_, PyDict>>,
) -> PyResult<f64> {
    let request = Request::new(method, tolerance, fix_ends, max_iterations, closed, params)?;
    let input = request.input(points, closed)?;
    let repeat = repeat.max(1);
    py.detach(|| {
        let start = std::time::Instant::now();
        for _ in 0..repeat {
            std::hint::black_box(request.run(std::hint::black_box(&input)))
                .map_err(|e| request.error(&e))?;
        }
        Ok(start.elapsed().as_secs_f64() / repeat as f64)
    })
}

/// The fairness metrics of the curve through the points: `batten analyze --json` as a dict.
#[pyfunction]
#[pyo3(signature = (points, closed = false))]
fn analyze<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    closed: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let failed = |e| errors::library("cannot analyse", &e);
    match convert::points_any(points, "points")? {
        convert::Points::Planar(points) => {
            let seq =
                batten::PointSeq::new(points, closed).map_err(|e| errors::library("points", &e))?;
            let metrics = py
                .detach(|| FairnessMetrics::of_seq(&seq))
                .map_err(failed)?;
            convert::to_py(py, &metrics)
        }
        convert::Points::Space(points) => {
            let seq =
                batten::SpaceSeq::new(points, closed).map_err(|e| errors::library("points", &e))?;
            let metrics = py
                .detach(|| batten::analysis::SpaceMetrics::of_seq(&seq))
                .map_err(failed)?;
            convert::to_py(py, &metrics)
        }
    }
}

/// The fairing methods, the default first: `batten methods --json` as a list of dicts.
#[pyfunction]
fn methods(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    Ok(convert::to_py(py, &library::catalogue())?.cast_into::<PyList>()?)
}

/// The name of the default method (the first of `methods()`).
#[pyfunction]
fn default_method() -> &'static str {
    library::default_method()
}

#[pymodule]
fn _batten(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("FairError", m.py().get_type::<FairError>())?;
    m.add_class::<BSpline>()?;
    m.add_class::<FairResult>()?;
    m.add_function(wrap_pyfunction!(fair, m)?)?;
    m.add_function(wrap_pyfunction!(fair_many, m)?)?;
    m.add_function(wrap_pyfunction!(analyze, m)?)?;
    m.add_function(wrap_pyfunction!(methods, m)?)?;
    m.add_function(wrap_pyfunction!(default_method, m)?)?;
    m.add_function(wrap_pyfunction!(result::_restore_fair_result, m)?)?;
    m.add_function(wrap_pyfunction!(_rust_seconds_per_call, m)?)?;
    Ok(())
}
