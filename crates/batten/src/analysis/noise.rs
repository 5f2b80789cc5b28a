//! A robust estimate of the noise in sampled points, for `--tolerance auto`.
//!
//! The `k`-th difference `Δᵏp_i = Σ_j (−1)^(k−j) C(k, j) p_{i+j}` of a smooth curve sampled
//! at spacing `h` is small (`hᵏ C⁽ᵏ⁾`), while independent noise of standard deviation `σ` in
//! each coordinate gives it a standard deviation of `σ·√C(2k, k)` per coordinate (the squared
//! binomial coefficients add up to `C(2k, k)`). Only the component along the local normal is
//! used: the chord `p_{i+k} − p_i` turned by 90° gives the normal, and the tangential
//! component holds the curve's own `hᵏ C⁽ᵏ⁾`, which for a curve turning steadily (a circle) is
//! not small. With `v_i = |n_i · Δᵏp_i| / √C(2k, k)`, the estimate starts from the median
//! absolute deviation, `σ̂ = 1.4826 · median v_i` (1.4826 makes the MAD a consistent estimator
//! of σ for Gaussian noise), and then takes, three times, the root mean square of the `v_i`
//! within `3σ̂`, divided by `√0.97334` (the mean square of a Gaussian clipped at 3σ). The
//! median ignores the curve's own large differences (a sharp nose, a corner) but is a wasteful
//! estimator: over noise draws its spread is half as large again as a mean square's, and an
//! underestimate narrows `band`'s band and lowers its debiasing target, both of which leave
//! spurious inflections. Clipped at 3σ̂, the mean square keeps the robustness (see
//! [`NoiseMeasure::sigma`] for the figures).
//!
//! The order is 5 (`√C(10, 5) = √252`), 3 below `FIFTH_ORDER_POINTS` points. Each order
//! divides the curve's own part by about `h / L` (`L` the curve's length scale) and leaves the
//! noise's, so a coarse clean curve is not taken for noise: exact samples of the benchmark's
//! ten curve families at 30 points give σ̂ a median of 3.6e-4 of the diagonal with third
//! differences, 8.4e-6 with fifth ones (at 100 points 8.9e-6 and 2.0e-8), and `band`'s
//! automatic tolerance on them moved the curve by up to that much. On noisy samples (0.1 to
//! 1 % of the diagonal, 30 to 1000 points) the two orders are equally accurate (with the
//! median alone, median σ̂/σ 0.98 to 1.17 for both); at 30 points and 0.1 % noise the fifth
//! order's worst case is 1.65 σ against 3.03.
//!
//! A MAD pooled over both coordinates underestimates noise that lies in one coordinate only
//! (the bundled `sine-noisy.csv`, noise in y: 0.0045 against a true 0.03); projected on the
//! normal it does not. See `docs/algorithms/band.md`.
//!
//! In space ([`noise_sigma_space`]) the part of a difference off the local chord is 2-D; its
//! length's median, `σ·√C(2k, k)·√(2 ln 2)` for Gaussian noise, gives the first σ̂, and the
//! clipped mean square of the lengths (Rayleigh-distributed) the rest. The code is one,
//! generic over the dimension, and a planar curve in space gives the planar results.

use crate::geom::{Point, next_index};
use crate::numeric::{PARALLEL_FROM, map_indices, max_indices, norm};

/// The MAD-to-σ factor for Gaussian noise.
pub const MAD_TO_SIGMA: f64 = 1.482_6;

/// From this many points the fifth differences are used, below it the third.
pub(super) const FIFTH_ORDER_POINTS: usize = 8;

/// The coefficients of the third and fifth differences and the standard deviation each gives
/// unit-variance independent noise, `√C(2k, k)`.
const THIRD: (&[f64], f64) = (&[-1.0, 3.0, -3.0, 1.0], 4.472_135_954_999_579);
const FIFTH: (&[f64], f64) = (&[-1.0, 5.0, -10.0, 10.0, -5.0, 1.0], 15.874_507_866_387_544);

/// How long the chord that gives the local normal must be, in units of a rough noise scale:
/// where the noise is as large as the point spacing (dense scans), the chord over the
/// difference's points points anywhere, and the projection would hide the noise. The chord
/// is widened symmetrically until it spans about this many rough noise scales.
const NORMAL_CHORD_NOISE_SPANS: f64 = 20.0;

/// The noise estimate σ̂ of the points `pts` (per coordinate, in data units), from the
/// differences of order 5 (3 below `FIFTH_ORDER_POINTS` points) along the local normal.
/// Closed curves wrap around. Returns 0 for fewer than four points or where every normal
/// component vanishes (points on a line, exact samples of a parabola).
///
/// The normal at a difference over `p_i … p_{i+k}` is that of the chord `p_{i+k+m} −
/// p_{i−m}` (indices clamped at the ends of an open curve), with `m = 0` unless the noise is
/// comparable to the point spacing: `m` is chosen so the chord spans about
/// `NORMAL_CHORD_NOISE_SPANS` times a rough noise scale (the same MAD taken over the whole
/// difference vectors, an overestimate) — at most an eighth of the points.
pub fn noise_sigma(pts: &[Point], closed: bool) -> f64 {
    let xy: Vec<[f64; 2]> = pts.iter().map(|p| [p.x, p.y]).collect();
    NoiseMeasure::of(&xy, closed).sigma(Spread::OneD)
}

/// The median of the length of a 2-D Gaussian vector of unit standard deviation per
/// coordinate is `√(2 ln 2)` (the Rayleigh distribution's median); its reciprocal turns the
/// median length into σ, as [`MAD_TO_SIGMA`] does for one coordinate.
pub const MEDIAN_LENGTH_2D_TO_SIGMA: f64 = 0.849_321_800_288_019;

/// Points whose distances from their best plane (Newell's normal through the centroid) are
/// all within this fraction of their largest deviation from the centroid count as planar.
const PLANAR_REL: f64 = 1e-9;

/// The noise estimate σ̂ of a space curve's points (per coordinate, in data units), the
/// counterpart of [`noise_sigma`]: the same differences, with the part off the local tangent
/// (the chord) taken as a whole. That part is 2-D, and for Gaussian noise of `σ` per
/// coordinate its length has the median `σ·√C(2k, k)·√(2 ln 2)`
/// ([`MEDIAN_LENGTH_2D_TO_SIGMA`]).
///
/// Points that lie in one plane (to `PLANAR_REL` of their size: a planar curve embedded in
/// space, noise included) have a 1-D off-tangent part, the planar normal component, and get
/// [`noise_sigma`]'s factor: their σ̂ is the planar one (bit for bit at `z ≡ 0`, to rounding in
/// any other plane).
pub fn noise_sigma_space(pts: &[[f64; 3]], closed: bool) -> f64 {
    NoiseMeasure::of(pts, closed).sigma(Spread::of_space(pts))
}

/// Whether the points lie in one plane (to `PLANAR_REL` of their size; noise included, so
/// the noise lies in that plane too): every deviation from the centroid (in units of the
/// largest coordinate deviation, so nothing over- or underflows) is within `PLANAR_REL` off
/// the plane of Newell's normal, the sum of the cross products of consecutive deviations,
/// each turned to agree with the sum so far (so a figure eight does not cancel it). Points
/// on a line are planar.
pub(crate) fn is_planar(pts: &[[f64; 3]]) -> bool {
    let n = pts.len() as f64;
    let mut c = [0.0; 3];
    for p in pts {
        for a in 0..3 {
            c[a] += p[a] / n;
        }
    }
    let size = pts
        .iter()
        .flat_map(|p| (0..3).map(move |a| (p[a] - c[a]).abs()))
        .fold(0.0_f64, f64::max);
    if !(size > 0.0 && size.is_finite()) {
        return true;
    }
    let u: Vec<[f64; 3]> = pts
        .iter()
        .map(|p| std::array::from_fn(|a| (p[a] - c[a]) / size))
        .collect();
    let mut normal = [0.0; 3];
    for w in u.windows(2) {
        let (a, b) = (w[0], w[1]);
        let x = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        let sign = if (0..3).map(|k| x[k] * normal[k]).sum::<f64>() < 0.0 {
            -1.0
        } else {
            1.0
        };
        for k in 0..3 {
            normal[k] += sign * x[k];
        }
    }
    let len = norm(&normal);
    if len == 0.0 {
        return true;
    }
    u.iter()
        .all(|q| ((0..3).map(|k| q[k] * normal[k]).sum::<f64>() / len).abs() <= PLANAR_REL)
}

/// `|d × c|`, the length of `d`'s part off `c` times `|c|`, by `hypot` (in 2-D the cross
/// product's magnitude, bit for bit as [`crate::geom::Vec2::cross`]; in the plane `z = 0` of
/// 3-D the same number).
fn off_axis<const D: usize>(d: &[f64; D], c: &[f64; D]) -> f64 {
    let mut acc: Option<f64> = None;
    for i in 0..D {
        for j in i + 1..D {
            let w = d[i] * c[j] - d[j] * c[i];
            acc = Some(acc.map_or(w.abs(), |s| s.hypot(w)));
        }
    }
    acc.unwrap_or(0.0)
}

/// The differences of [`noise_sigma`] and the chords that give their normals: the order's
/// coefficients' noise gain `√C(2k, k)`, the order `k`, every difference `Δᵏp_i` (`count` of
/// them) and the chord's reach `m` beyond the difference's points. `None` below four points.
struct Differences<const D: usize> {
    gain: f64,
    k: usize,
    differences: Vec<[f64; D]>,
    reach: usize,
}

impl<const D: usize> Differences<D> {
    fn of(pts: &[[f64; D]], closed: bool) -> Option<Differences<D>> {
        let n = pts.len();
        if n < 4 {
            return None;
        }
        let (coef, gain) = if n >= FIFTH_ORDER_POINTS {
            FIFTH
        } else {
            THIRD
        };
        let k = coef.len() - 1;
        let count = if closed { n } else { n - k };
        let difference = |i: usize| -> [f64; D] {
            let mut d = [0.0; D];
            // The points as a slice where none wraps (all but the last `k` of a closed curve).
            if i + k < n {
                for (c, p) in coef.iter().zip(&pts[i..=i + k]) {
                    for x in 0..D {
                        d[x] += c * p[x];
                    }
                }
                return d;
            }
            for (j, c) in coef.iter().enumerate() {
                let p = at(pts, closed, (i + j) as isize);
                for x in 0..D {
                    d[x] += c * p[x];
                }
            }
            d
        };
        // Each difference once (the rough scale and the normal parts both read it).
        let differences: Vec<[f64; D]> = map_indices(count, difference);
        let rough =
            || median(&mut map_indices(count, |i| norm(&differences[i]))) * MAD_TO_SIGMA / gain;
        let spacing = || {
            median(&mut map_indices(if closed { n } else { n - 1 }, |i| {
                // A closed curve's last chord ends at the first point.
                norm(&sub(pts[next_index(i, n)], pts[i]))
            }))
        };
        // The two medians side by side on long curves (a median is one thread's work).
        let (rough, spacing) = if count >= PARALLEL_FROM {
            rayon::join(rough, spacing)
        } else {
            (rough(), spacing())
        };
        let reach = if spacing > 0.0 {
            let m = (NORMAL_CHORD_NOISE_SPANS * rough / spacing).ceil();
            if m.is_finite() {
                (m as usize).min(n / 8)
            } else {
                0
            }
        } else {
            0
        };
        Some(Differences {
            gain,
            k,
            differences,
            reach,
        })
    }

    /// The chord that gives difference `i` its normal.
    fn chord(&self, pts: &[[f64; D]], closed: bool, i: usize) -> [f64; D] {
        let end = i + self.k + self.reach;
        if i >= self.reach && end < pts.len() {
            // Neither end wraps nor is clamped.
            return sub(pts[end], pts[i - self.reach]);
        }
        sub(
            at(pts, closed, (i + self.k + self.reach) as isize),
            at(pts, closed, i as isize - self.reach as isize),
        )
    }
}

/// Point `i` of `pts`, wrapped when closed, clamped to the ends when open.
fn at<const D: usize>(pts: &[[f64; D]], closed: bool, i: isize) -> [f64; D] {
    let n = pts.len() as isize;
    if closed {
        pts[i.rem_euclid(n) as usize]
    } else {
        pts[i.clamp(0, n - 1) as usize]
    }
}

fn sub<const D: usize>(a: [f64; D], b: [f64; D]) -> [f64; D] {
    std::array::from_fn(|x| a[x] - b[x])
}

/// Parts per parallel work unit of [`NoiseMeasure::correlation`]'s sums; fixed, so that the
/// correlation does not depend on the number of threads.
const CORRELATION_CHUNK: usize = 4096;

/// Where the clipped estimate cuts the parts, in units of the current σ̂.
const CLIP: f64 = 3.0;

/// Rounds of clipping: each takes σ̂ from the parts within [`CLIP`] of the last one (the
/// first from the median). On the quality benchmark's tuning curves the spread of
/// `ln(σ̂/σ)` is 0.141 after one round and 0.139 after three.
const CLIP_ROUNDS: usize = 3;

/// How the parts off the local chord spread for Gaussian noise of `σ` per coordinate.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Spread {
    /// One coordinate (a planar curve's normal component): `N(0, σ²)`.
    OneD,
    /// Two coordinates (a space curve's part off the chord), whose length is Rayleigh.
    TwoD,
}

impl Spread {
    /// The spread of a space curve's parts: one coordinate for points in one plane
    /// ([`is_planar`]), two otherwise.
    pub(crate) fn of_space(pts: &[[f64; 3]]) -> Spread {
        if is_planar(pts) {
            Spread::OneD
        } else {
            Spread::TwoD
        }
    }

    /// The factor that turns the median of the parts' lengths into σ.
    fn median_to_sigma(self) -> f64 {
        match self {
            Spread::OneD => MAD_TO_SIGMA,
            Spread::TwoD => MEDIAN_LENGTH_2D_TO_SIGMA,
        }
    }

    /// The mean square of a part no longer than `CLIP·σ`, over `σ²`: for one coordinate
    /// `1 − 2cφ(c)/(2Φ(c) − 1)`, for the length of two `(2 − (c² + 2)e^(−c²/2))/(1 −
    /// e^(−c²/2))`, at `c = CLIP` = 3.
    fn clipped_square(self) -> f64 {
        match self {
            Spread::OneD => 0.973_336_924_662_541_5,
            Spread::TwoD => 1.898_895_865_677_63,
        }
    }
}

/// The differences of a curve's points that σ̂ ([`NoiseMeasure::sigma`]) and the correlation
/// that tells noise from a clean curve ([`NoiseMeasure::correlation`]) are both taken from,
/// made once for both: a fair with `--tolerance auto` asks for both, and at 10⁶ points the
/// differences and their two medians are about half of either's time.
pub(crate) struct NoiseMeasure<'p, const D: usize> {
    pts: &'p [[f64; D]],
    closed: bool,
    /// `None` below four points.
    diffs: Option<Differences<D>>,
}

impl<'p, const D: usize> NoiseMeasure<'p, D> {
    /// The differences of `pts` (cyclic when `closed`).
    pub(crate) fn of(pts: &'p [[f64; D]], closed: bool) -> NoiseMeasure<'p, D> {
        NoiseMeasure {
            pts,
            closed,
            diffs: Differences::of(pts, closed),
        }
    }

    /// σ̂ from the differences' parts off the local chord (see the module's documentation):
    /// the median's estimate, then [`CLIP_ROUNDS`] times the root mean square of the parts
    /// within [`CLIP`]·σ̂, corrected for the clipping. The median alone ignores the curve's
    /// own large differences but wastes the rest: its spread over noise draws is half as large
    /// again as a mean square's. Clipped at 3σ̂ the estimate keeps the median's robustness and
    /// most of the mean square's precision (on the quality benchmark's tuning curves the
    /// spread of `ln(σ̂/σ)` fell from 0.181 to 0.139, at 30 points from 0.31 to 0.24). 0 for
    /// fewer than four points or where every part vanishes.
    pub(crate) fn sigma(&self, spread: Spread) -> f64 {
        let Some((mut parts, gain)) = self.off_tangent_parts() else {
            return 0.0;
        };
        let mut sigma = median(&mut parts) * spread.median_to_sigma();
        if !(sigma > 0.0 && sigma.is_finite()) {
            return sigma / gain;
        }
        for _ in 0..CLIP_ROUNDS {
            // In units of the last σ̂, so that no square under- or overflows.
            let (sum, kept) = parts
                .iter()
                .map(|v| v / sigma)
                .filter(|u| *u <= CLIP)
                .fold((0.0, 0usize), |(s, k), u| (s + u * u, k + 1));
            if kept == 0 {
                break;
            }
            sigma *= (sum / kept as f64 / spread.clipped_square()).sqrt();
        }
        sigma / gain
    }

    /// The lengths of the differences' parts off the local chord, in any dimension, and the
    /// noise gain `√C(2k, k)` of the differences used (`None` below four points).
    fn off_tangent_parts(&self) -> Option<(Vec<f64>, f64)> {
        let (pts, closed) = (self.pts, self.closed);
        let diffs = self.diffs.as_ref()?;
        let count = diffs.differences.len();
        // The differences without a chord are skipped; the vector is reserved whole (collected
        // from a filter, it grew by doubling: a tenth of a 200-point fair's instructions went
        // to growing the vectors here).
        let part = |i: usize| {
            let chord = diffs.chord(pts, closed, i);
            let len = norm(&chord);
            (len > 0.0).then(|| off_axis(&diffs.differences[i], &chord) / len)
        };
        let mut normal_parts = Vec::with_capacity(count);
        if count >= PARALLEL_FROM {
            use rayon::prelude::*;
            normal_parts.par_extend((0..count).into_par_iter().filter_map(part));
        } else {
            normal_parts.extend((0..count).filter_map(part));
        }
        Some((normal_parts, diffs.gain))
    }

    /// The lag-one correlation of the differences' parts off the local chord (as vectors):
    /// see [`difference_correlation`].
    pub(crate) fn correlation(&self) -> Option<f64> {
        let (pts, closed) = (self.pts, self.closed);
        let diffs = self.diffs.as_ref()?;
        let count = diffs.differences.len();
        // The unit chord by `norm`, so that coordinates of any size neither over- nor
        // underflow.
        let part = |i: usize| -> [f64; D] {
            let c = diffs.chord(pts, closed, i);
            let len = norm(&c);
            let d = &diffs.differences[i];
            if !(len > 0.0 && len.is_finite()) {
                return [0.0; D];
            }
            let u: [f64; D] = std::array::from_fn(|x| c[x] / len);
            let along = d.iter().zip(&u).map(|(a, b)| a * b).sum::<f64>();
            std::array::from_fn(|x| d[x] - along * u[x])
        };
        // In units of the largest part, so that no square under- or overflows. The parts are
        // formed again for the sums rather than stored and divided once per product they
        // enter (with the sums in parallel, 22 → 13 ms at 10⁶ points).
        let largest = |i: usize| part(i).iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let top = max_indices(count, CORRELATION_CHUNK, largest);
        if !(top > 0.0 && top.is_finite()) {
            return None;
        }
        let scaled = |i: usize| part(i).map(|v| v / top);
        let dot = |a: &[f64; D], b: &[f64; D]| (0..D).fold(0.0, |s, x| s + a[x] * b[x]);
        let pairs = if closed { count } else { count - 1 };
        // The sums `Σ ⟨e_i, e_{i+1}⟩` and `Σ |e_i|²` over fixed chunks of the parts, joined in
        // order (the same number on any number of threads).
        let chunk_sums = |c: usize| -> (f64, f64) {
            let (start, end) = (
                c * CORRELATION_CHUNK,
                ((c + 1) * CORRELATION_CHUNK).min(count),
            );
            let mut prev = scaled(start);
            let (mut lagged, mut total) = (0.0, dot(&prev, &prev));
            for i in start + 1..end {
                let e = scaled(i);
                lagged += dot(&prev, &e);
                total += dot(&e, &e);
                prev = e;
            }
            // The pair across the chunk's end (the last with the first on a closed curve).
            if end - 1 < pairs {
                lagged += dot(&prev, &scaled(next_index(end - 1, count)));
            }
            (lagged, total)
        };
        let sums = map_indices(count.div_ceil(CORRELATION_CHUNK), chunk_sums);
        let (lagged, total) = sums
            .iter()
            .fold((0.0, 0.0), |(l, t), (cl, ct)| (l + cl, t + ct));
        (total > 0.0).then(|| lagged / total)
    }
}

/// The lag-one correlation of the differences' parts off the local chord (those [`noise_sigma`]
/// takes the median of, as vectors): `Σ ⟨e_i, e_{i+1}⟩ / Σ |e_i|²`, cyclic when closed.
/// Independent noise gives `−k/(k + 1)` (−5/6 for the fifth differences: consecutive
/// differences share five points with alternating binomial weights); a smooth curve's own
/// differences change slowly from one to the next and give nearly 1. So a value near 1 says
/// that σ̂ measures the curve's shape, not noise. `None` below four points or when every part
/// vanishes (points on a line, rounding-free samples of a low-degree polynomial).
pub fn difference_correlation<const D: usize>(pts: &[[f64; D]], closed: bool) -> Option<f64> {
    NoiseMeasure::of(pts, closed).correlation()
}

/// The median of `v` (the upper one for an even count; 0 when empty), reordering it.
fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// A deterministic pseudo-random normal sample (Box–Muller over a small LCG).
    fn gaussian(seed: u64, count: usize) -> Vec<f64> {
        let mut s = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
        let mut uniform = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        (0..count)
            .map(|_| {
                let (u, v) = (uniform(), uniform());
                (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
            })
            .collect()
    }

    #[test]
    fn exact_line_and_parabola_have_no_noise() {
        let line: Vec<Point> = (0..20)
            .map(|i| Point::new(i as f64, 2.0 * i as f64))
            .collect();
        assert_eq!(noise_sigma(&line, false), 0.0);
        let parabola: Vec<Point> = (0..20)
            .map(|i| Point::new(i as f64, (i * i) as f64 * 0.1))
            .collect();
        assert!(noise_sigma(&parabola, false) < 1e-12);
    }

    /// A clean curve sampled coarsely is not taken for noise: the bundled sine's truth
    /// (`y = sin(x/2)`, 30 points over `[0, 4π]`) gave σ̂ = 2.1e-3 with third differences, a
    /// tenth of the noise of its noisy twin, and `band` flattened it by that much; fifth
    /// differences give 2.7e-5.
    #[test]
    fn a_coarse_clean_curve_is_not_noise() {
        let pts: Vec<Point> = (0..30)
            .map(|i| {
                let x = 4.0 * std::f64::consts::PI * i as f64 / 29.0;
                Point::new(x, (0.5 * x).sin())
            })
            .collect();
        let est = noise_sigma(&pts, false);
        assert!(est < 5e-5, "σ̂ = {est}");
        // The same 30 points with noise of 0.01 in y: found within a third.
        let e = gaussian(11, 30);
        let noisy: Vec<Point> = pts
            .iter()
            .zip(&e)
            .map(|(p, e)| Point::new(p.x, p.y + 0.01 * e))
            .collect();
        let est = noise_sigma(&noisy, false);
        assert!((est / 0.01 - 1.0).abs() < 0.35, "σ̂ = {est}");
    }

    /// Independent noise gives the fifth differences a lag-one correlation of −5/6, a clean
    /// curve's own differences nearly 1; noise on a curve sits in between, nearer the noise.
    #[test]
    fn the_differences_correlation_tells_noise_from_a_clean_curve() {
        let xy = |p: &[Point]| -> Vec<[f64; 2]> { p.iter().map(|q| [q.x, q.y]).collect() };
        // Noise about a line, open and closed (a circle): −5/6 to sampling error.
        let (ex, ey) = (gaussian(3, 4000), gaussian(4, 4000));
        let line: Vec<[f64; 2]> = (0..4000)
            .map(|i| [i as f64 * 0.01 + 1e-3 * ex[i], 1e-3 * ey[i]])
            .collect();
        let r = difference_correlation(&line, false).unwrap();
        assert!((r + 5.0 / 6.0).abs() < 0.03, "{r}");
        let circle: Vec<[f64; 2]> = (0..4000)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / 4000.0;
                [a.cos() + 1e-3 * ex[i], a.sin() + 1e-3 * ey[i]]
            })
            .collect();
        let r = difference_correlation(&circle, true).unwrap();
        assert!((r + 5.0 / 6.0).abs() < 0.03, "{r}");
        // The bundled sine's truth, 30 exact points: its differences are its shape.
        let sine: Vec<Point> = (0..30)
            .map(|i| {
                let x = 4.0 * std::f64::consts::PI * i as f64 / 29.0;
                Point::new(x, (0.5 * x).sin())
            })
            .collect();
        let sine_r = difference_correlation(&xy(&sine), false).unwrap();
        assert!(sine_r > 0.85, "{sine_r}");
        // With noise of 0.001 in y (a thirtieth of its noisy twin's), noise again.
        let e = gaussian(5, 30);
        let noisy: Vec<Point> = sine
            .iter()
            .zip(&e)
            .map(|(p, e)| Point::new(p.x, p.y + 1e-3 * e))
            .collect();
        let r = difference_correlation(&xy(&noisy), false).unwrap();
        assert!(r < 0.0, "{r}");
        // In space: a clean helix, and the same with noise.
        let helix: Vec<[f64; 3]> = (0..200)
            .map(|i| {
                let t = 0.06 * i as f64;
                [t.cos(), t.sin(), 0.15 * t]
            })
            .collect();
        let r = difference_correlation(&helix, false).unwrap();
        assert!(r > 0.85, "{r}");
        let ez = gaussian(6, 200);
        let noisy: Vec<[f64; 3]> = helix
            .iter()
            .enumerate()
            .map(|(i, p)| {
                [
                    p[0] + 1e-3 * ex[i],
                    p[1] + 1e-3 * ey[i],
                    p[2] + 1e-3 * ez[i],
                ]
            })
            .collect();
        assert!(difference_correlation(&noisy, false).unwrap() < 0.0);
        // The same at any scale (coordinates near the ends of the f64 range).
        for f in [1e-150, 1e150] {
            let scaled: Vec<[f64; 2]> = xy(&sine).iter().map(|p| [p[0] * f, p[1] * f]).collect();
            let r = difference_correlation(&scaled, false).unwrap();
            assert!((r - sine_r).abs() < 1e-9, "{r} against {sine_r} at {f}");
        }
        // Nothing to correlate: too few points, or a line.
        assert!(difference_correlation(&[[0.0, 0.0]; 3], false).is_none());
        let straight: Vec<[f64; 2]> = (0..20).map(|i| [i as f64, 2.0 * i as f64]).collect();
        assert!(difference_correlation(&straight, false).is_none());
    }

    #[test]
    fn recovers_noise_in_one_coordinate() {
        // A shallow sine sampled at 2000 points, closer than the noise (0.005 against 0.03),
        // with noise in y only: the estimate is within 10 % of the truth (a pooled MAD gives
        // about a third of it). The estimate is of the noise along the normal, so the sine is
        // shallow (slope at most 0.2), where the normal is nearly y.
        let sigma = 0.03;
        let e = gaussian(7, 2000);
        let pts: Vec<Point> = (0..2000)
            .map(|i| {
                let x = i as f64 * 0.005;
                Point::new(x, 0.2 * x.sin() + sigma * e[i])
            })
            .collect();
        let est = noise_sigma(&pts, false);
        assert!((est / sigma - 1.0).abs() < 0.1, "σ̂ = {est}");
    }

    /// The median's estimate alone, as σ̂ was taken before the clipped mean square.
    fn median_only(pts: &[[f64; 2]]) -> f64 {
        let (mut parts, gain) = NoiseMeasure::of(pts, false).off_tangent_parts().unwrap();
        MAD_TO_SIGMA * median(&mut parts) / gain
    }

    fn noisy_wave(n: usize, sigma: f64, seed: u64) -> Vec<[f64; 2]> {
        let (ex, ey) = (gaussian(seed, n), gaussian(seed + 1000, n));
        (0..n)
            .map(|i| {
                let x = 6.0 * i as f64 / (n - 1) as f64;
                [x + sigma * ex[i], x.sin() + sigma * ey[i]]
            })
            .collect()
    }

    /// Over 300 noise draws of 100 points the clipped mean square's `ln(σ̂/σ)` spreads less
    /// than the median's (here 0.128 against 0.177; at 100 points on the quality benchmark
    /// 0.12 against 0.15), and neither is biased by more than 3 %.
    #[test]
    fn the_clipped_mean_square_is_tighter_than_the_median() {
        let sigma = 0.01;
        let (mut clipped, mut med) = (Vec::new(), Vec::new());
        for seed in 0..300 {
            let pts = noisy_wave(100, sigma, seed);
            let xy: Vec<Point> = pts.iter().map(|p| Point::new(p[0], p[1])).collect();
            clipped.push((noise_sigma(&xy, false) / sigma).ln());
            med.push((median_only(&pts) / sigma).ln());
        }
        let stats = |v: &[f64]| {
            let m = v.iter().sum::<f64>() / v.len() as f64;
            let sd = (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / v.len() as f64).sqrt();
            (m, sd)
        };
        let ((mc, sc), (mm, sm)) = (stats(&clipped), stats(&med));
        assert!(sc < 0.85 * sm, "spread {sc} against the median's {sm}");
        assert!(mc.abs() < 0.03 && mm.abs() < 0.03, "bias {mc}, {mm}");
    }

    /// A few points far off (a spike of 50σ at 4 of 400 points) leave the estimate where the
    /// noise puts it: their differences lie beyond 3σ̂ and are clipped, as the median ignores
    /// them (σ̂ = 1.01σ); a plain mean square gives 4.4σ.
    #[test]
    fn outlying_differences_are_clipped() {
        let sigma = 0.01;
        let mut pts = noisy_wave(400, sigma, 5);
        for i in [50, 150, 250, 350] {
            pts[i][1] += 50.0 * sigma;
        }
        let xy: Vec<Point> = pts.iter().map(|p| Point::new(p[0], p[1])).collect();
        let est = noise_sigma(&xy, false);
        assert!((est / sigma - 1.0).abs() < 0.15, "σ̂ = {est}");
        let (parts, gain) = NoiseMeasure::of(&pts, false).off_tangent_parts().unwrap();
        let rms = (parts.iter().map(|v| v * v).sum::<f64>() / parts.len() as f64).sqrt() / gain;
        assert!(rms > 2.0 * sigma, "plain mean square {rms}");
    }

    #[test]
    fn isotropic_noise_on_a_closed_circle() {
        let sigma = 1e-3;
        let (ex, ey) = (gaussian(1, 3000), gaussian(2, 3000));
        let pts: Vec<Point> = (0..3000)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / 3000.0;
                Point::new(a.cos() + sigma * ex[i], a.sin() + sigma * ey[i])
            })
            .collect();
        let est = noise_sigma(&pts, true);
        assert!((est / sigma - 1.0).abs() < 0.1, "σ̂ = {est}");
    }

    #[test]
    fn the_estimates_do_not_depend_on_the_thread_count() {
        // Past the parallel threshold, and not a whole number of correlation chunks.
        let n = 2 * PARALLEL_FROM + 17;
        let e = gaussian(5, 2 * n);
        let pts: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let a = i as f64 * 6.0 / n as f64;
                [a.cos() + 1e-4 * e[2 * i], a.sin() + 1e-4 * e[2 * i + 1]]
            })
            .collect();
        for closed in [false, true] {
            let estimate = || {
                let m = NoiseMeasure::of(&pts, closed);
                (m.sigma(Spread::OneD), m.correlation())
            };
            let on = |threads: usize| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap()
                    .install(estimate)
            };
            let (one, three) = (on(1), on(3));
            assert_eq!(one, three);
            // The correlation as its definition reads, one sum after the other.
            let m = NoiseMeasure::of(&pts, closed);
            let diffs = m.diffs.as_ref().unwrap();
            let parts: Vec<[f64; 2]> = (0..diffs.differences.len())
                .map(|i| {
                    let c = diffs.chord(&pts, closed, i);
                    let u = [c[0] / c[0].hypot(c[1]), c[1] / c[0].hypot(c[1])];
                    let d = diffs.differences[i];
                    let along = d[0] * u[0] + d[1] * u[1];
                    [d[0] - along * u[0], d[1] - along * u[1]]
                })
                .collect();
            let dot = |a: &[f64; 2], b: &[f64; 2]| a[0] * b[0] + a[1] * b[1];
            let count = parts.len();
            let pairs = if closed { count } else { count - 1 };
            let lagged: f64 = (0..pairs)
                .map(|i| dot(&parts[i], &parts[(i + 1) % count]))
                .sum();
            let total: f64 = parts.iter().map(|p| dot(p, p)).sum();
            let r = one.1.unwrap();
            assert!(
                (r - lagged / total).abs() < 1e-12,
                "{r} vs {}",
                lagged / total
            );
            assert!(r < -0.5, "{r}");
        }
    }

    #[test]
    fn scales_with_the_data_and_ignores_rigid_motion() {
        let e = gaussian(3, 500);
        let pts: Vec<Point> = (0..500)
            .map(|i| Point::new(i as f64 * 0.01, (i as f64 * 0.01).cos() + 0.01 * e[i]))
            .collect();
        let base = noise_sigma(&pts, false);
        let (c, s) = (0.6_f64, 0.8_f64);
        let moved: Vec<Point> = pts
            .iter()
            .map(|p| {
                Point::new(
                    1e3 * (c * p.x - s * p.y) + 5.0,
                    1e3 * (s * p.x + c * p.y) - 2.0,
                )
            })
            .collect();
        let est = noise_sigma(&moved, false);
        assert!(
            (est / (1e3 * base) - 1.0).abs() < 1e-6,
            "{est} vs {}",
            1e3 * base
        );
    }

    /// A helix with Gaussian noise of σ per coordinate, open and closed (a torus knot).
    fn noisy_space_curve(sigma: f64, closed: bool) -> Vec<[f64; 3]> {
        let n = 3000;
        let (ex, ey, ez) = (gaussian(21, n), gaussian(22, n), gaussian(23, n));
        (0..n)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / n as f64;
                let p = if closed {
                    let r = 2.0 + (3.0 * t).cos();
                    [r * (2.0 * t).cos(), r * (2.0 * t).sin(), (3.0 * t).sin()]
                } else {
                    [(4.0 * t).cos(), (4.0 * t).sin(), 0.5 * t]
                };
                [
                    p[0] + sigma * ex[i],
                    p[1] + sigma * ey[i],
                    p[2] + sigma * ez[i],
                ]
            })
            .collect()
    }

    #[test]
    fn recovers_isotropic_noise_in_space() {
        for closed in [false, true] {
            let sigma = 2e-3;
            let est = noise_sigma_space(&noisy_space_curve(sigma, closed), closed);
            assert!(
                (est / sigma - 1.0).abs() < 0.15,
                "closed {closed}: σ̂ = {est}"
            );
        }
        // Exact samples: far below any noise.
        assert!(noise_sigma_space(&noisy_space_curve(0.0, false), false) < 1e-9);
    }

    #[test]
    fn a_planar_curve_in_space_gives_the_planar_estimate() {
        let e = gaussian(5, 800);
        let pts: Vec<Point> = (0..800)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / 800.0;
                Point::new(
                    3.0 * a.cos() + 0.01 * e[i],
                    a.sin() + 0.01 * e[(i + 400) % 800],
                )
            })
            .collect();
        let planar = noise_sigma(&pts, true);
        let flat: Vec<[f64; 3]> = pts.iter().map(|p| [p.x, p.y, 0.0]).collect();
        assert_eq!(noise_sigma_space(&flat, true), planar);
        // The same curve in a tilted plane, moved: to rounding.
        let (c, s) = (0.6_f64, 0.8_f64);
        let tilted: Vec<[f64; 3]> = pts
            .iter()
            .map(|p| [p.x + 1.0, c * p.y + 2.0, s * p.y - 3.0])
            .collect();
        let est = noise_sigma_space(&tilted, true);
        assert!((est / planar - 1.0).abs() < 1e-9, "{est} vs {planar}");
    }

    #[test]
    fn too_few_points() {
        let pts = [
            Point::new(0.0, 0.0),
            Point::new(1.0, 0.0),
            Point::new(2.0, 1.0),
        ];
        assert_eq!(noise_sigma(&pts, false), 0.0);
    }
}
