//! The `band` method inside the method (`Band::run`, the tolerance given as the automatic one
//! would be, `k·σ̂`), with the default options (3 passes, the debiasing stage), for n = 10³ …
//! 10⁶ points on a noisy half ellipse (semi-axes 3 and 1, noise 0.1 % of the diagonal per
//! coordinate, deterministic).
//!
//! The targets of the `band` issue are 10⁵ points in ≤ 0.3 s and 10⁶ in ≤ 3 s (figures in
//! BENCHMARKS.md). Above 2000 points `band` solves in the spline form on a working set of
//! points (docs/algorithms/band.md, Dense points).
//!
//! Run: `cargo bench -p batten --bench band -- --warm-up-time 1 --measurement-time 5`

#![allow(clippy::unwrap_used)]

mod common;

use std::hint::black_box;

use batten::fair::{Band, FairMethod, band_tolerance_factor};
use batten::{FairOptions, Point, PointSeq};
use common::normal_noise;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};

const SIZES: [usize; 5] = [1_000, 3_000, 10_000, 100_000, 1_000_000];

/// The half ellipse `(3 cos a, sin a)`, `a ∈ [0, π]`, with noise of `rel` times its diagonal.
fn curve(n: usize, rel: f64) -> Vec<Point> {
    let mut noise = normal_noise();
    let sigma = rel * (36.0_f64 + 1.0).sqrt();
    (0..n)
        .map(|i| {
            let a = std::f64::consts::PI * i as f64 / (n - 1) as f64;
            Point::new(3.0 * a.cos() + sigma * noise(), a.sin() + sigma * noise())
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("band");
    g.sample_size(10);
    for n in SIZES {
        let seq = PointSeq::open(curve(n, 0.001)).unwrap();
        let sigma = batten::analysis::noise_sigma(seq.points(), false);
        let opts = FairOptions::default().with_tolerance(band_tolerance_factor(n) * sigma);
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::new("method", n), &n, |b, _| {
            b.iter(|| Band.run(black_box(&seq), &opts).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
