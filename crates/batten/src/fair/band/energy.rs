//! The fairness energy of `band`: third divided differences of the points at chord-length
//! parameters, summed over windows of four consecutive points.
//!
//! For a window `q_j … q_{j+3}` at parameters `t_j … t_{j+3}` the third divided difference is
//! `Δ_j = Σ_k c_k q_{j+k}` with `c_k = 1 / Π_{m≠k} (t_{j+k} − t_{j+m})`, an estimate of
//! `C'''/6` on the window, and the energy is
//!
//! ```text
//! E(q) = Σ_j w_j Δ_jᵀ M_j Δ_j,      w_j = t_{j+3} − t_j,
//! ```
//!
//! a quadrature of `∫ |C'''|² ds / 36`. With the *jerk* metric `M_j = I`, it is the discrete
//! jerk energy `≈ ∫ κ'² + κ⁴ ds` for an arc-length curve. The *minimum-variation* metric
//! (Moreton & Séquin) `M_j = P_j + ε I`, `P_j = I − τ_j τ_jᵀ` the projection across the unit
//! chord `τ_j` of the window on a previous iterate, weighs the component of `C'''` off the
//! tangent, which is `κ'` along the normal (and `κτ` along the binormal in 3-D): the
//! variation of curvature, with `ε` of the jerk kept for regularity.
//!
//! Parameters are in units of the mean spacing, so the weights and coefficients are O(1)
//! whatever the data's scale. Closed curves take their windows cyclically, with the period
//! added to the parameters that wrap.

use super::spline::Span;
use crate::numeric::map_indices;

/// The shortest parameter step, relative to the mean chord: points of an iterate that (nearly)
/// coincide would give divided differences of unbounded size.
pub(super) const CHORD_FLOOR_REL: f64 = 0.1;

/// One window of four consecutive points.
#[derive(Clone, Copy, Debug)]
pub(super) struct Window<const D: usize> {
    /// Index of the first point (the window is `first … first + 3`, modulo n when closed).
    pub first: usize,
    /// The divided-difference coefficients `c_k`.
    pub coef: [f64; 4],
    /// `w_j · M_j`.
    pub metric: [[f64; D]; D],
}

/// Which metric the windows carry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Metric {
    /// `M = I`: the jerk energy.
    Jerk,
    /// `M = (I − ττᵀ) + ε I`, with `τ` from the previous iterate.
    MinVariation {
        /// Weight of the full jerk added for regularity.
        eps: f64,
        /// Weight of the speed term: the tangential component of the second divided
        /// difference, `v'` for a curve at speed `v` (0: none).
        speed: f64,
    },
}

/// The quadratic energy `E(x) = Σ_j w_j Δ_jᵀ M_j Δ_j` over flat coordinates
/// `x = [q_0, q_1, …]` (`D` numbers a point).
#[derive(Clone, Debug)]
pub(super) struct Energy<const D: usize> {
    /// Number of points.
    pub n: usize,
    /// Whether windows wrap around.
    pub closed: bool,
    /// The windows, in order.
    pub windows: Vec<Window<D>>,
}

/// The four consecutive indices from `first`, modulo `n` (cyclic windows and knot spans),
/// taken once for a window rather than once per entry: an integer division each, skipped
/// where nothing wraps.
pub(super) fn four_from(first: usize, n: usize) -> [usize; 4] {
    if first + 4 <= n {
        std::array::from_fn(|k| first + k)
    } else {
        std::array::from_fn(|k| (first + k) % n)
    }
}

/// The chord lengths of `shape`, cyclic when closed.
pub(super) fn chords_of<const D: usize>(shape: &[[f64; D]], closed: bool) -> Vec<f64> {
    let n = shape.len();
    map_indices(if closed { n } else { n - 1 }, |i| {
        super::distance(&shape[i], &shape[crate::geom::next_index(i, n)])
    })
}

/// The parameters of steps `chords`: their running sums from 0, in units of the mean step,
/// each step at least [`CHORD_FLOOR_REL`] of the mean (`chords.len() + 1` values; the last is
/// a closed curve's period).
pub(super) fn parameters(chords: &[f64]) -> Vec<f64> {
    let mean = chords.iter().sum::<f64>() / chords.len() as f64;
    let floor = CHORD_FLOOR_REL * mean;
    let mut t = Vec::with_capacity(chords.len() + 1);
    t.push(0.0);
    let mut acc = 0.0;
    for c in chords {
        acc += c.max(floor) / mean;
        t.push(acc);
    }
    t
}

/// The divided-difference coefficients at parameters `ts`: `c_k = 1 / Π_{m≠k} (t_k − t_m)`.
fn divided_difference<const K: usize>(ts: [f64; K]) -> [f64; K] {
    let mut coef = [0.0; K];
    for (k, c) in coef.iter_mut().enumerate() {
        let mut prod = 1.0;
        for (m, tm) in ts.iter().enumerate() {
            if m != k {
                prod *= ts[k] - tm;
            }
        }
        *c = 1.0 / prod;
    }
    coef
}

/// The unit vector from `a` to `b` (zero when they coincide).
fn unit_chord<const D: usize>(a: &[f64; D], b: &[f64; D]) -> [f64; D] {
    let len = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt();
    let mut tau = [0.0; D];
    if len > 0.0 {
        for (t, (x, y)) in tau.iter_mut().zip(a.iter().zip(b)) {
            *t = (y - x) / len;
        }
    }
    tau
}

/// `w · M` for a window whose tangent is the chord from `a` to `b`.
fn window_metric<const D: usize>(
    metric: Metric,
    w: f64,
    a: &[f64; D],
    b: &[f64; D],
) -> [[f64; D]; D] {
    let mut m = [[0.0; D]; D];
    match metric {
        Metric::Jerk => {
            for (k, row) in m.iter_mut().enumerate() {
                row[k] = w;
            }
        }
        Metric::MinVariation { eps, .. } => {
            let tau = unit_chord(a, b);
            for k in 0..D {
                for l in 0..D {
                    let id = if k == l { 1.0 } else { 0.0 };
                    m[k][l] = w * (id - tau[k] * tau[l] + eps * id);
                }
            }
        }
    }
    m
}

/// The speed term of the minimum-variation metric: for every three consecutive points, the
/// second divided difference `Δ²_j` (`≈ C''/2`) weighed across nothing but the unit chord
/// `τ_j = (q_{j+2} − q_j)/|…|` of `shape`, `w_j · speed · (τ_jᵀ Δ²_j)²`. For a curve at speed
/// `v` that is `v'²/4`: zero at arc-length parameters, whatever the curvature. Without it the
/// metric, blind along the tangent, lets points crowd where the curvature peaks, since there
/// the normal jerk `3vv'κ + v³κ'` costs `v³` less (an airfoil's nose doubled its curvature).
/// Each is stored as a window of four points with one coefficient zero (the last window of
/// an open curve reaches back one point), so the energy keeps its band.
fn speed_windows<const D: usize>(
    n: usize,
    closed: bool,
    param: &impl Fn(usize) -> f64,
    shape: &[[f64; D]],
    speed: f64,
) -> Vec<Window<D>> {
    let count = if closed { n } else { n - 2 };
    (0..count)
        .map(|j| {
            let ts = [param(j), param(j + 1), param(j + 2)];
            let c = divided_difference(ts);
            let tau = unit_chord(&shape[j % n], &shape[(j + 2) % n]);
            let w = speed * (ts[2] - ts[0]);
            let mut metric = [[0.0; D]; D];
            for a in 0..D {
                for b in 0..D {
                    metric[a][b] = w * tau[a] * tau[b];
                }
            }
            let (first, coef) = if closed || j + 3 < n {
                (j, [c[0], c[1], c[2], 0.0])
            } else {
                (j - 1, [0.0, c[0], c[1], c[2]])
            };
            Window {
                first,
                coef,
                metric,
            }
        })
        .collect()
}

/// The speed term of the spline form: `speed·½ ∫ (τᵀC'')² dt` over every knot span (the
/// point form's `w_j·speed·(τ_jᵀΔ²_j)²` summed over the points, `Δ² ≈ C''/2` and two spacings
/// a window), `τ` the unit chord of the span's control polygon. `C''` is linear on a span, so
/// two Gauss points integrate the square exactly: two windows a span, each `C''` at its point
/// weighed by `len/2 · ½`. `scale` is the energy's unit times `speed`.
fn spline_speed_windows<const D: usize>(
    ctrl: &[[f64; D]],
    spans: &[Span],
    scale: f64,
) -> Vec<Window<D>> {
    let n = ctrl.len();
    let offset = 0.5 / 3.0_f64.sqrt();
    let mut out = Vec::with_capacity(2 * spans.len());
    for span in spans {
        let tau = unit_chord(&ctrl[span.first], &ctrl[(span.first + 3) % n]);
        let w = scale * span.len * 0.25;
        let mut metric = [[0.0; D]; D];
        for a in 0..D {
            for b in 0..D {
                metric[a][b] = w * tau[a] * tau[b];
            }
        }
        for lambda in [0.5 - offset, 0.5 + offset] {
            let [s, e] = span.second;
            out.push(Window {
                first: span.first,
                coef: std::array::from_fn(|k| (1.0 - lambda) * s[k] + lambda * e[k]),
                metric,
            });
        }
    }
    out
}

impl<const D: usize> Energy<D> {
    /// The energy at the chord-length parameters of `shape` (the current iterate), with the
    /// metric's tangents from `shape` too. `shape` has at least four points and no two
    /// consecutive ones equal (validated input, or a result inside its tolerance band of it,
    /// which the caller checks).
    #[cfg(test)]
    pub(super) fn build(shape: &[[f64; D]], closed: bool, metric: Metric) -> Energy<D> {
        Self::build_with_chords(&chords_of(shape, closed), shape, closed, metric)
    }

    /// The energy with parameter steps `chords` (`n − 1` of them, `n` when closed; any
    /// positive scale) and the metric's tangents from `shape`.
    pub(super) fn build_with_chords(
        chords: &[f64],
        shape: &[[f64; D]],
        closed: bool,
        metric: Metric,
    ) -> Energy<D> {
        let n = shape.len();
        let t = parameters(chords);
        let period = if closed { t[chords.len()] } else { 0.0 };
        let param = |i: usize| -> f64 { if i >= n { t[i - n] + period } else { t[i] } };
        let count = if closed { n } else { n - 3 };
        let mut windows: Vec<Window<D>> = (0..count)
            .map(|j| {
                let ts = [param(j), param(j + 1), param(j + 2), param(j + 3)];
                let coef = divided_difference(ts);
                let w = ts[3] - ts[0];
                Window {
                    first: j,
                    coef,
                    metric: window_metric(metric, w, &shape[j], &shape[(j + 3) % n]),
                }
            })
            .collect();
        if let Metric::MinVariation { speed, .. } = metric
            && speed > 0.0
        {
            windows.extend(speed_windows(n, closed, &param, shape, speed));
        }
        Energy { n, closed, windows }
    }

    /// The energy of a cubic B-spline with control points `ctrl` (`≈ ∫ |C'''|² dt / 12`, as
    /// the point form: its windows overlap three times). `spans` gives, for each knot span,
    /// its first control point, the coefficients of `C'''/6` on its four control points and
    /// its length; the metric's tangent on a span is the chord from its first to its last
    /// control point. The whole is multiplied by `unit`.
    pub(super) fn spline(
        ctrl: &[[f64; D]],
        closed: bool,
        spans: &[Span],
        unit: f64,
        metric: Metric,
    ) -> Energy<D> {
        let n = ctrl.len();
        let mut windows: Vec<Window<D>> = spans
            .iter()
            .map(|span| Window {
                first: span.first,
                coef: span.third,
                metric: window_metric(
                    metric,
                    3.0 * span.len * unit,
                    &ctrl[span.first],
                    &ctrl[(span.first + 3) % n],
                ),
            })
            .collect();
        if let Metric::MinVariation { speed, .. } = metric
            && speed > 0.0
        {
            windows.extend(spline_speed_windows(ctrl, spans, unit * speed));
        }
        Energy { n, closed, windows }
    }

    /// The third divided difference of window `w` of `x`.
    #[inline]
    fn delta(&self, w: &Window<D>, x: &[f64]) -> [f64; D] {
        let mut d = [0.0; D];
        if w.first + 4 <= self.n {
            // No wrap: the window's points are one slice (no index taken modulo n, whose
            // integer division was most of a dense run's products with `A`).
            let x = &x[w.first * D..(w.first + 4) * D];
            for (k, c) in w.coef.iter().enumerate() {
                for a in 0..D {
                    d[a] += c * x[k * D + a];
                }
            }
            return d;
        }
        for (k, c) in w.coef.iter().enumerate() {
            let i = (w.first + k) % self.n;
            for a in 0..D {
                d[a] += c * x[i * D + a];
            }
        }
        d
    }

    /// `E(x)`.
    pub(super) fn value(&self, x: &[f64]) -> f64 {
        self.windows
            .iter()
            .map(|w| {
                let d = self.delta(w, x);
                let mut s = 0.0;
                for a in 0..D {
                    for b in 0..D {
                        s += d[a] * w.metric[a][b] * d[b];
                    }
                }
                s
            })
            .sum()
    }

    /// `out += A x`, with `A` the symmetric matrix of `E(x) = xᵀ A x`.
    pub(super) fn apply_add(&self, x: &[f64], out: &mut [f64]) {
        for w in &self.windows {
            let d = self.delta(w, x);
            let mut md = [0.0; D];
            for a in 0..D {
                for b in 0..D {
                    md[a] += w.metric[a][b] * d[b];
                }
            }
            if w.first + 4 <= self.n {
                let out = &mut out[w.first * D..(w.first + 4) * D];
                for (k, c) in w.coef.iter().enumerate() {
                    for a in 0..D {
                        out[k * D + a] += c * md[a];
                    }
                }
                continue;
            }
            for (k, c) in w.coef.iter().enumerate() {
                let i = (w.first + k) % self.n;
                for a in 0..D {
                    out[i * D + a] += c * md[a];
                }
            }
        }
    }

    /// Call `add(row, col, value)` for every entry of `scale · A` with `row ≥ col` in the
    /// (non-cyclic) flat numbering; entries of closed curves that wrap come with the larger
    /// index first as well. Entries at the same position are reported once per window.
    pub(super) fn for_each_lower(&self, scale: f64, mut add: impl FnMut(usize, usize, f64)) {
        for w in &self.windows {
            let at = four_from(w.first, self.n);
            for (k, &i) in at.iter().enumerate() {
                for (l, &j) in at.iter().enumerate() {
                    let cc = scale * w.coef[k] * w.coef[l];
                    for a in 0..D {
                        for b in 0..D {
                            let (r, c) = (i * D + a, j * D + b);
                            if r >= c {
                                add(r, c, cc * w.metric[a][b]);
                            }
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn sample(n: usize, f: impl Fn(f64) -> [f64; 2]) -> Vec<[f64; 2]> {
        (0..n).map(|i| f(i as f64 / (n - 1) as f64)).collect()
    }

    #[test]
    fn jerk_of_a_line_and_a_parabola_is_zero() {
        // Points on a parabola at unequal spacing: third divided differences vanish (the
        // parameters are chord lengths, so only the x(t), y(t) that are quadratic in t vanish
        // exactly: use a straight line, whose coordinates are linear in arc length).
        let line = sample(9, |s| [1.0 + 3.0 * s * s, 2.0 - 4.0 * s * s]);
        let e = Energy::build(&line, false, Metric::Jerk);
        let x: Vec<f64> = line.iter().flatten().copied().collect();
        assert!(e.value(&x) < 1e-20, "{}", e.value(&x));
    }

    #[test]
    fn divided_differences_of_a_cubic_are_its_leading_coefficient() {
        // x = 5t³ at parameters t (the energy's own): Δ = 5 on every window.
        let pts = sample(7, |s| [s, s * s]);
        let e = Energy::build(&pts, false, Metric::Jerk);
        // Reconstruct the parameters from the coefficients: evaluate Δ on t³ directly.
        for w in &e.windows {
            let ts: Vec<f64> = {
                // Recover t from the coefficient formula by evaluating Δ on 1, t, t², t³ with
                // the chord parameters of the same points.
                let chords: Vec<f64> = (0..6)
                    .map(|i| {
                        let (a, b) = (pts[i], pts[i + 1]);
                        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
                    })
                    .collect();
                let mean = chords.iter().sum::<f64>() / 6.0;
                let mut t = vec![0.0];
                for c in &chords {
                    t.push(t.last().unwrap() + c / mean);
                }
                t
            };
            let f = |p: u32| -> f64 {
                (0..4)
                    .map(|k| w.coef[k] * 5.0 * ts[w.first + k].powi(p as i32))
                    .sum()
            };
            assert!(f(0).abs() < 1e-9 && f(1).abs() < 1e-9 && f(2).abs() < 1e-9);
            assert!((f(3) - 5.0).abs() < 1e-9, "{}", f(3));
        }
    }

    #[test]
    fn apply_matches_the_quadratic_form_and_the_lower_entries() {
        for closed in [false, true] {
            let pts = sample(11, |s| [(3.0 * s).cos() + 0.1 * s, (2.0 * s).sin()]);
            let e = Energy::build(
                &pts,
                closed,
                Metric::MinVariation {
                    eps: 0.05,
                    speed: 0.3,
                },
            );
            let n2 = 22;
            let mut dense = vec![vec![0.0; n2]; n2];
            e.for_each_lower(1.0, |r, c, v| {
                dense[r][c] += v;
                if r != c {
                    dense[c][r] += v;
                }
            });
            let x: Vec<f64> = (0..n2).map(|i| (i as f64 * 0.37).sin()).collect();
            let mut ax = vec![0.0; n2];
            e.apply_add(&x, &mut ax);
            let quad: f64 = (0..n2).map(|i| x[i] * ax[i]).sum();
            assert!((quad - e.value(&x)).abs() < 1e-9 * e.value(&x).abs().max(1.0));
            for i in 0..n2 {
                let d: f64 = (0..n2).map(|j| dense[i][j] * x[j]).sum();
                assert!(
                    (d - ax[i]).abs() < 1e-9 * ax[i].abs().max(1.0),
                    "{closed} {i}"
                );
            }
        }
    }
}
