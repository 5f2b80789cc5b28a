#!/usr/bin/env python3
"""Quality benchmark of batten's fairing methods against the peers users would pick (issue #18).

    python3 -m venv /tmp/benv && /tmp/benv/bin/pip install numpy scipy csaps cadquery-ocp-novtk
    cargo build --release -p batten-cli
    /tmp/benv/bin/python bench/quality.py [--quick] [--methods han,mst,band,...] [--auto]
        [--peers csaps,gcv,splprep,occt|none] [--tol-mode hat3|auto|true3] [--split test|tune]
        [--families sine,...] [--sizes 30,100] [--limit TOOL=NMAX,...] [--timeout 60] [--jobs 2]
        [--out bench/results-quality.md] [--csv FILE] [--json FILE] [--no-clean]

(`cadquery-ocp` instead of `cadquery-ocp-novtk` works too, with VTK; without either, occt is
left out and said so.) The Markdown goes to stdout and to `--out`; `--json FILE` writes the
totals, the per-family/n/noise breakdowns, the clean-input summary and every row as JSON.

The batten binary is `$BATTEN_BIN`, by default `target/release/batten` of the repository this
script lives in. `--methods` defaults to every method `$BATTEN_BIN methods` lists, so a binary
with a new method is measured without changing this script; a method the binary does not know
is warned about and each of its runs reported as failed (with batten's message), not fatal. A
method spec may carry options, `han[passes=2;max_iterations=5]` (see `compare_peers.py`).

Protocol
========
Curves. Ten families, each a parametric curve r(t) with exact r' and r'' (so the curvature
κ = r'×r''/|r'|³ is exact), sampled at n points equally spaced in t (`FAMILIES` below):
sine, cubic y = x³ − a·x, clothoid (Fresnel integrals, κ = π·u, through its inflection),
airfoil (a whole NACA 4-digit section with the camber at half chord, so the camber line is one
polynomial; sampled in s with x = s², which clusters points at the leading edge as cosine
spacing does), ship waterline (a polynomial half-breadth with hollow entrance and run),
ellipse arc, logarithmic spiral, circle arc, strophoid (a loop) and epitrochoid (a dented arc).
The true inflections are the sign changes of r'×r'' in the sampled range, found on a grid of
20 001 parameters and refined by Brent's method. `--split test` (default) and `--split tune`
use disjoint seeds and slightly different family parameters (phases, lengths, shapes), so a
method can be tuned on one and reported on the other.

Noise. n ∈ {30, 100, 300, 1000}; Gaussian noise, isotropic, independent per coordinate, of
σ = 0.1 %, 0.5 % and 1 % of the bounding-box diagonal of the exact samples, on every point
(ends included); 3 seeds (test: 1, 2, 3; tune: 101, 102, 103). `--quick`: n ∈ {30, 300} and
one seed. Full run: 10 × 4 × 3 × 3 = 360 noisy curves.

Methods. Every batten method: `$BATTEN_BIN fair IN.csv -o OUT.csv --method M --tolerance T
--report R.json`, T = 3·σ̂ as a number (`--tol-mode hat3`, the default: works with any binary),
the word `auto` (`--auto` or `--tol-mode auto`: batten estimates σ̂ itself and takes k·σ̂, k = 3
unless the method has its own, as `band` does; `band` without `--tolerance` does the same), or
3·σ with the true σ (`--tol-mode true3`). batten runs with RAYON_NUM_THREADS=1 (the script runs
`--jobs` curves at once). Exit code 1 (tolerance missed) still yields a measured result; no
output file, a crash or the timeout (`--timeout`, 60 s) counts as a failure. `--limit T=N`
skips tool T (a method or a peer) on curves of more than N points (recorded as `skipped`).

Peers (each result is a set of output points, one per input point):
  - `csaps@M`: PyPI csaps `CubicSmoothingSpline` on chord-length parameters, evaluated there,
    its smoothing parameter p bisected (on logit p) to the smoothest spline whose max
    displacement does not exceed that of batten method M's result on the same curve;
  - `gcv`: SciPy `make_smoothing_spline` per coordinate on chord-length parameters, λ by
    generalised cross-validation (no tolerance involved);
  - `splprep`: SciPy `splprep` (cubic, u = chord length) with s = 2·n·σ̂²: the expected sum of
    squared residuals of the exact curve for noise σ̂ per coordinate in two coordinates;
  - `occt`: Open CASCADE variational smoothing, `Geom2dAPI_PointsToBSpline(points, 0.4, 0.2,
    0.4, DegMax 8, C2, Tol2D = 3·σ̂)` (PyPI cadquery-ocp-novtk or cadquery-ocp), built from
    its parts (`AppDef_Variational`, as the API builds it); the output point i is the curve at
    the i-th of the parameters the fit gave the points, sorted, ties spread (`peer_occt`).
    Skipped when OCP is not installed.
    At start, `check_occt` checks that these points lie on the curve the API itself returns.
σ̂ is batten's noise estimate (`analysis/noise.rs`, ported here as `noise_sigma` and checked
against the `noise_sigma` in batten's reports: the Markdown gives the largest difference);
with `--tol-mode true3` the true σ.

Metrics, the same for every result, on the C² cubic spline with chord-length parameters and
not-a-knot ends through the output points (batten's analysis curve):
  - inflections and vibrations: `$BATTEN_BIN analyze --json` on the output points (one
    definition for all: sign changes of the curvature, exact per span). The locations are
    found here by the same rule (curvature at the knots and at the vertex of each span's
    quadratic r'×r'', root of the quadratic in between); `infl_mismatch` counts results where
    the two counts differ;
  - matching: a result inflection matches a true one when their positions, as fractions of
    the curve's length (chord length of the output points; arc length of the exact curve),
    differ by at most w = max(0.03, 2/(n − 1)) (3 % of the length, at least two point
    spacings), one to one, closest pairs first. spurious = result inflections not matched;
    lost = true inflections not matched;
  - relative curvature error: RMS_i(κ_result(t_i) − κ_true(τ_i)) / RMS_i κ_true(τ_i), κ_result
    from the spline at its knots, τ_i the exact parameter point i was sampled at;
  - max displacement from the noisy input (reported in units of the true σ), wall time.

Clean input (`--no-clean` to skip): exact samples of a circle (closed), a circle arc, a
clothoid, a logarithmic spiral and every `examples/data/*-truth.*` file (their analytic forms,
from examples/data/README.md, give the exact curvature; the files are checked against them).
Each method runs with 3σ̂ (`auto` with `--auto`; floored at 1e-12 of the diagonal as batten
floors `auto`, the samples being exact) and with a fixed tolerance of 0.5 % of the diagonal;
gcv, splprep and occt run too (σ̂ from the points). A violation: more inflections or more
vibrations than the input (`analyze --json` before and after), or a relative curvature error
more than 1 % above the input's own (the spline through the exact samples against the exact κ).

Output: Markdown (`--out`) with totals per tool, per-family, per-n and per-noise breakdowns,
failures and clean-input violations; a CSV of every row (`--csv`, default: the Markdown path
with .csv).
"""
import os

# One BLAS thread per worker: the workers already use the cores (set before numpy loads).
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import csv  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import multiprocessing as mp  # noqa: E402
import signal  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from collections import defaultdict  # noqa: E402

import numpy as np  # noqa: E402
from scipy.interpolate import CubicSpline, make_smoothing_spline, splev, splprep  # noqa: E402
from scipy.optimize import brentq  # noqa: E402
from scipy.special import fresnel  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_peers import method_args  # noqa: E402  (one parser for method specs)

try:
    import csaps
except ImportError:  # pragma: no cover
    csaps = None
try:
    from OCP.AppDef import AppDef_MultiLine, AppDef_MultiPointConstraint, AppDef_Variational
    from OCP.AppParCurves import AppParCurves_Constraint, AppParCurves_ConstraintCouple
    from OCP.GeomAbs import GeomAbs_Shape
    from OCP.gp import gp_Pnt2d
    from OCP.OCP.collections import HArray1_AppParCurves_ConstraintCouple

    HAVE_OCCT = True
except ImportError:  # pragma: no cover
    HAVE_OCCT = False

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BATTEN = os.environ.get("BATTEN_BIN") or os.path.join(ROOT, "target", "release", "batten")

SIZES = [30, 100, 300, 1000]
QUICK_SIZES = [30, 300]
NOISES = [0.001, 0.005, 0.01]  # σ as a fraction of the bounding-box diagonal
SEEDS = {"test": [1, 2, 3], "tune": [101, 102, 103]}
TRUTH_GRID = 20001  # parameters on which the true inflections are bracketed and arc length summed
MATCH_FRACTION = 0.03  # inflection matching window, fraction of the curve length
MATCH_SPACINGS = 2.0  # ... and at least this many mean point spacings
CLEAN_FIXED_TOL = 0.005  # the fixed clean-input tolerance, fraction of the diagonal
CLEAN_FIXED_LABEL = f"{CLEAN_FIXED_TOL:.1%} diag"
CLEAN_KAPPA_SLACK = 0.01  # relative increase of the curvature error that counts as a violation
CSAPS_BISECTIONS = 24  # on logit p in [−40, 40]: to 5e-6 in logit, far below what max displacement sees
TOL_FACTOR = 3.0  # the tolerance is this many noise standard deviations (batten's `auto`: k = 3)
AUTO_TOLERANCE_FLOOR_REL = 1e-12  # batten's floor of `auto`, fraction of the diagonal (no zero tolerance)
OCCT_WEIGHTS = (0.4, 0.2, 0.4)
OCCT_DEGMAX = 8
MAD_TO_SIGMA = 1.4826  # the MAD-to-σ factor for Gaussian noise
CLIP, CLIP_ROUNDS = 3.0, 3  # σ̂'s clipped root mean square, as batten takes it
CLIPPED_SQUARE_1D = 0.9733369246625415  # E[v² | |v| ≤ 3σ]/σ² for Gaussian v
NORMAL_CHORD_NOISE_SPANS = 20.0  # batten's: the normal's chord spans about this many rough noise scales
OCCT_CHECK_REL = 1e-9  # check_occt: the peer's points on the API's curve to this fraction of the diagonal
OCCT_TIE_GAP = 1e-9  # parameters closer than this fraction of the range count as one (spread_ties)


# ================================================================ curve families
class Family:
    """A parametric curve with exact derivatives on [t0, t1].

    `deriv(t)` returns (r, r', r'') as three (len(t), 2) arrays."""

    def __init__(self, name, deriv, t0, t1, note):
        self.name, self.deriv, self.t0, self.t1, self.note = name, deriv, t0, t1, note

    def points(self, t):
        return self.deriv(np.asarray(t, float))[0]

    def kappa(self, t):
        _, d1, d2 = self.deriv(np.asarray(t, float))
        return cross(d1, d2) / np.hypot(d1[:, 0], d1[:, 1]) ** 3

    def inflections(self):
        """Parameters of the sign changes of r'×r'' in (t0, t1)."""
        g = np.linspace(self.t0, self.t1, TRUTH_GRID)
        _, d1, d2 = self.deriv(g)
        c = cross(d1, d2)
        f = lambda u: float(cross(*self.deriv(np.array([u]))[1:])[0])  # noqa: E731
        roots = []
        nz = np.flatnonzero(c != 0)
        for a, b in zip(nz[:-1], nz[1:]):
            if np.sign(c[a]) != np.sign(c[b]):
                roots.append(brentq(f, g[a], g[b], xtol=1e-14) if b == a + 1 else 0.5 * (g[a] + g[b]))
        return np.array(roots)

    def arclength(self):
        """(grid, cumulative arc length on it), for positions as fractions of the length."""
        g = np.linspace(self.t0, self.t1, TRUTH_GRID)
        sp = np.hypot(*self.deriv(g)[1].T)
        s = np.concatenate([[0.0], np.cumsum(0.5 * (sp[1:] + sp[:-1]) * np.diff(g))])
        return g, s


def cross(a, b):
    return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]


def stack(x, y):
    return np.c_[x, y]


def fam_sine(v):
    amp, w, phase, length = (1.0, 0.5, 0.3, 6 * np.pi) if v == "test" else (1.0, 0.5, 0.7, 5.5 * np.pi)

    def d(t):
        a = w * t + phase
        z = np.zeros_like(t)
        return (stack(t, amp * np.sin(a)), stack(z + 1, amp * w * np.cos(a)), stack(z, -amp * w * w * np.sin(a)))

    return Family("sine", d, 0.0, length, f"(t, {amp} sin({w}t + {phase})), t ∈ [0, {length / np.pi:g}π]")


def fam_cubic(v):
    a, t0, t1 = (1.0, -1.5, 1.6) if v == "test" else (1.2, -1.6, 1.5)

    def d(t):
        z = np.zeros_like(t)
        return stack(t, t**3 - a * t), stack(z + 1, 3 * t**2 - a), stack(z, 6 * t)

    return Family("cubic", d, t0, t1, f"(t, t³ − {a}t), t ∈ [{t0}, {t1}]")


def fam_clothoid(v):
    scale, t0, t1 = (3.0, -1.0, 1.6) if v == "test" else (3.0, -1.2, 1.4)

    def d(t):
        s, c = fresnel(t)  # S = ∫ sin(πu²/2), C = ∫ cos(πu²/2)
        th = 0.5 * np.pi * t**2
        d1 = stack(np.cos(th), np.sin(th))
        d2 = np.pi * t[:, None] * stack(-np.sin(th), np.cos(th))
        return scale * stack(c, s), scale * d1, scale * d2

    return Family("clothoid", d, t0, t1, f"{scale}·(C(u), S(u)), κ = πu/{scale}, u ∈ [{t0}, {t1}]")


def fam_airfoil(v):
    """NACA m5tt with the camber at half chord: yc = 4m(x − x²), one polynomial. x = s²,
    s ∈ [−1, 1] (lower surface s < 0), y = yc ± yt with sgn(s)·√x = s:
    y = 4m(s² − s⁴) + 5τ(0.2969 s − sgn(s)(0.1260 s² + 0.3516 s⁴ − 0.2843 s⁶ + 0.1015 s⁸))."""
    m, tau = (0.04, 0.12) if v == "test" else (0.05, 0.13)
    b = np.array([0.1260, 0.3516, -0.2843, 0.1015])  # coefficients of s², s⁴, s⁶, s⁸

    def d(s):
        sg = np.where(s < 0, -1.0, 1.0)
        pw = [s ** (2 * k + 2) for k in range(4)]
        even = sum(b[k] * pw[k] for k in range(4))
        even1 = sum(b[k] * (2 * k + 2) * s ** (2 * k + 1) for k in range(4))
        even2 = sum(b[k] * (2 * k + 2) * (2 * k + 1) * s ** (2 * k) for k in range(4))
        y = 4 * m * (s**2 - s**4) + 5 * tau * (0.2969 * s - sg * even)
        y1 = 4 * m * (2 * s - 4 * s**3) + 5 * tau * (0.2969 - sg * even1)
        y2 = 4 * m * (2 - 12 * s**2) + 5 * tau * (-sg * even2)
        return stack(s**2, y), stack(2 * s, y1), stack(2 + 0 * s, y2)

    name = f"NACA {round(100 * m)}5{round(100 * tau):02d}"
    return Family("airfoil", d, -1.0, 1.0, f"{name} whole section, x = s², s ∈ [−1, 1]")


def fam_waterline(v):
    """Half-breadth y = B(1 − 0.2t² − 1.8t⁴ + t⁶ + e·t(1 − t²)²), x = L·t, t ∈ [−1, 1]:
    full amidships, hollow entrance and run (one inflection near each end)."""
    half_len, beam, e = (3.5, 1.0, 0.1) if v == "test" else (3.2, 1.0, 0.15)

    def d(t):
        w = 1 - t**2
        y = 1 - 0.2 * t**2 - 1.8 * t**4 + t**6 + e * t * w**2
        y1 = -0.4 * t - 7.2 * t**3 + 6 * t**5 + e * (w**2 - 4 * t**2 * w)
        # d/dt [w² − 4t²w] = −4tw − 8tw + 8t³ = −12tw + 8t³
        y2 = -0.4 - 21.6 * t**2 + 30 * t**4 + e * (-12 * t * w + 8 * t**3)
        z = np.zeros_like(t)
        return stack(half_len * t, beam * y), stack(z + half_len, beam * y1), stack(z, beam * y2)

    return Family("waterline", d, -1.0, 1.0, f"({half_len}t, {beam}(1 − 0.2t² − 1.8t⁴ + t⁶ + {e}t(1 − t²)²))")


def fam_ellipse(v):
    a, b, t0, t1 = (3.0, 1.0, 0.2, 0.2 + 1.4 * np.pi) if v == "test" else (2.8, 1.0, 0.0, 1.3 * np.pi)

    def d(t):
        c, s = np.cos(t), np.sin(t)
        return stack(a * c, b * s), stack(-a * s, b * c), stack(-a * c, -b * s)

    return Family("ellipse", d, t0, t1, f"({a} cos t, {b} sin t), t ∈ [{t0:.3g}, {t1:.3g}]")


def fam_logspiral(v):
    b, t0, t1 = (0.15, 0.0, 4 * np.pi) if v == "test" else (0.17, 0.3, 3.8 * np.pi)

    def d(t):
        r = np.exp(b * t)
        c, s = np.cos(t), np.sin(t)
        p = stack(r * c, r * s)
        d1 = stack(r * (b * c - s), r * (b * s + c))
        d2 = stack(r * ((b * b - 1) * c - 2 * b * s), r * ((b * b - 1) * s + 2 * b * c))
        return p, d1, d2

    return Family("logspiral", d, t0, t1, f"e^({b}θ)(cos θ, sin θ), θ ∈ [{t0:.3g}, {t1:.3g}]")


def fam_circle(v):
    r, t0, t1 = (5.0, 0.0, 4 * np.pi / 3) if v == "test" else (5.0, np.pi / 18, 11 * np.pi / 9)
    return Family("circle", _circle_deriv(r), t0, t1, f"radius {r}, angle [{np.degrees(t0):.0f}°, {np.degrees(t1):.0f}°]")


def _circle_deriv(r):
    def d(t):
        c, s = np.cos(t), np.sin(t)
        return stack(r * c, r * s), stack(-r * s, r * c), stack(-r * c, -r * s)

    return d


def fam_strophoid(v):
    """x = 10(t³ − t)/(t² + 1) = 10(t − 2tg), y = 10(t² − 1)/(t² + 1) = 10(1 − 2g), g = 1/(t² + 1)."""
    t0, t1 = (-2.0, 2.0) if v == "test" else (-2.1, 1.9)
    return Family("strophoid", _strophoid_deriv, t0, t1, f"Han et al.'s strophoid, t ∈ [{t0}, {t1}]")


def _strophoid_deriv(t):
    g = 1 / (t**2 + 1)
    g1 = -2 * t * g**2
    g2 = -2 * g**2 + 8 * t**2 * g**3
    tg1 = g - 2 * t**2 * g**2  # (t g)'
    tg2 = -6 * t * g**2 + 8 * t**3 * g**3  # (t g)''
    return (stack(10 * (t - 2 * t * g), 10 * (1 - 2 * g)), stack(10 * (1 - 2 * tg1), -20 * g1), stack(-20 * tg2, -20 * g2))


def fam_epitrochoid(v):
    """((R + r) cos t − d cos(kt), (R + r) sin t − d sin(kt)), k = (R + r)/r: a dented arc."""
    big, small, dd, t0, t1 = (3.0, 1.0, 0.5, 0.0, 1.5 * np.pi) if v == "test" else (3.0, 1.0, 0.55, 0.2, 1.6 * np.pi)
    rr, k = big + small, (big + small) / small

    def d(t):
        c, s, ck, sk = np.cos(t), np.sin(t), np.cos(k * t), np.sin(k * t)
        return (stack(rr * c - dd * ck, rr * s - dd * sk), stack(-rr * s + dd * k * sk, rr * c - dd * k * ck),
                stack(-rr * c + dd * k * k * ck, -rr * s + dd * k * k * sk))

    return Family("epitrochoid", d, t0, t1, f"R = {big}, r = {small}, d = {dd}, t ∈ [{t0:.3g}, {t1:.3g}]")


FAMILIES = [fam_sine, fam_cubic, fam_clothoid, fam_airfoil, fam_waterline, fam_ellipse, fam_logspiral, fam_circle,
            fam_strophoid, fam_epitrochoid]


def check_families(split):
    """The exact derivatives against central differences (a wrong formula would make every
    curvature error meaningless)."""
    for make in FAMILIES:
        f = make(split)
        t = np.linspace(f.t0, f.t1, 37)[1:-1] + 1e-3  # off s = 0 for the airfoil's one-sided formula
        h = 1e-5 * (f.t1 - f.t0)
        p, d1, d2 = f.deriv(t)
        pp, pm = f.points(t + h), f.points(t - h)
        scale = np.abs(p).max() + 1
        e1 = np.abs((pp - pm) / (2 * h) - d1).max() / (np.abs(d1).max() + 1)
        e2 = np.abs((pp - 2 * p + pm) / h**2 - d2).max() / (np.abs(d2).max() + 1)
        if e1 > 1e-6 or e2 > 1e-3 * max(1, scale):
            raise SystemExit(f"family {f.name}: exact derivatives disagree with differences ({e1:.2g}, {e2:.2g})")


# ================================================================ measurement
def chord(p, closed=False):
    q = np.vstack([p, p[:1]]) if closed else p
    d = np.hypot(*np.diff(q, axis=0).T)
    return np.concatenate([[0.0], np.cumsum(d)])


def analysis_spline(p, closed=False):
    """batten's analysis curve: C² cubic, chord-length parameters, not-a-knot (periodic if closed)."""
    t = chord(p, closed)
    if closed:
        return t, CubicSpline(t, np.vstack([p, p[:1]]), bc_type="periodic")
    return t, CubicSpline(t, p, bc_type="not-a-knot")


def curvature_at_points(p, closed=False):
    t, cs = analysis_spline(p, closed)
    t = t[: len(p)]
    d1, d2 = cs(t, 1), cs(t, 2)
    return cross(d1, d2) / np.hypot(d1[:, 0], d1[:, 1]) ** 3


def inflection_positions(p):
    """Positions (fractions of the chord length) of the curvature sign changes of the analysis
    curve of the open point sequence p, by batten's rule (`analysis/metrics.rs`): the curvature
    at each knot and at the vertex of each span's quadratic r'×r'' inside the span, values under
    the rounding floor 64·ε·max|coord|/h_min² skipped, runs whose largest value is under 1e-12
    of the largest skipped; a change is located at the root of the span's quadratic."""
    t, cs = analysis_spline(p)
    h = np.diff(t)
    c = cs.c  # (4, spans, 2): coefficients of (t − t_i)^3, ^2, ^1, ^0
    a3, a2, a1 = c[0], c[1], c[2]
    # r' = a1 + 2 a2 u + 3 a3 u², r'' = 2 a2 + 6 a3 u  ⇒  r'×r'' = 2 a1×a2 + 6 a1×a3 u + 6 a2×a3 u²
    qa, qb, qc = 6 * cross(a2, a3), 6 * cross(a1, a3), 2 * cross(a1, a2)
    floor = 64 * np.finfo(float).eps * np.abs(p).max() / h.min() ** 2
    speed3 = lambda d: np.hypot(d[:, 0], d[:, 1]) ** 3  # noqa: E731
    kn = qc / speed3(a1)  # κ at each span's start
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.where(qa != 0, -qb / (2 * qa), -1.0)
    inside = (u > 0) & (u < h)
    ui = u[inside]
    d1v = a1[inside] + 2 * a2[inside] * ui[:, None] + 3 * a3[inside] * (ui * ui)[:, None]
    kv = (qc[inside] + qb[inside] * ui + qa[inside] * ui * ui) / speed3(d1v)  # κ at the vertices
    d1e, d2e = cs(t[-1], 1), cs(t[-1], 2)
    ke = (d1e[0] * d2e[1] - d1e[1] * d2e[0]) / np.hypot(*d1e) ** 3
    # samples in order along the curve: knot i, then vertex of span i (if inside), ..., last knot
    pos = np.concatenate([t[:-1], t[:-1][inside] + ui, [t[-1]]])
    val = np.concatenate([kn, kv, [ke]])
    order = np.argsort(pos, kind="stable")
    samples = list(zip(pos[order].tolist(), val[order].tolist()))
    # runs of one sign, as SignRuns
    runs = []  # [sign, max |κ|, first sample index, last sample index]
    for j, (_, k) in enumerate(samples):
        if abs(k) <= floor:
            continue
        s = 1 if k > 0 else -1
        if runs and runs[-1][0] == s:
            runs[-1][1] = max(runs[-1][1], abs(k))
            runs[-1][3] = j
        else:
            runs.append([s, abs(k), j, j])
    scale = max((r[1] for r in runs), default=0.0)
    kept = [r for r in runs if r[1] > 1e-12 * scale]
    out = []
    for r0, r1 in zip(kept[:-1], kept[1:]):
        if r0[0] == r1[0]:
            continue
        ta, tb = samples[r0[3]][0], samples[r1[2]][0]
        out.append(_root_between(ta, tb, t, qa, qb, qc) / t[-1])
    return np.array(out)


def _root_between(ta, tb, t, qa, qb, qc):
    """A zero of the piecewise quadratic r'×r'' between parameters ta < tb (first found)."""
    i0 = max(0, np.searchsorted(t, ta, side="right") - 1)
    i1 = min(len(t) - 2, np.searchsorted(t, tb, side="left"))
    for i in range(i0, i1 + 1):
        lo, hi = max(ta, t[i]) - t[i], min(tb, t[i + 1]) - t[i]
        for u in _quadratic_roots(qa[i], qb[i], qc[i]):
            if lo - 1e-12 * (hi - lo) <= u <= hi + 1e-12 * (hi - lo):
                return t[i] + u
    return 0.5 * (ta + tb)


def _quadratic_roots(a, b, c):
    """Real roots of a u² + b u + c (numerically stable form)."""
    if a == 0:
        return [-c / b] if b != 0 else []
    disc = b * b - 4 * a * c
    if disc < 0:
        return []
    q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
    return [q / a] + ([c / q] if q != 0 else [])


def match(result_pos, true_pos, window):
    """One-to-one matches within `window`, closest pairs first; returns the number matched."""
    pairs = sorted((abs(a - b), i, j) for i, a in enumerate(result_pos) for j, b in enumerate(true_pos)
                   if abs(a - b) <= window)
    used_r, used_t = set(), set()
    for _, i, j in pairs:
        if i not in used_r and j not in used_t:
            used_r.add(i)
            used_t.add(j)
    return len(used_r)


def noise_sigma(p, closed=False):
    """batten's noise estimate σ̂ (`analysis/noise.rs`) from the parts v_i = |n·Δᵏp_i|/√C(2k, k),
    k = 5 (k = 3 below 8 points), n the normal of the chord p[i+k+m] − p[i−m] (indices clamped
    on an open curve, wrapped on a closed one); m = 0 unless the noise is comparable to the
    spacing: m = ⌈20·rough/spacing⌉ ≤ n/8, rough the MAD over the whole |Δᵏp|, spacing the
    median distance of neighbours. σ̂ starts as 1.4826·median v, then three times
    σ̂ ← √(mean of v² over v ≤ 3σ̂ / 0.97334), the root mean square clipped at 3σ̂ and
    corrected for the clipping."""
    n = len(p)
    if n < 4:
        return 0.0
    coef = [-1.0, 5.0, -10.0, 10.0, -5.0, 1.0] if n >= 8 else [-1.0, 3.0, -3.0, 1.0]
    k = len(coef) - 1
    gain = math.sqrt(math.comb(2 * k, k))
    count = n if closed else n - k
    idx = lambda i: np.mod(i, n) if closed else np.clip(i, 0, n - 1)  # noqa: E731
    i = np.arange(count)
    dk = sum(c * p[idx(i + j)] for j, c in enumerate(coef))
    rough = _upper_median(np.hypot(dk[:, 0], dk[:, 1])) * MAD_TO_SIGMA / gain
    j = np.arange(n if closed else n - 1)
    spacing = _upper_median(np.hypot(*(p[idx(j + 1)] - p[idx(j)]).T))
    reach = 0
    if spacing > 0:
        m = math.ceil(NORMAL_CHORD_NOISE_SPANS * rough / spacing)
        reach = min(int(m), n // 8) if math.isfinite(m) else 0
    ch = p[idx(i + k + reach)] - p[idx(i - reach)]
    ln = np.hypot(ch[:, 0], ch[:, 1])
    ok = ln > 0
    v = np.abs(dk[ok, 0] * ch[ok, 1] - dk[ok, 1] * ch[ok, 0]) / ln[ok]
    s = MAD_TO_SIGMA * _upper_median(v)
    if not (s > 0 and math.isfinite(s)):
        return float(s / gain)
    for _ in range(CLIP_ROUNDS):
        u = v / s
        kept = u[u <= CLIP]
        if len(kept) == 0:
            break
        s *= math.sqrt(np.sum(kept * kept) / len(kept) / CLIPPED_SQUARE_1D)
    return float(s / gain)


def _upper_median(v):
    """The median as batten takes it: the upper one for an even count, 0 when empty."""
    return float(np.sort(v)[len(v) // 2]) if len(v) else 0.0


def max_disp(a, b):
    return float(np.max(np.hypot(*(a - b).T)))


# ================================================================ running tools
class Timeout(Exception):
    pass


def _alarm(signum, frame):  # noqa: ARG001
    raise Timeout()


def with_timeout(seconds, fn, *args):
    """Run fn(*args) in this (worker) process with a wall-clock limit."""
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        return fn(*args)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def write_csv(path, p):
    with open(path, "w") as f:
        f.write("x,y\n")
        for x, y in p:
            f.write(f"{float(x)!r},{float(y)!r}\n")


def read_points(path):
    return np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)


SUB_ENV = dict(os.environ, RAYON_NUM_THREADS="1")


def analyze(p, tmp, closed=False):
    path = os.path.join(tmp, "an.csv")
    write_csv(path, p)
    cmd = [BATTEN, "analyze", path, "--json"] + (["--closed"] if closed else [])
    out = subprocess.run(cmd, capture_output=True, text=True, check=True, env=SUB_ENV, timeout=120)
    return json.loads(out.stdout)


def run_batten(spec, p, tol, tmp, timeout, closed=False):
    """Returns (points or None, status, seconds, report dict or None, message)."""
    inp, out, rep = (os.path.join(tmp, x) for x in ("in.csv", "out.csv", "rep.json"))
    for f in (out, rep):
        if os.path.exists(f):
            os.remove(f)
    write_csv(inp, p)
    cmd = [BATTEN, "fair", inp, "-o", out, *method_args(spec), "--tolerance", tol, "--report", rep]
    if closed:
        cmd.append("--closed")
    t0 = time.perf_counter()
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=SUB_ENV)
    except subprocess.TimeoutExpired:
        return None, "timeout", time.perf_counter() - t0, None, f"over {timeout} s"
    dt = time.perf_counter() - t0
    msg = r.stderr.strip().splitlines()[-1] if r.stderr.strip() else ""
    if r.returncode not in (0, 1) or not os.path.exists(out):
        return None, "failed", dt, None, f"exit {r.returncode}: {msg}"
    report = json.load(open(rep)) if os.path.exists(rep) else None
    status = "ok" if r.returncode == 0 else ("tol_missed" if report and not report.get("tolerance_met", True)
                                             else "failed_output")
    return read_points(out), status, dt, report, msg


def peer_csaps(p, target):
    t = chord(p)

    def fit(x):
        return csaps.CubicSmoothingSpline(t, p.T, smooth=1.0 / (1.0 + math.exp(-x)))(t).T

    lo, hi = -40.0, 40.0  # logit p: −40 is the least-squares line, +40 interpolation
    best = fit(hi)
    low = fit(lo)
    if max_disp(low, p) <= target:
        return low
    for _ in range(CSAPS_BISECTIONS):
        mid = 0.5 * (lo + hi)
        q = fit(mid)
        if max_disp(q, p) <= target:
            best, hi = q, mid
        else:
            lo = mid
    return best


def peer_gcv(p, sigma_hat):  # noqa: ARG001
    t = chord(p)
    return np.c_[make_smoothing_spline(t, p[:, 0])(t), make_smoothing_spline(t, p[:, 1])(t)]


def peer_splprep(p, sigma_hat, closed=False):
    with warnings.catch_warnings():  # FITPACK's "s too small" warnings: the result is measured as it is
        warnings.simplefilter("ignore", RuntimeWarning)
        return _splprep(p, sigma_hat, closed)


def _splprep(p, sigma_hat, closed):
    t = chord(p, closed)
    if closed:
        q = np.vstack([p, p[:1]])
        tck, _ = splprep(q.T, u=t, s=2 * len(p) * sigma_hat**2, k=3, per=1, quiet=1)
        return np.array(splev(t[:-1], tck)).T
    tck, _ = splprep(p.T, u=t, s=2 * len(p) * sigma_hat**2, k=3, quiet=1)
    return np.array(splev(t, tck)).T


def peer_occt(p, sigma_hat):
    """Open CASCADE's variational smoothing, exactly as `Geom2dAPI_PointsToBSpline(points, W1,
    W2, W3, DegMax, Continuity, Tol2D)` sets it up (Geom2dAPI_PointsToBSpline.cxx: one
    AppDef_Variational over a 2-D multiline, no constraints, at most 1000 segments, no min-max,
    2 re-parametrisation iterations when Tol2D > 1e-3, else none), built here from its parts so
    that the parameters it gives each point (`AppDef_Variational::Parameters`, after its
    iterations) can be read: output point i is the curve at the i-th of those parameters,
    sorted (tangential noise can swap neighbours' parameters; the curve is the same, and the
    points come out in order along it), runs of equal parameters spread (`spread_ties`)."""
    n = len(p)
    tol = TOL_FACTOR * sigma_hat
    line = AppDef_MultiLine(n)
    for i, (x, y) in enumerate(p):
        mpc = AppDef_MultiPointConstraint(0, 1)
        mpc.SetPoint2d(1, gp_Pnt2d(float(x), float(y)))
        line.SetValue(i + 1, mpc)
    couples = HArray1_AppParCurves_ConstraintCouple(1, n)
    for i in range(1, n + 1):
        couples.SetValue(i, AppParCurves_ConstraintCouple(i, AppParCurves_Constraint.AppParCurves_NoConstraint))
    var = AppDef_Variational(line, 1, n, couples)
    var.SetMaxDegree(OCCT_DEGMAX)
    var.SetContinuity(GeomAbs_Shape.GeomAbs_C2)
    var.SetMaxSegment(1000)
    var.SetTolerance(tol)
    var.SetWithMinMax(False)
    var.SetNbIterations(2 if tol > 1e-3 else 0)
    var.SetCriteriumWeight(*OCCT_WEIGHTS)
    if not var.IsCreated() or var.IsOverConstrained():
        raise RuntimeError("AppDef_Variational: not created or over-constrained")
    var.Approximate()
    if not var.IsDone():
        raise RuntimeError("AppDef_Variational: not done")
    curve = var.Value()
    par = var.Parameters()
    us = spread_ties(np.sort([par.Value(i) for i in range(par.Lower(), par.Upper() + 1)]))
    out = np.empty((n, 2))
    pt = gp_Pnt2d()
    for i, u in enumerate(us):
        curve.Value(1, float(u), pt)
        out[i] = pt.X(), pt.Y()
    return out


def check_occt():
    """`peer_occt` against `Geom2dAPI_PointsToBSpline` itself on a noisy sine: its points must lie
    on the API's curve (the setup above is meant to be the API's, with the parameters exposed)."""
    try:
        from OCP.Geom2dAPI import Geom2dAPI_PointsToBSpline, Geom2dAPI_ProjectPointOnCurve
        from OCP.OCP.collections import Array1_gp_Pnt2d
    except ImportError:  # pragma: no cover — another OCP layout: nothing to compare with
        return
    f = fam_sine("test")
    p = f.points(np.linspace(f.t0, f.t1, 200)) + np.random.default_rng(0).normal(0.0, 0.05, (200, 2))
    sigma_hat = noise_sigma(p)
    arr = Array1_gp_Pnt2d(1, len(p))
    for i, (x, y) in enumerate(p):
        arr.SetValue(i + 1, gp_Pnt2d(float(x), float(y)))
    curve = Geom2dAPI_PointsToBSpline(arr, *OCCT_WEIGHTS, OCCT_DEGMAX, GeomAbs_Shape.GeomAbs_C2,
                                      TOL_FACTOR * sigma_hat).Curve()
    ends = [curve.Value(curve.FirstParameter()), curve.Value(curve.LastParameter())]

    def distance(x, y):  # to the curve: the nearest foot of a perpendicular, else the nearer end
        pt = gp_Pnt2d(float(x), float(y))
        proj = Geom2dAPI_ProjectPointOnCurve(pt, curve)
        return proj.LowerDistance() if proj.NbPoints() > 0 else min(pt.Distance(e) for e in ends)

    far = max(distance(x, y) for x, y in peer_occt(p, sigma_hat))
    if far > OCCT_CHECK_REL * float(np.hypot(*np.ptp(p, axis=0))):
        raise SystemExit(f"occt peer: its points lie up to {far:.3g} off Geom2dAPI_PointsToBSpline's curve")


def spread_ties(us):
    """Sorted parameters made strictly increasing: a run of (nearly) equal parameters, points
    that the fit maps to one curve point (mostly noisy end points beyond the curve's ends), is
    spread evenly up to the next distinct parameter (down to the previous one at the end)."""
    us = us.copy()
    gap = OCCT_TIE_GAP * max(us[-1] - us[0], 1e-300)
    i, n = 0, len(us)
    while i < n:
        j = i
        while j + 1 < n and us[j + 1] - us[i] <= gap:
            j += 1
        if j > i:
            if j + 1 < n:  # spread [u_i, u_{j+1}) over the run
                us[i:j + 1] = us[i] + (us[j + 1] - us[i]) * np.arange(j - i + 1) / (j - i + 1)
            else:  # a run at the end: spread (u_{i-1}, u_i]
                lo = us[i - 1] if i > 0 else us[i] - gap
                us[i:] = us[i] - (us[i] - lo) * np.arange(j - i, -1, -1) / (j - i + 1)
        i = j + 1
    return us


# ================================================================ one noisy curve
def batten_tolerance(tol_mode, diag, sigma_hat, sigma=None):
    """The `--tolerance` argument for batten: 3σ̂ as a number (`hat3`), the word `auto` (batten
    takes k·σ̂ itself, k = 3 unless the method has its own: the same figure with the same
    estimator), or 3σ with the true σ. Numbers are floored as batten floors `auto`."""
    if tol_mode == "auto":
        return "auto"
    return repr(max(TOL_FACTOR * (sigma if tol_mode == "true3" else sigma_hat), AUTO_TOLERANCE_FLOOR_REL * diag))


def noisy_case(task):
    """Run every tool on one noisy curve; returns the result rows."""
    split, fi, n, noise, seed, methods, peers, tol_mode, limits, timeout = task
    fam = FAMILIES[fi](split)
    tau = np.linspace(fam.t0, fam.t1, n)
    truth = fam.points(tau)
    diag = float(np.hypot(*(truth.max(0) - truth.min(0))))
    sigma = noise * diag
    rng = np.random.default_rng([seed, fi, n, int(round(noise * 1e4)), 0 if split == "test" else 1])
    noisy = truth + rng.normal(0.0, sigma, size=truth.shape)
    k_true = fam.kappa(tau)
    k_rms = float(np.sqrt(np.mean(k_true**2)))
    g, s = fam.arclength()
    true_pos = np.interp(fam.inflections(), g, s) / s[-1]
    window = max(MATCH_FRACTION, MATCH_SPACINGS / (n - 1))
    sig_hat = noise_sigma(noisy)
    peer_sigma = sigma if tol_mode == "true3" else sig_hat
    tol_arg = batten_tolerance(tol_mode, diag, sig_hat, sigma)
    base = dict(split=split, family=fam.name, n=n, noise=noise, sigma=sigma, seed=seed, true_inflections=len(true_pos),
                noise_sigma_hat=sig_hat)
    rows = []

    def measure(tool, matched_to, pts, status, dt, tol, note="", report=None):
        row = dict(base, tool=tool, matched_to=matched_to, status=status, time_s=dt, tolerance=tol, note=note)
        if report is not None:
            row["noise_sigma_report"] = report.get("noise_sigma")
            row["tol_source"] = report.get("tolerance_source")
            row["iterations"] = report.get("iterations")
        if pts is None:
            rows.append(row)
            return None
        if not np.all(np.isfinite(pts)):
            row.update(status="failed", note="non-finite output")
            rows.append(row)
            return None
        md = max_disp(pts, noisy)
        try:
            a = analyze(pts, tmp)
            pos = inflection_positions(pts)
            k = curvature_at_points(pts)
        except Exception as e:  # noqa: BLE001 — a degenerate output is that tool's failure
            row.update(status="failed", note=f"unmeasurable output: {e}")
            rows.append(row)
            return None
        m = match(pos, true_pos, window)
        row.update(max_disp=md, max_disp_sigma=md / sigma, inflections=a["inflections"], vibrations=a["vibrations"],
                   infl_mismatch=int(len(pos) != a["inflections"]), matched=m, spurious=a["inflections"] - m,
                   lost=len(true_pos) - m, kappa_rel=float(np.sqrt(np.mean((k - k_true) ** 2)) / k_rms),
                   over_tol=int(tol is not None and md > tol * (1 + 1e-9) + 1e-12 * diag))
        rows.append(row)
        return md

    def skipped(tool, limit_key):
        """Whether --limit leaves `tool` out at this n (then recorded as skipped)."""
        if limit_key in limits and n > limits[limit_key]:
            rows.append(dict(base, tool=tool, matched_to="", status="skipped", note=f"n > {limits[limit_key]}"))
            return True
        return False

    with tempfile.TemporaryDirectory() as tmp:
        measure("input", "", noisy, "ok", 0.0, None)
        for spec in methods:
            if skipped(spec, spec.partition("[")[0]):
                continue
            pts, status, dt, rep, msg = run_batten(spec, noisy, tol_arg, tmp, timeout)
            tol = rep.get("tolerance") if rep else None
            md = measure(spec, "", pts, status, dt, tol, msg if status != "ok" else "", rep)
            if md is not None and "csaps" in peers and not skipped(f"csaps@{spec}", "csaps"):
                run_peer(measure, f"csaps@{spec}", spec, peer_csaps, (noisy, md), md, timeout)
        for tool, fn, tol in (("gcv", peer_gcv, None), ("splprep", peer_splprep, None),
                              ("occt", peer_occt, TOL_FACTOR * peer_sigma)):
            if tool in peers and not skipped(tool, tool):
                run_peer(measure, tool, "", fn, (noisy, peer_sigma), tol, timeout)
    return rows


def run_peer(measure, tool, matched_to, fn, args, tol, timeout):
    t0 = time.perf_counter()
    try:
        pts = with_timeout(timeout, fn, *args)
    except Timeout:
        measure(tool, matched_to, None, "timeout", time.perf_counter() - t0, tol, f"over {timeout} s")
        return
    except Exception as e:  # noqa: BLE001 — a peer that throws is counted, not fatal
        measure(tool, matched_to, None, "failed", time.perf_counter() - t0, tol, f"{type(e).__name__}: {e}")
        return
    measure(tool, matched_to, pts, "ok", time.perf_counter() - t0, tol)


# ================================================================ clean input
def example_truths():
    """The bundled truth files with their analytic forms (examples/data/README.md)."""
    data = os.path.join(ROOT, "examples", "data")
    cases = []

    def add(fname, fam, tau, closed=False):
        path = os.path.join(data, fname)
        if not os.path.exists(path):
            return
        if fname.endswith(".json"):
            pts = np.array(json.load(open(path))["points"], float)
        else:
            lines = [ln for ln in open(path) if ln.strip() and not ln.startswith("#")]
            pts = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])  # lines[0]: the header
        exact = fam.points(tau)
        if pts.shape != exact.shape or np.abs(pts - exact).max() > 1e-9 * (1 + np.abs(exact).max()):
            print(f"warning: {fname} does not match its analytic form; skipped", file=sys.stderr)
            return
        cases.append((fname, pts, fam.kappa(tau), closed))

    add("strophoid-truth.csv", Family("strophoid", _strophoid_deriv, -2, 2, ""), np.linspace(-2, 2, 65))
    sine = Family("sine", lambda t: (stack(t, np.sin(t / 2)), stack(1 + 0 * t, np.cos(t / 2) / 2),
                                     stack(0 * t, -np.sin(t / 2) / 4)), 0, 4 * np.pi, "")
    add("sine-truth.csv", sine, np.linspace(0, 4 * np.pi, 30))
    add("arc-truth.csv", Family("arc", _circle_deriv(5.0), 0, 2 * np.pi / 3, ""), np.linspace(0, 2 * np.pi / 3, 40))
    add("clothoid-truth.csv", Family("clothoid", _fresnel_deriv(1.0), 0, 2, ""), np.linspace(0, 2, 50))
    cub = Family("cubic", lambda t: (stack(t, t**3 - t), stack(1 + 0 * t, 3 * t**2 - 1), stack(0 * t, 6 * t)), -1.5, 1.5, "")
    add("cubic-truth.csv", cub, np.linspace(-1.5, 1.5, 41))
    ell = Family("ellipse", lambda t: (stack(3 * np.cos(t), 2 * np.sin(t)), stack(-3 * np.sin(t), 2 * np.cos(t)),
                                       stack(-3 * np.cos(t), -2 * np.sin(t))), 0, 2 * np.pi, "")
    add("ellipse-truth.json", ell, 2 * np.pi * np.arange(48) / 48, closed=True)
    return cases


def _fresnel_deriv(scale):
    def d(t):
        s, c = fresnel(t)
        th = 0.5 * np.pi * t**2
        return (scale * stack(c, s), scale * stack(np.cos(th), np.sin(th)),
                scale * np.pi * t[:, None] * stack(-np.sin(th), np.cos(th)))

    return d


def clean_cases():
    cases = []
    circ = Family("circle", _circle_deriv(5.0), 0, 2 * np.pi, "")
    tau = 2 * np.pi * np.arange(64) / 64
    cases.append(("circle (closed, 64)", circ.points(tau), circ.kappa(tau), True))
    tau = np.linspace(0.3, 0.3 + 3 * np.pi / 2, 100)
    cases.append(("circle arc 270° (100)", circ.points(tau), circ.kappa(tau), False))
    clo = Family("clothoid", _fresnel_deriv(3.0), -1.0, 1.6, "")
    tau = np.linspace(-1.0, 1.6, 200)
    cases.append(("clothoid u ∈ [−1, 1.6] (200)", clo.points(tau), clo.kappa(tau), False))
    spi = fam_logspiral("test")
    tau = np.linspace(spi.t0, spi.t1, 300)
    cases.append(("log spiral (300)", spi.points(tau), spi.kappa(tau), False))
    return cases + example_truths()


def clean_case(task):
    label, pts, k_true, closed, methods, peers, limits, timeout, tol_mode = task
    rows = []
    diag = float(np.hypot(*(pts.max(0) - pts.min(0))))
    k_rms = float(np.sqrt(np.mean(k_true**2)))
    with tempfile.TemporaryDirectory() as tmp:
        before = analyze(pts, tmp, closed)
        k_err0 = float(np.sqrt(np.mean((curvature_at_points(pts, closed) - k_true) ** 2))) / k_rms
        sig_hat = noise_sigma(pts, closed)

        def record(tool, tol_label, out, status, note=""):
            row = dict(case=label, tool=tool, tolerance=tol_label, status=status, note=note,
                       infl_before=before["inflections"], vib_before=before["vibrations"], kappa_before=k_err0)
            if out is not None:
                a = analyze(out, tmp, closed)
                k_err = float(np.sqrt(np.mean((curvature_at_points(out, closed) - k_true) ** 2))) / k_rms
                row.update(infl_after=a["inflections"], vib_after=a["vibrations"], kappa_after=k_err,
                           max_disp=max_disp(out, pts))
                bad = []
                if a["inflections"] > before["inflections"]:
                    bad.append("inflections")
                if a["vibrations"] > before["vibrations"]:
                    bad.append("vibrations")
                if k_err > k_err0 * (1 + CLEAN_KAPPA_SLACK) + 1e-12:
                    bad.append("curvature error")
                row["violation"] = ", ".join(bad)
                row["fewer_inflections"] = int(a["inflections"] < before["inflections"])
            rows.append(row)

        for spec in methods:
            name = spec.partition("[")[0]
            if name in limits and len(pts) > limits[name]:
                continue
            auto = batten_tolerance("auto" if tol_mode == "auto" else "hat3", diag, sig_hat)
            for tol_label, tol in (("auto" if auto == "auto" else "3σ̂", auto),
                                   (CLEAN_FIXED_LABEL, repr(CLEAN_FIXED_TOL * diag))):
                out, status, _, _, msg = run_batten(spec, pts, tol, tmp, timeout, closed)
                record(spec, tol_label, out, status, msg if status != "ok" else "")
        for tool, fn in (("gcv", peer_gcv), ("splprep", peer_splprep), ("occt", peer_occt)):
            if tool not in peers or (closed and tool != "splprep"):
                continue
            try:
                out = with_timeout(timeout, fn, pts, sig_hat)
                record(tool, "3σ̂" if tool != "gcv" else "GCV", out, "ok")
            except Exception as e:  # noqa: BLE001
                record(tool, "", None, "failed", f"{type(e).__name__}: {e}")
    return rows


# ================================================================ report
def med(xs):
    xs = [x for x in xs if x is not None and not (isinstance(x, float) and math.isnan(x))]
    return statistics.median(xs) if xs else float("nan")


def summarize(rows):
    """Per tool: results, failures, spurious, curves with any, lost, medians."""
    measured = [r for r in rows if "kappa_rel" in r]
    out = {}
    for tool in dict.fromkeys(r["tool"] for r in rows):
        rs = [r for r in rows if r["tool"] == tool]
        ms = [r for r in measured if r["tool"] == tool]
        out[tool] = dict(
            curves=len(rs),
            measured=len(ms),
            failed=sum(r["status"] in ("failed", "timeout") for r in rs),
            exit1=sum(r["status"] in ("tol_missed", "failed_output") for r in rs),
            timeouts=sum(r["status"] == "timeout" for r in rs),
            skipped=sum(r["status"] == "skipped" for r in rs),
            tol_missed=sum(r["status"] == "tol_missed" for r in rs),
            spurious=sum(r["spurious"] for r in ms),
            with_spurious=sum(r["spurious"] > 0 for r in ms),
            lost=sum(r["lost"] for r in ms),
            true=sum(r["true_inflections"] for r in ms),
            kappa=med([r["kappa_rel"] for r in ms]),
            disp=med([r["max_disp_sigma"] for r in ms]),
            over_tol=sum(r.get("over_tol", 0) for r in ms),
            time=med([r["time_s"] for r in ms]),
            mismatch=sum(r["infl_mismatch"] for r in ms),
        )
    return out


def cell(rows, tool, key, value):
    """The totals of one tool over the measured rows with row[key] == value (None: no rows)."""
    ms = [r for r in rows if r["tool"] == tool and r[key] == value and "kappa_rel" in r]
    if not ms:
        return None
    return dict(curves=len(ms), spurious=sum(r["spurious"] for r in ms), with_spurious=sum(r["spurious"] > 0 for r in ms),
                lost=sum(r["lost"] for r in ms), true=sum(r["true_inflections"] for r in ms),
                kappa=med([r["kappa_rel"] for r in ms]))


def clean_summary(clean_rows):
    """Per tool: runs, runs with a violation (and how many of them at the fixed, given tolerance),
    runs with fewer inflections, runs not measured."""
    per = {}
    for r in clean_rows:
        p = per.setdefault(r["tool"], dict(runs=0, violations=0, violations_given=0, fewer_inflections=0,
                                           not_measured=0))
        p["runs"] += 1
        p["violations"] += bool(r.get("violation"))
        p["violations_given"] += bool(r.get("violation")) and r["tolerance"] == CLEAN_FIXED_LABEL
        p["fewer_inflections"] += r.get("fewer_inflections", 0)
        p["not_measured"] += "infl_after" not in r
    return per


def fmt(x, spec=".3g"):
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def markdown(rows, clean_rows, args, meta):
    L = []
    L.append(f"# Quality benchmark (`bench/quality.py`, split `{args.split}`{', quick' if args.quick else ''})\n")
    L.append(f"Command: `{meta['command']}`  ")
    L.append(f"batten: `{meta['batten']}` ({meta['version']}); tolerance mode `{args.tol_mode}`; "
             f"{meta['curves']} noisy curves (families × n {meta['sizes']} × σ {', '.join(f'{x:.1%}' for x in NOISES)} "
             f"of the diagonal × seeds {meta['seeds']}); wall time {meta['wall']:.0f} s on {args.jobs} workers.  ")
    L.append(f"Peers: {', '.join(meta['peers']) or 'none'}{meta['peer_note']}. The protocol is the script's docstring.\n")
    L.append("Inflection matching window: max(3 % of the length, 2 point spacings). *spurious*: result "
             "inflections with no true one in the window; *curves w/ any*: curves with at least one; "
             "*lost*: true inflections with no result one (of the total true count); *κ err*: median over "
             "curves of RMS(κ − κ_true)/RMS(κ_true); *max disp*: median max displacement in units of the true σ; "
             "*failed*: no measurable result (exit 1, a missed tolerance with the output written, is measured "
             "and counted apart); *over tol*: results farther than their tolerance (batten: the report's; occt: its Tol2D; "
             "csaps: the matched displacement); *time*: median wall time (batten: the whole CLI run, one "
             "thread; csaps: the bisection).\n")
    summ = summarize(rows)
    L.append("## Totals\n")
    L.append("| tool | curves | failed | spurious | curves w/ any | lost | κ err (median) | max disp / σ | over tol | time [ms] |")
    L.append("|---|---|---|---|---|---|---|---|---|---|")
    for tool, s in summ.items():
        failed = f"{s['failed']}" + (f" ({s['timeouts']} timeouts)" if s["timeouts"] else "") + \
            (f", {s['skipped']} skipped" if s["skipped"] else "") + (f", {s['exit1']} exit 1" if s["exit1"] else "")
        L.append(f"| {tool} | {s['measured']} | {failed} | {s['spurious']} | {s['with_spurious']} | "
                 f"{s['lost']} / {s['true']} | {fmt(s['kappa'])} | {fmt(s['disp'])} | {s['over_tol']} | "
                 f"{fmt(1e3 * s['time'] if s['measured'] else float('nan'), '.1f')} |")
    if "occt" in summ and summ["occt"]["measured"]:
        o = summ["occt"]
        L.append(f"\nIssue #18's goal, against occt ({o['spurious']} spurious, median κ err {fmt(o['kappa'])}): "
                 "fewer spurious inflections in total and a median κ err no worse.\n")
        L.append("| batten method | spurious | κ err | fewer spurious | κ err no worse | curves not measured |")
        L.append("|---|---|---|---|---|---|")
        for tool, s in summ.items():
            if tool in ("input", "gcv", "splprep", "occt") or tool.startswith("csaps@") or not s["measured"]:
                continue
            L.append(f"| {tool} | {s['spurious']} | {fmt(s['kappa'])} | {'yes' if s['spurious'] < o['spurious'] else 'no'} | "
                     f"{'yes' if s['kappa'] <= o['kappa'] else 'no'} | {s['curves'] - s['measured']} |")
    rel = [abs(r["noise_sigma_report"] - r["noise_sigma_hat"]) / r["noise_sigma_hat"] for r in rows
           if r.get("noise_sigma_report") is not None and r["noise_sigma_hat"] > 0]
    if rel:
        L.append(f"\nσ̂ computed here and the `noise_sigma` of batten's reports differ by at most {max(rel):.1e} "
                 f"(relative, {len(rel)} reports); σ̂/σ: median {med([r['noise_sigma_hat'] / r['sigma'] for r in rows if r['tool'] == 'input']):.3f}.")
    mism = sum(s["mismatch"] for s in summ.values())
    L.append(f"\nInflection counts here and in `batten analyze` disagreed on {mism} results "
             "(the counts above are `analyze`'s).\n")
    tools = list(summ)
    for key, title, values, label in (
        ("family", "Per family", [f(args.split).name for f in FAMILIES], str),
        ("n", "Per n", meta["sizes_list"], str),
        ("noise", "Per noise level (σ / diagonal)", NOISES, lambda x: f"{x:.1%}"),
    ):
        L.append(f"## {title}\n")
        L.append("Each cell: spurious inflections (curves with any) / true lost / median κ err.\n")
        L.append("| tool | " + " | ".join(label(v) for v in values) + " |")
        L.append("|---|" + "---|" * len(values))
        for tool in tools:
            cells = []
            for v in values:
                c = cell(rows, tool, key, v)
                cells.append("–" if c is None else
                             f"{c['spurious']} ({c['with_spurious']}) / {c['lost']} / {fmt(c['kappa'], '.2g')}")
            L.append(f"| {tool} | " + " | ".join(cells) + " |")
        L.append("")
    L.append("## True inflections per family\n")
    L.append("| family | curve | true inflections |")
    L.append("|---|---|---|")
    for make in FAMILIES:
        f = make(args.split)
        L.append(f"| {f.name} | {f.note} | {len(f.inflections())} |")
    L.append("")
    bad = [r for r in rows if r["status"] not in ("ok", "skipped")]
    L.append("## Failures, timeouts, missed tolerances\n")
    if not bad:
        L.append("None.\n")
    else:
        counts = defaultdict(int)
        for r in bad:
            counts[(r["tool"], r["status"], (r.get("note") or "")[:90])] += 1
        L.append("| tool | status | runs | message (first) |")
        L.append("|---|---|---|---|")
        for (tool, st, note), c in sorted(counts.items()):
            L.append(f"| {tool} | {st} | {c} | {note.replace('|', '/')} |")
        L.append("")
    if clean_rows is not None:
        L.append("## Clean input\n")
        L.append("Exact samples; a violation is more inflections or vibrations than the input, or a relative "
                 f"curvature error more than {CLEAN_KAPPA_SLACK:.0%} above the input's own. "
                 f"Tolerance 3σ̂ ({'`--tolerance auto`' if args.tol_mode == 'auto' else 'as a number, floored at 1e-12 of the diagonal'}) "
                 "and a fixed one of 0.5 % of the diagonal.\n")
        per = clean_summary(clean_rows)
        L.append("*fewer inflections*: runs that removed inflections of the exact samples (not counted as "
                 "violations: the sine's and the clothoid's ends sit at zeros of κ, where the spline's sign "
                 "changes are marginal).\n")
        L.append("*with a violation*: at the data's own tolerance (3σ̂ or `auto`, what a user gets without "
                 "choosing one; the peers' only runs) and at the fixed tolerance, which asks a fairing method "
                 "to move the curve towards less curvature variation inside it: there a sine or a cubic, "
                 "exact but not of least variation, moves away from the curve it was sampled from (batten's "
                 "contract, README, Clean curves).\n")
        L.append("| tool | runs | with a violation: data's tolerance | with a violation: fixed tolerance "
                 "| fewer inflections | failed / not supported |")
        L.append("|---|---|---|---|---|---|")
        for tool, c in per.items():
            L.append(f"| {tool} | {c['runs']} | {c['violations'] - c['violations_given']} | {c['violations_given']} "
                     f"| {c['fewer_inflections']} | {c['not_measured']} |")
        L.append("\nViolations:\n")
        viol = [r for r in clean_rows if r.get("violation")]
        if not viol:
            L.append("None.\n")
        else:
            L.append("| case | tool | tolerance | violation | inflections | vibrations | κ err before → after | max disp |")
            L.append("|---|---|---|---|---|---|---|---|")
            for r in viol:
                L.append(f"| {r['case']} | {r['tool']} | {r['tolerance']} | {r['violation']} | "
                         f"{r['infl_before']} → {r['infl_after']} | {r['vib_before']} → {r['vib_after']} | "
                         f"{r['kappa_before']:.3g} → {r['kappa_after']:.3g} | {r['max_disp']:.3g} |")
            L.append("")
        fails = [r for r in clean_rows if "infl_after" not in r]
        if fails:
            L.append("Not measured (method failed or does not take the input):\n")
            L.append("| case | tool | tolerance | status | message |")
            L.append("|---|---|---|---|---|")
            for r in fails:
                L.append(f"| {r['case']} | {r['tool']} | {r['tolerance']} | {r['status']} | "
                         f"{(r.get('note') or '')[:90].replace('|', '/')} |")
            L.append("")
    return "\n".join(L)


def json_safe(x):
    """NaN and infinities as null, numpy scalars as Python numbers, recursively."""
    if isinstance(x, dict):
        return {str(k): json_safe(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [json_safe(v) for v in x]
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


def results_json(rows, clean_rows, args, meta):
    """Everything the Markdown shows, as data: totals and breakdowns per tool, the clean-input
    summary and violations, and every row."""
    summ = summarize(rows)
    tools = list(summ)
    fams = [f(args.split).name for f in FAMILIES]
    out = dict(
        meta=dict(meta, split=args.split, quick=args.quick, tol_mode=args.tol_mode, noises=NOISES,
                  match_fraction=MATCH_FRACTION, match_spacings=MATCH_SPACINGS, tol_factor=TOL_FACTOR,
                  occt_weights=OCCT_WEIGHTS, true_inflections={f(args.split).name: len(f(args.split).inflections())
                                                                for f in FAMILIES}),
        totals=summ,
        per_family={t: {v: cell(rows, t, "family", v) for v in fams} for t in tools},
        per_n={t: {str(v): cell(rows, t, "n", v) for v in meta["sizes_list"]} for t in tools},
        per_noise={t: {str(v): cell(rows, t, "noise", v) for v in NOISES} for t in tools},
        rows=rows,
    )
    if clean_rows is not None:
        out["clean"] = dict(summary=clean_summary(clean_rows), violations=[r for r in clean_rows if r.get("violation")],
                            rows=clean_rows)
    return json_safe(out)


def write_rows_csv(path, rows):
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)


# ================================================================ main
def batten_methods():
    out = subprocess.run([BATTEN, "methods"], capture_output=True, text=True, check=True)
    return [line.split()[0] for line in out.stdout.splitlines() if line.strip() and not line[0].isspace()]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--split", choices=["test", "tune"], default="test")
    ap.add_argument("--quick", action="store_true", help="n ∈ {30, 300}, one seed")
    ap.add_argument("--methods", default=None, help="comma-separated batten method specs (default: all)")
    ap.add_argument("--peers", default=None, help="csaps,gcv,splprep,occt or none (default: all available)")
    ap.add_argument("--tol-mode", choices=["hat3", "auto", "true3"], default="hat3",
                    help="batten's --tolerance: hat3 = 3σ̂ as a number (default; any binary), auto = the word "
                    "`auto` (batten estimates σ̂ itself; band's default), true3 = 3σ with the true σ")
    ap.add_argument("--auto", dest="tol_mode", action="store_const", const="auto",
                    help="short for --tol-mode auto: pass --tolerance auto to batten")
    ap.add_argument("--limit", default="", help="METHOD=NMAX,...: skip METHOD above NMAX points")
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds per run")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--families", default=None, help="comma-separated subset of the families")
    ap.add_argument("--sizes", default=None, help="comma-separated n (default: 30,100,300,1000)")
    ap.add_argument("--no-clean", action="store_true", help="skip the clean-input check")
    ap.add_argument("--out", default=None)
    ap.add_argument("--csv", default=None)
    ap.add_argument("--json", default=None, help="also write the totals, breakdowns and rows as JSON to this file")
    args = ap.parse_args()

    if not os.path.exists(BATTEN):
        raise SystemExit(f"no batten binary at {BATTEN}: build it (cargo build --release -p batten-cli) or set BATTEN_BIN")
    check_families(args.split)
    if HAVE_OCCT:
        check_occt()
    methods = [m.strip() for m in args.methods.split(",")] if args.methods else batten_methods()
    methods = [m for m in methods if m]
    known = batten_methods()
    for m in methods:
        method_args(m)
        if m.partition("[")[0] not in known:  # measured anyway: every run of it is reported as failed
            print(f"warning: {BATTEN} does not list method {m.partition('[')[0]!r} (it has {', '.join(known)}); "
                  "its runs will be reported as failures", file=sys.stderr)
    available = ["csaps"] * (csaps is not None) + ["gcv", "splprep"] + ["occt"] * HAVE_OCCT
    peer_note = "" if HAVE_OCCT else " (OCP not installed: `pip install cadquery-ocp-novtk` for occt)"
    if args.peers is None:
        peers = available
    else:
        peers = [] if args.peers.strip() == "none" else [p.strip() for p in args.peers.split(",") if p.strip()]
        missing = [p for p in peers if p not in available]
        if missing:
            raise SystemExit(f"peer(s) {', '.join(missing)} not available here; available: {', '.join(available)}")
    limits = {}
    for item in filter(None, (s.strip() for s in args.limit.split(","))):
        k, _, v = item.partition("=")
        limits[k.strip()] = int(v)
    sizes = [int(x) for x in args.sizes.split(",")] if args.sizes else (QUICK_SIZES if args.quick else SIZES)
    seeds = SEEDS[args.split][:1] if args.quick else SEEDS[args.split]
    fams = range(len(FAMILIES))
    if args.families:
        names = [f(args.split).name for f in FAMILIES]
        want = [s.strip() for s in args.families.split(",")]
        bad = [w for w in want if w not in names]
        if bad:
            raise SystemExit(f"unknown famil(ies) {', '.join(bad)}; known: {', '.join(names)}")
        fams = [names.index(w) for w in want]
    default_out = os.path.join(ROOT, "bench", "results-quality" + ("" if args.split == "test" else "-tune")
                               + ("-quick" if args.quick else "") + ".md")
    out_md = args.out or default_out
    out_csv = args.csv or os.path.splitext(out_md)[0] + ".csv"

    tasks = [(args.split, fi, n, noise, seed, methods, peers, args.tol_mode, limits, args.timeout)
             for n in sorted(sizes, reverse=True) for fi in fams for noise in NOISES for seed in seeds]
    t0 = time.time()
    rows = []
    with mp.Pool(args.jobs) as pool:
        for k, rs in enumerate(pool.imap_unordered(noisy_case, tasks), 1):
            rows.extend(rs)
            if k % 10 == 0 or k == len(tasks):
                print(f"{k}/{len(tasks)} curves, {time.time() - t0:.0f} s", file=sys.stderr)
        clean_rows = None
        if not args.no_clean:
            ctasks = [(label, pts, k, closed, methods, peers, limits, args.timeout, args.tol_mode)
                      for label, pts, k, closed in clean_cases()]
            clean_rows = [r for rs in pool.imap(clean_case, ctasks) for r in rs]
    wall = time.time() - t0
    key = {f(args.split).name: i for i, f in enumerate(FAMILIES)}
    rows.sort(key=lambda r: (key[r["family"]], r["n"], r["noise"], r["seed"]))
    version = subprocess.run([BATTEN, "--version"], capture_output=True, text=True).stdout.strip()
    meta = dict(command="python3 bench/quality.py " + " ".join(sys.argv[1:]), batten=os.path.relpath(BATTEN, ROOT)
                if BATTEN.startswith(ROOT) else BATTEN, version=version or "?", curves=len(tasks),
                sizes="{" + ", ".join(map(str, sorted(sizes))) + "}", sizes_list=sorted(sizes),
                seeds="{" + ", ".join(map(str, seeds)) + "}", wall=wall, peers=peers, peer_note=peer_note)
    text = markdown(rows, clean_rows, args, meta)
    with open(out_md, "w") as f:
        f.write(text + "\n")
    write_rows_csv(out_csv, rows)
    if clean_rows is not None:
        write_rows_csv(os.path.splitext(out_csv)[0] + "-clean.csv", clean_rows)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results_json(rows, clean_rows, args, meta), f, indent=1, ensure_ascii=False)
            f.write("\n")
    print(text)
    print(f"\nwrote {out_md}, {out_csv}" + (f" and {args.json}" if args.json else ""), file=sys.stderr)


if __name__ == "__main__":
    main()
