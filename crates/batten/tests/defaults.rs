//! Every method's documented defaults are its defaults: passing each parameter's default
//! explicitly (`--set KEY=DEFAULT`) gives bit for bit the result of passing none.

#![allow(clippy::unwrap_used)]

use batten::fair;
use batten::{FairOptions, Point, PointSeq};

/// Samples of a wavy curve with a fixed wobble.
fn wavy(n: usize) -> Vec<Point> {
    (0..n)
        .map(|i| {
            let x = 6.0 * i as f64 / (n - 1) as f64;
            let wobble = 0.02 * ((i * 7919 % 13) as f64 / 13.0 - 0.5);
            Point::new(x + 0.5 * wobble, x.sin() + wobble)
        })
        .collect()
}

/// Samples of a closed wavy loop with a fixed wobble.
fn loop_(n: usize) -> Vec<Point> {
    (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            let r = 1.0 + 0.2 * (3.0 * a).cos() + 0.01 * ((i * 7919 % 13) as f64 / 13.0 - 0.5);
            Point::new(r * a.cos(), r * a.sin())
        })
        .collect()
}

#[test]
fn explicit_defaults_change_nothing() {
    let open = PointSeq::open(wavy(60)).unwrap();
    let closed = PointSeq::closed(loop_(60)).unwrap();
    let mut runs = 0;
    for (m, input) in fair::methods()
        .iter()
        .flat_map(|m| [(m, &open), (m, &closed)])
        .filter(|(m, input)| !input.is_closed() || m.supports_closed())
    {
        runs += 1;
        let base = FairOptions::default().with_tolerance(0.05);
        let mut explicit = base.clone();
        for p in m.parameters() {
            explicit = explicit.with_param(p.name, p.default);
        }
        let a = fair::fair_with(*m, input, &base).unwrap();
        let b = fair::fair_with(*m, input, &explicit).unwrap_or_else(|e| {
            panic!(
                "{} (closed {}): its own defaults are refused: {e}",
                m.name(),
                input.is_closed()
            )
        });
        assert_eq!(a.points, b.points, "{}", m.name());
        assert_eq!(a.report.parameters, b.report.parameters, "{}", m.name());
        assert_eq!(a.report.status, b.report.status, "{}", m.name());
    }
    assert!(runs > fair::methods().len(), "{runs} runs");
}
