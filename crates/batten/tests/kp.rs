//! Kjellander, Poliakoff, the energy-optimal move (docs/algorithms/kjellander-poliakoff.md §2) and
//! Sapidis–Farin knot removal: the verified `kp.*` vectors (not `kp.example1.paper_table1`, which
//! is not reproducible), the identities of docs/algorithms/kjellander-poliakoff.md §2.3–2.5, and
//! the behaviour of the four registered methods.

#![allow(clippy::unwrap_used)]

use batten::curve::{Curve, CurveDeriv};
use batten::fair::{
    self, FairStatus, KpRule, energy_change_f, fair_hermite, hermite_step, parametric_energy,
    remove_reinsert_knot,
};
use batten::spline::{
    BSplineCurve, EndCondition, KnotRef, ParametricCubic, Parametrization, RemovalRule, parameters,
};
use batten::{Error, FairOptions, Point, PointSeq, Vec2};
use proptest::prelude::*;
use serde_json::Value;

const VECTORS: &str = include_str!("data/test-vectors.json");

const KP_METHODS: [&str; 3] = ["kjellander", "poliakoff", "energy"];
const ALL_METHODS: [&str; 4] = ["kjellander", "poliakoff", "energy", "sapidis-farin"];

fn vector(id: &str) -> Value {
    let all: Value = serde_json::from_str(VECTORS).expect("test vectors parse");
    let found = all["kjellander_poliakoff"]
        .as_array()
        .expect("kjellander_poliakoff list")
        .iter()
        .find(|v| v["id"] == id)
        .cloned()
        .expect("vector present");
    assert!(
        !found["tolerance"].is_null(),
        "{id} is not reproducible and must not be asserted"
    );
    found
}

/// `(abs, rel)` of a vector.
fn tol(v: &Value) -> (f64, f64) {
    (
        v["tolerance"]["abs"].as_f64().expect("abs"),
        v["tolerance"]["rel"].as_f64().expect("rel"),
    )
}

fn num(v: &Value) -> f64 {
    v.as_f64().expect("number")
}

fn pair(v: &Value) -> (f64, f64) {
    (num(&v[0]), num(&v[1]))
}

fn point(v: &Value) -> Point {
    let (x, y) = pair(v);
    Point::new(x, y)
}

fn vec2(v: &Value) -> Vec2 {
    let (x, y) = pair(v);
    Vec2::new(x, y)
}

fn points(v: &Value) -> Vec<Point> {
    v.as_array().expect("array").iter().map(point).collect()
}

fn vec2s(v: &Value) -> Vec<Vec2> {
    v.as_array().expect("array").iter().map(vec2).collect()
}

fn nums(v: &Value) -> Vec<f64> {
    v.as_array().expect("array").iter().map(num).collect()
}

#[track_caller]
fn close(got: f64, exp: f64, (abs, rel): (f64, f64), what: &str) {
    assert!(
        (got - exp).abs() <= abs + rel * exp.abs(),
        "{what}: got {got:.15e}, expected {exp:.15e}"
    );
}

#[track_caller]
fn close_xy(got: (f64, f64), exp: (f64, f64), t: (f64, f64), what: &str) {
    close(got.0, exp.0, t, what);
    close(got.1, exp.1, t, what);
}

fn xy_p(p: Point) -> (f64, f64) {
    (p.x, p.y)
}

fn xy_v(v: Vec2) -> (f64, f64) {
    (v.x, v.y)
}

fn one_move(method: &str, pts: &[Point]) -> batten::Faired {
    let input = PointSeq::open(pts.to_vec()).expect("valid input");
    let opts = FairOptions::default().with_max_iterations(1);
    fair::fair(method, &input, &opts).expect("fairing runs")
}

fn natural_chord(pts: &[Point]) -> ParametricCubic {
    ParametricCubic::interpolate(pts, Parametrization::ChordLength, EndCondition::Natural)
        .expect("spline")
}

// ---------------------------------------------------------------------------------------
// The verified vectors.

#[test]
fn kp_example1_single_step_chord_natural() {
    let v = vector("kp.example1.single_step.chord_natural");
    let t = tol(&v);
    let pts = points(&v["inputs"]["points"]);
    let k = v["inputs"]["k"].as_u64().expect("k") as usize - 1;
    let e = &v["expected"];
    let spline = natural_chord(&pts);
    for (got, exp) in spline.knots().iter().zip(nums(&e["t"])) {
        close(*got, exp, t, "t");
    }
    for (got, exp) in spline.tangents().iter().zip(vec2s(&e["first_derivatives"])) {
        close_xy(xy_v(*got), xy_v(exp), t, "r'");
    }
    let (knots, tans) = (spline.knots(), spline.tangents());

    let pol = hermite_step(KpRule::Poliakoff, knots, &pts, tans, k).expect("poliakoff");
    close_xy(
        xy_v(pol.jump),
        pair(&e["third_derivative_jump_at_k"]),
        t,
        "J_k",
    );
    close_xy(
        xy_p(pol.point),
        pair(&e["poliakoff_new_position"]),
        t,
        "poliakoff",
    );
    assert_eq!(pol.eta, Vec2::ZERO);

    let imp = hermite_step(KpRule::Energy, knots, &pts, tans, k).expect("energy");
    close_xy(
        xy_p(imp.point),
        pair(&e["improved_new_position"]),
        t,
        "improved",
    );
    close_xy(xy_v(imp.delta), pair(&e["improved_delta"]), t, "delta*");
    close_xy(xy_v(imp.eta), pair(&e["improved_eta"]), t, "eta*");
    close_xy(
        xy_v(imp.tangent),
        pair(&e["improved_new_tangent"]),
        t,
        "tangent",
    );
    close(
        imp.delta.length() / pol.delta.length(),
        num(&e["delta_improved_over_delta_poliakoff"]),
        t,
        "ratio",
    );

    // Lemma 1 on the vector: W before and after, and W' − W = 4F.
    let w0 = parametric_energy(&spline);
    close(w0, num(&e["hermite_energy_before"]), t, "W");
    let mut p1 = pts.clone();
    let mut m1 = tans.to_vec();
    p1[k] = imp.point;
    m1[k] = imp.tangent;
    let moved = ParametricCubic::from_hermite(knots.to_vec(), p1, m1).expect("hermite");
    let w1 = parametric_energy(&moved);
    close(
        w1,
        num(&e["hermite_energy_after_improved_pos_and_tangent"]),
        t,
        "W'",
    );
    let f = energy_change_f(knots, &pts, tans, k, imp.delta, imp.eta).expect("F");
    close(f, num(&e["F_at_optimum"]), t, "F");
    assert!((w1 - w0 - 4.0 * f).abs() < 1e-12 * w0);

    // The same single step through the registered methods (the worst point is k).
    let out = one_move("poliakoff", &pts);
    assert_eq!(out.report.moves.len(), 1);
    assert_eq!(out.report.moves[0].index, k);
    close_xy(
        xy_p(out.points[k]),
        pair(&e["poliakoff_new_position"]),
        t,
        "poliakoff run",
    );
    close(
        out.report.moves[0].before,
        xy_len(pair(&e["third_derivative_jump_at_k"])),
        t,
        "move.before",
    );
    let out = one_move("energy", &pts);
    assert_eq!(out.report.moves[0].index, k);
    close_xy(
        xy_p(out.points[k]),
        pair(&e["improved_new_position"]),
        t,
        "energy run",
    );
}

fn xy_len((x, y): (f64, f64)) -> f64 {
    x.hypot(y)
}

#[test]
fn kp_example1_uniform_kjellander() {
    let v = vector("kp.example1.uniform_kjellander");
    let t = tol(&v);
    let pts = points(&v["inputs"]["points"]);
    let k = v["inputs"]["k"].as_u64().expect("k") as usize - 1;
    let e = &v["expected"];
    let spline =
        ParametricCubic::interpolate(&pts, Parametrization::Uniform, EndCondition::Natural)
            .expect("spline");
    for (got, exp) in spline.tangents().iter().zip(vec2s(&e["first_derivatives"])) {
        close_xy(xy_v(*got), xy_v(exp), t, "r'");
    }
    let exp = pair(&e["new_position"]);
    for rule in [KpRule::Kjellander, KpRule::Poliakoff, KpRule::Energy] {
        let m = hermite_step(rule, spline.knots(), &pts, spline.tangents(), k).expect("step");
        close_xy(xy_p(m.point), exp, t, &format!("{rule:?}"));
    }
    let out = one_move("kjellander", &pts);
    assert_eq!(out.report.moves[0].index, k);
    close_xy(xy_p(out.points[k]), exp, t, "kjellander run");
}

#[test]
fn kp_hermite_generic() {
    let v = vector("kp.hermite_generic");
    let t = tol(&v);
    let i = &v["inputs"];
    let (knots, pts, tans) = (nums(&i["t"]), points(&i["points"]), vec2s(&i["tangents"]));
    let k = i["k"].as_u64().expect("k") as usize - 1;
    let e = &v["expected"];
    let pol = hermite_step(KpRule::Poliakoff, &knots, &pts, &tans, k).expect("poliakoff");
    close_xy(
        xy_p(pol.point),
        pair(&e["poliakoff_new_position"]),
        t,
        "poliakoff",
    );
    let imp = hermite_step(KpRule::Energy, &knots, &pts, &tans, k).expect("energy");
    close_xy(xy_v(imp.delta), pair(&e["improved_delta"]), t, "delta*");
    close_xy(xy_v(imp.eta), pair(&e["improved_eta"]), t, "eta*");
    close_xy(
        xy_p(imp.point),
        pair(&e["improved_new_position"]),
        t,
        "improved",
    );
    let f = energy_change_f(&knots, &pts, &tans, k, imp.delta, imp.eta).expect("F");
    close(f, num(&e["F_at_optimum"]), t, "F");
    let before =
        ParametricCubic::from_hermite(knots.clone(), pts.clone(), tans.clone()).expect("hermite");
    let (mut p1, mut m1) = (pts.clone(), tans.clone());
    p1[k] = imp.point;
    m1[k] = imp.tangent;
    let after = ParametricCubic::from_hermite(knots.clone(), p1, m1).expect("hermite");
    let dw = parametric_energy(&after) - parametric_energy(&before);
    close(dw, num(&e["energy_change_exact"]), t, "W' - W");
    close(dw, 4.0 * f, t, "W' - W = 4F");
    // Kjellander's eq 4 needs unit steps.
    assert!(matches!(
        hermite_step(KpRule::Kjellander, &knots, &pts, &tans, k),
        Err(Error::InvalidParameter { .. })
    ));
}

#[test]
fn kp_example2_first_step() {
    let v = vector("kp.example2.first_step");
    let t = tol(&v);
    let pts = points(&v["inputs"]["points"]);
    let e = &v["expected"];
    let spline = natural_chord(&pts);
    let jumps: Vec<f64> = spline
        .third_derivative_jumps()
        .iter()
        .map(|j| j.length())
        .collect();
    for (got, exp) in jumps.iter().zip(nums(&e["jump_norms_points_2_to_11"])) {
        close(*got, exp, t, "|J|");
    }
    let worst = e["worst_point"].as_u64().expect("worst") as usize - 1;
    for (method, key) in [
        ("poliakoff", "poliakoff_new_position"),
        ("energy", "improved_new_position"),
    ] {
        let out = one_move(method, &pts);
        let mv = &out.report.moves[0];
        assert_eq!(mv.index, worst, "{method}");
        close(mv.before, jumps[worst - 1], t, "move.before");
        close_xy(xy_p(out.points[worst]), pair(&e[key]), t, method);
        assert_eq!(out.report.moved_points, vec![worst]);
    }
}

// ---------------------------------------------------------------------------------------
// Identities of docs/algorithms/kjellander-poliakoff.md §2.3–2.5.

/// Random Hermite data: `n` points along x with bumps, tangents roughly along the curve.
fn hermite_data() -> impl Strategy<Value = (Vec<f64>, Vec<Point>, Vec<Vec2>)> {
    (5usize..12).prop_flat_map(|n| {
        (
            prop::collection::vec(0.3f64..3.0, n - 1),
            prop::collection::vec((-1.0f64..1.0, -1.0f64..1.0), n),
            prop::collection::vec((0.2f64..2.0, -1.5f64..1.5), n),
        )
            .prop_map(|(steps, offs, tans)| {
                let mut t = vec![0.0];
                for s in &steps {
                    t.push(t[t.len() - 1] + s);
                }
                let pts = t
                    .iter()
                    .zip(&offs)
                    .map(|(x, (dx, dy))| Point::new(x + 0.2 * dx, *dy))
                    .collect();
                let tans = tans.iter().map(|&(x, y)| Vec2::new(x, y)).collect();
                (t, pts, tans)
            })
    })
}

/// Random noisy open point data with distinct consecutive points.
fn noisy_points() -> impl Strategy<Value = Vec<Point>> {
    (6usize..40, 0.0f64..0.3).prop_flat_map(|(n, amp)| {
        prop::collection::vec((-1.0f64..1.0, -1.0f64..1.0), n).prop_map(move |noise| {
            noise
                .iter()
                .enumerate()
                .map(|(i, (a, b))| {
                    let x = i as f64 * 0.5;
                    Point::new(x + 0.1 * a, (0.4 * x).sin() + amp * b)
                })
                .collect()
        })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Spec §2.3: with all parameter steps 1, eq 8 reduces to eq 4.
    #[test]
    fn kjellander_equals_poliakoff_for_unit_steps((_, pts, tans) in hermite_data()) {
        let t: Vec<f64> = (0..pts.len()).map(|i| i as f64).collect();
        for k in 1..pts.len() - 1 {
            let kj = hermite_step(KpRule::Kjellander, &t, &pts, &tans, k).unwrap();
            let po = hermite_step(KpRule::Poliakoff, &t, &pts, &tans, k).unwrap();
            prop_assert!((kj.point - po.point).length() < 1e-12);
        }
    }

    /// Spec §2.5: on C² tangents the improved displacement is Poliakoff's, scaled by
    /// 4(A³+B³)/(A+B)³; and the position-only energy optimum is Poliakoff's (the corollary).
    #[test]
    fn improved_is_scaled_poliakoff_on_c2_data(pts in noisy_points()) {
        let s = natural_chord(&pts);
        let (t, m) = (s.knots(), s.tangents());
        for k in 1..pts.len() - 1 {
            let po = hermite_step(KpRule::Poliakoff, t, &pts, m, k).unwrap();
            let en = hermite_step(KpRule::Energy, t, &pts, m, k).unwrap();
            let po_only = hermite_step(KpRule::EnergyPositionOnly, t, &pts, m, k).unwrap();
            let (a, b) = (t[k] - t[k - 1], t[k + 1] - t[k]);
            let factor = 4.0 * (a.powi(3) + b.powi(3)) / (a + b).powi(3);
            let scale = po.delta.length().max(1e-300);
            prop_assert!((en.delta - po.delta * factor).length() <= 1e-9 * scale);
            prop_assert!((po_only.delta - po.delta).length() <= 1e-9 * scale);
        }
    }

    /// Lemma 1: W' − W = 4F exactly, for any δ and η; and (δ*, η*) minimises F.
    #[test]
    fn lemma1_energy_change(
        (t, pts, tans) in hermite_data(),
        d in (-0.5f64..0.5, -0.5f64..0.5),
        h in (-0.5f64..0.5, -0.5f64..0.5),
    ) {
        let before = ParametricCubic::from_hermite(t.clone(), pts.clone(), tans.clone()).unwrap();
        let w0 = parametric_energy(&before);
        let (delta, eta) = (Vec2::new(d.0, d.1), Vec2::new(h.0, h.1));
        for k in 1..pts.len() - 1 {
            let (mut p1, mut m1) = (pts.clone(), tans.clone());
            p1[k] += delta;
            m1[k] += eta;
            let after = ParametricCubic::from_hermite(t.clone(), p1, m1).unwrap();
            let f = energy_change_f(&t, &pts, &tans, k, delta, eta).unwrap();
            let dw = parametric_energy(&after) - w0;
            prop_assert!((dw - 4.0 * f).abs() <= 1e-10 * (1.0 + w0), "{dw} vs {}", 4.0 * f);
            let opt = hermite_step(KpRule::Energy, &t, &pts, &tans, k).unwrap();
            let f_opt = energy_change_f(&t, &pts, &tans, k, opt.delta, opt.eta).unwrap();
            prop_assert!(f_opt <= f + 1e-12 * (1.0 + f.abs()));
            prop_assert!(f_opt <= 0.0);
        }
    }

    /// The energy move never increases ∫|r''|² dt: on Hermite data (every move, tangents
    /// carried), and for the point method with the parameters kept.
    #[test]
    fn energy_never_increases((t, pts, tans) in hermite_data(), moves in 1usize..6) {
        let w = |p: &[Point], m: &[Vec2]| {
            parametric_energy(&ParametricCubic::from_hermite(t.clone(), p.to_vec(), m.to_vec()).unwrap())
        };
        let mut last = w(&pts, &tans);
        for i in 1..=moves {
            let opts = FairOptions::default().with_max_iterations(i).with_param("threshold", 0);
            let out = fair_hermite(KpRule::Energy, &t, &pts, &tans, &opts).unwrap();
            let tans_out = out.tangents.unwrap();
            let now = w(&out.points, &tans_out);
            prop_assert!(now <= last + 1e-12 * last.max(1.0), "{now} > {last}");
            last = now;
        }
    }

    #[test]
    fn energy_method_never_increases_energy_with_fixed_parameters(pts in noisy_points(), moves in 1usize..6) {
        let t = parameters(&pts, Parametrization::ChordLength, false).unwrap();
        let w = |p: &[Point]| {
            parametric_energy(&ParametricCubic::interpolate_at(&t, p, EndCondition::Natural).unwrap())
        };
        let input = PointSeq::open(pts.clone()).unwrap();
        let mut last = w(&pts);
        for i in 1..=moves {
            // The method as the paper states it: the clean-curve guard, which may return the
            // input (with its higher ∫|r''|²) after a later move, is off.
            let opts = FairOptions::default()
                .with_max_iterations(i)
                .with_param("threshold", 0)
                .with_param("reparametrize", "false")
                .with_keep_clean(false);
            let out = fair::fair("energy", &input, &opts).unwrap();
            let now = w(&out.points);
            prop_assert!(now <= last + 1e-12 * last.max(1.0), "{now} > {last}");
            last = now;
        }
    }

    /// The tolerance is a hard bound for every method.
    #[test]
    fn tolerance_is_never_exceeded(pts in noisy_points(), tol in 1e-4f64..0.2, method in 0usize..4) {
        let input = PointSeq::open(pts.clone()).unwrap();
        let opts = FairOptions::default()
            .with_tolerance(tol)
            .with_max_iterations(200)
            .with_param("threshold", 0);
        let out = fair::fair(ALL_METHODS[method], &input, &opts).unwrap();
        prop_assert!(out.report.tolerance_met);
        prop_assert!(out.report.max_displacement <= tol);
        for (p, q) in out.points.iter().zip(&pts) {
            prop_assert!(p.distance(*q) <= tol);
        }
    }
}

// ---------------------------------------------------------------------------------------
// The methods.

fn noisy_arc(n: usize) -> Vec<Point> {
    (0..n)
        .map(|i| {
            let a = i as f64 * 0.08;
            let noise = 0.004 * (((i * 7919) % 11) as f64 - 5.0) / 5.0;
            Point::new((3.0 + noise) * a.cos(), (3.0 + noise) * a.sin())
        })
        .collect()
}

#[test]
fn max_iterations_one_moves_exactly_one_point() {
    let pts = noisy_arc(30);
    for method in ALL_METHODS {
        let out = one_move(method, &pts);
        assert_eq!(out.report.iterations, 1, "{method}");
        assert_eq!(out.report.moves.len(), 1, "{method}");
        assert_eq!(out.report.status, FairStatus::IterationLimit, "{method}");
        assert_eq!(out.report.moves[0].iteration, 1);
        assert!(
            out.report.moves[0].after < out.report.moves[0].before,
            "{method}"
        );
        if method != "sapidis-farin" {
            assert_eq!(out.report.moved_points, vec![out.report.moves[0].index]);
        }
    }
}

#[test]
fn report_lists_every_move_and_moved_point() {
    let pts = noisy_arc(40);
    let input = PointSeq::open(pts).unwrap();
    for method in KP_METHODS {
        let opts = FairOptions::default().with_max_iterations(25);
        let out = fair::fair(method, &input, &opts).unwrap();
        let r = &out.report;
        assert_eq!(r.moves.len(), 25, "{method}");
        assert_eq!(r.history.len(), 26, "{method}");
        for (i, m) in r.moves.iter().enumerate() {
            assert_eq!(m.iteration, i + 1);
            assert!(m.distance > 0.0);
        }
        let mut idx: Vec<usize> = r.moves.iter().map(|m| m.index).collect();
        idx.sort_unstable();
        idx.dedup();
        assert_eq!(r.moved_points, idx, "{method}");
        let first = r.history[0].measure;
        let last = r.history[r.history.len() - 1].measure;
        assert!(last < first, "{method}: {last} !< {first}");
    }
}

#[test]
fn methods_converge_and_keep_the_ends() {
    let pts = noisy_arc(40);
    let input = PointSeq::open(pts.clone()).unwrap();
    for method in ALL_METHODS {
        for fix in [false, true] {
            let opts = FairOptions::default()
                .with_fix_ends(fix)
                .with_param("threshold", 0.05);
            let out = fair::fair(method, &input, &opts).unwrap();
            let r = &out.report;
            assert_eq!(r.status, FairStatus::Converged, "{method}: {:?}", r.notes);
            assert_eq!(out.points.len(), pts.len());
            assert_eq!(out.points[0], pts[0], "{method}");
            assert_eq!(out.points[pts.len() - 1], pts[pts.len() - 1], "{method}");
            let eps = r.parameters["epsilon"].as_f64().unwrap();
            assert!(r.history[r.history.len() - 1].measure <= eps);
            // The fairing removes the noise: curvature no longer oscillates as much.
            assert!(r.after.max_third_derivative_jump < r.before.max_third_derivative_jump);
        }
    }
}

#[test]
fn energy_position_mode_is_poliakoff() {
    let input = PointSeq::open(noisy_arc(30)).unwrap();
    let opts = FairOptions::default().with_max_iterations(40);
    let po = fair::fair("poliakoff", &input, &opts).unwrap();
    let en = fair::fair(
        "energy",
        &input,
        &opts.clone().with_param("mode", "position"),
    )
    .unwrap();
    assert_eq!(po.report.moves.len(), en.report.moves.len());
    for (a, b) in po.report.moves.iter().zip(&en.report.moves) {
        assert_eq!(a.index, b.index);
    }
    for (a, b) in po.points.iter().zip(&en.points) {
        assert!(a.distance(*b) < 1e-10);
    }
}

#[test]
fn closed_curves() {
    let input = PointSeq::closed(wobbly_ellipse(48, 0)).unwrap();
    for method in KP_METHODS {
        let opts = FairOptions::default().with_max_iterations(200);
        let out = fair::fair(method, &input, &opts).unwrap();
        let r = &out.report;
        assert!(!r.moves.is_empty());
        assert!(r.history[r.history.len() - 1].measure < 0.5 * r.history[0].measure);
        // Every point of a closed curve is a candidate, the first one included.
        assert!(r.after.vibrations <= r.before.vibrations, "{method}");
    }
}

/// A closed curve: an ellipse with a fixed wobble, listed from point `shift`.
fn wobbly_ellipse(n: usize, shift: usize) -> Vec<Point> {
    let pts: Vec<Point> = (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            let r = 2.0 + 0.02 * (((i * 7) % 5) as f64 - 2.0);
            Point::new(r * a.cos(), 1.3 * r * a.sin())
        })
        .collect();
    (0..n).map(|i| pts[(i + shift) % n]).collect()
}

#[test]
fn sapidis_farin_fairs_closed_curves_seam_free() {
    let n = 48;
    let input = PointSeq::closed(wobbly_ellipse(n, 0)).unwrap();
    let opts = FairOptions::default().with_tolerance(0.05);
    let out = fair::fair("sapidis-farin", &input, &opts).unwrap();
    let r = &out.report;
    assert!(r.moves.len() > 10, "{} moves", r.moves.len());
    assert!(r.max_displacement <= 0.05);
    assert!(
        r.after.vibrations < r.before.vibrations,
        "{:?}",
        (r.before.vibrations, r.after.vibrations)
    );
    assert!(r.history[r.history.len() - 1].measure < 0.2 * r.history[0].measure);
    assert!(r.end_changes.is_none());
    // Moves happen on both sides of the seam (point 0), which is not special.
    let seam = r
        .moves
        .iter()
        .filter(|m| m.index < 3 || m.index + 3 >= n)
        .count();
    assert!(seam > 0);
    // The same curve listed from another start gives the same faired curve.
    for shift in [1, 17, 47] {
        let rotated = PointSeq::closed(wobbly_ellipse(n, shift)).unwrap();
        let b = fair::fair("sapidis-farin", &rotated, &opts).unwrap();
        for i in 0..n {
            let d = b.points[i].distance(out.points[(i + shift) % n]);
            assert!(d < 1e-9, "shift {shift}, point {i}: {d}");
        }
    }
}

#[test]
fn sapidis_farin_needs_six_points_on_a_closed_curve() {
    let few = PointSeq::closed(wobbly_ellipse(5, 0)).unwrap();
    assert!(matches!(
        fair::fair("sapidis-farin", &few, &FairOptions::default()),
        Err(Error::TooFewPoints { needed: 6, got: 5 })
    ));
    let six = PointSeq::closed(wobbly_ellipse(6, 0)).unwrap();
    assert!(fair::fair("sapidis-farin", &six, &FairOptions::default()).is_ok());
}

#[test]
fn fair_data_is_left_alone() {
    // Equally spaced collinear points: every jump is zero.
    let pts: Vec<Point> = (0..10)
        .map(|i| Point::new(i as f64, 2.0 * i as f64))
        .collect();
    let input = PointSeq::open(pts.clone()).unwrap();
    for method in ALL_METHODS {
        let out = fair::fair(method, &input, &FairOptions::default()).unwrap();
        assert_eq!(out.report.status, FairStatus::NoChange, "{method}");
        assert!(out.report.moves.is_empty());
        for (a, b) in out.points.iter().zip(&pts) {
            assert!(a.distance(*b) < 1e-12, "{method}");
        }
    }
    // Four points: no interior knot for sapidis-farin.
    let four = PointSeq::open(pts[..4].to_vec()).unwrap();
    let out = fair::fair("sapidis-farin", &four, &FairOptions::default()).unwrap();
    assert_eq!(out.report.status, FairStatus::NoChange);
}

#[test]
fn tight_tolerance_limits_the_run() {
    let pts = noisy_arc(30);
    let input = PointSeq::open(pts).unwrap();
    for method in ALL_METHODS {
        let opts = FairOptions::default()
            .with_tolerance(1e-4)
            .with_param("threshold", 0.01);
        let out = fair::fair(method, &input, &opts).unwrap();
        let r = &out.report;
        assert!(r.tolerance_met, "{method}");
        assert!(r.max_displacement <= 1e-4, "{method}");
        assert_eq!(
            r.status,
            FairStatus::ToleranceLimited,
            "{method}: {:?}",
            r.notes
        );
    }
}

#[test]
fn parameters_are_checked() {
    let input = PointSeq::open(noisy_arc(10)).unwrap();
    let bad = [
        ("kjellander", "reparametrize", "false"),
        ("poliakoff", "mode", "position"),
        ("energy", "threshold", "2"),
        ("energy", "epsilon", "-1"),
        ("energy", "mode", "tangent"),
        ("sapidis-farin", "threshold", "x"),
    ];
    for (m, k, v) in bad {
        let opts = FairOptions::default().with_param(k, v);
        assert!(fair::fair(m, &input, &opts).is_err(), "{m} {k}={v}");
    }
    let opts = FairOptions::default().with_param("epsilon", 1e300);
    let out = fair::fair("poliakoff", &input, &opts).unwrap();
    assert_eq!(out.report.status, FairStatus::NoChange);
}

// ---------------------------------------------------------------------------------------
// Hermite mode.

#[test]
fn hermite_mode_updates_tangents() {
    let v = vector("kp.hermite_generic");
    let i = &v["inputs"];
    let (t, pts, tans) = (nums(&i["t"]), points(&i["points"]), vec2s(&i["tangents"]));
    let opts = FairOptions::default().with_max_iterations(1);
    let out = fair_hermite(KpRule::Energy, &t, &pts, &tans, &opts).unwrap();
    let k = out.moves[0].index;
    let step = hermite_step(KpRule::Energy, &t, &pts, &tans, k).unwrap();
    let new_tans = out.tangents.unwrap();
    assert_eq!(out.points[k], step.point);
    assert_eq!(new_tans[k], step.tangent);
    for j in (0..pts.len()).filter(|&j| j != k) {
        assert_eq!(out.points[j], pts[j]);
        assert_eq!(new_tans[j], tans[j]);
    }
    // Poliakoff keeps the tangents; Kjellander refuses non-unit steps.
    let out = fair_hermite(KpRule::Poliakoff, &t, &pts, &tans, &opts).unwrap();
    assert_eq!(out.tangents.unwrap(), tans);
    assert!(fair_hermite(KpRule::Kjellander, &t, &pts, &tans, &opts).is_err());
    let bad = FairOptions::default().with_param("reparametrize", "false");
    assert!(matches!(
        fair_hermite(KpRule::Energy, &t, &pts, &tans, &bad),
        Err(Error::UnknownOption { .. })
    ));
    // Many moves with the jumps of the Hermite curve going down.
    let opts = FairOptions::default().with_max_iterations(50);
    let out = fair_hermite(KpRule::Energy, &t, &pts, &tans, &opts).unwrap();
    assert!(out.history[out.history.len() - 1].measure < out.history[0].measure);
}

// ---------------------------------------------------------------------------------------
// Sapidis–Farin knot removal and reinsertion.

fn test_bspline() -> BSplineCurve {
    let pts: Vec<Point> = (0..12)
        .map(|i| {
            let x = i as f64 * 0.7 + 0.1 * ((i * 5) % 3) as f64;
            Point::new(x, (0.9 * x).sin() + 0.05 * (((i * 7) % 4) as f64 - 1.5))
        })
        .collect();
    BSplineCurve::interpolate(&pts, 3, Parametrization::ChordLength)
        .expect("interpolation")
        .0
}

fn jump_at(c: &BSplineCurve, u: f64) -> Vec2 {
    c.derivatives(u).d3 - c.derivatives_left(u).d3
}

#[test]
fn knot_reinsertion_changes_one_control_point_and_zeroes_the_jump() {
    let curve = test_bspline();
    let u = curve.knots().as_slice().to_vec();
    let ncp = curve.control_points().len();
    for j in 4..ncp {
        let before = jump_at(&curve, u[j]);
        assert!(before.length() > 1e-6);
        let faired = remove_reinsert_knot(&curve, j).unwrap();
        assert_eq!(faired.knots(), curve.knots(), "knot vector unchanged");
        let moved: Vec<usize> = (0..ncp)
            .filter(|&i| faired.control_points()[i] != curve.control_points()[i])
            .collect();
        assert_eq!(moved, vec![j - 2], "only P_(j-2) moves");
        let after = jump_at(&faired, u[j]);
        assert!(
            after.length() <= 1e-9 * before.length(),
            "jump {after:?} at knot {j}"
        );
        // The curve changes only on the support [u_(j-2), u_(j+2)] of N_(j-2).
        for s in 0..=200 {
            let x = s as f64 / 200.0;
            if x <= u[j - 2] || x >= u[j + 2] {
                assert!((faired.eval(x) - curve.eval(x)).length() < 1e-14);
            }
        }
    }
    assert!(remove_reinsert_knot(&curve, 3).is_err());
    assert!(remove_reinsert_knot(&curve, ncp).is_err());
}

#[test]
fn knot_reinsertion_matches_the_spline_modules_middle_removal() {
    // The same step by an independent implementation: Tiller's A5.8 removal with the
    // "middle" rule, reinserted by Boehm's algorithm (spline::bspline_ops).
    let curve = test_bspline();
    for j in 4..curve.control_points().len() {
        let ours = remove_reinsert_knot(&curve, j).unwrap();
        let theirs = curve
            .remove_knot_exact(KnotRef::Index(j), RemovalRule::Middle)
            .unwrap();
        assert_eq!(theirs.changed, vec![j - 2]);
        assert_eq!(theirs.reinserted.knots(), ours.knots());
        for (a, b) in ours
            .control_points()
            .iter()
            .zip(theirs.reinserted.control_points())
        {
            assert!((*a - *b).length() < 1e-12, "knot {j}: {a:?} vs {b:?}");
        }
    }
}

#[test]
fn knot_reinsertion_matches_removal_then_boehm_insertion() {
    // Independent check: remove u_j from the faired curve by least squares on the left
    // reconstruction, insert it back with Boehm's algorithm, and recover the same points.
    let curve = test_bspline();
    let u = curve.knots().as_slice().to_vec();
    let p = curve.control_points().to_vec();
    let j = 6;
    let faired = remove_reinsert_knot(&curve, j).unwrap();
    let q = faired.control_points();
    // R: control points of the curve without u_j, from the left (exact after fairing).
    let mut r: Vec<Point> = Vec::new();
    let mut ur = u.clone();
    ur.remove(j);
    for i in 0..p.len() - 1 {
        if i <= j - 4 {
            r.push(q[i]);
        } else if i >= j - 1 {
            r.push(q[i + 1]);
        } else {
            let a = (u[j] - ur[i]) / (ur[i + 3] - ur[i]);
            let prev = r[i - 1];
            r.push(prev + (q[i] - prev) / a);
        }
    }
    // Boehm: insert u_j into (ur, r).
    let mut back = Vec::new();
    for i in 0..p.len() {
        if i <= j - 4 {
            back.push(r[i]);
        } else if i >= j {
            back.push(r[i - 1]);
        } else {
            let a = (u[j] - ur[i]) / (ur[i + 3] - ur[i]);
            back.push(r[i - 1].lerp(r[i], a));
        }
    }
    for (a, b) in back.iter().zip(q) {
        assert!((*a - *b).length() < 1e-12, "{a:?} vs {b:?}");
    }
}

#[test]
fn sapidis_farin_outputs_the_faired_curve_at_the_input_parameters() {
    let pts = noisy_arc(25);
    let input = PointSeq::open(pts.clone()).unwrap();
    let opts = FairOptions::default().with_max_iterations(30);
    let out = fair::fair("sapidis-farin", &input, &opts).unwrap();
    let curve = out.curve.expect("the faired B-spline");
    let (_, t) = BSplineCurve::interpolate(&pts, 3, Parametrization::ChordLength).unwrap();
    for (p, tk) in out.points.iter().zip(&t) {
        assert!((curve.eval(*tk) - *p).length() < 1e-12);
    }
    let r = &out.report;
    assert_eq!(r.moves.len(), 30);
    for m in &r.moves {
        // Control points P_2 .. P_(m-2) only.
        assert!(m.index >= 2 && m.index + 2 < pts.len());
        assert!(m.after <= 1e-9 * m.before);
    }
}
