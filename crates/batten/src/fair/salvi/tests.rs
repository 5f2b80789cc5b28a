//! Salvi & Várady target-curvature fairing and Eck & Hadenfeld local energy fairing
//! (docs/algorithms/salvi-varady.md §3): the `salvi_varady` test vectors, the properties of
//! `sv.fair.properties`, and the behaviour of both methods on B-spline and point input.
//!
//! Unit tests (formerly `tests/salvi.rs`): they reach the target curvature and the shared
//! local-fairing machinery of `fair/local.rs`, which are not public.

use crate::fair::eck_hadenfeld::{self, EckHadenfeldParams};
use crate::fair::local::{
    RecentList, clamp_to_original, principal_curvatures, support_ranges, uniform_samples,
};
use crate::fair::salvi::target::{
    moving_average, sample_curvature, target_curvature, target_measure,
};
use crate::fair::salvi::{self, SalviParams, Smoother};
use crate::fair::{self, FairStatus};
use crate::spline::{BSplineCurve, KnotVector};
use crate::{Curve, Error, FairOptions, Point, PointSeq};
use proptest::prelude::*;
use serde_json::Value;

use crate::test_rng::Rng;
use crate::test_vectors::{self, nums, points};

fn vector(id: &str) -> Value {
    test_vectors::vector("salvi_varady", id)
}

fn assert_close(got: &[f64], exp: &[f64], tol: &Value, what: &str) {
    test_vectors::all_close(got, exp, tol, what);
}

/// A clamped uniform cubic with control points on `f`.
fn cubic(n: usize, f: impl Fn(usize) -> Point) -> BSplineCurve {
    BSplineCurve::new(
        3,
        KnotVector::clamped_uniform(3, n).expect("knots"),
        (0..n).map(f).collect(),
        None,
    )
}

/// The base of the `sv.fair.properties` test: 20 control points on a sine arc.
fn sine_base() -> BSplineCurve {
    cubic(20, |i| {
        let x = i as f64 * 0.5;
        Point::new(x, (x * 0.6).sin() * 1.5)
    })
}

/// `base` with its interior control points perturbed by N(0, sigma²) in each coordinate.
fn perturbed(base: &BSplineCurve, sigma: f64, seed: u64) -> BSplineCurve {
    let mut rng = Rng::new(seed);
    let mut pts = base.control_points().to_vec();
    let n = pts.len();
    for p in &mut pts[1..n - 1] {
        p.x += sigma * rng.gaussian();
        p.y += sigma * rng.gaussian();
    }
    base.with_control_points(pts).expect("finite")
}

/// Largest `|a(t) − b(t)|` over a dense parameter grid.
fn max_deviation(a: &BSplineCurve, b: &BSplineCurve) -> f64 {
    let (t0, t1) = a.domain();
    (0..=2000)
        .map(|i| {
            let t = t0 + (t1 - t0) * i as f64 / 2000.0;
            a.eval(t).distance(b.eval(t))
        })
        .fold(0.0, f64::max)
}

/// Largest distance from a point of `a` to the curve `b` (dense sampling): how far `a` is from
/// `b` as a shape, whatever the parametrisation.
fn shape_distance(a: &BSplineCurve, b: &BSplineCurve) -> f64 {
    let (t0, t1) = b.domain();
    let dense: Vec<Point> = (0..=8000)
        .map(|i| b.eval(t0 + (t1 - t0) * i as f64 / 8000.0))
        .collect();
    let (s0, s1) = a.domain();
    (0..=1000)
        .map(|i| {
            let q = a.eval(s0 + (s1 - s0) * i as f64 / 1000.0);
            dense
                .iter()
                .map(|p| p.distance(q))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

fn max_control_move(a: &BSplineCurve, b: &BSplineCurve) -> f64 {
    a.control_points()
        .iter()
        .zip(b.control_points())
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f64::max)
}

fn rms_difference(a: &[f64], b: &[f64]) -> f64 {
    (a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>() / a.len() as f64).sqrt()
}

fn non_increasing(history: &[crate::fair::HistoryRow]) -> bool {
    history.windows(2).all(|w| w[1].measure <= w[0].measure)
}

// ---------------------------------------------------------------------------------------------
// Vectors

#[test]
fn vector_curvature_samples() {
    let v = vector("sv.curvature_samples");
    let inp = &v["inputs"];
    let curve = BSplineCurve::try_new(
        inp["degree"].as_u64().expect("degree") as usize,
        KnotVector::try_new(nums(&inp["knots"])).expect("knots"),
        points(&inp["control_points"]),
        None,
    )
    .expect("curve");
    let kappa = sample_curvature(&curve, &nums(&inp["t"])).expect("curvature");
    assert_close(
        &kappa,
        &nums(&v["expected"]["kappa"]),
        &v["tolerance"],
        "kappa",
    );
}

#[test]
fn vector_target_smoothing() {
    let v = vector("sv.target_smoothing");
    let kappa = nums(&v["inputs"]["kappa"]);
    let exp = &v["expected"];
    let tol = &v["tolerance"];
    let g1 = moving_average(&kappa, 1, 1);
    assert_close(&g1, &nums(&exp["h1_passes1"]), tol, "h1_passes1");
    let g2 = moving_average(&kappa, 2, 3);
    assert_close(&g2, &nums(&exp["h2_passes3"]), tol, "h2_passes3");
    let m = target_measure(&kappa, &g1);
    // The stored measure has 12 significant digits.
    assert!((m - exp["measure_h1_passes1"].as_f64().expect("measure")).abs() < 1e-10);
    // The same smoother through the method's entry point (N = 10 gives h = ⌊10/20⌋ = 0, so the
    // half-width is given).
    let curve = sine_base();
    let t = uniform_samples(curve.domain(), kappa.len());
    let g = target_curvature(
        &curve,
        &t,
        &kappa,
        &Smoother::MovingAverage {
            half_width: Some(2),
            passes: 3,
        },
        false,
    )
    .expect("target");
    assert_close(&g, &nums(&exp["h2_passes3"]), tol, "target_curvature");
}

#[test]
fn vector_clamp_eq11() {
    let v = vector("sv.clamp_eq11");
    let orig = nums(&v["inputs"]["d_orig"]);
    let orig = [orig[0], orig[1]];
    let results = v["expected"]["results"].as_array().expect("results");
    for (case, exp) in v["inputs"]["cases"]
        .as_array()
        .expect("cases")
        .iter()
        .zip(results)
    {
        let new = nums(&case["d_new"]);
        let (got, _) = clamp_to_original(
            &orig,
            &[new[0], new[1]],
            case["delta"].as_f64().expect("delta"),
        );
        assert_close(&got, &nums(exp), &v["tolerance"], "clamp");
    }
}

#[test]
fn vector_support_counts() {
    let v = vector("sv.support_counts");
    let knots = KnotVector::try_new(nums(&v["inputs"]["knots"])).expect("knots");
    let n = v["inputs"]["N"].as_u64().expect("N") as usize;
    let t = uniform_samples((0.0, 1.0), n);
    let ranges = support_ranges(&knots, 3, knots.len() - 4, &t).expect("ranges");
    let counts: Vec<f64> = ranges.iter().map(|r| r.len() as f64).collect();
    assert_close(
        &counts,
        &nums(&v["expected"]["counts_j_0_to_7"]),
        &v["tolerance"],
        "counts",
    );
}

#[test]
fn vector_principal_curvatures_paraboloid() {
    let v = vector("sv.principal_curvatures.paraboloid");
    let inp = &v["inputs"];
    let net: Vec<Vec<[f64; 3]>> = inp["control_net_xyz"]
        .as_array()
        .expect("net")
        .iter()
        .map(|row| {
            row.as_array()
                .expect("row")
                .iter()
                .map(|p| {
                    let c = nums(p);
                    [c[0], c[1], c[2]]
                })
                .collect()
        })
        .collect();
    let uv = nums(&inp["uv"]);
    // The tensor-product basis, from two B-spline curves whose control points are unused.
    let basis = |knots: &Value, n: usize, t: f64| {
        let c = BSplineCurve::try_new(
            3,
            KnotVector::try_new(nums(knots)).expect("knots"),
            vec![Point::ORIGIN; n],
            None,
        )
        .expect("basis curve");
        let span = c.find_span(t);
        let mut b = [[0.0; crate::spline::MAX_ORDER]; 4];
        c.basis_derivs(span, t, 2, &mut b);
        (span - 3, b)
    };
    let (iu, bu) = basis(&inp["knots_u"], net.len(), uv[0]);
    let (iv, bv) = basis(&inp["knots_v"], net[0].len(), uv[1]);
    let partial = |du: usize, dv: usize| {
        let mut s = [0.0; 3];
        for a in 0..4 {
            for b in 0..4 {
                let w = bu[du][a] * bv[dv][b];
                for (k, sk) in s.iter_mut().enumerate() {
                    *sk += w * net[iu + a][iv + b][k];
                }
            }
        }
        s
    };
    let pc = principal_curvatures(
        partial(1, 0),
        partial(0, 1),
        partial(2, 0),
        partial(1, 1),
        partial(0, 2),
    )
    .expect("regular point");
    let exp = &v["expected"];
    let tol = &v["tolerance"];
    assert_close(
        &[pc.kappa1, pc.kappa2],
        &[
            exp["kappa1"].as_f64().expect("k1"),
            exp["kappa2"].as_f64().expect("k2"),
        ],
        tol,
        "kappa",
    );
    assert_close(&pc.normal, &nums(&exp["normal"]), tol, "normal");
}

// ---------------------------------------------------------------------------------------------
// sv.fair.properties

/// Spec §3: noisy cubic, 20 control points, N(0, 0.03), N = 200, moving average h = N/20 with
/// 3 passes, 300 iterations, R = 4, δ = 0.2.
#[test]
fn fair_properties() {
    assert_eq!(
        vector("sv.fair.properties")["expected"]["property_test"],
        true
    );
    let base = sine_base();
    for seed in 1..=6 {
        let noisy = perturbed(&base, 0.03, seed);
        let params = SalviParams::DEFAULT
            .with_tolerance(0.2)
            .with_samples(200)
            .with_tabu_length(4)
            .with_max_iterations(300)
            .with_window(0);
        let (faired, r) = salvi::fair_curve(&noisy, &params).expect("fair");
        let local = &r.local;
        assert_eq!(local.history.len(), local.iterations + 1);
        assert!(non_increasing(&local.history), "seed {seed}: Ê increased");
        // The reference run fell 300×; how far it falls depends on the (unpublished) base
        // curve — 7× to 1000× on the bases we tried — so only a clear drop is asserted.
        assert!(
            local.measure_after < local.measure_before / 10.0,
            "seed {seed}: {} -> {}",
            local.measure_before,
            local.measure_after
        );
        assert!(max_control_move(&faired, &noisy) <= 0.2 * (1.0 + 1e-12));
        assert!(local.max_control_displacement <= 0.2 * (1.0 + 1e-12));
        assert!(max_deviation(&faired, &noisy) <= 0.2 * (1.0 + 1e-12));
        assert!(r.max_curve_deviation <= 0.2 * (1.0 + 1e-12));
        let truth = sample_curvature(&base, &r.samples).expect("curvature");
        let before = rms_difference(&r.curvature_before, &truth);
        let after = rms_difference(&r.curvature_after, &truth);
        assert!(
            after < before,
            "seed {seed}: curvature RMS {before} -> {after}"
        );
    }
}

/// The local bookkeeping (per-sample contributions, updated only on the moved point's support)
/// agrees with Ê recomputed from scratch on the returned curve.
#[test]
fn local_updates_agree_with_a_full_evaluation() {
    let noisy = perturbed(&sine_base(), 0.03, 11);
    let (faired, r) =
        salvi::fair_curve(&noisy, &SalviParams::DEFAULT.with_tolerance(0.2)).expect("fair");
    let kappa = sample_curvature(&faired, &r.samples).expect("curvature");
    let full = target_measure(&kappa, &r.target);
    assert!((full - r.local.measure_after).abs() <= 1e-9 * full);
    let last = r.local.history.last().expect("history").measure;
    assert!((full - last).abs() <= 1e-9 * full);
    assert_close(
        &r.curvature_after,
        &kappa,
        &serde_json::json!({"abs": 1e-9, "rel": 1e-9}),
        "curvature_after",
    );
    // Each recorded move lowered its local measure, and moved one interior point.
    for m in &r.local.moves {
        assert!(m.after < m.before);
        assert!(m.index > 0 && m.index < 19);
    }
}

/// Spec §3 step 5 literally (no skipping of stalled points) still satisfies every invariant.
#[test]
fn literal_selection_keeps_the_invariants() {
    let noisy = perturbed(&sine_base(), 0.03, 3);
    let params = SalviParams::DEFAULT
        .with_tolerance(0.2)
        .with_max_iterations(300)
        .with_window(0)
        .with_skip_stalled(false);
    let (faired, r) = salvi::fair_curve(&noisy, &params).expect("fair");
    assert!(non_increasing(&r.local.history));
    assert!(r.local.measure_after < r.local.measure_before);
    assert!(max_control_move(&faired, &noisy) <= 0.2 * (1.0 + 1e-12));
}

// ---------------------------------------------------------------------------------------------
// Properties of both methods

#[test]
fn knots_degree_and_weights_are_preserved() {
    let noisy = perturbed(&sine_base(), 0.05, 5);
    let (s, _) =
        salvi::fair_curve(&noisy, &SalviParams::DEFAULT.with_max_iterations(100)).expect("salvi");
    let (e, _) = eck_hadenfeld::fair_curve(&noisy, &EckHadenfeldParams::DEFAULT).expect("eh");
    for c in [&s, &e] {
        assert_eq!(c.degree(), noisy.degree());
        assert_eq!(c.knots(), noisy.knots());
        assert_eq!(c.weights(), None);
        assert_eq!(c.control_points().len(), noisy.control_points().len());
        // End control points are fixed by default.
        assert_eq!(c.control_points()[0], noisy.control_points()[0]);
        assert_eq!(c.control_points()[19], noisy.control_points()[19]);
    }
    assert_ne!(s.control_points(), noisy.control_points());
    assert_ne!(e.control_points(), noisy.control_points());
    // A rational curve with non-uniform knots keeps its weights.
    let knots = KnotVector::new(vec![
        0.0, 0.0, 0.0, 0.0, 0.1, 0.25, 0.3, 0.5, 0.6, 0.8, 1.0, 1.0, 1.0, 1.0,
    ]);
    let w = vec![1.0, 0.9, 1.3, 1.0, 0.8, 1.1, 1.0, 1.2, 0.9, 1.0];
    let pts = perturbed(
        &cubic(10, |i| Point::new(i as f64, (i as f64 * 0.5).sin())),
        0.05,
        2,
    )
    .control_points()
    .to_vec();
    let rational = BSplineCurve::new(3, knots, pts, Some(w.clone()));
    let params = SalviParams::DEFAULT
        .with_tolerance(0.1)
        .with_max_iterations(150);
    let (s, r) = salvi::fair_curve(&rational, &params).expect("salvi rational");
    let (e, re) =
        eck_hadenfeld::fair_curve(&rational, &EckHadenfeldParams::DEFAULT.with_tolerance(0.1))
            .expect("eh rational");
    for c in [&s, &e] {
        assert_eq!(c.knots(), rational.knots());
        assert_eq!(c.weights(), Some(&w[..]));
        assert!(max_deviation(c, &rational) <= 0.1 * (1.0 + 1e-12));
    }
    assert!(non_increasing(&r.local.history) && r.local.measure_after < r.local.measure_before);
    assert!(non_increasing(&re.history) && re.measure_after < re.measure_before);
    // The rational bookkeeping agrees with a full evaluation too.
    let k = sample_curvature(&s, &r.samples).expect("curvature");
    let full = target_measure(&k, &r.target);
    assert!((full - r.local.measure_after).abs() <= 1e-9 * full);
}

#[test]
fn a_bump_is_removed() {
    // One control point of a straight line pushed out by 0.5: the curve bulges by 1/3.
    let line = cubic(20, |i| Point::new(i as f64 * 0.5, 0.0));
    let mut pts = line.control_points().to_vec();
    pts[9].y += 0.5;
    let bumped = line.with_control_points(pts).expect("bump");
    let bump = shape_distance(&bumped, &line);
    assert!(bump > 0.3);
    let (s, rs) =
        salvi::fair_curve(&bumped, &SalviParams::DEFAULT.with_tolerance(0.75)).expect("salvi");
    assert!(
        shape_distance(&s, &line) < 0.25 * bump,
        "salvi: {} (status {:?})",
        shape_distance(&s, &line),
        rs.local.status
    );
    for order in [2, 3] {
        let (e, _) = eck_hadenfeld::fair_curve(
            &bumped,
            &EckHadenfeldParams::DEFAULT
                .with_tolerance(0.75)
                .with_order(order),
        )
        .expect("eh");
        assert!(shape_distance(&e, &line) < 0.05 * bump, "eh order {order}");
    }
    // On a curved base the target curvature is the smoothed bumped curvature; salvi still
    // removes most of the bump.
    let sine = sine_base();
    let mut pts = sine.control_points().to_vec();
    pts[9].y += 0.5;
    let bumped = sine.with_control_points(pts).expect("bump");
    let bump = shape_distance(&bumped, &sine);
    let (s, _) =
        salvi::fair_curve(&bumped, &SalviParams::DEFAULT.with_tolerance(0.75)).expect("salvi");
    assert!(shape_distance(&s, &sine) < 0.3 * bump);
    // The third-order energy, which does not flatten the sine as the second does.
    let (e, _) = eck_hadenfeld::fair_curve(
        &bumped,
        &EckHadenfeldParams::DEFAULT
            .with_tolerance(0.75)
            .with_order(3),
    )
    .expect("eh");
    assert!(shape_distance(&e, &sine) < 0.3 * bump);
}

#[test]
fn eck_hadenfeld_energy_and_stopping() {
    let noisy = perturbed(&sine_base(), 0.03, 9);
    for order in [2, 3] {
        let params = EckHadenfeldParams::DEFAULT
            .with_tolerance(0.05)
            .with_order(order)
            .with_max_iterations(5000);
        let (faired, r) = eck_hadenfeld::fair_curve(&noisy, &params).expect("eh");
        assert!(non_increasing(&r.history));
        let before = eck_hadenfeld::energy(&noisy, order).expect("energy");
        let after = eck_hadenfeld::energy(&faired, order).expect("energy");
        assert!((before - r.measure_before).abs() <= 1e-12 * before);
        assert!((after - r.measure_after).abs() <= 1e-9 * before);
        assert!(after < before);
        let last = r.history.last().expect("history").measure;
        assert!((last - after).abs() <= 1e-9 * before);
        assert!(max_control_move(&faired, &noisy) <= 0.05 * (1.0 + 1e-12));
        // It stopped by its own rule, not the limit.
        assert!(r.iterations < 5000, "order {order}: {:?}", r.status);
        assert!(matches!(
            r.status,
            FairStatus::Converged | FairStatus::ToleranceLimited
        ));
    }
    // A straight line at its Greville abscissae is x(t) = t: zero energy, nothing to do.
    let knots = KnotVector::clamped_uniform(3, 8).expect("knots");
    let u = knots.as_slice().to_vec();
    let line = BSplineCurve::new(
        3,
        knots,
        (0..8)
            .map(|i| Point::new((u[i + 1] + u[i + 2] + u[i + 3]) / 3.0, 0.0))
            .collect(),
        None,
    );
    let (same, r) = eck_hadenfeld::fair_curve(&line, &EckHadenfeldParams::DEFAULT).expect("eh");
    assert_eq!(r.status, FairStatus::NoChange);
    assert_eq!(same, line);
    assert!(eck_hadenfeld::fair_curve(&line, &EckHadenfeldParams::DEFAULT.with_order(4)).is_err());
}

#[test]
fn salvi_window_rule_and_stall_rule_stop_the_run() {
    let noisy = perturbed(&sine_base(), 0.03, 4);
    let params = SalviParams::DEFAULT
        .with_tolerance(0.2)
        .with_max_iterations(100_000);
    let (_, r) = salvi::fair_curve(&noisy, &params).expect("salvi");
    assert!(r.local.iterations < 100_000);
    assert_ne!(r.local.status, FairStatus::IterationLimit);
    // With the window rule off, the run ends when no point can improve.
    let (_, r) = salvi::fair_curve(&noisy, &params.with_window(0)).expect("salvi");
    assert!(r.local.iterations < 100_000);
    assert_ne!(r.local.status, FairStatus::IterationLimit);
    // Zero iterations: nothing happens.
    let (c, r) =
        salvi::fair_curve(&noisy, &SalviParams::DEFAULT.with_max_iterations(0)).expect("salvi");
    assert_eq!(c, noisy);
    assert_eq!(r.local.status, FairStatus::NoChange);
}

#[test]
fn targets_pinned_fitted_and_given() {
    let noisy = perturbed(&sine_base(), 0.03, 8);
    let t = uniform_samples(noisy.domain(), 200);
    let kappa = sample_curvature(&noisy, &t).expect("curvature");
    for smoother in [
        Smoother::DEFAULT,
        Smoother::BSplineFit { coefficients: None },
    ] {
        let g = target_curvature(&noisy, &t, &kappa, &smoother, true).expect("target");
        assert_eq!(g[0], kappa[0]);
        assert_eq!(g[199], kappa[199]);
        let free = target_curvature(&noisy, &t, &kappa, &smoother, false).expect("target");
        // Away from the ends the pin changes nothing.
        assert_eq!(g[100], free[100]);
        // The target is smoother than the data: smaller second differences.
        let rough = |v: &[f64]| {
            v.windows(3)
                .map(|w| (w[0] - 2.0 * w[1] + w[2]).abs())
                .sum::<f64>()
        };
        assert!(rough(&free) < 0.2 * rough(&kappa), "{smoother:?}");
        let params = SalviParams::DEFAULT
            .with_tolerance(0.2)
            .with_smoother(smoother.clone())
            .with_pin_ends(true);
        let (_, r) = salvi::fair_curve(&noisy, &params).expect("salvi");
        assert!(non_increasing(&r.local.history));
        assert!(
            r.local.measure_after < 0.2 * r.local.measure_before,
            "{smoother:?}"
        );
    }
    // The true curvature as a given target ("manual editing") brings the curvature closer
    // to it than the moving average does.
    let truth = sample_curvature(&sine_base(), &t).expect("curvature");
    let params = SalviParams::DEFAULT.with_tolerance(0.2).with_samples(200);
    let (_, given) = salvi::fair_curve(
        &noisy,
        &params.clone().with_smoother(Smoother::Given(truth.clone())),
    )
    .expect("given");
    let (_, average) = salvi::fair_curve(&noisy, &params).expect("average");
    assert!(
        rms_difference(&given.curvature_after, &truth)
            < rms_difference(&average.curvature_after, &truth)
    );
    assert!(matches!(
        salvi::fair_curve(
            &noisy,
            &params.with_smoother(Smoother::Given(vec![0.0; 10]))
        ),
        Err(Error::LengthMismatch { .. })
    ));
}

#[test]
fn degenerate_and_invalid_input() {
    // Coincident first control points: zero speed at t = 0, curvature undefined.
    let mut pts = sine_base().control_points().to_vec();
    pts[1] = pts[0];
    let cusp = sine_base().with_control_points(pts).expect("curve");
    assert!(matches!(
        salvi::fair_curve(&cusp, &SalviParams::DEFAULT),
        Err(Error::Degenerate(_))
    ));
    // The energy is defined there, so eck-hadenfeld fairs it.
    assert!(eck_hadenfeld::fair_curve(&cusp, &EckHadenfeldParams::DEFAULT).is_ok());
    // Degree 1 has no curvature and no second-derivative energy.
    let poly = BSplineCurve::new(
        1,
        KnotVector::clamped_uniform(1, 5).expect("knots"),
        (0..5)
            .map(|i| Point::new(i as f64, (i % 2) as f64))
            .collect(),
        None,
    );
    assert!(salvi::fair_curve(&poly, &SalviParams::DEFAULT).is_err());
    assert!(eck_hadenfeld::fair_curve(&poly, &EckHadenfeldParams::DEFAULT).is_err());
    let base = sine_base();
    for bad in [0.0, -1.0, f64::NAN] {
        assert!(salvi::fair_curve(&base, &SalviParams::DEFAULT.with_tolerance(bad)).is_err());
        assert!(
            eck_hadenfeld::fair_curve(&base, &EckHadenfeldParams::DEFAULT.with_tolerance(bad))
                .is_err()
        );
    }
    assert!(salvi::fair_curve(&base, &SalviParams::DEFAULT.with_samples(3)).is_err());
    // Every control point at one place: no default tolerance.
    let dot = cubic(6, |_| Point::new(1.0, 1.0));
    assert!(matches!(
        eck_hadenfeld::fair_curve(&dot, &EckHadenfeldParams::DEFAULT),
        Err(Error::Degenerate(_))
    ));
    // Free ends move the end control points too.
    let noisy = perturbed(&base, 0.03, 1);
    let (c, _) = eck_hadenfeld::fair_curve(
        &noisy,
        &EckHadenfeldParams::DEFAULT
            .with_tolerance(0.1)
            .with_free_ends(true),
    )
    .expect("eh");
    assert_ne!(c.control_points()[0], noisy.control_points()[0]);
}

#[test]
fn recent_list_capacity_four_by_default() {
    assert_eq!(crate::fair::local::DEFAULT_TABU_LENGTH, 4);
    let mut l = RecentList::new(SalviParams::DEFAULT.tabu_length);
    for j in 0..6 {
        l.push(j);
    }
    assert_eq!(l.iter().collect::<Vec<_>>(), [2, 3, 4, 5]);
}

// ---------------------------------------------------------------------------------------------
// Point input through the registry

fn noisy_sine_points(n: usize, seed: u64) -> Vec<Point> {
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|i| {
            let x = i as f64 * 0.1;
            Point::new(x, x.sin() + 0.01 * rng.gaussian())
        })
        .collect()
}

#[test]
fn point_input_respects_the_tolerance() {
    let input = PointSeq::open(noisy_sine_points(60, 1)).expect("points");
    for method in ["salvi", "eck-hadenfeld"] {
        for tol in [0.002, 0.02, 0.1] {
            let opts = FairOptions::default().with_tolerance(tol);
            let out = fair::fair(method, &input, &opts).expect("fair");
            let r = &out.report;
            assert!(r.tolerance_met, "{method} {tol}");
            assert!(
                r.max_displacement <= tol,
                "{method} {tol}: {}",
                r.max_displacement
            );
            assert!(
                r.max_displacement > 0.0,
                "{method} {tol}: {:?} {:?}",
                r.status,
                r.notes
            );
            assert_eq!(out.points.len(), 60);
            assert!(non_increasing(&r.history), "{method}");
            let curve = out.curve.as_ref().expect("curve");
            assert_eq!(curve.degree(), 3);
            assert_eq!(curve.control_points().len(), 60);
            // The output points lie on the faired curve, in order.
            let (c0, c1) = curve.domain();
            // To rounding: salvi runs in the principal frame, and the curve is moved back.
            assert!(out.points[0].distance(curve.eval(c0)) < 1e-12);
            assert!(out.points[59].distance(curve.eval(c1)) < 1e-12);
        }
        // The faired points are smoother than the input: fewer curvature sign changes.
        let out =
            fair::fair(method, &input, &FairOptions::default().with_tolerance(0.02)).expect("fair");
        assert!(
            out.report.after.inflections <= out.report.before.inflections,
            "{method}: {} -> {}",
            out.report.before.inflections,
            out.report.after.inflections
        );
        // Without a tolerance: δ = 1% of the bounding-box diagonal.
        let out = fair::fair(method, &input, &FairOptions::default()).expect("fair");
        assert!(out.report.max_displacement <= 0.01 * input.scale());
        assert!(out.report.notes.iter().any(|n| n.contains("no tolerance")));
        // Fixed ends are the input's own.
        let out = fair::fair(
            method,
            &input,
            &FairOptions::default()
                .with_tolerance(0.05)
                .with_fix_ends(true),
        )
        .expect("fair");
        assert_eq!(out.points[0], input.points()[0]);
        assert_eq!(out.points[59], input.points()[59]);
    }
}

#[test]
fn point_input_least_squares_fit() {
    let input = PointSeq::open(noisy_sine_points(80, 2)).expect("points");
    for method in ["salvi", "eck-hadenfeld"] {
        let opts = FairOptions::default()
            .with_tolerance(0.05)
            .with_param("control_points", 15);
        let out = fair::fair(method, &input, &opts).expect("fair");
        assert_eq!(
            out.curve.as_ref().expect("curve").control_points().len(),
            15
        );
        assert!(out.report.tolerance_met);
        assert!(out.report.max_displacement <= 0.05);
        assert_eq!(out.report.parameters["fit"], "least_squares");
        // A tolerance below the fit's own residual cannot be met; the report says why.
        let opts = FairOptions::default()
            .with_tolerance(1e-4)
            .with_param("control_points", 6);
        let out = fair::fair(method, &input, &opts).expect("fair");
        assert!(!out.report.tolerance_met);
        assert_eq!(out.report.status, FairStatus::ToleranceExceeded);
        assert!(out.report.notes.iter().any(|n| n.contains("fit alone")));
    }
}

#[test]
fn registry_and_options() {
    let names: Vec<&str> = fair::methods().iter().map(|m| m.name()).collect();
    assert!(names.contains(&"salvi") && names.contains(&"eck-hadenfeld"));
    let input = PointSeq::open(noisy_sine_points(30, 3)).expect("points");
    let closed = PointSeq::closed(
        (0..12)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / 12.0;
                Point::new(a.cos(), a.sin())
            })
            .collect(),
    )
    .expect("closed");
    assert!(matches!(
        fair::fair("salvi", &closed, &FairOptions::default()),
        Err(Error::ClosedUnsupported { .. })
    ));
    for method in ["salvi", "eck-hadenfeld"] {
        assert!(matches!(
            fair::fair(
                method,
                &input,
                &FairOptions::default().with_param("bogus", 1)
            ),
            Err(Error::UnknownOption { .. })
        ));
        assert!(
            fair::fair(
                method,
                &input,
                &FairOptions::default().with_param("free_ends", "maybe")
            )
            .is_err()
        );
        assert!(
            fair::fair(
                method,
                &input,
                &FairOptions::default().with_param("degree", 9)
            )
            .is_err()
        );
        let out = fair::fair(
            method,
            &input,
            &FairOptions::default()
                .with_tolerance(0.01)
                .with_max_iterations(7),
        )
        .expect("fair");
        assert!(out.report.iterations <= 7);
    }
    let out = fair::fair(
        "salvi",
        &input,
        &FairOptions::default()
            .with_tolerance(0.01)
            .with_param("smoother", "bspline")
            .with_param("samples", 300)
            .with_param("pin_ends", "true"),
    )
    .expect("bspline smoother");
    assert_eq!(out.report.parameters["samples"], 300);
    assert_eq!(out.report.parameters["smoother"], "bspline");
    assert!(
        fair::fair(
            "salvi",
            &input,
            &FairOptions::default().with_param("smoother", "median")
        )
        .is_err()
    );
    let out = fair::fair(
        "eck-hadenfeld",
        &input,
        &FairOptions::default()
            .with_tolerance(0.01)
            .with_param("order", 3),
    )
    .expect("order 3");
    assert_eq!(out.report.parameters["order"], 3);
}

// ---------------------------------------------------------------------------------------------
// Property tests

fn arb_curve() -> impl Strategy<Value = (BSplineCurve, f64)> {
    (6usize..16, any::<u64>(), 0.005f64..0.3, 0.01f64..0.2).prop_map(|(n, seed, noise, delta)| {
        let base = cubic(n, |i| {
            let x = i as f64 * 0.7;
            Point::new(x, (x * 0.5).sin())
        });
        (perturbed(&base, noise, seed), delta)
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn salvi_measure_never_increases((curve, delta) in arb_curve()) {
        let params = SalviParams::DEFAULT.with_tolerance(delta).with_max_iterations(80);
        match salvi::fair_curve(&curve, &params) {
            Ok((faired, r)) => {
                prop_assert!(non_increasing(&r.local.history));
                prop_assert!(r.local.measure_after <= r.local.measure_before);
                prop_assert!(max_control_move(&faired, &curve) <= delta * (1.0 + 1e-12));
                prop_assert!(max_deviation(&faired, &curve) <= delta * (1.0 + 1e-12));
                prop_assert_eq!(faired.knots(), curve.knots());
            }
            // Heavy noise can fold the control polygon into a cusp.
            Err(e) => prop_assert!(matches!(e, Error::Degenerate(_)), "{e}"),
        }
    }

    #[test]
    fn eck_hadenfeld_energy_never_increases(
        (curve, delta) in arb_curve(),
        order in 2usize..=3,
    ) {
        let params = EckHadenfeldParams::DEFAULT
            .with_tolerance(delta)
            .with_order(order)
            .with_max_iterations(300);
        let (faired, r) = eck_hadenfeld::fair_curve(&curve, &params).expect("eh");
        prop_assert!(non_increasing(&r.history));
        let before = eck_hadenfeld::energy(&curve, order).expect("energy");
        let after = eck_hadenfeld::energy(&faired, order).expect("energy");
        prop_assert!(after <= before * (1.0 + 1e-12));
        prop_assert!(max_control_move(&faired, &curve) <= delta * (1.0 + 1e-12));
        prop_assert!(max_deviation(&faired, &curve) <= delta * (1.0 + 1e-12));
        prop_assert_eq!(faired.degree(), curve.degree());
    }
}

/// A closed curve: an ellipse with a fixed wobble and no symmetry (so that no two control
/// points are ever equally good to move), listed from point `shift`.
fn wobbly_ellipse(n: usize, shift: usize) -> Vec<Point> {
    let pts: Vec<Point> = (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            let r = 2.0 + 0.02 * (((i * 7) % 5) as f64 - 2.0) + 0.01 * (1.7 * i as f64).sin();
            Point::new(r * a.cos(), 1.3 * r * a.sin())
        })
        .collect();
    (0..n).map(|i| pts[(i + shift) % n]).collect()
}

#[test]
fn eck_hadenfeld_fairs_closed_curves_seam_free() {
    let n = 40;
    let input = PointSeq::closed(wobbly_ellipse(n, 0)).unwrap();
    for order in [2, 3] {
        let opts = FairOptions::default()
            .with_tolerance(0.1)
            .with_param("order", order);
        let out = fair::fair("eck-hadenfeld", &input, &opts).unwrap();
        let r = &out.report;
        let p = &r.parameters;
        let (before, after) = (
            p["measure_before"].as_f64().unwrap(),
            p["measure_after"].as_f64().unwrap(),
        );
        assert!(after < 0.2 * before, "order {order}: {before} → {after}");
        assert!(r.max_displacement <= 0.1);
        // Each move lowers the energy.
        assert!(r.history.windows(2).all(|w| w[1].measure <= w[0].measure));
        // The wobble's inflections go (as on an open curve, a δ below the wobble clamps every
        // move and leaves them).
        assert!(
            r.after.inflections * 4 < r.before.inflections,
            "order {order}: {} → {}",
            r.before.inflections,
            r.after.inflections
        );
        // Every control point may move, the ones at the seam included.
        assert!(r.moves.iter().any(|m| m.index == 0 || m.index == n - 1));
        // The same curve listed from another start gives the same faired curve.
        for shift in [1, 13, 39] {
            let rotated = PointSeq::closed(wobbly_ellipse(n, shift)).unwrap();
            let b = fair::fair("eck-hadenfeld", &rotated, &opts).unwrap();
            for i in 0..n {
                let d = b.points[i].distance(out.points[(i + shift) % n]);
                assert!(d < 1e-9, "order {order}, shift {shift}, point {i}: {d}");
            }
        }
    }
}

#[test]
fn eck_hadenfeld_closed_curve_limits() {
    let few = PointSeq::closed(wobbly_ellipse(7, 0)).unwrap();
    assert!(matches!(
        fair::fair("eck-hadenfeld", &few, &FairOptions::default()),
        Err(Error::TooFewPoints { needed: 8, got: 7 })
    ));
    let ok = PointSeq::closed(wobbly_ellipse(8, 0)).unwrap();
    assert!(fair::fair("eck-hadenfeld", &ok, &FairOptions::default()).is_ok());
    for (key, value) in [("degree", "2"), ("control_points", "6")] {
        assert!(matches!(
            fair::fair(
                "eck-hadenfeld",
                &ok,
                &FairOptions::default().with_param(key, value)
            ),
            Err(Error::InvalidParameter { .. })
        ));
    }
}
