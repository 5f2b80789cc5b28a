//! The spline function and the unit responses: test vectors and properties.

use super::*;

#[test]
fn vector_spline_function_coefficients() {
    let v = vector("han.spline_function.coefficients");
    let t = tol(&v);
    let s = CubicSplineFn::try_new(
        arr(&v["inputs"]["x"]),
        arr(&v["inputs"]["y"]),
        FnEndCondition::Han,
    )
    .unwrap();
    let ex = &v["expected"];
    check_all("c", s.c(), &arr(&ex["c"]), t);
    check_all("a", s.forward_a(), &arr(&ex["a"]), t);
    check_all("b", s.forward_b(), &arr(&ex["b"]), t);
    check_all("a*", s.backward_a(), &arr(&ex["a_star"]), t);
    check_all("b*", s.backward_b(), &arr(&ex["b_star"]), t);
    check_all("e", &s.indicator(), &arr(&ex["e"]), t);
    for j in 1..s.len() - 1 {
        check("eq 9", s.c_explicit(j), s.c()[j], t);
    }
}

fn check_response_matrix(x: &[f64], rows: &Value, t: Tol) -> UnitResponses {
    let r = UnitResponses::new(x).unwrap();
    let n = x.len();
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), n);
    for (i, row) in rows.iter().enumerate() {
        let row = arr(row);
        assert_eq!(row.len(), n - 2);
        for (k, want) in row.iter().enumerate() {
            let j = k + 1;
            check(&format!("c~[{i}][{j}]"), r.c(i, j), *want, t);
            check(&format!("column c~^{j}[{i}]"), r.column_c(j)[i], *want, t);
        }
    }
    r
}

#[test]
fn vector_unit_responses_nonuniform() {
    let v = vector("han.unit_spline_responses.nonuniform");
    let t = tol(&v);
    let x = arr(&v["inputs"]["x"]);
    let r = check_response_matrix(&x, &v["expected"]["C_rows_i_cols_j_2_to_nm1"], t);
    check(
        "eq 14 corrected at j = 2",
        r.c(1, 1),
        v["expected"]["eq14_corrected_j2"].as_f64().unwrap(),
        Tol {
            abs: 1e-11,
            rel: 1e-11,
        },
    );
    // The printed eq 14 (a_1 = −1 in the numerator) gives the documented wrong value.
    let s = CubicSplineFn::new(x.clone(), vec![0.0; x.len()], FnEndCondition::Han);
    let (h, a, a_star) = (s.h(), s.forward_a(), s.backward_a());
    let den = 2.0 * (h[0] + h[1]) - a[0] * h[0] - a_star[1] * h[1];
    let printed = -((1.0 + a[0]) / h[0] + (1.0 + a_star[1]) / h[1]) / den;
    let wrong = v["expected"]["eq14_printed_literal_j2_WRONG"]
        .as_f64()
        .unwrap();
    check(
        "printed eq 14",
        printed,
        wrong,
        Tol {
            abs: 1e-11,
            rel: 1e-11,
        },
    );
    assert!((printed - r.c(1, 1)).abs() > 0.1);
}

#[test]
fn vector_unit_responses_uniform9() {
    let v = vector("han.unit_spline_responses.uniform9");
    let t = tol(&v);
    let x = arr(&v["inputs"]["x"]);
    check_response_matrix(&x, &v["expected"]["C_rows_i_cols_j_2_to_nm1"], t);
    let s = CubicSplineFn::new(x.clone(), vec![0.0; x.len()], FnEndCondition::Han);
    check_all("a", s.forward_a(), &arr(&v["expected"]["a_1_to_8"]), t);
    assert!((s.forward_a()[7] - (2.0 - 3f64.sqrt())).abs() < 1e-6);
}

fn random_grid(rng: &mut Rng, n: usize) -> Vec<f64> {
    let mut x = vec![rng.uniform(-2.0, 2.0)];
    for _ in 1..n {
        let last = x[x.len() - 1];
        x.push(last + rng.uniform(0.05, 3.0));
    }
    x
}

/// The property vector `han.unit_spline_responses.properties`, on 300 random grids.
#[test]
fn unit_response_properties() {
    let v = vector("han.unit_spline_responses.properties");
    assert_eq!(v["expected"]["property_test"], Value::Bool(true));
    let mut rng = Rng::new(7);
    for _ in 0..300 {
        let n = 5 + (rng.next_u64() % 20) as usize;
        let x = random_grid(&mut rng, n);
        let s = CubicSplineFn::new(x.clone(), vec![0.0; n], FnEndCondition::Han);
        for i in 1..n - 1 {
            assert!(s.forward_a()[i] > 0.0 && s.forward_a()[i] < 0.5);
            assert!(s.backward_a()[i - 1] > 0.0 && s.backward_a()[i - 1] < 0.5);
        }
        let r = UnitResponses::from_spline(&s).unwrap();
        for j in 1..n - 1 {
            let col = r.column_c(j);
            let ecol = r.column_e(j);
            assert_eq!(col[0], col[1], "c~_1 = c~_2");
            assert_eq!(col[n - 1], col[n - 2], "c~_n = c~_(n-1)");
            for i in 1..n - 1 {
                let d = i.abs_diff(j);
                // sgn c~_i^j = (−1)^(|i−j|+1), sgn e~_i^j = (−1)^|i−j| (observation 2).
                let sign = if d % 2 == 0 { -1.0 } else { 1.0 };
                assert!(col[i] * sign > 0.0, "sign of c~[{i}][{j}]");
                assert!(ecol[i] * sign < 0.0, "sign of e~[{i}][{j}]");
                // Decay: |c~_i| ≤ 2^−(|i−j|−1) |c~_{j∓1}|.
                if d >= 2 {
                    let near = if i < j { col[j - 1] } else { col[j + 1] };
                    let bound = near.abs() * 0.5f64.powi(d as i32 - 1);
                    assert!(col[i].abs() <= bound * (1.0 + 1e-12), "decay at [{i}][{j}]");
                }
                assert_eq!(col[i], r.c(i, j));
                assert!((ecol[i] - r.e(i, j)).abs() <= 1e-12 * ecol[i].abs().max(1e-300));
            }
        }
        // Eq 13 is exact: c(y + γ) = c(y) + Σ γ_j c~^j.
        let y: Vec<f64> = (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let gamma: Vec<f64> = (0..n)
            .map(|k| {
                if k == 0 || k == n - 1 {
                    0.0
                } else {
                    rng.uniform(-0.5, 0.5)
                }
            })
            .collect();
        let base = CubicSplineFn::new(x.clone(), y.clone(), FnEndCondition::Han);
        let moved: Vec<f64> = y.iter().zip(&gamma).map(|(a, b)| a + b).collect();
        let direct = CubicSplineFn::new(x.clone(), moved, FnEndCondition::Han);
        let scale = direct.c().iter().fold(0.0_f64, |m, c| m.max(c.abs()));
        for i in 0..n {
            let sum: f64 = (1..n - 1).map(|j| gamma[j] * r.c(i, j)).sum();
            assert!((base.c()[i] + sum - direct.c()[i]).abs() <= 1e-13 * scale);
        }
    }
}

/// c~^j against a direct solve of the spline through δ_j, on random grids.
#[test]
fn unit_responses_match_direct_solve() {
    let mut rng = Rng::new(11);
    for _ in 0..100 {
        let n = 5 + (rng.next_u64() % 40) as usize;
        let x = random_grid(&mut rng, n);
        let r = UnitResponses::new(&x).unwrap();
        for j in 1..n - 1 {
            let mut delta = vec![0.0; n];
            delta[j] = 1.0;
            let s = CubicSplineFn::new(x.clone(), delta, FnEndCondition::Han);
            let e = s.indicator();
            for i in 0..n {
                assert!((r.c(i, j) - s.c()[i]).abs() <= 1e-12 * (1.0 + s.c()[i].abs()));
                assert!((r.e(i, j) - e[i]).abs() <= 1e-12 * (1.0 + e[i].abs()));
            }
        }
    }
}

/// The local eq 13 update (`add_columns`) equals re-solving the perturbed spline.
#[test]
fn add_columns_matches_resolve() {
    let mut rng = Rng::new(3);
    for _ in 0..50 {
        let n = 8 + (rng.next_u64() % 200) as usize;
        let x = random_grid(&mut rng, n);
        let mut y: Vec<f64> = (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let r = UnitResponses::new(&x).unwrap();
        let mut c = CubicSplineFn::new(x.clone(), y.clone(), FnEndCondition::Han)
            .c()
            .to_vec();
        for _ in 0..20 {
            let len = 1 + (rng.next_u64() % 4) as usize;
            let start = 1 + (rng.next_u64() as usize) % (n - 1 - len);
            let g: Vec<f64> = (0..len).map(|_| rng.uniform(-0.3, 0.3)).collect();
            r.add_columns(start, &g, &mut c);
            for (k, gk) in g.iter().enumerate() {
                y[start + k] += gk;
            }
        }
        let direct = CubicSplineFn::new(x, y, FnEndCondition::Han);
        let scale = direct.c().iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for (a, b) in c.iter().zip(direct.c()) {
            assert!((a - b).abs() <= 1e-12 * scale, "{a} vs {b}");
        }
    }
}
