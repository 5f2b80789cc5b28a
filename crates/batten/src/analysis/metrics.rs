//! [`FairnessMetrics`]: the numbers every report carries (docs/algorithms/README.md §0.3, §0.4,
//! docs/algorithms/cali.md §4.4).

use std::sync::OnceLock;

use rayon::prelude::*;
use serde::Serialize;

use super::curvature::{curvature_derivative, signed_curvature};
use super::gfi::lfi;
use crate::error::{Error, Result};
use crate::geom::{Point, PointSeq, Vec2};
use crate::numeric::GaussLegendre;
use crate::spline::{
    EndCondition, ParametricCubic, Parametrization, c2_closed_tangents, c2_tangents,
    hermite_coeffs, parameters, span_derivatives,
};

/// Relative zero for sign tests (docs/algorithms/han.md §1.7.0): `sgn0(v) = 0` when `|v| ≤
/// ZERO_REL·max|v_k|`.
pub const ZERO_REL: f64 = 1e-12;

/// Rounding-noise factor of the sign tests in [`FairnessMetrics::of_seq`]. The curvature of
/// the spline through collinear points is pure rounding noise, of size up to about
/// `ε·R/h_min²` (R the largest coordinate magnitude, h_min the shortest chord; measured on
/// collinear data with 10–1000 points and offsets up to 1000× the spacing). A value relative to
/// the largest one (as in [`count_sign_changes`]) does not filter it out, since then every value
/// is noise: curvatures below `NOISE_FACTOR·ε·R/h_min²`, and derivatives of curvature below
/// that over `h_min`, count as zero.
const NOISE_FACTOR: f64 = 64.0;

/// The relative margin within which a knot's squared r''' jump has its `hypot` measured
/// against the largest so far.
const JUMP_SHORTLIST_MARGIN: f64 = 1e-9;

/// Below this largest squared r''' jump every jump is measured (squares of subnormal size lose
/// their relative precision).
const JUMP_SHORTLIST_MIN: f64 = f64::MIN_POSITIVE / f64::EPSILON;

/// Spans per parallel work unit of [`FairnessMetrics::of_seq`]. Fixed, so that the sums (and
/// so the numbers) do not depend on the number of threads.
const SPANS_PER_CHUNK: usize = 4096;

/// What [`FairnessMetrics::of_seq`] gathers over a chunk of consecutive spans.
#[derive(Debug, Default)]
struct SpanSums {
    /// Whether every span's coefficients are finite.
    finite: bool,
    kappa: SignRuns,
    dk: SignRuns,
    /// The jumps of dκ/ds at the knots inside the chunk.
    jumps: SignRuns,
    /// dκ/ds and r'''/6 at the chunk's first knot from the right, and at its last from the
    /// left, for the jumps at the knots between chunks.
    first_right_dk: f64,
    last_left_dk: f64,
    first_a3: Vec2,
    last_a3: Vec2,
    /// Largest |r''' jump| at the knots inside the chunk.
    max_third_jump: f64,
    max_curvature: f64,
    /// Arc length of the chunk.
    length: f64,
    /// The sum of Calì's LFI at the chunk's knots.
    gfi: f64,
    strain: f64,
    variation: f64,
}

/// A sequence of values seen in order, kept as its runs of one sign: enough to count its sign
/// changes exactly as [`count_sign_changes`] would on the values with those of magnitude at
/// most `floor` set to zero, without storing the values. A run survives the relative zero of
/// [`sgn0`] when its largest magnitude does. Sequences of consecutive pieces can be built
/// apart (in parallel) and counted together in order ([`count_runs`]).
#[derive(Clone, Debug, Default)]
struct SignRuns {
    /// The largest |v| of each run, with the run's sign; adjacent runs of opposite sign.
    /// (One `f64` a run, not a sign and a magnitude: at 10⁶ points a noisy curve has about
    /// 2·10⁶ runs in all.)
    runs: Vec<f64>,
}

impl SignRuns {
    /// Append `v`; values with `|v| ≤ floor` are zeros and skipped.
    #[inline]
    fn push(&mut self, v: f64, floor: f64) {
        let a = v.abs();
        if a <= floor {
            return;
        }
        let positive = v > 0.0;
        match self.runs.last_mut() {
            Some(m) if (*m > 0.0) == positive => {
                *m = if positive { m.max(a) } else { -(-*m).max(a) };
            }
            _ => self.runs.push(if positive { a } else { -a }),
        }
    }

    /// [`SignRuns::push`] of each of `values` in order, with one test (no branch per value)
    /// when all of them lie beyond the floor with one sign, as most of a span's samples do.
    #[inline]
    fn push_all<const N: usize>(&mut self, values: &[f64; N], floor: f64) {
        // Plain comparisons (a NaN leaves `lo` and `hi` as they were, and takes the slow
        // path below), not `f64::min`/`max`, whose NaN rules cost several instructions each.
        let (mut lo, mut hi, mut nan) = (f64::INFINITY, f64::NEG_INFINITY, false);
        for &v in values {
            lo = if v < lo { v } else { lo };
            hi = if v > hi { v } else { hi };
            nan |= v.is_nan();
        }
        let last = self.runs.last_mut();
        if !nan && lo > floor {
            match last {
                Some(m) if *m > 0.0 => *m = m.max(hi),
                _ => self.runs.push(hi),
            }
        } else if !nan && hi < -floor {
            match last {
                // A NaN run is continued as `push` continues it (as negative).
                Some(m) if *m < 0.0 || m.is_nan() => *m = m.min(lo),
                _ => self.runs.push(lo),
            }
        } else {
            for &v in values {
                self.push(v, floor);
            }
        }
    }

    /// The sign changes (see [`count_sign_changes`]).
    #[cfg(test)]
    fn count(&self, cyclic: bool) -> usize {
        count_runs(std::slice::from_ref(self), cyclic)
    }
}

/// The sign changes (see [`count_sign_changes`]) of the values whose runs are `parts`, one
/// after the other. Adjacent runs of one sign across parts count as one run would: the count
/// only sees the sequence of the signs of the runs that survive the relative zero, and a
/// survivor's sign repeated does not change it.
fn count_runs(parts: &[SignRuns], cyclic: bool) -> usize {
    let values = || parts.iter().flat_map(|p| p.runs.iter().copied());
    let scale = values().fold(0.0_f64, |m, r| m.max(r.abs()));
    let mut kept = values()
        .filter(|r| sgn0(r.abs(), scale) != 0)
        .map(|r| r > 0.0);
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

/// [`count_sign_changes`] with values of magnitude at most `floor` also counted as zero.
#[cfg(test)]
fn count_sign_changes_above(values: &[f64], cyclic: bool, floor: f64) -> usize {
    let mut runs = SignRuns::default();
    for &v in values {
        runs.push(v, floor);
    }
    runs.count(cyclic)
}

/// The sign of `v` with values within `ZERO_REL · scale` of zero counted as 0
/// (docs/algorithms/han.md §1.7.0).
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
#[non_exhaustive]
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
    /// has the sign of HAN's `e_i` (docs/algorithms/han.md §1.4).
    pub vibrations: usize,
    /// Local extrema of κ(s): the number of monotone pieces of the curvature plot minus one,
    /// from the sign of dκ/ds sampled at each span's quadrature nodes and both one-sided
    /// limits at its knots (docs/algorithms/README.md §0.4).
    pub curvature_extrema: usize,
    /// `∫ κ² ds`.
    pub strain_energy: f64,
    /// `∫ (dκ/ds)² ds`.
    pub variation_energy: f64,
    /// Largest |κ|, over the same samples as `curvature_extrema` (the knots and each span's
    /// quadrature nodes).
    pub max_curvature: f64,
    /// Calì's global fairness indicator (docs/algorithms/cali.md §4.4) on the analysis curve at
    /// its knots, the data points: the sum over the knots of the squared second divided
    /// difference of κ in arc length (cyclic when closed; none at an open curve's two ends).
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
        let unit = seq.scaled_to_unit(1.0 / s);
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
        let closed = seq.is_closed();
        let spans = AnalysisSpans::of(seq)?;
        let m = spans.len();
        let t = &spans.t;

        // Rounding-noise floors of κ and dκ/ds (see NOISE_FACTOR).
        let coord = crate::geom::max_abs_coordinate(seq.points());
        let h_min = t.windows(2).fold(f64::INFINITY, |a, w| a.min(w[1] - w[0]));
        let kappa_floor = NOISE_FACTOR * f64::EPSILON * coord / (h_min * h_min);
        let dk_floor = kappa_floor / h_min;

        // One pass over the spans, each span's polynomial formed from the Hermite data and
        // evaluated directly (no span search, no stored coefficients): inflections from the
        // curvature at the knots and at the vertex of each span's quadratic `r'×r''`; length and
        // energies by Gauss–Legendre quadrature; extrema and max |κ| from the quadrature nodes'
        // samples between both one-sided limits at the knots; the jumps of dκ/ds and r''' at
        // the knots. The spans are cut into fixed chunks measured in parallel and joined in
        // order, so the numbers do not depend on the thread count.
        static RULE: OnceLock<GaussLegendre> = OnceLock::new();
        // Computed once per process (Newton on the Legendre polynomial: 4 % of a 200-point
        // measurement when it was computed every time).
        let gl = RULE.get_or_init(|| GaussLegendre::new(QUADRATURE_NODES));
        let chunk = |c: usize| {
            spans.measure_chunk(
                c * SPANS_PER_CHUNK..((c + 1) * SPANS_PER_CHUNK).min(m),
                gl,
                kappa_floor,
                dk_floor,
            )
        };
        let n_chunks = m.div_ceil(SPANS_PER_CHUNK);
        let chunks: Vec<SpanSums> = if n_chunks > 1 {
            (0..n_chunks).into_par_iter().map(chunk).collect()
        } else {
            (0..n_chunks).map(chunk).collect()
        };
        if chunks.iter().any(|r| !r.finite) {
            return Err(Error::Singular("spline coefficients are not finite".into()));
        }
        let Joined {
            mut kappa_runs,
            dk_runs,
            jump_runs,
            gfi,
            max_curvature,
            length,
            strain,
            variation,
            max_third_derivative_jump,
        } = Joined::of(chunks, closed, dk_floor);
        if !closed {
            let c = spans.coeffs(m - 1);
            let d = span_derivatives(&c, t[m] - t[m - 1]);
            let mut end = SignRuns::default();
            end.push(signed_curvature(&d), kappa_floor);
            kappa_runs.push(end);
        }
        let inflections = count_runs(&kappa_runs, closed);
        let curvature_extrema = count_runs(&dk_runs, closed);
        let vibrations = count_runs(&jump_runs, closed);
        drop((kappa_runs, dk_runs, jump_runs));

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

/// The chunks' measurements joined in order: the runs of each quantity, part by part (with
/// the knots between chunks, and P_0 of a closed curve), the knots' arc lengths and
/// curvatures (closed curves), and the sums and maxima.
struct Joined {
    kappa_runs: Vec<SignRuns>,
    dk_runs: Vec<SignRuns>,
    jump_runs: Vec<SignRuns>,
    gfi: f64,
    max_curvature: f64,
    length: f64,
    strain: f64,
    variation: f64,
    max_third_derivative_jump: f64,
}

impl Joined {
    /// Join `chunks` (in order).
    fn of(chunks: Vec<SpanSums>, closed: bool, dk_floor: f64) -> Joined {
        // The runs of each quantity, part by part in order.
        let mut kappa_runs = Vec::with_capacity(chunks.len() + 1);
        let mut dk_runs = Vec::with_capacity(chunks.len());
        let mut jump_runs = Vec::with_capacity(2 * chunks.len());
        let (mut max_curvature, mut length, mut strain, mut variation) = (0.0_f64, 0.0, 0.0, 0.0);
        let mut gfi = 0.0;
        let mut max_third_derivative_jump = 0.0_f64;
        let knot = |v: f64| {
            let mut r = SignRuns::default();
            r.push(v, dk_floor);
            r
        };
        if let (true, Some(first), Some(last)) = (closed, chunks.first(), chunks.last()) {
            // The knot P_0 of a closed curve: the last span meets the first.
            jump_runs.push(knot(first.first_right_dk - last.last_left_dk));
            let j = (first.first_a3 - last.last_a3) * 6.0;
            max_third_derivative_jump = max_third_derivative_jump.max(j.length());
        }
        let mut prev: Option<(f64, Vec2)> = None;
        for r in chunks {
            if let Some((left_dk, a3)) = prev {
                // The knot between this chunk and the one before.
                jump_runs.push(knot(r.first_right_dk - left_dk));
                let j = (r.first_a3 - a3) * 6.0;
                max_third_derivative_jump = max_third_derivative_jump.max(j.length());
            }
            prev = Some((r.last_left_dk, r.last_a3));
            kappa_runs.push(r.kappa);
            dk_runs.push(r.dk);
            jump_runs.push(r.jumps);
            max_curvature = max_curvature.max(r.max_curvature);
            max_third_derivative_jump = max_third_derivative_jump.max(r.max_third_jump);
            gfi += r.gfi;
            length += r.length;
            strain += r.strain;
            variation += r.variation;
        }
        Joined {
            kappa_runs,
            dk_runs,
            jump_runs,
            gfi,
            max_curvature,
            length,
            strain,
            variation,
            max_third_derivative_jump,
        }
    }
}

/// Gauss–Legendre nodes per span for the length and the energies of
/// [`FairnessMetrics::of_seq`].
const QUADRATURE_NODES: usize = 16;

/// The analysis curve ([`analysis_curve`]) as its knots, points and tangents only: each span's
/// power-basis coefficients are formed when the span pass reaches it, by the same function
/// and so with the same bits as [`ParametricCubic`] stores them (64 bytes a point never held).
struct AnalysisSpans<'a> {
    /// The knots, `t_0..t_m`.
    t: Vec<f64>,
    /// The points (a closed curve's last span ends at `points[0]`).
    points: &'a [Point],
    /// The tangents at the knots (a closed curve repeats the first at the end).
    tangents: Vec<Vec2>,
}

impl<'a> AnalysisSpans<'a> {
    /// The spans of [`analysis_curve`] of `seq`.
    fn of(seq: &'a PointSeq) -> Result<AnalysisSpans<'a>> {
        let points = seq.points();
        let (t, tangents) = if seq.is_closed() {
            c2_closed_tangents(points, Parametrization::ChordLength)?
        } else {
            let t = parameters(points, Parametrization::ChordLength, false)?;
            let tangents = c2_tangents(&t, points, EndCondition::NotAKnot)?;
            (t, tangents)
        };
        Ok(AnalysisSpans {
            t,
            points,
            tangents,
        })
    }

    /// Number of spans.
    fn len(&self) -> usize {
        self.t.len() - 1
    }

    /// Whether the curve is closed (its last span ends at the first point).
    fn is_closed(&self) -> bool {
        self.points.len() == self.len()
    }

    /// Span `i`'s coefficients `[a0, a1, a2, a3]` in `s = t − t_i`.
    #[inline]
    fn coeffs(&self, i: usize) -> [Vec2; 4] {
        let n = self.points.len();
        hermite_coeffs(
            self.points[i].to_vec2(),
            self.points[crate::geom::next_index(i, n)].to_vec2(),
            self.tangents[i],
            self.tangents[i + 1],
            self.t[i + 1] - self.t[i],
        )
    }

    /// The span pass of [`FairnessMetrics::of_seq`] over `spans`.
    fn measure_chunk(
        &self,
        spans: std::ops::Range<usize>,
        gl: &GaussLegendre,
        kappa_floor: f64,
        dk_floor: f64,
    ) -> SpanSums {
        let t = &self.t;
        let mut r = SpanSums {
            finite: true,
            ..SpanSums::default()
        };
        // The rule as fixed-size arrays, so that the node loop is unrolled and vectorised.
        let mut nodes = [0.0; QUADRATURE_NODES];
        let mut weights = [0.0; QUADRATURE_NODES];
        nodes.copy_from_slice(gl.nodes());
        weights.copy_from_slice(gl.weights());
        let first = spans.start;
        let m = self.len();
        // Calì's LFI at each knot of the chunk (docs/algorithms/cali.md §4.4), from the
        // curvatures at the knots and the spans' lengths: (κ, length) of the knot and span
        // two before the current one and of those just before it. The chunk's first knot
        // needs the span before the chunk (a closed curve's last span before its first).
        // The samples at the quadrature nodes of the span at hand.
        let mut samples = SampleTerms::new();
        let mut back: Option<(f64, f64)> = None;
        let mut prev: Option<(f64, f64)> = (first > 0 || self.is_closed()).then(|| {
            let j = (first + m - 1) % m;
            let c = self.coeffs(j);
            let kappa = signed_curvature(&span_derivatives(&c, 0.0));
            (
                kappa,
                span_terms(&c, t[j + 1] - t[j], (&nodes, &weights), &mut samples).length,
            )
        });
        let mut d_end = None;
        // The largest squared r''' jump so far (see the jumps below).
        let mut jump_sq = 0.0_f64;
        let mut last_left_dk = 0.0;
        let mut last_a3 = Vec2::ZERO;
        for i in spans {
            let c = self.coeffs(i);
            r.finite &= c.iter().all(|v| v.is_finite());
            let [_, a1, a2, a3] = c;
            let h = t[i + 1] - t[i];
            // At the knot: s = t_i − t_i = 0 (the knots are finite).
            let d0 = span_derivatives(&c, 0.0);
            let kappa0 = signed_curvature(&d0);
            r.kappa.push(kappa0, kappa_floor);
            if let (Some((kb, lb)), Some((kp, lp))) = (back, prev) {
                r.gfi += lfi(kb, kp, kappa0, [lb, lp, lb + lp]);
            }
            // cross(s) = 6(a2×a3) s² + 6(a1×a3) s + 2(a1×a2)
            let qa = 6.0 * a2.cross(a3);
            let qb = 6.0 * a1.cross(a3);
            if qa != 0.0 {
                let sv = -qb / (2.0 * qa);
                if sv > 0.0 && sv < h {
                    let d = span_derivatives(&c, (t[i] + sv) - t[i]);
                    r.kappa.push(signed_curvature(&d), kappa_floor);
                }
            }
            // The one-sided dκ/ds and r''' at the knots, for their jumps.
            let right_dk = curvature_derivative(&d0);
            if i == first {
                r.first_right_dk = right_dk;
                r.first_a3 = a3;
            } else {
                r.jumps.push(right_dk - last_left_dk, dk_floor);
                let j = (a3 - last_a3) * 6.0;
                // hypot only for a jump whose squared length may hold the chunk's largest:
                // the sum of squares is within a few ulps of the exact value, far inside the
                // margin (the same maximum, bit for bit; tiny values measure every jump).
                let sq = j.length_squared();
                let floor = jump_sq * (1.0 - JUMP_SHORTLIST_MARGIN);
                if jump_sq < JUMP_SHORTLIST_MIN || sq.is_nan() || sq >= floor {
                    r.max_third_jump = r.max_third_jump.max(j.length());
                    jump_sq = jump_sq.max(sq);
                }
            }
            let d = span_derivatives(&c, t[i + 1] - t[i]);
            last_left_dk = curvature_derivative(&d);
            d_end = Some(d);
            last_a3 = a3;

            // The samples of dκ/ds and κ: the quadrature nodes, between both one-sided
            // limits at the knots.
            let q = span_terms(&c, h, (&nodes, &weights), &mut samples);
            r.dk.push(right_dk, dk_floor);
            r.dk.push_all(&samples.dkappa_ds, dk_floor);
            // The nodes' largest κ² by comparisons from 0 (a NaN is skipped, as `f64::max`
            // skips it), then joined with the knot's.
            let mut nodes_kappa2 = 0.0_f64;
            for k2 in samples.kappa2 {
                nodes_kappa2 = if k2 > nodes_kappa2 { k2 } else { nodes_kappa2 };
            }
            let mut kappa2 = (kappa0 * kappa0).max(nodes_kappa2);
            r.dk.push(last_left_dk, dk_floor);
            if i + 1 == m {
                let k = signed_curvature(&d);
                kappa2 = kappa2.max(k * k);
            }
            r.max_curvature = r.max_curvature.max(kappa2.sqrt());
            r.length += q.length;
            r.strain += q.strain;
            r.variation += q.variation;

            (back, prev) = (prev, Some((kappa0, q.length)));
        }
        // The chunk's last knot, with the knot at the end of its last span.
        if let (Some((kb, lb)), Some((kp, lp)), Some(d)) = (back, prev, d_end) {
            r.gfi += lfi(kb, kp, signed_curvature(&d), [lb, lp, lb + lp]);
        }
        r.last_left_dk = last_left_dk;
        r.last_a3 = last_a3;
        for runs in [&mut r.kappa, &mut r.dk, &mut r.jumps] {
            runs.runs.shrink_to_fit();
        }
        r
    }
}

/// A span's length and energies by the quadrature rule of [`FairnessMetrics::of_seq`].
struct SpanIntegrals {
    length: f64,
    strain: f64,
    variation: f64,
}

/// [`SpanIntegrals`] of the span with coefficients `c` over `[0, h]` (the rule's nodes and
/// weights on `[−1, 1]`), with the samples at the nodes left in `q` (they also give the
/// extrema and the largest |κ|).
#[inline]
fn span_terms(
    c: &[Vec2; 4],
    h: f64,
    (nodes, weights): (&[f64; QUADRATURE_NODES], &[f64; QUADRATURE_NODES]),
    q: &mut SampleTerms<QUADRATURE_NODES>,
) -> SpanIntegrals {
    let half = 0.5 * h;
    let mut at = [0.0; QUADRATURE_NODES];
    for (s, x) in at.iter_mut().zip(nodes) {
        // The node's offset from the span's start.
        *s = half + half * x;
    }
    q.fill(c, &at);
    let mut r = SpanIntegrals {
        length: 0.0,
        strain: 0.0,
        variation: 0.0,
    };
    for j in 0..QUADRATURE_NODES {
        let ws = weights[j] * half * q.w[j].sqrt();
        r.length += ws;
        r.strain += ws * q.kappa2[j];
        r.variation += ws * q.dkappa_ds[j] * q.dkappa_ds[j];
    }
    r
}

/// κ² and dκ/ds of a span at `N` parameters, without square roots: with `w = |r'|²`,
/// `κ = (r'×r'')/w^{3/2}`, so `κ² = (r'×r'')²/w³`, and `dκ/ds = [(r'×r''')·w −
/// 3(r'×r'')(r'·r'')]/w³` (the numerator of [`curvature_derivative`]). Computed component by
/// component over fixed arrays, so that the loops vectorise.
struct SampleTerms<const N: usize> {
    w: [f64; N],
    kappa2: [f64; N],
    dkappa_ds: [f64; N],
}

/// The squared speed and the products d1×d2, d1×d3, d1·d2 of the derivatives of span
/// coefficients `c` at `s`: the operations of `span_derivatives`, per component (so the
/// sample loops vectorise).
#[inline(always)]
fn products(c: &[Vec2; 4], s: f64) -> [f64; 4] {
    let [_, a1, a2, a3] = *c;
    let d1x = a1.x + (a2.x * 2.0 + a3.x * (3.0 * s)) * s;
    let d1y = a1.y + (a2.y * 2.0 + a3.y * (3.0 * s)) * s;
    let d2x = a2.x * 2.0 + a3.x * (6.0 * s);
    let d2y = a2.y * 2.0 + a3.y * (6.0 * s);
    let (d3x, d3y) = (a3.x * 6.0, a3.y * 6.0);
    [
        d1x * d1x + d1y * d1y,
        d1x * d2y - d1y * d2x,
        d1x * d3y - d1y * d3x,
        d1x * d2x + d1y * d2y,
    ]
}

impl<const N: usize> SampleTerms<N> {
    /// Zeros, to be filled by [`SampleTerms::fill`] (one buffer for every span of a chunk, not
    /// a new one a span, which cost a fill with zeros and a copy each).
    fn new() -> SampleTerms<N> {
        SampleTerms {
            w: [0.0; N],
            kappa2: [0.0; N],
            dkappa_ds: [0.0; N],
        }
    }

    /// The terms of span coefficients `c` at the parameters `at`.
    #[inline]
    fn fill(&mut self, c: &[Vec2; 4], at: &[f64; N]) {
        for j in 0..N {
            let [w, c12, c13, dot] = products(c, at[j]);
            let inv = 1.0 / (w * w * w);
            self.w[j] = w;
            self.kappa2[j] = c12 * c12 * inv;
            self.dkappa_ds[j] = (c13 * w - 3.0 * c12 * dot) * inv;
        }
    }
}

/// Displacement between two point sets of equal length.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
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
    // The distances (a `hypot` each) in parallel on long sequences; the sum in order, so
    // the same bits on any number of threads.
    let distances = crate::numeric::map_indices(a.len(), |i| a[i].distance(b[i]));
    let mut d = Displacement {
        max: 0.0,
        argmax: 0,
        sum: 0.0,
        moved: Vec::with_capacity(distances.iter().filter(|&&v| v > 0.0).count()),
    };
    for (i, &dist) in distances.iter().enumerate() {
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
    fn push_all_keeps_the_runs_of_push() {
        let mut rng = crate::test_rng::Rng::new(7);
        let mut next = move || rng.uniform();
        for case in 0..3000 {
            let floor = if case % 4 == 0 { 0.0 } else { 1e-3 };
            let (mut one, mut all) = (SignRuns::default(), SignRuns::default());
            for _ in 0..6 {
                // Blocks mostly of one sign, some crossing zero or the floor, a few NaN.
                let sign = if next() < 0.5 { -1.0 } else { 1.0 };
                let block: [f64; 4] = std::array::from_fn(|_| match next() {
                    x if x < 0.02 => f64::NAN,
                    x if x < 0.1 => 0.0,
                    x if x < 0.2 => -sign * next(),
                    x if x < 0.3 => sign * 1e-4,
                    _ => sign * (0.01 + next()),
                });
                block.iter().for_each(|&v| one.push(v, floor));
                all.push_all(&block, floor);
            }
            let bits = |r: &SignRuns| r.runs.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&one), bits(&all), "case {case}");
        }
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
                assert_eq!(
                    count_runs(&[a, b], cyclic),
                    expected,
                    "case {case}, cut {cut}"
                );
            }
        }
    }

    /// The span pass against a plain evaluation of [`analysis_curve`] (the way the metrics
    /// were measured before the pass kept no coefficients): the counts and the jumps exactly,
    /// across chunk boundaries, open and closed; the energies to rounding.
    #[test]
    fn span_pass_matches_the_analysis_curve() {
        use crate::analysis::curvature::{curvature_derivative, signed_curvature};
        let n = 2 * SPANS_PER_CHUNK + 300;
        let pts: Vec<Point> = (0..n)
            .map(|i| {
                let a = i as f64 * 0.003;
                let wobble = 2e-3 * ((i * 7919 % 13) as f64 - 6.0);
                Point::new(a + 0.5 * wobble, a.sin() + wobble)
            })
            .collect();
        for closed in [false, true] {
            let pts = if closed {
                // A closed loop with the same kind of noise.
                pts.iter()
                    .enumerate()
                    .map(|(i, p)| {
                        let a = std::f64::consts::TAU * i as f64 / n as f64;
                        Point::new(a.cos() + 0.01 * p.y, a.sin() + 0.01 * p.x.sin())
                    })
                    .collect()
            } else {
                pts.clone()
            };
            let seq = PointSeq::new(pts, closed).unwrap();
            let got = FairnessMetrics::of_seq(&seq).unwrap();
            let curve = analysis_curve(&seq).unwrap();
            let m = curve.num_spans();
            let t = curve.knots();
            // Inflections: κ at the knots and at the vertices of r'×r''.
            let mut kappa = Vec::new();
            for i in 0..m {
                let [_, a1, a2, a3] = curve.span_coeffs(i);
                kappa.push(signed_curvature(&curve.derivatives_in_span(i, t[i])));
                let (qa, qb) = (6.0 * a2.cross(a3), 6.0 * a1.cross(a3));
                if qa != 0.0 {
                    let sv = -qb / (2.0 * qa);
                    if sv > 0.0 && sv < t[i + 1] - t[i] {
                        kappa.push(signed_curvature(&curve.derivatives_in_span(i, t[i] + sv)));
                    }
                }
            }
            if !closed {
                kappa.push(signed_curvature(&curve.derivatives_in_span(m - 1, t[m])));
            }
            let coord = crate::geom::max_abs_coordinate(seq.points());
            let h_min = t.windows(2).fold(f64::INFINITY, |a, w| a.min(w[1] - w[0]));
            let kappa_floor = NOISE_FACTOR * f64::EPSILON * coord / (h_min * h_min);
            let dk_floor = kappa_floor / h_min;
            assert_eq!(
                got.inflections,
                count_sign_changes_above(&kappa, closed, kappa_floor)
            );
            // Vibrations: the jumps of dκ/ds at the knots.
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
            assert_eq!(
                got.vibrations,
                count_sign_changes_above(&jumps, closed, dk_floor)
            );
            assert!(got.vibrations > 0 && got.inflections > 0);
            let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
            // Extrema and max |κ|: dκ/ds and κ at each span's quadrature nodes, between the
            // one-sided limits at its knots.
            let gl = GaussLegendre::new(QUADRATURE_NODES);
            let (mut dk, mut max_kappa) = (Vec::new(), 0.0_f64);
            for i in 0..m {
                let h = t[i + 1] - t[i];
                let mut at = vec![t[i]];
                at.extend(gl.nodes().iter().map(|x| t[i] + 0.5 * h * (1.0 + x)));
                at.push(t[i + 1]);
                for &x in &at {
                    let d = curve.derivatives_in_span(i, x);
                    dk.push(curvature_derivative(&d));
                    max_kappa = max_kappa.max(signed_curvature(&d).abs());
                }
            }
            assert_eq!(
                got.curvature_extrema,
                count_sign_changes_above(&dk, closed, dk_floor)
            );
            assert!(got.curvature_extrema > 0);
            assert!(
                rel(got.max_curvature, max_kappa) < 1e-9,
                "{} {max_kappa}",
                got.max_curvature
            );
            let third = curve
                .third_derivative_jumps()
                .iter()
                .fold(0.0_f64, |a, j| a.max(j.length()));
            assert_eq!(got.max_third_derivative_jump, third);
            // Energies and length by the general quadrature on the curve.
            // The GFI: Calì's divided differences of κ at the knots over the arc lengths
            // there, cyclic when closed, summed (as `fairness_indicators` sums them).
            let mut s = vec![0.0];
            for i in 0..m {
                let gl = GaussLegendre::new(QUADRATURE_NODES);
                let len = gl.integrate(t[i], t[i + 1], |x| {
                    curve.derivatives_in_span(i, x).d1.length()
                });
                s.push(s[i] + len);
            }
            let mut kappa_knots: Vec<f64> = (0..m)
                .map(|i| signed_curvature(&curve.derivatives_in_span(i, t[i])))
                .collect();
            if closed {
                s.pop();
            } else {
                kappa_knots.push(signed_curvature(&curve.derivatives_in_span(m - 1, t[m])));
            }
            let period = closed.then_some(got.length);
            let gfi: f64 = super::super::gfi::lfi_from_samples(&kappa_knots, &s, period)
                .iter()
                .sum();
            assert!(rel(got.gfi, gfi) < 1e-9, "{} {gfi}", got.gfi);
            assert!(got.gfi > 0.0);
            assert!(rel(got.length, crate::analysis::arc_length(&curve)) < 1e-13);
            assert!(rel(got.strain_energy, crate::analysis::strain_energy(&curve)) < 1e-12);
            assert!(
                rel(
                    got.variation_energy,
                    crate::analysis::variation_energy(&curve)
                ) < 1e-12
            );
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
