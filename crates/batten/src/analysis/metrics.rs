//! [`FairnessMetrics`]: the numbers every report carries (spec §0.3, §0.4, §4.4).

use rayon::prelude::*;
use serde::Serialize;

use super::curvature::{curvature_derivative, signed_curvature};
use super::gfi::{fairness_indicators, lfi_from_samples};
use crate::curve::Derivatives;
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

/// Spans per parallel work unit of [`FairnessMetrics::of_seq`]. Fixed, so that the sums (and
/// so the numbers) do not depend on the number of threads.
const SPANS_PER_CHUNK: usize = 4096;

/// What [`FairnessMetrics::of_seq`] gathers over a chunk of consecutive spans.
#[derive(Debug, Default)]
struct SpanSums {
    kappa: SignRuns,
    dk: SignRuns,
    max_curvature: f64,
    /// Arc length of the chunk, and at each of its spans' starts from the chunk's start.
    length: f64,
    s_knots: Vec<f64>,
    strain: f64,
    variation: f64,
}

/// A sequence of values seen in order, kept as its runs of one sign: enough to count its sign
/// changes exactly as [`count_sign_changes`] would on the values with those of magnitude at
/// most `floor` set to zero, without storing the values. A run survives the relative zero of
/// [`sgn0`] when its largest magnitude does. Sequences of consecutive pieces can be built
/// apart (in parallel) and appended in order.
#[derive(Clone, Debug, Default)]
struct SignRuns {
    /// `(sign, largest |v| of the run)`, adjacent runs of opposite sign.
    runs: Vec<(i8, f64)>,
}

impl SignRuns {
    /// Append `v`; values with `|v| ≤ floor` are zeros and skipped.
    #[inline]
    fn push(&mut self, v: f64, floor: f64) {
        let a = v.abs();
        if a <= floor {
            return;
        }
        let sign = if v > 0.0 { 1 } else { -1 };
        match self.runs.last_mut() {
            Some((s, m)) if *s == sign => *m = m.max(a),
            _ => self.runs.push((sign, a)),
        }
    }

    /// Append the runs of the values that follow.
    fn append(&mut self, later: SignRuns) {
        for (sign, a) in later.runs {
            match self.runs.last_mut() {
                Some((s, m)) if *s == sign => *m = m.max(a),
                _ => self.runs.push((sign, a)),
            }
        }
    }

    /// The sign changes (see [`count_sign_changes`]).
    fn count(&self, cyclic: bool) -> usize {
        let scale = self.runs.iter().fold(0.0_f64, |m, r| m.max(r.1));
        let mut kept = self
            .runs
            .iter()
            .filter(|r| sgn0(r.1, scale) != 0)
            .map(|r| r.0);
        let Some(first) = kept.next() else {
            return 0;
        };
        let (mut n, mut last) = (0, first);
        for s in kept {
            if s != last {
                n += 1;
                last = s;
            }
        }
        // The wrap from the last kept sign back to the first.
        if cyclic && last != first {
            n += 1;
        }
        n
    }
}

/// [`count_sign_changes`] with values of magnitude at most `floor` also counted as zero.
fn count_sign_changes_above(values: &[f64], cyclic: bool, floor: f64) -> usize {
    let mut runs = SignRuns::default();
    for &v in values {
        runs.push(v, floor);
    }
    runs.count(cyclic)
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

/// Speed, κ and dκ/ds at one parameter, sharing one square root: the same operations, in
/// the same order, as [`signed_curvature`] and [`curvature_derivative`] (so the same bits),
/// for the span pass that evaluates them 25 times per span.
struct SpeedCurvature {
    speed: f64,
    kappa: f64,
    dkappa_ds: f64,
}

impl SpeedCurvature {
    #[inline]
    fn of(d: &Derivatives) -> SpeedCurvature {
        let w = d.d1.length_squared();
        let speed = w.sqrt();
        let c12 = d.d1.cross(d.d2);
        let k_t = (d.d1.cross(d.d3) * w - 3.0 * c12 * d.d1.dot(d.d2)) / (w * w * speed);
        SpeedCurvature {
            speed,
            kappa: c12 / (w * speed),
            dkappa_ds: k_t / speed,
        }
    }
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
    /// The measurement runs on the points divided by [`crate::geom::unit_scale`] (a power of
    /// two, so the division is exact) and the numbers are scaled back to data units, so that
    /// coordinates of any magnitude are measured alike: the counts do not depend on the scale,
    /// and each number scales with its power of length (an energy that does not fit in an
    /// `f64` in data units is reported as infinite or zero, not as a failure).
    ///
    /// # Errors
    /// The spline constructors' errors.
    pub fn of_seq(seq: &PointSeq) -> Result<FairnessMetrics> {
        let s = crate::geom::unit_scale(seq.points());
        if s == 1.0 {
            return Self::measure(seq);
        }
        let unit = seq.with_points(crate::geom::scale_points(seq.points(), 1.0 / s))?;
        Ok(Self::measure(&unit)?.rescaled(s))
    }

    /// The metrics of the same curve scaled by `s` (counts unchanged; each number times `s`
    /// to its power of length).
    pub fn rescaled(mut self, s: f64) -> FairnessMetrics {
        self.strain_energy *= s.powi(-1);
        self.variation_energy *= s.powi(-3);
        self.max_curvature *= s.powi(-1);
        self.gfi *= s.powi(-6);
        self.max_third_derivative_jump *= s.powi(-2);
        self.length *= s;
        self
    }

    /// [`FairnessMetrics::of_seq`] in the coordinates as given.
    fn measure(seq: &PointSeq) -> Result<FairnessMetrics> {
        let curve = analysis_curve(seq)?;
        let closed = seq.is_closed();
        let m = curve.num_spans();
        let t = curve.knots();

        // Rounding-noise floors of κ and dκ/ds (see NOISE_FACTOR).
        let coord = crate::geom::max_abs_coordinate(seq.points());
        let h_min = t.windows(2).fold(f64::INFINITY, |a, w| a.min(w[1] - w[0]));
        let kappa_floor = NOISE_FACTOR * f64::EPSILON * coord / (h_min * h_min);
        let dk_floor = kappa_floor / h_min;

        // One pass over the spans, evaluating each span's polynomial directly (no span search):
        // inflections from the curvature at the knots and at the vertex of each span's
        // quadratic `r'×r''`; extrema and max |κ| from dense samples with both one-sided limits
        // at the knots; length and energies by Gauss–Legendre quadrature. The spans are cut
        // into fixed chunks measured in parallel and joined in order, so the numbers do not
        // depend on the thread count.
        let gl = GaussLegendre::default();
        let chunks: Vec<SpanSums> = (0..m.div_ceil(SPANS_PER_CHUNK))
            .into_par_iter()
            .map(|c| {
                let spans = c * SPANS_PER_CHUNK..((c + 1) * SPANS_PER_CHUNK).min(m);
                let mut r = SpanSums {
                    s_knots: Vec::with_capacity(spans.len()),
                    ..SpanSums::default()
                };
                for i in spans {
                    let [_, a1, a2, a3] = curve.span_coeffs(i);
                    let h = t[i + 1] - t[i];
                    let d0 = curve.derivatives_in_span(i, t[i]);
                    r.kappa.push(signed_curvature(&d0), kappa_floor);
                    // cross(s) = 6(a2×a3) s² + 6(a1×a3) s + 2(a1×a2)
                    let qa = 6.0 * a2.cross(a3);
                    let qb = 6.0 * a1.cross(a3);
                    if qa != 0.0 {
                        let sv = -qb / (2.0 * qa);
                        if sv > 0.0 && sv < h {
                            let d = curve.derivatives_in_span(i, t[i] + sv);
                            r.kappa.push(signed_curvature(&d), kappa_floor);
                        }
                    }
                    for j in 0..=SAMPLES_PER_SPAN {
                        let tt = t[i] + h * j as f64 / SAMPLES_PER_SPAN as f64;
                        let c = SpeedCurvature::of(&curve.derivatives_in_span(i, tt));
                        r.max_curvature = r.max_curvature.max(c.kappa.abs());
                        r.dk.push(c.dkappa_ds, dk_floor);
                    }
                    r.s_knots.push(r.length);
                    let half = 0.5 * h;
                    let mid = t[i] + half;
                    for (x, w) in gl.nodes().iter().zip(gl.weights()) {
                        let c = SpeedCurvature::of(&curve.derivatives_in_span(i, mid + half * x));
                        let (k, dk) = (c.kappa, c.dkappa_ds);
                        let ws = w * half * c.speed;
                        r.length += ws;
                        r.strain += ws * k * k;
                        r.variation += ws * dk * dk;
                    }
                }
                r
            })
            .collect();
        let mut kappa_runs = SignRuns::default();
        let mut dk_runs = SignRuns::default();
        let mut s_knots = Vec::with_capacity(m + 1);
        let (mut max_curvature, mut length, mut strain, mut variation) = (0.0_f64, 0.0, 0.0, 0.0);
        for r in chunks {
            kappa_runs.append(r.kappa);
            dk_runs.append(r.dk);
            max_curvature = max_curvature.max(r.max_curvature);
            s_knots.extend(r.s_knots.iter().map(|s| length + s));
            length += r.length;
            strain += r.strain;
            variation += r.variation;
        }
        s_knots.push(length);
        if !closed {
            let d = curve.derivatives_in_span(m - 1, t[m]);
            kappa_runs.push(signed_curvature(&d), kappa_floor);
        }
        let inflections = kappa_runs.count(closed);
        let curvature_extrema = dk_runs.count(closed);

        // Vibrations: jumps of dκ/ds at the knots where r''' jumps.
        let knots: Vec<usize> = if closed {
            (0..m).collect()
        } else {
            (1..m).collect()
        };
        let jumps: Vec<f64> = knots
            .par_iter()
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
                .into_par_iter()
                .map(|k| signed_curvature(&curve.derivatives_in_span(k, t[k])))
                .collect();
            lfi_from_samples(&kappa, &s_knots[..m], Some(length))
                .iter()
                .sum()
        } else {
            // The open GFI is measured on another spline: free this one first (72 bytes a
            // point), so that the two are never held at once.
            drop(curve);
            drop(s_knots);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference: zero the values at or below the floor, then count.
    fn reference(values: &[f64], cyclic: bool, floor: f64) -> usize {
        let filtered: Vec<f64> = values
            .iter()
            .map(|&v| if v.abs() <= floor { 0.0 } else { v })
            .collect();
        count_sign_changes(&filtered, cyclic)
    }

    #[test]
    fn sign_runs_count_as_the_values_do() {
        let mut state = 99_u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for case in 0..2000 {
            let n = (next() * 40.0) as usize;
            // Magnitudes over many decades, so that both the floor and the relative zero bite.
            let values: Vec<f64> = (0..n)
                .map(|_| {
                    let mag = 10f64.powf(-16.0 * next());
                    let v = if next() < 0.5 { -mag } else { mag };
                    if next() < 0.1 { 0.0 } else { v }
                })
                .collect();
            let floor = if case % 3 == 0 {
                0.0
            } else {
                10f64.powf(-14.0 * next())
            };
            let cut = (next() * (n as f64 + 1.0)) as usize;
            for cyclic in [false, true] {
                let expected = reference(&values, cyclic, floor);
                assert_eq!(count_sign_changes_above(&values, cyclic, floor), expected);
                // Built in two pieces and appended.
                let (mut a, mut b) = (SignRuns::default(), SignRuns::default());
                values[..cut].iter().for_each(|&v| a.push(v, floor));
                values[cut..].iter().for_each(|&v| b.push(v, floor));
                a.append(b);
                assert_eq!(a.count(cyclic), expected, "case {case}, cut {cut}");
            }
        }
    }

    #[test]
    fn metrics_do_not_depend_on_the_thread_count() {
        // More spans than one chunk, so that the chunks are joined.
        let n = 3 * SPANS_PER_CHUNK + 17;
        let pts: Vec<Point> = (0..n)
            .map(|i| {
                let a = i as f64 * 0.01;
                Point::new(
                    a.cos() * (1.0 + 0.3 * a),
                    a.sin() * (1.0 + 0.3 * a) + 1e-4 * (i % 7) as f64,
                )
            })
            .collect();
        for closed in [false, true] {
            let seq = PointSeq::new(pts.clone(), closed).unwrap();
            let one = rayon::ThreadPoolBuilder::new()
                .num_threads(1)
                .build()
                .unwrap()
                .install(|| FairnessMetrics::of_seq(&seq).unwrap());
            let three = rayon::ThreadPoolBuilder::new()
                .num_threads(3)
                .build()
                .unwrap()
                .install(|| FairnessMetrics::of_seq(&seq).unwrap());
            assert_eq!(one, three);
            assert!(one.inflections > 0 && one.vibrations > 0);
        }
    }
}
