//! [`FairnessMetrics::of_seq`], what every report measures twice and `batten analyze` is:
//! at 200 points (the Python package's many small curves, issue #17) and at 10⁴ … 10⁶
//! points (issue #14), open and closed.
//!
//! Run: `cargo bench -p batten --bench metrics -- --warm-up-time 1 --measurement-time 3`

#![allow(clippy::unwrap_used)]

mod common;

use std::hint::black_box;

use batten::{FairnessMetrics, PointSeq};
use common::{noisy_sine, noisy_spiral};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("metrics");
    let small = PointSeq::open(noisy_sine(200)).unwrap();
    g.throughput(Throughput::Elements(200));
    g.bench_function("open_sine/200", |b| {
        b.iter(|| FairnessMetrics::of_seq(black_box(&small)).unwrap())
    });
    let ring = PointSeq::new(noisy_spiral(200, 2.0, 0.01)[..200].to_vec(), true).unwrap();
    g.bench_function("closed_spiral/200", |b| {
        b.iter(|| FairnessMetrics::of_seq(black_box(&ring)).unwrap())
    });
    for n in [10_000, 100_000, 1_000_000] {
        let seq = PointSeq::open(noisy_spiral(n, 6.0, 0.01)).unwrap();
        g.throughput(Throughput::Elements(n as u64));
        if n >= 100_000 {
            g.sample_size(10);
        }
        g.bench_with_input(BenchmarkId::new("open_spiral", n), &n, |b, _| {
            b.iter(|| FairnessMetrics::of_seq(black_box(&seq)).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
