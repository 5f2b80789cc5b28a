//! The curvature samples of `salvi` and the target g made from them
//! (docs/algorithms/salvi-varady.md §3 steps 2–4): the sample count, the signed curvature at the
//! samples, the smoothers (moving average, a B-spline fit of κ(s), or given), the pinned ends, and
//! the measure Ê of eq 14 (`docs/algorithms/salvi-varady.md`, "Samples", "Target curvature", "The
//! measure").

use crate::analysis::{ArcLengthTable, signed_curvature};
use crate::curve::{CurveDeriv, Piecewise};
use crate::error::{Error, Result};
use crate::geom::Point;
use crate::numeric::SymBanded;
use crate::spline::{BSplineCurve, KnotVector, MAX_ORDER};

/// Spec default number of samples N (§3 step 2).
pub(super) const DEFAULT_SAMPLES: usize = 200;

/// The default sample count is at least this many per non-empty knot span.
pub(super) const SAMPLES_PER_SPAN: usize = 8;

/// Fewest samples accepted.
pub(super) const MIN_SAMPLES: usize = 4;

/// Most samples accepted when given: every iteration evaluates its simplex over the samples
/// of one support, so a run costs about 1 ms per 1000 samples per iteration (20 000 samples
/// and the default 1000 iterations: about 20 s; 10⁶ ran for more than 5 minutes). The
/// automatic count, 8 per knot span, is not capped. Also the bound of `half_width` and
/// `target_coefficients`, which are counts of samples.
pub const MAX_SAMPLES: usize = 20_000;

/// The moving-average half-width is `⌊N / HALF_WIDTH_DIVISOR⌋` (docs/algorithms/salvi-varady.md §3
/// step 3.2).
pub(super) const HALF_WIDTH_DIVISOR: usize = 20;

/// Passes of the moving average (docs/algorithms/salvi-varady.md §3 step 3.2).
pub(super) const DEFAULT_PASSES: usize = 3;

/// Coefficients of the B-spline target fit: `max(MIN_TARGET_COEFFICIENTS, ⌊N/20⌋)`.
pub(super) const MIN_TARGET_COEFFICIENTS: usize = 4;

/// The B-spline target fit samples κ at this many arc-length points per coefficient.
pub(super) const LOOSE_SAMPLES_PER_COEFFICIENT: usize = 4;

/// How the target curvature g is made from the curvature of the unfaired curve.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Smoother {
    /// Centred moving average, window truncated at the ends, repeated (normative,
    /// docs/algorithms/salvi-varady.md §3).
    MovingAverage {
        /// Half-width h in samples; `None`: `⌊N/20⌋`.
        half_width: Option<usize>,
        /// Number of passes.
        passes: usize,
    },
    /// Least-squares cubic B-spline function of arc length over a loose sampling.
    BSplineFit {
        /// Number of coefficients; `None`: `max(4, ⌊N/20⌋)`.
        coefficients: Option<usize>,
    },
    /// A target given sample by sample (the paper's manual editing); length N.
    Given(Vec<f64>),
}

impl Smoother {
    /// The normative default: moving average, `h = ⌊N/20⌋`, 3 passes.
    pub const DEFAULT: Smoother = Smoother::MovingAverage {
        half_width: None,
        passes: DEFAULT_PASSES,
    };
}

impl Default for Smoother {
    fn default() -> Smoother {
        Smoother::DEFAULT
    }
}

/// Signed curvature (§0.1) of `curve` at each parameter.
///
/// # Errors
/// [`Error::Degenerate`] at a parameter where the curvature is undefined (zero speed).
#[cfg(test)]
pub(super) fn sample_curvature(curve: &BSplineCurve, t: &[f64]) -> Result<Vec<f64>> {
    t.iter()
        .map(|&ti| {
            let k = signed_curvature(&curve.derivatives(ti));
            if k.is_finite() {
                Ok(k)
            } else {
                Err(zero_speed(ti))
            }
        })
        .collect()
}

pub(super) fn zero_speed(t: f64) -> Error {
    Error::Degenerate(format!(
        "the curve has zero speed at t = {t}, where its curvature is undefined"
    ))
}

/// The normative smoother (docs/algorithms/salvi-varady.md §3 step 3.2): a centred moving average
/// of half-width h whose window is truncated at the ends (the mean of the samples that exist),
/// applied `passes` times. O(N) per pass.
pub(super) fn moving_average(values: &[f64], half_width: usize, passes: usize) -> Vec<f64> {
    let n = values.len();
    let mut cur = values.to_vec();
    let mut prefix = vec![0.0; n + 1];
    for _ in 0..passes {
        for i in 0..n {
            prefix[i + 1] = prefix[i] + cur[i];
        }
        for (i, c) in cur.iter_mut().enumerate() {
            let lo = i.saturating_sub(half_width);
            let hi = (i + half_width + 1).min(n);
            *c = (prefix[hi] - prefix[lo]) / (hi - lo) as f64;
        }
    }
    cur
}

/// Eq 14: `Σ_i (κ_i − g_i)²`.
///
/// # Panics
/// If the lengths differ.
#[cfg(test)]
pub(super) fn target_measure(kappa: &[f64], target: &[f64]) -> f64 {
    assert_eq!(
        kappa.len(),
        target.len(),
        "κ and g must have one value per sample"
    );
    kappa
        .iter()
        .zip(target)
        .map(|(k, g)| (k - g) * (k - g))
        .sum()
}

/// The sample count asked for, or the default `max(200, 8 × non-empty spans)`.
pub(super) fn sample_count(curve: &BSplineCurve, samples: Option<usize>) -> usize {
    samples.unwrap_or_else(|| {
        let spans = curve.breakpoints().len().saturating_sub(1);
        DEFAULT_SAMPLES.max(SAMPLES_PER_SPAN * spans)
    })
}

/// The target curvature g at the samples `t` of `curve`, whose curvature there is `kappa`
/// (docs/algorithms/salvi-varady.md §3 step 3).
///
/// # Errors
/// [`Error::LengthMismatch`] for a given target of the wrong length or `kappa` not matching
/// `t`; [`Error::InvalidParameter`] for a B-spline fit with fewer than 4 coefficients;
/// [`Error::Degenerate`] for a curve of zero length or zero speed; [`Error::Singular`].
pub(super) fn target_curvature(
    curve: &BSplineCurve,
    t: &[f64],
    kappa: &[f64],
    smoother: &Smoother,
    pin_ends: bool,
) -> Result<Vec<f64>> {
    let n = t.len();
    if kappa.len() != n {
        return Err(Error::LengthMismatch {
            what: "curvature samples",
            got: kappa.len(),
            expected: n,
        });
    }
    let default_h = n / HALF_WIDTH_DIVISOR;
    let (mut g, ramp) = match smoother {
        Smoother::MovingAverage { half_width, passes } => {
            let h = half_width.unwrap_or(default_h);
            (moving_average(kappa, h, *passes), h)
        }
        Smoother::BSplineFit { coefficients } => {
            let m = coefficients.unwrap_or(MIN_TARGET_COEFFICIENTS.max(default_h));
            (bspline_target(curve, t, m)?, default_h)
        }
        Smoother::Given(g) => {
            if g.len() != n {
                return Err(Error::LengthMismatch {
                    what: "target curvature",
                    got: g.len(),
                    expected: n,
                });
            }
            if let Some(index) = g.iter().position(|v| !v.is_finite()) {
                return Err(Error::NonFinite { index });
            }
            (g.clone(), default_h)
        }
    };
    if pin_ends && n >= 2 {
        let h = ramp.clamp(1, (n - 1) / 2).max(1) as f64;
        let (e0, e1) = (kappa[0] - g[0], kappa[n - 1] - g[n - 1]);
        for (i, gi) in g.iter_mut().enumerate() {
            let a = (1.0 - i as f64 / h).max(0.0);
            let b = (1.0 - (n - 1 - i) as f64 / h).max(0.0);
            *gi += e0 * a + e1 * b;
        }
        g[0] = kappa[0];
        g[n - 1] = kappa[n - 1];
    }
    Ok(g)
}

/// Least-squares cubic B-spline function g(s) with `m` coefficients on uniform knots over
/// the arc length, fitted to κ at `4m` arc-length-uniform points, evaluated at `s(t_i)`.
fn bspline_target(curve: &BSplineCurve, t: &[f64], m: usize) -> Result<Vec<f64>> {
    if m < MIN_TARGET_COEFFICIENTS {
        return Err(Error::InvalidParameter {
            name: "target_coefficients".into(),
            reason: format!("{m} is below {MIN_TARGET_COEFFICIENTS}"),
        });
    }
    let table = ArcLengthTable::new(curve);
    let total = table.total();
    if !(total > 0.0 && total.is_finite()) {
        return Err(Error::Degenerate("the curve has zero length".into()));
    }
    let degree = 3;
    // The basis of g, evaluated through a B-spline whose control points are placeholders.
    let basis = BSplineCurve::try_new(
        degree,
        KnotVector::clamped_uniform(degree, m)?,
        vec![Point::ORIGIN; m],
        None,
    )?;
    let loose = LOOSE_SAMPLES_PER_COEFFICIENT * m;
    let mut normal = SymBanded::zeros(m, degree);
    let mut rhs = vec![0.0; m];
    let mut b = [[0.0; MAX_ORDER]; 4];
    for l in 0..loose {
        let u = l as f64 / (loose - 1) as f64;
        let tl = table.t_at(curve, u * total);
        let k = signed_curvature(&curve.derivatives(tl));
        if !k.is_finite() {
            return Err(zero_speed(tl));
        }
        let span = basis.find_span(u);
        basis.basis_derivs(span, u, 0, &mut b);
        for a in 0..=degree {
            let ia = span - degree + a;
            rhs[ia] += b[0][a] * k;
            for c in 0..=a {
                normal.add(ia, span - degree + c, b[0][a] * b[0][c]);
            }
        }
    }
    normal.factorize()?;
    normal.solve_in_place(&mut rhs)?;
    Ok(t.iter()
        .map(|&ti| {
            let u = (table.s_at(curve, ti) / total).clamp(0.0, 1.0);
            let span = basis.find_span(u);
            basis.basis_derivs(span, u, 0, &mut b);
            (0..=degree).map(|a| b[0][a] * rhs[span - degree + a]).sum()
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moving_average_vector() {
        // Vector sv.target_smoothing.
        let k = [0.0, 1.0, 0.0, 2.0, 1.0, 3.0, 2.0, 2.0, 5.0, 4.0];
        let g = moving_average(&k, 1, 1);
        let exp = [
            0.5,
            1.0 / 3.0,
            1.0,
            1.0,
            2.0,
            2.0,
            7.0 / 3.0,
            3.0,
            11.0 / 3.0,
            4.5,
        ];
        for (a, b) in g.iter().zip(exp) {
            assert!((a - b).abs() <= 1e-12 + 1e-12 * b.abs());
        }
        assert!((target_measure(&k, &g) - 7.83333333333).abs() < 1e-10);
        assert_eq!(moving_average(&k, 3, 0), k);
        assert_eq!(moving_average(&[], 3, 2), Vec::<f64>::new());
    }
}
