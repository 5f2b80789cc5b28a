#!/usr/bin/env python3
"""Check batten's DXF and IGES files with the libraries CAD users' scripts use.

- ezdxf (PyPI) reads batten's DXF output: the LWPOLYLINE of `fair -o out.dxf` has the faired
  points, the SPLINE of `--curve-out c.dxf` the degree, knots, control points and weights of
  the faired B-spline (compared with `--curve-out c.json`).
- batten reads DXF files that ezdxf wrote: an LWPOLYLINE, a POLYLINE (2-D), a SPLINE with
  control points and weights and a SPLINE with fit points only, picked by handle.
- Open CASCADE (PyPI cadquery-ocp or cadquery-ocp-novtk, IGESControl_Reader) reads batten's
  `--curve-out c.igs` back to the same curve: degree, knots, poles and weights within 1e-9,
  and points along the curve within 1e-9.

Not part of CI. Usage:
    cargo build --release -p batten-cli
    python3 bench/check_formats.py [--out bench/results-formats.md]
Needs: ezdxf, cadquery-ocp(-novtk). Environment: BATTEN_BIN overrides the batten binary
(default target/release/batten). Exits 1 when a check fails.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

import ezdxf

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
BATTEN = os.environ.get("BATTEN_BIN", os.path.join(ROOT, "target", "release", "batten"))
EXAMPLE = os.path.join(ROOT, "examples", "data", "sine-noisy.csv")
# What the checks must hold: the bound for OCCT, and the 12 decimals the Rust dxf
# crate writes (half a unit of the 12th place, with room for the decimal-to-double rounding).
OCCT_TOL = 1e-9
DXF_TOL = 1e-12

failures = []
rows = []


def check(name, ok, detail):
    rows.append((name, "ok" if ok else "FAILED", detail))
    if not ok:
        failures.append(name)


def batten(*args):
    r = subprocess.run([BATTEN, *args], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"batten {' '.join(args)}: exit {r.returncode}: {r.stderr.strip()}")
    return r


def read_csv(path):
    with open(path) as f:
        next(f)
        return [tuple(float(v) for v in line.split(",")) for line in f if line.strip()]


def max_gap(a, b):
    return max(abs(x - y) for p, q in zip(a, b) for x, y in zip(p, q))


def de_boor(degree, knots, ctrl, weights, t):
    """A point of a (rational) B-spline, homogeneous de Boor."""
    n = len(ctrl)
    k = max(i for i in range(degree, n) if knots[i] <= t)
    w = weights or [1.0] * n
    d = [[ctrl[j][0] * w[j], ctrl[j][1] * w[j], w[j]] for j in range(k - degree, k + 1)]
    for r in range(1, degree + 1):
        for j in range(degree, r - 1, -1):
            i = j + k - degree
            den = knots[i + degree - r + 1] - knots[i]
            a = 0.0 if den == 0 else (t - knots[i]) / den
            d[j] = [(1 - a) * d[j - 1][c] + a * d[j][c] for c in range(3)]
    return (d[degree][0] / d[degree][2], d[degree][1] / d[degree][2])


def dxf_output(tmp):
    out, curve_dxf, curve_json, ref = (os.path.join(tmp, n) for n in ("o.dxf", "c.dxf", "c.json", "o.csv"))
    common = ["--method", "mst", "--tolerance", "0.1"]
    batten("fair", EXAMPLE, "-o", ref, *common)
    batten("fair", EXAMPLE, "-o", out, *common, "--curve-out", curve_dxf)
    batten("fair", EXAMPLE, "-o", ref, *common, "--curve-out", curve_json)
    want = read_csv(ref)
    doc = ezdxf.readfile(out)
    polys = doc.modelspace().query("LWPOLYLINE")
    got = [(x, y) for x, y, *_ in polys[0].get_points("xy")] if len(polys) == 1 else []
    gap = max_gap(got, want) if len(got) == len(want) else math.inf
    check("ezdxf reads `-o out.dxf` (LWPOLYLINE)", gap <= DXF_TOL, f"{len(got)} points, max gap {gap:.1e}")

    with open(curve_json) as f:
        cj = json.load(f)
    spl = ezdxf.readfile(curve_dxf).modelspace().query("SPLINE")[0]
    knots = list(spl.knots)
    ctrl = [(p[0], p[1]) for p in spl.control_points]
    same_shape = spl.dxf.degree == cj["degree"] and len(knots) == len(cj["knots"]) and len(ctrl) == len(cj["control_points"])
    gap = max(max_gap([(k,) for k in knots], [(k,) for k in cj["knots"]]), max_gap(ctrl, cj["control_points"])) if same_shape else math.inf
    check("ezdxf reads `--curve-out c.dxf` (SPLINE)", same_shape and gap <= DXF_TOL,
          f"degree {spl.dxf.degree}, {len(knots)} knots, {len(ctrl)} control points, max gap {gap:.1e}")


def dxf_input(tmp):
    path = os.path.join(tmp, "ezdxf.dxf")
    doc = ezdxf.new("R2010")
    msp = doc.modelspace()
    pts = [(0.4 * i, math.sin(0.2 * i) + 0.02 * ((i * 7919) % 13 - 6) / 6) for i in range(30)]
    lw = msp.add_lwpolyline(pts, dxfattribs={"layer": "HULL", "elevation": 2.5})
    pl = msp.add_polyline2d(pts, dxfattribs={"layer": "DECK"})
    ctrl = [(0, 0), (1, 0.3), (2, 0.55), (3, 0.7), (4, 0.8), (5, 1.3), (6, 0.8), (7, 0.7), (8, 0.55), (9, 0.3), (10, 0)]
    w = [1, 1, 1, 1.2, 1, 0.8, 1, 1, 1, 1, 1]
    sp = msp.add_rational_spline(ctrl, w, degree=3, dxfattribs={"layer": "CURVES"})
    fit = msp.add_spline(pts[::3], degree=3, dxfattribs={"layer": "FIT"})
    doc.saveas(path)
    for name, entity, n, method in [("LWPOLYLINE", lw, 30, "mst"), ("POLYLINE", pl, 30, "mst"),
                                    ("SPLINE (control points)", sp, 11, "salvi"), ("SPLINE (fit points)", fit, 10, "mst")]:
        out = os.path.join(tmp, f"from-ezdxf-{entity.dxf.handle}.csv")
        batten("fair", path, "--entity", entity.dxf.handle, "-o", out, "--method", method, "--tolerance", "0.05")
        got = read_csv(out)
        check(f"batten reads ezdxf's {name} (--entity {entity.dxf.handle})", len(got) == n, f"{len(got)} points faired")


def iges_output(tmp):
    try:
        from OCP.BRepAdaptor import BRepAdaptor_Curve
        from OCP.IFSelect import IFSelect_RetDone
        from OCP.IGESControl import IGESControl_Reader
        from OCP.TopAbs import TopAbs_EDGE
        from OCP.TopExp import TopExp_Explorer
        from OCP.TopoDS import TopoDS
    except ImportError:
        rows.append(("OCCT reads `--curve-out c.igs`", "skipped", "cadquery-ocp not installed"))
        return
    cases = [("mst on sine-noisy", EXAMPLE, "mst", "0.1"),
             ("salvi on a rational cubic", None, "salvi", "0.2")]
    for label, src, method, tol in cases:
        if src is None:
            src = os.path.join(tmp, "rational.json")
            with open(src, "w") as f:
                json.dump({"degree": 3, "knots": [0, 0, 0, 0, 0.2, 0.35, 0.5, 0.7, 0.8, 1, 1, 1, 1],
                           "control_points": [[0, 0], [1, 0.3], [2, 0.55], [3, 0.9], [4, 0.8], [5, 1.3],
                                              [6, 0.8], [7, 0.7], [8, 0.0]],
                           "weights": [1, 1, 1.5, 1, 0.7, 1, 1, 2, 1]}, f)
        igs, js = os.path.join(tmp, f"{method}.igs"), os.path.join(tmp, f"{method}.json")
        out = os.path.join(tmp, f"{method}.csv")
        batten("fair", src, "-o", out, "--method", method, "--tolerance", tol, "--curve-out", igs)
        batten("fair", src, "-o", out, "--method", method, "--tolerance", tol, "--curve-out", js)
        with open(js) as f:
            cj = json.load(f)
        r = IGESControl_Reader()
        if r.ReadFile(igs) != IFSelect_RetDone:
            check(f"OCCT reads --curve-out c.igs ({label})", False, "ReadFile failed")
            continue
        r.TransferRoots()
        ex = TopExp_Explorer(r.OneShape(), TopAbs_EDGE)
        edge = TopoDS.Edge(ex.Current()) if hasattr(TopoDS, "Edge") else TopoDS.Edge_s(ex.Current())
        bs = BRepAdaptor_Curve(edge).BSpline()
        knots = [bs.Knot(i) for i in range(1, bs.NbKnots() + 1) for _ in range(bs.Multiplicity(i))]
        poles = [(bs.Pole(i).X(), bs.Pole(i).Y()) for i in range(1, bs.NbPoles() + 1)]
        weights = [bs.Weight(i) for i in range(1, bs.NbPoles() + 1)]
        shape = bs.Degree() == cj["degree"] and len(knots) == len(cj["knots"]) and len(poles) == len(cj["control_points"])
        gap = math.inf
        if shape:
            w = cj.get("weights") or [1.0] * len(poles)
            gap = max(max_gap([(k,) for k in knots], [(k,) for k in cj["knots"]]),
                      max_gap(poles, cj["control_points"]), max_gap([(x,) for x in weights], [(x,) for x in w]))
            a, b = cj["knots"][cj["degree"]], cj["knots"][-cj["degree"] - 1]
            for i in range(101):
                t = a + (b - a) * i / 100
                p = bs.Value(t)
                q = de_boor(cj["degree"], cj["knots"], cj["control_points"], cj.get("weights"), min(t, b - 1e-15 * (b - a)) if i == 100 else t)
                gap = max(gap, abs(p.X() - q[0]), abs(p.Y() - q[1]))
        check(f"OCCT reads `--curve-out c.igs` ({label})", shape and gap <= OCCT_TOL,
              f"degree {bs.Degree()}, {len(knots)} knots, {len(poles)} poles, rational {bs.IsRational()}, max gap {gap:.1e}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        dxf_output(tmp)
        dxf_input(tmp)
        iges_output(tmp)
    lines = ["| check | result | detail |", "|---|---|---|"]
    lines += [f"| {a} | {b} | {c} |" for a, b, c in rows]
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out:
        with open(args.out, "w") as f:
            f.write(f"# batten's CAD files checked with ezdxf {ezdxf.__version__} and Open CASCADE\n\n"
                    "Made by `python3 bench/check_formats.py --out bench/results-formats.md`.\n\n" + text)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
