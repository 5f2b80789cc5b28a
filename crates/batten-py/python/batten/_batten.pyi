"""Type stubs of the extension module ``batten._batten`` (re-exported by ``batten``)."""

from typing import Any, Iterable, Literal, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

ArrayLike = npt.ArrayLike
FixEnds = Union[bool, Literal["free", "position", "tangent", "curvature"], None]
Tolerance = Union[float, Literal["auto"], None]
ParamValue = Union[str, bool, int, float]

class FairError(Exception):
    """A fairing (or analysis) that failed on valid input; the message is the CLI's."""

class BSpline:
    """A B-spline (or NURBS) curve: degree, knots, control points, optional weights."""

    def __init__(
        self,
        degree: int,
        knots: ArrayLike,
        control_points: ArrayLike,
        weights: Optional[ArrayLike] = None,
    ) -> None: ...
    @property
    def degree(self) -> int: ...
    @property
    def knots(self) -> npt.NDArray[np.float64]: ...
    @property
    def control_points(self) -> npt.NDArray[np.float64]: ...
    @property
    def weights(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def domain(self) -> Tuple[float, float]: ...
    def evaluate(self, t: ArrayLike) -> npt.NDArray[np.float64]: ...

class FairResult:
    """The faired points, the report (the CLI's ``--report`` JSON as a dict), the curve."""

    @property
    def points(self) -> npt.NDArray[np.float64]: ...
    @property
    def report(self) -> dict[str, Any]: ...
    @property
    def curve(self) -> Optional[BSpline]: ...
    @property
    def tangents(self) -> Optional[npt.NDArray[np.float64]]: ...

def fair(
    points: Union[ArrayLike, BSpline],
    method: Optional[str] = None,
    tolerance: Tolerance = None,
    fix_ends: FixEnds = None,
    max_iterations: Optional[int] = None,
    closed: bool = False,
    **params: ParamValue,
) -> FairResult:
    """Fair one curve: an (n, 2) array of points, an (n, 3) array (a space curve: methods
    ``band`` and ``mst``; the tolerance is a 3-D distance), or a BSpline for the methods that
    take one. ``points`` of the result has the input's shape.

    The keywords are ``batten fair``'s flags; further keywords are the method's parameters
    (``--set KEY=VALUE``; ``**{"lambda": 2}`` for a name that is a Python keyword).
    Raises ValueError for bad input or options, FairError for a failed fair.
    """

def fair_many(
    curves: Iterable[Union[ArrayLike, BSpline]],
    method: Optional[str] = None,
    tolerance: Tolerance = None,
    fix_ends: FixEnds = None,
    max_iterations: Optional[int] = None,
    closed: bool = False,
    **params: ParamValue,
) -> list[FairResult]:
    """Fair every curve with the same options, in parallel with the GIL released.

    Results are in input order and equal to ``fair`` on each curve. The first bad curve
    raises (its index in the message: ``curves[3]: ...``).
    """

def analyze(points: ArrayLike, closed: bool = False) -> dict[str, Any]:
    """The fairness metrics of the curve through the points (``batten analyze --json``); for an
    (n, 3) array those of a space curve (``dimension`` 3: curvature, torsion, energies)."""

def methods() -> list[dict[str, Any]]:
    """The methods, the default first (``batten methods --json``): name, summary,
    closed_curves, bspline_input, parameters [{name, type, default, doc}]."""

def default_method() -> str:
    """The name of the default method."""

def _restore_fair_result(
    points: npt.NDArray[np.float64],
    report: dict[str, Any],
    curve: Optional[BSpline],
    tangents: Optional[npt.NDArray[np.float64]],
) -> FairResult: ...

__all__: Sequence[str]
