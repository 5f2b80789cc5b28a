//! Local fairing, `salvi` (Salvi & Várady) and `eck-hadenfeld`, on noisy cubic B-splines of
//! 10², 10³ and 10⁴ control points, a fixed 200 iterations each (one control point per
//! iteration). A call includes the set-up: curvature sampling and target smoothing for `salvi`
//! (N = max(200, 8 per span) samples), the Gram band for `eck-hadenfeld`.
//!
//! Run: `cargo bench -p batten --bench salvi`

mod common;

use std::hint::black_box;

use batten::Point;
use batten::fair::{EckHadenfeldParams, SalviParams, eck_hadenfeld_fair_curve, salvi_fair_curve};
use batten::spline::{BSplineCurve, KnotVector};
use common::uniform_noise;
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};

const SIZES: [usize; 3] = [100, 1_000, 10_000];

/// Iterations per run.
const ITERATIONS: usize = 200;

/// A clamped uniform cubic whose control points follow a sine, with a deterministic
/// pseudo-random wobble of ±0.03 on the interior points (spacing 0.5).
fn noisy_curve(n: usize) -> BSplineCurve {
    let mut uniform = uniform_noise();
    let mut noise = move || uniform() * 0.06;
    let pts = (0..n)
        .map(|i| {
            let x = i as f64 * 0.5;
            let p = Point::new(x, (x * 0.6).sin() * 1.5);
            if i == 0 || i + 1 == n {
                p
            } else {
                Point::new(p.x + noise(), p.y + noise())
            }
        })
        .collect();
    BSplineCurve::new(
        3,
        KnotVector::clamped_uniform(3, n).expect("knots"),
        pts,
        None,
    )
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("local_fairing");
    g.sample_size(10);
    let salvi_params = SalviParams::DEFAULT
        .with_tolerance(0.2)
        .with_max_iterations(ITERATIONS)
        .with_window(0);
    let eh_params = EckHadenfeldParams::DEFAULT
        .with_tolerance(0.2)
        .with_max_iterations(ITERATIONS)
        .with_min_rel_decrease(0.0);
    for n in SIZES {
        let curve = noisy_curve(n);
        g.bench_with_input(BenchmarkId::new("salvi", n), &n, |b, _| {
            b.iter(|| salvi_fair_curve(black_box(&curve), &salvi_params).expect("salvi"))
        });
        g.bench_with_input(BenchmarkId::new("eck-hadenfeld", n), &n, |b, _| {
            b.iter(|| eck_hadenfeld_fair_curve(black_box(&curve), &eh_params).expect("eh"))
        });
    }
    // Degenerate input: a straight line with one bumped control point (κ = 0 away from the
    // bump, so the target is mostly zero and most supports have nothing to gain).
    let n = 1_000;
    let mut pts: Vec<Point> = (0..n).map(|i| Point::new(i as f64 * 0.5, 0.0)).collect();
    pts[n / 2].y = 0.5;
    let line = BSplineCurve::new(
        3,
        KnotVector::clamped_uniform(3, n).expect("knots"),
        pts,
        None,
    );
    g.bench_function("salvi/line-bump-1000", |b| {
        b.iter(|| salvi_fair_curve(black_box(&line), &salvi_params).expect("salvi"))
    });
    g.bench_function("eck-hadenfeld/line-bump-1000", |b| {
        b.iter(|| eck_hadenfeld_fair_curve(black_box(&line), &eh_params).expect("eh"))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
