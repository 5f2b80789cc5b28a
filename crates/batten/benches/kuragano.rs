//! Kuragano & Yamaguchi (docs/algorithms/kuragano.md §5): uniform quintic interpolation (eq 8 with
//! natural ends, eq 8 + eq 9 with four end gradients, and least squares with a gradient at every
//! point) at n = 10³ … 10⁵ points, and the `kuragano` method (interpolant, ρ samples, degree-3
//! specification, Levenberg–Marquardt shape modification) at 10² … 10³ points.
//!
//! Run: `cargo bench -p batten --bench kuragano -- --warm-up-time 1 --measurement-time 3`

#![allow(clippy::unwrap_used)]

mod common;

use std::hint::black_box;

use batten::fair::{FairMethod, Kuragano};
use batten::spline::{
    QuinticEnds, QuinticForm, interpolate_quintic, interpolate_quintic_hermite,
    quintic_end_gradients,
};
use batten::{FairOptions, Point, PointSeq, Vec2};
use common::noisy_spiral;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};

const INTERPOLATION_SIZES: [usize; 3] = [1_000, 10_000, 100_000];
const MODIFICATION_SIZES: [usize; 3] = [100, 300, 1_000];

/// Levenberg–Marquardt linearisations per shape-modification run in the bench: a fixed count,
/// so the figure is a cost per iteration times this.
const LM_ITERATIONS: usize = 20;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("kuragano_interpolate");
    g.sample_size(10);
    for n in INTERPOLATION_SIZES {
        let pts = noisy_spiral(n, 3.0, 0.01);
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::new("natural", n), &n, |b, _| {
            b.iter(|| {
                interpolate_quintic(black_box(&pts), &QuinticEnds::Natural, QuinticForm::BSpline)
            })
        });
        let grads = quintic_end_gradients(&pts, 1.0).unwrap();
        let ends = QuinticEnds::Gradients(grads);
        g.bench_with_input(BenchmarkId::new("gradients", n), &n, |b, _| {
            b.iter(|| interpolate_quintic(black_box(&pts), &ends, QuinticForm::BSpline))
        });
        let every: Vec<Vec2> = pts
            .windows(2)
            .map(|w| w[1] - w[0])
            .chain(std::iter::once(pts[n - 1] - pts[n - 2]))
            .collect();
        g.bench_with_input(BenchmarkId::new("hermite_least_squares", n), &n, |b, _| {
            b.iter(|| interpolate_quintic_hermite(black_box(&pts), &every, QuinticForm::BSpline))
        });
    }
    // Degenerate input: collinear points (every end-condition right-hand side is zero).
    let line: Vec<Point> = (0..100_000)
        .map(|i| Point::new(i as f64, 2.0 * i as f64))
        .collect();
    g.bench_function("natural_collinear/100000", |b| {
        b.iter(|| {
            interpolate_quintic(
                black_box(&line),
                &QuinticEnds::Natural,
                QuinticForm::BSpline,
            )
        })
    });
    g.finish();

    let mut g = c.benchmark_group("kuragano_modify");
    g.sample_size(10);
    for n in MODIFICATION_SIZES {
        let seq = PointSeq::open(noisy_spiral(n, 3.0, 1e-3)).unwrap();
        let opts = FairOptions::default()
            .with_param("degree", 3)
            .with_max_iterations(LM_ITERATIONS);
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::new("degree3_20_iterations", n), &n, |b, _| {
            b.iter(|| Kuragano.run(black_box(&seq), &opts).unwrap())
        });
    }
    // Degenerate input: a straight line has no applicable degree; the method returns at once.
    let line = PointSeq::open(
        (0..1_000)
            .map(|i| Point::new(i as f64, 0.5 * i as f64))
            .collect(),
    )
    .unwrap();
    g.bench_function("straight_auto/1000", |b| {
        b.iter(|| {
            Kuragano
                .run(black_box(&line), &FairOptions::default())
                .unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
