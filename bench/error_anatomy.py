"""Where a fairing's curvature error is: at the ends or inside, bias or spread, and at what wavelength.

    /tmp/benv/bin/python bench/error_anatomy.py FAMILY N NOISE [--seeds 20] [--split test]
        [--method "band[speed=0]"] [--no-occt]

For one curve family of `bench/quality.py` (same families, same splits) at N points with
Gaussian noise NOISE × the bounding-box diagonal, over `--seeds` noise draws: `batten fair`
(`--tolerance auto`) and Open CASCADE's variational smoothing (`quality.py`'s `peer_occt`), each
result's curvature at the points (`quality.py`'s analysis spline) against the exact one,
relative to RMS(κ_true), split

- by place: the first and last tenth of the points (ends) and the points between (interior);
- into its mean over the seeds (bias) and its standard deviation (spread), as RMS over the
  points of the part;
- the interior error by wavelength (in points): the mean over the seeds of its power in the
  bands 1–4, 4–16, 16–64 and above 64 points, as an RMS;

and the median over the seeds of the whole curve's error (the quality benchmark's κ err). With
Open CASCADE it also prints the degree and the number of poles of its curve for the first seed.
Not part of CI; needs numpy, scipy and (for the peer) cadquery-ocp, as `quality.py` does.
"""

import os
import tempfile

import numpy as np

from one_case import Case, arguments
from one_case import quality as q

HERE = os.path.dirname(os.path.abspath(__file__))

BANDS = [(1, 4), (4, 16), (16, 64), (64, None)]


def occt_curve(p, sigma_hat):
    """`quality.peer_occt`'s points and its curve's degree and number of poles."""
    src = open(os.path.join(HERE, "quality.py"), encoding="utf-8").read()
    body = src[src.index("def peer_occt"):src.index("def check_occt")]
    ns = dict(q.__dict__)
    exec(body.replace("    return out\n", "    return out, curve\n"), ns)  # noqa: S102
    out, curve = ns["peer_occt"](p, sigma_hat)
    return out, curve.Degree(), curve.NbPoles()


def by_wavelength(e):
    """The RMS of `e` in each band of wavelengths (in samples)."""
    f = np.fft.rfftfreq(len(e))
    power = np.abs(np.fft.rfft(e)) ** 2 * 2 / len(e) ** 2
    wl = np.divide(1.0, f, out=np.full_like(f, np.inf), where=f > 0)
    return [float(np.sum(power[(wl >= a) & (wl < (b or np.inf))])) for a, b in BANDS]


def main():
    ap = arguments(__doc__, seeds=20)
    ap.add_argument("--method", default="band", help="a batten method spec, as quality.py's --methods")
    ap.add_argument("--no-occt", action="store_true")
    a = ap.parse_args()
    case = Case(a.family, a.n, a.noise, a.split)
    m = max(1, a.n // 10)
    tools = {a.method: []} | ({} if a.no_occt else {"occt": []})
    shape = None
    with tempfile.TemporaryDirectory() as tmp:
        for seed in range(1, a.seeds + 1):
            noisy = case.noisy(seed)
            pts, status, _, _, msg = q.run_batten(a.method, noisy, "auto", tmp, 120)
            if pts is None:
                raise SystemExit(f"seed {seed}: batten {status}: {msg}")
            tools[a.method].append(pts)
            if not a.no_occt:
                out, degree, poles = occt_curve(noisy, q.noise_sigma(noisy))
                tools["occt"].append(out)
                if shape is None:
                    shape = (degree, poles)
    print(f"{a.family} ({a.split} split), n = {a.n}, noise {a.noise:g} of the diagonal, {a.seeds} seeds; "
          "curvature error relative to RMS(κ_true)")
    print("| tool | κ err median | ends: bias, spread | interior: bias, spread | interior by wavelength "
          + " / ".join(f"{lo}–{hi}" if hi else f"> {lo}" for lo, hi in BANDS) + " |")
    print("|---|---|---|---|---|")
    for tool, results in tools.items():
        err = np.array([(q.curvature_at_points(p) - case.k_true) / case.k_rms for p in results])
        whole = np.sqrt(np.mean(err**2, axis=1))
        bias, spread = err.mean(0), err.std(0)
        ends = np.r_[0:m, a.n - m:a.n]
        rms = lambda v, idx: float(np.sqrt(np.mean(v[idx] ** 2)))  # noqa: E731
        inner = slice(m, a.n - m)
        waves = np.sqrt(np.mean([by_wavelength(e[inner]) for e in err], axis=0))
        print(f"| {tool} | {np.median(whole):.3f} | {rms(bias, ends):.3f}, {rms(spread, ends):.3f} | "
              f"{rms(bias, inner):.3f}, {rms(spread, inner):.3f} | "
              + " / ".join(f"{w:.3f}" for w in waves) + " |")
    if shape:
        print(f"Open CASCADE's curve (seed 1): degree {shape[0]}, {shape[1]} poles")


if __name__ == "__main__":
    main()
