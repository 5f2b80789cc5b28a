"""Fair a fleet of 10 000 curves on a Dask cluster and print the throughput and the summary.

Starts a real ``distributed.LocalCluster`` (2 worker processes, one thread each), puts the
curves in a Dask bag, fairs them with ``batten.dask.fair_bag`` and prints:

- the throughput on the cluster, against ``batten.fair_many`` in this process (the
  difference is Dask's overhead: scheduling, and pickling curves to the workers and back);
- the summary (the columns of ``batten batch --summary``): status counts, displacements,
  inflections and vibrations before and after.

    pip install ./crates/batten-py "dask[bag,dataframe,distributed]" pandas
    python examples/python/dask_fleet.py [--curves 10000] [--points 200]
"""

from __future__ import annotations

import argparse
import time

import dask
import dask.bag as db
import numpy as np
import pandas as pd
from distributed import Client, LocalCluster

import batten
import batten.dask as bd


def fleet(n: int, points: int, seed: int = 0) -> list[np.ndarray]:
    """`n` noisy curves: sines and arcs of random amplitude, phase and length, noise σ 0.005."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 1.0, points)
    curves = []
    for i in range(n):
        if i % 2:
            x = 6.0 * t
            y = rng.uniform(0.5, 2.0) * np.sin(x + rng.uniform(0.0, np.pi))
        else:
            a = rng.uniform(0.5, 2.5) * t
            x, y = np.cos(a), np.sin(a)
        curves.append(np.column_stack([x, y + 0.005 * rng.standard_normal(points)]))
    return curves


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--curves", type=int, default=10_000)
    ap.add_argument("--points", type=int, default=200)
    ap.add_argument("--method", default="mst")
    ap.add_argument("--tolerance", default="0.02", help="a distance or 'auto'")
    args = ap.parse_args()
    tol = args.tolerance if args.tolerance == "auto" else float(args.tolerance)
    options = dict(method=args.method, tolerance=tol)

    curves = fleet(args.curves, args.points)
    t0 = time.perf_counter()
    local = batten.fair_many(curves, **options)
    t_local = time.perf_counter() - t0

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        client.run(lambda: __import__("batten"))  # import on the workers before timing
        bag = db.from_sequence(curves, npartitions=40)
        t0 = time.perf_counter()
        points, summary = bd.fair_bag(bag, **options)
        faired, rows = dask.compute(points, summary)
        t_dask = time.perf_counter() - t0

    same = all(np.array_equal(p, r.points) for p, r in zip(faired, local))
    n = len(curves)
    print(f"{n} curves of {args.points} points, {args.method} at tolerance {args.tolerance}")
    print(f"  fair_many (this process, rayon):      {t_local:7.2f} s  {n / t_local:8.0f} curves/s")
    print(f"  Dask LocalCluster (2 processes):       {t_dask:7.2f} s  {n / t_dask:8.0f} curves/s"
          f"  ({t_dask / t_local:.2f}x fair_many)")
    print(f"  results identical to fair_many: {same}")

    df = bd.summary_frame(rows, curve_dtype="int64")
    print("\nstatus:", df["status"].value_counts().to_dict())
    cols = ["max_displacement", "inflections_before", "inflections_after",
            "vibrations_before", "vibrations_after", "gfi_before", "gfi_after"]
    with pd.option_context("display.width", 120, "display.max_columns", 20):
        print(df[cols].astype("float64").describe().loc[["mean", "50%", "max"]].T)
        print("\nfirst rows:")
        print(df.head(5).to_string(index=False))


if __name__ == "__main__":
    main()
