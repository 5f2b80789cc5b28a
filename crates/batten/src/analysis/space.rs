//! Measurements of space curves: curvature (unsigned), torsion and their extrema, energies
//! and length, on the C² cubic through the points ([`SpaceMetrics`]).

use rayon::prelude::*;
use serde::Serialize;

use super::count_sign_changes;
use super::space_curve::{Frenet, SpaceCubic, SpaceDerivatives};
use crate::error::Result;
use crate::geom::SpaceSeq;
use crate::geom::norm3 as norm;
use crate::numeric::GaussLegendre;

/// Rounding-noise factor of the sign tests, as for planar curves: κ below
/// `NOISE_FACTOR·ε·R/h_min²` (R the largest coordinate magnitude, h_min the shortest chord)
/// counts as zero, dκ/ds below that over `h_min` too; the triple product `(r'×r'')·r'''`
/// counts as zero below `NOISE_FACTOR·ε·R` times its sensitivity to errors of size
/// `R/h_min^k` in the k-th derivative (`|r''||r'''|/h + |r'||r'''|/h² + |r'||r''|/h³`).
///
/// Torsion needs the third derivative, whose rounding error grows as `1/h³`: on very dense
/// points it is below that floor and reads 0 (measured on two turns of a helix with
/// κ = 0.98, τ = 0.079: found within 5 % at 10⁵ points; at 3·10⁵ the rounding error in the
/// triple product is 15 % of it, and at 10⁶ larger than it, where the floor sets it to 0).
const NOISE_FACTOR: f64 = 64.0;

/// Spans per parallel work unit: fixed, so that the numbers do not depend on the number of
/// threads.
const SPANS_PER_CHUNK: usize = 4096;

/// A sequence of values seen in order, kept as the signed peak of each of its runs of one
/// sign (zeros skipped): its sign changes under the relative zero of [`super::sgn0`] are
/// those of the peaks, so chunks can be gathered apart and joined.
#[derive(Debug, Default)]
struct Peaks(Vec<f64>);

impl Peaks {
    /// Append a value; those of magnitude at most `floor` (and NaN) are zeros, skipped.
    #[inline]
    fn push(&mut self, v: f64, floor: f64) {
        if v.abs() > floor {
            self.merge(v);
        }
    }

    #[inline]
    fn merge(&mut self, v: f64) {
        match self.0.last_mut() {
            Some(p) if (*p > 0.0) == (v > 0.0) => {
                if v.abs() > p.abs() {
                    *p = v;
                }
            }
            _ => self.0.push(v),
        }
    }

    /// Append the peaks of the values that follow.
    fn join(&mut self, later: Peaks) {
        later.0.into_iter().for_each(|v| self.merge(v));
    }

    fn sign_changes(&self, cyclic: bool) -> usize {
        count_sign_changes(&self.0, cyclic)
    }
}

/// The rounding floors of one measurement.
#[derive(Clone, Copy, Debug)]
struct Floors {
    kappa: f64,
    dkappa: f64,
    /// `NOISE_FACTOR·ε·R`.
    coord: f64,
    /// The shortest chord.
    h: f64,
}

impl Floors {
    /// Whether the triple product of these derivatives is above its rounding noise.
    #[inline]
    fn triple_counts(&self, f: &Frenet, d: &SpaceDerivatives) -> bool {
        let (n1, n2, n3) = (norm(d.d1), norm(d.d2), norm(d.d3));
        let h = self.h;
        let noise = self.coord * (n2 * n3 / h + n1 * n3 / (h * h) + n1 * n2 / (h * h * h));
        f.triple.abs() > noise
    }
}

/// What one chunk of spans gathers.
#[derive(Debug, Default)]
struct Sums {
    dk: Peaks,
    tau: Peaks,
    dtau: Peaks,
    max_curvature: f64,
    max_torsion: f64,
    length: f64,
    strain: f64,
    variation: f64,
    torsion: f64,
}

impl Sums {
    fn join(mut self, later: Sums) -> Sums {
        self.dk.join(later.dk);
        self.tau.join(later.tau);
        self.dtau.join(later.dtau);
        self.max_curvature = self.max_curvature.max(later.max_curvature);
        self.max_torsion = self.max_torsion.max(later.max_torsion);
        self.length += later.length;
        self.strain += later.strain;
        self.variation += later.variation;
        self.torsion += later.torsion;
        self
    }
}

/// The fairness numbers of a space curve, measured on the C² cubic through the points with
/// chord-length parameters (not-a-knot ends when open, periodic when closed, see
/// [`SpaceCubic::of_seq`]), as [`super::FairnessMetrics`] are for planar curves. Curvature is
/// unsigned in space, so there are no inflections (a planar curve's inflections are minima
/// of κ here); torsion takes their place as the signed quantity. Torsion is undefined where
/// κ is zero: samples with κ at the rounding floor are left out of the torsion's numbers
/// (and of dκ/ds's signs), and a triple product `(r'×r'')·r'''` within its rounding noise
/// counts as zero torsion, so that a planar curve, however rotated, has none.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[non_exhaustive]
pub struct SpaceMetrics {
    /// Always 3.
    pub dimension: usize,
    /// Number of points.
    pub points: usize,
    /// Whether the curve is closed.
    pub closed: bool,
    /// Largest κ, over the samples of the planar metrics: each span's quadrature nodes,
    /// between the one-sided limits at its knots (docs/algorithms/README.md §0.4).
    pub max_curvature: f64,
    /// Local extrema of κ(s), from the sign of d|κ|/ds at the same samples.
    pub curvature_extrema: usize,
    /// Largest |τ| where the torsion is defined (κ above the rounding floor).
    pub max_torsion: f64,
    /// Sign changes of τ(s).
    pub torsion_sign_changes: usize,
    /// Local extrema of τ(s).
    pub torsion_extrema: usize,
    /// `∫ κ² ds`.
    pub strain_energy: f64,
    /// `∫ (dκ/ds)² ds`.
    pub variation_energy: f64,
    /// `∫ τ² ds`.
    pub torsion_energy: f64,
    /// Total arc length.
    pub length: f64,
}

impl SpaceMetrics {
    /// Measure a space curve.
    ///
    /// As for planar curves, the measurement runs on the points divided by the power of two
    /// that brings the bounding box's largest side near 1 (exactly), and the numbers are
    /// scaled back, so that the counts do not depend on the scale.
    ///
    /// Extrema are counted as the monotone pieces of the densely sampled function minus one
    /// (sign changes of its derivative, cyclically when closed); the maxima are taken over
    /// the same samples (17 a span, both ends); energies and length by Gauss–Legendre
    /// quadrature per span. O(n) time, in parallel over fixed chunks of spans (the numbers
    /// do not depend on the thread count); memory for the spline (104 bytes a point).
    ///
    /// # Errors
    /// The interpolant's errors.
    pub fn of_seq(seq: &SpaceSeq) -> Result<SpaceMetrics> {
        let s = crate::geom::unit_scale_xyz(seq.points());
        if s == 1.0 {
            return Self::measure(seq);
        }
        let inv = 1.0 / s;
        let pts = seq.points().iter().map(|p| p.map(|c| c * inv)).collect();
        Ok(Self::measure(&seq.with_points(pts)?)?.rescaled(s))
    }

    /// The metrics of the same curve scaled by `s` (counts unchanged; each number times `s`
    /// to its power of length).
    pub fn rescaled(mut self, s: f64) -> SpaceMetrics {
        self.max_curvature *= s.powi(-1);
        self.max_torsion *= s.powi(-1);
        self.strain_energy *= s.powi(-1);
        self.variation_energy *= s.powi(-3);
        self.torsion_energy *= s.powi(-1);
        self.length *= s;
        self
    }

    /// [`SpaceMetrics::of_seq`] in the coordinates as given.
    fn measure(seq: &SpaceSeq) -> Result<SpaceMetrics> {
        let curve = SpaceCubic::of_seq(seq)?;
        let closed = seq.is_closed();
        let m = curve.num_spans();
        let t = curve.knots();
        let coord = seq
            .points()
            .iter()
            .flatten()
            .fold(0.0_f64, |a, c| a.max(c.abs()));
        let h_min = t.windows(2).fold(f64::INFINITY, |a, w| a.min(w[1] - w[0]));
        let kappa = NOISE_FACTOR * f64::EPSILON * coord / (h_min * h_min);
        let floors = Floors {
            kappa,
            dkappa: kappa / h_min,
            coord: NOISE_FACTOR * f64::EPSILON * coord,
            h: h_min,
        };
        let gl = GaussLegendre::default();
        let sums = (0..m.div_ceil(SPANS_PER_CHUNK))
            .into_par_iter()
            .map(|c| {
                let mut r = Sums::default();
                for i in c * SPANS_PER_CHUNK..((c + 1) * SPANS_PER_CHUNK).min(m) {
                    span_sums(&curve, i, &gl, floors, &mut r);
                }
                r
            })
            .collect::<Vec<Sums>>()
            .into_iter()
            .fold(Sums::default(), Sums::join);
        Ok(SpaceMetrics {
            dimension: 3,
            points: seq.len(),
            closed,
            max_curvature: sums.max_curvature,
            curvature_extrema: sums.dk.sign_changes(closed),
            max_torsion: sums.max_torsion,
            torsion_sign_changes: sums.tau.sign_changes(closed),
            torsion_extrema: sums.dtau.sign_changes(closed),
            strain_energy: sums.strain,
            variation_energy: sums.variation,
            torsion_energy: sums.torsion,
            length: sums.length,
        })
    }
}

/// Gather span `i` of `curve` into `r`: the maxima and the sign runs from samples at the
/// Gauss–Legendre nodes between both one-sided limits at the knots, as for planar curves
/// (docs/algorithms/README.md §0.4); length and energies by the same nodes.
#[inline]
fn span_sums(curve: &SpaceCubic, i: usize, gl: &GaussLegendre, floors: Floors, r: &mut Sums) {
    let t = curve.knots();
    let (t0, h) = (t[i], t[i + 1] - t[i]);
    let half = 0.5 * h;
    let mid = t0 + half;
    sample(r, &curve.derivatives_in_span(i, t0), floors);
    for (x, w) in gl.nodes().iter().zip(gl.weights()) {
        let d = curve.derivatives_in_span(i, mid + half * x);
        let f = sample(r, &d, floors);
        let ws = w * half * f.speed;
        r.length += ws;
        r.strain += ws * f.kappa * f.kappa;
        r.variation += ws * f.dkappa_ds * f.dkappa_ds;
        if f.kappa > floors.kappa && floors.triple_counts(&f, &d) {
            let tau = f.torsion();
            r.torsion += ws * tau * tau;
        }
    }
    sample(r, &curve.derivatives_in_span(i, t[i + 1]), floors);
}

/// One sample of the maxima and the sign runs; its Frenet quantities.
#[inline]
fn sample(r: &mut Sums, d: &SpaceDerivatives, floors: Floors) -> Frenet {
    let f = Frenet::of(d);
    r.max_curvature = r.max_curvature.max(f.kappa);
    if f.kappa <= floors.kappa {
        // No osculating plane: neither d|κ|/ds nor τ has a meaningful sign.
        return f;
    }
    r.dk.push(f.dkappa_ds, floors.dkappa);
    if floors.triple_counts(&f, d) {
        let tau = f.torsion();
        r.max_torsion = r.max_torsion.max(tau.abs());
        r.tau.push(tau, 0.0);
        r.dtau.push(f.torsion_rate(), 0.0);
    }
    f
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::geom::Xyz;

    #[test]
    fn peaks_count_as_the_values_do() {
        let values = [1.0, 0.0, 2.0, -1e-20, 3.0, -1.0, -4.0, 1e-3, 2.0, -5.0];
        for cut in 0..=values.len() {
            let (mut a, mut b) = (Peaks::default(), Peaks::default());
            values[..cut].iter().for_each(|&v| a.push(v, 0.0));
            values[cut..].iter().for_each(|&v| b.push(v, 0.0));
            a.join(b);
            for cyclic in [false, true] {
                assert_eq!(a.sign_changes(cyclic), count_sign_changes(&values, cyclic));
            }
        }
    }

    #[test]
    fn metrics_do_not_depend_on_the_thread_count() {
        let n = 2 * SPANS_PER_CHUNK + 29;
        let pts: Vec<Xyz> = (0..n)
            .map(|i| {
                let a = i as f64 * 0.01;
                [a.cos(), a.sin(), 0.1 * a + 1e-4 * (i % 5) as f64]
            })
            .collect();
        for closed in [false, true] {
            let seq = SpaceSeq::new(pts.clone(), closed).unwrap();
            let run = |threads| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap()
                    .install(|| SpaceMetrics::of_seq(&seq).unwrap())
            };
            let one = run(1);
            assert_eq!(one, run(3));
            assert!(one.curvature_extrema > 0 && one.torsion_sign_changes > 0);
        }
    }
}
