"""Speed of the Python package: fair_many, the per-call overhead, and Dask against fair_many.

    pip install ./crates/batten-py "dask[bag,distributed]"
    python bench/python_speed.py [--curves 10000] [--points 200] [--tolerance 0.02]

1. ``fair_many`` on N curves of 200 points with ``mst`` at a given tolerance (goal: 10 000
   curves in at most 1 s on 2 cores).
2. The overhead of one ``batten.fair`` call on a 200-point curve above the library call it
   makes (goal: at most 20 µs): the Python call's time minus the time of the same library
   call in a loop inside the extension (``batten._batten._rust_seconds_per_call``), best of
   several batches of each; with and without reading ``report`` (a dict made on first use).
   Timed in process CPU time (``time.process_time``), both sides, so that other work on a
   shared machine does not show up as overhead.
3. The Dask example's set-up (``fair_bag``, LocalCluster of 2 worker processes) against
   ``fair_many`` in one process: the scheduler's overhead.

Prints a Markdown table for BENCHMARKS.md.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

import batten
from batten import _batten


def fleet(n: int, points: int, seed: int = 0) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    x = np.linspace(0.0, 6.0, points)
    return [
        np.column_stack(
            [x, rng.uniform(0.5, 2.0) * np.sin(x + rng.uniform(0, np.pi))
             + 0.005 * rng.standard_normal(points)]
        )
        for _ in range(n)
    ]


def best(f, repeat: int, clock=time.perf_counter) -> float:
    """The shortest of `repeat` runs of `f`, in seconds of `clock`."""
    times = []
    for _ in range(repeat):
        t0 = clock()
        f()
        times.append(clock() - t0)
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--curves", type=int, default=10_000)
    ap.add_argument("--points", type=int, default=200)
    ap.add_argument("--tolerance", type=float, default=0.02)
    ap.add_argument("--no-dask", action="store_true")
    args = ap.parse_args()
    opts = dict(method="mst", tolerance=args.tolerance)
    curves = fleet(args.curves, args.points)
    rows = []

    t_many = best(lambda: batten.fair_many(curves, **opts), 3)
    cpu_many = best(lambda: batten.fair_many(curves, **opts), 3, time.process_time)
    rows.append((f"fair_many, {args.curves} curves × {args.points} points, mst, tolerance "
                 f"{args.tolerance}", f"{t_many:.2f} s",
                 f"{args.curves / t_many:.0f} curves/s; CPU {cpu_many:.2f} s "
                 f"(≈ {cpu_many / 2:.2f} s on 2 free cores)"))

    one = curves[0]
    calls = 300
    for label, kw in (("mst, tolerance (p searched)", opts), ("mst, p = 0.9 given", dict(method="mst", p=0.9))):
        cpu = time.process_time
        py = best(lambda: [batten.fair(one, **kw) for _ in range(calls)], 5, cpu) / calls
        py_report = best(lambda: [batten.fair(one, **kw).report for _ in range(calls)], 5,
                         cpu) / calls
        rust = best(lambda: _batten._rust_seconds_per_call(one, calls, **kw), 5, cpu) / calls
        rows.append((f"one call, {args.points} points, {label}: library", f"{rust * 1e6:.0f} µs", ""))
        rows.append((f"  batten.fair, overhead above the library", f"{(py - rust) * 1e6:.1f} µs",
                     f"{py * 1e6:.0f} µs per call"))
        rows.append((f"  batten.fair + .report, overhead", f"{(py_report - rust) * 1e6:.1f} µs",
                     f"{py_report * 1e6:.0f} µs per call"))

    t_an = best(lambda: [batten.analyze(one) for _ in range(calls)], 5, time.process_time) / calls
    rows.append(("batten.analyze, same curve (the metrics every report measures, before and after)",
                 f"{t_an * 1e6:.0f} µs", ""))

    if not args.no_dask:
        import dask
        import dask.bag as db
        from distributed import Client, LocalCluster

        import batten.dask as bd

        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            client.run(lambda: __import__("batten"))

            def run():
                bag = db.from_sequence(curves, npartitions=40)
                dask.compute(*bd.fair_bag(bag, **opts))

            t_dask = best(run, 2)
        rows.append(("Dask fair_bag, LocalCluster 2 processes × 1 thread, 40 partitions",
                     f"{t_dask:.2f} s", f"{args.curves / t_dask:.0f} curves/s, "
                     f"{t_dask / t_many:.2f}× fair_many"))

    print(f"cores: {os.cpu_count()}, load average: {os.getloadavg()[0]:.1f}\n")
    print("| what | time | |\n|---|---|---|")
    for r in rows:
        print("| " + " | ".join(r) + " |")


if __name__ == "__main__":
    main()
