"""batten.fair, fair_many, analyze, methods, BSpline: behaviour, errors, types."""

from __future__ import annotations

import pickle
import threading

import numpy as np
import pytest

import batten
from conftest import noisy_circle, noisy_sine, same_array_bits, same_bits

REPORT_KEYS = [
    "method", "status", "iterations", "moved_points", "moves", "max_displacement",
    "max_displacement_index", "sum_displacement", "tolerance", "tolerance_source",
    "noise_sigma", "tolerance_met", "fix_ends", "fixed_ends", "end_changes", "before",
    "after", "elapsed_seconds", "parameters", "history", "solver", "notes",
]  # fmt: skip


def without_elapsed(report: dict) -> dict:
    return {k: v for k, v in report.items() if k != "elapsed_seconds"}


def test_fair_keeps_the_count_and_respects_the_tolerance():
    pts = noisy_sine()
    r = batten.fair(pts, method="mst", tolerance=0.02)
    assert r.points.shape == pts.shape and r.points.dtype == np.float64
    assert list(r.report) == REPORT_KEYS
    d = np.hypot(*(r.points - pts).T)
    assert d.max() <= 0.02
    assert r.report["tolerance_met"] is True
    assert r.report["max_displacement"] == pytest.approx(d.max(), rel=1e-12)
    assert r.report["max_displacement_index"] == int(np.argmax(d))
    assert r.report["sum_displacement"] == pytest.approx(d.sum(), rel=1e-12)
    assert r.report["moved_points"] == [i for i in range(len(pts)) if d[i] > 0]
    assert r.report["before"]["points"] == len(pts)
    # The faired curve is fairer: fewer inflections than the noisy one.
    assert r.report["after"]["inflections"] < r.report["before"]["inflections"]
    assert r.curve is None and r.tangents is None


def test_default_method_is_the_first_listed():
    r = batten.fair(noisy_sine())
    assert r.report["method"] == batten.default_method() == batten.methods()[0]["name"]


def test_given_parameters_reach_the_method():
    r = batten.fair(noisy_sine(), method="mst", p=0.9)
    assert r.report["parameters"]["p"] == 0.9
    assert r.report["parameters"]["selection"] == "given"
    # A string is passed through as --set would pass it.
    s = batten.fair(noisy_sine(), method="mst", p="0.9")
    same_array_bits(r.points, s.points)


def test_auto_tolerance_is_three_noise_sigmas():
    r = batten.fair(noisy_sine(amplitude=0.02), method="mst", tolerance="auto")
    rep = r.report
    assert rep["tolerance_source"] == "auto"
    assert rep["tolerance"] == pytest.approx(3.0 * rep["noise_sigma"], rel=1e-15)
    assert rep["tolerance_met"]
    given = batten.fair(noisy_sine(), method="mst", tolerance=0.05).report
    assert given["tolerance_source"] == "given" and given["tolerance"] == 0.05


@pytest.mark.parametrize("fix, held", [(True, 1), ("position", 1), ("tangent", 2), ("curvature", 3)])
def test_fix_ends_holds_end_points(fix, held):
    pts = noisy_sine()
    r = batten.fair(pts, method="mst", tolerance=0.05, fix_ends=fix)
    assert r.report["fixed_ends"] == ("position" if fix is True else fix)
    same_array_bits(r.points[:held], pts[:held])
    same_array_bits(r.points[-held:], pts[-held:])


def test_every_point_held_returns_the_input_unchanged():
    pts = noisy_sine(n=6)
    r = batten.fair(pts, method="mst", fix_ends="curvature")
    same_array_bits(r.points, pts)
    assert r.report["status"] == "no_change" and r.report["moved_points"] == []


def test_closed_curves():
    pts = noisy_circle()
    r = batten.fair(pts, method="mst", tolerance=0.02, closed=True)
    assert r.report["before"]["closed"] is True and r.report["end_changes"] is None
    assert r.report["tolerance_met"]
    closed_ok = {m["name"]: m["closed_curves"] for m in batten.methods()}
    no = next(n for n, ok in closed_ok.items() if not ok)
    with pytest.raises(ValueError, match=f"^method {no} does not support closed curves$"):
        batten.fair(pts, method=no, closed=True)


def test_input_types():
    pts = noisy_sine()
    base = batten.fair(pts, method="mst", p=0.9).points
    for variant in (pts.tolist(), np.asfortranarray(pts), tuple(map(tuple, pts))):
        same_array_bits(batten.fair(variant, method="mst", p=0.9).points, base)
    strided = np.repeat(pts, 2, axis=0)[::2]
    assert not strided.flags.c_contiguous or strided.base is not None
    same_array_bits(batten.fair(strided, method="mst", p=0.9).points, base)
    ints = np.array([[0, 0], [1, 2], [2, 3], [3, 3], [4, 2], [5, 0]])
    assert batten.fair(ints, method="mst", p=0.5).points.dtype == np.float64


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(method="nope"), "unknown method 'nope' (known: band, han, "),
        (dict(method="mst", foo=1), "unknown option 'foo' for method mst (known: p)"),
        (dict(method="mst", p="abc"), "invalid value for p: 'abc' is not a finite number"),
        (dict(method="mst", p=float("nan")), "invalid value for p: 'NaN' is not a finite number"),
        (dict(tolerance=-1.0), "invalid value for tolerance: must be a positive finite number, got -1"),
        (dict(tolerance="far"), "tolerance: 'far' is not a positive distance in data units or 'auto'"),
        (dict(tolerance=True), "tolerance: a bool is not a positive distance"),
        (dict(fix_ends="ends"), "invalid value for fix_ends: 'ends' is not one of free, position, tangent, curvature"),
        (dict(max_iterations=-1), "max_iterations: -1 is not a whole number ≥ 0"),
        (dict(max_iterations=2.5), "max_iterations: 2.5 is not a whole number"),
        (dict(method="mst", p=[1]), "p: [1] is not a number, a bool or a string"),
    ],
)
def test_bad_options_are_value_errors_with_the_cli_message(kwargs, message):
    with pytest.raises(ValueError) as e:
        batten.fair(noisy_sine(), **kwargs)
    assert str(e.value).startswith(message), str(e.value)
    assert "\n" not in str(e.value)


@pytest.mark.parametrize(
    "points, message",
    [
        (np.zeros((5, 4)), "points: expected an (n, 2) array of x, y or an (n, 3) array of x, y, z, got shape (5, 4)"),
        (np.zeros(5), "points: expected an (n, 2) array of x, y or an (n, 3) array of x, y, z, got shape (5,)"),
        (np.zeros((2, 2, 2)), "points: expected an (n, 2) array of x, y or an (n, 3) array of x, y, z, got shape (2, 2, 2)"),
        ([[0, 0], [1, 1], [1, 1], [2, 2]], "points: point 2 duplicates the point before it (zero-length chord)"),
        ([[0, 0], [1, 1], [2, 2]], "points: too few points: 4 needed, 3 given"),
        ([[0, 0], [1, np.inf], [2, 2], [3, 3]], "points: point 1 is not finite (NaN or infinity)"),
        ([["a", "b"]] * 4, "points: not an array of numbers: could not convert string to float: 'a'"),
    ],
)
def test_bad_points_are_value_errors(points, message):
    with pytest.raises(ValueError) as e:
        batten.fair(points, method="mst")
    assert str(e.value) == message


def test_closed_curve_repeating_its_first_point_is_refused():
    pts = noisy_circle()
    with pytest.raises(ValueError, match="duplicates the point before it"):
        batten.fair(np.vstack([pts, pts[:1]]), closed=True)


def test_a_missed_tolerance_is_not_an_exception():
    # A least-squares fit with 5 control points cannot come within 1e-6 of 60 points.
    pts = noisy_sine(n=60)
    r = batten.fair(pts, method="salvi", tolerance=1e-6, control_points=5)
    assert r.report["tolerance_met"] is False
    assert r.report["status"] == "tolerance_exceeded"
    assert r.report["max_displacement"] > 1e-6


def huge_curve() -> np.ndarray:
    """Valid points near the largest f64 (every method runs in unit coordinates)."""
    x = np.arange(20.0)
    return np.column_stack([x * 1e300, np.sin(x) * 1e300])


def test_huge_coordinates_are_faired_like_unit_ones():
    unit = huge_curve() / 1e300
    small = batten.fair(unit, method="mst", tolerance=0.1)
    huge = batten.fair(huge_curve(), method="mst", tolerance=0.1e300)
    assert np.all(np.isfinite(huge.points))
    np.testing.assert_allclose(huge.points / 1e300, small.points, rtol=1e-9, atol=1e-12)
    assert batten.analyze(huge_curve())["inflections"] == batten.analyze(unit)["inflections"]


def test_fair_many_equals_fair_on_each_curve():
    curves = [noisy_sine(seed=s) for s in range(12)] + [noisy_sine(n=40, seed=99)]
    many = batten.fair_many(curves, method="mst", tolerance=0.02)
    assert len(many) == len(curves)
    for c, r in zip(curves, many):
        one = batten.fair(c, method="mst", tolerance=0.02)
        same_array_bits(r.points, one.points)
        same_bits(without_elapsed(r.report), without_elapsed(one.report))
    assert batten.fair_many([], method="mst") == []
    # Any iterable of curves.
    assert len(batten.fair_many((c for c in curves[:3]), method="mst", p=0.9)) == 3


def test_fair_many_names_the_bad_curve():
    curves = [noisy_sine(), np.zeros((4, 5)), noisy_sine()]
    with pytest.raises(ValueError, match=r"^curves\[1\]: points: expected an \(n, 2\) array"):
        batten.fair_many(curves)
    near = noisy_sine()
    near[5] = near[4] + 1e-15
    with pytest.raises(ValueError, match=r"^curves\[1\]: .*closer than"):
        batten.fair_many([noisy_sine(), near], method="mst")
    # The first bad curve in the list's order, whether it fails as an array (read with
    # Python) or as points (validated in parallel without it).
    bad_array = np.zeros((4, 5))
    with pytest.raises(ValueError, match=r"^curves\[1\]: .*closer than"):
        batten.fair_many([noisy_sine(), near, bad_array, near], method="mst")
    with pytest.raises(ValueError, match=r"^curves\[1\]: points: expected an \(n, 2\) array"):
        batten.fair_many([noisy_sine(), bad_array, near], method="mst")


def test_fair_many_releases_the_gil():
    curves = [noisy_sine(n=300, seed=s) for s in range(300)]
    ticks = 0
    t = threading.Thread(target=batten.fair_many, args=(curves,), kwargs=dict(method="mst"))
    t.start()
    while t.is_alive():
        ticks += 1
    t.join()
    # With the GIL held for the whole call this loop would get a handful of turns at most.
    assert ticks > 1000


def test_analyze_measures_the_curve():
    x = np.linspace(0.0, 1.0, 50)
    line = np.column_stack([x, 2.0 * x])
    m = batten.analyze(line)
    assert m["points"] == 50 and m["closed"] is False
    assert m["inflections"] == 0
    assert m["length"] == pytest.approx(np.sqrt(5.0), rel=1e-12)
    c = batten.analyze(noisy_circle(amplitude=0.0, n=200), closed=True)
    assert c["closed"] is True and c["inflections"] == 0
    # Strain energy of the unit circle: ∫κ² ds = 2π.
    assert c["strain_energy"] == pytest.approx(2 * np.pi, rel=1e-3)
    with pytest.raises(ValueError, match="^points: too few points"):
        batten.analyze([[0, 0], [1, 1]])


def test_methods_lists_typed_parameters():
    ms = batten.methods()
    names = [m["name"] for m in ms]
    assert names[0] == batten.default_method() and "mst" in names and "salvi" in names
    for m in ms:
        assert list(m) == ["name", "summary", "closed_curves", "bspline_input", "parameters"]
        for p in m["parameters"]:
            assert list(p) == ["name", "type", "default", "doc"]
            assert p["type"] in {"number", "integer", "boolean", "choice", "text"}
    salvi = ms[names.index("salvi")]
    assert salvi["bspline_input"] is True
    kinds = {p["name"]: p["type"] for p in salvi["parameters"]}
    assert kinds["passes"] == "integer" and kinds["pin_ends"] == "boolean"
    assert kinds["smoother"] == "choice" and kinds["samples"] == "text"


def bspline_of(points: np.ndarray) -> batten.BSpline:
    n = len(points)
    inner = np.linspace(0.0, 1.0, n - 2)[1:-1]
    knots = np.concatenate([[0.0] * 4, inner, [1.0] * 4])
    return batten.BSpline(3, knots, points)


def test_bspline_in_and_out():
    ctrl = noisy_sine(n=30)
    b = bspline_of(ctrl)
    assert b.degree == 3 and b.weights is None
    same_array_bits(b.control_points, ctrl)
    assert b.knots.shape == (34,) and b.domain == (0.0, 1.0)
    ends = b.evaluate([0.0, 1.0])
    same_array_bits(ends, ctrl[[0, -1]])
    r = batten.fair(b, method="salvi", tolerance=0.05)
    assert isinstance(r.curve, batten.BSpline)
    assert r.curve.degree == 3
    same_array_bits(r.curve.knots, b.knots)
    assert r.curve.control_points.shape == ctrl.shape
    assert r.report["tolerance_met"] and r.report["noise_sigma"] is None
    # B-spline out from point input too, for the control-point methods.
    assert batten.fair(noisy_sine(), method="salvi", tolerance=0.05).curve is not None
    # Rational.
    w = np.ones(30)
    w[5] = 2.0
    nurbs = batten.BSpline(3, b.knots, ctrl, w)
    same_array_bits(nurbs.weights, w)
    assert nurbs != b and bspline_of(ctrl) == b


def test_bspline_errors():
    with pytest.raises(ValueError, match="^invalid knot vector: 5 knots for 4 control points of degree 3: expected 8$"):
        batten.BSpline(3, [0, 0, 0, 1, 1], np.zeros((4, 2)) + np.arange(4)[:, None])
    with pytest.raises(ValueError, match=r"^control_points: expected an \(n, 2\) array of x, y, got shape \(4, 3\)$"):
        batten.BSpline(3, [0, 0, 0, 0, 1, 1, 1, 1], np.zeros((4, 3)))
    b = bspline_of(noisy_sine(n=30))
    with pytest.raises(ValueError, match=r"^method mst takes points, not a B-spline curve \(B-spline input: salvi, eck-hadenfeld\)$"):
        batten.fair(b, method="mst")
    # A method without closed curves refuses closed=True first, as an option (the CLI's check).
    with pytest.raises(ValueError, match="^method salvi does not support closed curves$"):
        batten.fair(b, method="salvi", closed=True)
    with pytest.raises(ValueError, match="^closed=True applies to points"):
        batten.fair(b, method="eck-hadenfeld", closed=True)


def test_results_pickle():
    r = batten.fair(noisy_sine(), method="salvi", tolerance=0.05)
    back = pickle.loads(pickle.dumps(r))
    same_array_bits(back.points, r.points)
    same_bits(back.report, r.report)
    assert back.curve == r.curve and back.tangents is None
    assert repr(back) == repr(r)
    b = pickle.loads(pickle.dumps(r.curve))
    assert b == r.curve
