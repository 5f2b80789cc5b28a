#!/usr/bin/env python3
"""Side-by-side comparison of batten with the tools users would otherwise reach for.

Quality at equal max deviation, on noisy analytic curves with a known truth:
  - batten methods (`batten fair --method M`), each run with --tolerance D;
  - PyPI csaps (`CubicSmoothingSpline`, chord-length parametric), p bisected to the same max
    deviation as the batten result it is compared with (what the Han paper did for MST);
  - SciPy `make_smoothing_spline` (per coordinate, chord-length t), lam bisected likewise;
  - SciPy `splprep`/`splev` (smoothing factor s bisected likewise);
  - Open CASCADE `Geom2dAPI_PointsToBSpline` (PyPI cadquery-ocp-novtk), approximation with
    tolerance D, evaluated at the chord-length parameters it was given.
Every result is measured the same way, by `batten analyze --json` on its points, plus the RMS
curvature error against the truth (curvature of the not-a-knot chord-length cubic through the
points, compared at the data points).

Speed: wall time of each tool on the same data at several sizes.

Not part of CI. Usage:
    cargo build --release -p batten-cli
    python3 bench/compare_peers.py [--quick] [--out bench/results.md]
        [--methods han,mst] [--peers csaps,...|none] [--n 65]
Needs: numpy, scipy, csaps; optional cadquery-ocp-novtk.

Options:
  --methods  comma-separated method specs. A spec is a method name, optionally with options in
             brackets separated by ';': `han[passes=2;max_iterations=5]`. `max_iterations=N`
             becomes `--max-iterations N`, every other `key=value` becomes `--set key=value` on
             the `batten fair` command line. The whole spec string is the `matched to`/tool label.
  --peers    comma-separated peers to run (csaps, scipy-smoothing, scipy-splprep, occt), or
             `none`; default: every available peer.
  --n        number of points per curve (default 65).
Environment: BATTEN_BIN overrides the batten binary (default target/release/batten).
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy.interpolate import CubicSpline, make_smoothing_spline, splev, splprep

try:
    import csaps
except ImportError:  # pragma: no cover
    csaps = None
try:
    from OCP.Geom2dAPI import Geom2dAPI_PointsToBSpline
    from OCP.OCP.collections import Array1_double as TColStd_Array1OfReal
    from OCP.OCP.collections import Array1_gp_Pnt2d as TColgp_Array1OfPnt2d
    from OCP.gp import gp_Pnt2d
    from OCP.GeomAbs import GeomAbs_Shape
    GeomAbs_C2 = GeomAbs_Shape.GeomAbs_C2
    HAVE_OCCT = True
except ImportError:  # pragma: no cover
    HAVE_OCCT = False

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BATTEN = os.environ.get("BATTEN_BIN") or os.path.join(ROOT, "target", "release", "batten")


# ---------------------------------------------------------------- truth curves
def strophoid(n):
    t = np.linspace(-2, 2, n)
    return np.c_[10 * (t**3 - t) / (t**2 + 1), 10 * (t**2 - 1) / (t**2 + 1)]


def sine(n):
    x = np.linspace(0, 4 * np.pi, n)
    return np.c_[x, np.sin(x / 2)]


def arc(n):
    a = np.linspace(0, 2.0, n)
    return np.c_[5 * np.cos(a), 5 * np.sin(a)]


def clothoid(n):
    s = np.linspace(0, 3.0, n)
    fine = np.linspace(0, 3.0, 20 * n)
    th = fine**2 / 2
    x = np.concatenate([[0], np.cumsum((np.cos(th[1:]) + np.cos(th[:-1])) / 2 * np.diff(fine))])
    y = np.concatenate([[0], np.cumsum((np.sin(th[1:]) + np.sin(th[:-1])) / 2 * np.diff(fine))])
    return np.c_[np.interp(s, fine, x), np.interp(s, fine, y)]


def cubic(n):
    x = np.linspace(-1.5, 1.5, n)
    return np.c_[x, x**3 - x]


CURVES = {"strophoid": strophoid, "sine": sine, "arc": arc, "clothoid": clothoid, "cubic": cubic}


# ---------------------------------------------------------------- helpers
def chord(p):
    d = np.linalg.norm(np.diff(p, axis=0), axis=1)
    return np.concatenate([[0.0], np.cumsum(d)])


def curvature_at_points(p):
    t = chord(p)
    cs = CubicSpline(t, p, bc_type="not-a-knot")
    d1, d2 = cs(t, 1), cs(t, 2)
    return (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.linalg.norm(d1, axis=1) ** 3


def write_csv(path, p):
    with open(path, "w") as f:
        f.write("x,y\n")
        for x, y in p:
            f.write(f"{float(x)!r},{float(y)!r}\n")


def read_csv(path):
    return np.loadtxt(path, delimiter=",", skiprows=1)


def analyze(p, tmp):
    path = os.path.join(tmp, "a.csv")
    write_csv(path, p)
    out = subprocess.run([BATTEN, "analyze", path, "--json"], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def max_dev(a, b):
    return float(np.max(np.linalg.norm(a - b, axis=1)))


def bisect(fit, target, lo, hi, log=True, iters=60):
    """Find the most-smoothing parameter whose max deviation stays <= target.
    `fit(v)` returns points; deviation decreases as v moves from lo (smooth) to hi (tight)."""
    best = fit(hi)
    for _ in range(iters):
        mid = math.sqrt(lo * hi) if log else 0.5 * (lo + hi)
        pts = fit(mid)
        if pts is not None and max_dev(pts, DATA) <= target:
            best, hi = pts, mid
        else:
            lo = mid
    return best


# ---------------------------------------------------------------- peers
def peer_csaps(p, target):
    t = chord(p)
    def fit(v):  # v = 1 - p_smooth, small = tight
        return csaps.CubicSmoothingSpline(t, p.T, smooth=1.0 - v)(t).T
    return bisect(lambda v: fit(v), target, 1.0 - 1e-15, 1e-15)


def peer_scipy_sss(p, target):
    t = chord(p)
    def fit(lam):
        try:
            return np.c_[make_smoothing_spline(t, p[:, 0], lam=lam)(t), make_smoothing_spline(t, p[:, 1], lam=lam)(t)]
        except Exception:
            return None
    return bisect(fit, target, 1e6 * t[-1] ** 3, 1e-12)


def peer_splprep(p, target):
    t = chord(p)
    def fit(s):
        try:
            tck, _ = splprep(p.T, u=t, s=s, k=3)
            return np.array(splev(t, tck)).T
        except Exception:
            return None
    return bisect(fit, target, len(p) * target**2 * 4, 1e-14)


def peer_occt(p, target):
    t = chord(p)
    pts = TColgp_Array1OfPnt2d(1, len(p))
    par = TColStd_Array1OfReal(1, len(p))
    for i, (x, y) in enumerate(p):
        pts.SetValue(i + 1, gp_Pnt2d(float(x), float(y)))
        par.SetValue(i + 1, float(t[i]))
    approx = Geom2dAPI_PointsToBSpline(pts, par, 3, 8, GeomAbs_C2, float(target))
    c = approx.Curve()
    # OCCT rescales the given parameters to the curve's own domain ([0, 1] here).
    a, b = c.FirstParameter(), c.LastParameter()
    us = a + (b - a) * t / t[-1]
    return np.array([[c.Value(float(u)).X(), c.Value(float(u)).Y()] for u in us])


PEERS = {"csaps": peer_csaps, "scipy-smoothing": peer_scipy_sss, "scipy-splprep": peer_splprep}
if HAVE_OCCT:
    PEERS["occt"] = peer_occt


def method_args(spec):
    """`han[passes=2;max_iterations=5]` -> ["--method", "han", "--set", "passes=2", "--max-iterations", "5"]."""
    name, _, opts = spec.partition("[")
    if opts and not opts.endswith("]"):
        raise SystemExit(f"bad method spec {spec!r}: expected name[key=value;...]")
    args = ["--method", name.strip()]
    for opt in filter(None, (o.strip() for o in opts[:-1].split(";"))):
        key, eq, value = opt.partition("=")
        if not eq:
            raise SystemExit(f"bad option {opt!r} in method spec {spec!r}: expected key=value")
        key, value = key.strip(), value.strip()
        if key.replace("-", "_") == "max_iterations":
            args += ["--max-iterations", value]
        else:
            args += ["--set", f"{key}={value}"]
    return args


def run_batten(method, p, tol, tmp):
    inp, out, rep = (os.path.join(tmp, n) for n in ("in.csv", "out.csv", "rep.json"))
    write_csv(inp, p)
    t0 = time.perf_counter()
    r = subprocess.run([BATTEN, "fair", inp, "-o", out, *method_args(method), "--tolerance", repr(float(tol)),
                        "--report", rep], capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if r.returncode not in (0, 1) or not os.path.exists(out):
        return None, dt
    return read_csv(out), dt


def main():
    global DATA
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--methods", default="han,mst")
    ap.add_argument("--out", default=None)
    ap.add_argument("--peers", default=None, help="comma-separated peers, or 'none' (default: all available)")
    ap.add_argument("--n", type=int, default=65, help="points per curve")
    args = ap.parse_args()
    peers = PEERS
    if args.peers is not None:
        names = [] if args.peers.strip() == "none" else [s.strip() for s in args.peers.split(",") if s.strip()]
        unknown = [s for s in names if s not in PEERS]
        if unknown:
            raise SystemExit(f"unknown peer(s) {', '.join(unknown)}; available: {', '.join(PEERS)}")
        peers = {s: PEERS[s] for s in names}
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    for m in methods:
        method_args(m)  # reject a malformed spec before the run
    seeds = [1, 2] if args.quick else [1, 2, 3, 4, 5]
    noises = [0.01, 0.03] if args.quick else [0.005, 0.01, 0.03]
    n = args.n
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, f in CURVES.items():
            truth = f(n)
            scale = np.linalg.norm(truth.max(0) - truth.min(0))
            k_truth = curvature_at_points(truth)
            infl_truth = analyze(truth, tmp)["inflections"]
            for sigma in noises:
                for seed in seeds:
                    rng = np.random.default_rng(seed)
                    noisy = truth.copy()
                    noisy[1:-1] += rng.normal(0, sigma * scale / 10, size=(n - 2, 2))
                    DATA = noisy
                    tol = 3 * sigma * scale / 10
                    for method in methods:
                        res, dt = run_batten(method, noisy, tol, tmp)
                        if res is None:
                            continue
                        d = max_dev(res, noisy)
                        results = {f"batten-{method}": (res, dt)}
                        for pname, peer in peers.items():
                            t0 = time.perf_counter()
                            try:
                                pr = peer(noisy, d)
                            except Exception as e:  # noqa: BLE001
                                print(f"{pname} failed on {name}: {e}", file=sys.stderr)
                                continue
                            results[pname] = (pr, time.perf_counter() - t0)
                        for tool, (pts, dt) in results.items():
                            m = analyze(pts, tmp)
                            kerr = float(np.sqrt(np.mean((curvature_at_points(pts) - k_truth) ** 2)))
                            rows.append(dict(curve=name, sigma=sigma, seed=seed, ref=method, tool=tool,
                                             max_dev=max_dev(pts, noisy), spurious_infl=m["inflections"] - infl_truth,
                                             vib=m["vibrations"], kappa_rms=kerr, time=dt))
    # Aggregate: mean over seeds per (curve, sigma, ref, tool).
    from collections import defaultdict
    agg = defaultdict(list)
    for r in rows:
        agg[(r["curve"], r["sigma"], r["ref"], r["tool"])].append(r)
    lines = ["| curve | σ | matched to | tool | max dev | spurious infl | vib | κ RMS err | time [ms] |",
             "|---|---|---|---|---|---|---|---|---|"]
    for (c, s, ref, tool), rs in sorted(agg.items()):
        mean = lambda k: sum(r[k] for r in rs) / len(rs)  # noqa: E731
        lines.append(f"| {c} | {s} | {ref} | {tool} | {mean('max_dev'):.4g} | {mean('spurious_infl'):.2f} | "
                     f"{mean('vib'):.1f} | {mean('kappa_rms'):.4g} | {1e3 * mean('time'):.1f} |")
    text = "\n".join(lines)
    print(text)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text + "\n")


if __name__ == "__main__":
    main()
