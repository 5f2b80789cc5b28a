//! `fair` with every method on arbitrary small curves and option sets: never a panic, only
//! `Ok` or a typed error; the same number of points back; and when the report says the
//! tolerance is met, no point moved farther than it.
#![no_main]

use arbitrary::Arbitrary;
use batten::fair::{self, EndFix};
use batten::{FairOptions, Point, PointSeq};
use libfuzzer_sys::fuzz_target;

/// Parameters worth varying, with values drawn from a short list per key (the parsers of the
/// values are fuzzed by the readers; here the methods are).
const PARAMS: &[(&str, &[&str])] = &[
    ("degree", &["2", "3", "4", "5", "auto"]),
    ("samples", &["7", "41", "200", "auto"]),
    ("p", &["0", "0.5", "0.999", "1"]),
    ("threshold", &["0", "0.1", "0.5", "1"]),
    ("control_points", &["4", "6", "auto"]),
    ("free_ends", &["true", "false"]),
    ("passes", &["1", "3"]),
    ("smoother", &["average", "bspline"]),
    ("residual", &["rho", "kappa"]),
    ("ends", &["gradients", "natural"]),
];

#[derive(Debug, Arbitrary)]
struct Case {
    method: u8,
    /// Points as small integers on a grid (scaled below), so that curves are varied but
    /// mostly valid; duplicates and straight runs happen and must be refused or handled.
    points: Vec<(i16, i16)>,
    scale_exp: i8,
    closed: bool,
    tolerance: Option<u16>,
    fix_ends: u8,
    max_iterations: Option<u8>,
    params: Vec<(u8, u8)>,
}

fuzz_target!(|case: Case| {
    let methods = fair::methods();
    let method = methods[usize::from(case.method) % methods.len()];
    if case.points.len() > 24 {
        return;
    }
    let scale = 10f64.powi(i32::from(case.scale_exp % 20));
    let pts: Vec<Point> = case
        .points
        .iter()
        .map(|&(x, y)| Point::new(f64::from(x) * scale, f64::from(y) * scale))
        .collect();
    let Ok(seq) = PointSeq::new(pts, case.closed) else {
        return;
    };
    let mut options = FairOptions::default()
        .with_end_fix(EndFix::ALL[usize::from(case.fix_ends) % EndFix::ALL.len()]);
    if let Some(t) = case.tolerance {
        options = options.with_tolerance((f64::from(t) + 1.0) * 1e-3 * scale);
    }
    if let Some(n) = case.max_iterations {
        options = options.with_max_iterations(usize::from(n % 30) + 1);
    } else {
        // The methods' own limits can be long on a pathological curve; keep runs short.
        options = options.with_max_iterations(30);
    }
    for &(k, v) in case.params.iter().take(4) {
        let (key, values) = PARAMS[usize::from(k) % PARAMS.len()];
        if method.parameters().iter().any(|s| s.name == key) {
            options = options.with_param(key, values[usize::from(v) % values.len()]);
        }
    }
    let Ok(faired) = fair::fair_with(method, &seq, &options) else {
        return;
    };
    assert_eq!(faired.points.len(), seq.len(), "{}", method.name());
    let report = &faired.report;
    if let Some(t) = report.tolerance
        && report.tolerance_met
    {
        let moved = seq
            .points()
            .iter()
            .zip(&faired.points)
            .map(|(a, b)| (*b - *a).length())
            .fold(0.0, f64::max);
        assert!(
            moved <= t * (1.0 + 1e-9),
            "{}: tolerance {t} reported met, a point moved {moved}",
            method.name()
        );
    }
});
