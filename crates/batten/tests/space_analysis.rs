//! Space curves (issue #16): the analysis curve, curvature and torsion, and SpaceMetrics,
//! against closed forms, the planar metrics and their invariances.
#![allow(clippy::unwrap_used)]

use std::f64::consts::TAU;

use batten::analysis::{SpaceCubic, SpaceMetrics};
use batten::{FairnessMetrics, Point, PointSeq, SpaceSeq, Xyz};
use proptest::prelude::*;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
}

/// The rotation by `angle` about the unit axis through `axis`, then a shift.
fn rigid(p: &[Xyz], axis: Xyz, angle: f64, shift: Xyz) -> Vec<Xyz> {
    let l = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    let [x, y, z] = axis.map(|c| c / l);
    let (s, c) = angle.sin_cos();
    let k = 1.0 - c;
    let r = [
        [c + x * x * k, x * y * k - z * s, x * z * k + y * s],
        [y * x * k + z * s, c + y * y * k, y * z * k - x * s],
        [z * x * k - y * s, z * y * k + x * s, c + z * z * k],
    ];
    p.iter()
        .map(|v| {
            std::array::from_fn(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2] + shift[i])
        })
        .collect()
}

fn helix(a: f64, b: f64, n: usize, dt: f64) -> Vec<Xyz> {
    (0..n)
        .map(|i| {
            let t = i as f64 * dt;
            [a * t.cos(), a * t.sin(), b * t]
        })
        .collect()
}

/// A generic open space curve (no symmetry, torsion of both signs).
fn wobbly(n: usize, c: [f64; 4]) -> Vec<Xyz> {
    (0..n)
        .map(|i| {
            let t = i as f64 / (n - 1) as f64 * 4.0;
            [
                t + c[0] * (1.3 * t).sin(),
                (1.0 + c[1]) * t.sin() + 0.2 * t * t,
                c[2] * (2.1 * t).cos() + c[3] * t * t * t * 0.1,
            ]
        })
        .collect()
}

#[test]
fn helix_has_constant_curvature_and_torsion() {
    let (a, b) = (2.0, 0.7);
    let kappa = a / (a * a + b * b);
    let tau = b / (a * a + b * b);
    for sign in [1.0, -1.0] {
        let pts: Vec<Xyz> = helix(a, sign * b, 600, 0.02);
        let seq = SpaceSeq::new(pts, false).unwrap();
        let curve = SpaceCubic::of_seq(&seq).unwrap();
        let samples = curve.samples(4);
        let inner = &samples[samples.len() / 10..samples.len() * 9 / 10];
        for s in inner {
            assert!(
                rel(s.curvature, kappa) < 1e-4,
                "κ {} vs {kappa}",
                s.curvature
            );
            let t = s.torsion.unwrap();
            assert!(rel(t, sign * tau) < 1e-4, "τ {t} vs {}", sign * tau);
            // The principal normal points at the axis.
            let p = s.point;
            let towards = [-p[0] / a, -p[1] / a, 0.0];
            let d: f64 = (0..3).map(|k| s.normal[k] * towards[k]).sum();
            assert!(d > 1.0 - 1e-6);
        }
        let m = SpaceMetrics::of_seq(&seq).unwrap();
        assert_eq!(m.dimension, 3);
        assert_eq!(m.torsion_sign_changes, 0);
        assert!(rel(m.max_curvature, kappa) < 1e-3);
        assert!(rel(m.max_torsion, tau) < 1e-2);
        let len = 599.0 * 0.02 * (a * a + b * b).sqrt();
        assert!(rel(m.length, len) < 1e-7);
        assert!(rel(m.strain_energy, kappa * kappa * len) < 1e-4);
        assert!(rel(m.torsion_energy, tau * tau * len) < 1e-4);
    }
}

/// On a dense helix (10⁵ points over two turns) the rounding floor of the torsion, which
/// grows as 1/h³, stays below the true torsion.
#[test]
fn torsion_of_a_dense_helix_is_found() {
    let (a, b) = (1.0, 0.5 / (2.0 * std::f64::consts::PI));
    let n = 100_000;
    let pts = helix(a, b, n, 4.0 * std::f64::consts::PI / (n - 1) as f64);
    let m = SpaceMetrics::of_seq(&SpaceSeq::new(pts, false).unwrap()).unwrap();
    let tau = b / (a * a + b * b);
    assert!(
        rel(m.max_torsion, tau) < 0.05,
        "τ {} vs {tau}",
        m.max_torsion
    );
    assert_eq!(m.torsion_sign_changes, 0);
    let len = 4.0 * std::f64::consts::PI * (a * a + b * b).sqrt();
    assert!(
        rel(m.torsion_energy, tau * tau * len) < 0.05,
        "{}",
        m.torsion_energy
    );
}

/// Planar data without and with inflections, open and closed.
fn planar_cases() -> Vec<(Vec<Point>, bool)> {
    let ellipse = |n: usize, span: f64| -> Vec<Point> {
        (0..n)
            .map(|i| {
                let t = span * i as f64 / n as f64;
                Point::new(3.0 * t.cos(), 1.2 * t.sin())
            })
            .collect()
    };
    let spiral: Vec<Point> = (0..80)
        .map(|i| {
            let t = 0.1 * i as f64;
            let r = 1.0 + 0.3 * t;
            Point::new(r * t.cos(), r * t.sin())
        })
        .collect();
    vec![
        (ellipse(90, 0.75 * TAU), false),
        (ellipse(90, TAU), true),
        (spiral, false),
    ]
}

fn assert_matches_planar(m: &SpaceMetrics, p: &FairnessMetrics, what: &str) {
    assert_eq!(m.curvature_extrema, p.curvature_extrema, "{what}");
    assert!(rel(m.max_curvature, p.max_curvature) < 1e-9, "{what}");
    assert!(rel(m.strain_energy, p.strain_energy) < 1e-9, "{what}");
    assert!(rel(m.variation_energy, p.variation_energy) < 1e-9, "{what}");
    assert!(rel(m.length, p.length) < 1e-9, "{what}");
    assert_eq!(m.torsion_sign_changes, 0, "{what}");
    assert_eq!(m.torsion_extrema, 0, "{what}");
    assert_eq!(m.max_torsion, 0.0, "{what}");
    assert_eq!(m.torsion_energy, 0.0, "{what}");
}

#[test]
fn a_planar_curve_in_space_measures_as_in_the_plane() {
    for (k, (pts, closed)) in planar_cases().into_iter().enumerate() {
        let planar = FairnessMetrics::of_seq(&PointSeq::new(pts.clone(), closed).unwrap()).unwrap();
        assert_eq!(planar.inflections, 0);
        let flat: Vec<Xyz> = pts.iter().map(|p| [p.x, p.y, 0.0]).collect();
        let m = SpaceMetrics::of_seq(&SpaceSeq::new(flat.clone(), closed).unwrap()).unwrap();
        assert_matches_planar(&m, &planar, &format!("case {k}, z = 0"));
        for (axis, angle) in [([1.0, 2.0, 3.0], 0.7), ([-0.3, 1.0, 0.1], 2.9)] {
            let moved = rigid(&flat, axis, angle, [5.0, -3.0, 11.0]);
            let m = SpaceMetrics::of_seq(&SpaceSeq::new(moved, closed).unwrap()).unwrap();
            assert_matches_planar(&m, &planar, &format!("case {k}, rotated {angle}"));
        }
    }
}

#[test]
fn a_planar_inflection_is_a_minimum_of_unsigned_curvature() {
    // y = x³ − x inflects once: κ ≥ 0 in space has one more extremum there.
    let pts: Vec<Point> = (0..41)
        .map(|i| {
            let x = -1.5 + 0.075 * i as f64;
            Point::new(x, x * x * x - x)
        })
        .collect();
    let planar = FairnessMetrics::of_seq(&PointSeq::open(pts.clone()).unwrap()).unwrap();
    assert_eq!(planar.inflections, 1);
    let flat: Vec<Xyz> = pts.iter().map(|p| [p.x, p.y, 0.0]).collect();
    for pts in [flat.clone(), rigid(&flat, [0.2, 1.0, -0.5], 1.1, [0.0; 3])] {
        let m = SpaceMetrics::of_seq(&SpaceSeq::new(pts, false).unwrap()).unwrap();
        assert_eq!(m.curvature_extrema, planar.curvature_extrema + 1);
        assert_eq!(m.torsion_sign_changes, 0);
        assert_eq!(m.max_torsion, 0.0);
        assert!(rel(m.strain_energy, planar.strain_energy) < 1e-9);
        assert!(rel(m.variation_energy, planar.variation_energy) < 1e-9);
    }
}

/// τ = −(dB/ds)·N with the binormal B differenced numerically.
#[test]
fn torsion_matches_finite_differences_of_the_frame() {
    let seq = SpaceSeq::new(wobbly(60, [0.3, 0.2, 0.5, 0.4]), false).unwrap();
    let curve = SpaceCubic::of_seq(&seq).unwrap();
    let binormal = |i: usize, t: f64| -> Xyz {
        let d = curve.derivatives_in_span(i, t);
        let c = cross(d.d1, d.d2);
        let l = norm(c);
        c.map(|v| v / l)
    };
    let mut checked = 0;
    for i in 1..curve.num_spans() - 1 {
        let (t0, t1) = (curve.knots()[i], curve.knots()[i + 1]);
        for f in [0.25, 0.5, 0.75] {
            let t = t0 + f * (t1 - t0);
            let d = curve.derivatives_in_span(i, t);
            let Some(tau) = d.torsion() else { continue };
            let n = d.principal_normal().unwrap();
            let e = 1e-5 * (t1 - t0);
            let (bp, bm) = (binormal(i, t + e), binormal(i, t - e));
            let speed = norm(d.d1);
            let db: Xyz = std::array::from_fn(|k| (bp[k] - bm[k]) / (2.0 * e * speed));
            let fd = -(0..3).map(|k| db[k] * n[k]).sum::<f64>();
            assert!(
                (fd - tau).abs() < 1e-6 * (1.0 + tau.abs()),
                "span {i}: τ {tau} vs finite differences {fd}"
            );
            // The Frenet–Serret formula dT/ds = κN, by differences too.
            let unit = |t: f64| {
                let d1 = curve.derivatives_in_span(i, t).d1;
                let l = norm(d1);
                d1.map(|v| v / l)
            };
            let (tp, tm) = (unit(t + e), unit(t - e));
            let kappa = d.curvature();
            for k in 0..3 {
                let dt = (tp[k] - tm[k]) / (2.0 * e * speed);
                assert!((dt - kappa * n[k]).abs() < 1e-6 * (1.0 + kappa));
            }
            checked += 1;
        }
    }
    assert!(checked > 100);
    let m = SpaceMetrics::of_seq(&seq).unwrap();
    assert!(m.torsion_sign_changes > 0 && m.max_torsion > 0.0);
}

fn cross(a: Xyz, b: Xyz) -> Xyz {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: Xyz) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

#[test]
fn a_tilted_circle_is_planar_with_constant_curvature() {
    let r = 2.5;
    let flat: Vec<Xyz> = (0..200)
        .map(|i| {
            let a = TAU * i as f64 / 200.0;
            [r * a.cos(), r * a.sin(), 0.0]
        })
        .collect();
    let pts = rigid(&flat, [1.0, 1.0, 0.3], 0.9, [1.0, 2.0, 3.0]);
    let m = SpaceMetrics::of_seq(&SpaceSeq::new(pts, true).unwrap()).unwrap();
    assert!(m.closed);
    assert!(rel(m.max_curvature, 1.0 / r) < 1e-4, "{m:?}");
    assert!(rel(m.length, TAU * r) < 1e-8, "{m:?}");
    assert!(rel(m.strain_energy, TAU / r) < 1e-4, "{m:?}");
    assert_eq!(m.torsion_sign_changes, 0);
    assert_eq!(m.max_torsion, 0.0);
}

#[test]
fn a_torus_knot_is_closed_and_twisted() {
    // The (2, 3) torus knot (trefoil) on the torus of radii 2 and 0.8.
    let n = 400;
    let pts: Vec<Xyz> = (0..n)
        .map(|i| {
            let u = TAU * i as f64 / n as f64;
            let rr = 2.0 + 0.8 * (3.0 * u).cos();
            [
                rr * (2.0 * u).cos(),
                rr * (2.0 * u).sin(),
                0.8 * (3.0 * u).sin(),
            ]
        })
        .collect();
    let seq = SpaceSeq::new(pts.clone(), true).unwrap();
    let m = SpaceMetrics::of_seq(&seq).unwrap();
    // Length by a fine polygon.
    let fine = 200_000;
    let at = |u: f64| {
        let rr = 2.0 + 0.8 * (3.0 * u).cos();
        [
            rr * (2.0 * u).cos(),
            rr * (2.0 * u).sin(),
            0.8 * (3.0 * u).sin(),
        ]
    };
    let poly: f64 = (0..fine)
        .map(|i| {
            let (a, b) = (
                at(TAU * i as f64 / fine as f64),
                at(TAU * (i + 1) as f64 / fine as f64),
            );
            norm([b[0] - a[0], b[1] - a[1], b[2] - a[2]])
        })
        .sum();
    assert!(rel(m.length, poly) < 1e-6, "{} vs {poly}", m.length);
    // The threefold symmetry: extrema and sign changes come in threes, even (cyclic).
    assert_eq!(m.curvature_extrema % 6, 0, "{m:?}");
    assert_eq!(m.torsion_extrema % 6, 0, "{m:?}");
    assert_eq!(m.torsion_sign_changes % 2, 0, "{m:?}");
    assert!(m.max_torsion > 0.0 && m.torsion_energy > 0.0);
    // Rotating the start point round the loop changes nothing but rounding.
    let mut shifted = pts;
    shifted.rotate_left(37);
    let s = SpaceMetrics::of_seq(&SpaceSeq::new(shifted, true).unwrap()).unwrap();
    assert_eq!(s.curvature_extrema, m.curvature_extrema);
    assert_eq!(s.torsion_extrema, m.torsion_extrema);
    assert!(rel(s.length, m.length) < 1e-12);
}

#[test]
fn samples_run_along_the_curve() {
    let seq = SpaceSeq::new(wobbly(30, [0.1, 0.0, 0.3, 0.2]), false).unwrap();
    let curve = SpaceCubic::of_seq(&seq).unwrap();
    let s = curve.samples(3);
    assert_eq!(s.len(), 29 * 3 + 1);
    assert!(s.windows(2).all(|w| w[1].s >= w[0].s));
    let m = SpaceMetrics::of_seq(&seq).unwrap();
    assert!(rel(s[s.len() - 1].s, m.length) < 1e-12);
    assert_eq!(s[0].point, seq.points()[0]);
    for x in &s {
        let l = norm(x.normal);
        assert!((l - 1.0).abs() < 1e-12 || (l == 0.0 && x.curvature == 0.0));
    }
    // A straight line: κ = 0, no torsion, no normal.
    let line: Vec<Xyz> = (0..6)
        .map(|i| [i as f64, 2.0 * i as f64, -(i as f64)])
        .collect();
    let seq = SpaceSeq::new(line, false).unwrap();
    let m = SpaceMetrics::of_seq(&seq).unwrap();
    assert_eq!((m.curvature_extrema, m.torsion_sign_changes), (0, 0));
    assert!(m.max_curvature < 1e-12 && m.max_torsion == 0.0);
    for x in SpaceCubic::of_seq(&seq).unwrap().samples(2) {
        assert!(x.torsion.is_none() || x.curvature < 1e-12);
    }
}

fn assert_same_counts(a: &SpaceMetrics, b: &SpaceMetrics) {
    assert_eq!(a.curvature_extrema, b.curvature_extrema);
    assert_eq!(a.torsion_sign_changes, b.torsion_sign_changes);
    assert_eq!(a.torsion_extrema, b.torsion_extrema);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// Rigid motions change nothing but rounding.
    #[test]
    fn rigid_motions_do_not_change_the_metrics(
        c0 in 0.0..0.5, c1 in -0.3..0.3, c2 in 0.1..0.8, c3 in -0.5..0.5,
        ax in -1.0..1.0, ay in -1.0..1.0, az in 0.1..1.0, angle in -3.0..3.0,
        shift in prop::array::uniform3(-100.0..100.0),
        closed in any::<bool>(),
    ) {
        let pts = wobbly(40, [c0, c1, c2, c3]);
        let a = SpaceMetrics::of_seq(&SpaceSeq::new(pts.clone(), closed).unwrap()).unwrap();
        let moved = rigid(&pts, [ax, ay, az], angle, shift);
        let b = SpaceMetrics::of_seq(&SpaceSeq::new(moved, closed).unwrap()).unwrap();
        assert_same_counts(&a, &b);
        for (x, y) in [
            (a.max_curvature, b.max_curvature),
            (a.max_torsion, b.max_torsion),
            (a.strain_energy, b.strain_energy),
            (a.variation_energy, b.variation_energy),
            (a.torsion_energy, b.torsion_energy),
            (a.length, b.length),
        ] {
            prop_assert!(rel(y, x) < 1e-8, "{x} vs {y}");
        }
    }

    /// Scaling by s: κ and τ by 1/s, length by s, energies by their powers, counts unchanged.
    #[test]
    fn scaling_scales_the_metrics(
        c0 in 0.0..0.5, c2 in 0.1..0.8, c3 in -0.5..0.5,
        log_s in -6.0..6.0, closed in any::<bool>(),
    ) {
        let s = 10f64.powf(log_s);
        let pts = wobbly(40, [c0, 0.1, c2, c3]);
        let a = SpaceMetrics::of_seq(&SpaceSeq::new(pts.clone(), closed).unwrap()).unwrap();
        let scaled: Vec<Xyz> = pts.iter().map(|p| p.map(|c| c * s)).collect();
        let b = SpaceMetrics::of_seq(&SpaceSeq::new(scaled, closed).unwrap()).unwrap();
        assert_same_counts(&a, &b);
        for (x, y, power) in [
            (a.max_curvature, b.max_curvature, -1),
            (a.max_torsion, b.max_torsion, -1),
            (a.strain_energy, b.strain_energy, -1),
            (a.variation_energy, b.variation_energy, -3),
            (a.torsion_energy, b.torsion_energy, -1),
            (a.length, b.length, 1),
        ] {
            prop_assert!(rel(y, x * s.powi(power)) < 1e-9, "{x} vs {y} at scale {s}");
        }
    }
}
