//! Calì et al.'s local and global fairness indicators, LFI and GFI (docs/algorithms/cali.md §4.4).
//!
//! `LFI_i = (κ''_i)²` with κ'' the second divided difference of the signed curvature with
//! respect to arc length at the correspondence (Greville) points `ξ_i`, i = 1..m−1, and
//! `GFI = Σ LFI_i`. The paper does not say where κ'' is evaluated; the exact κ'' of a cubic is a
//! Dirac mass at the knots, so the spec's normative divided difference is used.

use std::sync::OnceLock;

use rayon::prelude::*;
use serde::Serialize;

use super::signed_curvature;
use crate::curve::CurveDeriv;
use crate::curve::Piecewise;
use crate::numeric::GaussLegendre;
use crate::spline::BSplineCurve;

/// The indicators of a B-spline curve, at its Greville points.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct FairnessIndicators {
    /// Greville abscissae ξ_0..ξ_m.
    pub xi: Vec<f64>,
    /// Signed curvature at ξ_i.
    pub kappa: Vec<f64>,
    /// Arc length from the start to ξ_i.
    pub s: Vec<f64>,
    /// LFI_i; zero at i = 0 and i = m, where it is not defined.
    pub lfi: Vec<f64>,
    /// GFI = Σ LFI_i.
    pub gfi: f64,
}

/// LFI and GFI of a B-spline curve (docs/algorithms/cali.md §4.4).
pub fn fairness_indicators(curve: &BSplineCurve) -> FairnessIndicators {
    let xi = curve.knots().greville(curve.degree());
    let cubic = curve.degree() == 3 && curve.weights().is_none();
    // In fixed chunks, each sweeping its spans forward from one search (the same spans as a
    // search per point, so the same numbers with any thread count).
    let kappa_of = |chunk: &[f64]| {
        let mut span = chunk.first().map_or(0, |&t| curve.find_span(t));
        chunk
            .iter()
            .map(|&t| {
                if cubic {
                    // signed_curvature's formula, on the cubic's own derivatives.
                    span = curve.find_span_from(t, span);
                    let [d1, d2, _] = curve.cubic_derivs_in_span(span, t);
                    let w = d1.length_squared();
                    d1.cross(d2) / (w * w.sqrt())
                } else {
                    signed_curvature(&curve.derivatives(t))
                }
            })
            .collect::<Vec<f64>>()
    };
    let kappa: Vec<f64> = if xi.len() <= KAPPA_CHUNK {
        // One chunk: no work for the thread pool (small curves, issue #17).
        kappa_of(&xi)
    } else {
        xi.par_chunks(KAPPA_CHUNK)
            .map(kappa_of)
            .collect::<Vec<_>>()
            .concat()
    };
    let s = arc_lengths_at_sorted(curve, &xi);
    let lfi = lfi_from_samples(&kappa, &s, None);
    let gfi = lfi.iter().sum();
    FairnessIndicators {
        xi,
        kappa,
        s,
        lfi,
        gfi,
    }
}

/// Arc length from the start of the domain to each of the increasing parameters `ts`, in one
/// O(n) sweep: each piece between consecutive parameters (split at the breakpoints) is
/// integrated once by Gauss–Legendre quadrature, instead of integrating from a span start
/// for every parameter. The pieces are integrated in parallel, a block at a time, and summed
/// in order, so the result is the same bit for bit with any number of threads.
pub(crate) fn arc_lengths_at_sorted(curve: &BSplineCurve, ts: &[f64]) -> Vec<f64> {
    static RULE: OnceLock<GaussLegendre> = OnceLock::new();
    let gl = RULE.get_or_init(|| GaussLegendre::new(ARC_NODES));
    let bp = curve.breakpoints();
    let piece = |(a, b, span): (f64, f64, usize)| {
        if curve.weights().is_some() {
            gl.integrate(a, b, |x| curve.first_derivative(x).length_squared().sqrt())
        } else if curve.degree() <= 3 {
            // x' of a polynomial piece of degree ≤ 3 is its Taylor expansion about the
            // piece's midpoint, exactly: one evaluation per piece instead of one per node
            // (the speed of 10⁶-point GFIs, issue #14).
            let half = 0.5 * (b - a);
            let mid = a + half;
            let [d1, d2, d3] = if curve.degree() == 3 {
                curve.cubic_derivs_in_span(span, mid)
            } else {
                let d = curve.derivs_in_span(span, mid);
                [d.d1, d.d2, d.d3]
            };
            let d3_half = d3 * 0.5;
            gl.integrate(-half, half, |s| {
                (d1 + (d2 + d3_half * s) * s).length_squared().sqrt()
            })
        } else {
            // The nodes are inside the piece's span.
            gl.integrate(a, b, |x| {
                curve
                    .first_derivative_in_span(span, x)
                    .length_squared()
                    .sqrt()
            })
        }
    };
    let mut out = Vec::with_capacity(ts.len());
    // Each piece with the span its quadrature evaluates on: the span containing the point
    // the per-piece search used to look up (its midpoint as each branch of `piece` computes
    // it), found by walking forward, since the pieces come in order.
    // (Sized to the curve when it is smaller than a block: a small curve's GFI should not
    // map and unmap half a megabyte.)
    let cap = (ts.len() + bp.len()).min(ARC_BLOCK) + 8;
    let mut pieces: Vec<(f64, f64, usize)> = Vec::with_capacity(cap);
    let rational = curve.weights().is_some();
    let mut span = curve.find_span(bp[0]);
    // The number of pieces up to each parameter of the block.
    let mut ends: Vec<usize> = Vec::with_capacity(cap);
    let (mut pos, mut s, mut k) = (bp[0], 0.0, 0);
    for (idx, &t) in ts.iter().enumerate() {
        while pos < t {
            while k + 1 < bp.len() && bp[k + 1] <= pos {
                k += 1;
            }
            let end = if k + 1 < bp.len() {
                t.min(bp[k + 1])
            } else {
                t
            };
            if end <= pos {
                break;
            }
            let probe = if curve.degree() <= 3 {
                pos + 0.5 * (end - pos)
            } else {
                0.5 * (pos + end)
            };
            if !rational {
                span = curve.find_span_from(probe, span);
            }
            pieces.push((pos, end, span));
            pos = end;
        }
        ends.push(pieces.len());
        if pieces.len() >= ARC_BLOCK || idx + 1 == ts.len() {
            let lengths: Vec<f64> = if pieces.len() >= 2 * ARC_MIN_PARALLEL {
                pieces.par_iter().map(|&p| piece(p)).collect()
            } else {
                pieces.iter().map(|&p| piece(p)).collect()
            };
            let mut j = 0;
            for &e in &ends {
                for l in &lengths[j..e] {
                    s += l;
                }
                j = e;
                out.push(s);
            }
            pieces.clear();
            ends.clear();
        }
    }
    out
}

/// Greville points per parallel work unit of [`fairness_indicators`]'s curvatures.
const KAPPA_CHUNK: usize = 4096;

/// Pieces per block of [`arc_lengths_at_sorted`].
const ARC_BLOCK: usize = 16_384;
/// Below twice this many pieces a block is integrated on the calling thread.
const ARC_MIN_PARALLEL: usize = 1024;

/// Gauss–Legendre nodes per piece in [`arc_lengths_at_sorted`]: the speed of a spline span is
/// smooth, and 8 nodes integrate it to rounding level on the pieces between Greville points.
const ARC_NODES: usize = 8;

/// `LFI_i = (κ''_i)²` from curvature samples `kappa` at arc lengths `s` (increasing). With
/// `period = Some(L)` the samples are cyclic (a closed curve of length L) and every sample gets
/// an indicator; otherwise the first and last are zero.
pub(crate) fn lfi_from_samples(kappa: &[f64], s: &[f64], period: Option<f64>) -> Vec<f64> {
    let n = kappa.len();
    let mut out = vec![0.0; n];
    let second = |km: f64, k0: f64, kp: f64, sm: f64, s0: f64, sp: f64| {
        lfi(km, k0, kp, [s0 - sm, sp - s0, sp - sm])
    };
    match period {
        Some(len) if n >= 3 => {
            for i in 0..n {
                let im = (i + n - 1) % n;
                let ip = (i + 1) % n;
                let sm = if i == 0 { s[im] - len } else { s[im] };
                let sp = if ip == 0 { s[0] + len } else { s[ip] };
                out[i] = second(kappa[im], kappa[i], kappa[ip], sm, s[i], sp);
            }
        }
        _ => {
            for i in 1..n.saturating_sub(1) {
                out[i] = second(
                    kappa[i - 1],
                    kappa[i],
                    kappa[i + 1],
                    s[i - 1],
                    s[i],
                    s[i + 1],
                );
            }
        }
    }
    out
}

/// Calì's `LFI = (κ'')²` at a sample (docs/algorithms/cali.md §4.4): the second divided
/// difference of the curvatures `k0` before, `k1` at and `k2` after it, with `l = [l01, l12,
/// l02]` the arc lengths from the first to the second, the second to the third and the first
/// to the third (each as the caller measures it).
#[inline]
pub(crate) fn lfi(k0: f64, k1: f64, k2: f64, l: [f64; 3]) -> f64 {
    let d = 2.0 * ((k2 - k1) / l[1] - (k1 - k0) / l[0]) / l[2];
    d * d
}
