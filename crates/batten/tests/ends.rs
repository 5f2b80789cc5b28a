//! `--fix-ends`: position, tangent and curvature at the ends of an open curve, for every
//! method (`EndFix`, `FairReport::end_changes`).

use batten::analysis::signed_curvature;
use batten::curve::{Curve, CurveDeriv};
use batten::fair::{self, EndFix, FairStatus};
use batten::spline::{BSplineCurve, Parametrization};
use batten::{FairOptions, Point, PointSeq, Vec2};
use proptest::prelude::*;

mod common;

/// The methods that move the points themselves.
const POINT_METHODS: [&str; 5] = ["han", "mst", "kjellander", "poliakoff", "energy"];
/// The methods that move the control points of a clamped cubic fitted to the points.
const CONTROL_POINT_METHODS: [&str; 4] = ["sapidis-farin", "salvi", "eck-hadenfeld", "cali"];

/// Samples of `sin(x)` on [0, 2π] with a uniform wobble of width `amp`.
fn noisy_sine(n: usize, amp: f64, seed: u64) -> Vec<Point> {
    common::jitter(
        &common::sine(n, std::f64::consts::TAU),
        common::Noise::Uniform(amp),
        seed,
    )
}

fn held_indices(n: usize, k: usize) -> impl Iterator<Item = usize> {
    (0..k).chain(n - k..n)
}

#[test]
fn end_fix_names_and_counts() {
    for (fix, name, held) in [
        (EndFix::Free, "free", 0),
        (EndFix::Position, "position", 1),
        (EndFix::Tangent, "tangent", 2),
        (EndFix::Curvature, "curvature", 3),
    ] {
        assert_eq!(fix.as_str(), name);
        assert_eq!(name.parse::<EndFix>().unwrap(), fix);
        assert_eq!(fix.held(), held);
        assert_eq!(fix.is_fixed(), held > 0);
    }
    assert!("sideways".parse::<EndFix>().is_err());
    assert_eq!(FairOptions::default().fix_ends, EndFix::Free);
    assert_eq!(
        FairOptions::default().with_fix_ends(true).fix_ends,
        EndFix::Position
    );
}

/// The report says what was held, not only what was asked: with `--fix-ends` left free,
/// the methods that keep their end points anyway (`han`, the Kjellander family, the
/// control-point methods unless `free_ends`) report `position`, and their end points are
/// indeed exactly the input's; the others report `free`.
#[test]
fn the_report_says_what_was_held() {
    let pts = noisy_sine(40, 0.05, 5);
    let input = PointSeq::open(pts.clone()).unwrap();
    let keep = [
        "han",
        "kjellander",
        "poliakoff",
        "energy",
        "sapidis-farin",
        "salvi",
        "eck-hadenfeld",
        "cali",
    ];
    for method in POINT_METHODS
        .iter()
        .chain(&CONTROL_POINT_METHODS)
        .chain(&["band"])
    {
        let out = fair::fair(method, &input, &FairOptions::default()).unwrap();
        let r = &out.report;
        let want = if keep.contains(method) {
            EndFix::Position
        } else {
            EndFix::Free
        };
        assert_eq!(r.fixed_ends, want, "{method}");
        assert_eq!(r.fix_ends, want.is_fixed(), "{method}");
        if want == EndFix::Position {
            let n = pts.len();
            assert!(
                out.points[0] == pts[0] && out.points[n - 1] == pts[n - 1],
                "{method}: says it held the end points"
            );
        }
    }
}

#[test]
fn point_methods_hold_their_end_points() {
    let pts = noisy_sine(40, 0.05, 3);
    let input = PointSeq::open(pts.clone()).unwrap();
    for method in POINT_METHODS {
        for fix in [EndFix::Position, EndFix::Tangent, EndFix::Curvature] {
            let opts = FairOptions::default().with_end_fix(fix);
            let out = fair::fair(method, &input, &opts).unwrap();
            let r = &out.report;
            assert!(r.max_displacement > 0.0, "{method} {fix}: nothing moved");
            for i in held_indices(pts.len(), fix.held()) {
                assert_eq!(out.points[i], pts[i], "{method} {fix}: point {i} moved");
            }
            assert_eq!(r.fixed_ends, fix);
            assert!(r.fix_ends);
            let ends = r.end_changes.expect("open curve");
            if fix >= EndFix::Tangent {
                assert_eq!(ends.tangent_angle, [0.0, 0.0], "{method} {fix}");
            }
            if fix == EndFix::Curvature {
                assert_eq!(ends.curvature, [0.0, 0.0], "{method} {fix}");
            }
        }
    }
}

/// Unit end tangent and curvature of a curve at both ends of its domain.
fn end_state(c: &BSplineCurve) -> [(Vec2, f64); 2] {
    let (a, b) = c.domain();
    let at = |t: f64| {
        let d = c.derivatives(t);
        (d.d1 / d.d1.length(), signed_curvature(&d))
    };
    [at(a), at(b)]
}

#[test]
fn control_point_methods_keep_the_curve_end_tangent_and_curvature() {
    let pts = noisy_sine(40, 0.05, 5);
    let input = PointSeq::open(pts.clone()).unwrap();
    let (fit, _) = BSplineCurve::interpolate(&pts, 3, Parametrization::ChordLength).unwrap();
    let before = end_state(&fit);
    for method in CONTROL_POINT_METHODS {
        for fix in [EndFix::Tangent, EndFix::Curvature] {
            let opts = FairOptions::default().with_tolerance(0.2).with_end_fix(fix);
            let out = fair::fair(method, &input, &opts).unwrap();
            let curve = out.curve.expect("a B-spline method returns its curve");
            // Kept, to rounding: salvi fits in the principal frame of the points, where the
            // chords are the same up to their last bits.
            let (k, kf) = (curve.knots().as_slice(), fit.knots().as_slice());
            assert_eq!(k.len(), kf.len(), "{method}: the knots are kept");
            for (a, b) in k.iter().zip(kf) {
                assert!(
                    (a - b).abs() <= 1e-12,
                    "{method}: the knots are kept: {a} vs {b}"
                );
            }
            let moved = curve
                .control_points()
                .iter()
                .zip(fit.control_points())
                .filter(|(p, q)| p.distance(**q) > 1e-9)
                .count();
            assert!(moved > 0, "{method} {fix}: nothing moved");
            let k = fix.held();
            let n = fit.control_points().len();
            for i in held_indices(n, k) {
                assert!(
                    curve.control_points()[i].distance(fit.control_points()[i]) <= 1e-12,
                    "{method} {fix}: control point {i} moved"
                );
            }
            let after = end_state(&curve);
            for end in 0..2 {
                let (t0, k0) = before[end];
                let (t1, k1) = after[end];
                assert!(
                    t0.cross(t1).abs() < 1e-9 && t0.dot(t1) > 0.0,
                    "{method} {fix}"
                );
                if fix == EndFix::Curvature {
                    assert!(
                        (k1 - k0).abs() <= 1e-9 * (1.0 + k0.abs()),
                        "{method}: {k0} → {k1}"
                    );
                }
            }
        }
    }
}

#[test]
fn kuragano_holds_every_control_point_acting_at_an_end() {
    // A clean spiral arc (no inflection), so that kuragano has a radius-of-curvature law to
    // reshape the curve to.
    let pts: Vec<Point> = (0..30)
        .map(|i| {
            let a = 0.1 * i as f64;
            let r = 2.0 + 0.5 * a + 0.01 * (3.0 * a).sin();
            Point::new(r * a.cos(), r * a.sin())
        })
        .collect();
    let input = PointSeq::open(pts.clone()).unwrap();
    // The clean-curve guard would return this clean input unchanged: off, to see the ends.
    let opts = FairOptions::default().with_keep_clean(false);
    let free = fair::fair("kuragano", &input, &opts).unwrap();
    let held = fair::fair(
        "kuragano",
        &input,
        &opts.clone().with_end_fix(EndFix::Curvature),
    )
    .unwrap();
    let (c_free, c_held) = (free.curve.unwrap(), held.curve.unwrap());
    assert_ne!(held.report.status, FairStatus::NoChange);
    // The held run's interior moved (differently from the free run's).
    let n = c_held.control_points().len();
    let p = c_held.degree();
    let interior_moved = (p + 1..n - p - 1)
        .any(|i| c_held.control_points()[i].distance(c_free.control_points()[i]) > 0.0);
    assert!(interior_moved);
    // Every control point acting at an end is the same in the runs with 1 and 0 iterations.
    let design = fair::fair(
        "kuragano",
        &input,
        &opts
            .clone()
            .with_end_fix(EndFix::Curvature)
            .with_max_iterations(0),
    )
    .unwrap()
    .curve
    .unwrap();
    for i in held_indices(n, p + 1) {
        assert_eq!(
            c_held.control_points()[i],
            design.control_points()[i],
            "{i}"
        );
    }
    let (a, b) = (end_state(&design), end_state(&c_held));
    for end in 0..2 {
        assert!((a[end].0 - b[end].0).length() < 1e-12);
        assert!((a[end].1 - b[end].1).abs() < 1e-12);
    }
    // Without the hold the end curvature changes: the hold is what keeps it.
    let f = end_state(&c_free);
    assert!((0..2).any(|end| (f[end].1 - a[end].1).abs() > 1e-6));
}

#[test]
fn holding_every_point_changes_nothing() {
    let pts = noisy_sine(6, 0.05, 1);
    let input = PointSeq::open(pts.clone()).unwrap();
    for method in POINT_METHODS {
        let out = fair::fair(
            method,
            &input,
            &FairOptions::default().with_end_fix(EndFix::Curvature),
        )
        .unwrap();
        assert_eq!(out.points, pts, "{method}");
        assert_eq!(out.report.status, FairStatus::NoChange);
        assert!(out.report.notes.iter().any(|n| n.contains("all 6 points")));
    }
}

#[test]
fn closed_curves_have_no_end_changes() {
    let pts: Vec<Point> = (0..24)
        .map(|i| {
            let a = i as f64 * std::f64::consts::TAU / 24.0;
            Point::new(2.0 * a.cos() + 0.01 * (5.0 * a).sin(), a.sin())
        })
        .collect();
    let input = PointSeq::closed(pts).unwrap();
    let out = fair::fair("han", &input, &FairOptions::default()).unwrap();
    assert!(out.report.end_changes.is_none());
    // Every method says, once, that fix_ends does nothing on a closed curve.
    for method in ["han", "mst", "kjellander", "sapidis-farin"] {
        let out = fair::fair(
            method,
            &input,
            &FairOptions::default().with_end_fix(EndFix::Tangent),
        )
        .unwrap();
        let said = out
            .report
            .notes
            .iter()
            .filter(|n| n.contains("fix_ends has no effect"));
        assert_eq!(said.count(), 1, "{method}: {:?}", out.report.notes);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// The held points never move, whatever the method, the data and the tolerance.
    #[test]
    fn held_points_never_move(
        seed in any::<u64>(),
        n in 8usize..60,
        amp in 0.0f64..0.2,
        method in 0usize..POINT_METHODS.len(),
        level in 1usize..4,
        tol in prop::option::of(1e-3f64..0.5),
    ) {
        let pts = noisy_sine(n, amp, seed);
        let Ok(input) = PointSeq::open(pts.clone()) else { return Ok(()) };
        let fix = EndFix::ALL[level];
        let mut opts = FairOptions::default().with_end_fix(fix);
        if let Some(t) = tol {
            opts = opts.with_tolerance(t);
        }
        let out = fair::fair(POINT_METHODS[method], &input, &opts).unwrap();
        for i in held_indices(n, fix.held()) {
            prop_assert_eq!(out.points[i], pts[i]);
        }
        if let Some(t) = tol {
            prop_assert!(out.report.max_displacement <= t);
        }
    }
}
