//! The case vectors: each case procedure against the paper's numbers.

use super::*;

fn check_moves(id: &str, got: &[CaseMove], want: &Value, t: Tol) {
    let want = want.as_array().unwrap();
    assert_eq!(got.len(), want.len(), "{id}: number of moves {got:?}");
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert_eq!(
            g.tag.as_str(),
            w["tag"].as_str().unwrap(),
            "{id}: tag of move {k}"
        );
        assert_eq!(
            g.i + 1,
            w["i"].as_u64().unwrap() as usize,
            "{id}: i of move {k}"
        );
        let wg: BTreeMap<usize, f64> = w["gammas"]
            .as_object()
            .unwrap()
            .iter()
            .map(|(p, v)| (p.parse::<usize>().unwrap(), v.as_f64().unwrap()))
            .collect();
        let gg: BTreeMap<usize, f64> = g
            .points()
            .zip(g.gammas())
            .map(|(p, v)| (p + 1, *v))
            .collect();
        assert_eq!(
            gg.keys().collect::<Vec<_>>(),
            wg.keys().collect::<Vec<_>>(),
            "{id}: points"
        );
        for (p, w) in &wg {
            check(&format!("{id}: move {k} gamma at {p}"), gg[p], *w, t);
        }
        assert_eq!(g.scale, 1.0);
    }
}

fn run_case_vector(id: &str, procedure: Procedure) {
    let v = vector(id);
    let t = tol(&v);
    let mut seg = Segment::new(arr(&v["inputs"]["x"]), arr(&v["inputs"]["y"])).unwrap();
    let moves = match procedure {
        Procedure::CoarseCase1 => seg.coarse_case1(),
        Procedure::CoarseCase2 => seg.coarse_case2(),
        Procedure::CoarseCase3 => seg.coarse_case3(),
        Procedure::FineCase1 => seg.fine_case1(),
        Procedure::FineCase2 => seg.fine_case2(),
        Procedure::FineCase3 => seg.fine_case3(),
    };
    let ex = &v["expected"];
    check_moves(id, &moves, &ex["moves_in_order"], t);
    check_all(&format!("{id}: y"), seg.y(), &arr(&ex["y_after"]), t);
    check_all(&format!("{id}: c"), seg.c(), &arr(&ex["c_after"]), t);
    check_all(&format!("{id}: e"), seg.e(), &arr(&ex["e_after"]), t);
    // The incrementally updated c and e equal a fresh solve.
    let fresh = CubicSplineFn::new(seg.x().to_vec(), seg.y().to_vec(), FnEndCondition::Han);
    check_all(
        &format!("{id}: c vs solve"),
        seg.c(),
        fresh.c(),
        Tol {
            abs: 1e-13,
            rel: 1e-12,
        },
    );
    check_all(
        &format!("{id}: e vs solve"),
        seg.e(),
        &fresh.indicator(),
        Tol {
            abs: 1e-12,
            rel: 1e-11,
        },
    );
}

#[test]
fn vector_case_coarse_case1() {
    run_case_vector("han.case.coarse_case1.first", Procedure::CoarseCase1);
}

#[test]
fn vector_case_coarse_case2() {
    run_case_vector("han.case.coarse_case2.C2", Procedure::CoarseCase2);
}

#[test]
fn vector_case_coarse_case2_end() {
    run_case_vector("han.case.coarse_case2.C2end", Procedure::CoarseCase2);
}

#[test]
fn vector_case_coarse_case3() {
    run_case_vector("han.case.coarse_case3.C3", Procedure::CoarseCase3);
}

#[test]
fn vector_case_coarse_case3_end() {
    run_case_vector("han.case.coarse_case3.C3end", Procedure::CoarseCase3);
}

#[test]
fn vector_case_fine_case1() {
    run_case_vector("han.case.fine_case1.F1", Procedure::FineCase1);
}

#[test]
fn vector_case_fine_case2() {
    run_case_vector("han.case.fine_case2.F2", Procedure::FineCase2);
}

#[test]
fn vector_case_fine_case2_end() {
    run_case_vector("han.case.fine_case2.F2end", Procedure::FineCase2);
}

/// Second differences with a three-point run of the other sign: y'' > 0 everywhere except
/// points `run..run+3`, which bend the other way.
fn three_point_run(n: usize, run: usize) -> (Vec<f64>, Vec<f64>) {
    let x: Vec<f64> = (0..n).map(|i| i as f64 * 0.5).collect();
    let mut y = vec![0.0; n];
    let mut slope = -1.0;
    for i in 1..n {
        let d = if (run..run + 3).contains(&i) {
            -0.05
        } else {
            0.1
        };
        slope += d;
        y[i] = y[i - 1] + slope * 0.5;
    }
    (x, y)
}

/// The maximal runs of one strict sign of `c` (`sgn0`), as (first index, length, sign).
fn sign_runs(c: &[f64]) -> Vec<(usize, usize, i8)> {
    let scale = c.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let mut runs: Vec<(usize, usize, i8)> = Vec::new();
    for (i, v) in c.iter().enumerate() {
        let s = crate::analysis::sgn0(*v, scale);
        match runs.last_mut() {
            Some(r) if r.2 == s => r.1 += 1,
            _ => runs.push((i, 1, s)),
        }
    }
    runs
}

#[test]
fn fine_case3_removes_a_three_point_run_that_the_paper_cases_leave() {
    let (x, y) = three_point_run(24, 10);
    let seg = Segment::new(x, y).unwrap();
    let runs = sign_runs(seg.c());
    assert!(
        runs.iter().any(|r| r.1 == 3 && r.2 < 0),
        "no three-point run to remove: {runs:?}"
    );
    // The paper's fine cases do not touch it.
    let mut paper = seg.clone();
    assert!(paper.fine_case1().is_empty());
    assert!(paper.fine_case2().is_empty());
    assert_eq!(paper.inflection_count(), 2);
    // Fine case 3 moves y_{i−1}..y_{i+3} and removes both inflections.
    let mut ext = seg.clone();
    let moves = ext.fine_case3();
    assert!(!moves.is_empty());
    for m in &moves {
        assert_eq!(m.tag, MoveTag::F3);
        assert_eq!(m.tag.as_str(), "F3");
        assert_eq!(m.gammas().len(), 5);
        let g = m.gammas();
        let lf = ext.params().lambda_fine;
        assert!((g[0] + lf * g[1]).abs() <= 1e-12 * g[1].abs());
        assert!((g[4] + lf * g[3]).abs() <= 1e-12 * g[3].abs());
    }
    // The run is set to c = 0 (α = 0; its neighbours changed sign, so no α step). Moving the
    // outer points leaves single opposite signs beside it, which fine case 1 removes in the
    // next iteration.
    let first = moves[0].i;
    let scale = ext.c().iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    for k in first..first + 3 {
        assert!(ext.c()[k].abs() <= 1e-12 * scale, "c[{k}] = {}", ext.c()[k]);
    }
    assert!(!seg.params().fine_run3, "off in a Segment unless asked for");
    // Whole runs of the method on noisy sines as in `bench/compare_peers.py` (65 points,
    // σ = 3 % of a tenth of the diagonal, tolerance 3σ): with fine case 3 (the default) fewer
    // inflections are left than with the paper's cases alone.
    let sigma = 0.038;
    let on_opts = FairOptions::default().with_tolerance(3.0 * sigma);
    let paper = on_opts.clone().with_param("fine_run3", "false");
    let (mut with, mut without) = (0, 0);
    for seed in 1..=20 {
        let input = PointSeq::open(noisy_sine_curve(65, sigma, seed)).unwrap();
        let on = fair::fair("han", &input, &on_opts).unwrap();
        let off = fair::fair("han", &input, &paper).unwrap();
        assert_eq!(on.report.parameters["fine_run3"], true);
        assert_eq!(off.report.parameters["fine_run3"], false);
        with += on.report.after.inflections;
        without += off.report.after.inflections;
    }
    assert!(
        with < without,
        "{with} inflections with fine case 3, {without} without"
    );
}

#[test]
fn every_case_vector_is_covered() {
    let covered = [
        "han.case.coarse_case1.first",
        "han.case.coarse_case2.C2",
        "han.case.coarse_case2.C2end",
        "han.case.coarse_case3.C3",
        "han.case.coarse_case3.C3end",
        "han.case.fine_case1.F1",
        "han.case.fine_case2.F2",
        "han.case.fine_case2.F2end",
    ];
    for v in vectors() {
        let id = v["id"].as_str().unwrap();
        if id.starts_with("han.case.") {
            assert!(covered.contains(&id), "case vector {id} has no test");
        }
    }
}

#[test]
fn vector_fair_segment_noisy_sine() {
    let v = vector("han.fair_segment.noisy_sine");
    let t = tol(&v);
    let iterations = v["inputs"]["iterations"].as_u64().unwrap() as usize;
    let mut seg = Segment::new(arr(&v["inputs"]["x"]), arr(&v["inputs"]["y"])).unwrap();
    let ex = &v["expected"];
    let counts = |s: &Segment| vec![s.inflection_count() as f64, s.vibration_count() as f64];
    assert_eq!(counts(&seg), arr(&ex["infl_vib_before"]));
    let mut moves = 0;
    seg.fair(iterations, |_| moves += 1);
    assert!(moves > 0);
    assert_eq!(counts(&seg), arr(&ex["infl_vib_after"]));
    check_all("y", seg.y(), &arr(&ex["y_after"]), t);
    let fresh = CubicSplineFn::new(seg.x().to_vec(), seg.y().to_vec(), FnEndCondition::Han);
    check_all(
        "c vs solve",
        seg.c(),
        fresh.c(),
        Tol {
            abs: 1e-13,
            rel: 1e-12,
        },
    );
}
