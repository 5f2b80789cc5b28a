//! The split of an arbitrary curve into overlapping function segments, each with the frame in
//! which it is a function `Y(X)` (`docs/algorithms/han.md`, "Fairing arbitrary curves", spec
//! §1.8 steps 2–4).

use std::f64::consts::PI;

use crate::error::{Error, Result};
use crate::geom::{Point, Vec2};

/// A function segment of a point sequence: points `start..=end` (0-based, inclusive) and the
/// direction θ (radians) of its local x axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Span {
    /// First point.
    pub start: usize,
    /// Last point (inclusive).
    pub end: usize,
    /// Local x-axis direction: the bisector of the extreme chord directions.
    pub theta: f64,
}

/// Chord directions `φ_i = atan2(P_{i+1} − P_i)`, i = 0..N−2.
///
/// # Errors
/// [`Error::NonFinite`], [`Error::DuplicatePoint`] (zero chord).
pub(super) fn chord_angles(points: &[Point]) -> Result<Vec<f64>> {
    if let Some(index) = points.iter().position(|p| !p.is_finite()) {
        return Err(Error::NonFinite { index });
    }
    points
        .windows(2)
        .enumerate()
        .map(|(i, w)| {
            let d = w[1] - w[0];
            if d == Vec2::ZERO {
                Err(Error::DuplicatePoint { index: i + 1 })
            } else {
                Ok(d.atan2())
            }
        })
        .collect()
}

/// Unwrapped turning angles (docs/algorithms/han.md §1.8 step 2, \[FIX\]): `α_0 = 0`,
/// `α_i = α_{i−1} + wrap(φ_i − φ_{i−1})` with wrap into (−π, π]; one per chord. `α_{N−2}` is
/// the total turning of the polyline.
///
/// # Errors
/// As [`chord_angles`].
#[cfg(test)]
pub(super) fn turning_angles(points: &[Point]) -> Result<Vec<f64>> {
    let phi = chord_angles(points)?;
    Ok(unwrap_turning(&phi))
}

fn unwrap_turning(phi: &[f64]) -> Vec<f64> {
    let mut alpha = Vec::with_capacity(phi.len());
    let mut acc = 0.0;
    for (i, &p) in phi.iter().enumerate() {
        if i > 0 {
            acc += wrap_angle(p - phi[i - 1]);
        }
        alpha.push(acc);
    }
    alpha
}

/// Wrap into (−π, π].
fn wrap_angle(a: f64) -> f64 {
    let w = a - (a / std::f64::consts::TAU).round() * std::f64::consts::TAU;
    if w <= -PI {
        w + std::f64::consts::TAU
    } else {
        w
    }
}

/// Split a point sequence into overlapping function segments (docs/algorithms/han.md §1.8 step 3):
/// from b, the first chord s whose inclusion makes `max α − min α > max_turn` ends the segment at
/// `P_{s−1}` (0-based: points `b..=s−1`); segments have at least `overlap + 2` points (capped
/// at the end); the next starts `overlap − 1` points before the end, so neighbours share
/// `overlap` points. Each span carries its bisector frame angle (step 4).
///
/// # Errors
/// [`Error::TooFewPoints`] for fewer than 2 points, [`Error::InvalidParameter`] for a
/// `max_turn` outside (0, π] or `overlap` = 0, and the errors of [`chord_angles`].
pub(super) fn partition(points: &[Point], max_turn: f64, overlap: usize) -> Result<Vec<Span>> {
    if points.len() < 2 {
        return Err(Error::TooFewPoints {
            needed: 2,
            got: points.len(),
        });
    }
    check_max_turn(max_turn)?;
    if overlap == 0 {
        return Err(Error::InvalidParameter {
            name: "overlap".into(),
            reason: "segments must share at least one point".into(),
        });
    }
    let phi = chord_angles(points)?;
    let alpha = unwrap_turning(&phi);
    let n = points.len();
    let mut spans = Vec::new();
    let mut b = 0;
    loop {
        let (mut hi, mut lo) = (alpha[b], alpha[b]);
        let mut end = n - 1;
        for (s, &a) in alpha.iter().enumerate().take(n - 1).skip(b + 1) {
            hi = hi.max(a);
            lo = lo.min(a);
            if hi - lo > max_turn {
                end = s - 1;
                break;
            }
        }
        end = end.max(b + overlap + 1).min(n - 1);
        spans.push(Span {
            start: b,
            end,
            theta: frame_angle(&phi, &alpha, b, end),
        });
        if end == n - 1 {
            return Ok(spans);
        }
        b = end + 1 - overlap;
    }
}

/// θ = φ_a + (α_u + α_l)/2 − α_a over the chords a..end−1 (docs/algorithms/han.md §1.8 step 4,
/// \[FIX\]).
fn frame_angle(phi: &[f64], alpha: &[f64], a: usize, end: usize) -> f64 {
    let chords = &alpha[a..end];
    let (hi, lo) = chords
        .iter()
        .fold((f64::NEG_INFINITY, f64::INFINITY), |(h, l), &v| {
            (h.max(v), l.min(v))
        });
    phi[a] + (hi + lo) / 2.0 - alpha[a]
}

pub(super) fn check_max_turn(max_turn: f64) -> Result<()> {
    if max_turn > 0.0 && max_turn <= PI {
        Ok(())
    } else {
        Err(Error::InvalidParameter {
            name: "max_turn".into(),
            reason: format!("{max_turn} is outside (0, π]"),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_is_half_open() {
        assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(0.25) - 0.25).abs() < 1e-16);
        assert!((wrap_angle(-2.0 * PI + 0.1) - 0.1).abs() < 1e-12);
    }
}
