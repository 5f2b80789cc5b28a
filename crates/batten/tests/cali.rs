//! Tests of the integral λ-operator (docs/algorithms/cali.md §4.2) and the `cali` fairing method
//! (docs/algorithms/cali.md §4.3–4.6): operator identities against direct integral means, the
//! vectors under "cali" in `tests/data/test-vectors.json`, the local LFI/GFI update against a full
//! recomputation, the paper's strophoid test as the spec reads it, and the tolerance as a hard
//! bound.

mod common;

use batten::analysis::fairness_indicators;
use batten::curve::{Curve, CurveDeriv};
use batten::fair::{FairStatus, LocalIndicators, fair};
use batten::spline::{BSplineCurve, KnotVector, LambdaOperator, Parametrization};
use batten::{Error, FairOptions, Point, PointSeq};
use common::Rng;
use proptest::prelude::*;
use serde_json::Value;

// ---------------------------------------------------------------------------------------------
// Helpers

fn vectors() -> Vec<Value> {
    let text = include_str!("data/test-vectors.json");
    let all: Value = serde_json::from_str(text).expect("test-vectors.json parses");
    all["cali"].as_array().expect("a 'cali' list").clone()
}

fn vector(id: &str) -> Value {
    vectors()
        .into_iter()
        .find(|v| v["id"] == id)
        .unwrap_or_else(|| panic!("vector {id} missing"))
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("an array")
        .iter()
        .map(|x| x.as_f64().expect("a number"))
        .collect()
}

fn points(v: &Value) -> Vec<Point> {
    v.as_array()
        .expect("an array of points")
        .iter()
        .map(|p| {
            let c = floats(p);
            Point::new(c[0], c[1])
        })
        .collect()
}

/// `|got − exp| ≤ abs + rel·|exp|` element-wise (docs/algorithms/README.md §7).
fn assert_close(what: &str, got: &[f64], exp: &[f64], tol: &Value) {
    let abs = tol["abs"].as_f64().expect("abs tolerance");
    let rel = tol["rel"].as_f64().expect("rel tolerance");
    assert_eq!(got.len(), exp.len(), "{what}: length");
    for (k, (g, e)) in got.iter().zip(exp).enumerate() {
        assert!(
            (g - e).abs() <= abs + rel * e.abs(),
            "{what}[{k}]: got {g}, expected {e}"
        );
    }
}

fn xs_ys(p: &[Point]) -> (Vec<f64>, Vec<f64>) {
    (
        p.iter().map(|q| q.x).collect(),
        p.iter().map(|q| q.y).collect(),
    )
}

/// A clamped knot vector for `n_ctrl` control points of degree `p` with random interior knots.
fn random_knots(p: usize, n_ctrl: usize, rng: &mut Rng) -> KnotVector {
    let mut interior: Vec<f64> = (0..n_ctrl - p - 1)
        .map(|_| 0.02 + 0.96 * rng.uniform())
        .collect();
    interior.sort_by(f64::total_cmp);
    let mut k = vec![0.0; p + 1];
    k.extend(interior);
    k.extend(std::iter::repeat_n(1.0, p + 1));
    KnotVector::new(k)
}

fn random_polygon(n: usize, rng: &mut Rng) -> Vec<Point> {
    (0..n)
        .map(|_| Point::new(4.0 * rng.uniform() - 2.0, 4.0 * rng.uniform() - 2.0))
        .collect()
}

/// The mean of the control-polygon function φ (piecewise linear through `(ξ_i, P_i)`) over
/// `[a, b]`, by two-point Gauss–Legendre on each linear piece: independent of the α, β, γ
/// formulas.
fn polygon_mean(xi: &[f64], pts: &[Point], a: f64, b: f64) -> Point {
    let phi = |t: f64| -> Point {
        let j = xi.partition_point(|&x| x <= t).clamp(1, xi.len() - 1);
        let (x0, x1) = (xi[j - 1], xi[j]);
        let s = if x1 > x0 { (t - x0) / (x1 - x0) } else { 1.0 };
        pts[j - 1].lerp(pts[j], s)
    };
    let mut cuts = vec![a];
    cuts.extend(xi.iter().copied().filter(|&x| x > a && x < b));
    cuts.push(b);
    let g = 0.5 / 3f64.sqrt();
    let (mut sx, mut sy) = (0.0, 0.0);
    for w in cuts.windows(2) {
        let (mid, len) = (0.5 * (w[0] + w[1]), w[1] - w[0]);
        for t in [mid - g * len, mid + g * len] {
            let q = phi(t);
            sx += 0.5 * len * q.x;
            sy += 0.5 * len * q.y;
        }
    }
    Point::new(sx / (b - a), sy / (b - a))
}

/// The strophoid of the paper's eq 30 at unit scale.
fn strophoid(t: f64) -> Point {
    let d = t * t + 1.0;
    Point::new((t * t * t - t) / d, (t * t - 1.0) / d)
}

/// Signed curvature of eq 30 from its analytic derivatives:
/// x' = (t⁴ + 4t² − 1)/d², y' = 4t/d², x'' = (12t − 4t³)/d³, y'' = (4 − 12t²)/d³, d = t² + 1.
fn strophoid_curvature(t: f64) -> f64 {
    let d = t * t + 1.0;
    let (d2, d3) = (d * d, d * d * d);
    let (x1, y1) = ((t.powi(4) + 4.0 * t * t - 1.0) / d2, 4.0 * t / d2);
    let (x2, y2) = ((12.0 * t - 4.0 * t.powi(3)) / d3, (4.0 - 12.0 * t * t) / d3);
    (x1 * y2 - y1 * x2) / (x1 * x1 + y1 * y1).powf(1.5)
}

/// 31 points of eq 30 equally spaced in t ∈ [−2, 2], 25 random interior ones perturbed by
/// N(0, σ²) in both coordinates (docs/algorithms/cali.md §4.6).
fn noisy_strophoid(sigma: f64, seed: u64) -> Vec<Point> {
    let mut rng = Rng::new(seed);
    let mut pts: Vec<Point> = (0..31)
        .map(|k| strophoid(-2.0 + 4.0 * k as f64 / 30.0))
        .collect();
    let mut interior: Vec<usize> = (1..30).collect();
    for k in 0..25 {
        let r = k + (rng.next_u64() % (interior.len() - k) as u64) as usize;
        interior.swap(k, r);
    }
    for &k in &interior[..25] {
        pts[k].x += sigma * rng.gaussian();
        pts[k].y += sigma * rng.gaussian();
    }
    pts
}

/// max |κ| of a curve, sampled densely in every span.
fn max_abs_curvature(c: &BSplineCurve) -> f64 {
    let (a, b) = c.domain();
    let n = 40 * c.control_points().len();
    (0..=n)
        .map(|k| {
            let d = c.derivatives(a + (b - a) * k as f64 / n as f64);
            (d.d1.cross(d.d2) / d.d1.length().powi(3)).abs()
        })
        .fold(0.0, f64::max)
}

fn noisy_sine(n: usize, sigma: f64, seed: u64) -> Vec<Point> {
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|k| {
            let x = 6.0 * k as f64 / (n - 1) as f64;
            Point::new(x, x.sin() + sigma * rng.gaussian())
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// The operator

#[test]
fn rows_sum_to_one_and_are_convex() {
    let mut rng = Rng::new(7);
    for p in 1..=5 {
        for n_ctrl in [p + 1, p + 2, 12, 30] {
            for uniform in [true, false] {
                let knots = if uniform {
                    KnotVector::clamped_uniform(p, n_ctrl).expect("knots")
                } else {
                    random_knots(p, n_ctrl, &mut rng)
                };
                let op = LambdaOperator::try_new(p, &knots).expect("operator");
                assert_eq!(op.len(), n_ctrl);
                for j in 0..n_ctrl {
                    let (a, b, g) = (op.alpha()[j], op.beta()[j], op.gamma()[j]);
                    assert!((a + b + g - 1.0).abs() <= 1e-15, "p={p} j={j}");
                    assert!(a >= 0.0 && g >= 0.0 && b >= 0.5 - 1e-15, "p={p} j={j}");
                    for lambda in [0.0, 0.3, 1.0] {
                        let r = op.row(j, lambda);
                        assert!((r.iter().sum::<f64>() - 1.0).abs() <= 1e-15);
                        assert!(r.iter().all(|&w| w >= 0.0));
                    }
                }
                assert_eq!(op.alpha()[0], 0.0);
                assert_eq!(op.gamma()[n_ctrl - 1], 0.0);
                // Interlacing η_i ≤ ξ_i ≤ η_{i+1}, with equal ends.
                let (xi, eta) = (op.xi(), op.eta());
                for i in 0..n_ctrl {
                    assert!(eta[i] <= xi[i] && xi[i] <= eta[i + 1]);
                }
                assert_eq!(xi[0], eta[0]);
                assert!((xi[n_ctrl - 1] - eta[n_ctrl]).abs() <= 1e-15);
            }
        }
    }
}

#[test]
fn lambda_zero_leaves_the_curve_unchanged() {
    let mut rng = Rng::new(11);
    let knots = random_knots(3, 15, &mut rng);
    let op = LambdaOperator::try_new(3, &knots).expect("operator");
    let poly = random_polygon(15, &mut rng);
    assert_eq!(op.apply(&poly, 0.0).expect("apply"), poly);
    for i in 2..=12 {
        let local = op.apply_local(&poly, i, 0.0).expect("local");
        assert_eq!(&local[..], &poly[i - 2..=i + 2]);
    }
    // The same through the fairing state: nothing moves and the GFI is the same.
    let pts = noisy_sine(25, 0.02, 3);
    let (curve, _) =
        BSplineCurve::interpolate(&pts, 3, Parametrization::ChordLength).expect("interpolation");
    let state = LocalIndicators::new(&curve).expect("indicators");
    for i in state.candidates() {
        let t = state.trial(i, 0.0).expect("trial");
        let (lo, hi) = t.moved_range();
        for j in lo..=hi {
            assert_eq!(t.moved_point(j), Some(curve.control_points()[j]));
        }
        assert!(t.gfi_change().abs() <= 1e-9 * state.gfi(), "{i}");
    }
}

#[test]
fn lambda_one_is_the_integral_operator_and_lambda_the_shrunk_mean() {
    let mut rng = Rng::new(23);
    for p in [2, 3, 4] {
        for uniform in [true, false] {
            let n_ctrl = 14;
            let knots = if uniform {
                KnotVector::clamped_uniform(p, n_ctrl).expect("knots")
            } else {
                random_knots(p, n_ctrl, &mut rng)
            };
            let op = LambdaOperator::try_new(p, &knots).expect("operator");
            let poly = random_polygon(n_ctrl, &mut rng);
            let (xi, eta) = (op.xi(), op.eta());
            for lambda in [1.0, 0.5, 0.1] {
                let got = op.apply(&poly, lambda).expect("apply");
                for i in 0..n_ctrl {
                    // Eqs 19–20: the mean over [ζ_i, η'_i].
                    let a = (1.0 - lambda) * xi[i] + lambda * eta[i];
                    let b = (1.0 - lambda) * xi[i] + lambda * eta[i + 1];
                    let want = polygon_mean(xi, &poly, a, b);
                    assert!(
                        got[i].distance(want) <= 1e-12,
                        "p={p} uniform={uniform} λ={lambda} i={i}: {:?} vs {want:?}",
                        got[i]
                    );
                }
            }
        }
    }
}

#[test]
fn reproduces_lines_and_points() {
    let mut rng = Rng::new(5);
    let knots = random_knots(3, 20, &mut rng);
    let op = LambdaOperator::try_new(3, &knots).expect("operator");
    let (o, d) = (Point::new(3.0, -1.0), batten::Vec2::new(0.6, 0.8));
    let mut s: Vec<f64> = (0..20).map(|_| 10.0 * rng.uniform()).collect();
    s.sort_by(f64::total_cmp);
    let line: Vec<Point> = s.iter().map(|&t| o + d * t).collect();
    for lambda in [0.25, 0.7, 1.0] {
        for q in op.apply(&line, lambda).expect("apply") {
            assert!((q - o).cross(d).abs() <= 1e-13, "off the line: {q:?}");
        }
        let same = vec![o; 20];
        for q in op.apply(&same, lambda).expect("apply") {
            assert!(q.distance(o) <= 1e-15);
        }
    }
    // Local moves keep a line too, and in place equals the returned window.
    let mut moved = line.clone();
    op.apply_local_in_place(&mut moved, 7, 0.8).expect("local");
    let window = op.apply_local(&line, 7, 0.8).expect("local");
    assert_eq!(&moved[5..=9], &window[..]);
    assert_eq!(&moved[..5], &line[..5]);
    assert_eq!(&moved[10..], &line[10..]);
    for q in &moved {
        assert!((*q - o).cross(d).abs() <= 1e-13);
    }
}

#[test]
fn operator_rejects_bad_input() {
    let unclamped = KnotVector::new((0..12).map(|k| k as f64).collect());
    assert!(matches!(
        LambdaOperator::try_new(3, &unclamped),
        Err(Error::InvalidKnots(_))
    ));
    let knots = KnotVector::clamped_uniform(3, 8).expect("knots");
    assert!(LambdaOperator::try_new(0, &knots).is_err());
    let op = LambdaOperator::try_new(3, &knots).expect("operator");
    let poly = random_polygon(8, &mut Rng::new(1));
    assert!(matches!(
        op.apply(&poly, 1.5),
        Err(Error::InvalidParameter { .. })
    ));
    assert!(op.apply(&poly, f64::NAN).is_err());
    assert!(matches!(
        op.apply(&poly[..7], 0.5),
        Err(Error::LengthMismatch { .. })
    ));
    assert!(op.apply_local(&poly, 1, 0.5).is_err());
    assert!(op.apply_local(&poly, 6, 0.5).is_err());
    assert!(op.apply_local(&poly, 5, 0.5).is_ok());
}

#[test]
fn interior_knot_of_full_multiplicity() {
    // A knot of multiplicity p + 1 splits the curve; the coefficients across it vanish.
    let knots = KnotVector::new(vec![
        0.0, 0.0, 0.0, 0.0, 0.3, 0.5, 0.5, 0.5, 0.5, 0.8, 1.0, 1.0, 1.0, 1.0,
    ]);
    let op = LambdaOperator::try_new(3, &knots).expect("operator");
    let xi = op.xi();
    let j = xi
        .windows(2)
        .position(|w| w[0] == w[1])
        .expect("two equal Greville points");
    assert_eq!(op.gamma()[j], 0.0);
    assert_eq!(op.alpha()[j + 1], 0.0);
    for k in 0..op.len() {
        assert!(op.alpha()[k].is_finite() && op.gamma()[k].is_finite());
    }
}

// ---------------------------------------------------------------------------------------------
// Vectors

#[test]
fn vector_operator_paper_polygon() {
    let v = vector("cali.operator.paper_polygon");
    let inp = &v["inputs"];
    let exp = &v["expected"];
    let tol = &v["tolerance"];
    let p = inp["degree"].as_u64().expect("degree") as usize;
    let knots = KnotVector::try_new(floats(&inp["knots"])).expect("knots");
    let op = LambdaOperator::try_new(p, &knots).expect("operator");
    assert_close("xi", op.xi(), &floats(&exp["xi"]), tol);
    assert_close("eta", op.eta(), &floats(&exp["eta"]), tol);
    assert_close("alpha", op.alpha(), &floats(&exp["alpha"]), tol);
    assert_close("beta", op.beta(), &floats(&exp["beta"]), tol);
    assert_close("gamma", op.gamma(), &floats(&exp["gamma"]), tol);
    let poly = points(&inp["control_points"]);
    for (lambda, key) in [(0.5, "MP_lambda_0_5"), (1.0, "MP_lambda_1")] {
        let (gx, gy) = xs_ys(&op.apply(&poly, lambda).expect("apply"));
        let (ex, ey) = xs_ys(&points(&exp[key]));
        assert_close(key, &gx, &ex, tol);
        assert_close(key, &gy, &ey, tol);
    }
}

#[test]
fn vector_operator_nonuniform() {
    let v = vector("cali.operator.nonuniform");
    let inp = &v["inputs"];
    let exp = &v["expected"];
    let tol = &v["tolerance"];
    let p = inp["degree"].as_u64().expect("degree") as usize;
    let knots = KnotVector::try_new(floats(&inp["knots"])).expect("knots");
    let op = LambdaOperator::try_new(p, &knots).expect("operator");
    for (key, got) in [
        ("xi", op.xi()),
        ("eta", op.eta()),
        ("alpha", op.alpha()),
        ("beta", op.beta()),
        ("gamma", op.gamma()),
    ] {
        assert_close(key, got, &floats(&exp[key]), tol);
    }
}

#[test]
fn vector_strophoid31_clean_indicators() {
    let v = vector("cali.interpolation_and_gfi.strophoid31_clean");
    let exp = &v["expected"];
    let tol = &v["tolerance"];
    let pts = points(&v["inputs"]["points"]);
    let (curve, _) =
        BSplineCurve::interpolate(&pts, 3, Parametrization::ChordLength).expect("interpolation");
    let state = LocalIndicators::new(&curve).expect("indicators");
    assert_close(
        "kappa_at_xi",
        state.kappa(),
        &floats(&exp["kappa_at_xi"]),
        tol,
    );
    assert_close("LFI", state.lfi(), &floats(&exp["LFI"]), tol);
    assert_close(
        "GFI",
        &[state.gfi()],
        &[exp["GFI"].as_f64().expect("GFI")],
        tol,
    );
}

#[test]
fn vector_first_move_noisy_strophoid() {
    let v = vector("cali.fair.first_move.noisy_strophoid");
    let inp = &v["inputs"];
    let exp = &v["expected"];
    let tol = &v["tolerance"];
    let pts = points(&inp["points"]);
    let tau = inp["tau"].as_f64().expect("tau");

    // The first candidate is the largest LFI among 2..=m−2.
    let (curve, _) =
        BSplineCurve::interpolate(&pts, 3, Parametrization::ChordLength).expect("interpolation");
    let state = LocalIndicators::new(&curve).expect("indicators");
    let first = state
        .candidates()
        .max_by(|&a, &b| state.lfi()[a].total_cmp(&state.lfi()[b]))
        .expect("candidates");
    assert_eq!(
        first as u64,
        exp["first_candidate"].as_u64().expect("index")
    );

    let input = PointSeq::open(pts).expect("points");
    let opts = FairOptions::default()
        .with_param("tau", tau)
        .with_max_iterations(1);
    let out = fair("cali", &input, &opts).expect("fair");
    let mv = &out.report.moves[0];
    assert_eq!(
        mv.index as u64,
        exp["accepted_centre"].as_u64().expect("index")
    );
    let lambda = out.report.parameters["lambdas"][0]
        .as_f64()
        .expect("lambda");
    assert_close(
        "GFI/lambda",
        &[mv.before, mv.after, lambda],
        &[
            exp["GFI_before"].as_f64().expect("GFI_before"),
            exp["GFI_after"].as_f64().expect("GFI_after"),
            exp["lambda"].as_f64().expect("lambda"),
        ],
        tol,
    );
    assert_eq!(out.report.status, FairStatus::IterationLimit);
    assert_eq!(out.report.history.len(), 2);
}

#[test]
fn vector_strophoid_analytic_curvature() {
    let v = vector("cali.strophoid.analytic_curvature");
    let exp = &v["expected"];
    let tol = &v["tolerance"];
    // Our analytic formula agrees with central differences of the curve itself.
    for &t in &[-1.7, -0.4, 0.0, 0.3, 1.2] {
        let e = 1e-4;
        let (a, b, c) = (strophoid(t - e), strophoid(t), strophoid(t + e));
        let d1 = (c - a) / (2.0 * e);
        let d2 = ((c - b) - (b - a)) / (e * e);
        let k_fd = d1.cross(d2) / d1.length().powi(3);
        assert!((k_fd - strophoid_curvature(t)).abs() < 1e-5, "t={t}");
    }
    let n = 400_000;
    let samples: Vec<(f64, f64)> = (0..=n)
        .map(|k| {
            let t = -2.0 + 4.0 * k as f64 / n as f64;
            (t, strophoid_curvature(t))
        })
        .collect();
    let (t_max, k_max) = samples
        .iter()
        .copied()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .expect("samples");
    assert!(t_max.abs() < 1e-4, "max at t = {t_max}");
    assert!(strophoid(0.0).distance(Point::new(0.0, -1.0)) == 0.0);
    assert_close(
        "max|kappa|",
        &[k_max.abs()],
        &[exp["max_abs_kappa"].as_f64().expect("max")],
        tol,
    );
    // |κ(±2)|: at t = 2, r' = (31, 8)/25 and r'' = (−8, −44)/125, so |κ| = 0.416 / 1.64^1.5
    // = 0.1980740. The vector's 0.198063 is 1.1e-5 off, just outside its own 1e-5; the exact
    // value is asserted, and the vector's to 2e-5.
    let exact_end = 0.416 / 1.64f64.powf(1.5);
    let vec_end = exp["abs_kappa_at_t_pm2"].as_f64().expect("ends");
    for t in [-2.0, 2.0] {
        let k = strophoid_curvature(t).abs();
        assert!((k - exact_end).abs() <= 1e-14, "t={t}: {k}");
        assert!((k - vec_end).abs() <= 2e-5, "t={t}: {k} vs {vec_end}");
    }
    // No inflection.
    assert!(samples.iter().all(|s| s.1 < 0.0));
}

// ---------------------------------------------------------------------------------------------
// The fairing method

/// Median of a small sample.
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

#[test]
fn strophoid_reproduction() {
    // Spec §4.6: unit scale, σ = 0.01 and 0.02, τ = 0.99; six fixed seeds per σ. The paper's
    // absolute GFI numbers are not asserted.
    //
    // The spec's claims — the GFI falls by two orders of magnitude, max |κ| returns to within
    // 25 % of the analytic 4.0 — are asserted on the median over the seeds: they do not hold
    // for every draw. The GFI cannot fall much below that of the noise-free curve (3717), so a
    // draw whose noisy GFI is only ~100 times that falls less than 30×; and a
    // draw can end with max |κ| up to 1.5 × 4.0. Every run must still lower the GFI by a factor
    // 30 (or to within 10× the noise-free curve's) and lower max |κ|.
    let (clean, _) =
        BSplineCurve::interpolate(&noisy_strophoid(0.0, 1), 3, Parametrization::ChordLength)
            .expect("interpolation");
    let clean_gfi = fairness_indicators(&clean).gfi;
    for sigma in [0.01, 0.02] {
        let (mut ratios, mut kappas) = (Vec::new(), Vec::new());
        for seed in 1..=6 {
            let pts = noisy_strophoid(sigma, seed);
            let (noisy, _) = BSplineCurve::interpolate(&pts, 3, Parametrization::ChordLength)
                .expect("interpolation");
            let input = PointSeq::open(pts.clone()).expect("points");
            let out = fair("cali", &input, &FairOptions::default()).expect("fair");
            let r = &out.report;
            let gfi0 = r.history[0].measure;
            let gfi1 = r.history.last().expect("history").measure;
            let curve = out.curve.as_ref().expect("curve");
            let (k0, k1) = (max_abs_curvature(&noisy), max_abs_curvature(curve));
            assert_eq!(r.status, FairStatus::Converged, "σ={sigma} seed={seed}");
            // By a factor 30, or to within 10× the noise-free curve's GFI, below which the
            // noise left nothing to remove.
            assert!(
                gfi1 * 30.0 <= gfi0 || gfi1 <= 10.0 * clean_gfi,
                "σ={sigma} seed={seed}: GFI {gfi0} → {gfi1} (noise-free {clean_gfi})"
            );
            assert!(k1 < k0, "σ={sigma} seed={seed}: max|κ| {k0} → {k1}");
            ratios.push(gfi0 / gfi1);
            kappas.push(k1);
            // The final indicators are the analysis module's, recomputed from scratch.
            let full = fairness_indicators(curve).gfi;
            assert!((full - gfi1).abs() <= 1e-9 * full);
            // End points kept, output = curve at the data parameters, same count.
            assert_eq!(out.points.len(), 31);
            assert_eq!(out.points[0], pts[0]);
            assert_eq!(out.points[30], pts[30]);
            assert_eq!(curve.control_points()[0], pts[0]);
            assert_eq!(curve.control_points()[30], pts[30]);
        }
        let (ratio, kappa) = (median(ratios.clone()), median(kappas.clone()));
        assert!(
            ratio >= 100.0,
            "σ={sigma}: median GFI reduction {ratio} ({ratios:?})"
        );
        assert!(
            (kappa - 4.0).abs() <= 0.25 * 4.0,
            "σ={sigma}: median max|κ| {kappa} ({kappas:?})"
        );
    }
}

#[test]
fn history_and_moves_are_consistent() {
    let pts = noisy_strophoid(0.02, 9);
    let input = PointSeq::open(pts.clone()).expect("points");
    let out = fair("cali", &input, &FairOptions::default()).expect("fair");
    let r = &out.report;
    assert!(!r.moves.is_empty());
    assert_eq!(r.history.len(), r.moves.len() + 1);
    assert_eq!(r.iterations, r.moves.len());
    for (k, mv) in r.moves.iter().enumerate() {
        assert_eq!(mv.iteration, k + 1);
        assert!((2..=28).contains(&mv.index));
        assert!(mv.after < 0.99 * mv.before, "{mv:?}");
        assert_eq!(r.history[k].measure, mv.before);
        assert_eq!(r.history[k + 1].measure, mv.after);
        assert!(r.history[k + 1].max_distance >= 0.0);
    }
    // The history's last distance is the largest output displacement.
    let last = r.history.last().expect("history").max_distance;
    assert!((last - r.max_displacement).abs() <= 1e-15);
    // Output points are the faired curve at the chord-length data parameters.
    let curve = out.curve.as_ref().expect("curve");
    let (_, params) =
        BSplineCurve::interpolate(&pts, 3, Parametrization::ChordLength).expect("interpolation");
    for (t, q) in params.iter().zip(&out.points) {
        assert!(curve.eval(*t).distance(*q) <= 1e-12);
    }
}

#[test]
fn local_update_equals_full_recomputation() {
    for (seed, degree) in [(1u64, 3usize), (2, 3), (3, 2), (4, 4), (5, 5)] {
        let pts = noisy_sine(40, 0.01, seed);
        let (curve, _) = BSplineCurve::interpolate(&pts, degree, Parametrization::ChordLength)
            .expect("interpolation");
        let mut state = LocalIndicators::new(&curve).expect("indicators");
        let mut rng = Rng::new(seed + 100);
        for step in 0..25 {
            let cands: Vec<usize> = state.candidates().collect();
            let i = cands[(rng.next_u64() % cands.len() as u64) as usize];
            // Include the ends of the candidate range, where the window touches P_0 / P_m.
            let i = match step {
                0 => *cands.first().expect("first"),
                1 => *cands.last().expect("last"),
                _ => i,
            };
            let lambda = rng.uniform();
            let trial = state.trial(i, lambda).expect("trial");
            let moved = {
                let mut c = state.control_points().to_vec();
                let (lo, hi) = trial.moved_range();
                for (j, q) in c.iter_mut().enumerate().take(hi + 1).skip(lo) {
                    *q = trial.moved_point(j).expect("moved");
                }
                curve.with_control_points(c).expect("curve")
            };
            let full = fairness_indicators(&moved);
            let rel = (trial.gfi_after() - full.gfi).abs() / full.gfi;
            assert!(
                rel <= 1e-9,
                "degree {degree} step {step} i={i}: rel {rel:e}"
            );
            let lfi_i = state.lfi_after(i, lambda).expect("lfi");
            assert!((lfi_i - full.lfi[i]).abs() <= 1e-9 * full.gfi);
            assert!((trial.lfi_centre() - full.lfi[i]).abs() <= 1e-9 * full.gfi);
            state.commit(&trial).expect("commit");
            for (a, b) in state.lfi().iter().zip(&full.lfi) {
                assert!((a - b).abs() <= 1e-9 * full.gfi);
            }
            assert!((state.gfi() - full.gfi).abs() <= 1e-9 * full.gfi);
            // A trial made before a commit cannot be committed.
            assert!(state.commit(&trial).is_err());
        }
        let final_curve = state.curve().expect("curve");
        assert_eq!(final_curve.control_points()[0], curve.control_points()[0]);
        let m = curve.control_points().len() - 1;
        assert_eq!(final_curve.control_points()[m], curve.control_points()[m]);
    }
}

#[test]
fn best_trial_minimises_the_local_indicator() {
    let pts = noisy_sine(30, 0.02, 77);
    let (curve, _) =
        BSplineCurve::interpolate(&pts, 3, Parametrization::ChordLength).expect("interpolation");
    let state = LocalIndicators::new(&curve).expect("indicators");
    for i in state.candidates() {
        let best = state.best_trial(i, 1e-6).expect("best");
        let f = best.lfi_centre();
        for k in 0..=50 {
            let l = k as f64 / 50.0;
            let g = state.lfi_after(i, l).expect("lfi");
            // Golden section finds a local minimum; on these curves LFI_i(λ) is unimodal
            // enough that the grid never beats it by more than the λ resolution allows.
            assert!(
                f <= g * (1.0 + 1e-6) + 1e-9 * state.gfi(),
                "i={i} λ={l}: {f} > {g}"
            );
        }
    }
}

#[test]
fn straight_and_clean_input() {
    // Collinear data: κ ≡ 0 (exactly, or up to rounding at an odd slope and uneven spacing),
    // nothing to do. Chasing rounding-level LFIs would slide the points along the line.
    for (slope, offset) in [(0.5, 0.0), (0.3, 0.1), (1.0 / 3.0, -7.3), (-2.9, 1e3)] {
        let line: Vec<Point> = (0..50)
            .map(|k| {
                let x = 0.37 * k as f64 + 0.01 * (k * k) as f64;
                Point::new(x, slope * x + offset)
            })
            .collect();
        let out = fair(
            "cali",
            &PointSeq::open(line.clone()).expect("points"),
            &FairOptions::default(),
        )
        .expect("fair");
        assert_eq!(out.report.status, FairStatus::NoChange, "slope {slope}");
        assert_eq!(out.points, line);
        assert!(out.report.moved_points.is_empty());
        assert!(!out.report.notes.is_empty());
    }
    // Too few points for a candidate (m < 4): unchanged, with a note.
    let few = vec![
        Point::new(0.0, 0.0),
        Point::new(1.0, 0.3),
        Point::new(2.0, 0.1),
        Point::new(3.0, 0.5),
    ];
    let out = fair(
        "cali",
        &PointSeq::open(few.clone()).expect("points"),
        &FairOptions::default(),
    )
    .expect("fair");
    assert_eq!(out.points, few);
    assert_eq!(out.report.status, FairStatus::NoChange);
    assert!(!out.report.notes.is_empty());
}

#[test]
fn options_and_errors() {
    let pts = noisy_strophoid(0.01, 4);
    let closed = PointSeq::closed(pts[..30].to_vec()).expect("points");
    assert!(matches!(
        fair("cali", &closed, &FairOptions::default()),
        Err(Error::ClosedUnsupported { .. })
    ));
    let open = PointSeq::open(pts).expect("points");
    for (k, v) in [
        ("tau", "0"),
        ("tau", "1.5"),
        ("lambda_tol", "0"),
        ("degree", "1"),
        ("degree", "8"),
    ] {
        assert!(
            fair("cali", &open, &FairOptions::default().with_param(k, v)).is_err(),
            "{k}={v}"
        );
    }
    assert!(matches!(
        fair(
            "cali",
            &open,
            &FairOptions::default().with_param("bogus", 1)
        ),
        Err(Error::UnknownOption { .. })
    ));
    // Degree 2 and 4 run; the parameters used are reported.
    for degree in [2, 4] {
        let out = fair(
            "cali",
            &open,
            &FairOptions::default().with_param("degree", degree),
        )
        .expect("fair");
        assert_eq!(out.report.parameters["degree"], degree);
        assert!(out.report.after.max_curvature.is_finite());
    }
    // max_iterations bounds the accepted moves; fix_ends changes nothing (ends always fixed).
    let a = fair(
        "cali",
        &open,
        &FairOptions::default().with_max_iterations(3),
    )
    .expect("fair");
    assert_eq!(a.report.moves.len(), 3);
    assert_eq!(a.report.status, FairStatus::IterationLimit);
    let b = fair("cali", &open, &FairOptions::default().with_fix_ends(true)).expect("fair");
    let c = fair("cali", &open, &FairOptions::default()).expect("fair");
    assert_eq!(b.points, c.points);
}

#[test]
fn tolerance_limits_moves() {
    let pts = noisy_strophoid(0.02, 5);
    let input = PointSeq::open(pts).expect("points");
    let free = fair("cali", &input, &FairOptions::default()).expect("fair");
    let tol = 0.3 * free.report.max_displacement;
    let bound = fair("cali", &input, &FairOptions::default().with_tolerance(tol)).expect("fair");
    assert!(bound.report.max_displacement <= tol);
    assert!(bound.report.tolerance_met);
    assert_eq!(bound.report.status, FairStatus::ToleranceLimited);
    assert!(bound.report.history.last().expect("history").measure >= free.report.after_gfi());
}

/// The GFI of a report's last history row (a small helper so the test reads well).
trait AfterGfi {
    fn after_gfi(&self) -> f64;
}

impl AfterGfi for batten::FairReport {
    fn after_gfi(&self) -> f64 {
        self.history.last().map_or(f64::NAN, |h| h.measure)
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(8))]

    /// The tolerance is never exceeded (spec: a move beyond it is refused).
    #[test]
    fn tolerance_is_never_exceeded(
        seed in 0u64..1000,
        sigma in 0.005f64..0.05,
        n in 12usize..60,
        tol in 0.001f64..0.05,
    ) {
        let pts = noisy_sine(n, sigma, seed);
        let input = PointSeq::open(pts).expect("points");
        let out = fair("cali", &input, &FairOptions::default().with_tolerance(tol))
            .expect("fair");
        prop_assert!(out.report.max_displacement <= tol);
        prop_assert!(out.report.tolerance_met);
        for h in &out.report.history {
            prop_assert!(h.max_distance <= tol);
        }
    }
}
