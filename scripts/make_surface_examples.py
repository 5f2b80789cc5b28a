#!/usr/bin/env python3
"""Generate the example surfaces in examples/data: a small car-body-like bicubic patch and a
copy with perturbed interior control points, for `batten fair-surface`.

Deterministic, standard library only. Numbers are written with repr(), the shortest text
that reads back to the same double.

    python3 scripts/make_surface_examples.py            # writes into examples/data/
    python3 scripts/make_surface_examples.py --out DIR

hood.json          a bicubic B-spline surface, 12 x 12 control points on clamped uniform
                   knots over [0, 1]^2, x in [0, 4], y in [0, 2]. The control points are
                   (x, y, f(x, y)) at the Greville abscissae (Schoenberg's
                   variation-diminishing approximation, as fair as f itself) with
                   f(x, y) = 0.35 (1 - ((x - 2)/2.6)^2) (1 - 0.5 ((y - 1)/1.4)^2) + 0.04 x,
                   a crowned panel like a bonnet: convex both ways, gently tilted.
hood-dented.json   the same net with two defects on interior control points only (the two
                   outer rings are untouched, so --fix-boundary=tangent holds the same
                   boundary):
                   a dent: z -= 0.03 exp(-((i - 4)^2 + (j - 7)^2) / 1.5) and
                   a ripple: z += 0.008 sin(2.2 j) on the rows i = 7 and 8, j = 2..9.
"""

import argparse
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_OUT = os.path.join(HERE, "..", "examples", "data")
N = 12
P = 3


def knots(n, p):
    spans = n - p
    return [0.0] * (p + 1) + [i / spans for i in range(1, spans)] + [1.0] * (p + 1)


def greville(k, n, p):
    return [sum(k[i + 1:i + p + 1]) / p for i in range(n)]


def f(x, y):
    return 0.35 * (1 - ((x - 2) / 2.6) ** 2) * (1 - 0.5 * ((y - 1) / 1.4) ** 2) + 0.04 * x


def surface(net):
    k = knots(N, P)
    return {
        "degree_u": P,
        "degree_v": P,
        "knots_u": k,
        "knots_v": k,
        "control_points": net,
    }


def write(path, s):
    rows = ",\n".join(
        "    [" + ", ".join("[" + ", ".join(repr(c) for c in p) + "]" for p in row) + "]"
        for row in s["control_points"]
    )
    text = (
        "{\n"
        f'  "degree_u": {s["degree_u"]},\n'
        f'  "degree_v": {s["degree_v"]},\n'
        f'  "knots_u": [{", ".join(repr(x) for x in s["knots_u"])}],\n'
        f'  "knots_v": [{", ".join(repr(x) for x in s["knots_v"])}],\n'
        '  "control_points": [\n' + rows + "\n  ]\n}\n"
    )
    json.loads(text)
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(text)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=DEFAULT_OUT)
    out = ap.parse_args().out
    g = greville(knots(N, P), N, P)
    net = [[[4 * g[i], 2 * g[j], f(4 * g[i], 2 * g[j])] for j in range(N)] for i in range(N)]
    write(os.path.join(out, "hood.json"), surface(net))
    dented = [[list(p) for p in row] for row in net]
    for i in range(N):
        for j in range(N):
            dz = -0.03 * math.exp(-((i - 4) ** 2 + (j - 7) ** 2) / 1.5)
            if i in (7, 8) and 2 <= j <= 9:
                dz += 0.008 * math.sin(2.2 * j)
            if 2 <= i < N - 2 and 2 <= j < N - 2:
                dented[i][j][2] += dz
    write(os.path.join(out, "hood-dented.json"), surface(dented))


if __name__ == "__main__":
    main()
