//! The repros of issue #14 as tests: accepted values that crashed or ran for minutes, outputs
//! found unwritable only after the computation, partial sets of outputs, and messages that
//! took several lines or said the wrong thing. Every run here must end within seconds.

#![allow(clippy::unwrap_used)]

mod common;

use common::{assert_usage_error, names, stderr};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Longest any run here may take: the point of these tests is that nothing hangs.
const TIME_LIMIT: Duration = Duration::from_secs(30);

/// Run `batten` with `args` in `dir`; kill it and fail past [`TIME_LIMIT`].
fn batten_in(dir: &Path, args: &[&str]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_batten"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > TIME_LIMIT {
            child.kill().unwrap();
            let _ = child.wait();
            panic!("batten {args:?} ran for more than {TIME_LIMIT:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// A noisy sine of `n` points as CSV.
fn noisy_sine(n: usize) -> String {
    let mut t = String::from("x,y\n");
    for i in 0..n {
        let x = i as f64 * 4.0 * std::f64::consts::PI / (n - 1) as f64;
        let noise = 0.03 * (((i * 7919) % 13) as f64 / 6.0 - 1.0);
        t.push_str(&format!("{x},{}\n", (x / 2.0).sin() + noise));
    }
    t
}

/// A temporary directory holding `in.csv` (a noisy sine of 40 points).
fn setup() -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_path_buf();
    fs::write(d.join("in.csv"), noisy_sine(40)).unwrap();
    (dir, d)
}

const MAX: &str = "18446744073709551615";

#[test]
fn size_like_values_have_upper_bounds() {
    let (_t, d) = setup();
    let cases: Vec<(Vec<String>, Vec<&str>)> = vec![
        (
            args(&["evaluate", "in.csv", "--samples", MAX]),
            vec!["samples"],
        ),
        (
            args(&["evaluate", "in.csv", "--samples", "100000000000"]),
            vec!["samples", "100000"],
        ),
        (
            fair(&["--method", "kuragano", "--set", &format!("samples={MAX}")]),
            vec!["samples", "100000"],
        ),
        (
            fair(&["--method", "kuragano", "--set", "samples=100000000"]),
            vec!["samples", "100000"],
        ),
        (
            fair(&["--method", "salvi", "--set", "samples=1000000"]),
            vec!["samples", "20000"],
        ),
        (
            fair(&[
                "--method",
                "salvi",
                "--set",
                "smoother=bspline",
                "--set",
                &format!("target_coefficients={MAX}"),
            ]),
            vec!["target_coefficients"],
        ),
        (
            fair(&["--method", "salvi", "--set", &format!("half_width={MAX}")]),
            vec!["half_width"],
        ),
        (
            fair(&["--method", "salvi", "--set", &format!("window={MAX}")]),
            vec!["window"],
        ),
        (
            fair(&["--method", "han", "--set", &format!("overlap={MAX}")]),
            vec!["overlap"],
        ),
        (
            fair(&[
                "--max-iterations",
                MAX,
                "--method",
                "kjellander",
                "--set",
                "threshold=0",
            ]),
            vec!["--max-iterations", "1000000"],
        ),
        (
            fair(&["--max-iterations", "0"]),
            vec!["--max-iterations", "1000000"],
        ),
        (
            args(&["batch", "in.csv", "-o", "out", "--jobs", "30000"]),
            vec!["--jobs", "1024"],
        ),
        (
            args(&["batch", "in.csv", "-o", "out", "--jobs", "0"]),
            vec!["--jobs", "1024"],
        ),
        (
            args(&["batch", "in.csv", "-o", "out", "--max-iterations", "0"]),
            vec!["--max-iterations"],
        ),
    ];
    for (a, needles) in &cases {
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        let o = batten_in(&d, &a);
        assert_usage_error(&o, needles);
        assert_eq!(names(&d), ["in.csv"], "{a:?} wrote something");
    }
}

fn args(a: &[&str]) -> Vec<String> {
    a.iter().map(|s| s.to_string()).collect()
}

/// `batten fair in.csv -o o.csv` followed by `extra`.
fn fair(extra: &[&str]) -> Vec<String> {
    let mut v = args(&["fair", "in.csv", "-o", "o.csv"]);
    v.extend(args(extra));
    v
}

#[test]
fn upper_bounds_themselves_are_accepted() {
    let (_t, d) = setup();
    let o = batten_in(
        &d,
        &[
            "fair",
            "in.csv",
            "-o",
            "o.csv",
            "--method",
            "cali",
            "--max-iterations",
            "1",
        ],
    );
    assert!(o.status.code().is_some_and(|c| c <= 1), "{}", stderr(&o));
    let o = batten_in(&d, &["batch", "in.csv", "-o", "out", "--jobs", "1024"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(names(&d.join("out")), ["in.csv", "in.report.json"]);
}

/// Every output is checked before the computation: a directory where a file is wanted, a
/// place where nothing can be created (/proc), a missing directory. Exit 2, one line naming
/// the path, nothing written — not the main output without its report.
#[test]
fn unwritable_outputs_are_usage_errors_before_any_work() {
    let (_t, d) = setup();
    fs::create_dir(d.join("dir.json")).unwrap();
    fs::create_dir(d.join("dir.csv")).unwrap();
    fs::create_dir(d.join("dir.svg")).unwrap();
    fs::create_dir(d.join("dir.html")).unwrap();
    let before = names(&d);
    let cases: &[(&[&str], &str)] = &[
        (
            &["fair", "in.csv", "-o", "out.csv", "--report", "dir.json"],
            "dir.json",
        ),
        (
            &[
                "fair",
                "in.csv",
                "-o",
                "out.csv",
                "--report",
                "/proc/x.json",
            ],
            "/proc/x.json",
        ),
        (&["fair", "in.csv", "-o", "/proc/x.csv"], "/proc/x.csv"),
        (&["fair", "in.csv", "-o", "dir.csv"], "dir.csv"),
        (
            &["fair", "in.csv", "-o", "out.csv", "--curve-out", "dir.json"],
            "dir.json",
        ),
        (&["plot", "in.csv", "-o", "/proc/x.svg"], "/proc/x.svg"),
        (&["plot", "in.csv", "-o", "dir.svg"], "dir.svg"),
        (&["report", "in.csv", "-o", "/proc/x.html"], "/proc/x.html"),
        (&["report", "in.csv", "-o", "dir.html"], "dir.html"),
        (&["batch", "in.csv", "-o", "/proc/out"], "/proc/out"),
        (
            &["batch", "in.csv", "-o", "out", "--summary", "/proc/s.csv"],
            "/proc/s.csv",
        ),
        (
            &["batch", "in.csv", "-o", "out", "--summary", "dir.json"],
            "dir.json",
        ),
    ];
    for (a, path) in cases {
        let o = batten_in(&d, a);
        assert_usage_error(&o, &[path, "cannot write"]);
        assert_eq!(names(&d), before, "{a:?} left files behind");
    }
}

/// `batch` on an input folder that does not exist says so, exit 2, and creates neither the
/// output directory nor the summary.
#[test]
fn batch_with_a_missing_input_directory_creates_nothing() {
    let (_t, d) = setup();
    let o = batten_in(&d, &["batch", "nothere", "-o", "out", "--summary", "s.csv"]);
    assert_usage_error(&o, &["nothere", "no such file or directory"]);
    assert_eq!(names(&d), ["in.csv"]);
    let o = batten_in(&d, &["batch", "scans/", "-o", "out"]);
    assert_usage_error(&o, &["scans/", "no such file or directory"]);
    assert_eq!(names(&d), ["in.csv"]);
}

#[test]
fn clap_usage_errors_are_one_line_naming_the_flag() {
    let (_t, d) = setup();
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["fair", "in.csv", "-o", "o.csv", "--tolerance", "-0.1"],
            &["--tolerance", "-0.1", "negative"],
        ),
        (
            &["fair", "in.csv", "-o", "o.csv", "--fix-ends", "tangent"],
            &["--fix-ends=tangent"],
        ),
        (
            &["plot", "in.csv", "-o", "o.svg", "--kind", "foo"],
            &["--kind", "foo", "comb", "curvature", "all"],
        ),
        (
            &["batch", "in.csv", "-o", "out", "--jobs", "0"],
            &["--jobs", "0"],
        ),
        (&["fair", "in.csv"], &["--output"]),
        (&["fair", "in.csv", "-o", "o.csv", "--bogus"], &["--bogus"]),
        (&["frobnicate"], &["frobnicate"]),
        (
            &["fair", "in.csv", "-o", "o.csv", "--tolerance", "abc"],
            &["--tolerance", "abc", "auto"],
        ),
    ];
    for (a, needles) in cases {
        let o = batten_in(&d, a);
        assert_usage_error(&o, needles);
    }
    // Help and version still print in full, on stdout, exit 0.
    let o = batten_in(&d, &["fair", "--help"]);
    assert_eq!(o.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&o.stdout).lines().count() > 10);
}

#[test]
fn input_problems_are_named_at_the_line() {
    let (_t, d) = setup();
    let big = "x,y\n0,0\n1,1e308\n2,0\n3,1\n4,0\n";
    fs::write(d.join("big.csv"), big).unwrap();
    let o = batten_in(&d, &["fair", "big.csv", "-o", "o.csv"]);
    assert_usage_error(&o, &["big.csv:3:", "1e300"]);
    let o = batten_in(&d, &["analyze", "big.csv"]);
    assert_usage_error(&o, &["big.csv:3:", "1e300"]);

    // Two points 1e-15 apart on a curve about 7 long.
    let near = "x,y\n0,0\n1,1\n1.000000000000001,1\n2,0\n3,1\n4,0\n5,1\n";
    fs::write(d.join("near.csv"), near).unwrap();
    let o = batten_in(&d, &["fair", "near.csv", "-o", "o.csv"]);
    assert_usage_error(&o, &["near.csv:4:", "line 3", "nearly duplicates"]);

    let c = r#"{"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0], [1, 1]], "foo": 1}"#;
    fs::write(d.join("c.json"), c).unwrap();
    let o = batten_in(&d, &["fair", "c.json", "-o", "o.json", "--method", "salvi"]);
    assert_usage_error(&o, &["c.json:1:", "unknown field `foo`"]);

    let c3 =
        "{\"degree\": 1, \"knots\": [0, 0, 1, 1],\n \"control_points\": [[0, 0],\n [1, 1, 0]]}";
    fs::write(d.join("c3.json"), c3).unwrap();
    let o = batten_in(
        &d,
        &["fair", "c3.json", "-o", "o.json", "--method", "salvi"],
    );
    assert_usage_error(&o, &["c3.json:3:", "expected 2 fields (x, y), found 3"]);

    let bad = r#"{"degree": 1, "knots": [0, 0, 1], "control_points": [[0, 0], [1, 1]]}"#;
    fs::write(d.join("bad.json"), bad).unwrap();
    let o = batten_in(&d, &["evaluate", "bad.json"]);
    assert_usage_error(&o, &["bad.json", "knot"]);

    let o = batten_in(
        &d,
        &[
            "fair",
            "in.csv",
            "-o",
            "o.csv",
            "--method",
            "kuragano",
            "--set",
            "gradient_fraction=0",
        ],
    );
    assert_usage_error(&o, &["gradient_fraction", "positive"]);
    assert_eq!(
        names(&d),
        [
            "big.csv", "bad.json", "c.json", "c3.json", "in.csv", "near.csv"
        ]
        .iter()
        .copied()
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect::<Vec<_>>()
    );
}

#[test]
fn counts_of_one_are_singular() {
    let (_t, d) = setup();
    let o = batten_in(
        &d,
        &[
            "fair",
            "in.csv",
            "-o",
            "o.csv",
            "--method",
            "cali",
            "--max-iterations",
            "1",
        ],
    );
    let err = stderr(&o);
    assert!(err.contains(" 1 iteration,"), "{err}");
    fs::write(d.join("one.csv"), "x,y\n0,0\n").unwrap();
    let o = batten_in(&d, &["analyze", "one.csv"]);
    assert_usage_error(&o, &["one.csv: 1 point, at least 4 needed"]);
    let o = batten_in(&d, &["batch", "in.csv", "-o", "out"]);
    let err = stderr(&o);
    assert!(err.contains("batch: 1 file: "), "{err}");
}
