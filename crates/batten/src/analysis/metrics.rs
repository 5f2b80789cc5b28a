//! [`FairnessMetrics`]: the numbers every report carries (spec §0.3, §0.4, §4.4).

use serde::Serialize;

use super::curvature::{curvature_derivative, signed_curvature};
use super::gfi::{fairness_indicators, lfi_from_samples};
use crate::error::{Error, Result};
use crate::geom::{Point, PointSeq};
use crate::numeric::GaussLegendre;
use crate::spline::{BSplineCurve, EndCondition, ParametricCubic, Parametrization};

/// Relative zero for sign tests (spec §1.7.0): `sgn0(v) = 0` when `|v| ≤ ZERO_REL·max|v_k|`.
pub const ZERO_REL: f64 = 1e-12;

/// Samples per span for curvature extrema and the maximum curvature. The derivative of
/// curvature of a cubic span changes sign at most a few times; 16 samples resolve it.
const SAMPLES_PER_SPAN: usize = 16;

/// Rounding-noise factor of the sign tests in [`FairnessMetrics::of_seq`]. The curvature of
/// the spline through collinear points is pure rounding noise, of size up to about
/// `ε·R/h_min²` (R the largest coordinate magnitude, h_min the shortest chord; measured on
/// collinear data with 10–1000 points and offsets up to 1000× the spacing). A value relative to
/// the largest one (as in [`count_sign_changes`]) does not filter it out, since then every value
/// is noise: curvatures below `NOISE_FACTOR·ε·R/h_min²`, and derivatives of curvature below
/// that over `h_min`, count as zero.
const NOISE_FACTOR: f64 = 64.0;

/// [`count_sign_changes`] with values of magnitude at most `floor` also counted as zero.
fn count_sign_changes_above(values: &[f64], cyclic: bool, floor: f64) -> usize {
    let filtered: Vec<f64> = values
        .iter()
        .map(|&v| if v.abs() <= floor { 0.0 } else { v })
        .collect();
    count_sign_changes(&filtered, cyclic)
}

/// The sign of `v` with values within `ZERO_REL · scale` of zero counted as 0 (spec §1.7.0).
#[inline]
pub fn sgn0(v: f64, scale: f64) -> i8 {
    if v.abs() <= ZERO_REL * scale {
        0
    } else if v > 0.0 {
        1
    } else {
        -1
    }
}

/// Number of sign changes along `values`: zeros (relative to the largest magnitude, see
/// [`sgn0`]) are skipped, so `+ 0 −` counts once and `+ 0 +` not at all. With `cyclic`, a
/// change from the last non-zero sign back to the first counts too.
pub fn count_sign_changes(values: &[f64], cyclic: bool) -> usize {
    let scale = values.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let signs: Vec<i8> = values
        .iter()
        .map(|&v| sgn0(v, scale))
        .filter(|&s| s != 0)
        .collect();
    let mut n = signs.windows(2).filter(|w| w[0] != w[1]).count();
    if cyclic && signs.len() > 1 && signs[0] != signs[signs.len() - 1] {
        n += 1;
    }
    n
}

/// Fairness numbers of a curve, as `batten analyze --json` prints them.
///
/// They are measured on the *analysis curve* of the points ([`analysis_curve`]): the C² cubic
/// spline through them with chord-length parameters, not-a-knot ends for an open curve
/// (\[CHOICE\]: it imposes no artificial zero curvature at the ends) and periodic for a closed one.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FairnessMetrics {
    /// Number of points.
    pub points: usize,
    /// Whether the curve is closed.
    pub closed: bool,
    /// Sign changes of the curvature along the curve. Exact for the cubic: the curvature
    /// numerator `r'×r''` of a span is a quadratic, so its values at the knots and at its
    /// vertex carry every sign change.
    pub inflections: usize,
    /// Curvature vibrations (HAN's `Vib_num` on the parametric spline): sign changes of the
    /// jumps of dκ/ds at the interior knots. For a function graph the jump of dκ/ds at x_i
    /// has the sign of HAN's `e_i` (spec §1.4).
    pub vibrations: usize,
    /// Local extrema of κ(s): the number of monotone pieces of the curvature plot minus one.
    pub curvature_extrema: usize,
    /// `∫ κ² ds`.
    pub strain_energy: f64,
    /// `∫ (dκ/ds)² ds`.
    pub variation_energy: f64,
    /// Largest |κ| (sampled densely).
    pub max_curvature: f64,
    /// Calì's global fairness indicator (spec §4.4) on the cubic B-spline interpolant with
    /// averaging knots (open curves), or on the periodic spline at its knots (closed curves).
    pub gfi: f64,
    /// Largest `|r'''(t_k+) − r'''(t_k−)|` at the knots of the analysis curve (the bad-point
    /// measure of Kjellander and Poliakoff).
    pub max_third_derivative_jump: f64,
    /// Total arc length.
    pub length: f64,
}

/// The C² cubic spline through the points that all metrics are measured on (see
/// [`FairnessMetrics`]).
///
/// # Errors
/// The spline constructors' errors (too few points, zero chords).
pub fn analysis_curve(seq: &PointSeq) -> Result<ParametricCubic> {
    if seq.is_closed() {
        ParametricCubic::closed(seq.points(), Parametrization::ChordLength)
    } else {
        ParametricCubic::interpolate(
            seq.points(),
            Parametrization::ChordLength,
            EndCondition::NotAKnot,
        )
    }
}

impl FairnessMetrics {
    /// Measure a validated point sequence.
    ///
    /// # Errors
    /// The spline constructors' errors.
    pub fn of_seq(seq: &PointSeq) -> Result<FairnessMetrics> {
        let curve = analysis_curve(seq)?;
        let closed = seq.is_closed();
        let m = curve.num_spans();
        let t = curve.knots();

        // One pass over the spans, evaluating each span's polynomial directly (no span search):
        // inflections from the curvature at the knots and at the vertex of each span's
        // quadratic `r'×r''`; extrema and max |κ| from dense samples with both one-sided limits
        // at the knots; length and energies by Gauss–Legendre quadrature.
        let gl = GaussLegendre::default();
        let mut kappa_seq = Vec::with_capacity(2 * m + 1);
        let mut dk_seq = Vec::with_capacity((SAMPLES_PER_SPAN + 1) * m);
        let mut s_knots = Vec::with_capacity(m + 1);
        let (mut max_curvature, mut length, mut strain, mut variation) = (0.0_f64, 0.0, 0.0, 0.0);
        for i in 0..m {
            let [_, a1, a2, a3] = curve.span_coeffs(i);
            let h = t[i + 1] - t[i];
            let d0 = curve.derivatives_in_span(i, t[i]);
            kappa_seq.push(signed_curvature(&d0));
            // cross(s) = 6(a2×a3) s² + 6(a1×a3) s + 2(a1×a2)
            let qa = 6.0 * a2.cross(a3);
            let qb = 6.0 * a1.cross(a3);
            if qa != 0.0 {
                let sv = -qb / (2.0 * qa);
                if sv > 0.0 && sv < h {
                    kappa_seq.push(signed_curvature(&curve.derivatives_in_span(i, t[i] + sv)));
                }
            }
            for j in 0..=SAMPLES_PER_SPAN {
                let tt = t[i] + h * j as f64 / SAMPLES_PER_SPAN as f64;
                let d = curve.derivatives_in_span(i, tt);
                max_curvature = max_curvature.max(signed_curvature(&d).abs());
                dk_seq.push(curvature_derivative(&d));
            }
            s_knots.push(length);
            let half = 0.5 * h;
            let mid = t[i] + half;
            for (x, w) in gl.nodes().iter().zip(gl.weights()) {
                let d = curve.derivatives_in_span(i, mid + half * x);
                let speed = d.d1.length_squared().sqrt();
                let k = signed_curvature(&d);
                let dk = curvature_derivative(&d);
                let ws = w * half * speed;
                length += ws;
                strain += ws * k * k;
                variation += ws * dk * dk;
            }
        }
        s_knots.push(length);
        if !closed {
            kappa_seq.push(signed_curvature(&curve.derivatives_in_span(m - 1, t[m])));
        }
        // Rounding-noise floors of κ and dκ/ds (see NOISE_FACTOR).
        let coord = crate::geom::max_abs_coordinate(seq.points());
        let h_min = t.windows(2).fold(f64::INFINITY, |a, w| a.min(w[1] - w[0]));
        let kappa_floor = NOISE_FACTOR * f64::EPSILON * coord / (h_min * h_min);
        let dk_floor = kappa_floor / h_min;
        let inflections = count_sign_changes_above(&kappa_seq, closed, kappa_floor);
        let curvature_extrema = count_sign_changes_above(&dk_seq, closed, dk_floor);

        // Vibrations: jumps of dκ/ds at the knots where r''' jumps.
        let knots: Vec<usize> = if closed {
            (0..m).collect()
        } else {
            (1..m).collect()
        };
        let jumps: Vec<f64> = knots
            .iter()
            .map(|&k| {
                let right = curve.derivatives_in_span(k, t[k]);
                let left = if k == 0 {
                    curve.derivatives_in_span(m - 1, t[m])
                } else {
                    curve.derivatives_in_span(k - 1, t[k])
                };
                curvature_derivative(&right) - curvature_derivative(&left)
            })
            .collect();
        let vibrations = count_sign_changes_above(&jumps, closed, dk_floor);
        let max_third_derivative_jump = curve
            .third_derivative_jumps()
            .iter()
            .fold(0.0_f64, |a, j| a.max(j.length()));

        let gfi = if closed {
            let kappa: Vec<f64> = (0..m)
                .map(|k| signed_curvature(&curve.derivatives_in_span(k, t[k])))
                .collect();
            lfi_from_samples(&kappa, &s_knots[..m], Some(length))
                .iter()
                .sum()
        } else {
            let (bs, _) = BSplineCurve::interpolate(seq.points(), 3, Parametrization::ChordLength)?;
            fairness_indicators(&bs).gfi
        };

        Ok(FairnessMetrics {
            points: seq.len(),
            closed,
            inflections,
            vibrations,
            curvature_extrema,
            strain_energy: strain,
            variation_energy: variation,
            max_curvature,
            gfi,
            max_third_derivative_jump,
            length,
        })
    }
}

/// Displacement between two point sets of equal length.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Displacement {
    /// Largest distance `|a_i − b_i|`.
    pub max: f64,
    /// Index of the largest distance.
    pub argmax: usize,
    /// Sum of the distances.
    pub sum: f64,
    /// Indices whose points differ, increasing.
    pub moved: Vec<usize>,
}

/// Distances between corresponding points of `a` and `b`.
///
/// # Errors
/// [`Error::LengthMismatch`] when the lengths differ.
pub fn displacement(a: &[Point], b: &[Point]) -> Result<Displacement> {
    if a.len() != b.len() {
        return Err(Error::LengthMismatch {
            what: "point sets",
            got: b.len(),
            expected: a.len(),
        });
    }
    let mut d = Displacement {
        max: 0.0,
        argmax: 0,
        sum: 0.0,
        moved: Vec::new(),
    };
    for (i, (p, q)) in a.iter().zip(b).enumerate() {
        let dist = p.distance(*q);
        d.sum += dist;
        if dist > d.max {
            d.max = dist;
            d.argmax = i;
        }
        if dist > 0.0 {
            d.moved.push(i);
        }
    }
    Ok(d)
}
