//! The one seeded random generator of the tests: the unit tests inside the crate take it as
//! `crate::test_rng` (compiled only for tests), the integration tests through
//! `tests/common` (which includes this file), so both draw the same numbers from a seed.
//!
//! A plain xorshift (no crate): a seed gives the same numbers on every platform, and a failing
//! case can be re-run from its seed.

#![allow(dead_code)]

use std::f64::consts::TAU;

/// A seeded xorshift (shifts 13, 7, 17) with uniform and Gaussian samples.
#[derive(Clone, Debug)]
pub(crate) struct Rng(u64);

impl Rng {
    /// The generator for `seed`: any seed, 0 included, gives a nonzero state.
    pub(crate) fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    /// The next 64 random bits.
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// Uniform in [0, 1), on a grid of 2⁻⁵³.
    pub(crate) fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [−0.5, 0.5).
    pub(crate) fn centered(&mut self) -> f64 {
        self.uniform() - 0.5
    }

    /// A standard normal sample: Box–Muller on two uniform samples.
    pub(crate) fn gaussian(&mut self) -> f64 {
        let (a, b) = (self.uniform(), self.uniform());
        (-2.0 * a.max(1e-300).ln()).sqrt() * (TAU * b).cos()
    }

    /// One sample of `noise`.
    pub(crate) fn sample(&mut self, noise: Noise) -> f64 {
        match noise {
            Noise::Uniform(width) => width * self.centered(),
            Noise::Gaussian(sigma) => sigma * self.gaussian(),
        }
    }
}

/// Noise added to each coordinate.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Noise {
    /// Uniform of this width, centred on zero: `width · [−0.5, 0.5)`.
    Uniform(f64),
    /// Gaussian with this standard deviation.
    Gaussian(f64),
}
