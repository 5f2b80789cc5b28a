//! The variation-diminishing spline operator and the integral λ-operator of Milovanović and
//! Kocić, as used by Calì, Miglio, Moroni and Rasella, *Curve fairing using integral spline
//! operators* (`../shared/papers/cali-integral-spline-operators.txt`, §3, eqs 5–23), in the
//! clamped 0-based notation of docs/algorithms/cali.md §4.1–4.2 (`../shared/spec/ALGORITHMS.md`).
//!
//! For a degree-p clamped knot vector `u_0..u_{m+p+1}` and control points `P_0..P_m`:
//!
//! - the *correspondence* (Greville) points `ξ_i = (u_{i+1} + … + u_{i+p})/p`, i = 0..m
//!   (the paper's `ξ_i^k`), carry the control polygon function φ, piecewise linear through
//!   `(ξ_i, P_i)`; the B-spline itself is the VDS operator `S_m P = Σ φ(ξ_i) B_i` (eq 11);
//! - the points `η_i = (u_i + … + u_{i+p})/(p+1)`, i = 0..m+1 (the paper's `ξ_i^{k+1}`),
//!   interlace them: `η_i ≤ ξ_i ≤ η_{i+1}`;
//! - the integral operator `T_m` (eqs 12–13) replaces `φ(ξ_i)` by the mean of φ over
//!   `[η_i, η_{i+1}]`, which is the tridiagonal matrix `M` of eqs 15–17 applied to the control
//!   points; the λ-operator (eqs 19–23) averages over `[(1−λ)ξ_i + λη_i, (1−λ)ξ_i + λη_{i+1}]`
//!   instead, and its matrix is `M^λ = (1 − λ) I + λ M`:
//!
//!   ```text
//!   (M^λ P)_i = λ α_i P_{i−1} + (1 − λ(α_i + γ_i)) P_i + λ γ_i P_{i+1}
//!   α_i = (ξ_i − η_i)² / (2 (ξ_i − ξ_{i−1}) (η_{i+1} − η_i))      i = 1..m,   α_0 = 0
//!   γ_i = (η_{i+1} − ξ_i)² / (2 (ξ_{i+1} − ξ_i) (η_{i+1} − η_i))  i = 0..m−1, γ_m = 0
//!   β_i = 1 − α_i − γ_i
//!   ```
//!
//! Spec §4.2 \[FIX\]: the paper lists γ_i only for i = 1..m−1 although its matrix uses γ_0, and
//! prints the last row as "β_m γ_m" instead of "α_m β_m". Here γ_0 > 0 and α_m > 0, so the
//! end control points move under `M^λ` (the fairing method keeps them fixed itself).
//!
//! Properties (tested in `tests/cali.rs`): every row sums to 1 (affine invariance, points
//! and lines are reproduced); `α_i, γ_i ≥ 0` and `α_i + γ_i ≤ 1/2`, so for λ ∈ [0, 1] every
//! new control point is a convex combination of at most three old ones (the convex-hull
//! property the paper relies on instead of an explicit deviation bound).
//!
//! Degenerate knots: an interior knot of multiplicity p + 1 makes two consecutive Greville
//! points coincide (`ξ_{i−1} = ξ_i`); the averaging interval then has no part on that side
//! (`ξ_i − η_i = 0`), so the coefficient is 0 (the 0/0 := 0 convention of docs/algorithms/README.md
//! §0.5). Ratios are clamped to their exact range [0, 1] so that rounding never produces a negative
//! or oversized weight.

use super::{BSplineCurve, KnotVector};
use crate::error::{Error, Result};
use crate::geom::Point;

/// How many control points on each side of the centre a local move changes (docs/algorithms/cali.md
/// §4.5: the set `L_i = {P_{i−2}, …, P_{i+2}}`).
pub const LOCAL_HALF_WIDTH: usize = 2;

/// The number of control points a local move changes: `2·LOCAL_HALF_WIDTH + 1 = 5`.
pub const LOCAL_WIDTH: usize = 2 * LOCAL_HALF_WIDTH + 1;

/// The integral λ-operator `M^λ` of a clamped knot vector (docs/algorithms/cali.md §4.2), built
/// once in O(m).
///
/// Holds the correspondence points ξ, the points η and the coefficients α, β, γ; applying
/// the operator to a control polygon (whole or locally) is then O(1) per control point.
///
/// ```
/// use batten::Point;
/// use batten::spline::{KnotVector, LambdaOperator};
///
/// let knots = KnotVector::clamped_uniform(3, 6).unwrap();
/// let op = LambdaOperator::try_new(3, &knots).unwrap();
/// let polygon: Vec<Point> = (0..6).map(|i| Point::new(i as f64, (i % 2) as f64)).collect();
/// // λ = 0 is the identity, λ = 1 the integral operator T_m.
/// assert_eq!(op.apply(&polygon, 0.0).unwrap(), polygon);
/// let smoothed = op.apply(&polygon, 1.0).unwrap();
/// assert!(smoothed[2].y > 0.0 && smoothed[2].y < 1.0);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct LambdaOperator {
    degree: usize,
    xi: Vec<f64>,
    eta: Vec<f64>,
    alpha: Vec<f64>,
    beta: Vec<f64>,
    gamma: Vec<f64>,
}

impl LambdaOperator {
    /// The operator of a clamped degree-`degree` knot vector `u_0..u_{m+p+1}` (m + 1 control
    /// points).
    ///
    /// # Errors
    /// - [`Error::InvalidParameter`] for degree 0;
    /// - [`Error::InvalidKnots`] when there are fewer than `2(p + 1)` knots, the knot vector is
    ///   not clamped (the first p + 1 and the last p + 1 knots equal: the control polygon
    ///   function is only defined on `[ξ_0, ξ_m]`), the domain is empty, or a knot has
    ///   multiplicity above p + 1 (then an averaging interval `[η_i, η_{i+1}]` is empty).
    pub fn try_new(degree: usize, knots: &KnotVector) -> Result<LambdaOperator> {
        let p = degree;
        if p == 0 {
            return Err(Error::InvalidParameter {
                name: "degree".into(),
                reason: "the λ-operator needs degree at least 1".into(),
            });
        }
        let u = knots.as_slice();
        if u.len() < 2 * (p + 1) {
            return Err(Error::InvalidKnots(format!(
                "{} knots are too few for degree {p}: at least {} needed",
                u.len(),
                2 * (p + 1)
            )));
        }
        let m = u.len() - p - 2;
        if u[..=p].iter().any(|&k| k != u[0]) || u[m + 1..].iter().any(|&k| k != u[m + 1]) {
            return Err(Error::InvalidKnots(
                "the λ-operator needs a clamped knot vector (first and last p + 1 knots equal)"
                    .into(),
            ));
        }
        if u[p] >= u[m + 1] {
            return Err(Error::InvalidKnots("the parameter domain is empty".into()));
        }
        let pf = p as f64;
        let xi = knots.greville(p);
        let eta: Vec<f64> = (0..=m + 1)
            .map(|i| u[i..=i + p].iter().sum::<f64>() / (pf + 1.0))
            .collect();
        let mut alpha = vec![0.0; m + 1];
        let mut gamma = vec![0.0; m + 1];
        for i in 0..=m {
            let width = eta[i + 1] - eta[i];
            if width <= 0.0 {
                return Err(Error::InvalidKnots(format!(
                    "knots {i}..={} are equal: multiplicity above degree + 1",
                    i + p + 1
                )));
            }
            // Left part [η_i, ξ_i] of the averaging interval, on the polygon leg ξ_{i−1}..ξ_i.
            if i > 0 {
                alpha[i] = half_weight(xi[i] - eta[i], xi[i] - xi[i - 1], width);
            }
            // Right part [ξ_i, η_{i+1}], on the leg ξ_i..ξ_{i+1}.
            if i < m {
                gamma[i] = half_weight(eta[i + 1] - xi[i], xi[i + 1] - xi[i], width);
            }
        }
        let beta = alpha.iter().zip(&gamma).map(|(a, g)| 1.0 - a - g).collect();
        Ok(LambdaOperator {
            degree: p,
            xi,
            eta,
            alpha,
            beta,
            gamma,
        })
    }

    /// The operator of a non-rational clamped B-spline's degree and knots.
    ///
    /// # Errors
    /// As [`LambdaOperator::try_new`], and [`Error::InvalidParameter`] for a rational curve
    /// (the operator acts on the control points of a polynomial spline; with weights the
    /// identity `S_m P = Σ φ(ξ_i) B_i` does not hold).
    pub fn for_curve(curve: &BSplineCurve) -> Result<LambdaOperator> {
        if curve.weights().is_some() {
            return Err(Error::InvalidParameter {
                name: "weights".into(),
                reason: "the λ-operator is defined for non-rational B-splines".into(),
            });
        }
        LambdaOperator::try_new(curve.degree(), curve.knots())
    }

    /// The degree p.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The number of control points, m + 1.
    pub fn len(&self) -> usize {
        self.xi.len()
    }

    /// Always false: a valid knot vector has at least p + 1 control points.
    pub fn is_empty(&self) -> bool {
        self.xi.is_empty()
    }

    /// The correspondence (Greville) points ξ_0..ξ_m.
    pub fn xi(&self) -> &[f64] {
        &self.xi
    }

    /// The points η_0..η_{m+1} (averages of p + 1 consecutive knots).
    pub fn eta(&self) -> &[f64] {
        &self.eta
    }

    /// The sub-diagonal coefficients α_0..α_m of `M` (α_0 = 0).
    pub fn alpha(&self) -> &[f64] {
        &self.alpha
    }

    /// The diagonal coefficients β_0..β_m of `M`.
    pub fn beta(&self) -> &[f64] {
        &self.beta
    }

    /// The super-diagonal coefficients γ_0..γ_m of `M` (γ_m = 0).
    pub fn gamma(&self) -> &[f64] {
        &self.gamma
    }

    /// Row `j` of `M^λ`: the weights of `P_{j−1}`, `P_j`, `P_{j+1}` (the first is 0 for
    /// j = 0, the last 0 for j = m). They sum to 1.
    ///
    /// # Panics
    /// If `j` is not a control-point index.
    pub fn row(&self, j: usize, lambda: f64) -> [f64; 3] {
        let (a, g) = (lambda * self.alpha[j], lambda * self.gamma[j]);
        [a, 1.0 - (a + g), g]
    }

    /// `M^λ P`: the λ-operator applied to the whole control polygon.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when `points` does not have m + 1 entries,
    /// [`Error::InvalidParameter`] when λ is not in [0, 1].
    pub fn apply(&self, points: &[Point], lambda: f64) -> Result<Vec<Point>> {
        self.check(points, lambda)?;
        Ok((0..points.len())
            .map(|j| self.row_point(points, j, lambda))
            .collect())
    }

    /// The five new control points `(M^λ P)_j`, j = i−2..=i+2, of a local move centred at
    /// `i` (docs/algorithms/cali.md §4.5 step 3.1), computed from the current `points`; nothing
    /// else changes.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`], [`Error::InvalidParameter`] for λ outside [0, 1] or a
    /// centre outside `2..=m−2` (where the window would leave the polygon).
    pub fn apply_local(
        &self,
        points: &[Point],
        i: usize,
        lambda: f64,
    ) -> Result<[Point; LOCAL_WIDTH]> {
        self.check(points, lambda)?;
        self.check_centre(i)?;
        Ok(self.local_unchecked(points, i, lambda))
    }

    /// As [`LambdaOperator::apply_local`], writing the five new points into `points`.
    ///
    /// # Errors
    /// As [`LambdaOperator::apply_local`]; `points` is unchanged on error.
    pub fn apply_local_in_place(&self, points: &mut [Point], i: usize, lambda: f64) -> Result<()> {
        let new = self.apply_local(points, i, lambda)?;
        points[i - LOCAL_HALF_WIDTH..=i + LOCAL_HALF_WIDTH].copy_from_slice(&new);
        Ok(())
    }

    /// The local move without checks: the caller guarantees `points.len() == self.len()`,
    /// `LOCAL_HALF_WIDTH ≤ i ≤ m − LOCAL_HALF_WIDTH` and λ finite.
    pub(crate) fn local_unchecked(
        &self,
        points: &[Point],
        i: usize,
        lambda: f64,
    ) -> [Point; LOCAL_WIDTH] {
        let mut out = [Point::ORIGIN; LOCAL_WIDTH];
        for (o, j) in out
            .iter_mut()
            .zip(i - LOCAL_HALF_WIDTH..=i + LOCAL_HALF_WIDTH)
        {
            *o = self.row_point(points, j, lambda);
        }
        out
    }

    /// `(M^λ P)_j`, written as `P_j + λα_j (P_{j−1} − P_j) + λγ_j (P_{j+1} − P_j)`: the same
    /// affine combination, but exact at λ = 0 and free of cancellation for far-off data.
    #[inline]
    fn row_point(&self, points: &[Point], j: usize, lambda: f64) -> Point {
        let p = points[j];
        let mut v = crate::geom::Vec2::ZERO;
        if j > 0 {
            v += (points[j - 1] - p) * (lambda * self.alpha[j]);
        }
        if j + 1 < points.len() {
            v += (points[j + 1] - p) * (lambda * self.gamma[j]);
        }
        p + v
    }

    fn check(&self, points: &[Point], lambda: f64) -> Result<()> {
        if points.len() != self.len() {
            return Err(Error::LengthMismatch {
                what: "control points",
                got: points.len(),
                expected: self.len(),
            });
        }
        if !(0.0..=1.0).contains(&lambda) {
            return Err(Error::InvalidParameter {
                name: "lambda".into(),
                reason: format!("{lambda} is outside [0, 1], where the convex-hull property holds"),
            });
        }
        Ok(())
    }

    fn check_centre(&self, i: usize) -> Result<()> {
        let m = self.len() - 1;
        if i < LOCAL_HALF_WIDTH || i + LOCAL_HALF_WIDTH > m {
            return Err(Error::InvalidParameter {
                name: "centre".into(),
                reason: format!(
                    "{i} is outside {LOCAL_HALF_WIDTH}..={} (m = {m})",
                    m.saturating_sub(LOCAL_HALF_WIDTH)
                ),
            });
        }
        Ok(())
    }
}

/// `δ² / (2 Δ w)`, the weight of the far end of a polygon leg of length Δ in the mean of that
/// leg over a sub-interval of length δ ≤ Δ next to its near end, divided by the whole averaging
/// width w. Computed as `(δ/Δ)·δ/(2w)` with `δ/Δ` clamped to [0, 1] (0 for an empty leg, where
/// δ = 0 exactly in exact arithmetic).
#[inline]
fn half_weight(delta: f64, leg: f64, width: f64) -> f64 {
    let delta = delta.max(0.0);
    let ratio = if leg > 0.0 {
        (delta / leg).min(1.0)
    } else {
        0.0
    };
    ratio * delta / (2.0 * width)
}
