//! What the benches share: one deterministic noise source and the noisy spiral most of them
//! time, so that every bench measures the same inputs run after run.

#![allow(dead_code)]

use batten::Point;

/// Uniform pseudo-random numbers in `[−0.5, 0.5)`: a xorshift generator from a fixed seed.
pub fn uniform_noise() -> impl FnMut() -> f64 {
    let mut state = 0x2545_F491_4F6C_DD1D_u64;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}

/// Approximately standard normal numbers: the sum of four of [`uniform_noise`]'s, rescaled
/// to unit variance.
pub fn normal_noise() -> impl FnMut() -> f64 {
    let mut uniform = uniform_noise();
    move || (uniform() + uniform() + uniform() + uniform()) * 3.0_f64.sqrt()
}

/// `n` points of the spiral `r = 1 + 0.3a` over `a ∈ [0, turns·π)`, each coordinate moved
/// by `wobble` times the local spacing `step·r` times [`uniform_noise`].
pub fn noisy_spiral(n: usize, turns: f64, wobble: f64) -> Vec<Point> {
    let mut noise = uniform_noise();
    let step = turns * std::f64::consts::PI / n as f64;
    (0..n)
        .map(|i| {
            let a = i as f64 * step;
            let r = 1.0 + 0.3 * a;
            let e = wobble * step * r;
            Point::new(r * a.cos() + e * noise(), r * a.sin() + e * noise())
        })
        .collect()
}

/// `n` points of `y = sin(x)`, x in [0, 6], y moved by 0.005 times [`normal_noise`]: the
/// curves of `bench/python_speed.py`.
pub fn noisy_sine(n: usize) -> Vec<Point> {
    let mut noise = normal_noise();
    (0..n)
        .map(|i| {
            let x = 6.0 * i as f64 / (n - 1) as f64;
            Point::new(x, x.sin() + 0.005 * noise())
        })
        .collect()
}
