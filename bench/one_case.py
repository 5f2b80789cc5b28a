"""One curve of `quality.py`'s families, for the scripts that look at a single case closely
(`error_anatomy.py`, `smoothing_order.py`): `quality.py` loaded as a module, and the case's
truth and noisy draws."""

import argparse
import importlib.util
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
_spec = importlib.util.spec_from_file_location("quality", os.path.join(HERE, "quality.py"))
quality = importlib.util.module_from_spec(_spec)
_argv, sys.argv = sys.argv, [sys.argv[0]]
_spec.loader.exec_module(quality)
sys.argv = _argv


def arguments(doc, seeds):
    """The parser of `FAMILY N NOISE [--seeds] [--split]`, for a script to add its own."""
    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    ap.add_argument("family")
    ap.add_argument("n", type=int)
    ap.add_argument("noise", type=float)
    ap.add_argument("--seeds", type=int, default=seeds)
    ap.add_argument("--split", default="test", choices=["test", "tune"])
    return ap


class Case:
    """`family` (a name) at `n` points with Gaussian noise `noise` × the bounding-box diagonal:
    the exact points `truth`, curvature `k_true` and its RMS `k_rms`, the noise `sigma`."""

    def __init__(self, family, n, noise, split):
        families = [f(split) for f in quality.FAMILIES]
        names = [f.name for f in families]
        if family not in names:
            raise SystemExit(f"unknown family {family!r}: one of {', '.join(names)}")
        self.index = names.index(family)
        self.family = families[self.index]
        self.n = n
        self.tau = np.linspace(self.family.t0, self.family.t1, n)
        self.truth = self.family.points(self.tau)
        self.k_true = self.family.kappa(self.tau)
        self.k_rms = float(np.sqrt(np.mean(self.k_true**2)))
        self.sigma = noise * float(np.hypot(*(self.truth.max(0) - self.truth.min(0))))

    def noisy(self, seed):
        """The truth with noise draw `seed` (its own stream, apart from `quality.py`'s)."""
        rng = np.random.default_rng([seed, self.index, self.n, 7])
        return self.truth + rng.normal(0.0, self.sigma, size=self.truth.shape)

    def kappa_error(self, points):
        """RMS(κ − κ_true)/RMS(κ_true) of `points` (the quality benchmark's κ err)."""
        return float(np.sqrt(np.mean((quality.curvature_at_points(points) - self.k_true) ** 2)) / self.k_rms)
