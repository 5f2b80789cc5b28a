//! Correctness tests of the foundation: geometry, parametrisation, the parametric cubic, B-spline
//! and NURBS evaluation and operations, curvature, arc length and the fairness measures.
//!
//! - the spec's vectors (`tests/data/test-vectors.json`, format in docs/algorithms/README.md §7)
//!   that concern the foundation: `common.*`, `sv.curvature_samples`, `sv.support_counts`,
//!   `cali.interpolation_and_gfi.strophoid31_clean`, `ky.basis.*`;
//! - closed forms: circle curvature 1/R (exact NURBS circle and interpolants of 400 points),
//!   the single inflection of y = x³ − x;
//! - properties (proptest): knot insertion leaves the curve unchanged and removal undoes it,
//!   curvature and the fairness metrics are invariant under rigid motion;
//! - derivatives against central finite differences;
//! - least-squares approximation; validation of knot vectors and curves (also through serde);
//! - parity with scipy's `CubicSpline` (fixture made by `tests/fixtures/make_scipy_cubic_fixture.py`);
//! - degenerate input: collinear data, spans of very different lengths, nearly coincident
//!   points.
#![allow(clippy::unwrap_used)]

use std::f64::consts::{FRAC_1_SQRT_2, PI, TAU};
use std::sync::OnceLock;

use batten::analysis::{curvature_at, fairness_indicators, signed_curvature};
use batten::curve::{Curve, CurveDeriv, Derivatives, Piecewise};
use batten::spline::{
    BSplineCurve, EndCondition, KnotRef, KnotVector, MAX_ORDER, ParametricCubic, Parametrization,
    RemovalRule, parameters,
};
use batten::{Error, FairnessMetrics, Point, PointSeq, Rigid, Vec2};
use proptest::prelude::*;
use serde_json::Value;

// ---------------------------------------------------------------------------------------------
// Helpers

fn vectors() -> &'static Value {
    static V: OnceLock<Value> = OnceLock::new();
    V.get_or_init(|| {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/test-vectors.json");
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
    })
}

/// The vector with the given id, from whichever section holds it.
fn vector(id: &str) -> &'static Value {
    vectors()
        .as_object()
        .unwrap()
        .values()
        .filter_map(Value::as_array)
        .flatten()
        .find(|v| v["id"] == id)
        .unwrap_or_else(|| panic!("no vector {id}"))
}

#[derive(Clone, Copy, Debug)]
struct Tol {
    abs: f64,
    rel: f64,
}

fn tol_of(v: &Value) -> Tol {
    Tol {
        abs: v["tolerance"]["abs"].as_f64().unwrap(),
        rel: v["tolerance"]["rel"].as_f64().unwrap(),
    }
}

/// Spec §7: `|got − exp| ≤ abs + rel·|exp|`.
fn check(got: f64, exp: f64, tol: Tol, what: &str) {
    assert!(
        (got - exp).abs() <= tol.abs + tol.rel * exp.abs(),
        "{what}: got {got:e}, expected {exp:e} (diff {:e})",
        (got - exp).abs()
    );
}

fn check_all(got: &[f64], exp: &[f64], tol: Tol, what: &str) {
    assert_eq!(got.len(), exp.len(), "{what}: length");
    for (i, (g, e)) in got.iter().zip(exp).enumerate() {
        check(*g, *e, tol, &format!("{what}[{i}]"));
    }
}

fn f64s(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn points(v: &Value) -> Vec<Point> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|p| Point::new(p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
        .collect()
}

/// Largest |v| of a derivative-like list.
fn max_len(v: &[Vec2]) -> f64 {
    v.iter().fold(0.0_f64, |m, x| m.max(x.length()))
}

/// Points on a circle of radius `r` about `c`, `n` of them over the angle range `[a0, a1)`.
fn arc(c: Point, r: f64, a0: f64, a1: f64, n: usize) -> Vec<Point> {
    (0..n)
        .map(|i| {
            let a = a0 + (a1 - a0) * i as f64 / n as f64;
            c + Vec2::from_angle(a) * r
        })
        .collect()
}

/// The exact rational quadratic full circle of radius `r` about `c` (9 control points,
/// Piegl–Tiller §7.5), parameter domain [0, 1], counter-clockwise.
fn nurbs_circle(c: Point, r: f64) -> BSplineCurve {
    let offs = [
        (1.0, 0.0),
        (1.0, 1.0),
        (0.0, 1.0),
        (-1.0, 1.0),
        (-1.0, 0.0),
        (-1.0, -1.0),
        (0.0, -1.0),
        (1.0, -1.0),
        (1.0, 0.0),
    ];
    let pts = offs.iter().map(|&(x, y)| c + Vec2::new(x, y) * r).collect();
    let w = (0..9)
        .map(|i| if i % 2 == 0 { 1.0 } else { FRAC_1_SQRT_2 })
        .collect();
    let knots = KnotVector::new(vec![
        0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0,
    ]);
    BSplineCurve::new(2, knots, pts, Some(w))
}

/// A non-uniform cubic used by several tests.
fn wavy_cubic() -> BSplineCurve {
    let pts = vec![
        Point::new(0.0, 0.0),
        Point::new(1.0, 1.4),
        Point::new(2.1, -0.3),
        Point::new(3.0, 0.9),
        Point::new(4.2, 1.8),
        Point::new(5.0, -0.2),
        Point::new(6.3, 0.4),
        Point::new(7.0, 1.1),
        Point::new(8.4, 0.0),
    ];
    let knots = KnotVector::new(vec![
        0.0, 0.0, 0.0, 0.0, 0.1, 0.3, 0.45, 0.5, 0.8, 1.0, 1.0, 1.0, 1.0,
    ]);
    BSplineCurve::new(3, knots, pts, None)
}

/// Parameters strictly inside every span of a piecewise curve (a third and two thirds in).
fn inner_params<C: Piecewise + ?Sized>(c: &C) -> Vec<f64> {
    c.breakpoints()
        .windows(2)
        .flat_map(|w| [w[0] + (w[1] - w[0]) / 3.0, w[0] + 2.0 * (w[1] - w[0]) / 3.0])
        .collect()
}

fn max_dist<A: Curve + ?Sized, B: Curve + ?Sized>(a: &A, b: &B, samples: usize) -> f64 {
    let (t0, t1) = a.domain();
    (0..=samples)
        .map(|k| {
            let t = t0 + (t1 - t0) * k as f64 / samples as f64;
            (a.eval(t) - b.eval(t)).length()
        })
        .fold(0.0, f64::max)
}

// ---------------------------------------------------------------------------------------------
// Spec vectors

#[test]
fn vector_common_signed_curvature_circle() {
    let v = vector("common.signed_curvature.circle");
    let tol = tol_of(v);
    let exp_ccw = v["expected"]["kappa_ccw"].as_f64().unwrap();
    let exp_cw = v["expected"]["kappa_cw"].as_f64().unwrap();
    for t in f64s(&v["inputs"]["t"]) {
        let (s, c) = t.sin_cos();
        let ccw = Derivatives {
            point: Point::new(2.0 * c, 2.0 * s),
            d1: Vec2::new(-2.0 * s, 2.0 * c),
            d2: Vec2::new(-2.0 * c, -2.0 * s),
            d3: Vec2::new(2.0 * s, -2.0 * c),
        };
        let cw = Derivatives {
            point: Point::new(2.0 * c, -2.0 * s),
            d1: Vec2::new(-2.0 * s, -2.0 * c),
            d2: Vec2::new(-2.0 * c, 2.0 * s),
            d3: Vec2::new(2.0 * s, 2.0 * c),
        };
        check(signed_curvature(&ccw), exp_ccw, tol, "kappa_ccw");
        check(signed_curvature(&cw), exp_cw, tol, "kappa_cw");
    }
    // The same circle as an exact NURBS and its reversal, at the vector's relative angles.
    let circle = nurbs_circle(Point::ORIGIN, 2.0);
    let rev = circle.reverse().unwrap();
    for k in 0..=20 {
        let t = k as f64 / 20.0;
        check(curvature_at(&circle, t), exp_ccw, tol, "NURBS ccw");
        check(curvature_at(&rev, t), exp_cw, tol, "NURBS cw");
    }
}

#[test]
fn vector_common_chord_length_parameters() {
    let v = vector("common.chord_length_parameters");
    let tol = tol_of(v);
    let pts = points(&v["inputs"]["points"]);
    let t = parameters(&pts, Parametrization::ChordLength, false).unwrap();
    check_all(&t, &f64s(&v["expected"]["t"]), tol, "t");
    let total = t[t.len() - 1];
    let tn: Vec<f64> = t.iter().map(|x| x / total).collect();
    check_all(
        &tn,
        &f64s(&v["expected"]["t_normalised"]),
        tol,
        "t_normalised",
    );
    // The normalised parameters are what B-spline interpolation returns.
    let (_, tb) = BSplineCurve::interpolate(&pts, 3, Parametrization::ChordLength).unwrap();
    check_all(
        &tb,
        &f64s(&v["expected"]["t_normalised"]),
        tol,
        "interpolate params",
    );
}

fn sv_curve(v: &Value) -> BSplineCurve {
    let inp = &v["inputs"];
    BSplineCurve::try_new(
        inp["degree"].as_u64().unwrap() as usize,
        KnotVector::try_new(f64s(&inp["knots"])).unwrap(),
        points(&inp["control_points"]),
        None,
    )
    .unwrap()
}

#[test]
fn vector_sv_curvature_samples() {
    let v = vector("sv.curvature_samples");
    let tol = tol_of(v);
    let c = sv_curve(v);
    let kappa: Vec<f64> = f64s(&v["inputs"]["t"])
        .iter()
        .map(|&t| curvature_at(&c, t))
        .collect();
    check_all(&kappa, &f64s(&v["expected"]["kappa"]), tol, "kappa");
}

#[test]
fn vector_sv_support_counts() {
    let v = vector("sv.support_counts");
    let knots = f64s(&v["inputs"]["knots"]);
    let n = v["inputs"]["N"].as_u64().unwrap() as usize;
    let p = 3;
    let n_ctrl = knots.len() - p - 1;
    let pts = (0..n_ctrl).map(|i| Point::new(i as f64, 0.0)).collect();
    let c = BSplineCurve::new(p, KnotVector::new(knots), pts, None);
    // Sample t lies in supp N_j = [u_j, u_{j+p+1}) (last span closed) exactly when the span
    // that evaluates it, k, has k − p ≤ j ≤ k. The basis there is a partition of unity.
    let mut counts = vec![0u64; n_ctrl];
    let mut b = [[0.0; MAX_ORDER]; 4];
    for i in 0..n {
        let t = i as f64 / (n - 1) as f64;
        let k = c.find_span(t);
        c.basis_derivs(k, t, 0, &mut b);
        assert!((b[0][..=p].iter().sum::<f64>() - 1.0).abs() < 1e-14);
        assert!(b[0][..=p].iter().all(|&x| x >= 0.0));
        for c in &mut counts[k - p..=k] {
            *c += 1;
        }
    }
    let exp: Vec<u64> = v["expected"]["counts_j_0_to_7"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap())
        .collect();
    assert_eq!(counts, exp);
}

#[test]
fn vector_cali_strophoid31_interpolation_and_gfi() {
    let v = vector("cali.interpolation_and_gfi.strophoid31_clean");
    let tol = tol_of(v);
    let e = &v["expected"];
    let pts = points(&v["inputs"]["points"]);
    let (c, t) = BSplineCurve::interpolate(&pts, 3, Parametrization::ChordLength).unwrap();
    check_all(&t, &f64s(&e["parameters"]), tol, "parameters");
    check_all(c.knots().as_slice(), &f64s(&e["knots"]), tol, "knots");
    let cp = points(&e["control_points"]);
    assert_eq!(cp.len(), c.control_points().len());
    for (i, (g, x)) in c.control_points().iter().zip(&cp).enumerate() {
        check(g.x, x.x, tol, &format!("control point {i} x"));
        check(g.y, x.y, tol, &format!("control point {i} y"));
    }
    let fi = fairness_indicators(&c);
    check_all(&fi.kappa, &f64s(&e["kappa_at_xi"]), tol, "kappa_at_xi");
    check_all(&fi.s, &f64s(&e["s_at_xi"]), tol, "s_at_xi");
    check_all(&fi.lfi, &f64s(&e["LFI"]), tol, "LFI");
    check(fi.gfi, e["GFI"].as_f64().unwrap(), tol, "GFI");
}

/// KY's uniform quintic (docs/algorithms/kuragano.md §5.1): knots −5..6, six control points, one
/// segment t ∈ [0, 1].
fn ky_quintic(ctrl: Vec<Point>) -> BSplineCurve {
    let knots = KnotVector::new((-5..=6).map(f64::from).collect());
    BSplineCurve::new(5, knots, ctrl, None)
}

/// The curve whose x coordinate is the basis function N_j (control point j = (1, 0)).
fn ky_unit(j: usize) -> BSplineCurve {
    ky_quintic(
        (0..6)
            .map(|i| Point::new(if i == j { 1.0 } else { 0.0 }, 0.0))
            .collect(),
    )
}

#[test]
fn vector_ky_basis_values_t0_3() {
    let v = vector("ky.basis.values_t0_3");
    let tol = tol_of(v);
    let t = v["inputs"]["t"].as_f64().unwrap();
    let c = ky_unit(0);
    let k = c.find_span(t);
    assert_eq!(k, 5);
    let mut b = [[0.0; MAX_ORDER]; 4];
    c.basis_derivs(k, t, 2, &mut b);
    check_all(&b[0][..6], &f64s(&v["expected"]["N"]), tol, "N");
    check_all(&b[1][..6], &f64s(&v["expected"]["dN"]), tol, "dN");
    check_all(&b[2][..6], &f64s(&v["expected"]["d2N"]), tol, "d2N");
    // The closed form of KY eq 3 at more points.
    for i in 0..=10 {
        let t = i as f64 / 10.0;
        let eq3 = [
            (1.0 - t).powi(5),
            5.0 * t.powi(5) - 20.0 * t.powi(4) + 20.0 * t.powi(3) + 20.0 * t * t - 50.0 * t + 26.0,
            -10.0 * t.powi(5) + 30.0 * t.powi(4) - 60.0 * t * t + 66.0,
            10.0 * t.powi(5) - 20.0 * t.powi(4) - 20.0 * t.powi(3) + 20.0 * t * t + 50.0 * t + 26.0,
            -5.0 * t.powi(5) + 5.0 * t.powi(4) + 10.0 * t.powi(3) + 10.0 * t * t + 5.0 * t + 1.0,
            t.powi(5),
        ];
        c.basis_derivs(c.find_span(t), t, 0, &mut b);
        for j in 0..6 {
            assert!((b[0][j] - eq3[j] / 120.0).abs() < 1e-15, "N_{j}({t})");
        }
    }
}

#[test]
fn vector_ky_basis_rows() {
    let v = vector("ky.basis.rows");
    let tol = tol_of(v);
    let e = &v["expected"];
    let c = ky_unit(0);
    let mut b = [[0.0; MAX_ORDER]; 4];
    c.basis_derivs(c.find_span(0.0), 0.0, 3, &mut b);
    for r in 0..=2 {
        let exp = f64s(&e[format!("r{r}")]);
        check_all(&b[r][..5], &exp, tol, &format!("r{r}"));
        check(b[r][5], 0.0, tol, &format!("r{r} coefficient of q_5"));
    }
    // r = 3: the vector (and the table in docs/algorithms/kuragano.md §5.1) print (−1, −2, 0, 2,
    // 1)/2, but the third derivative of eq 3 at t = 0 is (−60, 120, 0, −120, 60)/120 = (−1, 2, 0,
    // −2, 1)/2, which is also ½(Δ³q_0 + Δ³q_1) (the quadratic B-spline values (½, ½) applied to the
    // third differences). So the middle signs of the vector are checked flipped, and the rest of it
    // as printed.
    let exp3 = f64s(&e["r3"]);
    let eq3_d3 = [
        -60.0 / 120.0,
        120.0 / 120.0,
        0.0,
        -120.0 / 120.0,
        60.0 / 120.0,
        0.0,
    ];
    check_all(&b[3][..6], &eq3_d3, tol, "r3 from eq 3");
    for (j, &x) in exp3.iter().enumerate() {
        let corrected = if j == 1 || j == 3 { -x } else { x };
        check(
            b[3][j],
            corrected,
            tol,
            &format!("r3[{j}] (sign-corrected)"),
        );
    }
    // The fourth derivative through the hodograph: (C')''' = C''''.
    let r4: Vec<f64> = (0..6)
        .map(|j| {
            let h = ky_unit(j).derivative_curve().unwrap();
            h.derivatives(0.0).d3.x
        })
        .collect();
    check_all(&r4[..5], &f64s(&e["r4"]), tol, "r4");
    check(r4[5], 0.0, tol, "r4 coefficient of q_5");
}

// ---------------------------------------------------------------------------------------------
// Closed forms

#[test]
fn nurbs_circle_has_curvature_one_over_r() {
    for (c, r) in [
        (Point::ORIGIN, 1.0),
        (Point::new(3.0, -2.0), 0.25),
        (Point::new(-100.0, 50.0), 40.0),
    ] {
        let circle = nurbs_circle(c, r);
        for k in 0..=1000 {
            let t = k as f64 / 1000.0;
            let d = circle.derivatives(t);
            assert!(((d.point - c).length() - r).abs() <= 1e-12 * r);
            let kappa = signed_curvature(&d);
            assert!((kappa - 1.0 / r).abs() <= 1e-9 / r, "κ({t}) = {kappa}");
        }
        // Moving it does not change that.
        let moved = circle.transform(&Rigid::new(1.1, Vec2::new(7.0, -3.0)));
        for k in 0..=50 {
            let t = k as f64 / 50.0;
            assert!((curvature_at(&moved, t) - 1.0 / r).abs() <= 1e-9 / r);
        }
    }
}

/// Interpolants of 400 points of a circle of radius 3: the periodic cubic and the open
/// B-splines (cubic and quintic) have curvature 1/R to the interpolation accuracy, O(h²) for the
/// cubics with h = 2πR/400 ≈ 0.047 ((h/R)²/12 ≈ 2e-5). Measured relative errors |Δκ|·R:
/// periodic cubic 2.06e-5 everywhere; open cubic B-spline 2.06e-5 and quintic 9.4e-11 away
/// from the ten spans at either end (the open ends are not periodic). Length and strain energy
/// of the analysis curve are within 1e-9 relative.
#[test]
fn circle_interpolants_have_curvature_one_over_r() {
    let r = 3.0;
    let c = Point::new(1.0, 2.0);
    let pts = arc(c, r, 0.0, TAU, 400);
    let closed = ParametricCubic::closed(&pts, Parametrization::ChordLength).unwrap();
    let (t0, t1) = closed.domain();
    let mut worst = 0.0_f64;
    for k in 0..=8000 {
        let t = t0 + (t1 - t0) * k as f64 / 8000.0;
        worst = worst.max((curvature_at(&closed, t) - 1.0 / r).abs() * r);
    }
    assert!(
        worst < 3e-5,
        "periodic cubic: relative curvature error {worst:e}"
    );

    for (degree, bound) in [(3, 3e-5), (5, 1e-9)] {
        let (bs, t) =
            BSplineCurve::interpolate(&pts, degree, Parametrization::ChordLength).unwrap();
        let mut worst = 0.0_f64;
        for w in t[10..t.len() - 10].windows(2) {
            for j in 0..4 {
                let tt = w[0] + (w[1] - w[0]) * j as f64 / 4.0;
                worst = worst.max((curvature_at(&bs, tt) - 1.0 / r).abs() * r);
            }
        }
        assert!(worst < bound, "degree {degree}: relative error {worst:e}");
    }

    let m = FairnessMetrics::of_seq(&PointSeq::closed(pts).unwrap()).unwrap();
    assert_eq!(m.inflections, 0);
    assert!((m.length - TAU * r).abs() < 1e-8 * r);
    assert!((m.max_curvature - 1.0 / r).abs() < 3e-5 / r);
    assert!((m.strain_energy - TAU / r).abs() < 1e-8 / r);
}

fn cubic_graph(n: usize) -> Vec<Point> {
    (0..n)
        .map(|i| {
            let x = -1.5 + 3.0 * i as f64 / (n - 1) as f64;
            Point::new(x, x * x * x - x)
        })
        .collect()
}

#[test]
fn cubic_graph_has_exactly_one_inflection() {
    let base = cubic_graph(50);
    let mut variants: Vec<Vec<Point>> = vec![
        base.clone(),
        base.iter().map(|p| Point::new(p.x, -p.y)).collect(),
        base.iter().map(|p| Point::new(-p.x, p.y)).collect(),
        base.iter().rev().copied().collect(),
    ];
    for angle in [0.3, 1.0, PI / 2.0, 2.5, PI, -0.7] {
        let m = Rigid::new(angle, Vec2::new(10.0 * angle, -3.0));
        variants.push(base.iter().map(|&p| m.apply(p)).collect());
    }
    for (i, pts) in variants.into_iter().enumerate() {
        let m = FairnessMetrics::of_seq(&PointSeq::open(pts).unwrap()).unwrap();
        assert_eq!(m.inflections, 1, "variant {i}");
    }
}

// ---------------------------------------------------------------------------------------------
// Knot insertion and removal

/// A random valid B-spline or NURBS: degree 1–5, clamped on [0, 1] with up to 6 distinct
/// interior knots of random multiplicity ≤ degree.
fn arb_curve() -> impl Strategy<Value = BSplineCurve> {
    (
        1usize..=5,
        prop::collection::vec((0.02f64..0.98, 1usize..=5), 0..6),
        prop::collection::vec((-10.0f64..10.0, -10.0f64..10.0), 40),
        prop::collection::vec(0.3f64..3.0, 40),
        any::<bool>(),
    )
        .prop_map(|(p, interior, xy, w, rational)| {
            let mut interior: Vec<(f64, usize)> =
                interior.into_iter().map(|(u, m)| (u, m.min(p))).collect();
            interior.sort_by(|a, b| a.0.total_cmp(&b.0));
            interior.dedup_by(|a, b| (a.0 - b.0).abs() < 1e-3);
            let mut knots = vec![0.0; p + 1];
            for &(u, m) in &interior {
                knots.extend(std::iter::repeat_n(u, m));
            }
            knots.extend(std::iter::repeat_n(1.0, p + 1));
            let n = knots.len() - p - 1;
            let pts = xy[..n].iter().map(|&(x, y)| Point::new(x, y)).collect();
            let w = rational.then(|| w[..n].to_vec());
            BSplineCurve::new(p, KnotVector::new(knots), pts, w)
        })
}

fn curve_scale(c: &BSplineCurve) -> f64 {
    c.control_points()
        .iter()
        .fold(1.0_f64, |m, p| m.max(p.to_vec2().length()))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Knot insertion leaves the curve unchanged (1e-12 relative to its size); removing the
    /// inserted copies again gives back the original knots and control points.
    #[test]
    fn knot_insertion_keeps_the_curve(
        c in arb_curve(),
        u_new in 0.001f64..0.999,
        pick in any::<prop::sample::Index>(),
        use_existing in any::<bool>(),
        times_raw in 1usize..=5,
    ) {
        let p = c.degree();
        let (a, b) = c.domain();
        let interior: Vec<f64> = c.knots().as_slice().iter().copied()
            .filter(|&k| k > a && k < b).collect();
        let u = if use_existing && !interior.is_empty() {
            interior[pick.index(interior.len())]
        } else {
            u_new
        };
        let s = c.knots().multiplicity(u);
        prop_assume!(s < p);
        let times = times_raw.min(p - s);
        let scale = curve_scale(&c);
        let ci = c.insert_knot(u, times).unwrap();
        prop_assert_eq!(ci.control_points().len(), c.control_points().len() + times);
        prop_assert_eq!(ci.knots().multiplicity(u), s + times);
        prop_assert_eq!(ci.weights().is_some(), c.weights().is_some());
        for k in 0..=200 {
            let t = k as f64 / 200.0;
            let d = (c.eval(t) - ci.eval(t)).length();
            prop_assert!(d <= 1e-12 * scale, "t = {}: {:e}", t, d);
        }
        let (cr, removed) = ci.remove_knot(KnotRef::Value(u), times, 1e-9 * scale).unwrap();
        prop_assert_eq!(removed, times);
        prop_assert_eq!(cr.knots(), c.knots());
        for (x, y) in cr.control_points().iter().zip(c.control_points()) {
            prop_assert!((*x - *y).length() <= 1e-9 * scale);
        }
        match (cr.weights(), c.weights()) {
            (None, None) => {}
            (Some(w1), Some(w0)) => {
                for (x, y) in w1.iter().zip(w0) {
                    prop_assert!((x - y).abs() <= 1e-9 * y);
                }
            }
            _ => prop_assert!(false, "rationality changed"),
        }
    }

    /// Unconditional removal reports the deviation it causes: a dense sample never exceeds it,
    /// and the tolerance-bounded removal honours its tolerance.
    #[test]
    fn knot_removal_reports_its_deviation(c in arb_curve(), pick in any::<prop::sample::Index>()) {
        let (a, b) = c.domain();
        let interior: Vec<f64> = c.knots().as_slice().iter().copied()
            .filter(|&k| k > a && k < b).collect();
        prop_assume!(!interior.is_empty());
        let u = interior[pick.index(interior.len())];
        for rule in [RemovalRule::Left, RemovalRule::Right, RemovalRule::Middle,
                     RemovalRule::Average, RemovalRule::LeastSquares] {
            let Ok(rem) = c.remove_knot_exact(KnotRef::Value(u), rule) else {
                // Only a rational curve may fail (a weight would become non-positive).
                prop_assert!(c.weights().is_some());
                continue;
            };
            prop_assert_eq!(rem.curve.control_points().len(), c.control_points().len() - 1);
            let sampled = max_dist(&c, &rem.curve, 4000);
            prop_assert!(sampled <= rem.max_deviation * (1.0 + 1e-9) + 1e-12,
                "{:?}: sampled {:e} > reported {:e}", rule, sampled, rem.max_deviation);
            // Reinsertion is exact but for rounding, which scales with the curve it works on:
            // the removed one, whose control points a removal next to a multiple knot can
            // blow up (a random case, kept as a seed: degree 5, Left, 2.6e7 from a curve of 5).
            let again = max_dist(&rem.reinserted, &rem.curve, 500);
            prop_assert!(again <= 1e-9 * curve_scale(&rem.curve));
            if matches!(rule, RemovalRule::Left | RemovalRule::Right | RemovalRule::Middle) {
                prop_assert!(rem.changed.len() <= 1);
            }
            // Tolerance-bounded removal: refused below the deviation, allowed above it.
            let dev = rem.max_deviation;
            if rule == RemovalRule::Middle && dev > 1e-6 {
                let (_, n) = c.remove_knot(KnotRef::Value(u), 1, 0.5 * dev).unwrap();
                prop_assert_eq!(n, 0);
                let (cr, n) = c.remove_knot(KnotRef::Value(u), 1, 2.0 * dev).unwrap();
                prop_assert_eq!(n, 1);
                prop_assert!(max_dist(&c, &cr, 2000) <= 2.0 * dev);
            }
        }
    }
}

#[test]
fn removal_rules_place_the_change_as_documented() {
    let c = wavy_cubic();
    let p = c.degree();
    let r = 5; // u_5 = 0.3, simple
    let mut sq = Vec::new();
    for (rule, expect) in [
        (RemovalRule::Left, Some(r - 1)),
        (RemovalRule::Right, Some(r - p)),
        (RemovalRule::Middle, Some(r - 2)),
        (RemovalRule::Average, None),
        (RemovalRule::LeastSquares, None),
    ] {
        let rem = c.remove_knot_exact(KnotRef::Index(r), rule).unwrap();
        if let Some(k) = expect {
            assert_eq!(rem.changed, vec![k], "{rule:?}");
        } else {
            assert!(rem.changed.len() > 1, "{rule:?}");
        }
        // Removal and reinsertion: the knot is removable from `reinserted` (C³ there).
        let d3 = |f: &dyn Fn(f64) -> Derivatives| f(0.3).d3;
        let jump =
            d3(&|t| rem.reinserted.derivatives(t)) - d3(&|t| rem.reinserted.derivatives_left(t));
        assert!(jump.length() < 1e-9 * max_len(&[rem.reinserted.derivatives(0.3).d3]));
        let change: f64 = c
            .control_points()
            .iter()
            .zip(rem.reinserted.control_points())
            .map(|(a, b)| (*a - *b).length_squared())
            .sum();
        sq.push((rule, change));
        // The reduced curve, reinserted, is `reinserted`.
        let back = rem.curve.insert_knot(0.3, 1).unwrap();
        for (a, b) in back
            .control_points()
            .iter()
            .zip(rem.reinserted.control_points())
        {
            assert!((*a - *b).length() < 1e-12);
        }
    }
    let ls = sq[4].1;
    for (rule, change) in &sq {
        assert!(
            ls <= change * (1.0 + 1e-12),
            "least change {ls} > {rule:?} {change}"
        );
    }
    // Removing a knot twice in a row to below its multiplicity is refused.
    assert!(c.remove_knot(KnotRef::Index(r), 2, 1.0).is_err());
    // End knots and non-knots are not removable; insertion outside the domain is refused.
    assert!(c.remove_knot(KnotRef::Index(0), 1, 1.0).is_err());
    assert!(c.remove_knot(KnotRef::Value(0.31), 1, 1.0).is_err());
    assert!(c.remove_knot(KnotRef::Index(99), 1, 1.0).is_err());
    assert!(c.remove_knot(KnotRef::Index(5), 1, f64::NAN).is_err());
    assert!(c.insert_knot(0.0, 1).is_err());
    assert!(c.insert_knot(1.5, 1).is_err());
    assert!(c.insert_knot(f64::NAN, 1).is_err());
    assert!(c.insert_knot(0.3, 3).is_err());
    assert_eq!(c.insert_knot(0.3, 0).unwrap(), c);
}

#[test]
fn knot_of_full_multiplicity_is_merged() {
    // A cubic with a knot of multiplicity 4 at 0.5 whose two pieces meet: removing one copy
    // merges the two coincident control points without changing the curve.
    let pts = vec![
        Point::new(0.0, 0.0),
        Point::new(1.0, 1.0),
        Point::new(2.0, 1.0),
        Point::new(3.0, 0.0),
        Point::new(3.0, 0.0),
        Point::new(4.0, 1.0),
        Point::new(5.0, 0.5),
        Point::new(6.0, 0.0),
    ];
    let knots = KnotVector::new(vec![
        0.0, 0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 0.5, 1.0, 1.0, 1.0, 1.0,
    ]);
    let c = BSplineCurve::new(3, knots, pts, None);
    let (cr, n) = c.remove_knot(KnotRef::Value(0.5), 1, 1e-12).unwrap();
    assert_eq!(n, 1);
    assert_eq!(cr.knots().multiplicity(0.5), 3);
    assert!(max_dist(&c, &cr, 400) < 1e-14);
    // The C⁰ corner there is not removable further within a small tolerance.
    let (_, n) = cr.remove_knot(KnotRef::Value(0.5), 1, 1e-6).unwrap();
    assert_eq!(n, 0);
}

#[test]
fn parametric_cubic_converts_exactly_and_reduces_to_c2() {
    let pts: Vec<Point> = (0..12)
        .map(|i| {
            let x = i as f64 * 0.8 + 0.1 * (i % 3) as f64;
            Point::new(x, (0.6 * x).sin() * 2.0)
        })
        .collect();
    let pc =
        ParametricCubic::interpolate(&pts, Parametrization::ChordLength, EndCondition::NotAKnot)
            .unwrap();
    let bs = BSplineCurve::from_parametric_cubic(&pc).unwrap();
    assert_eq!(bs.domain(), pc.domain());
    let (t0, t1) = pc.domain();
    for k in 0..=500 {
        let t = t0 + (t1 - t0) * k as f64 / 500.0;
        let (a, b) = (pc.derivatives(t), bs.derivatives(t));
        assert!((a.point - b.point).length() < 1e-12);
        assert!((a.d1 - b.d1).length() < 1e-11);
        assert!((a.d2 - b.d2).length() < 1e-10);
    }
    // Every interior double knot of a C² spline can lose one copy.
    let mut c2 = bs.clone();
    for &t in &pc.knots()[1..pc.knots().len() - 1] {
        let (next, n) = c2.remove_knot(KnotRef::Value(t), 1, 1e-10).unwrap();
        assert_eq!(n, 1, "knot {t}");
        c2 = next;
    }
    assert_eq!(c2.control_points().len(), pts.len() + 2);
    assert!(max_dist(&pc, &c2, 2000) < 1e-10);
    // Not-a-knot: the second and second-to-last knots go too.
    let t = pc.knots();
    for u in [t[1], t[t.len() - 2]] {
        let (next, n) = c2.remove_knot(KnotRef::Value(u), 1, 1e-9).unwrap();
        assert_eq!(n, 1);
        c2 = next;
    }
    // A C¹ Hermite curve with a tangent kink in curvature is not reducible at that knot.
    let tangents: Vec<Vec2> = (0..pts.len())
        .map(|i| Vec2::new(1.0, 0.3 * (i % 2) as f64))
        .collect();
    let h = ParametricCubic::from_hermite(pc.knots().to_vec(), pts.clone(), tangents).unwrap();
    let hb = BSplineCurve::from_parametric_cubic(&h).unwrap();
    let (_, n) = hb
        .remove_knot(KnotRef::Value(h.knots()[3]), 1, 1e-6)
        .unwrap();
    assert_eq!(n, 0);
    // A closed spline converts as well.
    let ring = arc(Point::ORIGIN, 1.0, 0.0, TAU, 9);
    let closed = ParametricCubic::closed(&ring, Parametrization::ChordLength).unwrap();
    let cb = BSplineCurve::from_parametric_cubic(&closed).unwrap();
    assert!(max_dist(&closed, &cb, 900) < 1e-13);
}

#[test]
fn reverse_transform_and_hodograph() {
    let c = wavy_cubic();
    let r = c.reverse().unwrap();
    assert_eq!(r.domain(), c.domain());
    for k in 0..=100 {
        let t = k as f64 / 100.0;
        assert!((r.eval(t) - c.eval(1.0 - t)).length() < 1e-13);
        assert!((curvature_at(&r, t) + curvature_at(&c, 1.0 - t)).abs() < 1e-10);
    }
    let m = Rigid::new(-0.4, Vec2::new(2.0, 5.0));
    let tc = c.transform(&m);
    let h = c.derivative_curve().unwrap();
    assert_eq!(h.degree(), 2);
    let hh = h.derivative_curve().unwrap();
    for t in inner_params(&c) {
        assert!((tc.eval(t) - m.apply(c.eval(t))).length() < 1e-12);
        let d = c.derivatives(t);
        assert!((h.eval(t).to_vec2() - d.d1).length() < 1e-11);
        assert!((h.derivatives(t).d1 - d.d2).length() < 1e-10);
        assert!((hh.eval(t).to_vec2() - d.d2).length() < 1e-10);
    }
    // A non-clamped (uniform) knot vector and a rational curve.
    let u = ky_quintic(
        (0..6)
            .map(|i| Point::new(i as f64, (i * i) as f64 * 0.1))
            .collect(),
    );
    let uh = u.derivative_curve().unwrap();
    for k in 0..=10 {
        let t = k as f64 / 10.0;
        assert!((uh.eval(t).to_vec2() - u.derivatives(t).d1).length() < 1e-12);
    }
    let ur = u.reverse().unwrap();
    for k in 0..=10 {
        let t = k as f64 / 10.0;
        assert!((ur.eval(t) - u.eval(1.0 - t)).length() < 1e-12);
    }
    assert!(nurbs_circle(Point::ORIGIN, 1.0).derivative_curve().is_err());
    let line = BSplineCurve::new(
        1,
        KnotVector::new(vec![0.0, 0.0, 1.0, 1.0]),
        vec![Point::ORIGIN, Point::new(1.0, 1.0)],
        None,
    );
    assert!(line.derivative_curve().is_err());
}

// ---------------------------------------------------------------------------------------------
// Derivatives against central differences

/// Compare each derivative with the central difference of the one below it, at parameters
/// inside the spans (away from the knots, where derivatives may jump).
fn check_finite_differences<C: CurveDeriv + Piecewise + ?Sized>(c: &C, what: &str) {
    let (t0, t1) = c.domain();
    let h = 1e-5 * (t1 - t0);
    for t in inner_params(c) {
        let d = c.derivatives(t);
        let (dp, dm) = (c.derivatives(t + h), c.derivatives(t - h));
        let fd = [
            (dp.point - dm.point) / (2.0 * h),
            (dp.d1 - dm.d1) / (2.0 * h),
            (dp.d2 - dm.d2) / (2.0 * h),
        ];
        let an = [d.d1, d.d2, d.d3];
        let scale = 1.0 + max_len(&an);
        for (o, (f, a)) in fd.iter().zip(&an).enumerate() {
            assert!(
                (*f - *a).length() <= 1e-6 * scale,
                "{what}: derivative {} at {t}: fd {f:?} vs {a:?}",
                o + 1
            );
        }
    }
}

#[test]
fn derivatives_match_finite_differences() {
    let pts: Vec<Point> = (0..14)
        .map(|i| {
            let a = i as f64 * 0.45;
            Point::new(a + 0.2 * a.sin(), (1.3 * a).cos() * (1.0 + 0.1 * a))
        })
        .collect();
    for p in 1..MAX_ORDER {
        let (c, _) = BSplineCurve::interpolate(&pts, p, Parametrization::Centripetal).unwrap();
        check_finite_differences(&c, &format!("B-spline degree {p}"));
        let r = c.insert_knot(0.37, 1).unwrap();
        check_finite_differences(&r, &format!("B-spline degree {p} with an inserted knot"));
    }
    check_finite_differences(&nurbs_circle(Point::new(1.0, 1.0), 2.0), "NURBS circle");
    let mut w = vec![1.0; 9];
    for (i, x) in w.iter_mut().enumerate() {
        *x = 0.5 + 0.3 * i as f64;
    }
    let c = wavy_cubic();
    let nurbs = BSplineCurve::new(3, c.knots().clone(), c.control_points().to_vec(), Some(w));
    check_finite_differences(&nurbs, "rational cubic");
    for end in [
        EndCondition::Natural,
        EndCondition::NotAKnot,
        EndCondition::Clamped(Vec2::new(1.0, -1.0), Vec2::new(0.0, 2.0)),
    ] {
        let pc = ParametricCubic::interpolate(&pts, Parametrization::ChordLength, end).unwrap();
        check_finite_differences(&pc, &format!("ParametricCubic {end:?}"));
    }
    let ring = arc(Point::ORIGIN, 2.0, 0.1, TAU + 0.1, 13);
    let closed = ParametricCubic::closed(&ring, Parametrization::Centripetal).unwrap();
    check_finite_differences(&closed, "closed ParametricCubic");
}

// ---------------------------------------------------------------------------------------------
// Rigid-motion invariance

/// A random open polyline: a walk with steps in [0.3, 2] and turns of at most 1.2 rad, so
/// consecutive points are distinct and the curve has no cusps.
fn arb_walk() -> impl Strategy<Value = Vec<Point>> {
    prop::collection::vec((0.3f64..2.0, -1.2f64..1.2), 6..40).prop_map(|steps| {
        let mut p = Point::ORIGIN;
        let mut heading = 0.0;
        let mut out = vec![p];
        for (len, turn) in steps {
            heading += turn;
            p += Vec2::from_angle(heading) * len;
            out.push(p);
        }
        out
    })
}

fn rel_close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn curvature_and_metrics_are_rigid_invariant(
        pts in arb_walk(),
        angle in -PI..PI,
        tx in -50.0f64..50.0,
        ty in -50.0f64..50.0,
    ) {
        let m = Rigid::new(angle, Vec2::new(tx, ty));
        let moved: Vec<Point> = pts.iter().map(|&p| m.apply(p)).collect();
        // Chord-length parameters are invariant, so parameters correspond one to one.
        let a = ParametricCubic::interpolate(&pts, Parametrization::ChordLength, EndCondition::NotAKnot).unwrap();
        let b = ParametricCubic::interpolate(&moved, Parametrization::ChordLength, EndCondition::NotAKnot).unwrap();
        let (ba, _) = BSplineCurve::interpolate(&pts, 3, Parametrization::ChordLength).unwrap();
        let (bb, _) = BSplineCurve::interpolate(&moved, 3, Parametrization::ChordLength).unwrap();
        let bt = ba.transform(&m);
        let kscale = inner_params(&a).iter().fold(0.0_f64, |s, &t| s.max(curvature_at(&a, t).abs()));
        for t in inner_params(&a) {
            let (ka, kb) = (curvature_at(&a, t), curvature_at(&b, t));
            prop_assert!((ka - kb).abs() <= 1e-9 * kscale, "t={}: {} vs {}", t, ka, kb);
        }
        for t in inner_params(&ba) {
            let k0 = curvature_at(&ba, t);
            prop_assert!((k0 - curvature_at(&bb, t)).abs() <= 1e-9 * kscale);
            prop_assert!((k0 - curvature_at(&bt, t)).abs() <= 1e-9 * kscale);
        }
        let ma = FairnessMetrics::of_seq(&PointSeq::open(pts).unwrap()).unwrap();
        let mb = FairnessMetrics::of_seq(&PointSeq::open(moved).unwrap()).unwrap();
        prop_assert_eq!(ma.points, mb.points);
        prop_assert_eq!(ma.inflections, mb.inflections);
        prop_assert_eq!(ma.vibrations, mb.vibrations);
        prop_assert_eq!(ma.curvature_extrema, mb.curvature_extrema);
        prop_assert!(rel_close(ma.strain_energy, mb.strain_energy, 1e-9));
        prop_assert!(rel_close(ma.variation_energy, mb.variation_energy, 1e-9));
        prop_assert!(rel_close(ma.max_curvature, mb.max_curvature, 1e-9));
        prop_assert!(rel_close(ma.gfi, mb.gfi, 1e-9), "gfi {} vs {}", ma.gfi, mb.gfi);
        prop_assert!(rel_close(ma.max_third_derivative_jump, mb.max_third_derivative_jump, 1e-9));
        prop_assert!(rel_close(ma.length, mb.length, 1e-12));
    }
}

// ---------------------------------------------------------------------------------------------
// Least-squares approximation

#[test]
fn approximation_reproduces_a_curve_in_its_spline_space() {
    // With uniform parameters the knots depend only on the counts; a B-spline on exactly those
    // knots, sampled at those parameters, is reproduced.
    let m = 60;
    let probe: Vec<Point> = (0..m).map(|i| Point::new(i as f64, 0.0)).collect();
    for (p, n_ctrl) in [(1, 7), (2, 9), (3, 12), (4, 15), (5, 20)] {
        let (fit0, t) =
            BSplineCurve::approximate(&probe, p, n_ctrl, Parametrization::Uniform).unwrap();
        let ctrl: Vec<Point> = (0..n_ctrl)
            .map(|i| Point::new(i as f64 + 0.3 * (i % 3) as f64, ((i * 7) % 5) as f64 - 2.0))
            .collect();
        let truth = BSplineCurve::new(p, fit0.knots().clone(), ctrl, None);
        let data: Vec<Point> = t.iter().map(|&x| truth.eval(x)).collect();
        let (fit, t2) =
            BSplineCurve::approximate(&data, p, n_ctrl, Parametrization::Uniform).unwrap();
        assert_eq!(t2, t);
        assert_eq!(fit.knots(), truth.knots());
        for (a, b) in fit.control_points().iter().zip(truth.control_points()) {
            assert!((*a - *b).length() < 1e-10, "degree {p}: {a:?} vs {b:?}");
        }
    }
    // A global cubic polynomial lies in every cubic spline space, whatever the knots.
    let data: Vec<Point> = (0..41)
        .map(|i| {
            let t = i as f64 / 40.0;
            Point::new(t * t * t - 2.0 * t, 3.0 * t * t + t)
        })
        .collect();
    let (fit, _) = BSplineCurve::approximate(&data, 3, 9, Parametrization::Uniform).unwrap();
    for k in 0..=100 {
        let t = k as f64 / 100.0;
        let exact = Point::new(t * t * t - 2.0 * t, 3.0 * t * t + t);
        assert!((fit.eval(t) - exact).length() < 1e-12);
    }
}

#[test]
fn approximation_residual_falls_and_ends_are_interpolated() {
    let data: Vec<Point> = (0..400)
        .map(|i| {
            let a = i as f64 * 0.02;
            Point::new(a * a.cos(), a * a.sin() + 0.3 * (3.0 * a).sin())
        })
        .collect();
    let mut last = f64::INFINITY;
    for n_ctrl in [5, 8, 12, 20, 35, 60, 100, 200, 300, 400] {
        let (fit, t) =
            BSplineCurve::approximate(&data, 3, n_ctrl, Parametrization::ChordLength).unwrap();
        assert_eq!(fit.control_points().len(), n_ctrl);
        if n_ctrl < data.len() {
            // The end control points are the end points, and a clamped curve ends there.
            assert_eq!(fit.eval(0.0), data[0]);
            assert_eq!(fit.eval(1.0), data[data.len() - 1]);
        } else {
            // As many control points as points: the interpolant, solved for all of them.
            assert!((fit.eval(0.0) - data[0]).length() < 1e-13);
            assert!((fit.eval(1.0) - data[data.len() - 1]).length() < 1e-13);
        }
        let res: f64 = t
            .iter()
            .zip(&data)
            .map(|(&x, q)| (fit.eval(x) - *q).length_squared())
            .sum();
        assert!(
            res < last,
            "n_ctrl {n_ctrl}: residual {res:e} after {last:e}"
        );
        last = res;
    }
    assert!(
        last < 1e-20,
        "as many control points as points interpolates: {last:e}"
    );
    // The minimal case: a degree-1 fit with two control points is the chord.
    let (line, _) = BSplineCurve::approximate(&data, 1, 2, Parametrization::ChordLength).unwrap();
    assert_eq!(line.control_points(), &[data[0], data[399]]);
}

#[test]
fn approximation_rejects_bad_input() {
    let data = cubic_graph(10);
    assert!(matches!(
        BSplineCurve::approximate(&data, 3, 11, Parametrization::ChordLength),
        Err(Error::TooFewPoints { .. })
    ));
    assert!(BSplineCurve::approximate(&data, 3, 3, Parametrization::ChordLength).is_err());
    assert!(BSplineCurve::approximate(&data, 0, 3, Parametrization::ChordLength).is_err());
    assert!(BSplineCurve::approximate(&data, MAX_ORDER, 9, Parametrization::ChordLength).is_err());
    let mut dup = data.clone();
    dup[4] = dup[3];
    assert_eq!(
        BSplineCurve::approximate(&dup, 3, 6, Parametrization::ChordLength).unwrap_err(),
        Error::DuplicatePoint { index: 4 }
    );
    let mut nan = data;
    nan[2].y = f64::NAN;
    assert_eq!(
        BSplineCurve::approximate(&nan, 3, 6, Parametrization::ChordLength).unwrap_err(),
        Error::NonFinite { index: 2 }
    );
}

// ---------------------------------------------------------------------------------------------
// Validation

#[test]
fn knot_vectors_and_curves_are_validated() {
    assert!(matches!(
        KnotVector::try_new(vec![]),
        Err(Error::InvalidKnots(_))
    ));
    assert!(matches!(
        KnotVector::try_new(vec![0.0, f64::NAN, 1.0]),
        Err(Error::InvalidKnots(_))
    ));
    assert!(matches!(
        KnotVector::try_new(vec![0.0, f64::INFINITY]),
        Err(Error::InvalidKnots(_))
    ));
    assert!(matches!(
        KnotVector::try_new(vec![0.0, 0.6, 0.5, 1.0]),
        Err(Error::InvalidKnots(_))
    ));
    let k = |v: Vec<f64>| KnotVector::new(v);
    let pts4 = || {
        vec![
            Point::ORIGIN,
            Point::new(1.0, 1.0),
            Point::new(2.0, 0.0),
            Point::new(3.0, 1.0),
        ]
    };
    let clamped = || k(vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0]);
    assert!(BSplineCurve::try_new(3, clamped(), pts4(), None).is_ok());
    // Wrong knot count.
    assert!(matches!(
        BSplineCurve::try_new(3, k(vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0]), pts4(), None),
        Err(Error::InvalidKnots(_))
    ));
    // Multiplicity above degree + 1.
    assert!(matches!(
        BSplineCurve::try_new(1, k(vec![0.0, 0.0, 0.5, 0.5, 0.5, 1.0]), pts4(), None),
        Err(Error::InvalidKnots(_))
    ));
    // Empty domain.
    assert!(matches!(
        BSplineCurve::try_new(1, k(vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0]), pts4(), None),
        Err(Error::InvalidKnots(_))
    ));
    assert!(matches!(
        BSplineCurve::try_new(0, k(vec![0.0, 1.0, 2.0, 3.0, 4.0]), pts4(), None),
        Err(Error::InvalidParameter { .. })
    ));
    assert!(matches!(
        BSplineCurve::try_new(
            3,
            k(vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0]),
            pts4()[..2].to_vec(),
            None
        ),
        Err(Error::TooFewPoints { needed: 4, got: 2 })
    ));
    let mut bad = pts4();
    bad[1].x = f64::NAN;
    assert_eq!(
        BSplineCurve::try_new(3, clamped(), bad, None),
        Err(Error::NonFinite { index: 1 })
    );
    for w in [
        vec![1.0, 0.0, 1.0, 1.0],
        vec![1.0, -1.0, 1.0, 1.0],
        vec![1.0, f64::NAN, 1.0, 1.0],
        vec![1.0, f64::INFINITY, 1.0, 1.0],
    ] {
        assert!(
            matches!(
                BSplineCurve::try_new(3, clamped(), pts4(), Some(w.clone())),
                Err(Error::InvalidParameter { .. })
            ),
            "{w:?}"
        );
    }
    assert!(matches!(
        BSplineCurve::try_new(3, clamped(), pts4(), Some(vec![1.0; 3])),
        Err(Error::LengthMismatch { .. })
    ));
}

#[test]
fn serde_rejects_what_the_constructors_reject() {
    let good = r#"{"degree":3,"knots":[0,0,0,0,0.5,1,1,1,1],
        "control_points":[[0,0],[1,1],[2,0],[3,1],[4,0]],"weights":[1,2,1,0.5,1]}"#;
    let c: BSplineCurve = serde_json::from_str(good).unwrap();
    let back: BSplineCurve = serde_json::from_str(&serde_json::to_string(&c).unwrap()).unwrap();
    assert_eq!(back, c);
    let plain = wavy_cubic();
    let json = serde_json::to_string(&plain).unwrap();
    assert!(
        !json.contains("weights"),
        "weights are omitted for a non-rational curve"
    );
    assert_eq!(serde_json::from_str::<BSplineCurve>(&json).unwrap(), plain);
    for bad in [
        // unsorted knots
        r#"{"degree":3,"knots":[0,0,0,0,0.7,0.5,1,1,1,1],"control_points":[[0,0],[1,1],[2,0],[3,1],[4,0],[5,1]]}"#,
        // wrong knot count
        r#"{"degree":3,"knots":[0,0,0,0,1,1,1,1],"control_points":[[0,0],[1,1],[2,0],[3,1],[4,0]]}"#,
        // multiplicity above degree + 1
        r#"{"degree":1,"knots":[0,0,0.5,0.5,0.5,1],"control_points":[[0,0],[1,1],[2,0],[3,1]]}"#,
        // zero, negative weights; wrong weight count
        r#"{"degree":1,"knots":[0,0,1,1],"control_points":[[0,0],[1,1]],"weights":[1,0]}"#,
        r#"{"degree":1,"knots":[0,0,1,1],"control_points":[[0,0],[1,1]],"weights":[-1,1]}"#,
        r#"{"degree":1,"knots":[0,0,1,1],"control_points":[[0,0],[1,1]],"weights":[1]}"#,
        // degree 0, empty domain
        r#"{"degree":0,"knots":[0,1,2],"control_points":[[0,0],[1,1]]}"#,
        r#"{"degree":1,"knots":[0,0,0,1],"control_points":[[0,0],[1,1]]}"#,
        // NaN and infinity cannot be written in JSON: the parser refuses them already
        r#"{"degree":1,"knots":[0,0,NaN,1],"control_points":[[0,0],[1,1]]}"#,
        r#"{"degree":1,"knots":[0,0,1,1],"control_points":[[0,1e400],[1,1]]}"#,
    ] {
        assert!(serde_json::from_str::<BSplineCurve>(bad).is_err(), "{bad}");
    }
    assert!(serde_json::from_str::<KnotVector>("[0, 1, 0.5]").is_err());
    assert!(serde_json::from_str::<KnotVector>("[]").is_err());
    assert_eq!(
        serde_json::from_str::<KnotVector>("[0, 0.5, 1]").unwrap(),
        KnotVector::new(vec![0.0, 0.5, 1.0])
    );
}

// ---------------------------------------------------------------------------------------------
// Parity with scipy

/// `ParametricCubic` against `scipy.interpolate.CubicSpline` with chord-length parameters for
/// natural, not-a-knot, clamped and periodic ends: values and three derivatives agree to 1e-10
/// relative to the largest magnitude of each quantity over the samples.
#[test]
fn parametric_cubic_matches_scipy() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/scipy_cubic.json"
    );
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let cases = doc["cases"].as_array().unwrap();
    assert!(cases.len() >= 10);
    let vecs = |v: &Value| -> Vec<Vec2> { points(v).into_iter().map(Point::to_vec2).collect() };
    for case in cases {
        let name = format!(
            "{} {}",
            case["name"].as_str().unwrap(),
            case["bc"].as_str().unwrap()
        );
        let pts = points(&case["points"]);
        let spline = match case["bc"].as_str().unwrap() {
            "natural" => ParametricCubic::interpolate(
                &pts,
                Parametrization::ChordLength,
                EndCondition::Natural,
            ),
            "not-a-knot" => ParametricCubic::interpolate(
                &pts,
                Parametrization::ChordLength,
                EndCondition::NotAKnot,
            ),
            "clamped" => {
                let d0 = f64s(&case["d_start"]);
                let d1 = f64s(&case["d_end"]);
                ParametricCubic::interpolate(
                    &pts,
                    Parametrization::ChordLength,
                    EndCondition::Clamped(Vec2::new(d0[0], d0[1]), Vec2::new(d1[0], d1[1])),
                )
            }
            "periodic" => ParametricCubic::closed(&pts, Parametrization::ChordLength),
            other => panic!("unknown bc {other}"),
        }
        .unwrap();
        let t = f64s(&case["t"]);
        let tscale = t[t.len() - 1];
        for (a, b) in spline.knots().iter().zip(&t) {
            assert!((a - b).abs() <= 1e-13 * tscale, "{name}: knots");
        }
        let s = f64s(&case["s"]);
        let expected = [
            vecs(&case["value"]),
            vecs(&case["d1"]),
            vecs(&case["d2"]),
            vecs(&case["d3"]),
        ];
        for (o, exp) in expected.iter().enumerate() {
            let scale = max_len(exp);
            for (&x, e) in s.iter().zip(exp) {
                let d = spline.derivatives(x);
                let got = [d.point.to_vec2(), d.d1, d.d2, d.d3][o];
                assert!(
                    (got - *e).length() <= 1e-10 * scale,
                    "{name}: derivative {o} at {x}: {got:?} vs {e:?}"
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Degenerate input

/// The size of rounding noise in the curvature of a spline through `pts`: `ε·R/h_min²` with R
/// the largest coordinate magnitude and h_min the shortest chord.
fn curvature_noise(pts: &[Point]) -> f64 {
    let r = batten::geom::max_abs_coordinate(pts);
    let h = pts
        .windows(2)
        .fold(f64::INFINITY, |a, w| a.min((w[1] - w[0]).length()));
    f64::EPSILON * r / (h * h)
}

/// Regression: on collinear points the curvature is pure rounding noise, and the sign tests
/// relative to the largest |κ| counted its sign changes as inflections (6 of them on 10 points
/// of y = 0.37x + 2, hundreds on 1000 points), vibrations and extrema.
#[test]
fn collinear_data_has_zero_curvature_and_no_inflection() {
    let steps = |n: usize| -> Vec<f64> {
        let mut x = 0.0;
        (0..n)
            .map(|k| {
                let v = x;
                x += 0.2 + 0.3 * ((k * 7) % 5) as f64;
                v
            })
            .collect()
    };
    for (n, slope, offset) in [
        (10, 0.37, 2.0),
        (10, 0.0, 0.0),
        (10, -4.0, 1.0),
        (10, 0.37, 1000.0),
        (50, 1e-3, 0.0),
        (1000, 0.37, 5.0),
        (1000, -2.0, 1000.0),
    ] {
        let pts: Vec<Point> = steps(n)
            .iter()
            .map(|&x| Point::new(x + offset, slope * x + offset))
            .collect();
        let what = format!("{n} points, slope {slope}, offset {offset}");
        let len = (pts[n - 1] - pts[0]).length();
        let noise = curvature_noise(&pts);
        let m = FairnessMetrics::of_seq(&PointSeq::open(pts.clone()).unwrap()).unwrap();
        assert_eq!(m.inflections, 0, "{what}");
        assert_eq!(m.vibrations, 0, "{what}");
        assert_eq!(m.curvature_extrema, 0, "{what}");
        assert!(
            m.max_curvature <= 64.0 * noise,
            "{what}: {:e}",
            m.max_curvature
        );
        assert!(m.strain_energy <= (64.0 * noise).powi(2) * len, "{what}");
        assert!((m.length - len).abs() <= 1e-12 * len, "{what}");
        if n > 10 {
            continue;
        }
        // Every interpolant and approximant of collinear data is straight (to rounding).
        for end in [EndCondition::Natural, EndCondition::NotAKnot] {
            let pc = ParametricCubic::interpolate(&pts, Parametrization::ChordLength, end).unwrap();
            for t in inner_params(&pc) {
                assert!(curvature_at(&pc, t).abs() <= 64.0 * noise, "{what}");
            }
        }
        for p in 1..=5 {
            let (bs, _) = BSplineCurve::interpolate(&pts, p, Parametrization::ChordLength).unwrap();
            let (ap, _) =
                BSplineCurve::approximate(&pts, p, p + 2, Parametrization::ChordLength).unwrap();
            for t in inner_params(&bs).into_iter().chain(inner_params(&ap)) {
                assert!(
                    curvature_at(&bs, t).abs() <= 64.0 * noise,
                    "{what}, degree {p}"
                );
                assert!(
                    curvature_at(&ap, t).abs() <= 64.0 * noise,
                    "{what}, degree {p}"
                );
            }
        }
    }
}

#[test]
fn spans_of_very_different_lengths() {
    // A chord of 1e-4 between chords of about 1 and 3.
    let pts = vec![
        Point::new(0.0, 0.0),
        Point::new(1.0, 0.5),
        Point::new(1.0001, 0.5),
        Point::new(4.0, 1.0),
        Point::new(5.0, 3.0),
        Point::new(6.0, 2.5),
    ];
    let t = parameters(&pts, Parametrization::ChordLength, false).unwrap();
    assert!(((t[2] - t[1]) - 1e-4).abs() < 1e-15);
    for end in [EndCondition::Natural, EndCondition::NotAKnot] {
        let pc = ParametricCubic::interpolate(&pts, Parametrization::ChordLength, end).unwrap();
        for (k, p) in pc.knots().iter().zip(&pts) {
            assert!((pc.eval(*k) - *p).length() < 1e-12);
        }
        for t in inner_params(&pc) {
            let d = pc.derivatives(t);
            assert!(d.d1.is_finite() && d.d2.is_finite() && d.d3.is_finite());
        }
    }
    for p in 1..=5 {
        let (bs, tb) = BSplineCurve::interpolate(&pts, p, Parametrization::ChordLength).unwrap();
        for (tk, q) in tb.iter().zip(&pts) {
            assert!((bs.eval(*tk) - *q).length() < 1e-9, "degree {p}");
        }
    }
    let m = FairnessMetrics::of_seq(&PointSeq::open(pts).unwrap()).unwrap();
    assert!(m.strain_energy.is_finite() && m.max_curvature.is_finite() && m.gfi.is_finite());
}

#[test]
fn nearly_coincident_points() {
    // Two points 1e-10 apart on a curve of size ~5: accepted, interpolated, finite; exactly
    // coincident points are an error naming the second one.
    let mut pts = cubic_graph(12);
    pts.insert(6, pts[5] + Vec2::new(1e-10, 0.0));
    let seq = PointSeq::open(pts.clone()).unwrap();
    let pc =
        ParametricCubic::interpolate(&pts, Parametrization::ChordLength, EndCondition::NotAKnot)
            .unwrap();
    for (k, p) in pc.knots().iter().zip(&pts) {
        assert!((pc.eval(*k) - *p).length() < 1e-12);
    }
    let (bs, tb) = BSplineCurve::interpolate(&pts, 3, Parametrization::Centripetal).unwrap();
    for (tk, q) in tb.iter().zip(&pts) {
        assert!((bs.eval(*tk) - *q).length() < 1e-9);
    }
    assert!(bs.control_points().iter().all(|p| p.is_finite()));
    let m = FairnessMetrics::of_seq(&seq).unwrap();
    assert!(m.length.is_finite() && m.strain_energy.is_finite());

    let mut dup = pts.clone();
    dup[6] = dup[5];
    assert_eq!(
        PointSeq::open(dup.clone()),
        Err(Error::DuplicatePoint { index: 6 })
    );
    assert_eq!(
        ParametricCubic::interpolate(&dup, Parametrization::ChordLength, EndCondition::Natural),
        Err(Error::DuplicatePoint { index: 6 })
    );
    assert_eq!(
        BSplineCurve::interpolate(&dup, 3, Parametrization::ChordLength).unwrap_err(),
        Error::DuplicatePoint { index: 6 }
    );
}

/// Every parameter of every method is checked before any input is read: a value that is not
/// one the parameter takes is refused by `check_options`, and the defaults pass.
#[test]
fn every_method_checks_its_parameter_values_up_front() {
    use batten::fair::{self, FairOptions};
    for m in fair::methods() {
        fair::check_options(*m, false, &FairOptions::default())
            .unwrap_or_else(|e| panic!("{}: defaults refused: {e}", m.name()));
        for spec in m.parameters() {
            let o = FairOptions::default().with_param(spec.name, "not-a-value");
            match fair::check_options(*m, false, &o) {
                Err(Error::InvalidParameter { name, .. }) => {
                    assert_eq!(name, spec.name, "{}: wrong parameter named", m.name());
                }
                other => panic!(
                    "{}: {}=not-a-value gave {other:?}, not an invalid-parameter error",
                    m.name(),
                    spec.name
                ),
            }
            // The documented default is accepted.
            let o = FairOptions::default().with_param(spec.name, spec.default);
            assert!(
                fair::check_options(*m, false, &o).is_ok(),
                "{}: {}={} (the default) refused",
                m.name(),
                spec.name,
                spec.default
            );
        }
    }
    // Range checks happen up front too.
    let mst = fair::method("mst").unwrap();
    let o = FairOptions::default().with_param("p", "2");
    assert!(matches!(
        fair::check_options(mst, false, &o),
        Err(Error::InvalidParameter { .. })
    ));
}
