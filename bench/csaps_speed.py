#!/usr/bin/env python3
"""Time PyPI csaps on the data of batten's `mst` bench (crates/batten/benches/mst.rs).

Same curve (a spiral arc with a deterministic xorshift wobble of 1% of the point spacing),
same chord-length parameters, same p (csaps's own default for the data, which batten's
`SmoothingSpline::default_p` reproduces), n = 10^3 .. 10^6.

Timings per size (best and median wall time, best process CPU time of several runs):
- fit:      csaps.CubicSmoothingSpline(t, xy, smooth=p)   (batten: mst/fit)
- fit+eval: the same, then evaluate at t                   (batten's fit returns the values)
and, for the "spline" group, scipy.interpolate.CubicSpline(t, xy, bc_type="natural").

Usage: python3 bench/csaps_speed.py [--sizes 1000,10000,100000,1000000]
"""

import argparse
import time

import numpy as np
import csaps
import scipy
from scipy.interpolate import CubicSpline

MASK = (1 << 64) - 1


def curve(n):
    """The batten bench curve, bit for bit (xorshift64 13/7/17, 53-bit uniforms)."""
    state = 0x2545F4914F6CDD1D
    noise = np.empty(2 * n)
    for k in range(2 * n):
        state ^= (state << 13) & MASK
        state ^= state >> 7
        state ^= (state << 17) & MASK
        noise[k] = (state >> 11) / float(1 << 53) - 0.5
    step = 6.0 * np.pi / n
    a = np.arange(n) * step
    r = 1.0 + 0.3 * a
    e = 0.01 * step * r
    x = r * np.cos(a) + e * noise[0::2]
    y = r * np.sin(a) + e * noise[1::2]
    return x, y


def chord_length(x, y):
    d = np.hypot(np.diff(x), np.diff(y))
    return np.concatenate([[0.0], np.cumsum(d)])


def best_of(f, min_runs=3, min_seconds=1.0):
    """Best wall time, median wall time and best process CPU time (the CPU time is the fairer
    figure on a loaded machine)."""
    times, cpu = [], []
    start = time.perf_counter()
    while len(times) < min_runs or time.perf_counter() - start < min_seconds:
        t0, c0 = time.perf_counter(), time.process_time()
        f()
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
        if len(times) >= 50:
            break
    return min(times), float(np.median(times)), min(cpu)


def fmt(s):
    return f"{s * 1e3:9.3f} ms" if s >= 1e-3 else f"{s * 1e6:9.1f} µs"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", default="1000,10000,100000,1000000")
    args = ap.parse_args()
    sizes = [int(s) for s in args.sizes.split(",")]
    print(f"csaps {csaps.__version__}, numpy {np.__version__}, scipy {scipy.__version__}")
    print("wall best / wall median / CPU best")
    print(f"{'n':>8}  {'csaps fit':>38}  {'csaps fit+eval':>38}  {'CubicSpline natural':>38}")
    for n in sizes:
        x, y = curve(n)
        t = chord_length(x, y)
        xy = np.vstack([x, y])
        p = csaps.CubicSmoothingSpline(t, xy, smooth=None).smooth
        fit = best_of(lambda: csaps.CubicSmoothingSpline(t, xy, smooth=p))
        fit_eval = best_of(lambda: csaps.CubicSmoothingSpline(t, xy, smooth=p)(t))
        interp = best_of(lambda: CubicSpline(t, xy, axis=1, bc_type="natural"))
        cols = ["  " + " / ".join(fmt(v) for v in r) for r in (fit, fit_eval, interp)]
        print(f"{n:>8}" + "".join(cols))


if __name__ == "__main__":
    main()
