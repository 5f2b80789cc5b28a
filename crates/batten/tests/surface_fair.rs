//! Surface fairing (`salvi`, `eck-hadenfeld`) on the bundled hood patch with a dent and a
//! ripple: Π̂ falls at least 5× with the tolerance held, measured independently on a dense
//! grid; held boundary rows stay bit for bit; fair surfaces come back unchanged.

use std::path::Path;

use batten::io::read_surface_json;
use batten::surface::{
    BSplineSurface, BoundaryFix, SurfaceFairOptions, SurfaceMethod, analyze_surface, fair_surface,
};

fn example(name: &str) -> BSplineSurface {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/data")
        .join(name);
    read_surface_json(&p).expect("example reads")
}

/// `max |a(u, v) − b(u, v)|` on a 201 × 201 grid, written out here rather than taken from
/// the library so that the check is independent of the code it checks.
fn dense_deviation(a: &BSplineSurface, b: &BSplineSurface) -> f64 {
    let n = 201;
    let mut m = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            let (u, v) = (i as f64 / (n - 1) as f64, j as f64 / (n - 1) as f64);
            let (p, q) = (a.point(u, v), b.point(u, v));
            let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
            m = m.max(d);
        }
    }
    m
}

#[test]
fn salvi_fairs_the_dented_hood_within_tolerance() {
    let s = example("hood-dented.json");
    let tol = 0.05;
    let opts = SurfaceFairOptions::default()
        .with_tolerance(tol)
        .with_fix_boundary(BoundaryFix::Tangent);
    let (f, r) = fair_surface(&s, &opts).expect("fairs");
    assert!(r.tolerance_met);
    assert!(
        r.after.pi_hat * 5.0 <= r.before.pi_hat,
        "{} -> {}",
        r.before.pi_hat,
        r.after.pi_hat
    );
    let dev = dense_deviation(&s, &f);
    assert!(dev <= tol, "dense deviation {dev}");
    assert!((dev - r.max_displacement).abs() <= 0.1 * tol);
    // The two outer rings are untouched.
    let (nu, nv) = s.size();
    for i in 0..nu {
        for j in 0..nv {
            if i < 2 || j < 2 || i + 2 >= nu || j + 2 >= nv {
                assert_eq!(s.control_point(i, j), f.control_point(i, j), "{i},{j}");
            }
        }
    }
    // The curvature ranges move back towards those of the undented hood.
    let clean = analyze_surface(&example("hood.json"));
    let after = analyze_surface(&f);
    let before = analyze_surface(&s);
    let spread = |a: &batten::surface::SurfaceAnalysis| {
        let (k1, k2) = (a.kappa1.expect("k1"), a.kappa2.expect("k2"));
        (k1.max - k1.min) + (k2.max - k2.min)
    };
    assert!(spread(&after) < 0.5 * spread(&before));
    assert!(spread(&after) > spread(&clean));
    // The report's measures are those of analyze_surface.
    assert_eq!(r.before.pi_hat, before.fairness_measure);
}

/// A sphere patch (exact rational bi-quadratic) and a plane are their own targets: Π̂ = 0 up
/// to rounding, so `salvi` returns them bit for bit.
#[test]
fn fair_surfaces_come_back_unchanged() {
    let lat = 0.5f64;
    let lon = 0.9f64;
    let wl = lat.cos();
    let h = lon / 2.0;
    let profile = [
        ((-lat).cos(), (-lat).sin(), 1.0),
        (1.0 / wl, 0.0, wl),
        (lat.cos(), lat.sin(), 1.0),
    ];
    let around = [
        (1.0, 0.0, 1.0),
        (h.cos() / h.cos(), h.sin() / h.cos(), h.cos()),
        (lon.cos(), lon.sin(), 1.0),
    ];
    let (mut control, mut weights) = (Vec::new(), Vec::new());
    for &(rho, z, w1) in &profile {
        for &(c, s, w2) in &around {
            control.push([3.0 * rho * c, 3.0 * rho * s, 3.0 * z]);
            weights.push(w1 * w2);
        }
    }
    let k = batten::spline::KnotVector::new(vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
    let sphere = BSplineSurface::try_new((2, 2), (k.clone(), k), (3, 3), control, Some(weights))
        .expect("sphere");
    let a = analyze_surface(&sphere);
    assert!(a.fairness_measure < 1e-12, "{}", a.fairness_measure);
    assert_eq!(a.umbilic_fraction, 1.0);
    let (f, r) = fair_surface(&sphere, &SurfaceFairOptions::default()).expect("fairs");
    assert_eq!(f, sphere, "{r:?}");
    assert_eq!(r.moves, 0);
    // A tilted plane, affine in the parameters: no curvature, no thin-plate energy.
    let mut plane = Vec::new();
    for i in 0..8 {
        for j in 0..6 {
            let (x, y) = (i as f64 / 7.0, j as f64 / 5.0);
            plane.push([2.0 * x, y, 0.3 * x - 0.2 * y]);
        }
    }
    let mut plane = BSplineSurface::clamped_uniform((3, 3), (8, 6), plane).expect("plane");
    // Control points of an affine map are its values at the Greville abscissae.
    let (ku, kv) = plane.knots();
    let (gu, gv) = (ku.greville(3), kv.greville(3));
    let cp = gu
        .iter()
        .flat_map(|&x| gv.iter().map(move |&y| [2.0 * x, y, 0.3 * x - 0.2 * y]))
        .collect();
    plane = plane.with_control_points(cp).expect("plane");
    for m in SurfaceMethod::ALL {
        let (f, r) =
            fair_surface(&plane, &SurfaceFairOptions::default().with_method(m)).expect("fairs");
        assert_eq!(f, plane, "{}: {r:?}", m.name());
        assert!(r.tolerance_met);
        assert_eq!(r.max_displacement, 0.0);
    }
}

#[test]
fn bad_options_are_refused() {
    let s = example("hood.json");
    let e = fair_surface(
        &s,
        &SurfaceFairOptions::default().with_param("smothing", "1"),
    )
    .expect_err("unknown key");
    assert!(e.to_string().contains("unknown option 'smothing'"), "{e}");
    let e = fair_surface(
        &s,
        &SurfaceFairOptions::default().with_param("smoothing", "-1"),
    )
    .expect_err("bad value");
    assert!(e.to_string().contains("smoothing"), "{e}");
    let e = fair_surface(&s, &SurfaceFairOptions::default().with_tolerance(0.0))
        .expect_err("bad tolerance");
    assert!(e.to_string().contains("tolerance"), "{e}");
    let w = s
        .with_control_points(s.control_points().to_vec())
        .expect("copy");
    let (nu, nv) = w.size();
    let rational = BSplineSurface::try_new(
        w.degree(),
        (w.knots().0.clone(), w.knots().1.clone()),
        (nu, nv),
        w.control_points().to_vec(),
        Some(vec![1.0; nu * nv]),
    )
    .expect("rational");
    let e = fair_surface(
        &rational,
        &SurfaceFairOptions::default().with_method(SurfaceMethod::EckHadenfeld),
    )
    .expect_err("rational");
    assert!(e.to_string().contains("non-rational"), "{e}");
}

#[test]
fn eck_hadenfeld_lowers_the_thin_plate_energy_within_tolerance() {
    let s = example("hood-dented.json");
    let tol = 0.05;
    let opts = SurfaceFairOptions::default()
        .with_method(SurfaceMethod::EckHadenfeld)
        .with_tolerance(tol)
        .with_fix_boundary(BoundaryFix::Position);
    let (f, r) = fair_surface(&s, &opts).expect("fairs");
    assert!(r.tolerance_met);
    assert!(r.after.thin_plate_energy < r.before.thin_plate_energy);
    assert!(r.history.windows(2).all(|w| w[1] <= w[0] * (1.0 + 1e-12)));
    assert!(dense_deviation(&s, &f) <= tol);
    let (nu, nv) = s.size();
    for i in [0, nu - 1] {
        for j in 0..nv {
            assert_eq!(s.control_point(i, j), f.control_point(i, j));
            assert_eq!(s.control_point(j, i), f.control_point(j, i));
        }
    }
}
