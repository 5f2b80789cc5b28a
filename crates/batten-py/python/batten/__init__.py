"""batten: fair planar curves.

Move points (or B-spline control points) as little as possible, within a guaranteed
tolerance, until the curvature of the curve is free of spurious wiggles. A thin binding of
the Rust library behind the ``batten`` command: the same methods, options, reports and
messages.

>>> import numpy as np, batten
>>> x = np.linspace(0, 6, 200)
>>> r = batten.fair(np.column_stack([x, np.sin(x)]), method="mst", tolerance=0.01)
>>> r.points.shape, r.report["tolerance_met"]
((200, 2), True)

- :func:`fair` fairs one curve (``batten fair``); :func:`fair_many` a list of curves in
  parallel with the GIL released; :mod:`batten.dask` a Dask bag or dataframe of curves.
- :func:`analyze` measures a curve (``batten analyze --json``); :func:`methods` lists the
  methods and their parameters (``batten methods --json``).
- Bad input raises :class:`ValueError`, a failed fair :class:`FairError`; a missed tolerance
  is not an exception (``report["tolerance_met"]`` is false).
"""

from batten._batten import (
    BSpline,
    FairError,
    FairResult,
    __version__,
    analyze,
    default_method,
    fair,
    fair_many,
    methods,
)

__all__ = [
    "BSpline",
    "FairError",
    "FairResult",
    "__version__",
    "analyze",
    "default_method",
    "fair",
    "fair_many",
    "methods",
]
