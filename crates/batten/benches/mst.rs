//! Cubic smoothing spline (`mst`) at a given p, and the C² interpolating spline solve, for
//! n = 10³ … 10⁶ points. Compare with `bench/csaps_speed.py` (PyPI csaps on the same data).
//! And the Python package's case (issue #17): `mst` at a tolerance on a 200-point curve, the
//! search for p alone and the whole `fair` with its report.
//!
//! Run: `cargo bench -p batten --bench mst -- --warm-up-time 1 --measurement-time 3`

#![allow(clippy::unwrap_used)]

mod common;

use std::hint::black_box;

use batten::fair::{FairMethod, Mst, Smoothing, SmoothingSpline};
use batten::spline::{EndCondition, ParametricCubic, Parametrization, parameters};
use batten::{FairOptions, Point, PointSeq};
use common::{noisy_sine, noisy_spiral};
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
    // `bench/python_speed.py`'s curve and tolerance: the search's fits (12 here), then the whole
    // `fair` (the search plus the report's measures before and after).
    let small = noisy_sine(200);
    let t = parameters(&small, Parametrization::ChordLength, false).unwrap();
    let search = Smoothing::MaxDisplacement {
        tolerance: 0.02,
        max_steps: 60,
    };
    g.throughput(Throughput::Elements(200));
    g.sample_size(100);
    g.bench_function("tolerance_search/200", |b| {
        b.iter(|| SmoothingSpline::select(black_box(&t), black_box(&small), None, false, search))
    });
    let seq = PointSeq::open(small.clone()).unwrap();
    let opts = FairOptions::default().with_tolerance(0.02);
    g.bench_function("fair_tolerance/200", |b| {
        b.iter(|| batten::fair::fair("mst", black_box(&seq), &opts).unwrap())
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
