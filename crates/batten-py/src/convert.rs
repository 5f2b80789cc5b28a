//! numpy arrays in, numpy arrays and plain Python values out.

use batten::{Point, Xyz};
use numpy::ndarray::Array2;
use numpy::{PyArray1, PyArray2, PyArrayDyn, PyArrayMethods as _, PyUntypedArrayMethods as _};
use pyo3::prelude::*;

use crate::errors;

/// `obj` as a float64 numpy array: itself when it already is one, else `numpy.asarray(obj,
/// "float64")` (lists, integer arrays, pandas columns).
fn float_array<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if let Ok(a) = obj.cast::<PyArrayDyn<f64>>() {
        return Ok(a.clone());
    }
    let py = obj.py();
    let converted = py
        .import("numpy")?
        .getattr("asarray")?
        .call1((obj, "float64"))
        .map_err(|e| errors::value(format!("{what}: not an array of numbers: {}", e.value(py))))?;
    Ok(converted.cast_into::<PyArrayDyn<f64>>()?)
}

/// Points from an array-like: `(n, 2)` (x, y) or `(n, 3)` (x, y, z).
#[derive(Debug)]
pub enum Points {
    /// A planar curve.
    Planar(Vec<Point>),
    /// A space curve.
    Space(Vec<Xyz>),
}

/// Points from an `(n, 2)` or `(n, 3)` array-like.
pub fn points_any(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Points> {
    let array = float_array(obj, what)?;
    let shape = array.shape().to_vec();
    let view = array.try_readonly()?;
    let view = view.as_array();
    // An array in C order (what numpy makes by default) is read as one slice; others (Fortran
    // order, strided views) row by row.
    if let (Some(flat), [_, 2]) = (view.as_slice(), shape.as_slice()) {
        return Ok(Points::Planar(
            flat.chunks_exact(2)
                .map(|xy| Point::new(xy[0], xy[1]))
                .collect(),
        ));
    }
    match shape.as_slice() {
        [_, 2] => Ok(Points::Planar(
            view.outer_iter()
                .map(|row| Point::new(row[0], row[1]))
                .collect(),
        )),
        [_, 3] => Ok(Points::Space(
            view.outer_iter()
                .map(|row| [row[0], row[1], row[2]])
                .collect(),
        )),
        _ => Err(errors::value(format!(
            "{what}: expected an (n, 2) array of x, y or an (n, 3) array of x, y, z, got shape {}",
            shape_text(&shape)
        ))),
    }
}

/// Planar points from an `(n, 2)` array-like (B-spline control points: the library's
/// B-splines are planar).
pub fn points(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<Point>> {
    match points_any(obj, what)? {
        Points::Planar(p) => Ok(p),
        Points::Space(p) => Err(errors::value(format!(
            "{what}: expected an (n, 2) array of x, y, got shape ({}, 3)",
            p.len()
        ))),
    }
}

/// A 1-D array-like of numbers.
pub fn vector(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    let array = float_array(obj, what)?;
    if array.ndim() != 1 {
        return Err(errors::value(format!(
            "{what}: expected a 1-D array, got shape {}",
            shape_text(array.shape())
        )));
    }
    let view = array.try_readonly()?;
    Ok(view.as_array().iter().copied().collect())
}

/// `(3, 2)` as Python writes a shape.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// An `(n, 2)` array of the points' x, y.
pub fn points_array<'py>(py: Python<'py>, points: &[Point]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = points.iter().flat_map(|p| [p.x, p.y]).collect();
    // `flat` holds exactly 2·n values, so the shape always fits.
    match Array2::from_shape_vec((points.len(), 2), flat) {
        Ok(a) => PyArray2::from_owned_array(py, a),
        Err(_) => PyArray2::zeros(py, [0, 2], false),
    }
}

/// An `(n, 3)` array of space points.
pub fn space_array<'py>(py: Python<'py>, points: &[Xyz]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = points.iter().flatten().copied().collect();
    // `flat` holds exactly 3·n values, so the shape always fits.
    match Array2::from_shape_vec((points.len(), 3), flat) {
        Ok(a) => PyArray2::from_owned_array(py, a),
        Err(_) => PyArray2::zeros(py, [0, 3], false),
    }
}

/// A 1-D array.
pub fn vector_array<'py>(py: Python<'py>, values: &[f64]) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, values)
}

/// A serialisable value as Python: `json.loads` of its JSON text, so that a report is exactly
/// what `json.load` gives for the CLI's `--report` file (same keys in the same order, whole
/// numbers from an `f64` as `float`, NaN as `None`).
pub fn to_py<'py>(py: Python<'py>, value: &impl serde::Serialize) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value)
        .map_err(|e| errors::value(format!("cannot encode the result: {e}")))?;
    py.import("json")?.getattr("loads")?.call1((text,))
}
