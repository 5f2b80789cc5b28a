#!/usr/bin/env python3
"""Generate the example curves in examples/data: noisy samples of analytic curves, each with
its noise-free truth, so that a fairing can be judged against what it should recover.

Deterministic: numpy only, one fixed seed per curve (numpy.random.default_rng). Numbers are
written with repr(), the shortest text that reads back to the same double.

    python3 scripts/make_examples.py            # writes into examples/data/
    python3 scripts/make_examples.py --out DIR

Curves (the README in examples/data lists the files):
  strophoid  x = 10(t^3 - t)/(t^2 + 1), y = 10(t^2 - 1)/(t^2 + 1), t in [-2, 2]: 65 points
             equally spaced in t, 40 of the 63 interior points perturbed (Han et al., Fig. 5)
  sine       y = sin(x/2), x in [0, 4 pi]: 30 points, noise on y
  arc        circle of radius 5 about the origin, angles 0..120 degrees: 40 points
  clothoid   x = C(s), y = S(s) (Fresnel integrals, curvature pi*s), s in [0, 2]: 50 points;
             integrals by composite Gauss-Legendre quadrature
  cubic      y = x^3 - x, x in [-1.5, 1.5]: 41 points, noise on y
  ellipse    closed, x = 3 cos t, y = 2 sin t: 48 points, first not repeated (JSON)
  helix      a space curve, x = 2 cos t, y = 2 sin t, z = 0.5 t, t in [0, 4 pi]: 80 points,
             noise on x, y and z (CSV x,y,z)
"""

import argparse
import json
import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_OUT = os.path.join(HERE, "..", "examples", "data")

# Gauss-Legendre nodes per panel and number of panels per unit of s for the Fresnel integrals:
# the integrand varies on a scale of 1/s, so 64 panels per unit at 8 nodes is exact to
# rounding on [0, 2].
GL_NODES = 8
GL_PANELS_PER_UNIT = 64


def fresnel(s):
    """C(s) = int_0^s cos(pi u^2 / 2) du and S(s) = int_0^s sin(pi u^2 / 2) du, for s >= 0."""
    xg, wg = np.polynomial.legendre.leggauss(GL_NODES)
    c = np.empty_like(s)
    sn = np.empty_like(s)
    for i, si in enumerate(s):
        panels = max(1, int(np.ceil(si * GL_PANELS_PER_UNIT)))
        edges = np.linspace(0.0, si, panels + 1)
        half = 0.5 * (edges[1:] - edges[:-1])
        mid = 0.5 * (edges[1:] + edges[:-1])
        u = (mid[:, None] + half[:, None] * xg[None, :]).ravel()
        w = (half[:, None] * wg[None, :]).ravel()
        phase = 0.5 * np.pi * u * u
        c[i] = np.dot(w, np.cos(phase))
        sn[i] = np.dot(w, np.sin(phase))
    return c, sn


def strophoid():
    t = np.linspace(-2.0, 2.0, 65)
    x = 10.0 * (t**3 - t) / (t**2 + 1.0)
    y = 10.0 * (t**2 - 1.0) / (t**2 + 1.0)
    return np.column_stack([x, y])


def sine():
    x = np.linspace(0.0, 4.0 * np.pi, 30)
    return np.column_stack([x, np.sin(x / 2.0)])


def arc():
    a = np.linspace(0.0, 2.0 * np.pi / 3.0, 40)
    return np.column_stack([5.0 * np.cos(a), 5.0 * np.sin(a)])


def clothoid():
    s = np.linspace(0.0, 2.0, 50)
    c, sn = fresnel(s)
    return np.column_stack([c, sn])


def cubic():
    x = np.linspace(-1.5, 1.5, 41)
    return np.column_stack([x, x**3 - x])


def ellipse():
    t = np.linspace(0.0, 2.0 * np.pi, 48, endpoint=False)
    return np.column_stack([3.0 * np.cos(t), 2.0 * np.sin(t)])


def helix():
    t = np.linspace(0.0, 4.0 * np.pi, 80)
    return np.column_stack([2.0 * np.cos(t), 2.0 * np.sin(t), 0.5 * t])


# name, truth, sigma, seed, which coordinates get noise ("xy", "xyz" or "y"), how many interior
# points are perturbed (None: all but the two ends; the closed ellipse: all), closed,
# the formula for the README.
CURVES = [
    ("strophoid", strophoid, 0.05, 1, "xy", 40, False,
     "x = 10(t³−t)/(t²+1), y = 10(t²−1)/(t²+1), t ∈ [−2, 2], 65 points equally spaced in t"),
    ("sine", sine, 0.03, 2, "y", None, False,
     "y = sin(x/2), x ∈ [0, 4π], 30 points equally spaced in x"),
    ("arc", arc, 0.02, 3, "xy", None, False,
     "circle of radius 5 about the origin, angle 0° … 120°, 40 points equally spaced in angle"),
    ("clothoid", clothoid, 0.005, 4, "xy", None, False,
     "x = C(s), y = S(s) (Fresnel integrals, κ = πs), s ∈ [0, 2], 50 points equally spaced in s"),
    ("cubic", cubic, 0.02, 5, "y", None, False,
     "y = x³ − x, x ∈ [−1.5, 1.5], 41 points equally spaced in x"),
    ("ellipse", ellipse, 0.02, 6, "xy", None, True,
     "closed: x = 3 cos t, y = 2 sin t, t = 2πk/48, k = 0 … 47 (first point not repeated)"),
    ("helix", helix, 0.03, 7, "xyz", None, False,
     "space curve: x = 2 cos t, y = 2 sin t, z = t/2, t ∈ [0, 4π], 80 points equally spaced in t"),
]


def perturb(truth, sigma, seed, coords, count, closed):
    """Gaussian noise N(0, sigma²) on the chosen coordinates of the chosen points. Open curves
    keep their end points; `count` interior points (all if None) are chosen at random."""
    rng = np.random.default_rng(seed)
    n = len(truth)
    candidates = np.arange(n) if closed else np.arange(1, n - 1)
    if count is None:
        chosen = candidates
    else:
        chosen = np.sort(rng.choice(candidates, size=count, replace=False))
    noisy = truth.copy()
    cols = {"xy": [0, 1], "xyz": [0, 1, 2]}.get(coords, [1])
    for c in cols:
        noisy[chosen, c] += rng.normal(0.0, sigma, size=len(chosen))
    return noisy, chosen


def write_csv(path, pts, comment):
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        for line in comment:
            f.write(f"# {line}\n")
        f.write("x,y,z\n" if pts.shape[1] == 3 else "x,y\n")
        for row in pts:
            f.write(",".join(repr(float(v)) for v in row) + "\n")


def write_json(path, pts, closed):
    # Python's json writes floats with repr(): shortest round trip.
    points = ",\n".join(f"    [{float(x)!r}, {float(y)!r}]" for x, y in pts)
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write("{\n  \"points\": [\n" + points + "\n  ],\n")
        f.write(f"  \"closed\": {json.dumps(bool(closed))}\n}}\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=DEFAULT_OUT, help="output directory")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    rows = []
    for name, make, sigma, seed, coords, count, closed, formula in CURVES:
        truth = make()
        noisy, chosen = perturb(truth, sigma, seed, coords, count, closed)
        on = {"xy": "x and y", "xyz": "x, y and z"}.get(coords, "y")
        which = (f"{len(chosen)} of {len(truth) - 2} interior points" if count is not None
                 else ("all points" if closed else "all interior points"))
        noise = f"N(0, {sigma}²) on {on} of {which}; numpy default_rng seed {seed}"
        ext = "json" if closed else "csv"
        files = []
        for kind, pts in (("noisy", noisy), ("truth", truth)):
            fname = f"{name}-{kind}.{ext}"
            path = os.path.join(args.out, fname)
            if closed:
                write_json(path, pts, closed)
            else:
                comment = [f"{name} ({kind}): {formula}",
                           "noise: " + (noise if kind == "noisy" else "none"),
                           "made by scripts/make_examples.py"]
                write_csv(path, pts, comment)
            files.append(fname)
        rows.append((name, files, formula, sigma, on, which, seed))
    write_readme(os.path.join(args.out, "README.md"), rows)


def write_readme(path, rows):
    lines = [
        "# Example curves",
        "",
        "Noisy samples of analytic curves, each with its noise-free truth (same point count and",
        "order), made by `scripts/make_examples.py` (numpy only, fixed seeds; rerun it to",
        "regenerate these files bit for bit). Numbers are written in their shortest exact form.",
        "Open curves are CSV (`# ` comment lines, a header `x,y`, then one point per line); the",
        "closed ellipse is JSON with `\"closed\": true` and its first point not repeated; the",
        "helix is a space curve (header `x,y,z`).",
        "The end points of open curves are never perturbed.",
        "",
        "| files | curve | noise σ | on | points perturbed | seed |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for name, files, formula, sigma, on, which, seed in rows:
        f = ", ".join(f"`{x}`" for x in files)
        lines.append(f"| {f} | {formula} | {sigma} | {on} | {which} | {seed} |")
    lines += [
        "",
        "The strophoid is the one of Han et al. (Fig. 5): 65 points, 40 interior points",
        "perturbed. The clothoid's Fresnel integrals are computed by composite 8-point",
        "Gauss–Legendre quadrature (64 panels per unit of s), exact to rounding.",
        "",
        "Try: `batten compare examples/data/strophoid-noisy.csv --methods han,mst`, or",
        "`batten fair examples/data/sine-noisy.csv -o sine-faired.csv --tolerance 0.1`.",
        "",
    ]
    # The surfaces of scripts/make_surface_examples.py live in the same folder.
    lines += [
        '## Surfaces',
        '',
        '`hood.json` and `hood-dented.json` (made by `scripts/make_surface_examples.py`, standard',
        'library only, deterministic) are B-spline surfaces for the `*-surface` commands: a crowned,',
        'bonnet-like bicubic patch of 12 × 12 control points over 4 × 2 units, z = 0.35 (1 −',
        '((x − 2)/2.6)²)(1 − 0.5((y − 1)/1.4)²) + 0.04x at the Greville abscissae, and the same net',
        'with a dent (z −= 0.03 exp(−((i − 4)² + (j − 7)²)/1.5)) and a ripple (z += 0.008 sin(2.2 j)',
        'on rows i = 7, 8) on interior control points only, so that `--fix-boundary=tangent` holds the',
        'same boundary. Try `batten fair-surface examples/data/hood-dented.json -o hood-faired.json',
        '--fix-boundary=tangent` and `batten plot-surface examples/data/hood-dented.json --faired',
        'hood-faired.json -o hood.png`.',
        "",
    ]
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write("\n".join(lines))


if __name__ == "__main__":
    main()
