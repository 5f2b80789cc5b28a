"""batten.dask on a real LocalCluster of 2 worker processes: exactly what fair_many gives."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import batten
from conftest import noisy_sine, run_cli, same_array_bits, same_bits, write_csv

dask = pytest.importorskip("dask")
db = pytest.importorskip("dask.bag")
dd = pytest.importorskip("dask.dataframe")
pd = pytest.importorskip("pandas")
distributed = pytest.importorskip("distributed")
bd = pytest.importorskip("batten.dask")

N_CURVES = 500
OPTIONS = dict(method="mst", tolerance=0.02)


def fleet(n: int = N_CURVES) -> list[np.ndarray]:
    """`n` noisy sines of 40 to 120 points with different amplitudes and phases."""
    rng = np.random.default_rng(17)
    curves = []
    for i in range(n):
        m = int(rng.integers(40, 121))
        x = np.linspace(0.0, 2.0 * np.pi, m)
        y = rng.uniform(0.5, 2.0) * np.sin(x + rng.uniform(0, np.pi))
        curves.append(np.column_stack([x, y + 0.01 * rng.standard_normal(m)]))
    return curves


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(
        n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None
    )
    c = distributed.Client(cluster)
    try:
        yield c
    finally:
        c.close()
        cluster.close()


@pytest.fixture(scope="module")
def curves():
    return fleet()


@pytest.fixture(scope="module")
def expected(curves):
    return batten.fair_many(curves, **OPTIONS)


def assert_row_matches(row: dict, curve, result) -> None:
    same_bits(
        {k: v for k, v in row.items()},
        bd.summary_row(curve, result.report),
    )


def test_fair_bag_on_a_cluster_equals_fair_many(client, curves, expected):
    assert len(client.scheduler_info()["workers"]) == 2
    bag = db.from_sequence(curves, npartitions=8)
    points, summary = bd.fair_bag(bag, **OPTIONS)
    pts, rows = dask.compute(points, summary)
    assert len(pts) == len(rows) == N_CURVES
    for i, (p, row, r) in enumerate(zip(pts, rows, expected)):
        same_array_bits(p, r.points)
        assert row["curve"] == i
        assert_row_matches(row, i, r)
    assert list(rows[0]) == list(bd.SUMMARY_COLUMNS)
    # Pairs keep their ids.
    pairs = db.from_sequence([(f"c{i}", c) for i, c in enumerate(curves[:20])], npartitions=3)
    _, rows = dask.compute(*bd.fair_bag(pairs, **OPTIONS))
    assert [r["curve"] for r in rows] == [f"c{i}" for i in range(20)]


def test_fair_dataframe_on_a_cluster_equals_fair_many(client, curves, expected):
    frame = pd.DataFrame(
        {
            "curve": np.repeat(np.arange(N_CURVES), [len(c) for c in curves]),
            "x": np.concatenate([c[:, 0] for c in curves]),
            "y": np.concatenate([c[:, 1] for c in curves]),
            "label": "fleet",
        }
    )
    # Curves straddle partition boundaries: their points must still come back in order.
    ddf = dd.from_pandas(frame, npartitions=7)
    points, summary = bd.fair_dataframe(ddf, **OPTIONS)
    pts, rows = dask.compute(points, summary)
    assert list(pts.columns) == ["curve", "x", "y", "label"]
    assert list(rows.columns) == list(bd.SUMMARY_COLUMNS)
    assert len(rows) == N_CURVES and sorted(rows["curve"]) == list(range(N_CURVES))
    by_curve = {c: g for c, g in pts.groupby("curve")}
    records = {r["curve"]: r for r in rows.to_dict("records")}
    for i, r in enumerate(expected):
        same_array_bits(by_curve[i][["x", "y"]].to_numpy(), r.points)
        want = bd.summary_row(i, r.report)
        got = records[i]
        for k in bd.SUMMARY_COLUMNS:
            if want[k] is None:
                assert pd.isna(got[k]), k
            elif isinstance(want[k], float):
                same_bits(float(got[k]), want[k], k)
            else:
                assert got[k] == want[k], k


def test_bad_curves_are_rows_not_exceptions():
    good = noisy_sine()
    bag = db.from_sequence([good, [[0, 0], [1, 1]], good], npartitions=1)
    pts, rows = dask.compute(*bd.fair_bag(bag, **OPTIONS), scheduler="sync")
    assert [r["status"] for r in rows] == ["ok", "invalid_input", "ok"]
    assert rows[1]["error"] == "1: points: too few points: 4 needed, 2 given"
    assert rows[1]["points"] == 2 and rows[1]["iterations"] is None
    assert pts[1] is None
    same_array_bits(pts[0], batten.fair(good, **OPTIONS).points)
    # Options are checked when the graph is built.
    with pytest.raises(ValueError, match="unknown method 'nope'"):
        bd.fair_bag(bag, method="nope")
    with pytest.raises(ValueError, match="no column 'x'"):
        bd.fair_dataframe(dd.from_pandas(pd.DataFrame({"curve": [0], "u": [1.0], "y": [0.0]}), npartitions=1))


def test_summary_rows_have_the_batch_summary_values(cli, tmp_path: Path):
    curves = fleet(4)
    curves[3] = curves[3][:6]  # a short one
    inputs = [write_csv(tmp_path / f"c{i}.csv", c) for i, c in enumerate(curves)]
    out = tmp_path / "out"
    proc = run_cli(
        cli, "batch", *map(str, inputs), "-o", str(out), "--summary", str(tmp_path / "s.json"),
        "--method", "mst", "--tolerance", "0.02",
    )  # fmt: skip
    assert proc.returncode in (0, 1), proc.stderr
    batch_rows = json.loads((tmp_path / "s.json").read_text())
    _, rows = dask.compute(*bd.fair_bag(db.from_sequence(curves), **OPTIONS), scheduler="sync")
    for b, r in zip(batch_rows, rows):
        assert list(b)[1:] == list(r)[1:]
        b = {k: v for k, v in b.items() if k not in ("file", "error")}
        r = {k: v for k, v in r.items() if k not in ("curve", "error")}
        same_bits(r, b)


def test_space_curves_in_a_dataframe_with_z(client):
    from conftest import noisy_helix

    helices = [noisy_helix(n=60 + 5 * i, seed=i) for i in range(12)]
    frame = pd.DataFrame(
        {
            "curve": np.repeat(np.arange(12), [len(c) for c in helices]),
            "x": np.concatenate([c[:, 0] for c in helices]),
            "y": np.concatenate([c[:, 1] for c in helices]),
            "z": np.concatenate([c[:, 2] for c in helices]),
        }
    )
    points, summary = bd.fair_dataframe(dd.from_pandas(frame, npartitions=3), z="z", **OPTIONS)
    pts, rows = dask.compute(points, summary)
    expected = batten.fair_many(helices, **OPTIONS)
    by_curve = {c: g for c, g in pts.groupby("curve")}
    records = {r["curve"]: r for r in rows.to_dict("records")}
    for i, r in enumerate(expected):
        same_array_bits(by_curve[i][["x", "y", "z"]].to_numpy(), r.points)
        assert records[i]["status"] == "ok"
        assert pd.isna(records[i]["inflections_before"])
        same_bits(float(records[i]["strain_energy_after"]), r.report["after"]["strain_energy"])
