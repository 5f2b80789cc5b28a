//! `batten.FairResult`: the faired points, the report, and the method's curve.

use batten::FairReport;
use batten::fair::SpaceFairReport;
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyTuple;

use crate::bspline::BSpline;
use crate::convert;
use crate::options::Output;

/// The library's report, planar or for a space curve.
#[derive(Debug)]
enum Report {
    Planar(FairReport),
    Space(SpaceFairReport),
}

/// What `batten.fair` returns: `points` (an `(n, 2)` or `(n, 3)` array, as the input: same
/// count and order as the
/// input), `report` (a dict with the keys and values of the CLI's `--report` JSON), `curve`
/// (the method's B-spline, or `None`) and `tangents` (an `(n, 2)` array for methods that
/// carry tangents, else `None`).
#[pyclass(frozen, module = "batten", name = "FairResult")]
pub struct FairResult {
    points: Py<PyArray2<f64>>,
    /// The report as the library made it, turned into a dict when first asked for (most of
    /// a fast call's cost would be that dict, and many callers only want the points).
    source: Option<Report>,
    report: PyOnceLock<Py<PyAny>>,
    curve: Option<Py<BSpline>>,
    tangents: Option<Py<PyArray2<f64>>>,
}

impl std::fmt::Debug for FairResult {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FairResult")
            .field("points", &self.points)
            .field("source", &self.source)
            .field("curve", &self.curve)
            .field("tangents", &self.tangents)
            .finish_non_exhaustive()
    }
}

impl FairResult {
    /// Wrap the library's result.
    pub fn new(py: Python<'_>, output: Output) -> PyResult<FairResult> {
        let faired = match output {
            Output::Planar(f) => f,
            Output::Space(f) => {
                return Ok(FairResult {
                    points: convert::space_array(py, &f.points).unbind(),
                    source: Some(Report::Space(f.report)),
                    report: PyOnceLock::new(),
                    curve: None,
                    tangents: None,
                });
            }
        };
        Ok(FairResult {
            points: convert::points_array(py, &faired.points).unbind(),
            source: Some(Report::Planar(faired.report)),
            report: PyOnceLock::new(),
            curve: match faired.curve {
                Some(c) => Some(Py::new(py, BSpline::from_curve(c))?),
                None => None,
            },
            tangents: faired.tangents.map(|t| {
                let pts: Vec<batten::Point> =
                    t.iter().map(|v| batten::Point::new(v.x, v.y)).collect();
                convert::points_array(py, &pts).unbind()
            }),
        })
    }

    fn report_object<'py>(&self, py: Python<'py>) -> PyResult<&Bound<'py, PyAny>> {
        let r = self.report.get_or_try_init(py, || -> PyResult<Py<PyAny>> {
            match &self.source {
                Some(Report::Planar(report)) => Ok(convert::to_py(py, report)?.unbind()),
                Some(Report::Space(report)) => Ok(convert::to_py(py, report)?.unbind()),
                None => Ok(pyo3::types::PyDict::new(py).into_any().unbind()),
            }
        })?;
        Ok(r.bind(py))
    }
}

#[pymethods]
impl FairResult {
    /// The faired points, an `(n, 2)` array (`(n, 3)` for a space curve).
    #[getter]
    fn points(&self, py: Python<'_>) -> Py<PyArray2<f64>> {
        self.points.clone_ref(py)
    }

    /// The fairing report: the same keys and values as `batten fair --report` (status,
    /// iterations, moved_points, max_displacement, tolerance, tolerance_met, before, after,
    /// parameters, notes, ...).
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.report_object(py).cloned()
    }

    /// The method's faired B-spline curve, for methods that work on one; else `None`.
    #[getter]
    fn curve(&self, py: Python<'_>) -> Option<Py<BSpline>> {
        self.curve.as_ref().map(|c| c.clone_ref(py))
    }

    /// Updated tangents, an `(n, 2)` array, for methods that carry them; else `None`.
    #[getter]
    fn tangents(&self, py: Python<'_>) -> Option<Py<PyArray2<f64>>> {
        self.tangents.as_ref().map(|t| t.clone_ref(py))
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let r = self.report_object(py)?;
        let item = |k: &str| -> String {
            r.get_item(k)
                .and_then(|v| v.repr())
                .map(|s| s.to_string())
                .unwrap_or_else(|_| "?".into())
        };
        Ok(format!(
            "FairResult(method={}, points={}, status={}, max_displacement={}, tolerance_met={})",
            item("method"),
            self.points.bind(py).len()?,
            item("status"),
            item("max_displacement"),
            item("tolerance_met"),
        ))
    }

    /// Pickle support (Dask moves results between processes).
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let py = slf.py();
        let me = slf.get();
        let restore = py
            .import("batten._batten")?
            .getattr("_restore_fair_result")?;
        let args = PyTuple::new(
            py,
            [
                me.points.bind(py).clone().into_any(),
                me.report_object(py)?.clone(),
                me.curve(py)
                    .map_or_else(|| py.None(), Py::into_any)
                    .into_bound(py),
                me.tangents(py)
                    .map_or_else(|| py.None(), Py::into_any)
                    .into_bound(py),
            ],
        )?;
        Ok((restore, args))
    }
}

/// Rebuild a pickled [`FairResult`].
#[pyfunction]
pub fn _restore_fair_result(
    points: Bound<'_, PyArray2<f64>>,
    report: Bound<'_, PyAny>,
    curve: Option<Py<BSpline>>,
    tangents: Option<Bound<'_, PyArray2<f64>>>,
) -> FairResult {
    let py = points.py();
    let cell = PyOnceLock::new();
    // A new cell is empty, so this cannot fail.
    let _ = cell.set(py, report.unbind());
    FairResult {
        points: points.unbind(),
        source: None,
        report: cell,
        curve,
        tangents: tangents.map(Bound::unbind),
    }
}
