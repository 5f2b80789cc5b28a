//! Calì's fairness indicators (docs/algorithms/cali.md §4.4: κ and arc length at the correspondence
//! points, LFI, GFI) of a clamped B-spline, kept up to date under the local λ-moves of
//! docs/algorithms/cali.md §4.5 in time independent of the number of control points, and the
//! golden-section search for λ (`docs/algorithms/cali.md`, "Fairness indicators" and "The
//! algorithm").

use crate::analysis::{fairness_indicators, signed_curvature};
use crate::curve::Derivatives;
use crate::error::{Error, Result};
use crate::geom::{Point, Vec2};
use crate::numeric::{GaussLegendre, minimize_golden};
use crate::spline::{BSplineCurve, LOCAL_HALF_WIDTH, LOCAL_WIDTH, LambdaOperator, MAX_ORDER};

/// A candidate is only tried when `|κ''_i|` exceeds `ROUNDING_FACTOR` times the rounding level
/// of its divided difference, `ε·S/h⁴` (S the largest coordinate magnitude of the input, h the
/// shorter arc-length step next to ξ_i, ε the machine epsilon): the position error `ε·S`
/// becomes a curvature error `ε·S/h²` and a κ'' error `ε·S/h⁴`. Below it `LFI_i` is noise — on
/// collinear data κ is 0 up to rounding, and chasing that noise would slide the points along
/// the line by a fair part of their spacing.
pub(super) const ROUNDING_FACTOR: f64 = 16.0;

/// The new control points of a move: the window `P_{i−2..i+2}` with the ends of the polygon
/// kept.
#[derive(Clone, Copy, Debug)]
struct Window {
    /// i − 2.
    first: usize,
    /// Moved indices `lo..=hi` (the window without `P_0` and `P_m`).
    lo: usize,
    hi: usize,
    pts: [Point; LOCAL_WIDTH],
}

impl Window {
    #[inline]
    fn get(&self, ctrl: &[Point], k: usize) -> Point {
        if k >= self.lo && k <= self.hi {
            self.pts[k - self.first]
        } else {
            ctrl[k]
        }
    }
}

/// The result of trying one local move on a [`LocalIndicators`] state, without committing it.
#[derive(Clone, Debug)]
pub struct Trial {
    centre: usize,
    pub(super) lambda: f64,
    lfi_centre: f64,
    gfi_before: f64,
    pub(super) delta_gfi: f64,
    window: Window,
    kappa_lo: usize,
    kappa: Vec<f64>,
    h_lo: usize,
    h: Vec<f64>,
    lfi_lo: usize,
    lfi: Vec<f64>,
    pub(super) deps: (usize, usize),
    generation: u64,
}

impl Trial {
    /// The centre i of the move.
    pub fn centre(&self) -> usize {
        self.centre
    }

    /// The shape parameter λ.
    pub fn lambda(&self) -> f64 {
        self.lambda
    }

    /// `LFI_i` at the centre after the move.
    pub fn lfi_centre(&self) -> f64 {
        self.lfi_centre
    }

    /// `GFI_new − GFI`.
    pub fn gfi_change(&self) -> f64 {
        self.delta_gfi
    }

    /// `GFI_new`, the GFI of the curve after the move.
    pub fn gfi_after(&self) -> f64 {
        self.gfi_before + self.delta_gfi
    }

    /// The indices `lo..=hi` of the control points the move changes (`P_{i−2..i+2}` without
    /// `P_0` and `P_m`).
    pub fn moved_range(&self) -> (usize, usize) {
        (self.window.lo, self.window.hi)
    }

    /// The new position of control point `j` (for `j` in [`Trial::moved_range`]), or `None`.
    pub fn moved_point(&self, j: usize) -> Option<Point> {
        (j >= self.window.lo && j <= self.window.hi).then(|| self.window.pts[j - self.window.first])
    }

    /// The indices `lo..=hi` of the LFIs the move changes.
    pub fn lfi_range(&self) -> (usize, usize) {
        (self.lfi_lo, self.lfi_lo + self.lfi.len().saturating_sub(1))
    }

    #[inline]
    pub(super) fn control_point(&self, ctrl: &[Point], j: usize) -> Point {
        self.window.get(ctrl, j)
    }
}

/// Calì's indicators (docs/algorithms/cali.md §4.4) of a clamped, non-rational B-spline, kept up to
/// date under the local λ-moves of docs/algorithms/cali.md §4.5 in time independent of the number
/// of control points.
///
/// Holds the control points, κ at the correspondence points, the arc-length increments
/// `h_j = s_j − s_{j−1}` (a move shifts every later `s_j` by a constant, which the divided
/// differences do not see), the LFIs and the GFI. [`LocalIndicators::trial`] evaluates a move
/// without committing it; [`LocalIndicators::commit`] applies it.
#[derive(Clone, Debug)]
pub struct LocalIndicators {
    p: usize,
    template: BSplineCurve,
    op: LambdaOperator,
    pub(super) ctrl: Vec<Point>,
    /// Span of ξ_j and the first and second basis derivatives there (stride 2(p + 1)).
    xi_span: Vec<usize>,
    xi_basis: Vec<f64>,
    /// Quadrature nodes of interval j (between ξ_{j−1} and ξ_j) are
    /// `iv_start[j]..iv_start[j + 1]`; interval 0 is empty.
    iv_start: Vec<usize>,
    /// Smallest and largest span used by the nodes of interval j.
    iv_kmin: Vec<usize>,
    iv_kmax: Vec<usize>,
    node_span: Vec<usize>,
    node_weight: Vec<f64>,
    /// First basis derivatives at the nodes, stride p + 1.
    node_basis: Vec<f64>,
    kappa: Vec<f64>,
    h: Vec<f64>,
    pub(super) lfi: Vec<f64>,
    gfi: f64,
    generation: u64,
    /// Control points held at each end (at least `P_0` and `P_m`; `--fix-ends`).
    held: usize,
}

impl LocalIndicators {
    /// The indicators of `curve`, from [`fairness_indicators`], with the basis values the
    /// local updates need.
    ///
    /// # Errors
    /// - [`Error::InvalidParameter`] for a rational curve or a degree above
    ///   [`MAX_ORDER`] − 1;
    /// - the errors of [`LambdaOperator::for_curve`] (knots not clamped, …);
    /// - [`Error::Degenerate`] when a curvature or an LFI is not finite (zero speed at a
    ///   correspondence point) or two correspondence points coincide (an interior knot of
    ///   multiplicity p + 1).
    pub fn new(curve: &BSplineCurve) -> Result<LocalIndicators> {
        let p = curve.degree();
        if p >= MAX_ORDER {
            return Err(Error::InvalidParameter {
                name: "degree".into(),
                reason: format!("must be at most {}", MAX_ORDER - 1),
            });
        }
        let op = LambdaOperator::for_curve(curve)?;
        let m = op.len() - 1;
        let xi = op.xi();
        if let Some(j) = xi.windows(2).position(|w| w[1] <= w[0]) {
            return Err(Error::Degenerate(format!(
                "correspondence points {j} and {} coincide (interior knot of multiplicity {})",
                j + 1,
                p + 1
            )));
        }
        let u = curve.knots().as_slice();
        let mut b = [[0.0; MAX_ORDER]; 4];

        let mut xi_span = Vec::with_capacity(m + 1);
        let mut xi_basis = Vec::with_capacity((m + 1) * 2 * (p + 1));
        for &t in xi {
            let k = curve.find_span(t);
            curve.basis_derivs(k, t, 2, &mut b);
            xi_span.push(k);
            xi_basis.extend_from_slice(&b[1][..=p]);
            xi_basis.extend_from_slice(&b[2][..=p]);
        }

        let gl = GaussLegendre::default();
        let mut iv_start = vec![0, 0];
        let mut iv_kmin = vec![p];
        let mut iv_kmax = vec![p];
        let mut node_span = Vec::new();
        let mut node_weight = Vec::new();
        let mut node_basis = Vec::new();
        for j in 1..=m {
            let (a, end) = (xi[j - 1], xi[j]);
            let mut t0 = a;
            let (mut kmin, mut kmax) = (usize::MAX, 0);
            while t0 < end {
                let k = curve.find_span(t0);
                let t1 = end.min(u[k + 1]);
                if t1 <= t0 {
                    break;
                }
                let (half, mid) = (0.5 * (t1 - t0), 0.5 * (t0 + t1));
                for (x, w) in gl.nodes().iter().zip(gl.weights()) {
                    let t = mid + half * x;
                    curve.basis_derivs(k, t, 1, &mut b);
                    node_span.push(k);
                    node_weight.push(w * half);
                    node_basis.extend_from_slice(&b[1][..=p]);
                }
                kmin = kmin.min(k);
                kmax = kmax.max(k);
                t0 = t1;
            }
            if kmin > kmax {
                return Err(Error::Degenerate(format!(
                    "the interval between correspondence points {} and {j} is empty",
                    j - 1
                )));
            }
            iv_start.push(node_span.len());
            iv_kmin.push(kmin);
            iv_kmax.push(kmax);
        }

        let ind = fairness_indicators(curve);
        let h: Vec<f64> = std::iter::once(0.0)
            .chain(ind.s.windows(2).map(|w| w[1] - w[0]))
            .collect();
        if let Some(j) = (0..=m).find(|&j| !ind.kappa[j].is_finite() || !ind.lfi[j].is_finite()) {
            return Err(Error::Degenerate(format!(
                "the curvature at correspondence point {j} (parameter {}) is not finite",
                xi[j]
            )));
        }
        if let Some(j) = (1..=m).find(|&j| h[j].partial_cmp(&0.0).is_none_or(|o| o.is_le())) {
            return Err(Error::Degenerate(format!(
                "zero arc length between correspondence points {} and {j}",
                j - 1
            )));
        }
        Ok(LocalIndicators {
            p,
            template: curve.clone(),
            op,
            ctrl: curve.control_points().to_vec(),
            xi_span,
            xi_basis,
            iv_start,
            iv_kmin,
            iv_kmax,
            node_span,
            node_weight,
            node_basis,
            kappa: ind.kappa,
            h,
            lfi: ind.lfi,
            gfi: ind.gfi,
            generation: 0,
            held: 1,
        })
    }

    /// Hold `k` control points at each end (at least 1, `P_0` and `P_m`): 2 keeps the end
    /// tangents of the curve and 3 its end curvatures. A move changes only the control points
    /// of its window that are not held.
    pub fn with_held_ends(mut self, k: usize) -> LocalIndicators {
        self.held = k.max(1);
        self
    }

    /// The number of control points, m + 1.
    pub fn len(&self) -> usize {
        self.ctrl.len()
    }

    /// Always false.
    pub fn is_empty(&self) -> bool {
        self.ctrl.is_empty()
    }

    /// The current control points.
    pub fn control_points(&self) -> &[Point] {
        &self.ctrl
    }

    /// The λ-operator of the knot vector.
    pub fn operator(&self) -> &LambdaOperator {
        &self.op
    }

    /// Signed curvature at the correspondence points ξ_0..ξ_m.
    pub fn kappa(&self) -> &[f64] {
        &self.kappa
    }

    /// `LFI_0..LFI_m` (zero at 0 and m, where it is not defined).
    pub fn lfi(&self) -> &[f64] {
        &self.lfi
    }

    /// The GFI, `Σ LFI_j`.
    pub fn gfi(&self) -> f64 {
        self.gfi
    }

    /// The candidate centres `2..=m−2` (empty when m < 4).
    pub fn candidates(&self) -> std::ops::RangeInclusive<usize> {
        let m = self.len() - 1;
        LOCAL_HALF_WIDTH..=m.saturating_sub(LOCAL_HALF_WIDTH)
    }

    /// The curve with the current control points.
    ///
    /// # Errors
    /// [`Error::NonFinite`] if a control point became non-finite (it cannot for λ ∈ [0, 1]).
    pub fn curve(&self) -> Result<BSplineCurve> {
        self.template.with_control_points(self.ctrl.clone())
    }

    /// `LFI_i` after the move centred at `i` with shape parameter λ: the objective of the
    /// λ search (docs/algorithms/cali.md §4.5 step 3.3).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a centre outside [`LocalIndicators::candidates`] or
    /// λ outside [0, 1].
    pub fn lfi_after(&self, i: usize, lambda: f64) -> Result<f64> {
        self.check_move(i, lambda)?;
        Ok(self.objective(i, lambda))
    }

    /// Evaluate the move centred at `i` with shape parameter λ: the new control points
    /// `(M^λ P)_j`, j = i−2..=i+2 (except `P_0` and `P_m`, which are kept), and the LFIs and
    /// GFI that result, recomputed only where the curve changed.
    ///
    /// # Errors
    /// As [`LocalIndicators::lfi_after`].
    pub fn trial(&self, i: usize, lambda: f64) -> Result<Trial> {
        self.check_move(i, lambda)?;
        Ok(self.trial_unchecked(i, lambda))
    }

    /// The move centred at `i` with the λ that minimises `LFI_i(λ)` on [0, 1]: golden section
    /// to `lambda_tol`, both end points compared (docs/algorithms/cali.md §4.5 \[CHOICE\]).
    ///
    /// # Errors
    /// As [`LocalIndicators::lfi_after`], and [`Error::InvalidParameter`] for a `lambda_tol`
    /// that is not positive and finite.
    pub fn best_trial(&self, i: usize, lambda_tol: f64) -> Result<Trial> {
        self.check_move(i, 0.0)?;
        if !(lambda_tol.is_finite() && lambda_tol > 0.0) {
            return Err(Error::InvalidParameter {
                name: "lambda_tol".into(),
                reason: format!("must be positive and finite, got {lambda_tol}"),
            });
        }
        let best = minimize_golden(|l| self.objective(i, l), 0.0, 1.0, lambda_tol);
        Ok(self.trial_unchecked(i, best.x))
    }

    /// Apply a move evaluated by [`LocalIndicators::trial`] on this very state.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when the state has changed since the trial was made.
    pub fn commit(&mut self, trial: &Trial) -> Result<()> {
        if trial.generation != self.generation {
            return Err(Error::InvalidParameter {
                name: "trial".into(),
                reason: "it was made before the last commit".into(),
            });
        }
        self.commit_unchecked(trial);
        Ok(())
    }

    pub(super) fn commit_unchecked(&mut self, t: &Trial) {
        for j in t.window.lo..=t.window.hi {
            self.ctrl[j] = t.window.pts[j - t.window.first];
        }
        self.kappa[t.kappa_lo..t.kappa_lo + t.kappa.len()].copy_from_slice(&t.kappa);
        self.h[t.h_lo..t.h_lo + t.h.len()].copy_from_slice(&t.h);
        self.lfi[t.lfi_lo..t.lfi_lo + t.lfi.len()].copy_from_slice(&t.lfi);
        // Re-sum rather than accumulate differences, so rounding does not drift.
        self.gfi = self.lfi.iter().sum();
        self.generation += 1;
    }

    /// [`ROUNDING_FACTOR`] times the rounding level `ε·S/h⁴` of `κ''_i` for coordinates of
    /// magnitude `scale`.
    pub(super) fn rounding_level(&self, i: usize, scale: f64) -> f64 {
        let h = self.h[i].min(self.h[i + 1]);
        ROUNDING_FACTOR * f64::EPSILON * scale / h / h / h / h
    }

    fn check_move(&self, i: usize, lambda: f64) -> Result<()> {
        if !self.candidates().contains(&i) {
            return Err(Error::InvalidParameter {
                name: "centre".into(),
                reason: format!(
                    "{i} is outside the candidates {}..={}",
                    self.candidates().start(),
                    self.candidates().end()
                ),
            });
        }
        if !(0.0..=1.0).contains(&lambda) {
            return Err(Error::InvalidParameter {
                name: "lambda".into(),
                reason: format!("{lambda} is outside [0, 1]"),
            });
        }
        Ok(())
    }

    fn window(&self, i: usize, lambda: f64) -> Window {
        let m = self.len() - 1;
        Window {
            first: i - LOCAL_HALF_WIDTH,
            lo: (i - LOCAL_HALF_WIDTH).max(self.held),
            hi: (i + LOCAL_HALF_WIDTH).min(m.saturating_sub(self.held)),
            pts: self.op.local_unchecked(&self.ctrl, i, lambda),
        }
    }

    /// κ at ξ_j with the window's control points.
    #[inline]
    fn kappa_with(&self, j: usize, w: &Window) -> f64 {
        let p = self.p;
        let k = self.xi_span[j];
        let stride = 2 * (p + 1);
        let b = &self.xi_basis[j * stride..(j + 1) * stride];
        let mut d1 = Vec2::ZERO;
        let mut d2 = Vec2::ZERO;
        for l in 0..=p {
            let v = w.get(&self.ctrl, k - p + l).to_vec2();
            d1 += v * b[l];
            d2 += v * b[p + 1 + l];
        }
        signed_curvature(&Derivatives {
            d1,
            d2,
            ..Derivatives::default()
        })
    }

    /// `s_j − s_{j−1}` with the window's control points.
    #[inline]
    fn h_with(&self, j: usize, w: &Window) -> f64 {
        let p = self.p;
        let mut s = 0.0;
        for n in self.iv_start[j]..self.iv_start[j + 1] {
            let first = self.node_span[n] - p;
            let b = &self.node_basis[n * (p + 1)..(n + 1) * (p + 1)];
            let mut d1 = Vec2::ZERO;
            for (l, &bl) in b.iter().enumerate() {
                d1 += w.get(&self.ctrl, first + l).to_vec2() * bl;
            }
            // sqrt rather than hypot: the speed is far from overflow and this is the hot loop.
            s += self.node_weight[n] * d1.length_squared().sqrt();
        }
        s
    }

    fn objective(&self, i: usize, lambda: f64) -> f64 {
        let w = self.window(i, lambda);
        let d = second_difference(
            [
                self.kappa_with(i - 1, &w),
                self.kappa_with(i, &w),
                self.kappa_with(i + 1, &w),
            ],
            self.h_with(i, &w),
            self.h_with(i + 1, &w),
        );
        d * d
    }

    fn trial_unchecked(&self, i: usize, lambda: f64) -> Trial {
        let m = self.len() - 1;
        let p = self.p;
        let w = self.window(i, lambda);
        // Curvatures whose span uses a moved control point: a ≤ span ≤ b + p.
        let k_lo = self.xi_span.partition_point(|&k| k < w.lo);
        let k_hi = self.xi_span.partition_point(|&k| k <= w.hi + p).max(k_lo);
        let kappa: Vec<f64> = (k_lo..k_hi).map(|j| self.kappa_with(j, &w)).collect();
        // Arc-length intervals with a node in such a span.
        let h_lo = 1 + self.iv_kmax[1..].partition_point(|&k| k < w.lo);
        let h_hi = (1 + self.iv_kmin[1..].partition_point(|&k| k <= w.hi + p)).max(h_lo);
        let h: Vec<f64> = (h_lo..h_hi).map(|j| self.h_with(j, &w)).collect();
        // LFI_j reads κ_{j−1..j+1}, h_j, h_{j+1}.
        let l_lo = k_lo.saturating_sub(1).min(h_lo - 1).max(1);
        let l_hi = (k_hi.max(h_hi.saturating_sub(1))).min(m - 1); // inclusive: k_hi − 1 + 1
        let get_k = |j: usize| {
            if (k_lo..k_hi).contains(&j) {
                kappa[j - k_lo]
            } else {
                self.kappa[j]
            }
        };
        let get_h = |j: usize| {
            if (h_lo..h_hi).contains(&j) {
                h[j - h_lo]
            } else {
                self.h[j]
            }
        };
        let mut lfi = Vec::with_capacity(l_hi + 1 - l_lo.min(l_hi + 1));
        let mut delta = 0.0;
        for j in l_lo..=l_hi {
            let d = second_difference(
                [get_k(j - 1), get_k(j), get_k(j + 1)],
                get_h(j),
                get_h(j + 1),
            );
            let v = d * d;
            delta += v - self.lfi[j];
            lfi.push(v);
        }
        let lfi_centre = if (l_lo..=l_hi).contains(&i) {
            lfi[i - l_lo]
        } else {
            self.lfi[i]
        };
        // Control points the result depends on: the operator rows (i−3..=i+3) and everything
        // the LFIs in l_lo..=l_hi read.
        let deps = (
            (w.first.saturating_sub(1))
                .min(self.xi_span[l_lo - 1] - p)
                .min(self.iv_kmin[l_lo] - p),
            (i + LOCAL_HALF_WIDTH + 1)
                .min(m)
                .max(self.xi_span[l_hi + 1])
                .max(self.iv_kmax[l_hi + 1]),
        );
        Trial {
            centre: i,
            lambda,
            lfi_centre,
            gfi_before: self.gfi,
            delta_gfi: delta,
            window: w,
            kappa_lo: k_lo,
            kappa,
            h_lo,
            h,
            lfi_lo: l_lo,
            lfi,
            deps,
            generation: self.generation,
        }
    }
}

/// `κ''` at the middle of three curvature samples from the arc-length increments before and
/// after it (docs/algorithms/cali.md §4.4): `2 [(κ_+ − κ_0)/h_+ − (κ_0 − κ_−)/h_−] / (h_− + h_+)`.
#[inline]
fn second_difference(k: [f64; 3], h_minus: f64, h_plus: f64) -> f64 {
    2.0 * ((k[2] - k[1]) / h_plus - (k[1] - k[0]) / h_minus) / (h_minus + h_plus)
}
