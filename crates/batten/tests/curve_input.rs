//! B-spline in, B-spline out: `fair::fair_curve` for the methods that work on control points.

#![allow(clippy::unwrap_used)]

use batten::fair::{self, FairOptions};
use batten::spline::{BSplineCurve, KnotVector};
use batten::{Curve, Error, Point};

/// A cubic on 12 control points along a gentle arc, and the same with control point 6
/// pushed out (a bump).
fn bumped() -> (BSplineCurve, BSplineCurve) {
    let pts: Vec<Point> = (0..12)
        .map(|i| {
            let x = i as f64;
            Point::new(x, 0.02 * x * (11.0 - x))
        })
        .collect();
    let knots = KnotVector::clamped_uniform(3, pts.len()).unwrap();
    let clean = BSplineCurve::new(3, knots.clone(), pts.clone(), None);
    let mut bumped_pts = pts;
    bumped_pts[6].y += 0.4;
    (clean, BSplineCurve::new(3, knots, bumped_pts, None))
}

fn max_distance(a: &BSplineCurve, b: &BSplineCurve) -> f64 {
    (0..=400)
        .map(|i| {
            let t = i as f64 / 400.0;
            a.eval(t).distance(b.eval(t))
        })
        .fold(0.0, f64::max)
}

#[test]
fn control_point_methods_fair_a_bspline_directly() {
    let (_, bump) = bumped();
    for method in ["salvi", "eck-hadenfeld"] {
        let tol = 0.5;
        let opts = FairOptions::default().with_tolerance(tol);
        let out = fair::fair_curve(method, &bump, &opts).unwrap();
        let curve = out.curve.expect("a control-point method returns its curve");
        assert_eq!(curve.degree(), bump.degree(), "{method}");
        assert_eq!(curve.knots(), bump.knots(), "{method}");
        assert_eq!(out.points.len(), bump.control_points().len(), "{method}");
        assert!(out.report.tolerance_met, "{method}");
        assert!(out.report.max_displacement <= tol, "{method}");
        // The faired curve is within δ of the input everywhere (convex hull, eq 10).
        assert!(max_distance(&curve, &bump) <= tol + 1e-12, "{method}");
        // Each method lowers its own measure (Ê for salvi, the energy for eck-hadenfeld).
        let measure = |k: &str| out.report.parameters[k].as_f64().unwrap();
        assert!(
            measure("measure_after") < measure("measure_before"),
            "{method}"
        );
        // Output points are the faired curve at the Greville abscissae.
        let p = curve.degree();
        let u = curve.knots().as_slice();
        for (i, q) in out.points.iter().enumerate() {
            let xi = u[i + 1..=i + p].iter().sum::<f64>() / p as f64;
            assert!(curve.eval(xi).distance(*q) < 1e-12, "{method} point {i}");
        }
    }
}

#[test]
fn point_methods_refuse_bspline_input() {
    let (_, bump) = bumped();
    let err = fair::fair_curve("mst", &bump, &FairOptions::default()).unwrap_err();
    match err {
        Error::InvalidParameter { name, reason } => {
            assert_eq!(name, "input");
            assert!(
                reason.contains("salvi") && reason.contains("eck-hadenfeld"),
                "{reason}"
            );
        }
        e => panic!("unexpected error {e}"),
    }
    assert!(matches!(
        fair::fair_curve("nope", &bump, &FairOptions::default()),
        Err(Error::UnknownMethod { .. })
    ));
}
