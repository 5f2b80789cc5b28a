//! The keyword arguments of `fair` and `fair_many` as the library's [`FairOptions`], with the
//! CLI's names: `method`, `tolerance` (a distance or `"auto"`), `fix_ends`, `max_iterations`
//! and the method's parameters (`--set KEY=VALUE`) as further keywords.

use std::collections::BTreeMap;

use batten::fair::{self, EndFix, FairMethod, FairedSpace};
use batten::spline::BSplineCurve;
use batten::{FairOptions, Faired, Point, PointSeq, SpaceSeq, Xyz};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyString};

use crate::bspline::BSpline;
use crate::{convert, errors};

/// A checked request: the method and the options, as `batten fair` builds them from its flags.
#[derive(Clone)]
pub struct Request {
    method: &'static dyn FairMethod,
    options: FairOptions,
}

impl std::fmt::Debug for Request {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Request")
            .field("method", &self.method.name())
            .field("options", &self.options)
            .finish()
    }
}

/// What to fair: points, or a B-spline curve (for the methods that take one).
#[derive(Debug)]
pub enum Input {
    /// A validated point sequence.
    Points(PointSeq),
    /// A B-spline curve, faired as it is.
    Curve(BSplineCurve),
    /// A validated space curve (`band`, `mst`).
    Space(SpaceSeq),
}

/// An input as read from Python, before the checks that need no Python
/// ([`Request::validate`]).
#[derive(Debug)]
pub enum Read {
    /// A B-spline curve (checked against the method already).
    Curve(BSplineCurve),
    /// Planar points, not yet validated.
    Planar(Vec<Point>),
    /// Space points, not yet validated.
    Space(Vec<Xyz>),
}

/// Why [`Request::validate`] refused an input: the library's error and the prefix of its
/// message.
#[derive(Debug)]
pub struct Refused {
    what: &'static str,
    error: batten::Error,
}

impl Refused {
    /// The Python exception, as [`Request::input`] raises it.
    pub fn to_py(&self) -> PyErr {
        errors::library(self.what, &self.error)
    }
}

/// What a run gives: a planar result (points or B-spline input) or a space curve's.
#[derive(Debug)]
pub enum Output {
    /// From [`Input::Points`] or [`Input::Curve`].
    Planar(Faired),
    /// From [`Input::Space`].
    Space(FairedSpace),
}

impl Request {
    /// Build and check the options. Every problem is a `ValueError` with the message the CLI
    /// gives for the same flag or `--set`.
    pub fn new(
        method: Option<&str>,
        tolerance: Option<&Bound<'_, PyAny>>,
        fix_ends: Option<&Bound<'_, PyAny>>,
        max_iterations: Option<&Bound<'_, PyAny>>,
        closed: bool,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Request> {
        let name = method.unwrap_or_else(|| fair::default_method());
        let method = fair::method(name).map_err(|e| errors::library("", &e))?;
        let mut options = FairOptions::default();
        match tolerance {
            None => {}
            Some(t) if t.is_none() => {}
            Some(t) => {
                if let Ok(s) = t.cast::<PyString>() {
                    let s = s.to_cow()?;
                    if s.trim() == "auto" {
                        options = options.with_auto_tolerance();
                    } else {
                        return Err(errors::value(format!(
                            "tolerance: '{s}' is not a positive distance in data units or 'auto'"
                        )));
                    }
                } else if t.is_instance_of::<PyBool>() {
                    return Err(errors::value(
                        "tolerance: a bool is not a positive distance in data units or 'auto'",
                    ));
                } else {
                    let d: f64 = t.extract().map_err(|_| {
                        errors::value(format!(
                            "tolerance: {} is not a positive distance in data units or 'auto'",
                            repr(t)
                        ))
                    })?;
                    options = options.with_tolerance(d);
                }
            }
        }
        options = options.with_end_fix(end_fix(fix_ends)?);
        options.max_iterations = iterations(max_iterations)?;
        options.params = parameters(params)?;
        fair::check_options(method, closed, &options).map_err(|e| errors::library("", &e))?;
        Ok(Request { method, options })
    }

    /// Read `obj` as the request's input: a [`BSpline`], an `(n, 2)` array-like of points,
    /// or an `(n, 3)` one (a space curve, for the methods that fair one).
    pub fn input(&self, obj: &Bound<'_, PyAny>, closed: bool) -> PyResult<Input> {
        self.validate(self.read(obj, closed)?, closed)
            .map_err(|refused| refused.to_py())
    }

    /// The part of [`Request::input`] that needs Python: `obj` converted, not yet validated.
    pub fn read(&self, obj: &Bound<'_, PyAny>, closed: bool) -> PyResult<Read> {
        if let Ok(b) = obj.cast::<BSpline>() {
            if closed {
                return Err(errors::value(
                    "closed=True applies to points: a B-spline curve is faired as it is",
                ));
            }
            // Checked before the run, as `batten fair` checks a curve file.
            if !self.method.run_curve_supported() {
                let takes: Vec<&str> = fair::methods()
                    .iter()
                    .filter(|m| m.run_curve_supported())
                    .map(|m| m.name())
                    .collect();
                return Err(errors::value(format!(
                    "method {} takes points, not a B-spline curve (B-spline input: {})",
                    self.method.name(),
                    takes.join(", ")
                )));
            }
            return Ok(Read::Curve(b.get().curve().clone()));
        }
        Ok(match convert::points_any(obj, "points")? {
            convert::Points::Planar(points) => Read::Planar(points),
            convert::Points::Space(points) => Read::Space(points),
        })
    }

    /// The part of [`Request::input`] that needs no Python (so `fair_many` runs it on every
    /// curve in parallel): the points validated as the CLI validates a file's.
    ///
    /// # Errors
    /// [`Refused`], for [`Refused::to_py`].
    pub fn validate(&self, read: Read, closed: bool) -> Result<Input, Refused> {
        let refused = |what, error| Refused { what, error };
        match read {
            Read::Curve(curve) => Ok(Input::Curve(curve)),
            Read::Planar(points) => PointSeq::new(points, closed)
                .map(Input::Points)
                .map_err(|e| refused("points", e)),
            Read::Space(points) => {
                fair::check_space_method(self.method.name()).map_err(|e| refused("", e))?;
                SpaceSeq::new(points, closed)
                    .map(Input::Space)
                    .map_err(|e| refused("points", e))
            }
        }
    }

    /// Fair `input`. Runs without Python: call it with the GIL released.
    ///
    /// # Errors
    /// The library's error, for [`Request::error`].
    pub fn run(&self, input: &Input) -> Result<Output, batten::Error> {
        Ok(match input {
            Input::Points(seq) => Output::Planar(fair::fair_with(self.method, seq, &self.options)?),
            Input::Curve(curve) => {
                Output::Planar(fair::fair_curve(self.method.name(), curve, &self.options)?)
            }
            Input::Space(seq) => {
                Output::Space(fair::fair_space(self.method.name(), seq, &self.options)?)
            }
        })
    }

    /// A failed run as the CLI words it: `method mst failed: ...`.
    pub fn error(&self, e: &batten::Error) -> PyErr {
        errors::library(&format!("method {} failed", self.method.name()), e)
    }
}

/// `fix_ends`: `None`/`False` free, `True` the end points (bare `--fix-ends`), or a name:
/// `"free"`, `"position"`, `"tangent"`, `"curvature"`.
fn end_fix(value: Option<&Bound<'_, PyAny>>) -> PyResult<EndFix> {
    let Some(v) = value.filter(|v| !v.is_none()) else {
        return Ok(EndFix::Free);
    };
    if let Ok(b) = v.cast::<PyBool>() {
        return Ok(if b.is_true() {
            EndFix::Position
        } else {
            EndFix::Free
        });
    }
    let Ok(s) = v.cast::<PyString>() else {
        return Err(errors::value(format!(
            "fix_ends: {} is not one of position, tangent, curvature (or free), or a bool",
            repr(v)
        )));
    };
    s.to_cow()?
        .parse::<EndFix>()
        .map_err(|e| errors::library("", &e))
}

/// `max_iterations`: a whole number ≥ 0, or `None` for the method's own limit.
fn iterations(value: Option<&Bound<'_, PyAny>>) -> PyResult<Option<usize>> {
    let Some(v) = value.filter(|v| !v.is_none()) else {
        return Ok(None);
    };
    if v.is_instance_of::<PyBool>() || !v.is_instance_of::<PyInt>() {
        return Err(errors::value(format!(
            "max_iterations: {} is not a whole number",
            repr(v)
        )));
    }
    v.extract::<usize>().map(Some).map_err(|_| {
        errors::value(format!(
            "max_iterations: {} is not a whole number ≥ 0",
            repr(v)
        ))
    })
}

/// The method parameters as the text `--set KEY=VALUE` would give: strings as they are,
/// `True`/`False` as `true`/`false`, integers in decimal, floats in the shortest form that
/// reads back to the same `f64`.
fn parameters(params: Option<&Bound<'_, PyDict>>) -> PyResult<BTreeMap<String, String>> {
    let mut out = BTreeMap::new();
    let Some(params) = params else {
        return Ok(out);
    };
    for (k, v) in params.iter() {
        let key: String = k.extract()?;
        let text = if let Ok(s) = v.cast::<PyString>() {
            s.to_cow()?.trim().to_string()
        } else if let Ok(b) = v.cast::<PyBool>() {
            b.is_true().to_string()
        } else if v.is_instance_of::<PyInt>() {
            v.str()?.to_cow()?.into_owned()
        } else if v.is_instance_of::<PyFloat>() {
            format!("{:?}", v.extract::<f64>()?)
        } else if let Ok(i) = v.extract::<i64>() {
            // numpy integers (through __index__).
            i.to_string()
        } else if let Ok(x) = v.extract::<f64>() {
            // numpy float32 and other objects with __float__.
            format!("{x:?}")
        } else {
            return Err(errors::value(format!(
                "{key}: {} is not a number, a bool or a string",
                repr(&v)
            )));
        };
        out.insert(key, text);
    }
    Ok(out)
}

/// `repr(v)`, or `?` when that fails.
fn repr(v: &Bound<'_, PyAny>) -> String {
    v.repr()
        .ok()
        .and_then(|r| r.to_str().ok().map(str::to_string))
        .unwrap_or_else(|| "?".to_string())
}
