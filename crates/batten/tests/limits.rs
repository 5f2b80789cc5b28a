//! Issue #14, "crashes and hangs on accepted values" (the library half): every size-like
//! option has a documented upper bound and a one-line error past it, checked before any
//! work (so that `batch` refuses it before reading a file); points closer than rounding are
//! refused by name instead of making a solver singular.

use batten::analysis::{KuraganoOptions, ROC_MAX_SAMPLES, evaluate_roc_fairness};
use batten::error::Error;
use batten::fair::{MAX_ITERATIONS, check_options, fair, method};
use batten::geom::NEAR_DUPLICATE_REL;
use batten::{FairOptions, Point, PointSeq};

fn sine(n: usize) -> Vec<Point> {
    (0..n)
        .map(|i| {
            let x = 0.4 * i as f64;
            Point::new(
                x,
                (0.5 * x).sin() + 0.01 * ((i * 7919 % 13) as f64 / 6.0 - 1.0),
            )
        })
        .collect()
}

/// The error names the parameter and says it is out of range, in one line.
fn assert_refused(r: Result<(), Error>, name: &str) {
    match r {
        Err(Error::InvalidParameter { name: n, reason }) => {
            assert_eq!(n, name);
            let line = Error::InvalidParameter { name: n, reason }.to_string();
            assert!(!line.contains('\n'), "{line}");
        }
        other => panic!("{name}: expected InvalidParameter, got {other:?}"),
    }
}

#[test]
fn kuragano_samples_are_bounded() {
    let pts = sine(20);
    // `evaluate --samples 18446744073709551615` panicked with "capacity overflow" and
    // `--samples 100000000000` aborted on allocation; 1e8 ran for minutes.
    for n in [
        usize::MAX,
        100_000_000_000,
        100_000_000,
        ROC_MAX_SAMPLES + 1,
    ] {
        let opts = KuraganoOptions::default().with_samples(n);
        assert_refused(evaluate_roc_fairness(&pts, &opts).map(|_| ()), "samples");
        let fo = FairOptions::default().with_param("samples", n);
        assert_refused(
            check_options(method("kuragano").unwrap(), false, &fo),
            "samples",
        );
    }
    // The bound itself is accepted.
    let fo = FairOptions::default().with_param("samples", ROC_MAX_SAMPLES);
    check_options(method("kuragano").unwrap(), false, &fo).expect("at the bound");
}

#[test]
fn salvi_samples_are_bounded() {
    // `--method salvi --set samples=1000000` ran for more than 5 minutes.
    let m = method("salvi").unwrap();
    for n in [usize::MAX, 1_000_000, batten::fair::SALVI_MAX_SAMPLES + 1] {
        let fo = FairOptions::default().with_param("samples", n);
        assert_refused(check_options(m, false, &fo), "samples");
    }
    let fo = FairOptions::default().with_param("samples", batten::fair::SALVI_MAX_SAMPLES);
    check_options(m, false, &fo).expect("at the bound");
}

#[test]
fn max_iterations_is_bounded() {
    // `--max-iterations 18446744073709551615 --method kjellander --set threshold=0` ran for
    // 51 s and took 1.1 GB.
    let seq = PointSeq::open(sine(30)).unwrap();
    for name in ["kjellander", "han", "salvi"] {
        let fo = FairOptions::default()
            .with_param("threshold", 0)
            .with_max_iterations(usize::MAX);
        let fo = if name == "kjellander" {
            fo
        } else {
            FairOptions::default().with_max_iterations(MAX_ITERATIONS + 1)
        };
        match fair(name, &seq, &fo) {
            Err(Error::InvalidParameter { name: n, .. }) => assert_eq!(n, "max_iterations"),
            other => panic!("{name}: {:?}", other.map(|f| f.report.status)),
        }
    }
    // At the bound, kjellander with threshold 0 stops in reasonable time.
    let start = std::time::Instant::now();
    let fo = FairOptions::default()
        .with_param("threshold", 0)
        .with_max_iterations(MAX_ITERATIONS);
    fair("kjellander", &seq, &fo).expect("at the bound");
    assert!(
        start.elapsed().as_secs_f64() < 30.0,
        "{:?}",
        start.elapsed()
    );
}

#[test]
fn near_duplicate_points_are_refused_by_name() {
    // Two points 1e-15 apart gave "singular system: zero pivot 11 in band LU" from every
    // method.
    let mut pts = sine(30);
    pts.insert(11, pts[10] + batten::Vec2::new(1e-15, 0.0));
    match PointSeq::open(pts.clone()) {
        Err(e @ Error::NearDuplicate { .. }) => {
            let Error::NearDuplicate {
                index,
                previous,
                relative,
            } = e
            else {
                unreachable!()
            };
            assert_eq!((previous, index), (10, 11));
            assert!(relative < NEAR_DUPLICATE_REL);
            let line = e.to_string();
            assert!(line.contains("points 10 and 11"), "{line}");
            assert!(!line.contains('\n'));
        }
        other => panic!("{other:?}"),
    }
    // 1e-9 apart (relative 1e-10) is shape, not rounding: every method fairs it.
    pts[11] = pts[10] + batten::Vec2::new(1e-9, 0.0);
    let seq = PointSeq::open(pts).unwrap();
    for m in batten::fair::methods() {
        fair(m.name(), &seq, &FairOptions::default().with_tolerance(0.1))
            .unwrap_or_else(|e| panic!("{}: {e}", m.name()));
    }
}
