//! B-spline surfaces: the principal-curvature vector of docs/algorithms/README.md §0.6, curvatures
//! against closed forms (an exact rational sphere patch, the saddle z = xy), derivatives against
//! finite differences.

use batten::spline::KnotVector;
use batten::surface::{BSplineSurface, Xyz};
use serde_json::Value;

const VECTORS: &str = include_str!("data/test-vectors.json");

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

#[test]
fn vector_principal_curvatures_paraboloid() {
    let all: Value = serde_json::from_str(VECTORS).expect("vectors parse");
    let v = all["salvi_varady"]
        .as_array()
        .expect("list")
        .iter()
        .find(|v| v["id"] == "sv.principal_curvatures.paraboloid")
        .expect("vector")
        .clone();
    let inp = &v["inputs"];
    let net = inp["control_net_xyz"].as_array().expect("net");
    let nu = net.len();
    let nv = net[0].as_array().expect("row").len();
    let control: Vec<Xyz> = net
        .iter()
        .flat_map(|row| row.as_array().expect("row").iter())
        .map(|p| {
            let c = floats(p);
            [c[0], c[1], c[2]]
        })
        .collect();
    let deg = floats(&inp["degree"]);
    let s = BSplineSurface::try_new(
        (deg[0] as usize, deg[1] as usize),
        (
            KnotVector::new(floats(&inp["knots_u"])),
            KnotVector::new(floats(&inp["knots_v"])),
        ),
        (nu, nv),
        control,
        None,
    )
    .expect("surface");
    let uv = floats(&inp["uv"]);
    let c = s.curvature(uv[0], uv[1]).expect("regular");
    let tol = v["tolerance"]["abs"].as_f64().expect("abs");
    let exp = &v["expected"];
    assert!((c.kappa1 - exp["kappa1"].as_f64().expect("k1")).abs() <= tol);
    assert!((c.kappa2 - exp["kappa2"].as_f64().expect("k2")).abs() <= tol);
    for (g, e) in c.normal.iter().zip(floats(&exp["normal"])) {
        assert!((g - e).abs() <= tol, "normal {:?}", c.normal);
    }
    assert!((c.gaussian - 0.7 * -0.3).abs() <= tol);
    assert!((c.mean - 0.2).abs() <= tol);
}

/// An exact sphere patch of radius `r`: the rational quadratic arc of latitudes
/// `[-lat, lat]` revolved by the rational quadratic arc of longitudes `[0, lon]`
/// (bi-quadratic NURBS, weights `cos(half angle)` in the middle rows).
fn sphere_patch(r: f64, lat: f64, lon: f64) -> BSplineSurface {
    // Profile in the (ρ, z) half plane: (cos φ, sin φ) from −lat to lat.
    let wl = lat.cos();
    let profile = [
        ((-lat).cos(), (-lat).sin(), 1.0),
        (1.0 / wl, 0.0, wl),
        (lat.cos(), lat.sin(), 1.0),
    ];
    let h = lon / 2.0;
    let wh = h.cos();
    let around = [
        (1.0, 0.0, 1.0),
        (h.cos() / wh, h.sin() / wh, wh),
        (lon.cos(), lon.sin(), 1.0),
    ];
    let mut control = Vec::new();
    let mut weights = Vec::new();
    for &(rho, z, w1) in &profile {
        for &(c, s, w2) in &around {
            control.push([r * rho * c, r * rho * s, r * z]);
            weights.push(w1 * w2);
        }
    }
    let k = KnotVector::new(vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
    BSplineSurface::try_new((2, 2), (k.clone(), k), (3, 3), control, Some(weights))
        .expect("sphere patch")
}

#[test]
fn sphere_patch_has_constant_curvature() {
    let r = 2.5;
    let s = sphere_patch(r, 0.6, 1.1);
    for i in 0..=10 {
        for j in 0..=10 {
            let (u, v) = (i as f64 / 10.0, j as f64 / 10.0);
            let p = s.point(u, v);
            let rad = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            assert!((rad - r).abs() < 1e-12 * r, "point off the sphere: {rad}");
            let c = s.curvature(u, v).expect("regular");
            assert!(
                (c.gaussian - 1.0 / (r * r)).abs() < 1e-10,
                "K = {}",
                c.gaussian
            );
            // S_u points up the meridian, S_v along the parallel: S_u × S_v points inwards
            // (towards the centre), so the curvature of the sphere is positive.
            let n = c.normal;
            let dir = [-p[0] / r, -p[1] / r, -p[2] / r];
            let along = n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2];
            let sign = along.signum();
            assert!((along.abs() - 1.0).abs() < 1e-10);
            assert!((c.mean - sign / r).abs() < 1e-10, "H = {}", c.mean);
            assert!((c.kappa1 - c.kappa2).abs() < 1e-6, "umbilic: {c:?}");
        }
    }
}

/// The saddle `z = xy` over `[−1, 1]²` as an exact bicubic: `x`, `y` and `xy` are linear in
/// each parameter, so their control values are the Greville abscissae and their products.
fn saddle(n: usize) -> BSplineSurface {
    let k = KnotVector::clamped_uniform(3, n).expect("knots");
    let g: Vec<f64> = k.greville(3).iter().map(|t| 2.0 * t - 1.0).collect();
    let mut control = Vec::new();
    for &x in &g {
        for &y in &g {
            control.push([x, y, x * y]);
        }
    }
    BSplineSurface::try_new((3, 3), (k.clone(), k), (n, n), control, None).expect("saddle")
}

#[test]
fn saddle_curvature_matches_the_monge_patch_formulas() {
    let s = saddle(7);
    for i in 0..=8 {
        for j in 0..=8 {
            let (u, v) = (i as f64 / 8.0, j as f64 / 8.0);
            let p = s.point(u, v);
            let (x, y) = (2.0 * u - 1.0, 2.0 * v - 1.0);
            assert!((p[0] - x).abs() < 1e-14 && (p[1] - y).abs() < 1e-14);
            assert!((p[2] - x * y).abs() < 1e-14);
            let w = 1.0 + x * x + y * y;
            let c = s.curvature(u, v).expect("regular");
            assert!((c.gaussian + 1.0 / (w * w)).abs() < 1e-12, "K at {x},{y}");
            assert!((c.mean + x * y / w.powf(1.5)).abs() < 1e-12, "H at {x},{y}");
            assert!(c.kappa1 >= c.kappa2);
            assert!((c.kappa1 * c.kappa2 - c.gaussian).abs() < 1e-12);
        }
    }
}

#[test]
fn derivatives_match_finite_differences() {
    // A rational bicubic-by-quadratic surface with non-uniform knots and uneven weights.
    let ku = KnotVector::new(vec![0.0, 0.0, 0.0, 0.0, 0.3, 0.55, 1.0, 1.0, 1.0, 1.0]);
    let kv = KnotVector::new(vec![0.0, 0.0, 0.0, 0.4, 1.0, 1.0, 1.0]);
    let (nu, nv) = (6, 4);
    let mut control = Vec::new();
    let mut weights = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            let (a, b) = (i as f64, j as f64);
            control.push([
                a + 0.1 * b * b,
                b - 0.2 * a,
                (0.7 * a).sin() + (1.3 * b).cos(),
            ]);
            weights.push(1.0 + 0.3 * ((a + 2.0 * b).sin()).abs());
        }
    }
    let s = BSplineSurface::try_new((3, 2), (ku, kv), (nu, nv), control, Some(weights))
        .expect("surface");
    let h = 1e-5;
    let fd = |f: &dyn Fn(f64, f64) -> Xyz, u: f64, v: f64, du: f64, dv: f64| {
        let a = f(u + du, v + dv);
        let b = f(u - du, v - dv);
        [
            (a[0] - b[0]) / (2.0 * h),
            (a[1] - b[1]) / (2.0 * h),
            (a[2] - b[2]) / (2.0 * h),
        ]
    };
    let close = |a: Xyz, b: Xyz, what: &str| {
        for k in 0..3 {
            assert!(
                (a[k] - b[k]).abs() < 1e-5 * (1.0 + b[k].abs()),
                "{what}: {a:?} vs {b:?}"
            );
        }
    };
    for &(u, v) in &[(0.1, 0.2), (0.45, 0.7), (0.8, 0.15), (0.62, 0.93)] {
        let d = s.derivatives(u, v);
        let point = |u: f64, v: f64| s.point(u, v);
        let su = |u: f64, v: f64| s.derivatives(u, v).su;
        let sv = |u: f64, v: f64| s.derivatives(u, v).sv;
        close(d.point, s.point(u, v), "point");
        close(d.su, fd(&point, u, v, h, 0.0), "S_u");
        close(d.sv, fd(&point, u, v, 0.0, h), "S_v");
        close(d.suu, fd(&su, u, v, h, 0.0), "S_uu");
        close(d.suv, fd(&su, u, v, 0.0, h), "S_uv");
        close(d.suv, fd(&sv, u, v, h, 0.0), "S_vu");
        close(d.svv, fd(&sv, u, v, 0.0, h), "S_vv");
        let f = s.fundamental_forms(u, v).expect("regular");
        let c = s.curvature(u, v).expect("regular");
        let det = f.e * f.g - f.f * f.f;
        assert!((c.gaussian - (f.l * f.n - f.m * f.m) / det).abs() < 1e-9);
    }
}

#[test]
fn a_plane_has_zero_curvature_and_a_degenerate_patch_none() {
    let mut control = Vec::new();
    for i in 0..4 {
        for j in 0..5 {
            control.push([i as f64, j as f64 * 0.5, 0.3 * i as f64 - 0.1 * j as f64]);
        }
    }
    let s = BSplineSurface::clamped_uniform((3, 3), (4, 5), control).expect("plane");
    let c = s.curvature(0.3, 0.6).expect("regular");
    assert!(c.kappa1.abs() < 1e-12 && c.kappa2.abs() < 1e-12);
    // Every control point in one row of u: S_u × S_v = 0 everywhere.
    let line: Vec<Xyz> = (0..16).map(|k| [(k % 4) as f64, 0.0, 0.0]).collect();
    let s = BSplineSurface::clamped_uniform((3, 3), (4, 4), line).expect("line");
    assert!(s.curvature(0.5, 0.5).is_none());
    assert!(s.normal(0.5, 0.5).is_none());
}

#[test]
fn constructor_rejects_bad_input() {
    let k = KnotVector::clamped_uniform(3, 4).expect("knots");
    let pts = vec![[0.0; 3]; 16];
    let unclamped = KnotVector::new(vec![0.0, 0.0, 0.0, 0.1, 0.9, 1.0, 1.0, 1.0]);
    let e = BSplineSurface::try_new((3, 3), (unclamped, k.clone()), (4, 4), pts.clone(), None)
        .expect_err("not clamped");
    assert!(e.to_string().contains("not clamped"), "{e}");
    let e = BSplineSurface::try_new(
        (3, 3),
        (k.clone(), k.clone()),
        (4, 4),
        pts[..15].to_vec(),
        None,
    )
    .expect_err("count");
    assert!(e.to_string().contains("control_points"), "{e}");
    let mut bad = pts.clone();
    bad[5][1] = f64::NAN;
    assert!(BSplineSurface::try_new((3, 3), (k.clone(), k.clone()), (4, 4), bad, None).is_err());
    let e = BSplineSurface::try_new((3, 3), (k.clone(), k), (4, 4), pts, Some(vec![0.0; 16]))
        .expect_err("weights");
    assert!(e.to_string().contains("weight [0][0]"), "{e}");
}
