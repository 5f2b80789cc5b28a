//! Tests of the `han` method (docs/algorithms/han.md §1): every `han.*` test vector, the properties
//! of the unit responses, each fairing case on a constructed example, the curve pipeline
//! (partition, strophoid, closed curves) and property tests (tolerance, fixed ends, rigid motions).
//!
//! Unit tests (formerly `tests/han.rs`): they reach the paper's case procedures, the unit
//! responses and the partition, which are not public.

#![allow(clippy::unwrap_used, clippy::needless_range_loop)]

use std::collections::BTreeMap;
use std::f64::consts::{FRAC_PI_2, PI};

use super::params::{DEFAULT_FINE_RUN3, DEFAULT_ITERATIONS};
use super::partition::{Span, partition, turning_angles};
use super::pipeline::MAX_LOCAL_SLOPE;
use super::responses::UnitResponses;
use super::segment::{CaseMove, MoveTag, Procedure, Segment, SegmentParams};
use crate::analysis::{FairnessMetrics, ZERO_REL};
use crate::fair::{self, FairOptions, FairStatus};
use crate::spline::{CubicSplineFn, FnEndCondition};
use crate::{Error, Point, PointSeq, Rigid, Vec2};
use proptest::prelude::*;
use serde_json::Value;

mod cases;
mod pipeline;
mod properties;
mod responses;
mod segment;

// ---------------------------------------------------------------------------------------------
// Test-vector plumbing
// ---------------------------------------------------------------------------------------------

fn vectors() -> Vec<Value> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/test-vectors.json");
    let text = std::fs::read_to_string(path).expect("test vectors");
    let all: Value = serde_json::from_str(&text).expect("valid JSON");
    all["han"].as_array().expect("han vectors").clone()
}

fn vector(id: &str) -> Value {
    vectors()
        .into_iter()
        .find(|v| v["id"] == id)
        .unwrap_or_else(|| panic!("no vector {id}"))
}

fn arr(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

#[derive(Clone, Copy, Debug)]
struct Tol {
    abs: f64,
    rel: f64,
}

fn tol(v: &Value) -> Tol {
    Tol {
        abs: v["tolerance"]["abs"].as_f64().expect("abs"),
        rel: v["tolerance"]["rel"].as_f64().expect("rel"),
    }
}

fn check(what: &str, got: f64, want: f64, t: Tol) {
    assert!(
        (got - want).abs() <= t.abs + t.rel * want.abs(),
        "{what}: got {got:e}, expected {want:e} (diff {:e})",
        (got - want).abs()
    );
}

fn check_all(what: &str, got: &[f64], want: &[f64], t: Tol) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        check(&format!("{what}[{k}]"), *g, *w, t);
    }
}

/// A small deterministic generator (xorshift64*) for reproducible random data.
struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
    fn normal(&mut self, sigma: f64) -> f64 {
        let u1 = self.uniform(f64::MIN_POSITIVE, 1.0);
        let u2 = self.uniform(0.0, 1.0);
        sigma * (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
    }
}

fn noisy_sine_curve(n: usize, sigma: f64, seed: u64) -> Vec<Point> {
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|i| {
            let x = 4.0 * PI * i as f64 / (n - 1) as f64;
            let noise = if i == 0 || i == n - 1 {
                0.0
            } else {
                rng.normal(sigma)
            };
            Point::new(x, (x / 2.0).sin() + noise)
        })
        .collect()
}

fn random_curve(seed: u64, n: usize, closed: bool) -> Vec<Point> {
    let mut rng = Rng::new(seed);
    if closed {
        let (rx, ry) = (rng.uniform(1.0, 10.0), rng.uniform(1.0, 10.0));
        return (0..n)
            .map(|i| {
                let a = 2.0 * PI * i as f64 / n as f64;
                let s = 0.05 * rx.min(ry);
                Point::new(rx * a.cos() + rng.normal(s), ry * a.sin() + rng.normal(s))
            })
            .collect();
    }
    // A random smooth curve (spiral arc or wave) plus noise.
    let turns = rng.uniform(-8.0, 8.0);
    let noise = rng.uniform(0.0, 0.05);
    let mut p = Point::new(rng.uniform(-100.0, 100.0), rng.uniform(-100.0, 100.0));
    let mut heading = rng.uniform(-PI, PI);
    let mut out = vec![p];
    for i in 1..n {
        let s = i as f64 / n as f64;
        heading += turns / n as f64 * (1.0 + (7.0 * s).sin());
        let step = rng.uniform(0.5, 1.5);
        p = p + Vec2::from_angle(heading) * step + Vec2::new(rng.normal(noise), rng.normal(noise));
        out.push(p);
    }
    out
}
