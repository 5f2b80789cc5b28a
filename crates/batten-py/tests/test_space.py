"""Space curves: (n, 3) arrays faired by band and mst with the tolerance in 3-D distance,
analysed with torsion, refused in one line by the planar methods, equal to the CLI."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import batten
from conftest import noisy_helix, noisy_sine, read_csv, run_cli, same_array_bits, same_bits, write_csv


def without_elapsed(report: dict) -> dict:
    return {k: v for k, v in report.items() if k != "elapsed_seconds"}


@pytest.mark.parametrize("method", ["band", "mst"])
@pytest.mark.parametrize("closed", [False, True])
def test_space_curves_keep_their_shape_and_the_tolerance(method, closed):
    pts = noisy_helix(seed=2)
    if closed:
        t = np.linspace(0.0, 2.0 * np.pi, 120, endpoint=False)
        rng = np.random.default_rng(4)
        pts = np.column_stack([np.cos(t), np.sin(t), 0.3 * np.sin(3 * t)])
        pts += 0.01 * rng.standard_normal(pts.shape)
    r = batten.fair(pts, method=method, tolerance=0.03, closed=closed)
    assert r.points.shape == pts.shape and r.points.dtype == np.float64
    d = np.linalg.norm(r.points - pts, axis=1)
    assert d.max() <= 0.03
    rep = r.report
    assert rep["dimension"] == 3 and rep["method"] == method
    assert rep["tolerance_met"] is True
    assert rep["max_displacement"] == pytest.approx(d.max(), rel=1e-12)
    assert rep["before"]["dimension"] == 3 and rep["before"]["points"] == len(pts)
    assert rep["after"]["variation_energy"] < rep["before"]["variation_energy"]
    assert r.curve is None and r.tangents is None


def test_auto_tolerance_in_space():
    r = batten.fair(noisy_helix(seed=5), method="band")
    rep = r.report
    assert rep["tolerance_source"] == "auto"
    assert rep["noise_sigma"] == pytest.approx(0.01, rel=0.3)
    assert rep["tolerance_met"] is True


def test_planar_methods_refuse_a_space_curve_in_one_line():
    with pytest.raises(ValueError) as e:
        batten.fair(noisy_helix(), method="han")
    assert str(e.value).startswith("method han fairs planar curves only")
    assert "\n" not in str(e.value)
    with pytest.raises(ValueError, match=r"^curves\[1\]: method kjellander fairs planar"):
        batten.fair_many([noisy_sine(), noisy_helix()], method="kjellander")


def test_fair_many_mixes_planar_and_space_curves():
    curves = [noisy_sine(seed=1), noisy_helix(seed=1), noisy_sine(seed=2)]
    many = batten.fair_many(curves, method="mst", tolerance=0.02)
    for c, r in zip(curves, many):
        one = batten.fair(c, method="mst", tolerance=0.02)
        same_array_bits(r.points, one.points)
        assert r.points.shape == c.shape
        same_bits(without_elapsed(r.report), without_elapsed(one.report))


def test_analyze_a_space_curve():
    m = batten.analyze(noisy_helix(n=400, amplitude=0.0))
    assert m["dimension"] == 3
    # Helix of radius 1, pitch 0.5: κ = 1/(1 + c²), τ = c/(1 + c²), c = 0.5/(2π).
    c = 0.5 / (2.0 * np.pi)
    assert m["max_curvature"] == pytest.approx(1.0 / (1.0 + c * c), rel=1e-2)
    assert m["max_torsion"] == pytest.approx(c / (1.0 + c * c), rel=5e-2)
    assert m["torsion_sign_changes"] == 0


def test_space_results_match_the_cli(cli, tmp_path: Path):
    pts = noisy_helix(seed=3)
    src = write_csv(tmp_path / "in.csv", pts)
    for kwargs, flags in [
        (dict(method="band", tolerance=0.03), ["--method", "band", "--tolerance", "0.03"]),
        (dict(method="mst", tolerance=0.02), ["--method", "mst", "--tolerance", "0.02"]),
        (dict(method="band", fix_ends="tangent", tolerance=0.03),
         ["--method", "band", "--tolerance", "0.03", "--fix-ends=tangent"]),
    ]:  # fmt: skip
        out, rep = tmp_path / "out.csv", tmp_path / "r.json"
        proc = run_cli(cli, "fair", str(src), "-o", str(out), "--report", str(rep), *flags)
        assert proc.returncode == 0, proc.stderr
        py = batten.fair(pts, **kwargs)
        same_array_bits(py.points, read_csv(out))
        same_bits(without_elapsed(py.report), without_elapsed(json.loads(rep.read_text())))
    proc = run_cli(cli, "analyze", str(src), "--json")
    assert proc.returncode == 0, proc.stderr
    same_bits(batten.analyze(pts), json.loads(proc.stdout))
