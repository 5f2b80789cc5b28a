"""How far a plain smoothing spline gets, by the order of its penalty: a yardstick for `band`.

    /tmp/benv/bin/python bench/smoothing_order.py FAMILY N NOISE [--orders 2,3,5]
        [--fits 1.0,1.05,1.1,1.25] [--seeds 10] [--split test]

For one curve family of `bench/quality.py` at N points with Gaussian noise NOISE × the
bounding-box diagonal: the points minimising `Σ_j w_j |Δᵏ_j q|² + μ Σ_i |q_i − p_i|²` (Δᵏ the
k-th divided difference at the *true* arc-length parameters, an oracle no fairing method has;
`w_j` the window's span), with `μ` by the discrepancy principle as `band`'s debiasing stage takes
it (mean squared residual `2·(fit·σ)²`, σ the true noise), for each order k and `fit`. Prints
the median over the seeds of the relative curvature error (the quality benchmark's κ err) and
Open CASCADE's on the same draws. Order 3 is `band`'s energy without its band, its metric and
its local weights: what no setting of those can beat by much. Not part of CI; needs numpy,
scipy and cadquery-ocp, as `quality.py` does.
"""

import math

import numpy as np
from scipy.sparse import csr_matrix, diags, identity
from scipy.sparse.linalg import splu

from one_case import Case, arguments
from one_case import quality as q


def penalty(t, order):
    """`Σ_j w_j |Δᵏ_j q|²` as a sparse matrix, parameters `t` in units of their mean step."""
    t = t / np.mean(np.diff(t))
    n = len(t)
    rows, cols, vals = [], [], []
    for j in range(n - order):
        tt = t[j:j + order + 1]
        for k in range(order + 1):
            rows.append(j)
            cols.append(j + k)
            vals.append(math.factorial(order) / np.prod([tt[k] - tt[m] for m in range(order + 1) if m != k]))
    d = csr_matrix((vals, (rows, cols)), shape=(n - order, n))
    return (d.T @ diags((t[order:] - t[:-order]) / order) @ d).tocsc()


def smooth(p, energy, fit, sigma):
    """The minimiser with `μ` from the discrepancy principle (bisection on log μ)."""
    n = len(p)

    def solve(mu):
        lu = splu((energy + mu * identity(n)).tocsc())
        return np.c_[lu.solve(mu * p[:, 0]), lu.solve(mu * p[:, 1])]

    lo, hi = -60.0, 20.0
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        r = solve(math.exp(mid))
        if np.mean(np.sum((r - p) ** 2, axis=1)) > 2 * (fit * sigma) ** 2:
            lo = mid
        else:
            hi = mid
    return solve(math.exp(hi))


def main():
    ap = arguments(__doc__, seeds=10)
    ap.add_argument("--orders", default="2,3,5")
    ap.add_argument("--fits", default="1.0,1.05,1.1,1.25")
    a = ap.parse_args()
    case = Case(a.family, a.n, a.noise, a.split)
    grid, s = case.family.arclength()
    arc = np.interp(case.tau, grid, s)
    orders = [int(x) for x in a.orders.split(",")]
    fits = [float(x) for x in a.fits.split(",")]
    energies = {k: penalty(arc, k) for k in orders}
    errors = {}
    for seed in range(1, a.seeds + 1):
        noisy = case.noisy(seed)
        for k in orders:
            for fit in fits:
                errors.setdefault((k, fit), []).append(case.kappa_error(smooth(noisy, energies[k], fit, case.sigma)))
        o = q.peer_occt(noisy, q.noise_sigma(noisy))
        errors.setdefault(("occt", None), []).append(case.kappa_error(o))
    print(f"{a.family} ({a.split} split), n = {a.n}, noise {a.noise:g} of the diagonal, {a.seeds} seeds: "
          "median κ err by penalty order and fit")
    print("| order | " + " | ".join(f"fit {f:g}" for f in fits) + " |")
    print("|---|" + "---|" * len(fits))
    for k in orders:
        print(f"| {k} | " + " | ".join(f"{np.median(errors[(k, f)]):.3f}" for f in fits) + " |")
    print(f"Open CASCADE: {np.median(errors[('occt', None)]):.3f}")


if __name__ == "__main__":
    main()
