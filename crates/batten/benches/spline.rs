//! The spline foundation at n = 10³ … 10⁶ points: global cubic B-spline interpolation (banded
//! collocation solve), least-squares approximation with n/10 control points (banded normal
//! equations), and `FairnessMetrics::of_seq` (analysis spline, curvature sampling, energies,
//! arc length and GFI). A degenerate case, collinear data, is measured for `of_seq` too.
//!
//! Run: `cargo bench -p batten --bench spline`

#![allow(clippy::unwrap_used)]

use std::hint::black_box;
use std::time::Duration;

use batten::spline::{BSplineCurve, Parametrization};
use batten::{FairnessMetrics, Point, PointSeq};
use criterion::measurement::WallTime;
use criterion::{
    BenchmarkGroup, BenchmarkId, Criterion, Throughput, criterion_group, criterion_main,
};

const SIZES: [usize; 4] = [1_000, 10_000, 100_000, 1_000_000];

/// A spiral arc with a small deterministic wobble (so the curvature is not trivially smooth).
fn curve(n: usize) -> Vec<Point> {
    let step = 6.0 * std::f64::consts::PI / n as f64;
    (0..n)
        .map(|i| {
            let a = i as f64 * step;
            let r = 1.0 + 0.3 * a;
            let wobble = 0.01 * step * r * ((i * 7919 % 13) as f64 / 13.0 - 0.5);
            Point::new(r * a.cos() + wobble, r * a.sin() - wobble)
        })
        .collect()
}

/// Unevenly spaced points on a straight line: the degenerate case of zero curvature.
fn line(n: usize) -> Vec<Point> {
    let mut x = 0.0;
    (0..n)
        .map(|k| {
            let p = Point::new(x, 0.37 * x + 2.0);
            x += 0.2 + 0.3 * ((k * 7) % 5) as f64;
            p
        })
        .collect()
}

/// Fewer samples and shorter runs for the large sizes, which take up to seconds per call.
fn configure(g: &mut BenchmarkGroup<'_, WallTime>, n: usize) {
    if n >= 100_000 {
        g.sample_size(10)
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(3));
    } else {
        g.sample_size(20)
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(2));
    }
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("bspline_interpolate_cubic");
    for n in SIZES {
        let pts = curve(n);
        configure(&mut g, n);
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &pts, |b, pts| {
            b.iter(|| {
                black_box(BSplineCurve::interpolate(pts, 3, Parametrization::ChordLength).unwrap())
            })
        });
    }
    g.finish();

    let mut g = c.benchmark_group("bspline_approximate_cubic_n_over_10");
    for n in SIZES {
        let pts = curve(n);
        configure(&mut g, n);
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &pts, |b, pts| {
            b.iter(|| {
                black_box(
                    BSplineCurve::approximate(pts, 3, n / 10, Parametrization::ChordLength)
                        .unwrap(),
                )
            })
        });
    }
    g.finish();

    let mut g = c.benchmark_group("fairness_metrics_of_seq");
    for n in SIZES {
        let seq = PointSeq::open(curve(n)).unwrap();
        configure(&mut g, n);
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &seq, |b, seq| {
            b.iter(|| black_box(FairnessMetrics::of_seq(seq).unwrap()))
        });
    }
    g.finish();

    let mut g = c.benchmark_group("fairness_metrics_of_seq_collinear");
    for n in [1_000, 100_000] {
        let seq = PointSeq::open(line(n)).unwrap();
        configure(&mut g, n);
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &seq, |b, seq| {
            b.iter(|| black_box(FairnessMetrics::of_seq(seq).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
