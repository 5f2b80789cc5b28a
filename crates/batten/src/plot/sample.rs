//! What is drawn of a point sequence: samples of its analysis curve (points, normals,
//! curvature, arc length), its inflections, and the selections that keep large inputs light.
//!
//! The data are never thinned; only what is drawn is. Samples are `per_span` evenly spaced
//! parameters in every span of the analysis curve ([`curvature_comb`]) with `per_span`
//! chosen so that there are at most [`MAX_VERTICES`] of them (down to one per span: the
//! knots). Polylines, combs and graphs then pick from these by arc length.

use super::{MAX_MARKERS, MAX_VERTICES};
use crate::analysis::{CombSample, ZERO_REL, analysis_curve, curvature_comb, signed_curvature};
use crate::curve::CurveDeriv;
use crate::error::Result;
use crate::geom::{Point, PointSeq, Rigid, Vec2};
use crate::numeric::GaussLegendre;
use crate::spline::{CubicSplineFn, FnEndCondition, ParametricCubic};

/// The most samples per span: enough for a smooth comb envelope on a short input.
const MAX_SAMPLES_PER_SPAN: usize = 16;

/// Rounding-noise factor of the inflection sign test: the same floor, `64·ε·R/h_min²`, as
/// [`crate::FairnessMetrics`] uses (see `NOISE_FACTOR` in `analysis/metrics.rs`), so the
/// markers drawn are the inflections the metrics count.
const INFLECTION_NOISE_FACTOR: f64 = 64.0;

/// Gauss–Legendre nodes per span for the arc lengths drawn against: exact for a straight
/// span, and far below a pixel's worth of error on any span of a smooth curve.
const ARC_NODES: usize = 8;

/// Bisection steps locating an inflection between two samples of opposite curvature sign:
/// 60 halvings take any span below the spacing of doubles.
const BISECTION_STEPS: usize = 60;

/// A point sequence as drawn: its analysis curve sampled, with arc lengths and inflections.
#[derive(Debug)]
pub(crate) struct Sampled<'a> {
    /// The data.
    pub seq: &'a PointSeq,
    /// Curve samples in parameter order (the last one left-sided at the end of the domain).
    pub comb: Vec<CombSample>,
    /// Arc length at each sample, from 0 to [`Sampled::length`].
    pub s: Vec<f64>,
    /// Total arc length.
    pub length: f64,
    /// Sign changes of the curvature, counted as [`crate::FairnessMetrics`] counts them.
    pub inflection_count: usize,
    /// Where (at most [`MAX_MARKERS`] of) them are: the point and its arc length.
    pub inflections: Vec<(Point, f64)>,
}

impl<'a> Sampled<'a> {
    /// Sample the analysis curve of `seq`.
    ///
    /// # Errors
    /// The analysis curve's constructor errors.
    pub(crate) fn new(seq: &'a PointSeq) -> Result<Sampled<'a>> {
        let curve = analysis_curve(seq)?;
        let m = curve.num_spans();
        let per_span = ((MAX_VERTICES - 1) / m.max(1)).clamp(1, MAX_SAMPLES_PER_SPAN);
        // Samples: `per_span` in every span, in order, then the end of the domain.
        let comb = curvature_comb(&curve, per_span);
        let arc = SpanArcLength::new(&curve);
        let s: Vec<f64> = comb
            .iter()
            .enumerate()
            .map(|(k, c)| arc.s_in_span(&curve, (k / per_span).min(m), c.t))
            .collect();
        let (inflection_count, located) = inflections(&curve, seq);
        let inflections = located
            .into_iter()
            .map(|t| {
                let s = arc.s_in_span(&curve, curve.find_span(t), t);
                (curve.derivatives(t).point, s)
            })
            .collect();
        Ok(Sampled {
            seq,
            comb,
            s,
            length: arc.total(),
            inflection_count,
            inflections,
        })
    }

    /// Indices of at most `max` samples, evenly spread by arc length, first and last included.
    pub(crate) fn by_arc_length(&self, max: usize) -> Vec<usize> {
        select_by_arc_length(&self.s, max)
    }

    /// Indices of the samples of a curvature graph: all of them when there are at most
    /// [`MAX_VERTICES`], else the smallest and largest curvature in each of
    /// `MAX_VERTICES / 2` arc-length bins, so that no peak is lost.
    pub(crate) fn graph_indices(&self) -> Vec<usize> {
        let kappa: Vec<f64> = self.comb.iter().map(|c| c.curvature).collect();
        min_max_indices(&self.s, &kappa, MAX_VERTICES / 2)
    }
}

/// Arc length of a [`ParametricCubic`] for drawing: cumulative at the knots, and within a
/// span by Gauss–Legendre on the span's own polynomial. Unlike
/// [`ArcLengthTable`](crate::analysis::ArcLengthTable) it evaluates spans directly (no span
/// search per quadrature node), which keeps a curve of 10⁶ points quick to draw.
#[derive(Debug)]
struct SpanArcLength {
    gl: GaussLegendre,
    cumulative: Vec<f64>,
}

impl SpanArcLength {
    fn new(curve: &ParametricCubic) -> SpanArcLength {
        let gl = GaussLegendre::new(ARC_NODES);
        let t = curve.knots();
        let mut cumulative = Vec::with_capacity(curve.num_spans() + 1);
        let mut s = 0.0;
        cumulative.push(s);
        for i in 0..curve.num_spans() {
            s += Self::within(&gl, curve.span_coeffs(i), t[i + 1] - t[i]);
            cumulative.push(s);
        }
        SpanArcLength { gl, cumulative }
    }

    /// `∫_0^u |r'|` on a span with power-basis coefficients `a`.
    fn within(gl: &GaussLegendre, a: [Vec2; 4], u: f64) -> f64 {
        if u <= 0.0 {
            return 0.0;
        }
        gl.integrate(0.0, u, |x| {
            (a[1] + (a[2] * 2.0 + a[3] * (3.0 * x)) * x).length()
        })
    }

    /// Arc length at parameter `t`, which lies in span `span` (`span = num_spans` for the end
    /// of the domain).
    fn s_in_span(&self, curve: &ParametricCubic, span: usize, t: f64) -> f64 {
        let knots = curve.knots();
        match (self.cumulative.get(span), knots.get(span)) {
            (Some(&c), Some(&t0)) if span < curve.num_spans() => {
                c + Self::within(&self.gl, curve.span_coeffs(span), t - t0)
            }
            _ => self.total(),
        }
    }

    fn total(&self) -> f64 {
        self.cumulative.last().copied().unwrap_or(0.0)
    }
}

/// Indices of at most `max` entries of the increasing sequence `s`, nearest to `max` evenly
/// spaced values from its first to its last entry (both included), without repeats.
pub(crate) fn select_by_arc_length(s: &[f64], max: usize) -> Vec<usize> {
    let n = s.len();
    if n <= max {
        return (0..n).collect();
    }
    if max < 2 {
        return vec![0];
    }
    let (first, last) = (s[0], s[n - 1]);
    let mut out = Vec::with_capacity(max);
    let mut i = 0;
    for j in 0..max {
        let target = first + (last - first) * j as f64 / (max - 1) as f64;
        while i + 1 < n && s[i + 1] <= target {
            i += 1;
        }
        let pick = if i + 1 < n && s[i + 1] - target < target - s[i] {
            i + 1
        } else {
            i
        };
        if out.last() != Some(&pick) {
            out.push(pick);
        }
    }
    if out.last() != Some(&(n - 1)) {
        out.push(n - 1);
    }
    out
}

/// Indices keeping the shape of the graph `(x_k, v_k)` (x increasing) in at most about
/// `2·bins + 2` vertices: all of them when that many or fewer, else the first, the last, and
/// in each of `bins` equal x-intervals the smallest and the largest finite `v`, in order.
pub(crate) fn min_max_indices(x: &[f64], v: &[f64], bins: usize) -> Vec<usize> {
    let n = x.len().min(v.len());
    if n <= 2 * bins + 2 || bins == 0 {
        return (0..n).collect();
    }
    let (first, last) = (x[0], x[n - 1]);
    let width = (last - first) / bins as f64;
    let mut out = Vec::with_capacity(2 * bins + 2);
    out.push(0);
    let mut k = 1;
    for b in 0..bins {
        let end = if b + 1 == bins {
            last
        } else {
            first + width * (b + 1) as f64
        };
        let (mut lo, mut hi): (Option<usize>, Option<usize>) = (None, None);
        while k < n - 1 && x[k] <= end {
            if v[k].is_finite() {
                if lo.is_none_or(|j| v[k] < v[j]) {
                    lo = Some(k);
                }
                if hi.is_none_or(|j| v[k] > v[j]) {
                    hi = Some(k);
                }
            }
            k += 1;
        }
        match (lo, hi) {
            (Some(a), Some(b)) if a == b => out.push(a),
            (Some(a), Some(b)) => {
                out.push(a.min(b));
                out.push(a.max(b));
            }
            _ => {}
        }
    }
    out.push(n - 1);
    out
}

/// Indices of at most `max` of `0..n`, evenly spread (every k-th, the last included).
pub(crate) fn stride_indices(n: usize, max: usize) -> Vec<usize> {
    if n <= max {
        return (0..n).collect();
    }
    let step = n.div_ceil(max.max(1));
    let mut v: Vec<usize> = (0..n).step_by(step).collect();
    if v.last() != Some(&(n - 1)) {
        v.push(n - 1);
    }
    v
}

/// Count the curvature sign changes of `curve` exactly as [`crate::FairnessMetrics`] does
/// (curvature at the knots and at the vertex of each span's quadratic numerator, evaluated
/// on the span's own polynomial, with the same rounding-noise floor and relative zero), and
/// locate at most [`MAX_MARKERS`] of them (evenly spread over the list when there are more)
/// by bisection between the two samples that bracket each change. Returns the count and the
/// parameters of the located ones.
fn inflections(curve: &ParametricCubic, seq: &PointSeq) -> (usize, Vec<f64>) {
    let closed = curve.is_closed();
    let m = curve.num_spans();
    let t = curve.knots();
    if m == 0 || t.len() < m + 1 {
        return (0, Vec::new());
    }
    let mut samples: Vec<(f64, f64)> = Vec::with_capacity(2 * m + 1);
    for i in 0..m {
        let [_, a1, a2, a3] = curve.span_coeffs(i);
        let h = t[i + 1] - t[i];
        samples.push((t[i], signed_curvature(&curve.derivatives_in_span(i, t[i]))));
        // cross(u) = 6(a2×a3) u² + 6(a1×a3) u + 2(a1×a2): its vertex.
        let qa = 6.0 * a2.cross(a3);
        let qb = 6.0 * a1.cross(a3);
        if qa != 0.0 {
            let u = -qb / (2.0 * qa);
            if u > 0.0 && u < h {
                let d = curve.derivatives_in_span(i, t[i] + u);
                samples.push((t[i] + u, signed_curvature(&d)));
            }
        }
    }
    if !closed {
        let d = curve.derivatives_in_span(m - 1, t[m]);
        samples.push((t[m], signed_curvature(&d)));
    }
    let coord = crate::geom::max_abs_coordinate(seq.points());
    let h_min = t.windows(2).fold(f64::INFINITY, |a, w| a.min(w[1] - w[0]));
    let floor = INFLECTION_NOISE_FACTOR * f64::EPSILON * coord / (h_min * h_min);
    let filtered = |k: f64| if k.abs() <= floor { 0.0 } else { k };
    let scale = samples
        .iter()
        .fold(0.0_f64, |a, &(_, k)| a.max(filtered(k).abs()));
    let signed: Vec<(f64, f64)> = samples
        .iter()
        .filter_map(|&(tt, k)| {
            let k = filtered(k);
            (k.abs() > ZERO_REL * scale).then_some((tt, k.signum()))
        })
        .collect();
    let period = t[m] - t[0];
    let mut changes: Vec<(f64, f64, f64)> = signed
        .windows(2)
        .filter(|w| w[0].1 != w[1].1)
        .map(|w| (w[0].0, w[1].0, w[0].1))
        .collect();
    if closed
        && let (Some(a), Some(b)) = (signed.last(), signed.first())
        && signed.len() > 1
        && a.1 != b.1
    {
        changes.push((a.0, b.0 + period, a.1));
    }
    let count = changes.len();
    let wrap = |tt: f64| if tt > t[m] { tt - period } else { tt };
    let located = stride_indices(count, MAX_MARKERS)
        .into_iter()
        .map(|j| {
            let (mut a, mut b, sign_a) = changes[j];
            for _ in 0..BISECTION_STEPS {
                let mid = 0.5 * (a + b);
                if mid <= a || mid >= b {
                    break;
                }
                let d = curve.derivatives(wrap(mid));
                let c = d.d1.cross(d.d2);
                if c == 0.0 {
                    a = mid;
                    b = mid;
                    break;
                }
                if c.signum() == sign_a {
                    a = mid;
                } else {
                    b = mid;
                }
            }
            wrap(0.5 * (a + b))
        })
        .collect();
    (count, located)
}

/// HAN's x–c data of a function segment: the abscissae and `c_i = y''(x_i)/6` of the cubic
/// spline function with HAN's end condition.
#[derive(Clone, Debug)]
pub(crate) struct XcData {
    pub x: Vec<f64>,
    pub c: Vec<f64>,
}

/// The frame in which `points` are a function graph: the data's own when x increases
/// strictly, else the chord frame (origin at the first point, x axis towards the last) when
/// x increases strictly there. `None` when neither.
pub(crate) fn function_frame(points: &[Point]) -> Option<(Rigid, bool)> {
    let increasing = |f: &dyn Fn(Point) -> f64| points.windows(2).all(|w| f(w[1]) > f(w[0]));
    if increasing(&|p| p.x) {
        return Some((Rigid::IDENTITY, false));
    }
    let (first, last) = (points.first()?, points.last()?);
    let frame = Rigid::to_local_frame(*first, (*last - *first).atan2());
    increasing(&|p| frame.apply(p).x).then_some((frame, true))
}

/// The x–c data of `points` in `frame`.
///
/// # Errors
/// [`crate::Error::NotIncreasing`] when x does not increase strictly in `frame`, and the other
/// errors of [`CubicSplineFn::try_new`].
pub(crate) fn xc_data(points: &[Point], frame: &Rigid) -> Result<XcData> {
    let (x, y): (Vec<f64>, Vec<f64>) = points
        .iter()
        .map(|&p| {
            let q = frame.apply(p);
            (q.x, q.y)
        })
        .unzip();
    let spline = CubicSplineFn::try_new(x, y, FnEndCondition::Han)?;
    Ok(XcData {
        x: spline.x().to_vec(),
        c: spline.c().to_vec(),
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::FairnessMetrics;

    #[test]
    fn arc_length_selection_is_even_and_keeps_the_ends() {
        let s: Vec<f64> = (0..1001).map(|i| (i as f64).powf(1.5)).collect();
        let idx = select_by_arc_length(&s, 50);
        assert!(idx.len() <= 50 && idx.len() >= 40, "{}", idx.len());
        assert_eq!(idx[0], 0);
        assert_eq!(*idx.last().unwrap(), 1000);
        assert!(idx.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(
            select_by_arc_length(&s[..10], 50),
            (0..10).collect::<Vec<_>>()
        );
    }

    #[test]
    fn min_max_keeps_spikes() {
        let x: Vec<f64> = (0..100_000).map(f64::from).collect();
        let mut v = vec![0.0; 100_000];
        v[31_337] = 5.0;
        v[77_777] = -3.0;
        let idx = min_max_indices(&x, &v, 100);
        assert!(idx.len() <= 202);
        assert!(idx.contains(&31_337) && idx.contains(&77_777));
        assert!(idx.windows(2).all(|w| w[0] < w[1]));
    }

    #[test]
    fn stride() {
        assert_eq!(stride_indices(5, 10), vec![0, 1, 2, 3, 4]);
        let v = stride_indices(1_000_001, 2000);
        assert!(v.len() <= 2001);
        assert_eq!(*v.last().unwrap(), 1_000_000);
    }

    fn seq_of(f: impl Fn(f64) -> f64, n: usize) -> PointSeq {
        let pts = (0..n)
            .map(|i| {
                let x = -1.5 + 3.0 * i as f64 / (n - 1) as f64;
                Point::new(x, f(x))
            })
            .collect();
        PointSeq::open(pts).unwrap()
    }

    #[test]
    fn inflections_match_the_metrics() {
        let cubic = seq_of(|x| x * x * x - x, 41);
        let s = Sampled::new(&cubic).unwrap();
        assert_eq!(s.inflection_count, 1);
        assert_eq!(
            s.inflection_count,
            FairnessMetrics::of_seq(&cubic).unwrap().inflections
        );
        let (p, _) = s.inflections[0];
        assert!(p.x.abs() < 1e-6 && p.y.abs() < 1e-6, "{p:?}");
        // A wiggly one, and a closed one.
        let wiggly = seq_of(|x| (7.0 * x).sin() + 0.01 * (40.0 * x).sin(), 60);
        let s = Sampled::new(&wiggly).unwrap();
        assert_eq!(
            s.inflection_count,
            FairnessMetrics::of_seq(&wiggly).unwrap().inflections
        );
        assert_eq!(s.inflections.len(), s.inflection_count);
        let star: Vec<Point> = (0..40)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / 40.0;
                let r = 2.0 + 0.6 * (5.0 * a).cos();
                Point::new(r * a.cos(), r * a.sin())
            })
            .collect();
        let star = PointSeq::closed(star).unwrap();
        let s = Sampled::new(&star).unwrap();
        assert_eq!(s.inflection_count, 10);
        assert_eq!(
            s.inflection_count,
            FairnessMetrics::of_seq(&star).unwrap().inflections
        );
        // Each marker lies where the curvature of the analysis curve vanishes.
        let curve = analysis_curve(&star).unwrap();
        let table = crate::analysis::ArcLengthTable::new(&curve);
        assert!((table.total() - s.length).abs() < 1e-9 * s.length);
        for &(p, s_at) in &s.inflections {
            let k = crate::analysis::curvature_at(&curve, table.t_at(&curve, s_at));
            assert!(k.abs() < 1e-6, "{k} at {p:?}");
        }
    }

    #[test]
    fn arc_lengths_match_the_table() {
        let wiggly = seq_of(|x| (3.0 * x).sin(), 25);
        let s = Sampled::new(&wiggly).unwrap();
        let curve = analysis_curve(&wiggly).unwrap();
        let table = crate::analysis::ArcLengthTable::new(&curve);
        assert_eq!(s.comb.len(), 24 * MAX_SAMPLES_PER_SPAN + 1);
        for (c, &sk) in s.comb.iter().zip(&s.s) {
            assert!((table.s_at(&curve, c.t) - sk).abs() < 1e-9, "{sk}");
        }
        assert!((s.length - table.total()).abs() < 1e-9);
    }

    #[test]
    fn straight_data_has_no_inflections() {
        let line = seq_of(|x| 0.5 * x + 1.0, 30);
        let s = Sampled::new(&line).unwrap();
        assert_eq!(s.inflection_count, 0);
        assert!(s.inflections.is_empty());
    }

    #[test]
    fn function_frames() {
        let up: Vec<Point> = (0..5).map(|i| Point::new(i as f64, 0.0)).collect();
        assert_eq!(function_frame(&up).map(|f| f.1), Some(false));
        // Vertical data: a function only in the chord frame.
        let vertical: Vec<Point> = (0..5)
            .map(|i| Point::new(0.1 * (i as f64).sin(), i as f64))
            .collect();
        assert_eq!(function_frame(&vertical).map(|f| f.1), Some(true));
        let (frame, _) = function_frame(&vertical).unwrap();
        let xc = xc_data(&vertical, &frame).unwrap();
        assert_eq!(xc.x.len(), 5);
        assert_eq!(xc.c[0], xc.c[1]); // HAN's end condition
        // A loop is a function in no frame.
        let lp: Vec<Point> = (0..12)
            .map(|i| {
                let a = i as f64 * 0.5;
                Point::new(a.cos(), a.sin())
            })
            .collect();
        assert!(function_frame(&lp).is_none());
    }
}
