//! What the library's integration tests share: one seeded random generator, and the
//! analytic curves they add its noise to.
//!
//! The generator is a plain xorshift (no crate), so a seed gives the same numbers on every
//! platform and a failing case can be re-run from its seed. Noise is added point by point,
//! x before y (before z), in the order of the points.

#![allow(dead_code)]

use std::f64::consts::TAU;

use batten::Point;

/// A seeded xorshift (shifts 13, 7, 17) with uniform and Gaussian samples.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// The generator for `seed`: any seed, 0 included, gives a nonzero state.
    pub fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    /// Uniform in [0, 1), on a grid of 2⁻⁵³.
    pub fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [−0.5, 0.5).
    pub fn centered(&mut self) -> f64 {
        self.uniform() - 0.5
    }

    /// A standard normal sample: Box–Muller on two uniform samples.
    pub fn gaussian(&mut self) -> f64 {
        let (a, b) = (self.uniform(), self.uniform());
        (-2.0 * a.max(1e-300).ln()).sqrt() * (TAU * b).cos()
    }

    /// One sample of `noise`.
    pub fn sample(&mut self, noise: Noise) -> f64 {
        match noise {
            Noise::Uniform(width) => width * self.centered(),
            Noise::Gaussian(sigma) => sigma * self.gaussian(),
        }
    }
}

/// Noise added to each coordinate.
#[derive(Clone, Copy, Debug)]
pub enum Noise {
    /// Uniform of this width, centred on zero: `width · [−0.5, 0.5)`.
    Uniform(f64),
    /// Gaussian with this standard deviation.
    Gaussian(f64),
}

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
