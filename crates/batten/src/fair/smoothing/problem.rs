//! One smoothing problem: its data, the system for a given p, its solution, GCV's trace
//! and the least-squares line of p = 0.
use super::{Fit, Penta, TERMS_CACHE_BYTES, alpha_of, by_coordinate, dot};
use crate::error::{Error, Result};
use crate::numeric::{CyclicSymBanded, SymBanded, factorize_with_inverse_band};

/// The data of one smoothing problem, validated, with what every trial shares.
pub(super) struct Problem<'a, const D: usize> {
    pub(super) t: &'a [f64],
    pub(super) y: &'a [[f64; D]],
    pub(super) closed: bool,
    /// `W⁻¹_ii` (0 for a pinned point); `None` for unit weights.
    pub(super) dinv: Option<Vec<f64>>,
    /// Reciprocal span lengths `1/h_k`: n − 1 (open) or n (closed).
    pub(super) ih: Vec<f64>,
    /// [`KnotTerms`] of every unknown, for the searches, which solve many times (empty for
    /// one solve: they are then made as the matrix is assembled).
    pub(super) terms: Vec<KnotTerms<D>>,
}

/// What row `j` of the system takes from the data, whatever p: `Qᵀ y` and the parts of the
/// entries of `a R + b Qᵀ W⁻¹ Q` (see [`KnotTerms::entries`]). Computed once per search
/// instead of once per trial.
#[derive(Clone, Copy, Debug)]
pub(super) struct KnotTerms<const D: usize> {
    /// `(Qᵀ y)` at the knot.
    pub(super) qty: [f64; D],
    /// `h_{k−1} + h_k`.
    pub(super) span_sum: f64,
    /// `h_k`.
    pub(super) span: f64,
    /// `1/h_k`.
    pub(super) ih: f64,
    /// `1/h_{k+1}` (0 when span k+1 does not exist).
    pub(super) ih_next: f64,
    /// `W⁻¹` at knot k + 1.
    pub(super) d_next: f64,
    /// The diagonal's data part, `W⁻¹_{k−1}/h²_{k−1} + W⁻¹_k (1/h_{k−1} + 1/h_k)² + W⁻¹_{k+1}/h²_k`.
    pub(super) data_diag: f64,
    /// The first off-diagonal's data part over `1/h_k`.
    pub(super) data_next: f64,
}

impl<const D: usize> KnotTerms<D> {
    /// The entries `(k,k)`, `(k,k+1)`, `(k,k+2)` of `a R + b Qᵀ W⁻¹ Q`, in the order of
    /// operations they have always been computed in (so the same bits).
    #[inline]
    pub(super) fn entries(&self, a: f64, b: f64) -> [f64; 3] {
        let d0 = a * self.span_sum / 3.0 + b * self.data_diag;
        let d1 = a * self.span / 6.0 - b * self.ih * self.data_next;
        let d2 = b * self.d_next * self.ih * self.ih_next;
        [d0, d1, d2]
    }
}

impl<'a, const D: usize> Problem<'a, D> {
    pub(super) fn new(
        t: &'a [f64],
        y: &'a [[f64; D]],
        weights: Option<&[f64]>,
        closed: bool,
    ) -> Result<Problem<'a, D>> {
        let n = y.len();
        let min = if closed { 3 } else { 2 };
        if n < min {
            return Err(Error::TooFewPoints {
                needed: min,
                got: n,
            });
        }
        let nt = if closed { n + 1 } else { n };
        if t.len() != nt {
            return Err(Error::LengthMismatch {
                what: "parameters",
                got: t.len(),
                expected: nt,
            });
        }
        if let Some(index) = t.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite { index });
        }
        if let Some(i) = t.windows(2).position(|w| w[1] <= w[0]) {
            return Err(Error::NotIncreasing { index: i + 1 });
        }
        if let Some(index) = y.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(Error::NonFinite { index });
        }
        let dinv = match weights {
            None => None,
            Some(w) => {
                if w.len() != n {
                    return Err(Error::LengthMismatch {
                        what: "weights",
                        got: w.len(),
                        expected: n,
                    });
                }
                if let Some(i) = w.iter().position(|&v| v.is_nan() || v <= 0.0) {
                    return Err(Error::InvalidParameter {
                        name: "weights".into(),
                        reason: format!("weight {i} is {}, must be positive", w[i]),
                    });
                }
                Some(w.iter().map(|&v| 1.0 / v).collect())
            }
        };
        let ih: Vec<f64> = t.windows(2).map(|w| 1.0 / (w[1] - w[0])).collect();
        Ok(Problem {
            t,
            y,
            closed,
            dinv,
            ih,
            terms: Vec::new(),
        })
    }

    /// The problem with the [`KnotTerms`] of every unknown kept, for a search, when they
    /// take at most [`TERMS_CACHE_BYTES`] (larger curves make them as each trial assembles
    /// its matrix: the same numbers, without the memory).
    pub(super) fn with_terms(mut self) -> Self {
        if self.m() * std::mem::size_of::<KnotTerms<D>>() <= TERMS_CACHE_BYTES {
            self.terms = (0..self.m()).map(|j| self.knot_terms(j)).collect();
        }
        self
    }

    /// The [`KnotTerms`] of unknown `j`: kept, or made now.
    #[inline]
    pub(super) fn terms_of(&self, j: usize) -> KnotTerms<D> {
        self.terms
            .get(j)
            .copied()
            .unwrap_or_else(|| self.knot_terms(j))
    }

    /// The [`KnotTerms`] of unknown `j` from the data.
    pub(super) fn knot_terms(&self, j: usize) -> KnotTerms<D> {
        let k = self.knot(j);
        let (km, kp) = (self.prev(k), self.next(k));
        let (ihm, ihp) = (self.ih[km], self.ih[k]);
        let s = ihm + ihp;
        let (dm, d, dp) = (self.d(km), self.d(k), self.d(kp));
        // Span k+1 exists whenever knot k+1 is an unknown.
        let ihpp = if self.closed || kp < self.n() - 1 {
            self.ih[kp]
        } else {
            0.0
        };
        KnotTerms {
            qty: self.qty(k),
            span_sum: self.span(km) + self.span(k),
            span: self.span(k),
            ih: ihp,
            ih_next: ihpp,
            d_next: dp,
            data_diag: dm * ihm * ihm + d * s * s + dp * ihp * ihp,
            data_next: d * s + dp * (ihp + ihpp),
        }
    }

    /// `W⁻¹_ii`.
    #[inline]
    pub(super) fn d(&self, i: usize) -> f64 {
        self.dinv.as_ref().map_or(1.0, |d| d[i])
    }

    /// The length of span k, `h_k = t_{k+1} − t_k`.
    #[inline]
    pub(super) fn span(&self, k: usize) -> f64 {
        self.t[k + 1] - self.t[k]
    }

    /// `(Qᵀ y)` at knot k: the jump of the divided differences.
    #[inline]
    pub(super) fn qty(&self, k: usize) -> [f64; D] {
        let (km, kp) = (self.prev(k), self.next(k));
        let (y, ih) = (self.y, &self.ih);
        std::array::from_fn(|a| (y[kp][a] - y[k][a]) * ih[k] - (y[k][a] - y[km][a]) * ih[km])
    }

    pub(super) fn n(&self) -> usize {
        self.y.len()
    }

    /// Number of unknowns (second derivatives not fixed by the end conditions).
    pub(super) fn m(&self) -> usize {
        if self.closed { self.n() } else { self.n() - 2 }
    }

    /// The knot of unknown `j`.
    #[inline]
    pub(super) fn knot(&self, j: usize) -> usize {
        if self.closed { j } else { j + 1 }
    }

    /// The knot (and span) before knot `k` (cyclically when closed). Only called for `k ≥ 1`
    /// on open curves.
    #[inline]
    pub(super) fn prev(&self, k: usize) -> usize {
        if k == 0 { self.n() - 1 } else { k - 1 }
    }

    /// The knot after knot `k` (cyclically when closed).
    #[inline]
    pub(super) fn next(&self, k: usize) -> usize {
        if k + 1 == self.n() { 0 } else { k + 1 }
    }

    /// `tr R / tr(Qᵀ W⁻¹ Q)`: csaps's default α and the centre of the searches.
    pub(super) fn alpha_ref(&self) -> Result<f64> {
        let (mut tr_r, mut tr_n) = (0.0, 0.0);
        for j in 0..self.m() {
            let k = self.knot(j);
            let (km, kp) = (self.prev(k), self.next(k));
            tr_r += (self.span(km) + self.span(k)) / 3.0;
            let s = self.ih[km] + self.ih[k];
            tr_n += self.d(km) * self.ih[km] * self.ih[km]
                + self.d(k) * s * s
                + self.d(kp) * self.ih[k] * self.ih[k];
        }
        let alpha = tr_r / tr_n;
        if alpha.is_finite() && alpha > 0.0 {
            Ok(alpha)
        } else {
            Err(Error::Degenerate(
                "no roughness/data balance: every point is pinned or there are no interior knots"
                    .into(),
            ))
        }
    }

    /// Solve for `p ∈ [0, 1]` (p = 0 by the least-squares line on open curves).
    pub(super) fn fit_p(&self, p: f64) -> Result<Fit<D>> {
        if p == 0.0 {
            self.fit_line()
        } else {
            self.solve(p, 1.0 - p, alpha_of(p), false)
        }
    }

    /// Solve for `α` given on a log scale, `α = α_ref · e^s`.
    pub(super) fn fit_log_alpha(&self, alpha_ref: f64, s: f64, gcv: bool) -> Result<Fit<D>> {
        let alpha = alpha_ref * s.exp();
        self.solve(1.0 / (1.0 + alpha), alpha / (1.0 + alpha), alpha, gcv)
    }

    /// The spline for the scaled system `(a R + b Qᵀ W⁻¹ Q) u = Qᵀ y` (`a = p`, `b = 1 − p`,
    /// `alpha = b/a` computed by the caller without rounding p);
    /// with `gcv`, also RSS and `tr(I − A)`.
    pub(super) fn solve(&self, a: f64, b: f64, alpha: f64, gcv: bool) -> Result<Fit<D>> {
        let (n, m) = (self.n(), self.m());
        // u at every knot; the open ends stay 0 (natural end conditions).
        let mut u = vec![[0.0; D]; n];
        let mut trace_residual = 0.0;
        if self.closed {
            let mut mat = CyclicSymBanded::zeros(m, 2);
            for (k, uk) in u.iter_mut().enumerate() {
                let terms = self.terms_of(k);
                *uk = terms.qty;
                let [d0, d1, d2] = terms.entries(a, b);
                mat.add(k, k, d0);
                mat.add(k, (k + 1) % m, d1);
                mat.add(k, (k + 2) % m, d2);
            }
            if gcv {
                let inv = mat.factorize_with_inverse()?;
                trace_residual = b * self.trace_term(|i, j| inv.get(i, j));
            } else {
                mat.factorize()?;
            }
            by_coordinate(&mut u, |c| mat.solve_in_place(c))?;
        } else if gcv {
            let mut mat = SymBanded::zeros(m, 2);
            for j in 0..m {
                let terms = self.terms_of(j);
                u[j + 1] = terms.qty;
                let [d0, d1, d2] = terms.entries(a, b);
                mat.add(j, j, d0);
                if j + 1 < m {
                    mat.add(j + 1, j, d1);
                }
                if j + 2 < m {
                    mat.add(j + 2, j, d2);
                }
            }
            let inv = factorize_with_inverse_band(&mut mat)?;
            trace_residual = b * self.trace_term(|i, j| inv.get(i - 1, j - 1));
            by_coordinate(&mut u[1..n - 1], |c| mat.solve_in_place(c))?;
        } else {
            // The same entries and operations as the band code above, written out for
            // half-bandwidth 2 (see `system.rs`).
            let row = |terms: &KnotTerms<D>, uj: &mut [f64; D]| {
                *uj = terms.qty;
                terms.entries(a, b)
            };
            let interior = u[1..n - 1].iter_mut();
            let mut mat = if self.terms.is_empty() {
                Penta::from_columns(
                    interior
                        .enumerate()
                        .map(|(j, uj)| row(&self.knot_terms(j), uj)),
                )
            } else {
                Penta::from_columns(self.terms.iter().zip(interior).map(|(t, uj)| row(t, uj)))
            };
            mat.factorize()?;
            mat.solve_in_place(&mut u[1..n - 1]);
        }
        // g_i = y_i − b D_i (Qu)_i, subtracted in place from a copy of the data (no growing
        // vector: pushing cost a capacity check and more a value).
        let mut values = self.y.to_vec();
        let mut rss = 0.0;
        let subtract = |i: usize, qu: [f64; D]| {
            let di = self.d(i);
            let g = &mut values[i];
            for c in 0..D {
                g[c] -= qu[c] * (b * di);
            }
            if gcv {
                // w_i |y_i − g_i|² = b² D_i |(Qu)_i|², exact even where g_i ≈ y_i.
                rss += b * b * di * dot(&qu, &qu);
            }
        };
        self.for_each_q_row(&u, subtract);
        for v in &mut u {
            for c in v.iter_mut() {
                *c *= a;
            }
        }
        Ok(Fit {
            p: a,
            alpha,
            values,
            second: u,
            rss,
            trace_residual,
        })
    }

    /// `(Q v)_i` of a closed curve, for `v` given at every knot (open curves: in
    /// [`Problem::solve`], the ends apart).
    #[inline]
    pub(super) fn q_row_times(&self, v: &[[f64; D]], i: usize) -> [f64; D] {
        let ih = &self.ih;
        let term = |j: usize, h: usize, c: usize| (v[j][c] - v[i][c]) * ih[h];
        let (im, ip) = (self.prev(i), self.next(i));
        std::array::from_fn(|c| term(im, im, c) + term(ip, i, c))
    }

    /// `(Q v)_i` for every knot `i` in order, passed to `f`: [`Problem::q_row_times`], and for
    /// open curves the same operations with the end terms apart.
    #[inline]
    fn for_each_q_row(&self, v: &[[f64; D]], mut f: impl FnMut(usize, [f64; D])) {
        let n = self.n();
        if self.closed {
            for i in 0..n {
                f(i, self.q_row_times(v, i));
            }
            return;
        }
        let ih = &self.ih;
        f(0, std::array::from_fn(|c| (v[1][c] - v[0][c]) * ih[0]));
        for (k, (w, h)) in v.windows(3).zip(ih.windows(2)).enumerate() {
            f(
                k + 1,
                std::array::from_fn(|c| (w[0][c] - w[1][c]) * h[0] + (w[2][c] - w[1][c]) * h[1]),
            );
        }
        f(
            n - 1,
            std::array::from_fn(|c| (v[n - 2][c] - v[n - 1][c]) * ih[n - 2]),
        );
    }

    /// The largest displacement `|y_i − g_i|` of a fit, computed as `|α W⁻¹_ii (Q γ)_i|` from
    /// its second derivatives `γ` rather than as the difference of `y_i` and `g_i`, which
    /// cancels when the displacements are far below the coordinates: at the bottom of the
    /// searches' range (`α = α_ref·e⁻²⁵`) that difference keeps only two or three digits, and
    /// they would move with a rigid motion of the data.
    pub(super) fn displacement_from_second(&self, fit: &Fit<D>) -> f64 {
        let mut largest = 0.0_f64;
        self.for_each_q_row(&fit.second, |i, qv| {
            let scale = fit.alpha * self.d(i);
            largest = largest.max(scale * scale * dot(&qv, &qv));
        });
        largest.sqrt()
    }

    /// `Σ_i W⁻¹_ii q_iᵀ M⁻¹ q_i` with `M⁻¹` read by knot indices through `inv` (only pairs of
    /// unknown knots at cyclic distance ≤ 2 are asked for).
    pub(super) fn trace_term(&self, inv: impl Fn(usize, usize) -> f64) -> f64 {
        let n = self.n();
        let is_unknown = |k: usize| self.closed || (1..n - 1).contains(&k);
        let mut total = 0.0;
        for i in 0..n {
            let di = self.d(i);
            if di == 0.0 {
                continue;
            }
            // Row i of Q: knots i−1, i, i+1 with 1/h_{i−1}, −(1/h_{i−1} + 1/h_i), 1/h_i.
            let mut q = [(0usize, 0.0f64); 3];
            let mut len = 0;
            if self.closed || i > 0 {
                let im = self.prev(i);
                if is_unknown(im) {
                    q[len] = (im, self.ih[im]);
                    len += 1;
                }
            }
            if is_unknown(i) {
                q[len] = (i, -(self.ih[self.prev(i)] + self.ih[i]));
                len += 1;
            }
            if self.closed || i + 1 < n {
                let ip = self.next(i);
                if is_unknown(ip) {
                    q[len] = (ip, self.ih[i]);
                    len += 1;
                }
            }
            let mut quad = 0.0;
            for &(ka, va) in &q[..len] {
                for &(kb, vb) in &q[..len] {
                    quad += va * vb * inv(ka, kb);
                }
            }
            total += di * quad;
        }
        total
    }

    /// p = 0 on an open curve: the weighted least-squares line in t, constrained through the
    /// pinned points (at most two).
    pub(super) fn fit_line(&self) -> Result<Fit<D>> {
        let n = self.n();
        let pins: Vec<usize> = (0..n).filter(|&i| self.d(i) == 0.0).collect();
        let t = self.t;
        // The line is `origin + slope · (t − t_origin)`.
        let (t_origin, origin, slope) = match pins.as_slice() {
            [] => {
                let (mut sw, mut st, mut sy) = (0.0, 0.0, [0.0; D]);
                for (i, (&ti, yi)) in t.iter().zip(self.y).enumerate() {
                    let w = 1.0 / self.d(i);
                    sw += w;
                    st += w * ti;
                    for c in 0..D {
                        sy[c] += yi[c] * w;
                    }
                }
                let (tm, ym) = (st / sw, sy.map(|v| v / sw));
                (tm, ym, self.slope_about(tm, ym, None))
            }
            &[k] => {
                let (tk, yk) = (t[k], self.y[k]);
                (tk, yk, self.slope_about(tk, yk, Some(k)))
            }
            &[k0, k1] => {
                let (t0, y0, y1) = (t[k0], self.y[k0], self.y[k1]);
                (
                    t0,
                    y0,
                    std::array::from_fn(|c| (y1[c] - y0[c]) / (t[k1] - t0)),
                )
            }
            _ => {
                return Err(Error::InvalidParameter {
                    name: "p".into(),
                    reason: "p = 0 with more than two pinned points (infinite weights) is not \
                             a line; use p > 0"
                        .into(),
                });
            }
        };
        let mut values = Vec::with_capacity(n);
        for (i, (&ti, &yi)) in t.iter().zip(self.y).enumerate() {
            let g = if self.d(i) == 0.0 {
                yi
            } else {
                std::array::from_fn(|c| origin[c] + slope[c] * (ti - t_origin))
            };
            values.push(g);
        }
        if values.iter().flatten().any(|g| !g.is_finite()) {
            return Err(Error::Singular("least-squares line is not finite".into()));
        }
        Ok(Fit {
            p: 0.0,
            alpha: f64::INFINITY,
            values,
            second: vec![[0.0; D]; n],
            rss: 0.0,
            trace_residual: 0.0,
        })
    }

    /// The weighted least-squares slope of the points about the fixed `(t0, y0)`, leaving out
    /// point `skip`.
    pub(super) fn slope_about(&self, t0: f64, y0: [f64; D], skip: Option<usize>) -> [f64; D] {
        let (mut stt, mut sty) = (0.0, [0.0; D]);
        for i in (0..self.n()).filter(|&i| Some(i) != skip) {
            let w = 1.0 / self.d(i);
            let dt = self.t[i] - t0;
            stt += w * dt * dt;
            for c in 0..D {
                sty[c] += (self.y[i][c] - y0[c]) * (w * dt);
            }
        }
        sty.map(|v| v / stt)
    }
}
