"""Fair many curves on Dask: a bag of curves, or a dataframe with one row per point.

Both functions fair each partition with :func:`batten.fair_many` (in parallel inside the
worker, the GIL released), so the results are exactly those of ``fair_many`` on the same
curves with the same options. They return two lazy collections: the faired points and one
summary row per curve, with the columns of ``batten batch --summary`` (``curve`` in place
of ``file``; see :data:`SUMMARY_COLUMNS`). Compute both in one call, ``dask.compute(points,
summary)``, so that each curve is faired once.

As in ``batten batch``, a curve that cannot be faired does not stop the others: its summary
row has status ``invalid_input`` (bad points) or ``failed`` (the method failed) and the
error message, and it has no faired points. A missed tolerance is status
``tolerance_exceeded``. Options themselves (an unknown method or parameter) are checked when
the graph is built, and raise ``ValueError`` there.

Needs ``dask[bag,dataframe]`` and pandas (``pip install batten[dask]``); ``distributed`` to
run on a cluster.
"""

from __future__ import annotations

import math
from typing import Any, Hashable, Iterable, Optional, Sequence, Tuple

import numpy as np

import batten

#: The summary's columns, in order: those of ``batten batch --summary`` with ``curve`` (the
#: curve's id) in place of ``file``.
SUMMARY_COLUMNS: Tuple[str, ...] = (
    "curve",
    "status",
    "error",
    "points",
    "iterations",
    "max_displacement",
    "sum_displacement",
    "tolerance_met",
    "inflections_before",
    "inflections_after",
    "vibrations_before",
    "vibrations_after",
    "strain_energy_before",
    "strain_energy_after",
    "gfi_before",
    "gfi_after",
    "end_tangent_change",
    "end_curvature_change",
)

_INT_COLUMNS = (
    "points",
    "iterations",
    "inflections_before",
    "inflections_after",
    "vibrations_before",
    "vibrations_after",
)
_FLOAT_COLUMNS = (
    "max_displacement",
    "sum_displacement",
    "strain_energy_before",
    "strain_energy_after",
    "gfi_before",
    "gfi_after",
    "end_tangent_change",
    "end_curvature_change",
)

# Columns added to a dataframe to keep each curve's points in order through the shuffle.
_PART = "__batten_partition"
_ROW = "__batten_row"


def _fmax(a: Optional[float], b: Optional[float]) -> Optional[float]:
    """Rust's ``f64::max``: the larger, ignoring a NaN (``None`` in JSON)."""
    vals = [v for v in (a, b) if v is not None and not math.isnan(v)]
    return max(vals) if vals else None


def summary_row(curve: Hashable, report: dict[str, Any]) -> dict[str, Any]:
    """The summary row of one faired curve, from its report (``batten batch``'s ``Row``).

    A space curve's report has no inflections, vibrations, GFI or end changes: those columns
    are ``None`` for it, as ``batten batch`` leaves them empty."""
    ends = report.get("end_changes")
    before, after = report["before"], report["after"]
    met = report["tolerance_met"]
    error = None
    if not met:
        error = (
            f"{curve}: tolerance {report['tolerance']!r} not met: "
            f"a point moved {report['max_displacement']:.4g}"
        )
    return {
        "curve": curve,
        "status": "ok" if met else "tolerance_exceeded",
        "error": error,
        "points": before["points"],
        "iterations": report["iterations"],
        "max_displacement": report["max_displacement"],
        "sum_displacement": report["sum_displacement"],
        "tolerance_met": met,
        "inflections_before": before.get("inflections"),
        "inflections_after": after.get("inflections"),
        "vibrations_before": before.get("vibrations"),
        "vibrations_after": after.get("vibrations"),
        "strain_energy_before": before["strain_energy"],
        "strain_energy_after": after["strain_energy"],
        "gfi_before": before.get("gfi"),
        "gfi_after": after.get("gfi"),
        "end_tangent_change": _fmax(*ends["tangent_angle"]) if ends else None,
        "end_curvature_change": (
            _fmax(abs(ends["curvature"][0]), abs(ends["curvature"][1])) if ends else None
        ),
    }


def _failed_row(curve: Hashable, error: Exception, points: Optional[int]) -> dict[str, Any]:
    row: dict[str, Any] = dict.fromkeys(SUMMARY_COLUMNS)
    row.update(
        curve=curve,
        status="failed" if isinstance(error, batten.FairError) else "invalid_input",
        error=f"{curve}: {error}",
        points=points,
    )
    return row


def check_options(**options: Any) -> None:
    """Raise ``ValueError`` now for options ``fair`` would refuse (unknown method, option or
    parameter, a bad value), rather than in every task."""
    batten.fair_many([], **options)


def fair_curves(
    curves: Sequence[Tuple[Hashable, Any]], **options: Any
) -> list[Tuple[Hashable, Optional[np.ndarray], dict[str, Any]]]:
    """Fair ``(curve_id, points)`` pairs with :func:`batten.fair_many`: ``(curve_id, faired
    points, summary row)`` for each, in order. A curve that fails is a row with its error
    and ``None`` for the points."""
    ids = [c for c, _ in curves]
    arrays = [p for _, p in curves]
    try:
        results: list[Any] = batten.fair_many(arrays, **options)
    except (ValueError, batten.FairError):
        # Some curve is bad: fair them one by one so that the others still get results.
        results = []
        for points in arrays:
            try:
                results.append(batten.fair(points, **options))
            except (ValueError, batten.FairError) as e:
                results.append(e)
    out = []
    for curve, points, r in zip(ids, arrays, results):
        if isinstance(r, Exception):
            n = len(points) if hasattr(points, "__len__") else None
            out.append((curve, None, _failed_row(curve, r, n)))
        else:
            out.append((curve, r.points, summary_row(curve, r.report)))
    return out


def _is_pair(item: Any) -> bool:
    return (
        isinstance(item, tuple)
        and len(item) == 2
        and isinstance(item[0], (str, int, np.integer))
        and not isinstance(item[0], bool)
    )


def _fair_partition(items: Iterable[Any], offset: int, options: dict[str, Any]) -> list[Any]:
    pairs = [
        item if _is_pair(item) else (offset + i, item) for i, item in enumerate(items)
    ]
    return fair_curves(pairs, **options)


def _pluck(results: list[Any], field: int) -> list[Any]:
    return [r[field] for r in results]


def fair_bag(bag: Any, **options: Any) -> Tuple[Any, Any]:
    """Fair every curve of a Dask bag.

    Elements are ``(n, 2)`` (or ``(n, 3)``, space curves) array-likes of points, or ``(curve_id, points)`` pairs (a str or
    int id). ``options`` are those of :func:`batten.fair` (``method``, ``tolerance``,
    ``fix_ends``, ``max_iterations``, ``closed``, the method's parameters).

    Returns ``(points, summary)``: two bags in the input's order, the faired ``(n, 2)``
    (``(n, 3)``) arrays (``None`` for a curve that failed) and one summary row (a dict with
    :data:`SUMMARY_COLUMNS`) per curve, ``curve`` the given id or the element's position in
    the bag.
    """
    import dask
    import dask.bag as db

    check_options(**options)
    parts = bag.to_delayed()
    sizes = [dask.delayed(len)(p) for p in parts]
    done = [
        dask.delayed(_fair_partition)(p, dask.delayed(sum)(sizes[:i]) if i else 0, options)
        for i, p in enumerate(parts)
    ]
    points = db.from_delayed([dask.delayed(_pluck)(d, 1) for d in done])
    summary = db.from_delayed([dask.delayed(_pluck)(d, 2) for d in done])
    return points, summary


def summary_frame(rows: Sequence[dict[str, Any]], curve_dtype: Any = object) -> Any:
    """Summary rows as a pandas DataFrame with fixed dtypes (nullable integers and booleans,
    strings), ``curve`` of ``curve_dtype``."""
    import pandas as pd

    df = pd.DataFrame(list(rows), columns=list(SUMMARY_COLUMNS))
    dtypes: dict[str, Any] = {"curve": curve_dtype, "status": "string", "error": "string"}
    dtypes.update(dict.fromkeys(_INT_COLUMNS, "Int64"))
    dtypes.update(dict.fromkeys(_FLOAT_COLUMNS, "float64"))
    dtypes["tolerance_met"] = "boolean"
    for col, dtype in dtypes.items():
        if dtype == "float64":
            df[col] = pd.array(
                [np.nan if v is None else v for v in df[col]], dtype="float64"
            )
        else:
            df[col] = df[col].astype(dtype)
    return df


def _tag(df: Any, number: int) -> Any:
    return df.assign(**{_PART: number, _ROW: np.arange(len(df), dtype=np.int64)})


def _fair_frame(
    df: Any, curve_id: str, coords: list[str], options: dict[str, Any], curve_dtype: Any
) -> Tuple[Any, Any]:
    df = df.sort_values([curve_id, _PART, _ROW], kind="stable")
    groups = [(c, g) for c, g in df.groupby(curve_id, sort=True)]
    pairs = [(c, g[coords].to_numpy(dtype=np.float64)) for c, g in groups]
    results = fair_curves(pairs, **options)
    frames = []
    for (c, g), (_, pts, _) in zip(groups, results):
        if pts is not None:
            g = g.drop(columns=[_PART, _ROW]).copy()
            for k, col in enumerate(coords):
                g[col] = pts[:, k]
            frames.append(g)
    import pandas as pd

    empty = df.drop(columns=[_PART, _ROW]).iloc[:0]
    points = pd.concat(frames) if frames else empty
    summary = summary_frame([r for _, _, r in results], curve_dtype)
    return points, summary


def fair_dataframe(
    ddf: Any,
    curve_id: str = "curve",
    x: str = "x",
    y: str = "y",
    z: Optional[str] = None,
    **options: Any,
) -> Tuple[Any, Any]:
    """Fair every curve of a Dask dataframe with one row per point.

    Rows with the same ``curve_id`` form one curve, their points in row order (as the
    dataframe's partitions hold them). With ``z`` (a column name) the curves are space
    curves (methods ``band`` and ``mst``). ``options`` are those of :func:`batten.fair`.

    Returns ``(points, summary)``: a dataframe with the input's columns and each faired
    curve's rows, ``x`` and ``y`` replaced by the faired coordinates (a curve that failed has
    no rows; ``z`` too for space curves), and a dataframe with one row per curve and :data:`SUMMARY_COLUMNS`. Both are
    grouped by curve after a shuffle: sort them by ``curve`` when order matters.
    """
    import dask
    import dask.dataframe as dd

    check_options(**options)
    coords = [x, y] if z is None else [x, y, z]
    for col in (curve_id, *coords):
        if col not in ddf.columns:
            raise ValueError(f"fair_dataframe: no column {col!r} (columns: {list(ddf.columns)})")
    curve_dtype = ddf.dtypes[curve_id]
    meta = ddf._meta
    tagged = dd.from_delayed(
        [dask.delayed(_tag)(p, i) for i, p in enumerate(ddf.to_delayed())],
        meta=_tag(meta, 0),
    )
    shuffled = tagged.shuffle(on=curve_id)
    done = [
        dask.delayed(_fair_frame, nout=2)(p, curve_id, coords, options, curve_dtype)
        for p in shuffled.to_delayed()
    ]
    points = dd.from_delayed([d[0] for d in done], meta=meta)
    summary = dd.from_delayed(
        [d[1] for d in done], meta=summary_frame([], curve_dtype)
    )
    return points, summary


__all__ = [
    "SUMMARY_COLUMNS",
    "check_options",
    "fair_bag",
    "fair_curves",
    "fair_dataframe",
    "summary_frame",
    "summary_row",
]

