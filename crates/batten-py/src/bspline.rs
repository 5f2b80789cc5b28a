//! `batten.BSpline`: a B-spline (or NURBS) curve, for the methods that fair control points.

use batten::Curve as _;
use batten::spline::{BSplineCurve, KnotVector};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use crate::{convert, errors};

/// A B-spline curve of any degree: `degree`, `knots` (length `len(control_points) + degree +
/// 1`), `control_points` (an `(m, 2)` array) and optional positive `weights` (NURBS).
///
/// `batten.fair(curve, method="salvi")` fairs it as it is (knots and degree kept) with the
/// methods whose `bspline_input` is true in `batten.methods()`; `FairResult.curve` is the
/// faired curve of the methods that work on one.
#[pyclass(frozen, module = "batten", name = "BSpline")]
#[derive(Clone, Debug)]
pub struct BSpline {
    curve: BSplineCurve,
}

impl BSpline {
    /// Wrap a library curve.
    pub fn from_curve(curve: BSplineCurve) -> BSpline {
        BSpline { curve }
    }

    /// The library curve.
    pub fn curve(&self) -> &BSplineCurve {
        &self.curve
    }
}

#[pymethods]
impl BSpline {
    #[new]
    #[pyo3(signature = (degree, knots, control_points, weights = None))]
    fn new(
        degree: usize,
        knots: &Bound<'_, PyAny>,
        control_points: &Bound<'_, PyAny>,
        weights: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<BSpline> {
        // Every problem with the arguments is bad input (a ValueError), as a malformed curve
        // file is for the CLI.
        let knots = KnotVector::try_new(convert::vector(knots, "knots")?)
            .map_err(|e| errors::value(e.to_string()))?;
        let control_points = convert::points(control_points, "control_points")?;
        let weights = match weights.filter(|w| !w.is_none()) {
            Some(w) => Some(convert::vector(w, "weights")?),
            None => None,
        };
        let curve = BSplineCurve::try_new(degree, knots, control_points, weights)
            .map_err(|e| errors::value(e.to_string()))?;
        Ok(BSpline { curve })
    }

    /// The degree p.
    #[getter]
    fn degree(&self) -> usize {
        self.curve.degree()
    }

    /// The knot vector, a 1-D array.
    #[getter]
    fn knots<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        convert::vector_array(py, self.curve.knots().as_slice())
    }

    /// The control points, an `(m, 2)` array.
    #[getter]
    fn control_points<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        convert::points_array(py, self.curve.control_points())
    }

    /// The weights (a 1-D array), or `None` for a non-rational B-spline.
    #[getter]
    fn weights<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.curve.weights().map(|w| convert::vector_array(py, w))
    }

    /// The parameter domain `(t_min, t_max)`.
    #[getter]
    fn domain(&self) -> (f64, f64) {
        self.curve.domain()
    }

    /// The curve's points at the parameters `t` (a 1-D array-like, clamped to the domain),
    /// as an `(len(t), 2)` array.
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let t = convert::vector(t, "t")?;
        if t.iter().any(|x| !x.is_finite()) {
            return Err(errors::value("t: NaN or infinite parameter"));
        }
        let (lo, hi) = self.curve.domain();
        let points: Vec<_> = t
            .iter()
            .map(|&x| self.curve.eval(x.clamp(lo, hi)))
            .collect();
        Ok(convert::points_array(py, &points))
    }

    fn __repr__(&self) -> String {
        format!(
            "BSpline(degree={}, control_points={}, knots={}{})",
            self.curve.degree(),
            self.curve.control_points().len(),
            self.curve.knots().len(),
            if self.curve.weights().is_some() {
                ", rational"
            } else {
                ""
            }
        )
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<BSpline>()
            .is_ok_and(|o| o.get().curve == self.curve)
    }

    /// Pickle support (Dask moves results between processes): the constructor's arguments.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let py = slf.py();
        let me = slf.get();
        let args = PyTuple::new(
            py,
            [
                me.degree().into_pyobject(py)?.into_any(),
                me.knots(py).into_any(),
                me.control_points(py).into_any(),
                match me.weights(py) {
                    Some(w) => w.into_any(),
                    None => py.None().into_bound(py),
                },
            ],
        )?;
        Ok((py.get_type::<BSpline>().into_any(), args))
    }
}
