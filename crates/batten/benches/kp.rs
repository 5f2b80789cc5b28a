//! Cost of the Kjellander–Poliakoff family and Sapidis–Farin: for n = 10³, 10⁴, 10⁵ points,
//! the set-up alone (`max_iterations = 0`: interpolation and ranking) and the set-up plus a
//! fixed number of moves, so that the per-move cost is `(moves − setup) / MOVES`. Plus a
//! degenerate input (equally spaced collinear points: every jump is zero, nothing moves), and
//! Sapidis–Farin on a closed curve.

use std::hint::black_box;

use batten::fair;
use batten::{FairOptions, Point, PointSeq};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};

/// Moves per measured run.
const MOVES: usize = 1000;

const METHODS: [&str; 4] = ["kjellander", "poliakoff", "energy", "sapidis-farin"];

/// A noisy arc: the same deterministic noise pattern for every size.
fn noisy_arc(n: usize) -> PointSeq {
    let pts = (0..n)
        .map(|i| {
            let a = i as f64 * 3.0 / n as f64;
            let r = 3.0 + 1e-3 * (((i * 7919) % 11) as f64 - 5.0) / 5.0;
            Point::new(r * a.cos(), r * a.sin())
        })
        .collect();
    PointSeq::open(pts).expect("valid points")
}

fn run(method: &str, input: &PointSeq, moves: usize) -> usize {
    let m = fair::method(method).expect("registered");
    let opts = FairOptions::default()
        .with_max_iterations(moves)
        .with_param("threshold", 0);
    let out = m.run(input, &opts).expect("runs");
    out.moves.len()
}

fn bench_kp(c: &mut Criterion) {
    for n in [1_000usize, 10_000, 100_000] {
        let input = noisy_arc(n);
        let mut group = c.benchmark_group(format!("kp/n={n}"));
        if n >= 10_000 {
            group.sample_size(10);
        }
        for method in METHODS {
            assert_eq!(run(method, &input, MOVES), MOVES);
            group.bench_with_input(BenchmarkId::new(method, "setup"), &input, |b, input| {
                b.iter(|| run(method, black_box(input), 0))
            });
            group.bench_with_input(
                BenchmarkId::new(method, format!("{MOVES}_moves")),
                &input,
                |b, input| b.iter(|| run(method, black_box(input), MOVES)),
            );
        }
        group.finish();
    }
    let line = PointSeq::open(
        (0..10_000)
            .map(|i| Point::new(i as f64, 0.5 * i as f64))
            .collect(),
    )
    .expect("valid points");
    let mut group = c.benchmark_group("kp/degenerate_collinear_n=10000");
    group.sample_size(10);
    for method in METHODS {
        assert_eq!(run(method, &line, MOVES), 0);
        group.bench_function(method, |b| b.iter(|| run(method, black_box(&line), MOVES)));
    }
    group.finish();

    // Sapidis–Farin on a closed curve (the periodic cubic): the same noisy circle arc
    // closed into a full circle.
    let mut group = c.benchmark_group("kp/closed");
    group.sample_size(10);
    for n in [1_000usize, 10_000, 100_000] {
        let closed = PointSeq::closed(
            (0..n)
                .map(|i| {
                    let a = i as f64 * std::f64::consts::TAU / n as f64;
                    let r = 3.0 + 1e-3 * (((i * 7919) % 11) as f64 - 5.0) / 5.0;
                    Point::new(r * a.cos(), r * a.sin())
                })
                .collect(),
        )
        .expect("valid points");
        assert_eq!(run("sapidis-farin", &closed, MOVES), MOVES);
        group.bench_with_input(
            BenchmarkId::new("sapidis-farin/setup", n),
            &closed,
            |b, input| b.iter(|| run("sapidis-farin", black_box(input), 0)),
        );
        group.bench_with_input(
            BenchmarkId::new(format!("sapidis-farin/{MOVES}_moves"), n),
            &closed,
            |b, input| b.iter(|| run("sapidis-farin", black_box(input), MOVES)),
        );
    }
    group.finish();
}

criterion_group!(benches, bench_kp);
criterion_main!(benches);
