//! The comparison protocol (`fair::compare`, Han et al.'s Table 1): `mst` at the first
//! method's largest displacement, the note that says so, the rows in the order given, closed
//! curves skipped by the methods that take only open ones, failures as rows, and runs that
//! are `fair`'s own.
#![allow(clippy::unwrap_used)]

use batten::error::Error;
use batten::fair::{
    self, BISECTION_REL_PRECISION, Comparison, ComparisonOutcome, EndFix, FairMethod,
};
use batten::{FairOptions, PointSeq};

mod common;
use common::{Noise, jitter};

/// `sin x` on [0, 6] with uniform noise.
fn noisy_sine(n: usize, amp: f64, seed: u64) -> PointSeq {
    PointSeq::open(jitter(&common::sine(n, 6.0), Noise::Uniform(amp), seed)).unwrap()
}

/// The registered methods called `names`, in that order.
fn methods(names: &[&str]) -> Vec<&'static dyn FairMethod> {
    names.iter().map(|n| fair::method(n).unwrap()).collect()
}

fn names(c: &Comparison) -> Vec<&'static str> {
    c.rows.iter().map(|r| r.method).collect()
}

#[test]
fn mst_runs_at_the_largest_displacement_of_the_first_method() {
    for (first, seed) in [("han", 1), ("band", 2), ("kjellander", 3), ("cali", 4)] {
        let input = noisy_sine(80, 0.08, seed);
        let options = FairOptions::default().with_tolerance(0.2);
        let c = fair::compare(&methods(&[first, "poliakoff", "mst"]), &input, &options);
        assert_eq!(names(&c), [first, "poliakoff", "mst"]);
        let target = c.rows[0].report().unwrap().max_displacement;
        assert!(target > 0.0, "{first}");
        let mst = &c.rows[2];
        assert_eq!(mst.tolerance, Some(target), "{first}");
        let note = mst.note.as_deref().unwrap();
        assert!(
            note.starts_with("run at tolerance ")
                && note.ends_with(&format!(
                    ", the max displacement of {first} (as in Han et al.)"
                )),
            "{note}"
        );
        // The search returns the feasible end of a bracket of relative width
        // BISECTION_REL_PRECISION in its smoothing weight; the largest displacement grows
        // no faster than that weight, so it lands within that fraction below the target.
        let got = mst.report().unwrap().max_displacement;
        assert!(got <= target, "{first}: {got} > {target}");
        assert!(
            got >= target * (1.0 - BISECTION_REL_PRECISION),
            "{first}: {got} vs {target}"
        );
        // The other rows ran with the options given, and say nothing.
        for row in &c.rows[..2] {
            assert_eq!(row.tolerance, Some(0.2));
            assert_eq!(row.note, None);
        }
    }
}

#[test]
fn the_runs_are_those_of_fair() {
    let input = noisy_sine(60, 0.06, 5);
    let options = FairOptions::default().with_tolerance(0.1);
    let c = fair::compare(&methods(&["han", "energy", "mst"]), &input, &options);
    let han = fair::fair("han", &input, &options).unwrap();
    let energy = fair::fair("energy", &input, &options).unwrap();
    let mst = fair::fair(
        "mst",
        &input,
        &FairOptions::default().with_tolerance(han.report.max_displacement),
    )
    .unwrap();
    for (row, alone) in c.rows.iter().zip([han, energy, mst]) {
        let f = row.faired().unwrap();
        assert_eq!(f.points, alone.points, "{}", row.method);
        assert_eq!(f.report.after, alone.report.after, "{}", row.method);
    }
}

#[test]
fn mst_first_or_not_listed_runs_with_the_options_given() {
    let input = noisy_sine(50, 0.05, 7);
    let options = FairOptions::default().with_tolerance(0.05);
    for list in [
        &["mst", "han"][..],
        &["han", "kjellander"],
        &["mst"],
        &["band"],
    ] {
        let c = fair::compare(&methods(list), &input, &options);
        assert_eq!(names(&c), list);
        for row in &c.rows {
            assert_eq!(row.tolerance, Some(0.05), "{list:?}");
            assert_eq!(row.note, None, "{list:?}");
            assert!(row.report().unwrap().tolerance_met, "{list:?}");
        }
    }
    assert!(fair::compare(&[], &input, &options).rows.is_empty());
}

#[test]
fn closed_input_is_skipped_by_the_methods_for_open_curves_in_order() {
    let input = PointSeq::closed(jitter(&common::lobed_loop(60), Noise::Uniform(0.02), 3)).unwrap();
    let all = fair::methods();
    let c = fair::compare(all, &input, &FairOptions::default().with_tolerance(0.05));
    assert_eq!(
        names(&c),
        all.iter().map(|m| m.name()).collect::<Vec<_>>(),
        "registry order"
    );
    let mut skipped = 0;
    for (row, m) in c.rows.iter().zip(all) {
        match &row.outcome {
            ComparisonOutcome::Skipped(why) => {
                assert!(!m.supports_closed(), "{}", row.method);
                assert_eq!(why, "does not support closed curves");
                skipped += 1;
            }
            ComparisonOutcome::Ran(f) => {
                assert!(m.supports_closed(), "{}", row.method);
                assert!(f.report.before.closed && f.points.len() == 60);
            }
            ComparisonOutcome::Failed(e) => panic!("{}: {e}", row.method),
        }
    }
    assert!(skipped > 0 && skipped < all.len(), "{skipped}");
    assert_eq!(c.failures().count(), 0);
}

#[test]
fn when_the_first_method_does_not_run_mst_says_so() {
    // Skipped: cali takes only open curves.
    let closed = PointSeq::closed(common::lobed_loop(40)).unwrap();
    let options = FairOptions::default().with_tolerance(0.05);
    let c = fair::compare(&methods(&["cali", "mst"]), &closed, &options);
    assert!(matches!(c.rows[0].outcome, ComparisonOutcome::Skipped(_)));
    assert_eq!(c.rows[1].tolerance, Some(0.05));
    assert_eq!(
        c.rows[1].note.as_deref(),
        Some("cali did not run, so mst ran with the options given")
    );

    // Failed: a parameter only mst knows, so han fails and mst keeps it.
    let input = noisy_sine(40, 0.05, 1);
    let options = FairOptions::default().with_param("p", 0.9);
    let c = fair::compare(&methods(&["han", "mst"]), &input, &options);
    let failures: Vec<_> = c.failures().collect();
    assert_eq!(failures.len(), 1);
    assert_eq!(failures[0].0, "han");
    assert!(matches!(failures[0].1, Error::UnknownOption { .. }));
    assert_eq!(
        c.rows[1].note.as_deref(),
        Some("han did not run, so mst ran with the options given")
    );
    assert_eq!(
        c.rows[1].report().unwrap().parameters["p"],
        serde_json::json!(0.9)
    );

    // Moved nothing: every point of a six-point curve is held.
    let tiny = noisy_sine(6, 0.05, 1);
    let options = FairOptions::default().with_end_fix(EndFix::Curvature);
    let c = fair::compare(&methods(&["han", "mst"]), &tiny, &options);
    assert_eq!(c.rows[0].report().unwrap().max_displacement, 0.0);
    assert_eq!(c.rows[1].tolerance, None);
    assert_eq!(
        c.rows[1].note.as_deref(),
        Some("han moved no point, so mst ran with the options given")
    );
}
