//! The `cali` method (Calì et al., docs/algorithms/cali.md §4.5) on noisy curves of n = 10², 10³,
//! 10⁴ points, its parts (the indicator state with its precomputed bases, one full λ-operator
//! application), and a degenerate input (collinear points: GFI = 0, nothing to do).
//!
//! With the paper's τ = 0.99 the number of accepted moves stops growing with n (one local move
//! cannot lower a GFI spread over n points by 1 %, see the module docs of `fair::cali`), so the
//! large cases measure the interpolation and one full candidate scan; the `tau_1-1/n` group
//! accepts moves in proportion to n and measures the incremental machinery.
//!
//! Run: `cargo bench -p batten --bench cali -- --warm-up-time 1 --measurement-time 5`

#![allow(clippy::unwrap_used)]

mod common;

use std::hint::black_box;

use batten::fair::{Cali, FairMethod, LocalIndicators};
use batten::spline::{BSplineCurve, LambdaOperator, Parametrization};
use batten::{FairOptions, Point, PointSeq};
use common::noisy_spiral;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};

const SIZES: [usize; 3] = [100, 1_000, 10_000];

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("cali");
    g.sample_size(10);
    for n in SIZES {
        let pts = noisy_spiral(n, 3.0, 0.05);
        let seq = PointSeq::open(pts.clone()).unwrap();
        g.throughput(Throughput::Elements(n as u64));
        // The whole method at the paper's τ = 0.99.
        let opts = FairOptions::default();
        g.bench_with_input(BenchmarkId::new("method", n), &n, |b, _| {
            b.iter(|| Cali.run(black_box(&seq), &opts).unwrap())
        });
        // τ = 1 − 1/n: accepted moves grow with n (skipped at 10⁴, ~10 s a run).
        if n <= 1_000 {
            let tau = 1.0 - 1.0 / n as f64;
            let opts = FairOptions::default().with_param("tau", tau);
            g.bench_with_input(BenchmarkId::new("method_tau_1-1/n", n), &n, |b, _| {
                b.iter(|| Cali.run(black_box(&seq), &opts).unwrap())
            });
        }
        // The indicator state: LFI/GFI plus the bases for the local updates.
        let (curve, _) = BSplineCurve::interpolate(&pts, 3, Parametrization::ChordLength).unwrap();
        g.bench_with_input(BenchmarkId::new("indicators", n), &n, |b, _| {
            b.iter(|| LocalIndicators::new(black_box(&curve)).unwrap())
        });
        // One scan: the best λ of every candidate, no commit.
        let state = LocalIndicators::new(&curve).unwrap();
        g.bench_with_input(BenchmarkId::new("scan", n), &n, |b, _| {
            b.iter(|| {
                state
                    .candidates()
                    .map(|i| state.best_trial(i, 1e-6).unwrap().gfi_change())
                    .sum::<f64>()
            })
        });
        // M^λ applied to the whole polygon.
        let op = LambdaOperator::for_curve(&curve).unwrap();
        g.bench_with_input(BenchmarkId::new("operator_apply", n), &n, |b, _| {
            b.iter(|| op.apply(black_box(curve.control_points()), 0.5).unwrap())
        });
    }
    // Degenerate input: collinear points (κ ≡ 0, GFI = 0): one scan finds nothing.
    let line: Vec<Point> = (0..1_000)
        .map(|i| Point::new(i as f64, 2.0 * i as f64))
        .collect();
    let seq = PointSeq::open(line).unwrap();
    let opts = FairOptions::default();
    g.throughput(Throughput::Elements(1_000));
    g.bench_function("collinear/1000", |b| {
        b.iter(|| Cali.run(black_box(&seq), &opts).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
