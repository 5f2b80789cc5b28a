//! Promises every fairing method keeps (issue #14), checked as properties over random noisy
//! curves: the tolerance is never exceeded; a rigid motion of the input moves the output
//! with it; coordinates up to the largest finite magnitudes work. (Clean curves staying
//! clean and scale invariance are in `tests/clean.rs`.)

use std::f64::consts::PI;

use batten::fair::{fair, methods};
use batten::{FairOptions, Point, PointSeq, Rigid, Vec2};
use proptest::prelude::*;

/// A noisy sine or arc: `n` points, deterministic noise of relative size `noise` from `seed`.
fn noisy(seed: u64, n: usize, noise: f64, arc: bool) -> Vec<Point> {
    let mut state = seed | 1;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    (0..n)
        .map(|i| {
            let t = i as f64 / (n - 1) as f64;
            let e = if i == 0 || i == n - 1 { 0.0 } else { noise };
            if arc {
                let a = 0.8 * PI * t;
                let r = 3.0 + e * next();
                Point::new(r * a.cos(), r * a.sin())
            } else {
                let x = 4.0 * PI * t;
                Point::new(x, (0.5 * x).sin() + e * next())
            }
        })
        .collect()
}

fn names() -> Vec<&'static str> {
    methods().iter().map(|m| m.name()).collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn the_tolerance_is_never_exceeded(
        seed in any::<u64>(),
        n in 8usize..60,
        noise in 0.0f64..0.1,
        arc in any::<bool>(),
        tol in 1e-4f64..0.3,
    ) {
        let pts = noisy(seed, n, noise, arc);
        let Ok(seq) = PointSeq::open(pts.clone()) else { return Ok(()) };
        for name in names() {
            let out = fair(name, &seq, &FairOptions::default().with_tolerance(tol))
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let worst = out.points.iter().zip(&pts).map(|(a, b)| a.distance(*b)).fold(0.0, f64::max);
            prop_assert!(worst <= tol, "{name}: {worst} > {tol}");
            prop_assert!(out.report.tolerance_met, "{name}");
            prop_assert!((out.report.max_displacement - worst).abs() <= 1e-12 * tol.max(worst));
        }
    }

    /// A rigid motion of the input gives the moved output. The methods work in intrinsic
    /// quantities (chord lengths, curvature, local frames) or, where a step depends on the
    /// axes (`salvi`), in the principal frame of the points, so the results agree to
    /// rounding; `kuragano` is the exception. A discrete choice at a knife edge (the worst point among near-ties, a sign
    /// test at its zero threshold) may part one method's runs now and then.
    #[test]
    fn rigid_motion_moves_the_result(
        seed in any::<u64>(),
        n in 10usize..40,
        arc in any::<bool>(),
        angle in -PI..PI,
        tx in -100.0f64..100.0,
        ty in -100.0f64..100.0,
    ) {
        let pts = noisy(seed, n, 0.05, arc);
        let Ok(seq) = PointSeq::open(pts.clone()) else { return Ok(()) };
        let motion = Rigid::new(angle, Vec2::new(tx, ty));
        let moved = PointSeq::open(pts.iter().map(|p| motion.apply(*p)).collect()).unwrap();
        let opts = FairOptions::default().with_tolerance(0.05);
        let scale = seq.bbox().diagonal();
        let mut parted = Vec::new();
        // kuragano is not rotation invariant (the spec's Marquardt scaling, see its `run`).
        for name in names().into_iter().filter(|&n| n != "kuragano") {
            let a = fair(name, &seq, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
            let b = fair(name, &moved, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
            let worst = a.points.iter().zip(&b.points)
                .map(|(p, q)| motion.apply(*p).distance(*q))
                .fold(0.0, f64::max);
            if worst > 1e-7 * scale {
                parted.push((name, worst / scale));
            }
            prop_assert_eq!(a.report.before.inflections, b.report.before.inflections, "{}", name);
            prop_assert!(b.report.tolerance_met, "{}", name);
        }
        // Knife edges part one or two methods' runs now and then (han and salvi by 0.1–0.3 %
        // of the size after a translation), never most of them. Before the principal frame,
        // salvi and kuragano parted on almost every rotation, by about 1 % of the size.
        prop_assert!(parted.len() <= 2, "parted (method, distance / size): {parted:?}");
    }
}

/// Issue #14: a value of 1e308 passed the parser and then failed in `han` as "point 3 is not
/// finite". Every method now runs on coordinates divided by a power of two there.
#[test]
fn coordinates_near_the_largest_float_work() {
    for scale in [1e308, 1e-300] {
        let pts: Vec<Point> = noisy(7, 24, 0.05, false)
            .iter()
            .map(|p| Point::new(p.x * (scale / 16.0), p.y * (scale / 16.0)))
            .collect();
        let seq = PointSeq::open(pts).unwrap();
        let tol = 0.05 * scale / 16.0;
        for name in names() {
            let out = fair(name, &seq, &FairOptions::default().with_tolerance(tol))
                .unwrap_or_else(|e| panic!("{name} at {scale:e}: {e}"));
            assert!(out.points.iter().all(|p| p.is_finite()), "{name}");
            assert!(out.report.tolerance_met, "{name} at {scale:e}");
            // ∫(dκ/ds)² ds scales as 1/length³: at 1e-300 it overflows to +∞, honestly.
            assert!(
                !out.report.after.variation_energy.is_nan(),
                "{name} at {scale:e}"
            );
            assert!(
                name == "mst" || out.report.after.inflections <= out.report.before.inflections,
                "{name}"
            );
        }
    }
}
