//! What the library's integration tests share: one seeded random generator, and the
//! analytic curves they add its noise to.
//!
//! The generator is a plain xorshift (no crate), so a seed gives the same numbers on every
//! platform and a failing case can be re-run from its seed. Noise is added point by point,
//! x before y (before z), in the order of the points.

#![allow(dead_code)]

use std::f64::consts::TAU;

use batten::Point;

#[path = "../../src/test_rng.rs"]
mod test_rng;
pub(crate) use test_rng::{Noise, Rng};

/// `points` with `noise` from `seed` added to each coordinate.
pub fn jitter(points: &[Point], noise: Noise, seed: u64) -> Vec<Point> {
    let mut rng = Rng::new(seed);
    points
        .iter()
        .map(|p| Point::new(p.x + rng.sample(noise), p.y + rng.sample(noise)))
        .collect()
}

/// `n` samples of `y = sin x`, `x` evenly spaced on `[0, x_max]`.
pub fn sine(n: usize, x_max: f64) -> Vec<Point> {
    (0..n)
        .map(|i| {
            let x = x_max * i as f64 / (n - 1) as f64;
            Point::new(x, x.sin())
        })
        .collect()
}

/// `n` samples of the closed three-lobed loop `r = 1 + 0.2 cos 3a`, `a` evenly spaced on
/// `[0, 2π)` (the last point is not the first again).
pub fn lobed_loop(n: usize) -> Vec<Point> {
    (0..n)
        .map(|i| {
            let a = TAU * i as f64 / n as f64;
            let r = 1.0 + 0.2 * (3.0 * a).cos();
            Point::new(r * a.cos(), r * a.sin())
        })
        .collect()
}

/// `n` samples of the ellipse arc `(a cos t, b sin t)`, `t` evenly spaced on `[0, t_max]`.
pub fn ellipse_arc(n: usize, a: f64, b: f64, t_max: f64) -> Vec<Point> {
    (0..n)
        .map(|i| {
            let t = t_max * i as f64 / (n - 1) as f64;
            Point::new(a * t.cos(), b * t.sin())
        })
        .collect()
}
