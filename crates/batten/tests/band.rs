//! `band`: the tolerance is never exceeded, the automatic tolerance, closed curves, rigid
//! motion and scale, clean curves, and the report's solver figures.

use batten::fair::{self, EndFix, FairStatus, ToleranceSource};
use batten::{FairOptions, Point, PointSeq};
use proptest::prelude::*;

mod common;
use common::{Noise, jitter};

/// Samples of a wavy open curve (`sin x` on [0, 6]), or of a closed three-lobed loop, with a
/// uniform wobble of width `amp`.
fn noisy(n: usize, amp: f64, seed: u64, closed: bool) -> PointSeq {
    let exact = if closed {
        common::lobed_loop(n)
    } else {
        common::sine(n, 6.0)
    };
    PointSeq::new(jitter(&exact, Noise::Uniform(amp), seed), closed).expect("valid points")
}

/// The largest displacement, by the contract's own measure (`Point::distance`, a `hypot`): a
/// square root of the summed squares can be one unit in the last place above it, and a point
/// on the band's edge then looks outside (n = 71, closed, tol 0.00793: the case in
/// `band.proptest-regressions`, which `never_exceeds_the_tolerance` re-runs first).
fn max_move(a: &[Point], b: &[Point]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f64::max)
}

#[test]
fn removes_the_wiggles_of_a_noisy_sine_within_the_tolerance() {
    let input = noisy(200, 0.04, 7, false);
    let out = fair::fair("band", &input, &FairOptions::default().with_tolerance(0.05)).unwrap();
    let r = &out.report;
    assert_eq!(r.status, FairStatus::Converged);
    assert!(r.tolerance_met && r.max_displacement <= 0.05);
    assert!(max_move(input.points(), &out.points) <= 0.05);
    assert!(r.before.inflections > 10, "{}", r.before.inflections);
    // sin on [0, 6] has one true inflection (at π).
    assert!(r.after.inflections <= 1, "{}", r.after.inflections);
    let solver = r.solver.as_ref().expect("band reports its solver");
    assert!(solver.iterations > 0 && solver.duality_gap <= 1e-6);
    // Without the debiasing stage the fairest curve in the band touches the band's edge.
    let pure = fair::fair(
        "band",
        &input,
        &FairOptions::default()
            .with_tolerance(0.05)
            .with_param("fit", 0),
    )
    .unwrap();
    let solver = pure
        .report
        .solver
        .as_ref()
        .expect("band reports its solver");
    assert!(solver.points_on_band_edge > 0);
    assert!(pure.report.after.inflections <= 1);
}

/// RMS distance of the points of a faired `noisy(n, _, _, false)` to the exact sine at the
/// same abscissae.
fn rms_to_sine(points: &[Point]) -> f64 {
    let exact = common::sine(points.len(), 6.0);
    let sum: f64 = points
        .iter()
        .zip(&exact)
        .map(|(p, q)| (p.x - q.x).powi(2) + (p.y - q.y).powi(2))
        .sum();
    (sum / points.len() as f64).sqrt()
}

#[test]
fn the_debiasing_stage_moves_closer_to_the_truth_and_stays_fair() {
    for seed in [3, 7, 11] {
        let input = noisy(400, 0.03, seed, false);
        let run = |fit: f64| {
            fair::fair(
                "band",
                &input,
                &FairOptions::default().with_param("fit", fit),
            )
            .unwrap()
        };
        let (pure, debiased) = (run(0.0), run(1.25));
        assert_eq!(pure.report.tolerance, debiased.report.tolerance);
        assert!(debiased.report.max_displacement <= debiased.report.tolerance.unwrap());
        assert!(
            debiased
                .report
                .notes
                .iter()
                .any(|n| n.starts_with("debiasing stage")),
            "{:?}",
            debiased.report.notes
        );
        let (a, b) = (rms_to_sine(&pure.points), rms_to_sine(&debiased.points));
        assert!(b < a, "seed {seed}: debiased {b} vs band alone {a}");
        assert!(debiased.report.after.inflections <= 1, "seed {seed}");
    }
}

/// A quarter of the ellipse (2 cos t, 0.5 sin t), t in [0, π/2], from its sharp vertex
/// (κ = 8) to its flat one (κ = 1/8), with uniform noise of half-width `amp`, and the exact
/// points.
fn noisy_quarter_ellipse(n: usize, amp: f64, seed: u64) -> (PointSeq, Vec<Point>) {
    let exact = common::ellipse_arc(n, 2.0, 0.5, std::f64::consts::FRAC_PI_2);
    let pts = jitter(&exact, Noise::Uniform(amp), seed);
    (PointSeq::new(pts, false).expect("valid points"), exact)
}

#[test]
fn local_debiasing_restores_a_flattened_vertex() {
    // One data weight for the whole curve is set by the flat part; at the sharp vertex the
    // fairest curve in the band flattens the end by about a noise standard deviation over
    // tens of points. The local stage finds that one-signed residual and weighs the data
    // there more: the end lies closer to the truth, and the curve stays inside its band.
    for seed in [2, 5, 9] {
        let (input, exact) = noisy_quarter_ellipse(1000, 0.006, seed);
        let run = |local: f64| {
            fair::fair(
                "band",
                &input,
                &FairOptions::default().with_param("local", local),
            )
            .unwrap()
        };
        let (single, local) = (run(0.0), run(2.0));
        let end_rms = |pts: &[Point]| -> f64 {
            let m = 60;
            let sum: f64 = pts[..m]
                .iter()
                .zip(&exact)
                .map(|(p, q)| (p.x - q.x).powi(2) + (p.y - q.y).powi(2))
                .sum();
            (sum / m as f64).sqrt()
        };
        let (a, b) = (end_rms(&single.points), end_rms(&local.points));
        assert!(b < 0.8 * a, "seed {seed}: local {b} vs single weight {a}");
        assert!(local.report.max_displacement <= local.report.tolerance.unwrap());
        let note = local
            .report
            .notes
            .iter()
            .find(|n| n.starts_with("debiasing stage"))
            .expect("a debiasing note");
        assert!(
            note.contains("raised at") && !note.contains("raised at 0 "),
            "{note}"
        );
        assert!(local.report.after.inflections == 0, "seed {seed}");
    }
}

/// A noisy arc of the ellipse (2.8 cos t, sin t), t in [0, 1.3π], with Gaussian noise of
/// `sigma` per coordinate, and the exact points.
fn noisy_ellipse_arc(n: usize, sigma: f64, seed: u64) -> (PointSeq, Vec<Point>) {
    let exact = common::ellipse_arc(n, 2.8, 1.0, 1.3 * std::f64::consts::PI);
    let pts = jitter(&exact, Noise::Gaussian(sigma), seed);
    (PointSeq::new(pts, false).expect("valid points"), exact)
}

#[test]
fn the_debiasing_stage_runs_when_even_the_smoothest_weight_meets_its_target() {
    // 1000 points, noise 0.5 % of the diagonal: the band's passes flatten both vertices, yet
    // their result is held by the band at a few points and lies farther from the data than a
    // smooth fit at the smallest weight rounding allows. That weight is the discrepancy's
    // answer; the stage was skipped there before (no note), and the vertices stayed flat.
    for seed in [1, 2] {
        let (input, exact) = noisy_ellipse_arc(1000, 0.03, seed);
        let run = |fit: f64| {
            fair::fair(
                "band",
                &input,
                &FairOptions::default().with_param("fit", fit),
            )
            .unwrap()
        };
        let (passes, debiased) = (run(0.0), run(1.25));
        assert!(
            debiased
                .report
                .notes
                .iter()
                .any(|n| n.starts_with("debiasing stage")),
            "seed {seed}: {:?}",
            debiased.report.notes
        );
        let rms = |pts: &[Point]| -> f64 {
            let sum: f64 = pts
                .iter()
                .zip(&exact)
                .map(|(p, q)| p.distance(*q).powi(2))
                .sum();
            (sum / pts.len() as f64).sqrt()
        };
        let (a, b) = (rms(&passes.points), rms(&debiased.points));
        assert!(b < 0.9 * a, "seed {seed}: debiased {b} vs passes {a}");
        assert!(debiased.report.max_displacement <= debiased.report.tolerance.unwrap());
        assert_eq!(debiased.report.after.inflections, 0, "seed {seed}");
    }
}

/// The curvature of the circle through `a`, `b`, `c`.
fn menger(a: Point, b: Point, c: Point) -> f64 {
    let (u, v, w) = (b - a, c - b, c - a);
    2.0 * u.cross(v).abs() / (u.length() * v.length() * w.length())
}

#[test]
fn the_debiasing_stage_runs_when_the_passes_meet_its_target_and_restores_flattened_ends() {
    // A 240° arc of radius 5, 1000 points, noise 0.5 % of the diagonal: the passes' result
    // is within the discrepancy target already (the flattening is at the free ends, a few
    // points, and the global residual does not see it), so the stage used to be skipped and
    // the ends came out a third flat (κ 0.12–0.14 over the last 30 points against 0.2; now
    // 0.16–0.17). The local weights find the ends' one-signed residual.
    let exact = common::ellipse_arc(1000, 5.0, 5.0, 4.0 * std::f64::consts::PI / 3.0);
    for seed in [1, 2, 3] {
        let input = PointSeq::new(jitter(&exact, Noise::Gaussian(0.068), seed), false).unwrap();
        let out = fair::fair("band", &input, &FairOptions::default()).unwrap();
        let r = &out.report;
        assert!(
            r.notes.iter().any(|n| n.starts_with("debiasing stage")),
            "seed {seed}: {:?}",
            r.notes
        );
        let q = &out.points;
        let n = q.len();
        let ends = [
            menger(q[0], q[15], q[30]),
            menger(q[n - 31], q[n - 16], q[n - 1]),
        ];
        for k in ends {
            assert!(
                k > 0.155 && k < 0.23,
                "seed {seed}: end curvature {ends:?}, true 0.2"
            );
        }
        assert_eq!(r.after.inflections, 0, "seed {seed}");
        assert!(r.tolerance_met && max_move(input.points(), q) <= r.tolerance.unwrap());
    }
}

/// A run whose gap meets the stopping rule while its dual residual creeps just above its
/// bound (rounding at the band's edge cuts every step short) ends as converged instead of
/// running on: the bundled noisy cubic took 246 iterations in all; now 68, with the same
/// points to 5e-10.
#[test]
fn a_creeping_dual_residual_ends_the_run() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/data/cubic-noisy.csv");
    let input = batten::io::read_points(&path, &batten::io::ReadOptions::default())
        .expect("example")
        .seq;
    let out = fair::fair("band", &input, &FairOptions::default()).unwrap();
    let r = &out.report;
    assert_eq!(r.status, FairStatus::Converged);
    let iterations = r.solver.as_ref().unwrap().iterations;
    assert!(iterations < 120, "{iterations} solver iterations");
    assert!(r.tolerance_met);
}

/// Exact samples with `--tolerance auto`: the noise estimate's differences are the curve's
/// own shape, so nothing moves and a note says why (the bundled `sine-truth.csv` used to lose
/// its end inflections and come out with 1.6 times its curvature error against the truth).
/// A tolerance given, the test does not apply.
#[test]
fn exact_samples_have_no_noise_for_the_automatic_tolerance() {
    for name in [
        "sine-truth.csv",
        "clothoid-truth.csv",
        "strophoid-truth.csv",
    ] {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples/data")
            .join(name);
        let input = batten::io::read_points(&path, &batten::io::ReadOptions::default())
            .expect("example")
            .seq;
        let out = fair::fair("band", &input, &FairOptions::default()).unwrap();
        let r = &out.report;
        assert_eq!(r.status, FairStatus::NoChange, "{name}: {:?}", r.notes);
        assert_eq!(r.tolerance_source, Some(ToleranceSource::Auto));
        assert!(
            r.notes.iter().any(|n| n.contains("found no noise")),
            "{name}: {:?}",
            r.notes
        );
        assert_eq!(out.points.as_slice(), input.points(), "{name}");
        // A tolerance given is the user's: the test does not apply (the result may still
        // be the input, where the clean-curve guard finds it worse).
        let given = FairOptions::default().with_tolerance(0.01 * input.bbox().diagonal());
        let faired = fair::fair("band", &input, &given).unwrap();
        assert!(
            faired
                .report
                .notes
                .iter()
                .all(|n| !n.contains("found no noise")),
            "{name}"
        );
        if name == "sine-truth.csv" {
            assert_eq!(faired.report.status, FairStatus::Converged);
        }
    }
    // Noisy points are faired as before.
    let noisy = noisy(200, 0.01, 3, false);
    let out = fair::fair("band", &noisy, &FairOptions::default()).unwrap();
    assert_eq!(out.report.status, FairStatus::Converged);
}

/// The other side of the contract: exact samples of a curve that is not fair (a parabola with
/// a small bump, two inflections it should not have) are left alone by the automatic
/// tolerance, which finds no noise, and faired within a tolerance given: the bump's
/// inflections go, the variation energy falls, no point moves farther than the tolerance.
/// A rule that left every clean input alone would leave this bump in place.
#[test]
fn a_clean_curve_with_a_bump_is_faired_within_a_given_tolerance() {
    let pts: Vec<Point> = (0..200)
        .map(|i| {
            let x = -1.0 + 2.0 * i as f64 / 199.0;
            let bump = 0.004 * (-((x - 0.3) / 0.08f64).powi(2)).exp();
            Point::new(x, 0.3 * x * x + bump)
        })
        .collect();
    let input = PointSeq::open(pts).unwrap();
    let auto = fair::fair("band", &input, &FairOptions::default()).unwrap();
    assert_eq!(auto.report.status, FairStatus::NoChange);
    assert_eq!(auto.points.as_slice(), input.points());
    assert_eq!(auto.report.before.inflections, 2);
    for tol in [0.002, 0.005] {
        let out = fair::fair("band", &input, &FairOptions::default().with_tolerance(tol)).unwrap();
        let r = &out.report;
        assert_eq!(r.status, FairStatus::Converged, "{tol}");
        assert_eq!(r.after.inflections, 0, "{tol}");
        assert!(
            r.after.variation_energy < 0.01 * r.before.variation_energy,
            "{tol}: {} → {}",
            r.before.variation_energy,
            r.after.variation_energy
        );
        assert!(max_move(input.points(), &out.points) <= tol);
    }
}

/// A sine of 1000 points with Gaussian noise of σ = 0.01, and `outliers` of its points
/// moved a further 10σ in y (every 20th point from the 7th, up and down by turns).
fn sine_with_outliers(outliers: usize) -> PointSeq {
    let mut pts = jitter(&common::sine(1000, 12.0), Noise::Gaussian(0.01), 17);
    for (j, i) in (7..1000).step_by(20).take(outliers).enumerate() {
        pts[i].y += if j % 2 == 0 { 0.1 } else { -0.1 };
    }
    PointSeq::open(pts).expect("valid points")
}

/// The automatic tolerance is a noise model (Gaussian, the same σ in every direction); where
/// the debiased fit presses the band's edge at more points than the model allows, the
/// tolerance is widened (by 1.2, at most 10 times) and the note says so. With 40 outliers at
/// 10σ, a band of `k·σ̂` forces the curve through them; widened, it need not.
#[test]
fn outliers_widen_the_automatic_tolerance() {
    let input = sine_with_outliers(40);
    let auto = fair::fair("band", &input, &FairOptions::default()).unwrap();
    let r = &auto.report;
    let sigma = r.noise_sigma.unwrap();
    let first = fair::band_tolerance_factor(1000) * sigma;
    let d = r.tolerance.unwrap();
    assert_eq!(r.tolerance_source, Some(ToleranceSource::Auto));
    assert!(d > 1.19 * first, "{d} against k·σ̂ = {first}");
    assert!(r.max_displacement <= d);
    assert!(
        r.notes
            .iter()
            .any(|n| n.contains("--tolerance auto widened")),
        "{:?}",
        r.notes
    );
    // The same data in a band of k·σ̂, given: the curve bends to the outliers.
    let narrow = fair::fair(
        "band",
        &input,
        &FairOptions::default().with_tolerance(first),
    )
    .unwrap();
    assert!(
        r.after.inflections < narrow.report.after.inflections,
        "{} widened against {} in k·σ̂",
        r.after.inflections,
        narrow.report.after.inflections
    );
    // Gaussian noise alone: the model holds, nothing is widened.
    let clean = fair::fair("band", &sine_with_outliers(0), &FairOptions::default()).unwrap();
    assert!(clean.report.notes.iter().all(|n| !n.contains("widened")));
    let k = fair::band_tolerance_factor(1000) * clean.report.noise_sigma.unwrap();
    assert!((clean.report.tolerance.unwrap() - k).abs() <= 1e-12 * k);
    // `--set k=` chooses the band's width: not widened either.
    let chosen = fair::fair(
        "band",
        &input,
        &FairOptions::default().with_param("k", 3.72),
    )
    .unwrap();
    assert!((chosen.report.tolerance.unwrap() - 3.72 * sigma).abs() <= 1e-12 * d);
}

#[test]
fn takes_k_noise_estimates_when_no_tolerance_is_given() {
    let input = noisy(300, 0.03, 11, false);
    let out = fair::fair("band", &input, &FairOptions::default()).unwrap();
    let r = &out.report;
    assert_eq!(r.tolerance_source, Some(ToleranceSource::Auto));
    let sigma = r.noise_sigma.expect("noise estimate reported");
    let d = r.tolerance.expect("tolerance reported");
    // k = max(3, √(2 ln n)): 3.38 at 300 points.
    let k = fair::band_tolerance_factor(300);
    assert!((k - (2.0 * 300f64.ln()).sqrt()).abs() < 1e-15 && k > 3.0);
    assert_eq!(fair::band_tolerance_factor(50), 3.0);
    assert!((d - k * sigma).abs() <= 1e-12 * d, "{d} vs {k}·{sigma}");
    assert!(r.max_displacement <= d);
    // `--set k=2` scales it.
    let two = fair::fair("band", &input, &FairOptions::default().with_param("k", 2)).unwrap();
    assert!((two.report.tolerance.unwrap() - 2.0 * sigma).abs() <= 1e-12 * d);
}

#[test]
fn closed_curves_stay_closed_and_fair() {
    let input = noisy(240, 0.02, 5, true);
    let out = fair::fair("band", &input, &FairOptions::default().with_tolerance(0.03)).unwrap();
    assert_eq!(out.points.len(), 240);
    assert!(out.report.max_displacement <= 0.03);
    assert!(out.report.after.inflections < out.report.before.inflections);
}

#[test]
fn held_ends_do_not_move() {
    let input = noisy(120, 0.04, 9, false);
    for (fix, held) in [
        (fair::EndFix::Position, 1),
        (fair::EndFix::Tangent, 2),
        (fair::EndFix::Curvature, 3),
    ] {
        let out = fair::fair(
            "band",
            &input,
            &FairOptions::default()
                .with_tolerance(0.05)
                .with_end_fix(fix),
        )
        .unwrap();
        let n = input.len();
        for i in (0..held).chain(n - held..n) {
            assert_eq!(out.points[i], input.points()[i], "{fix:?} point {i}");
        }
    }
}

#[test]
fn a_clean_arc_gains_no_inflection() {
    // Exact samples: σ̂ is rounding-sized, so is the automatic tolerance.
    let pts: Vec<Point> = (0..200)
        .map(|i| {
            let a = 4.0 * i as f64 / 199.0;
            Point::new(a.cos(), a.sin())
        })
        .collect();
    let input = PointSeq::open(pts).unwrap();
    let out = fair::fair("band", &input, &FairOptions::default()).unwrap();
    assert_eq!(out.report.after.inflections, 0);
    assert!(out.report.max_displacement <= 1e-6);
}

#[test]
fn too_few_points_on_a_closed_curve_is_a_clear_error() {
    let input = noisy(6, 0.0, 1, true);
    let err = fair::fair("band", &input, &FairOptions::default().with_tolerance(0.1))
        .unwrap_err()
        .to_string();
    assert!(err.contains("at least 8 points"), "{err}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// The promise: no point moves farther than the tolerance, open or closed, whatever the
    /// noise and the tolerance.
    #[test]
    fn never_exceeds_the_tolerance(
        n in 12usize..160,
        amp in 0.0f64..0.2,
        tol in 1e-4f64..0.3,
        seed in any::<u64>(),
        closed in any::<bool>(),
    ) {
        let input = noisy(n, amp, seed, closed);
        let out = fair::fair("band", &input, &FairOptions::default().with_tolerance(tol)).unwrap();
        prop_assert!(out.report.max_displacement <= tol);
        prop_assert!(max_move(input.points(), &out.points) <= tol);
        prop_assert!(out.report.tolerance_met);
    }

    /// Rotating, translating and scaling the input does the same to the result (the problem is
    /// solved in units of the tolerance about the centroid).
    #[test]
    fn follows_rigid_motion_and_scale(
        angle in 0.0f64..std::f64::consts::TAU,
        shift in -1e3f64..1e3,
        scale in prop_oneof![Just(1e-3), Just(1.0), Just(37.5), Just(1e4)],
        seed in any::<u64>(),
    ) {
        let input = noisy(80, 0.05, seed, false);
        let tol = 0.06;
        let base = fair::fair("band", &input, &FairOptions::default().with_tolerance(tol)).unwrap();
        let (s, c) = angle.sin_cos();
        let map = |p: &Point| Point::new(
            scale * (c * p.x - s * p.y) + shift,
            scale * (s * p.x + c * p.y) - 0.5 * shift,
        );
        let moved = PointSeq::open(input.points().iter().map(map).collect()).unwrap();
        let out = fair::fair(
            "band",
            &moved,
            &FairOptions::default().with_tolerance(scale * tol),
        )
        .unwrap();
        let expected: Vec<Point> = base.points.iter().map(map).collect();
        let off = max_move(&expected, &out.points);
        // Equal up to the solver's stopping rule and the rounding of the coordinates (5e-9 of
        // the tolerance at 1e-3 scale 559 units from the origin); compare in tolerances.
        prop_assert!(off <= 1e-6 * scale * tol, "off by {off:e} at scale {scale}");
    }
}

/// Dense points (20 000, noise about 5 spacings) are solved in the spline form: the run
/// converges, keeps the truth's inflections (one on the open sine, six on the closed
/// three-lobed curve), holds the tolerance, and held end points stay exactly where they were.
#[test]
fn dense_points_converge_in_the_spline_form() {
    for (closed, fix, truth) in [
        (false, EndFix::Free, 1),
        (false, EndFix::Position, 1),
        (true, EndFix::Free, 6),
    ] {
        let input = noisy(20_000, 0.002, 3, closed);
        let options = FairOptions::default().with_end_fix(fix);
        let out = fair::fair("band", &input, &options).expect("band runs");
        let r = &out.report;
        let case = format!("closed {closed}, {fix:?}: {:?}", r.notes);
        assert_eq!(r.status, FairStatus::Converged, "{case}");
        assert!(r.notes.iter().any(|n| n.contains("spline form")), "{case}");
        assert_eq!(r.after.inflections, truth, "{case}");
        let d = r.tolerance.expect("auto tolerance");
        assert!(
            r.tolerance_met && max_move(input.points(), &out.points) <= d,
            "{case}"
        );
        if fix == EndFix::Position {
            let (p, q) = (input.points(), &out.points);
            assert!(
                p[0] == q[0] && p[p.len() - 1] == q[q.len() - 1],
                "{case}: {:?} {:?} {:?} {:?}",
                p[0],
                q[0],
                p[p.len() - 1],
                q[q.len() - 1]
            );
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(8))]

    /// The spline form's promises on random dense curves (it solves on a working set of
    /// points and checks the others): the tolerance holds by the contract's measure, the run
    /// converges, and held end points stay exactly where they were. The noise is at least
    /// about the spacing, as in dense scans (with less, the knots every tolerance would
    /// carry fewer than four points each and the point form runs).
    #[test]
    fn dense_points_keep_the_tolerance_in_the_spline_form(
        n in 2_001usize..4_000,
        amp in 0.015f64..0.05,
        seed in any::<u64>(),
        closed in any::<bool>(),
        hold in any::<bool>(),
    ) {
        let input = noisy(n, amp, seed, closed);
        let fix = if hold && !closed { EndFix::Position } else { EndFix::Free };
        let out = fair::fair("band", &input, &FairOptions::default().with_end_fix(fix)).unwrap();
        let r = &out.report;
        prop_assert!(r.notes.iter().any(|n| n.contains("spline form")), "{:?}", r.notes);
        prop_assert_eq!(r.status, FairStatus::Converged);
        let d = r.tolerance.unwrap();
        prop_assert!(r.tolerance_met && max_move(input.points(), &out.points) <= d);
        if fix == EndFix::Position {
            let (p, q) = (input.points(), &out.points);
            prop_assert!(p[0] == q[0] && p[n - 1] == q[n - 1]);
        }
    }
}

/// Dense points with held tangents (10 000, noise about 16 spacings) take the point form,
/// which rounding mostly stops short of its stopping rule (docs/algorithms/band.md, Limits).
/// The report says so — status `stalled`, not the iteration limit, with the gap in a note —
/// and the tolerance holds. Whether a given draw stalls is up to rounding (35 of 40 seeds
/// did; seed 3 stalled until the noise estimate's lengths changed by an ulp), so three
/// draws are run and at least one must stall.
#[test]
fn a_run_that_rounding_stops_is_reported_as_stalled_within_the_tolerance() {
    let mut stalled = 0;
    for seed in [0, 1, 2] {
        let input = noisy(10_000, 0.01, seed, false);
        let options = FairOptions::default().with_end_fix(EndFix::Tangent);
        let out = fair::fair("band", &input, &options).expect("band runs");
        let r = &out.report;
        assert!(
            matches!(r.status, FairStatus::Stalled | FairStatus::Converged),
            "seed {seed}: {:?} {:?}",
            r.status,
            r.notes
        );
        assert!(r.iterations < 200, "stopped by rounding, not the limit");
        let d = r.tolerance.expect("auto tolerance");
        assert!(r.tolerance_met && max_move(input.points(), &out.points) <= d);
        if r.status == FairStatus::Stalled {
            stalled += 1;
            assert!(
                r.notes.iter().any(|n| n.contains("stopped short")),
                "{:?}",
                r.notes
            );
        }
    }
    assert!(stalled > 0, "none of the three draws stalled");
}

/// A 1000-point noisy clothoid (bench/quality.py's test case, 1 % noise, seed 3) on which the
/// debiasing stage's local weights met a matrix that rounding left indefinite (the energy's
/// null space held by tiny weights alone): the run failed with exit 1. The raising of the
/// weights now stops there, and the run converges inside the tolerance.
#[test]
fn an_indefinite_local_weights_matrix_ends_the_raising_not_the_run() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/clothoid-1000-indefinite.csv");
    let seq = batten::io::read_points(&path, &batten::io::ReadOptions::default())
        .unwrap()
        .seq;
    let out = fair::fair("band", &seq, &FairOptions::default()).unwrap();
    assert_eq!(out.report.status, FairStatus::Converged);
    assert!(out.report.tolerance_met);
    assert!(out.report.max_displacement <= out.report.tolerance.unwrap());
}
