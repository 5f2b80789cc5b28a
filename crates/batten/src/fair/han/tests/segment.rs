//! Each case removes its pattern (constructed examples); one segment's fairing.

use super::*;

/// Solve a small dense system by Gaussian elimination with partial pivoting.
fn dense_solve(mut m: Vec<Vec<f64>>, mut rhs: Vec<f64>) -> Vec<f64> {
    let n = rhs.len();
    for col in 0..n {
        let p = (col..n)
            .max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))
            .unwrap();
        m.swap(col, p);
        rhs.swap(col, p);
        for r in col + 1..n {
            let f = m[r][col] / m[col][col];
            for k in col..n {
                m[r][k] -= f * m[col][k];
            }
            rhs[r] -= f * rhs[col];
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|k| m[r][k] * x[k]).sum();
        x[r] = (rhs[r] - s) / m[r][r];
    }
    x
}

/// y (ends 0) on x whose interior c, or e, equals `target`, built from the unit responses.
///
/// The map y → c is invertible. The map y → e is not: with `c_1 = c_2` and `c_{n−1} = c_n`,
/// the third derivative vanishes on both end intervals, so its jumps sum to zero (Σ e_i = 0),
/// and the parabola through the two (zero) ends has e = 0. So an e target must sum to zero;
/// the last equation is dropped (it is implied) and `y_2 = 0` pins the parabola.
fn y_with(x: &[f64], target: &[f64], of_e: bool) -> Vec<f64> {
    let n = x.len();
    let r = UnitResponses::new(x).unwrap();
    let (m, rhs): (Vec<Vec<f64>>, Vec<f64>) = if of_e {
        assert!(
            target.iter().sum::<f64>().abs() < 1e-12,
            "e target must sum to zero"
        );
        let mut m: Vec<Vec<f64>> = (1..n - 2)
            .map(|i| (1..n - 1).map(|j| r.e(i, j)).collect())
            .collect();
        let mut pin = vec![0.0; n - 2];
        pin[0] = 1.0;
        m.push(pin);
        let mut rhs = target[1..n - 2].to_vec();
        rhs.push(0.0);
        (m, rhs)
    } else {
        let m = (1..n - 1)
            .map(|i| (1..n - 1).map(|j| r.c(i, j)).collect())
            .collect();
        (m, target[1..n - 1].to_vec())
    };
    let g = dense_solve(m, rhs);
    let mut y = vec![0.0; n];
    y[1..n - 1].copy_from_slice(&g);
    // The construction reproduces the target.
    let seg = Segment::new(x.to_vec(), y.clone()).unwrap();
    let got = if of_e { seg.e() } else { seg.c() };
    for (a, b) in got.iter().zip(target) {
        assert!((a - b).abs() < 1e-9, "constructed {a} for target {b}");
    }
    y
}

fn grid(n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| i as f64 + 0.3 * (i as f64 * 1.7).sin())
        .collect()
}

#[test]
fn coarse_case1_damps_and_with_lambda_one_removes() {
    let x = grid(12);
    let target = [
        0.0, 1.5, 1.5, 1.5, 1.5, -1.0, -1.0, -1.0, -1.0, -1.0, -1.0, 0.0,
    ];
    let seg0 = Segment::new(x.clone(), y_with(&x, &target, true)).unwrap();
    assert_eq!(seg0.vibration_count(), 1);
    let before = seg0.e()[4] * seg0.e()[5];
    // λ_c = 0.8 damps the vibration: both values shrink, the sign change stays.
    let mut seg = seg0.clone();
    let moves = seg.coarse_case1();
    assert_eq!(moves.len(), 1);
    assert_eq!(
        (moves[0].tag, moves[0].i, moves[0].start),
        (MoveTag::C1, 4, 4)
    );
    let after = seg.e()[4] * seg.e()[5];
    assert!(after < 0.0 && after.abs() < before.abs());
    let g = moves[0].gammas();
    assert!((g[0] + g[1]).abs() <= 1e-15 * g[0].abs());
    // λ_c = 1 removes it: one of the pair becomes zero.
    let mut seg = seg0
        .with_params(SegmentParams::DEFAULT.with_lambda_coarse(1.0))
        .unwrap();
    assert_eq!(seg.coarse_case1().len(), 1);
    assert!(seg.e()[4].abs().min(seg.e()[5].abs()) < 1e-12);
    assert_eq!(seg.vibration_count(), 0);
}

#[test]
fn coarse_case2_zeroes_an_isolated_indicator() {
    let x = grid(11);
    let target = vec![0.0, 1.0, 1.0, 1.0, 1.0, -8.0, 1.0, 1.0, 1.0, 1.0, 0.0];
    let mut seg = Segment::new(x.clone(), y_with(&x, &target, true)).unwrap();
    assert_eq!(seg.vibration_count(), 2);
    let moves = seg.coarse_case2();
    assert_eq!(moves.len(), 1);
    assert_eq!((moves[0].tag, moves[0].i), (MoveTag::C2, 5));
    assert!(seg.e()[5].abs() < 1e-12);
    // Σ e_i = 0 for HAN's end condition (the third derivative vanishes on both end
    // intervals), so the other values absorb the change; the isolated sign at 5 is gone.
    assert!(seg.e().iter().sum::<f64>().abs() < 1e-12);
    assert!(seg.coarse_case2().iter().all(|m| m.i != 5));
}

#[test]
fn coarse_case2_end_rule() {
    let x = grid(11);
    let target = vec![0.0, -8.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 0.0];
    let mut seg = Segment::new(x.clone(), y_with(&x, &target, true)).unwrap();
    let moves = seg.coarse_case2();
    assert_eq!(moves.len(), 1);
    assert_eq!((moves[0].tag, moves[0].i), (MoveTag::C2End, 1));
    assert!(seg.e()[1].abs() < 1e-12);
}

#[test]
fn coarse_case3_zeroes_a_pair() {
    let x = grid(12);
    let target = vec![0.0, 1.0, 1.0, 1.0, 1.0, -4.0, -4.0, 1.0, 1.0, 1.0, 1.0, 0.0];
    let mut seg = Segment::new(x.clone(), y_with(&x, &target, true)).unwrap();
    let moves = seg.coarse_case3();
    assert_eq!(moves.len(), 1);
    assert_eq!((moves[0].tag, moves[0].i), (MoveTag::C3, 5));
    assert!(seg.e()[5].abs() < 1e-12 && seg.e()[6].abs() < 1e-12);
    assert!(seg.coarse_case3().iter().all(|m| m.i != 5));
    // Mirrored end rule.
    let target = vec![0.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, -4.0, -4.0, 0.0];
    let mut seg = Segment::new(x.clone(), y_with(&x, &target, true)).unwrap();
    let moves = seg.coarse_case3();
    assert_eq!(moves.len(), 1);
    assert_eq!(
        (moves[0].tag, moves[0].i, moves[0].start),
        (MoveTag::C3End, 10, 9)
    );
    assert!(seg.e()[9].abs() < 1e-12 && seg.e()[10].abs() < 1e-12);
}

#[test]
fn fine_case1_removes_an_isolated_sign() {
    let x = grid(12);
    let target = vec![1.0, 1.0, 1.0, 1.0, 1.0, -0.3, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0];
    let seg0_y = y_with(&x, &target, false);
    let mut seg = Segment::new(x.clone(), seg0_y.clone()).unwrap();
    assert_eq!(seg.inflection_count(), 2);
    let moves = seg.fine_case1();
    assert!(!moves.is_empty() && moves.iter().all(|m| m.tag == MoveTag::F1 && m.i == 5));
    assert_eq!(seg.inflection_count(), 0);
    // The neighbours kept their sign, so c_i ends at α = 0.2 × the smaller neighbour.
    assert_eq!(moves.len(), 2);
    // Rebuild the state after the first move to get the neighbours the α rule saw.
    let mut y1 = seg0_y.clone();
    for (p, g) in moves[0].points().zip(moves[0].gammas()) {
        y1[p] += g;
    }
    let mid = Segment::new(x.clone(), y1).unwrap();
    let (l, r) = (mid.c()[4], mid.c()[6]);
    assert!(l > 0.0 && r > 0.0);
    let v = if r.abs() < l.abs() { r } else { l };
    assert!((seg.c()[5] - 0.2 * v).abs() < 1e-12);
    assert!((moves[1].after - 0.2 * v).abs() < 1e-12);
    // Pattern: the outer points move opposite to the middle one, scaled by λ_f.
    let g = moves[0].gammas();
    assert!((g[0] + 0.75 * g[1]).abs() <= 1e-14 * g[1].abs());
    assert!((g[0] - g[2]).abs() <= 1e-14 * g[1].abs());
}

#[test]
fn fine_case2_removes_a_pair() {
    let x = grid(12);
    let target = vec![1.0, 1.0, 1.0, 1.0, -0.4, -0.4, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0];
    let mut seg = Segment::new(x.clone(), y_with(&x, &target, false)).unwrap();
    assert_eq!(seg.inflection_count(), 2);
    let moves = seg.fine_case2();
    assert!(!moves.is_empty() && moves.iter().all(|m| m.tag == MoveTag::F2 && m.i == 4));
    assert_eq!(seg.inflection_count(), 0);
    // End rule: c_1 = c_2 opposite to c_3, c_4.
    let target = vec![-0.5, -0.5, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0];
    let mut seg = Segment::new(x.clone(), y_with(&x, &target, false)).unwrap();
    let moves = seg.fine_case2();
    assert_eq!(moves.len(), 1);
    assert_eq!((moves[0].tag, moves[0].i), (MoveTag::F2End, 1));
    assert!(seg.c()[0].abs() < 1e-12 && seg.c()[1].abs() < 1e-12);
}

#[test]
fn segment_is_reflection_invariant() {
    // y → −y mirrors every move (the α rule is symmetric, docs/algorithms/han.md §1.7.2).
    let v = vector("han.fair_segment.noisy_sine");
    let x = arr(&v["inputs"]["x"]);
    let y = arr(&v["inputs"]["y"]);
    // With and without fine case 3 (its α rule is the same).
    for run3 in [false, true] {
        let params = SegmentParams::DEFAULT.with_fine_run3(run3);
        let seg = |y: Vec<f64>| {
            Segment::new(x.clone(), y)
                .unwrap()
                .with_params(params)
                .unwrap()
        };
        let mut a = seg(y.clone());
        let mut b = seg(y.iter().map(|v| -v).collect());
        let mut f3 = 0;
        a.fair(10, |m| f3 += usize::from(m.tag == MoveTag::F3));
        b.fair(10, |_| {});
        assert_eq!(f3 > 0, run3, "fine case 3 moves: {f3}");
        for (p, q) in a.y().iter().zip(b.y()) {
            assert!((p + q).abs() < 1e-12, "fine_run3 = {run3}");
        }
    }
}

#[test]
fn segment_bounds_are_never_left() {
    let v = vector("han.fair_segment.noisy_sine");
    let x = arr(&v["inputs"]["x"]);
    let y = arr(&v["inputs"]["y"]);
    let d = 0.01;
    let lo: Vec<f64> = y.iter().map(|v| v - d).collect();
    let hi: Vec<f64> = y.iter().map(|v| v + d).collect();
    let mut seg = Segment::new(x, y.clone())
        .unwrap()
        .with_params(SegmentParams::DEFAULT.with_fine_run3(true))
        .unwrap()
        .with_bounds(lo, hi)
        .unwrap();
    let mut scaled = 0;
    seg.fair(10, |m| {
        if m.scale < 1.0 {
            scaled += 1;
        }
    });
    assert!(scaled > 0 && seg.was_limited());
    for (a, b) in seg.y().iter().zip(&y) {
        // The bound y ± d is itself rounded.
        assert!((a - b).abs() <= d * (1.0 + 1e-12));
    }
    assert_eq!(seg.y()[0], y[0]);
    assert_eq!(seg.y()[y.len() - 1], y[y.len() - 1]);
}

#[test]
fn segment_errors() {
    assert_eq!(
        Segment::new(vec![0.0, 1.0, 2.0, 3.0], vec![0.0; 4]).err(),
        Some(Error::TooFewPoints { needed: 5, got: 4 })
    );
    assert_eq!(
        Segment::new(vec![0.0, 1.0, 2.0, 2.0, 3.0], vec![0.0; 5]).err(),
        Some(Error::NotIncreasing { index: 3 })
    );
    let seg = Segment::new(vec![0.0, 1.0, 2.0, 3.0, 4.0], vec![0.0; 5]).unwrap();
    assert!(
        seg.clone()
            .with_params(SegmentParams::DEFAULT.with_lambda_fine(f64::NAN))
            .is_err()
    );
    assert!(seg.with_bounds(vec![0.1; 5], vec![1.0; 5]).is_err());
}

/// A dense sine segment `x = off + i·h`, `y = off + sin((x − off)/2)`: its c and e carry the
/// rounding of coordinates of magnitude `off` and nothing else worth fairing.
fn clean_dense_segment(n: usize, off: f64) -> Segment {
    let h = 12.0 * PI / n as f64;
    let x: Vec<f64> = (0..n).map(|i| off + i as f64 * h).collect();
    let y: Vec<f64> = x.iter().map(|&v| off + ((v - off) / 2.0).sin()).collect();
    Segment::new(x, y).unwrap()
}

#[test]
fn rounding_noise_is_not_faired() {
    // 20 000 samples at an offset of 1000: e is rounding noise (≈ 0.3 against a signal of
    // ≈ 1e-6) and c is noise near the 5 true inflections. The floors count both as 0.
    let mut seg = clean_dense_segment(20_000, 1000.0);
    let noise = seg
        .e()
        .iter()
        .zip(seg.e_floor())
        .skip(50)
        .take(19_900)
        .map(|(e, f)| e.abs() / f)
        .fold(0.0_f64, f64::max);
    assert!(noise > 1e-4 && noise < 1.0, "largest |e| / floor = {noise}");
    // Han's count takes strict sign changes only: an inflection whose nearest c is below the
    // floor is not counted.
    let inflections = seg.inflection_count();
    assert!((4..=5).contains(&inflections), "{inflections}");
    assert_eq!(seg.vibration_count(), 0);
    let y0 = seg.y().to_vec();
    let mut moves = 0;
    assert_eq!(seg.fair(10, |_| moves += 1), 0);
    assert_eq!(moves, 0);
    assert_eq!(seg.y(), &y0[..]);

    // The floors only filter rounding: noise of 1e-9 (10⁶ times the rounding of 1000) is
    // faired as before.
    let base = clean_dense_segment(20_000, 1000.0);
    let mut state = 7_u64;
    let y: Vec<f64> = base
        .y()
        .iter()
        .map(|v| {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
            v + 1e-9 * ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5)
        })
        .collect();
    let mut noisy = Segment::new(base.x().to_vec(), y).unwrap();
    let before = noisy.vibration_count();
    assert!(before > 1000, "{before} vibrations");
    assert!(noisy.fair(3, |_| {}) > 0);
    assert!(noisy.vibration_count() < before);
}

#[test]
fn coordinate_scale_raises_the_floors() {
    let seg = clean_dense_segment(1000, 0.0);
    let raised = seg.clone().with_coordinate_scale(1e7);
    for (a, b) in seg.c_floor().iter().zip(raised.c_floor()) {
        assert!(*b > 1e5 * a);
    }
    // Ignored: not finite, or not above the segment's own coordinates.
    assert_eq!(
        seg.clone().with_coordinate_scale(f64::NAN).c_floor(),
        seg.c_floor()
    );
    assert_eq!(
        seg.clone().with_coordinate_scale(1e-3).e_floor(),
        seg.e_floor()
    );
}

#[test]
fn clean_dense_curve_is_left_alone() {
    // A clean circle of 20 000 points far from the origin: han makes no move at all. (Its c
    // in a bisector frame is convex with no vibration of e; a spiral's is not, and han moves
    // a clean spiral a little.)
    let n = 20_000;
    let pts: Vec<Point> = (0..n)
        .map(|i| {
            let a = i as f64 * 1.9 * PI / n as f64;
            Point::new(500.0 + 3.0 * a.cos(), -300.0 + 3.0 * a.sin())
        })
        .collect();
    let input = PointSeq::open(pts.clone()).unwrap();
    let out = fair::fair("han", &input, &FairOptions::default()).unwrap();
    assert_eq!(out.report.status, FairStatus::NoChange);
    assert_eq!(out.points, pts);
}
