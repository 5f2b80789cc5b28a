//! Fairing space curves (`fair_space`, issue #16): `band` and `mst` keep the hard tolerance in
//! 3-D distance on noisy helices and torus knots, open and closed, with free and held ends;
//! they follow rigid motion, scale and translation; a planar curve in the plane `z = 0` (or
//! any other plane) gives the planar result; the planar methods are refused; extreme
//! coordinate scales work.
#![allow(clippy::unwrap_used)]

use batten::error::Error;
use batten::fair::{self, EndFix, FairStatus, SPACE_METHODS, ToleranceSource, fair_space};
use batten::geom::{SpaceSeq, Xyz};
use batten::{FairOptions, Point, PointSeq};
use proptest::prelude::*;

mod common;
use common::{Noise, Rng, jitter};

/// The true curve: an open helix of two turns, or a closed (2, 3) torus knot.
fn truth(n: usize, closed: bool) -> Vec<Xyz> {
    (0..n)
        .map(|i| {
            if closed {
                let t = std::f64::consts::TAU * i as f64 / n as f64;
                let r = 2.0 + (3.0 * t).cos();
                [r * (2.0 * t).cos(), r * (2.0 * t).sin(), (3.0 * t).sin()]
            } else {
                let t = 4.0 * std::f64::consts::PI * i as f64 / (n - 1) as f64;
                [t.cos(), t.sin(), 0.15 * t]
            }
        })
        .collect()
}

/// The true curve with Gaussian noise of `sigma` per coordinate.
fn noisy(n: usize, sigma: f64, seed: u64, closed: bool) -> (SpaceSeq, Vec<Xyz>) {
    let exact = truth(n, closed);
    let mut rng = Rng::new(seed);
    let pts = exact
        .iter()
        .map(|p| p.map(|c| c + rng.sample(Noise::Gaussian(sigma))))
        .collect();
    (SpaceSeq::new(pts, closed).expect("valid points"), exact)
}

/// 3-D distance by `hypot`, the contract's measure.
fn dist(a: &Xyz, b: &Xyz) -> f64 {
    (a[0] - b[0]).abs().hypot(a[1] - b[1]).hypot(a[2] - b[2])
}

fn max_move(a: &[Xyz], b: &[Xyz]) -> f64 {
    a.iter().zip(b).map(|(p, q)| dist(p, q)).fold(0.0, f64::max)
}

fn rms(a: &[Xyz], b: &[Xyz]) -> f64 {
    (a.iter()
        .zip(b)
        .map(|(p, q)| dist(p, q).powi(2))
        .sum::<f64>()
        / a.len() as f64)
        .sqrt()
}

/// The rotation about the unit axis of `(ax, ay, az)` by `angle` (Rodrigues), as a matrix.
fn rotation(axis: Xyz, angle: f64) -> [Xyz; 3] {
    let len = dist(&axis, &[0.0; 3]);
    let [x, y, z] = axis.map(|c| c / len);
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ]
}

fn apply(m: &[Xyz; 3], scale: f64, shift: Xyz, p: &Xyz) -> Xyz {
    std::array::from_fn(|r| scale * (m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2]) + shift[r])
}

fn held_count(fix: EndFix) -> usize {
    match fix {
        EndFix::Free => 0,
        EndFix::Position => 1,
        EndFix::Tangent => 2,
        _ => 3,
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    /// The promise in 3-D: no point moves farther than the tolerance (3-D distance), for
    /// `band` and `mst`, open and closed, free and held ends; held end points are kept bit
    /// for bit.
    #[test]
    fn never_exceeds_the_tolerance(
        n in 16usize..200,
        sigma in 0.0f64..0.05,
        tol in 1e-4f64..0.3,
        seed in any::<u64>(),
        closed in any::<bool>(),
        mst in any::<bool>(),
        fix in prop_oneof![
            Just(EndFix::Free),
            Just(EndFix::Position),
            Just(EndFix::Tangent),
            Just(EndFix::Curvature)
        ],
    ) {
        let (input, _) = noisy(n, sigma, seed, closed);
        let method = if mst { "mst" } else { "band" };
        let options = FairOptions::default().with_tolerance(tol).with_end_fix(fix);
        let out = fair_space(method, &input, &options).unwrap();
        prop_assert!(out.report.max_displacement <= tol);
        prop_assert!(max_move(input.points(), &out.points) <= tol);
        prop_assert!(out.report.tolerance_met);
        prop_assert_eq!(out.report.dimension, 3);
        if !closed {
            let h = held_count(fix);
            let (a, b) = (input.points(), &out.points);
            for i in (0..h).chain(n - h..n) {
                prop_assert_eq!(a[i], b[i], "held point {} moved", i);
            }
        }
    }

    /// Rotating, scaling and translating the input does the same to the result (band with a
    /// tolerance scaled with the data; mst by cross-validation, which is scale free).
    #[test]
    fn follows_rigid_motion_and_scale(
        axis in (-1.0f64..1.0, -1.0f64..1.0, 0.1f64..1.0),
        angle in 0.0f64..std::f64::consts::TAU,
        shift in -1e3f64..1e3,
        scale in prop_oneof![Just(1e-3), Just(1.0), Just(37.5), Just(1e4)],
        seed in any::<u64>(),
        closed in any::<bool>(),
    ) {
        let (input, _) = noisy(90, 0.02, seed, closed);
        let m = rotation([axis.0, axis.1, axis.2], angle);
        let shift3 = [shift, -0.5 * shift, 0.25 * shift];
        let map = |p: &Xyz| apply(&m, scale, shift3, p);
        let moved = SpaceSeq::new(input.points().iter().map(map).collect(), closed).unwrap();
        let tol = 0.05;
        for (method, base_opts, moved_opts) in [
            (
                "band",
                FairOptions::default().with_tolerance(tol),
                FairOptions::default().with_tolerance(scale * tol),
            ),
            ("mst", FairOptions::default(), FairOptions::default()),
        ] {
            let base = fair_space(method, &input, &base_opts).unwrap();
            let out = fair_space(method, &moved, &moved_opts).unwrap();
            let expected: Vec<Xyz> = base.points.iter().map(map).collect();
            let off = max_move(&expected, &out.points);
            // band's stopping rule bounds the relative duality gap (1e-9) and the dual
            // residual (1e-9 of its terms), which fix every pass's energy, not the points:
            // along the energy's flattest direction (points sliding along the curve, weighed
            // by ε of the jerk, the speed term and the debiasing stage's small data weight)
            // that residual leaves them free to about 1e-4·D, and each pass takes its metric
            // from the last. Over 64 random motions and CI's two regression seeds the points
            // agreed to 1.3e-11·D (median) and 2.8e-9·D (90th percentile), at most 7.1e-5·D
            // (2.5e-4·D without the speed term).
            prop_assert!(
                off <= 1e-3 * scale * tol,
                "{method}: off by {off:e} at scale {scale}"
            );
            // band's energies are in units of the tolerance and the spacing: scale free. A
            // pass before the last stops at a duality gap of 1e-5 of max(E, 1) (its result
            // only gives the next pass its reference), so its energy is compared to that.
            // The last pass and the debiasing stage stop at 1e-9, but their energies are
            // those of metrics taken from the passes before, known to that gap: over 1000
            // random motions they agreed to 3.6e-6 (relative), against 1e-8 when every pass
            // stopped at 1e-9.
            let band_energies = if method == "band" { base.report.history.len() } else { 0 };
            let last_pass = band_energies.saturating_sub(2);
            for (k, (a, b)) in base.report.history.iter().zip(&out.report.history).take(band_energies).enumerate() {
                let diff = (a.measure - b.measure).abs();
                if k < last_pass {
                    prop_assert!(diff <= 2e-5 * a.measure.abs().max(1.0), "{method}: pass {k} energy {} against {}", a.measure, b.measure);
                } else {
                    let rel = diff / a.measure.abs().max(f64::MIN_POSITIVE);
                    prop_assert!(rel <= 1e-5, "{method}: stage {k} energy {} against {}", a.measure, b.measure);
                }
            }
        }
    }
}

/// A noisy planar curve: `sin x` on [0, 6], or a closed three-lobed loop.
fn planar(n: usize, closed: bool, seed: u64) -> PointSeq {
    let exact = if closed {
        common::lobed_loop(n)
    } else {
        common::sine(n, 6.0)
    };
    PointSeq::new(jitter(&exact, Noise::Gaussian(0.01), seed), closed).unwrap()
}

/// A planar curve at `z = 0` faired in 3-D gives the planar method's x and y (`mst` within
/// 1e-9 of the tolerance, `band` within 1e-6: its solver's stopping rule) and z ≡ 0: the 3-D
/// path is the tested planar one on such input.
#[test]
fn a_planar_curve_at_z_zero_gives_the_planar_result() {
    for closed in [false, true] {
        let input = planar(120, closed, 3);
        let tol = 0.03;
        for method in ["band", "mst"] {
            for options in [
                FairOptions::default().with_tolerance(tol),
                FairOptions::default()
                    .with_tolerance(tol)
                    .with_end_fix(EndFix::Tangent),
            ] {
                let flat: Vec<Xyz> = input.points().iter().map(|p| [p.x, p.y, 0.0]).collect();
                let space = SpaceSeq::new(flat, closed).unwrap();
                let plane = fair::fair(method, &input, &options).unwrap();
                let out = fair_space(method, &space, &options).unwrap();
                let off = plane
                    .points
                    .iter()
                    .zip(&out.points)
                    .map(|(p, q)| (p.x - q[0]).abs().hypot(p.y - q[1]))
                    .fold(0.0, f64::max);
                // mst: the same arithmetic. band: the same problem, but the 3-D interior point
                // iterates differ within its stopping rule (2e-8 of the tolerance seen).
                let bound = if method == "mst" { 1e-9 } else { 1e-6 };
                assert!(
                    off <= bound * tol,
                    "{method} closed {closed}: off by {off:e} {:?} {:?} / {:?}",
                    plane.report.status,
                    plane.report.notes,
                    out.report.notes
                );
                assert!(out.points.iter().all(|q| q[2] == 0.0), "{method}: z moved");
                assert_eq!(out.report.status, plane.report.status, "{method}");
                assert_eq!(out.report.noise_sigma, plane.report.noise_sigma);
            }
        }
    }
}

/// A planar curve in a tilted plane, moved away from the origin, gives the planar result
/// moved the same way.
#[test]
fn a_rotated_planar_curve_gives_the_rotated_planar_result() {
    let m = rotation([0.3, -0.5, 0.8], 1.1);
    let shift = [2.0, -1.0, 0.5];
    for closed in [false, true] {
        let input = planar(100, closed, 9);
        let tol = 0.03;
        for method in ["band", "mst"] {
            let options = FairOptions::default().with_tolerance(tol);
            let plane = fair::fair(method, &input, &options).unwrap();
            let lift = |p: &Point| apply(&m, 1.0, shift, &[p.x, p.y, 0.0]);
            let space = SpaceSeq::new(input.points().iter().map(lift).collect(), closed).unwrap();
            let out = fair_space(method, &space, &options).unwrap();
            let expected: Vec<Xyz> = plane.points.iter().map(lift).collect();
            let off = max_move(&expected, &out.points);
            assert!(
                off <= 1e-6 * tol,
                "{method} closed {closed}: off by {off:e}"
            );
            assert!(out.report.max_displacement <= tol);
        }
    }
}

#[test]
fn planar_methods_are_refused_in_one_line() {
    let (input, _) = noisy(40, 0.01, 1, false);
    for m in fair::methods() {
        let r = fair_space(m.name(), &input, &FairOptions::default());
        if SPACE_METHODS.contains(&m.name()) {
            assert!(r.is_ok(), "{}: {:?}", m.name(), r.err());
        } else {
            let err = r.expect_err("refused");
            assert!(
                matches!(err, Error::PlanarOnly { .. }),
                "{}: {err}",
                m.name()
            );
            let text = err.to_string();
            assert!(!text.contains('\n') && text.contains(m.name()), "{text}");
        }
    }
    for name in ["han", "kjellander"] {
        assert!(matches!(
            fair::check_space_method(name),
            Err(Error::PlanarOnly { .. })
        ));
    }
    assert!(matches!(
        fair_space("nope", &input, &FairOptions::default()),
        Err(Error::UnknownMethod { .. })
    ));
}

/// A noisy helix (σ = 0.02 per coordinate, 400 points) faired by `band` with a given
/// tolerance ends much closer to the true helix than the noisy input; without a tolerance,
/// band takes k·σ̂ with σ̂ near the true σ.
#[test]
fn band_brings_a_noisy_helix_close_to_the_truth() {
    let sigma = 0.02;
    let (input, exact) = noisy(400, sigma, 5, false);
    let before = rms(input.points(), &exact);
    let out = fair_space("band", &input, &FairOptions::default().with_tolerance(0.1)).unwrap();
    let after = rms(&out.points, &exact);
    assert!(after < 0.4 * before, "RMS {before:e} → {after:e}");
    assert!(out.report.max_displacement <= 0.1);
    let auto = fair_space("band", &input, &FairOptions::default()).unwrap();
    assert_eq!(auto.report.tolerance_source, Some(ToleranceSource::Auto));
    let est = auto.report.noise_sigma.unwrap_or(0.0);
    assert!((est / sigma - 1.0).abs() < 0.15, "σ̂ = {est}");
    assert!(auto.report.tolerance_met);
    assert!(rms(&auto.points, &exact) < 0.5 * before);
    // mst within the same tolerance also moves towards the truth.
    let m = fair_space("mst", &input, &FairOptions::default().with_tolerance(0.1)).unwrap();
    assert!(rms(&m.points, &exact) < before);
}

/// An exact helix with `--tolerance auto`: no noise, nothing moves, a note says why.
#[test]
fn an_exact_helix_has_no_noise_for_the_automatic_tolerance() {
    let exact = SpaceSeq::new(truth(400, false), false).unwrap();
    let out = fair_space("band", &exact, &FairOptions::default()).unwrap();
    assert_eq!(
        out.report.status,
        FairStatus::NoChange,
        "{:?}",
        out.report.notes
    );
    assert!(
        out.report
            .notes
            .iter()
            .any(|n| n.contains("found no noise"))
    );
    assert_eq!(out.points.as_slice(), exact.points());
}

/// Coordinates ×1e-150 and ×1e150: the run works (on coordinates divided by a power of two)
/// and gives the unscaled result scaled.
#[test]
fn extreme_scales_work() {
    for closed in [false, true] {
        let (input, _) = noisy(80, 0.02, 11, closed);
        let tol = 0.05;
        for method in ["band", "mst"] {
            let base =
                fair_space(method, &input, &FairOptions::default().with_tolerance(tol)).unwrap();
            for f in [1e-150, 1e150] {
                let scaled: Vec<Xyz> = input.points().iter().map(|p| p.map(|c| c * f)).collect();
                let seq = SpaceSeq::new(scaled, closed).unwrap();
                let out = fair_space(
                    method,
                    &seq,
                    &FairOptions::default().with_tolerance(f * tol),
                )
                .unwrap();
                assert!(out.report.tolerance_met, "{method} ×{f:e}");
                assert!(out.report.max_displacement <= f * tol);
                let expected: Vec<Xyz> = base.points.iter().map(|p| p.map(|c| c * f)).collect();
                let off = max_move(&expected, &out.points);
                assert!(off <= 1e-6 * f * tol, "{method} ×{f:e}: off by {off:e}");
                assert!(
                    out.report
                        .noise_sigma
                        .is_some_and(|s| s.is_finite() && s > 0.0)
                );
            }
        }
    }
}

#[test]
fn every_point_held_returns_the_input() {
    let pts = truth(6, false);
    let input = SpaceSeq::new(pts.clone(), false).unwrap();
    for method in SPACE_METHODS {
        let out = fair_space(
            method,
            &input,
            &FairOptions::default()
                .with_tolerance(0.1)
                .with_end_fix(EndFix::Curvature),
        )
        .unwrap();
        assert_eq!(out.points, pts);
        assert_eq!(out.report.status, FairStatus::NoChange);
        assert!(out.report.moved_points.is_empty());
    }
}

#[test]
fn bad_options_are_clear_errors() {
    let (input, _) = noisy(40, 0.01, 2, true);
    let err = fair_space("mst", &input, &FairOptions::default().with_param("q", 1))
        .expect_err("unknown key");
    assert!(matches!(err, Error::UnknownOption { .. }), "{err}");
    let err = fair_space("mst", &input, &FairOptions::default().with_param("p", 0))
        .expect_err("p = 0 on a closed curve");
    assert!(err.to_string().contains("closed"), "{err}");
    let small = SpaceSeq::new(truth(6, true), true).unwrap();
    let err = fair_space("band", &small, &FairOptions::default().with_tolerance(0.1))
        .expect_err("too few points");
    assert!(err.to_string().contains("at least 8 points"), "{err}");
}

/// A 10⁵-point noisy helix with `band` and the automatic tolerance: the figure for the
/// report (`cargo test --release -p batten --test space_fair -- --ignored --nocapture`).
#[test]
#[ignore = "timing, 10⁵ points"]
fn a_dense_noisy_helix_timing() {
    let (input, exact) = noisy(100_000, 0.005, 17, false);
    let start = std::time::Instant::now();
    let out = fair_space("band", &input, &FairOptions::default()).unwrap();
    println!(
        "band, 1e5-point helix: {:.2} s, status {:?}, tolerance {:?}, σ̂ {:?}, max displacement \
         {:e}, RMS to truth {:e} → {:e}",
        start.elapsed().as_secs_f64(),
        out.report.status,
        out.report.tolerance,
        out.report.noise_sigma,
        out.report.max_displacement,
        rms(input.points(), &exact),
        rms(&out.points, &exact)
    );
    assert!(out.report.tolerance_met);
}

/// Once the gap met the stopping rule, a corrector that still aimed it at zero made the Newton
/// matrix singular at the band's edge (λ/σ without bound), and the dual residual then stalled
/// just above its bound: this turned helix (CI's case) ran two of its three passes to the
/// iteration limit, 416 solver iterations against 50 unturned. The corrector now keeps the gap
/// at a tenth of the rule's: 87.
#[test]
fn a_turned_helix_does_not_run_to_the_iteration_limit() {
    let (input, _) = noisy(90, 0.02, 3973364763628303186, false);
    let m = rotation([0.0, 0.0, 0.1], 1.6463812537942832);
    let turned = SpaceSeq::new(
        input
            .points()
            .iter()
            .map(|p| apply(&m, 1.0, [0.0; 3], p))
            .collect(),
        false,
    )
    .unwrap();
    let out = fair_space(
        "band",
        &turned,
        &FairOptions::default().with_tolerance(0.05),
    )
    .unwrap();
    assert_eq!(out.report.status, FairStatus::Converged);
    let solver = out.report.solver.unwrap();
    assert!(
        solver.iterations < 150,
        "{} solver iterations",
        solver.iterations
    );
}
