//! The `han` method (Han et al., docs/algorithms/han.md §1) for n = 10³ … 10⁶ points: the whole
//! method with the default options (partition, 3 passes × 10 iterations per segment, blending) on
//! the spiral of `benches/mst.rs`, the same on the spiral without its wobble at 10⁶ points, and one
//! sweep (one iteration of the five case procedures C1, C2, C3, F1, F2) over a single function
//! segment, so that the per-sweep cost is visible on its own.
//!
//! The 10⁶ whole-method case takes several seconds a run; Criterion may warn that it extended
//! the measurement time.
//!
//! Run: `cargo bench -p batten --bench han -- --warm-up-time 1 --measurement-time 5`

#![allow(clippy::unwrap_used)]

mod common;

use std::hint::black_box;

use batten::fair::{FairMethod, Han, HanSegment};
use batten::{FairOptions, PointSeq};
use common::{noisy_spiral, uniform_noise};
use criterion::{BatchSize, BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};

const SIZES: [usize; 4] = [1_000, 10_000, 100_000, 1_000_000];

/// One function segment: `x_i = i·h` over three periods of `y = sin(x/2)`, with the same
/// deterministic wobble of 1% of h on y.
fn segment(n: usize) -> HanSegment {
    let mut noise = uniform_noise();
    let h = 12.0 * std::f64::consts::PI / n as f64;
    let x: Vec<f64> = (0..n).map(|i| i as f64 * h).collect();
    let y: Vec<f64> = x
        .iter()
        .map(|&v| (v / 2.0).sin() + 0.01 * h * noise())
        .collect();
    HanSegment::new(x, y).unwrap()
}

fn bench(c: &mut Criterion) {
    // The whole method with the default options.
    let mut g = c.benchmark_group("han");
    g.sample_size(10);
    for n in SIZES {
        let seq = PointSeq::open(noisy_spiral(n, 6.0, 0.01)).unwrap();
        let opts = FairOptions::default();
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::new("method", n), &n, |b, _| {
            b.iter(|| Han.run(black_box(&seq), &opts).unwrap())
        });
    }
    // The clean spiral (no wobble): only rounding noise, which han leaves alone, so this is
    // the cost of the set-up and one sweep of scans per segment.
    let n = 1_000_000;
    let seq = PointSeq::open(noisy_spiral(n, 6.0, 0.0)).unwrap();
    let opts = FairOptions::default();
    g.throughput(Throughput::Elements(n as u64));
    g.bench_with_input(BenchmarkId::new("clean", n), &n, |b, _| {
        b.iter(|| Han.run(black_box(&seq), &opts).unwrap())
    });
    g.finish();

    // One sweep (one iteration of the five case procedures) over one segment, from the same
    // starting state each time; the clone is not timed.
    let mut g = c.benchmark_group("han_segment");
    for n in SIZES {
        let seg = segment(n);
        g.throughput(Throughput::Elements(n as u64));
        if n >= 100_000 {
            g.sample_size(10);
        }
        g.bench_with_input(BenchmarkId::new("sweep", n), &n, |b, _| {
            b.iter_batched(
                || seg.clone(),
                |mut s| {
                    s.fair(1, |_| {});
                    s
                },
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
