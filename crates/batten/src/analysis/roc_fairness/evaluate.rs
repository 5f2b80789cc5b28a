//! The fairness evaluation of a design (paper §5, docs/algorithms/kuragano.md §5.6): the
//! specification and the shape modification for every applicable degree, the cosine of the designed
//! and the modified ρ samples, and the best degree (`docs/algorithms/kuragano.md`, "Fairness
//! evaluation").

use serde::Serialize;

use super::fit::{MAX_DEGREE, MIN_DEGREE, RhoFit};
use super::modify::{Modification, ShapeConstraints, modify_shape};
use super::options::{DesignEnds, KuraganoOptions};
use super::samples::{RhoSamples, check_polynomial, default_samples, sample_rho};
use crate::curve::Piecewise;
use crate::error::Result;
use crate::geom::Point;
use crate::spline::BSplineCurve;
use crate::spline::quintic::{self, Ends, QuinticForm};

/// Cosines within this of the largest are a tie, resolved to the lowest degree
/// (docs/algorithms/kuragano.md §5.6): a higher degree is chosen only when it follows the design's
/// ρ better by more than this.
///
/// The paper breaks ties at its printed precision (Table 3 prints three decimals, Table 4
/// the angle to 0.01°). 10⁻⁴ is the size of what separates degrees on exact samples of
/// curves whose ρ *is* a low-degree polynomial: the design's ρ comes from the quintic
/// interpolant with estimated end gradients, whose ρ is off by about 1 % near the ends, and
/// higher degrees follow that error a little better (a 60-point log spiral, ρ linear in s:
/// 0.999688 for degree 1, 0.999778 for degree 6; a curve with ρ quadratic in s: 0.999736
/// for degree 2, 0.999800 for degree 6). The paper's own choices in Table 2 (six, 0.99993
/// against 0.99981 for quintic) and Table 4 (curves A, E, F, H) are kept; its curve B
/// (quintic 1.56° against quartic 1.58°, cosines 10⁻⁵ apart) would be quartic.
/// A tie tolerance of 10⁻⁶ reproduces the paper's choices.
pub const TIE_TOLERANCE: f64 = 1e-4;

/// The tie tolerance that reproduces every choice of the paper's Table 4 (curve B
/// included): two cosines near 1.5° that print as angles 0.02° apart differ by about 10⁻⁵.
#[cfg(test)]
pub(super) const PAPER_TIE_TOLERANCE: f64 = 1e-6;

/// The cosine of two sample vectors, not mean-centred (docs/algorithms/kuragano.md §5.6 step 2);
/// `None` when either is zero.
pub(super) fn cosine(a: &[f64], b: &[f64]) -> Option<f64> {
    let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    let na = a.iter().map(|x| x * x).sum::<f64>().sqrt();
    let nb = b.iter().map(|x| x * x).sum::<f64>().sqrt();
    (na > 0.0 && nb > 0.0).then(|| (dot / (na * nb)).clamp(-1.0, 1.0))
}

/// The angle `arccos(cos)` in degrees (docs/algorithms/kuragano.md §5.6 step 3).
pub fn angle_degrees(cos: f64) -> f64 {
    cos.clamp(-1.0, 1.0).acos().to_degrees()
}

/// Relative guard of [`truncate_angle`] against values that are a hair below a printed
/// decimal only through rounding (1.14 is stored as 1.13999…).
const TRUNCATE_GUARD_REL: f64 = 1e-9;

/// Truncate (not round) a non-negative angle to `decimals` places, as the paper's Table 4
/// and text print it (docs/algorithms/kuragano.md §5.6 step 3): 3.0061° → 3.00, 1.1459° → 1.14.
pub fn truncate_angle(deg: f64, decimals: u32) -> f64 {
    let f = 10f64.powi(decimals as i32);
    let scaled = deg * f;
    (scaled + TRUNCATE_GUARD_REL * scaled.abs().max(1.0)).floor() / f
}

/// The designed curve of [`evaluate`]: points (interpolated with [`KuraganoOptions::ends`])
/// or a curve.
#[derive(Clone, Copy, Debug)]
pub enum Design<'a> {
    /// A point sequence; the design is its uniform quintic interpolant.
    Points(&'a [Point]),
    /// A non-rational B-spline (any degree and knots; in the paper the uniform quintic of
    /// [`crate::spline::interpolate_quintic`]).
    Curve(&'a BSplineCurve),
}

impl<'a> From<&'a [Point]> for Design<'a> {
    fn from(p: &'a [Point]) -> Design<'a> {
        Design::Points(p)
    }
}

impl<'a> From<&'a Vec<Point>> for Design<'a> {
    fn from(p: &'a Vec<Point>) -> Design<'a> {
        Design::Points(p)
    }
}

impl<'a> From<&'a BSplineCurve> for Design<'a> {
    fn from(c: &'a BSplineCurve) -> Design<'a> {
        Design::Curve(c)
    }
}

/// One row of the evaluation (a row of the paper's Tables 3 and 4).
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct DegreeResult {
    /// The polynomial degree d.
    pub degree: usize,
    /// False when `ρ̂` changes sign (or the design has no valid ρ distribution).
    pub applicable: bool,
    /// The cosine between the designed and the predefined curve's ρ samples (`None` when not
    /// applicable).
    pub correlation: Option<f64>,
    /// `arccos(correlation)` in degrees, not truncated (`None` when not applicable).
    pub angle_deg: Option<f64>,
    /// S after the shape modification (not serialised).
    #[serde(skip)]
    pub s_final: Option<f64>,
    /// RMS of `ρ − ρ̂` after the shape modification (not serialised).
    #[serde(skip)]
    pub rho_rms: Option<f64>,
}

/// The fairness evaluation of a design (paper §5, docs/algorithms/kuragano.md §5.6). Serialised as
/// `{"degrees": [{"degree", "applicable", "correlation", "angle_deg"}, ...],
/// "best_degree", "fairness"}`, with `null` where a value does not exist.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Evaluation {
    /// Degrees 1..=6 in order.
    pub degrees: Vec<DegreeResult>,
    /// The degree with the largest cosine (ties within [`TIE_TOLERANCE`] to the lowest);
    /// `None` when no degree is applicable.
    pub best_degree: Option<usize>,
    /// The cosine of the best degree: the fairness of the design.
    pub fairness: Option<f64>,
}

impl DegreeResult {
    /// A row as the paper's tables print it, from its degree and cosine: applicable, with the
    /// angle of `correlation`, when there is one, not applicable otherwise; the figures of the
    /// shape modification (`s_final`, `rho_rms`) are absent.
    pub fn from_correlation(degree: usize, correlation: Option<f64>) -> DegreeResult {
        DegreeResult {
            degree,
            applicable: correlation.is_some(),
            correlation,
            angle_deg: correlation.map(angle_degrees),
            s_final: None,
            rho_rms: None,
        }
    }
}

impl Evaluation {
    /// The evaluation made of `degrees`, with the best degree chosen as [`evaluate`] chooses it
    /// (the largest cosine, ties within [`TIE_TOLERANCE`] to the lowest degree) and its cosine
    /// as the fairness.
    pub fn from_rows(degrees: Vec<DegreeResult>) -> Evaluation {
        let best = select_best(&degrees);
        Evaluation {
            best_degree: best.map(|d| d.degree),
            fairness: best.and_then(|d| d.correlation),
            degrees,
        }
    }
}

/// The selected row (docs/algorithms/kuragano.md §5.6 step 4): the applicable row with the largest
/// correlation, where correlations within [`TIE_TOLERANCE`] of the largest tie and the lowest
/// degree wins. `None` when no row has a correlation.
pub(super) fn select_best(rows: &[DegreeResult]) -> Option<&DegreeResult> {
    select_best_within(rows, TIE_TOLERANCE)
}

/// [`select_best`] with ties within `tie` (e.g. [`PAPER_TIE_TOLERANCE`]).
pub(super) fn select_best_within(rows: &[DegreeResult], tie: f64) -> Option<&DegreeResult> {
    let best = rows
        .iter()
        .filter(|d| d.applicable)
        .filter_map(|d| d.correlation)
        .fold(f64::NEG_INFINITY, f64::max);
    rows.iter()
        .filter(|d| d.applicable)
        .filter(|d| d.correlation.is_some_and(|c| c >= best - tie))
        .min_by_key(|d| d.degree)
}

/// Everything [`evaluate`] computed, for the fairing method.
pub(crate) struct Detailed {
    pub(crate) design: BSplineCurve,
    pub(crate) samples: RhoSamples,
    pub(crate) evaluation: Evaluation,
    pub(crate) modifications: Vec<Option<Modification>>,
}

/// The designed curve for a design.
pub(crate) fn design_curve(design: Design<'_>, opts: &KuraganoOptions) -> Result<BSplineCurve> {
    match design {
        Design::Curve(c) => {
            check_polynomial(c)?;
            Ok(c.clone())
        }
        Design::Points(p) => {
            let ends = match opts.ends {
                DesignEnds::Natural => Ends::Natural,
                DesignEnds::Gradients { fraction } => {
                    Ends::Gradients(quintic::end_gradients(p, fraction)?)
                }
            };
            quintic::interpolate(p, &ends, QuinticForm::BSpline)
        }
    }
}

/// Number of spans of a curve.
fn segments(curve: &BSplineCurve) -> usize {
    curve.breakpoints().len().saturating_sub(1).max(1)
}

/// The samples of the design with the options' `N_s` and `ρ_max`.
pub(crate) fn design_samples(curve: &BSplineCurve, opts: &KuraganoOptions) -> Result<RhoSamples> {
    let n = opts
        .samples
        .unwrap_or_else(|| default_samples(segments(curve)));
    sample_rho(curve, n, opts.rho_max)
}

/// The fits of every degree and whether each is applicable.
pub(crate) fn fits(samples: &RhoSamples) -> Result<Vec<(RhoFit, Vec<f64>, bool)>> {
    (MIN_DEGREE..=MAX_DEGREE)
        .map(|d| {
            let fit = RhoFit::fit(&samples.s, &samples.rho, d)?;
            let spec = fit.eval_all(&samples.s);
            let ok = !samples.inflected
                && !samples.straight
                && spec.iter().all(|&r| samples.sigma * r > 0.0);
            Ok((fit, spec, ok))
        })
        .collect()
}

pub(crate) fn evaluate_detailed(
    design: Design<'_>,
    opts: &KuraganoOptions,
    anchors: Option<(&[f64], &[Point])>,
) -> Result<Detailed> {
    opts.check()?;
    let curve = design_curve(design, opts)?;
    let samples = design_samples(&curve, opts)?;
    let mut degrees = Vec::with_capacity(MAX_DEGREE);
    let mut modifications = Vec::with_capacity(MAX_DEGREE);
    for (fit, spec, ok) in fits(&samples)? {
        let degree = fit.degree();
        if !ok {
            degrees.push(DegreeResult {
                degree,
                applicable: false,
                correlation: None,
                angle_deg: None,
                s_final: None,
                rho_rms: None,
            });
            modifications.push(None);
            continue;
        }
        let m = modify_shape(
            &curve,
            &samples,
            &spec,
            opts.residual,
            opts.max_iterations,
            &ShapeConstraints {
                anchors,
                ..ShapeConstraints::default()
            },
        )?;
        let c = cosine(&samples.rho, &m.samples.rho);
        degrees.push(DegreeResult {
            degree,
            applicable: true,
            correlation: c,
            angle_deg: c.map(angle_degrees),
            s_final: Some(m.s_final),
            rho_rms: Some(m.rho_rms),
        });
        modifications.push(Some(m));
    }
    let best = select_best(&degrees);
    let evaluation = Evaluation {
        best_degree: best.map(|d| d.degree),
        fairness: best.and_then(|d| d.correlation),
        degrees,
    };
    Ok(Detailed {
        design: curve,
        samples,
        evaluation,
        modifications,
    })
}

/// The fairness evaluation of a design (paper §5, docs/algorithms/kuragano.md §5.6): for every
/// applicable degree d = 1..6 the specification `ρ̂_d` and the shape modification towards it, then
/// the cosine of the designed and the modified ρ samples. A design with an inflection (or straight)
/// has no applicable degree: every row is not applicable and `best_degree` is `None`.
///
/// ```
/// use batten::Point;
/// use batten::analysis::{KuraganoOptions, evaluate_roc_fairness};
///
/// // A spiral arc: ρ grows with the arc length, no inflection.
/// let pts: Vec<Point> = (0..16)
///     .map(|i| {
///         let a = 0.2 * i as f64;
///         let r = 2.0 + 0.5 * a;
///         Point::new(r * a.cos(), r * a.sin())
///     })
///     .collect();
/// let e = evaluate_roc_fairness(&pts, &KuraganoOptions::default())?;
/// assert_eq!(e.degrees.len(), 6);
/// assert!(e.best_degree.is_some() && e.fairness.is_some_and(|c| c > 0.99));
/// // An S-shaped design has no applicable degree.
/// let s: Vec<Point> = (0..16).map(|i| Point::new(i as f64, (0.4 * i as f64).sin())).collect();
/// assert_eq!(evaluate_roc_fairness(&s, &KuraganoOptions::default())?.best_degree, None);
/// # Ok::<(), batten::Error>(())
/// ```
///
/// # Errors
/// Option errors ([`Error::InvalidParameter`]), the interpolation's errors for a point design,
/// [`Error::InvalidParameter`] for a rational curve with unequal weights, and
/// [`Error::Degenerate`] for a curve of zero length or with a zero-speed sample.
///
/// [`Error::InvalidParameter`]: crate::error::Error::InvalidParameter
/// [`Error::Degenerate`]: crate::error::Error::Degenerate
pub fn evaluate<'a>(design: impl Into<Design<'a>>, opts: &KuraganoOptions) -> Result<Evaluation> {
    evaluate_detailed(design.into(), opts, None).map(|d| d.evaluation)
}
