//! Reading the verified test vectors (`tests/data/test-vectors.json`, format in
//! `docs/algorithms/README.md` §7) in tests: the unit tests take it as `crate::test_vectors`
//! (compiled only for tests), the integration tests through `tests/common`, which includes
//! this file.

#![allow(dead_code)]

use serde_json::Value;

use crate::Point;

const VECTORS: &str = include_str!("../tests/data/test-vectors.json");

/// The vector `id` of the list `section` (`"kuragano"`, `"salvi_varady"`, …).
pub(crate) fn vector(section: &str, id: &str) -> Value {
    let all: Value = serde_json::from_str(VECTORS).expect("test-vectors.json parses");
    all[section]
        .as_array()
        .unwrap_or_else(|| panic!("{section} is a list"))
        .iter()
        .find(|v| v["id"] == id)
        .unwrap_or_else(|| panic!("vector {section}/{id} not found"))
        .clone()
}

/// A number.
pub(crate) fn num(v: &Value) -> f64 {
    v.as_f64().expect("number")
}

/// An array of numbers.
pub(crate) fn nums(v: &Value) -> Vec<f64> {
    v.as_array().expect("array").iter().map(num).collect()
}

/// An array of `[x, y]` pairs.
pub(crate) fn points(v: &Value) -> Vec<Point> {
    v.as_array()
        .expect("point list")
        .iter()
        .map(|p| Point::new(num(&p[0]), num(&p[1])))
        .collect()
}

/// The vectors' check `|got − exp| ≤ abs + rel·|exp|`, with `tol` = `{abs, rel}`.
pub(crate) fn close(got: f64, exp: f64, tol: &Value, what: &str) {
    let (abs, rel) = (num(&tol["abs"]), num(&tol["rel"]));
    assert!(
        (got - exp).abs() <= abs + rel * exp.abs(),
        "{what}: got {got:e}, expected {exp:e}"
    );
}

/// [`close`] element-wise, after checking the lengths agree.
pub(crate) fn all_close(got: &[f64], exp: &[f64], tol: &Value, what: &str) {
    assert_eq!(got.len(), exp.len(), "{what}: length");
    for (i, (g, e)) in got.iter().zip(exp).enumerate() {
        close(*g, *e, tol, &format!("{what}[{i}]"));
    }
}
