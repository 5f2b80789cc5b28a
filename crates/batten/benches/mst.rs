//! Cubic smoothing spline (`mst`) at a given p, and the C² interpolating spline solve, for
//! n = 10³ … 10⁶ points. Compare with `bench/csaps_speed.py` (PyPI csaps on the same data).
//!
//! Run: `cargo bench -p batten --bench mst -- --warm-up-time 1 --measurement-time 3`

#![allow(clippy::unwrap_used)]

mod common;

use std::hint::black_box;

use batten::fair::{FairMethod, Mst, SmoothingSpline};
use batten::spline::{EndCondition, ParametricCubic, Parametrization, parameters};
use batten::{FairOptions, Point, PointSeq};
use common::noisy_spiral;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};

const SIZES: [usize; 4] = [1_000, 10_000, 100_000, 1_000_000];

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("mst");
    for n in SIZES {
        let pts = noisy_spiral(n, 6.0, 0.01);
        let t = parameters(&pts, Parametrization::ChordLength, false).unwrap();
        let p = SmoothingSpline::default_p(&t, &vec![1.0; n], false).unwrap();
        g.throughput(Throughput::Elements(n as u64));
        if n >= 100_000 {
            g.sample_size(10);
        }
        g.bench_with_input(BenchmarkId::new("fit", n), &n, |b, _| {
            b.iter(|| SmoothingSpline::fit(black_box(&t), black_box(&pts), None, p).unwrap())
        });
        // The whole method: chord-length parameters, the solve, the report parameters.
        let seq = PointSeq::open(pts.clone()).unwrap();
        let opts = FairOptions::default().with_param("p", p);
        g.bench_with_input(BenchmarkId::new("method", n), &n, |b, _| {
            b.iter(|| Mst.run(black_box(&seq), &opts).unwrap())
        });
    }
    // Degenerate input: collinear points (Qᵀy = 0), the answer is the input.
    let line: Vec<Point> = (0..100_000)
        .map(|i| Point::new(i as f64, 2.0 * i as f64))
        .collect();
    let t = parameters(&line, Parametrization::ChordLength, false).unwrap();
    g.bench_function("fit_collinear/100000", |b| {
        b.iter(|| SmoothingSpline::fit(black_box(&t), black_box(&line), None, 0.5).unwrap())
    });
    g.finish();

    let mut g = c.benchmark_group("spline");
    for n in SIZES {
        let pts = noisy_spiral(n, 6.0, 0.01);
        let t = parameters(&pts, Parametrization::ChordLength, false).unwrap();
        g.throughput(Throughput::Elements(n as u64));
        if n >= 100_000 {
            g.sample_size(10);
        }
        g.bench_with_input(BenchmarkId::new("interpolate_natural", n), &n, |b, _| {
            b.iter(|| {
                ParametricCubic::interpolate_at(
                    black_box(&t),
                    black_box(&pts),
                    EndCondition::Natural,
                )
                .unwrap()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
