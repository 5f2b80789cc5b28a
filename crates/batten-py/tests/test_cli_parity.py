"""Results are bit-identical to the `batten` CLI's for the same input and options."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import batten
from conftest import (
    noisy_circle,
    noisy_sine,
    read_csv,
    run_cli,
    same_array_bits,
    same_bits,
    write_csv,
)

CASES = [
    # (python keywords, CLI flags, closed)
    ({}, [], False),
    (dict(method="mst", tolerance=0.02), ["--method", "mst", "--tolerance", "0.02"], False),
    (dict(method="mst", p=0.9), ["--method", "mst", "--set", "p=0.9"], False),
    (dict(method="han", tolerance="auto"), ["--method", "han", "--tolerance", "auto"], False),
    (
        dict(method="mst", tolerance=0.05, fix_ends="tangent"),
        ["--method", "mst", "--tolerance", "0.05", "--fix-ends=tangent"],
        False,
    ),
    (dict(method="mst", fix_ends=True), ["--method", "mst", "--fix-ends"], False),
    (
        dict(method="kjellander", max_iterations=7),
        ["--method", "kjellander", "--max-iterations", "7"],
        False,
    ),
    (
        dict(method="salvi", tolerance=0.05, passes=2, pin_ends=True),
        ["--method", "salvi", "--tolerance", "0.05", "--set", "passes=2", "--set", "pin_ends=true"],
        False,
    ),
    (dict(method="cali", tolerance=0.03), ["--method", "cali", "--tolerance", "0.03"], False),
    (dict(method="mst", tolerance=0.02, closed=True), ["--method", "mst", "--tolerance", "0.02", "--closed"], True),
    (dict(method="han", closed=True), ["--method", "han", "--closed"], True),
    # A missed tolerance: the CLI exits 1 and writes the result anyway.
    (
        dict(method="salvi", tolerance=1e-6, control_points=5),
        ["--method", "salvi", "--tolerance", "1e-6", "--set", "control_points=5"],
        False,
    ),
]


def without_elapsed(report: dict) -> dict:
    return {k: v for k, v in report.items() if k != "elapsed_seconds"}


@pytest.mark.parametrize("kwargs, flags, closed", CASES)
def test_fair_matches_the_cli_bit_for_bit(cli, tmp_path: Path, kwargs, flags, closed):
    pts = noisy_circle(seed=3) if closed else noisy_sine(n=80, seed=3)
    src = write_csv(tmp_path / "in.csv", pts)
    out, rep = tmp_path / "out.csv", tmp_path / "report.json"
    proc = run_cli(cli, "fair", str(src), "-o", str(out), "--report", str(rep), *flags)
    py = batten.fair(pts, **kwargs)
    expected_code = 0 if py.report["tolerance_met"] else 1
    assert proc.returncode == expected_code, proc.stderr
    same_array_bits(py.points, read_csv(out))
    same_bits(without_elapsed(py.report), without_elapsed(json.loads(rep.read_text())))


def test_bspline_input_matches_the_cli(cli, tmp_path: Path):
    ctrl = noisy_sine(n=30, seed=5)
    knots = np.concatenate([[0.0] * 4, np.linspace(0.0, 1.0, 28)[1:-1], [1.0] * 4])
    b = batten.BSpline(3, knots, ctrl)
    src = tmp_path / "curve.json"
    src.write_text(
        json.dumps({"degree": 3, "knots": knots.tolist(), "control_points": ctrl.tolist()})
    )
    out, rep, cur = tmp_path / "out.csv", tmp_path / "r.json", tmp_path / "c.json"
    proc = run_cli(
        cli, "fair", str(src), "-o", str(out), "--report", str(rep), "--curve-out", str(cur),
        "--method", "salvi", "--tolerance", "0.05",
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    py = batten.fair(b, method="salvi", tolerance=0.05)
    same_array_bits(py.points, read_csv(out))
    same_bits(without_elapsed(py.report), without_elapsed(json.loads(rep.read_text())))
    curve = json.loads(cur.read_text())
    assert py.curve is not None and curve["degree"] == py.curve.degree
    same_array_bits(py.curve.knots, np.array(curve["knots"], dtype=np.float64))
    same_array_bits(py.curve.control_points, np.array(curve["control_points"], dtype=np.float64))


def test_analyze_matches_the_cli(cli, tmp_path: Path):
    for closed in (False, True):
        pts = noisy_circle(seed=1) if closed else noisy_sine(seed=1)
        src = write_csv(tmp_path / "in.csv", pts)
        proc = run_cli(cli, "analyze", str(src), "--json", *(["--closed"] if closed else []))
        assert proc.returncode == 0, proc.stderr
        same_bits(batten.analyze(pts, closed=closed), json.loads(proc.stdout))


def test_methods_match_the_cli(cli):
    proc = run_cli(cli, "methods", "--json")
    assert proc.returncode == 0, proc.stderr
    assert batten.methods() == json.loads(proc.stdout)


@pytest.mark.parametrize(
    "kwargs, flags",
    [
        (dict(method="nope"), ["--method", "nope"]),
        (dict(method="mst", foo=1), ["--method", "mst", "--set", "foo=1"]),
        (dict(method="mst", p="abc"), ["--method", "mst", "--set", "p=abc"]),
        (dict(method="mst", closed=True, p=2), ["--method", "mst", "--closed", "--set", "p=2"]),
    ],
)
def test_option_errors_carry_the_cli_message(cli, tmp_path: Path, kwargs, flags):
    src = write_csv(tmp_path / "in.csv", noisy_sine())
    proc = run_cli(cli, "fair", str(src), "-o", str(tmp_path / "o.csv"), *flags)
    assert proc.returncode == 2
    with pytest.raises(ValueError) as e:
        batten.fair(noisy_sine(), **kwargs)
    assert proc.stderr.strip() == f"error: {e.value}"


def test_huge_coordinates_match_the_cli(cli, tmp_path: Path):
    x = np.arange(20.0)
    huge = np.column_stack([x * 1e200, np.sin(x) * 1e200])
    src = write_csv(tmp_path / "in.csv", huge)
    out = tmp_path / "o.csv"
    proc = run_cli(cli, "fair", str(src), "-o", str(out), "--method", "mst")
    assert proc.returncode == 0, proc.stderr
    r = batten.fair(huge, method="mst")
    assert np.array_equal(r.points, np.loadtxt(out, delimiter=",", skiprows=1))
