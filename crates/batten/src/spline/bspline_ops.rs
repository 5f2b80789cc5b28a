//! Operations on [`BSplineCurve`]: knot insertion and removal, least-squares approximation,
//! reversal, rigid motion, the hodograph and the exact conversion of a [`ParametricCubic`].
//!
//! References (L. Piegl and W. Tiller, *The NURBS Book*, 2nd ed., Springer 1997):
//! - knot insertion: Boehm's algorithm in the form of A5.1, applied to the homogeneous
//!   control points `(w x, w y, w)` so that rational curves are handled exactly (§5.2);
//! - knot removal: Tiller's algorithm A5.8 (§5.4), written as the `p − s + 1` equations
//!   `P_i = α_i Q_i + (1 − α_i) Q_{i−1}` that knot *insertion* imposes on the reduced control
//!   points Q; a knot is removable when this over-determined system is consistent. The
//!   fairing method of Sapidis and Farin (*Automatic fairing algorithm for B-spline curves*,
//!   CAD 22 (1990)) removes a knot and reinserts it; for a cubic with a simple knot its local
//!   formula is [`RemovalRule::Middle`] (see there);
//! - least-squares approximation with a fixed number of control points: §9.4.1, parameters of
//!   eq 9.5 (chord length) and the knot placement of eq 9.69, end points interpolated;
//! - the hodograph: §3.3, eq 3.8.

use super::{BSplineCurve, KnotVector, MAX_ORDER, ParametricCubic, Parametrization, parameters};
use crate::curve::Curve;
use crate::error::{Error, Result};
use crate::geom::{Point, Rigid, Vec2};
use crate::numeric::{SymBanded, minimize_brent};

/// Samples per knot span when the largest deviation between two curves is measured (before
/// the best sample of each span is refined by Brent's method). The difference of two splines
/// on a common span is a polynomial (or a ratio of polynomials) of low degree, which 16
/// samples resolve.
pub const DEVIATION_SAMPLES_PER_SPAN: usize = 16;

/// Relative accuracy in the parameter to which the largest deviation is located.
const DEVIATION_REL_TOL: f64 = 1e-10;

/// A knot of a [`BSplineCurve`], by position or by value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum KnotRef {
    /// Position in the knot vector; any index inside a run of equal knots names that run.
    Index(usize),
    /// A knot value, matched exactly (`==`).
    Value(f64),
}

/// Where [`BSplineCurve::remove_knot_exact`] puts the error when the knot is not removable.
///
/// Removing one copy of the knot `u = u_r` of multiplicity `s` (s ≤ p) from a degree-p curve
/// replaces the `p − s + 1` control points `P_{r−p} … P_{r−s}` by `p − s` new ones
/// `Q_{r−p} … Q_{r−s−1}`. Reinserting `u` maps Q back to points `P'_i = α_i Q_i + (1 − α_i)
/// Q_{i−1}` with `α_i = (u − u_i)/(u_{i+p+1} − u_i)`; the rules differ in which of the equations
/// `P'_i = P_i` they give up. With a removable knot (the curve is `C^{p−s+1}` at u) all rules
/// give the same curve and a zero deviation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RemovalRule {
    /// Solve from the left (Piegl–Tiller eq 5.28): `P'_i = P_i` for i < r−s; only the last
    /// affected control point `P_{r−s}` changes.
    Left,
    /// Solve from the right (eq 5.29): only the first affected control point `P_{r−p}` changes.
    Right,
    /// Solve from both ends and meet in the middle (Tiller's A5.8): only the control point
    /// `P_k`, `k = r − p + ⌊(p − s)/2⌋`, changes. For a cubic with a simple knot this is
    /// `k = r − 2`, the control point "under" the knot, and its new position is Farin's
    /// `((u_{r+2} − u_r) L + (u_r − u_{r−2}) R)/(u_{r+2} − u_{r−2})`, the weighted mean of the
    /// points L and R extrapolated from the two control points on either side: the
    /// Sapidis–Farin fairing step.
    #[default]
    Middle,
    /// The mean of the [`RemovalRule::Left`] and [`RemovalRule::Right`] reduced control
    /// points: every affected control point may change.
    Average,
    /// The reduced control points that change the affected control points least in the sum of
    /// squared distances (a small tridiagonal least-squares problem; in homogeneous
    /// coordinates for a rational curve): the least-change removal.
    LeastSquares,
}

/// The result of [`BSplineCurve::remove_knot_exact`].
#[derive(Clone, Debug, PartialEq)]
pub struct KnotRemoval {
    /// The curve with one copy of the knot removed.
    pub curve: BSplineCurve,
    /// The removed knot value inserted again into [`KnotRemoval::curve`]: the same knot
    /// vector as the input, with only the control points in [`KnotRemoval::changed`] moved.
    pub reinserted: BSplineCurve,
    /// Indices of the input's control points (and weights) that differ in
    /// [`KnotRemoval::reinserted`].
    pub changed: Vec<usize>,
    /// The largest distance `max_t |C(t) − C_removed(t)|` over the parameter domain, measured
    /// on the spans where the curve changed (sampled, then refined by Brent's method).
    pub max_deviation: f64,
}

/// Homogeneous control point `(w x, w y, w)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct H {
    x: f64,
    y: f64,
    w: f64,
}

impl H {
    fn lin(self, a: f64, other: H, b: f64) -> H {
        H {
            x: a * self.x + b * other.x,
            y: a * self.y + b * other.y,
            w: a * self.w + b * other.w,
        }
    }

    fn scale(self, a: f64) -> H {
        H {
            x: a * self.x,
            y: a * self.y,
            w: a * self.w,
        }
    }
}

/// The control points of `c` in homogeneous form (w = 1 for a non-rational curve).
fn homogeneous(c: &BSplineCurve) -> Vec<H> {
    match c.weights() {
        None => c
            .control_points()
            .iter()
            .map(|p| H {
                x: p.x,
                y: p.y,
                w: 1.0,
            })
            .collect(),
        Some(w) => c
            .control_points()
            .iter()
            .zip(w)
            .map(|(p, &w)| H {
                x: w * p.x,
                y: w * p.y,
                w,
            })
            .collect(),
    }
}

/// A curve from homogeneous control points; a non-rational curve ignores `w` (which its
/// operations keep at 1 up to rounding) so that it stays exactly non-rational.
fn from_homogeneous(
    degree: usize,
    knots: KnotVector,
    pw: &[H],
    rational: bool,
) -> Result<BSplineCurve> {
    if rational {
        if let Some(index) = pw.iter().position(|h| !(h.w > 0.0 && h.w.is_finite())) {
            return Err(Error::Degenerate(format!(
                "the operation gives the non-positive weight {} at control point {index}",
                pw[index].w
            )));
        }
        let pts = pw
            .iter()
            .map(|h| Point::new(h.x / h.w, h.y / h.w))
            .collect();
        let w = pw.iter().map(|h| h.w).collect();
        BSplineCurve::try_new(degree, knots, pts, Some(w))
    } else {
        let pts = pw.iter().map(|h| Point::new(h.x, h.y)).collect();
        BSplineCurve::try_new(degree, knots, pts, None)
    }
}

impl BSplineCurve {
    /// Insert the knot value `u` `times` times (Boehm's algorithm, Piegl–Tiller A5.1, in
    /// homogeneous coordinates). The curve is unchanged (to rounding); it gains `times`
    /// control points.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when `u` is not strictly inside the parameter domain or
    /// the multiplicity would exceed the degree (`s + times > p`; a knot of multiplicity
    /// `p + 1` would split the curve).
    pub fn insert_knot(&self, u: f64, times: usize) -> Result<BSplineCurve> {
        let (a, b) = self.domain();
        if !(u > a && u < b) {
            return Err(Error::InvalidParameter {
                name: "u".into(),
                reason: format!("{u} is not strictly inside the parameter domain [{a}, {b}]"),
            });
        }
        if times == 0 {
            return Ok(self.clone());
        }
        let p = self.degree();
        let s = self.knots().multiplicity(u);
        if s + times > p {
            return Err(Error::InvalidParameter {
                name: "times".into(),
                reason: format!(
                    "inserting {u} {times} times onto multiplicity {s} exceeds the degree {p}"
                ),
            });
        }
        let up = self.knots().as_slice();
        let pw = homogeneous(self);
        let np = pw.len();
        let r = times;
        let k = self.find_span(u);
        // New knot vector: u inserted after the span's left knot u_k.
        let mut uq = self.knots().clone();
        for _ in 0..r {
            uq.insert(k + 1, u);
        }
        // Unaffected control points.
        let mut qw = vec![H::default(); np + r];
        qw[..=k - p].copy_from_slice(&pw[..=k - p]);
        qw[k - s + r..].copy_from_slice(&pw[k - s..]);
        let mut rw = [H::default(); MAX_ORDER];
        rw[..=p - s].copy_from_slice(&pw[k - p..=k - s]);
        for j in 1..=r {
            let l = k - p + j;
            for i in 0..=p - j - s {
                let alpha = (u - up[l + i]) / (up[i + k + 1] - up[l + i]);
                rw[i] = rw[i + 1].lin(alpha, rw[i], 1.0 - alpha);
            }
            qw[l] = rw[0];
            qw[k + r - j - s] = rw[p - j - s];
        }
        let l = k - p + r;
        if l + 1 < k - s {
            qw[l + 1..k - s].copy_from_slice(&rw[1..k - s - l]);
        }
        from_homogeneous(p, uq, &qw, self.weights().is_some())
    }

    /// Insert every value of `values` once (repeated [`BSplineCurve::insert_knot`]; the
    /// values need not be sorted, and a value may repeat up to the degree).
    ///
    /// # Errors
    /// As [`BSplineCurve::insert_knot`].
    pub fn insert_knots(&self, values: &[f64]) -> Result<BSplineCurve> {
        let mut c = self.clone();
        for &u in values {
            c = c.insert_knot(u, 1)?;
        }
        Ok(c)
    }

    /// Resolve a knot reference to `(r, u, s)`: the last index of its run, its value and its
    /// multiplicity. Only knots strictly inside the parameter domain qualify.
    fn interior_knot(&self, knot: KnotRef) -> Result<(usize, f64, usize)> {
        let u = self.knots().as_slice();
        let value = match knot {
            KnotRef::Index(i) => *u.get(i).ok_or_else(|| Error::InvalidParameter {
                name: "knot".into(),
                reason: format!("index {i} is beyond the {} knots", u.len()),
            })?,
            KnotRef::Value(v) => v,
        };
        let (a, b) = self.domain();
        if !(value > a && value < b) {
            return Err(Error::InvalidParameter {
                name: "knot".into(),
                reason: format!("{value} is not an interior knot of the domain [{a}, {b}]"),
            });
        }
        let Some(r) = u.iter().rposition(|&k| k == value) else {
            return Err(Error::InvalidParameter {
                name: "knot".into(),
                reason: format!("{value} is not a knot"),
            });
        };
        let s = u[..=r].iter().rev().take_while(|&&k| k == value).count();
        Ok((r, value, s))
    }

    /// Remove exactly one copy of the interior knot `knot`, whatever the deviation, placing
    /// the error as `rule` says, and report the largest deviation this causes. The fairing
    /// step of Sapidis and Farin is [`KnotRemoval::reinserted`] with [`RemovalRule::Middle`]:
    /// the input with one control point moved so that the curve is `C^p` at the knot.
    ///
    /// ```
    /// use batten::spline::{BSplineCurve, KnotRef, KnotVector, RemovalRule};
    /// use batten::Point;
    ///
    /// let pts = (0..7).map(|i| Point::new(i as f64, (i % 2) as f64)).collect();
    /// let knots = KnotVector::new(vec![0., 0., 0., 0., 0.25, 0.5, 0.75, 1., 1., 1., 1.]);
    /// let c = BSplineCurve::new(3, knots, pts, None);
    /// let step = c.remove_knot_exact(KnotRef::Value(0.5), RemovalRule::Middle).unwrap();
    /// assert_eq!(step.changed, vec![3]); // the control point under the knot
    /// assert_eq!(step.curve.control_points().len(), 6);
    /// // Only that control point differs, and the curve moved by the reported amount.
    /// let same = |i: usize| step.reinserted.control_points()[i] == c.control_points()[i];
    /// assert!((0..7).all(|i| i == 3 || same(i)));
    /// assert!(step.max_deviation > 0.5 && step.max_deviation < 1.5);
    /// ```
    ///
    /// A knot of multiplicity `p + 1` (where the curve may be discontinuous) is removed by
    /// merging the two control points at the break: `Left` keeps the left one, `Right` the
    /// right one, the other rules take their (homogeneous) midpoint.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when `knot` is not an interior knot;
    /// [`Error::Degenerate`] when a rational removal gives a non-positive weight.
    pub fn remove_knot_exact(&self, knot: KnotRef, rule: RemovalRule) -> Result<KnotRemoval> {
        let (r, u, s) = self.interior_knot(knot)?;
        let removal = self.remove_once(r, u, s, rule)?;
        let (lo, hi) = removal.support;
        let max_deviation = max_deviation(self, &removal.curve, lo, hi);
        Ok(KnotRemoval {
            curve: removal.curve,
            reinserted: removal.reinserted,
            changed: removal.changed,
            max_deviation,
        })
    }

    /// Remove the knot `knot` up to `times` times, each time only if the curve then stays
    /// within `tol` (data units) of the original everywhere. Returns the curve and the number
    /// of copies removed (0 when the knot is not removable within `tol`).
    ///
    /// Each copy is removed by [`RemovalRule::Middle`] (Tiller's A5.8, which solves from both
    /// ends); the deviation from the *original* curve is measured (as in
    /// [`KnotRemoval::max_deviation`]) after every removal, so deviations do not accumulate
    /// beyond `tol`. A removal that would make a weight non-positive counts as failing.
    /// Rounding makes even a removable knot deviate by a few ulps of the data: pass a `tol`
    /// of at least `1e-12` times the size of the curve.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when `knot` is not an interior knot, `times` exceeds its
    /// multiplicity, or `tol` is negative or not finite.
    pub fn remove_knot(
        &self,
        knot: KnotRef,
        times: usize,
        tol: f64,
    ) -> Result<(BSplineCurve, usize)> {
        if !(tol >= 0.0 && tol.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "tol".into(),
                reason: format!("{tol} must be non-negative and finite"),
            });
        }
        let (r, u, s) = self.interior_knot(knot)?;
        if times > s {
            return Err(Error::InvalidParameter {
                name: "times".into(),
                reason: format!("cannot remove knot {u} {times} times: its multiplicity is {s}"),
            });
        }
        let p = self.degree();
        let knots = self.knots().as_slice();
        let last_knot = knots.len() - 1;
        let mut current = self.clone();
        let mut removed = 0;
        for t in 0..times {
            // In `current` the run of u ends at r − t and has multiplicity s − t.
            let Ok(step) = current.remove_once(r - t, u, s - t, RemovalRule::Middle) else {
                break;
            };
            // The change since the original lies on [u_{r−p−t}, u_{r−s+p+1+t}] (original knots).
            let lo = knots[(r - p).saturating_sub(t)];
            let hi = knots[(r - s + p + 1 + t).min(last_knot)];
            if max_deviation(self, &step.curve, lo, hi) <= tol {
                current = step.curve;
                removed += 1;
            } else {
                break;
            }
        }
        Ok((current, removed))
    }

    /// One unconditional removal of the knot whose run ends at index `r` (value `u`,
    /// multiplicity `s`).
    fn remove_once(&self, r: usize, u: f64, s: usize, rule: RemovalRule) -> Result<OneRemoval> {
        let p = self.degree();
        let knots = self.knots().as_slice();
        let pw = homogeneous(self);
        let rational = self.weights().is_some();
        let mut new_knots = self.knots().clone();
        new_knots.remove(r);
        let mut reinserted = pw.clone();
        let (new_pw, changed) = if s > p {
            // Multiplicity p + 1: merge P_{r−p−1} and P_{r−p}.
            let (left, right) = (pw[r - p - 1], pw[r - p]);
            let (merged, changed) = match rule {
                RemovalRule::Left => (left, vec![r - p]),
                RemovalRule::Right => (right, vec![r - p - 1]),
                _ => (left.lin(0.5, right, 0.5), vec![r - p - 1, r - p]),
            };
            reinserted[r - p - 1] = merged;
            reinserted[r - p] = merged;
            let mut q = pw[..r - p - 1].to_vec();
            q.push(merged);
            q.extend_from_slice(&pw[r - p + 1..]);
            (q, changed)
        } else {
            let first = r - p;
            let last = r - s;
            let alpha = |i: usize| (u - knots[i]) / (knots[i + p + 1] - knots[i]);
            // q[j] = Q_{first−1+j}, j = 0..=p−s+1: the known neighbours at both ends.
            let e = last - first + 1;
            let solve_split = |k: usize| {
                let mut q = vec![H::default(); e + 1];
                q[0] = pw[first - 1];
                q[e] = pw[last + 1];
                for i in first..k {
                    let a = alpha(i);
                    q[i - first + 1] = pw[i].lin(1.0 / a, q[i - first], -(1.0 - a) / a);
                }
                for i in (k + 1..=last).rev() {
                    let a = alpha(i);
                    q[i - first] = pw[i].lin(1.0 / (1.0 - a), q[i - first + 1], -a / (1.0 - a));
                }
                q
            };
            let q = match rule {
                RemovalRule::Left => solve_split(last),
                RemovalRule::Right => solve_split(first),
                RemovalRule::Middle => solve_split(first + (p - s) / 2),
                RemovalRule::Average => {
                    let (l, rr) = (solve_split(last), solve_split(first));
                    l.iter()
                        .zip(&rr)
                        .map(|(a, b)| a.lin(0.5, *b, 0.5))
                        .collect()
                }
                RemovalRule::LeastSquares => least_change(&pw, first, last, &alpha),
            };
            let single = match rule {
                RemovalRule::Left => Some(last),
                RemovalRule::Right => Some(first),
                RemovalRule::Middle => Some(first + (p - s) / 2),
                _ => None,
            };
            let mut changed = Vec::new();
            for i in first..=last {
                if single.is_some_and(|k| k != i) {
                    continue;
                }
                let a = alpha(i);
                let v = q[i - first + 1].lin(a, q[i - first], 1.0 - a);
                if v != pw[i] {
                    changed.push(i);
                }
                reinserted[i] = v;
            }
            let mut new_pw = pw[..first].to_vec();
            new_pw.extend_from_slice(&q[1..e]);
            new_pw.extend_from_slice(&pw[last + 1..]);
            (new_pw, changed)
        };
        let curve = from_homogeneous(p, new_knots, &new_pw, rational)?;
        let reinserted = from_homogeneous(p, self.knots().clone(), &reinserted, rational)?;
        let lo_i = changed.first().copied().unwrap_or(r - p);
        let hi_i = changed.last().copied().unwrap_or(r - p);
        let support = (knots[lo_i], knots[(hi_i + p + 1).min(knots.len() - 1)]);
        Ok(OneRemoval {
            curve,
            reinserted,
            changed,
            support,
        })
    }

    /// The least-squares B-spline of `degree` with `n_ctrl` control points approximating
    /// `points` (Piegl–Tiller §9.4.1): parameters of the given kind normalised to [0, 1],
    /// clamped knots placed by eq 9.69 (`d = (m+1)/(n−p+1)`, `u_{p+j} = (1−α) t_{i−1} + α t_i`
    /// with `i = ⌊j d⌋`, `α = j d − i`), which puts data in every knot span; the first and last
    /// points are interpolated and the interior control points minimise `Σ_k |Q_k − C(t_k)|²`
    /// over the interior points. The normal equations are symmetric banded with half-bandwidth
    /// `degree` and are solved by [`SymBanded`] in O(m·p²). Returns the curve and the data
    /// parameters.
    ///
    /// Eq 9.69 assumes fewer control points than points: with as many, the least-squares
    /// curve is the interpolant, and [`BSplineCurve::interpolate`] (averaging knots) is
    /// returned. Close to that count the eq 9.69 knots leave some basis functions with a single
    /// data point near the tail of their support, and the normal equations become singular to
    /// working precision ([`Error::Singular`]): with 400 chord-length points of a smooth curve,
    /// from about 350 cubic control points on. Fit with clearly fewer control points than
    /// points, or interpolate.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a degree outside `1..MAX_ORDER` or `n_ctrl < degree + 1`;
    /// [`Error::TooFewPoints`] when there are fewer points than control points; the errors of
    /// [`parameters`]; [`Error::Singular`].
    pub fn approximate(
        points: &[Point],
        degree: usize,
        n_ctrl: usize,
        param: Parametrization,
    ) -> Result<(BSplineCurve, Vec<f64>)> {
        let p = degree;
        if p == 0 || p >= MAX_ORDER {
            return Err(Error::InvalidParameter {
                name: "degree".into(),
                reason: format!("must be in 1..={}", MAX_ORDER - 1),
            });
        }
        if n_ctrl < p + 1 {
            return Err(Error::InvalidParameter {
                name: "n_ctrl".into(),
                reason: format!("{n_ctrl} control points cannot carry degree {p}"),
            });
        }
        if points.len() < n_ctrl {
            return Err(Error::TooFewPoints {
                needed: n_ctrl,
                got: points.len(),
            });
        }
        if n_ctrl == points.len() {
            return BSplineCurve::interpolate(points, degree, param);
        }
        let mut t = parameters(points, param, false)?;
        let m = points.len() - 1;
        let total = t[m];
        for v in &mut t {
            *v /= total;
        }
        t[m] = 1.0;
        let n = n_ctrl - 1;
        let d = (m + 1) as f64 / (n - p + 1) as f64;
        let mut knots = vec![0.0; p + 1];
        for j in 1..=n - p {
            let jd = j as f64 * d;
            let i = (jd.floor() as usize).clamp(1, m);
            let a = jd - i as f64;
            knots.push((1.0 - a) * t[i - 1] + a * t[i]);
        }
        knots.extend(std::iter::repeat_n(1.0, p + 1));
        let knots = KnotVector::try_new(knots)?;
        let mut ctrl = vec![points[0]; n + 1];
        ctrl[n] = points[m];
        let curve = BSplineCurve::try_new(p, knots, ctrl.clone(), None)?;
        if n >= 2 {
            // Unknowns P_1..P_{n−1}, indices 0..n−2 in the system.
            let mut a = SymBanded::zeros(n - 1, p);
            let mut rhs = vec![Vec2::ZERO; n - 1];
            let mut b = [[0.0; MAX_ORDER]; 4];
            let (q0, qm) = (points[0].to_vec2(), points[m].to_vec2());
            for (&tk, q) in t.iter().zip(points).take(m).skip(1) {
                let span = curve.find_span(tk);
                curve.basis_derivs(span, tk, 0, &mut b);
                let nb = &b[0];
                // R_k = Q_k − N_0 Q_0 − N_n Q_m.
                let mut rk = q.to_vec2();
                for (j, &nj) in nb.iter().enumerate().take(p + 1) {
                    match span - p + j {
                        0 => rk -= q0 * nj,
                        c if c == n => rk -= qm * nj,
                        _ => {}
                    }
                }
                for j in 0..=p {
                    let row = span - p + j;
                    if row == 0 || row == n || nb[j] == 0.0 {
                        continue;
                    }
                    rhs[row - 1] += rk * nb[j];
                    for jj in 0..=j {
                        let col = span - p + jj;
                        if col == 0 || col == n {
                            continue;
                        }
                        a.add(row - 1, col - 1, nb[j] * nb[jj]);
                    }
                }
            }
            a.factorize()?;
            a.solve_in_place(&mut rhs)?;
            for (c, v) in ctrl[1..n].iter_mut().zip(rhs) {
                *c = v.to_point();
            }
        }
        Ok((curve.with_control_points(ctrl)?, t))
    }

    /// The same curve traversed backwards on the same domain: `C_rev(t) = C(a + b − t)` for
    /// the domain `[a, b]` (reversed knots `u'_i = u_p + (u_n − u_{n+p−i})`, control points and
    /// weights in reverse order). The end knots of the domain are reproduced to rounding.
    ///
    /// # Errors
    /// [`Error::InvalidKnots`] only if the reflected knots overflow.
    pub fn reverse(&self) -> Result<BSplineCurve> {
        let (a, b) = self.domain();
        let knots: Vec<f64> = self
            .knots()
            .as_slice()
            .iter()
            .rev()
            .map(|&k| a + (b - k))
            .collect();
        let pts = self.control_points().iter().rev().copied().collect();
        let w = self.weights().map(|w| w.iter().rev().copied().collect());
        BSplineCurve::try_new(self.degree(), KnotVector::try_new(knots)?, pts, w)
    }

    /// The curve moved by a rigid motion (B-splines and NURBS are affine invariant: the
    /// control points move, knots and weights stay).
    pub fn transform(&self, motion: &Rigid) -> BSplineCurve {
        let mut c = self.clone();
        for (i, &q) in self.control_points().iter().enumerate() {
            c.set_control_point(i, motion.apply(q));
        }
        c
    }

    /// The hodograph `C'(t)` as a B-spline of degree `p − 1` (Piegl–Tiller eq 3.8):
    /// control points `p (P_{i+1} − P_i)/(u_{i+p+1} − u_{i+1})` (zero where that knot
    /// difference vanishes), knots without the first and the last. Its "points" are the
    /// derivative vectors, returned as points.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a rational curve (its derivative is not a B-spline of
    /// lower degree) or a linear one (degree 0 is not a curve here); [`Error::InvalidKnots`]
    /// when an interior knot of multiplicity `p + 1` makes the result invalid.
    pub fn derivative_curve(&self) -> Result<BSplineCurve> {
        if self.weights().is_some() {
            return Err(Error::InvalidParameter {
                name: "curve".into(),
                reason: "the hodograph of a rational curve is not a B-spline".into(),
            });
        }
        let p = self.degree();
        if p < 2 {
            return Err(Error::InvalidParameter {
                name: "degree".into(),
                reason: "the hodograph of a degree-1 curve has degree 0".into(),
            });
        }
        let u = self.knots().as_slice();
        let pts: Vec<Point> = self
            .control_points()
            .windows(2)
            .enumerate()
            .map(|(i, w)| {
                let du = u[i + p + 1] - u[i + 1];
                if du > 0.0 {
                    ((w[1] - w[0]) * (p as f64 / du)).to_point()
                } else {
                    Point::ORIGIN
                }
            })
            .collect();
        let knots = KnotVector::try_new(u[1..u.len() - 1].to_vec())?;
        BSplineCurve::try_new(p - 1, knots, pts, None)
    }

    /// The exact cubic B-spline form of a piecewise cubic Hermite curve (open or closed):
    /// every interior knot `t_i` doubled, control points `P_0`, then per span the inner Bézier
    /// points `P_i + h_i T_i/3` and `P_{i+1} − h_i T_{i+1}/3`, then `P_m`. The knots are the
    /// spline's parameters, so `C(t)` equals the spline at every t (to rounding). A C² spline
    /// gives removable knots: [`BSplineCurve::remove_knot`] with a small tolerance brings it to
    /// the simple-knot C² form.
    pub fn from_parametric_cubic(spline: &ParametricCubic) -> Result<BSplineCurve> {
        let t = spline.knots();
        let pts = spline.points();
        let tan = spline.tangents();
        let m = spline.num_spans();
        let mut knots = vec![t[0]; 4];
        for &ti in &t[1..m] {
            knots.push(ti);
            knots.push(ti);
        }
        knots.extend(std::iter::repeat_n(t[m], 4));
        let mut ctrl = Vec::with_capacity(2 * m + 2);
        ctrl.push(pts[0]);
        for i in 0..m {
            let h = t[i + 1] - t[i];
            ctrl.push(pts[i] + tan[i] * (h / 3.0));
            ctrl.push(pts[i + 1] - tan[i + 1] * (h / 3.0));
        }
        ctrl.push(pts[m]);
        BSplineCurve::try_new(3, KnotVector::try_new(knots)?, ctrl, None)
    }
}

/// An unconditional removal before its deviation is measured.
struct OneRemoval {
    curve: BSplineCurve,
    reinserted: BSplineCurve,
    changed: Vec<usize>,
    /// Parameter interval outside which the curve did not change.
    support: (f64, f64),
}

/// The reduced control points (with the known neighbours at both ends, as `solve_split`
/// returns them) that minimise `Σ_{i=first}^{last} |α_i Q_i + (1 − α_i) Q_{i−1} − P_i|²`:
/// the normal equations are tridiagonal and positive definite, solved by the Thomas
/// algorithm.
fn least_change(pw: &[H], first: usize, last: usize, alpha: &dyn Fn(usize) -> f64) -> Vec<H> {
    let e = last - first + 1;
    let mut q = vec![H::default(); e + 1];
    q[0] = pw[first - 1];
    q[e] = pw[last + 1];
    let nu = e - 1; // unknowns q[1..e]
    if nu == 0 {
        return q;
    }
    let al: Vec<f64> = (first..=last).map(alpha).collect();
    // Row i (equation first+i): α_i q[i+1] + (1−α_i) q[i] = P_{first+i}; unknown j ↔ q[j+1].
    let b: Vec<H> = (0..e)
        .map(|i| {
            let mut v = pw[first + i];
            if i == 0 {
                v = v.lin(1.0, q[0], -(1.0 - al[0]));
            }
            if i == e - 1 {
                v = v.lin(1.0, q[e], -al[e - 1]);
            }
            v
        })
        .collect();
    // (AᵀA)_{jj} = α_j² + (1−α_{j+1})², (AᵀA)_{j,j+1} = α_{j+1}(1−α_{j+1}).
    let diag: Vec<f64> = (0..nu)
        .map(|j| al[j] * al[j] + (1.0 - al[j + 1]) * (1.0 - al[j + 1]))
        .collect();
    let off: Vec<f64> = (0..nu.saturating_sub(1))
        .map(|j| al[j + 1] * (1.0 - al[j + 1]))
        .collect();
    let mut rhs: Vec<H> = (0..nu)
        .map(|j| b[j].lin(al[j], b[j + 1], 1.0 - al[j + 1]))
        .collect();
    // Thomas algorithm (symmetric, positive definite: no pivoting needed).
    let mut c = vec![0.0; nu];
    let mut dd = diag[0];
    rhs[0] = rhs[0].scale(1.0 / dd);
    for j in 1..nu {
        c[j - 1] = off[j - 1] / dd;
        dd = diag[j] - off[j - 1] * c[j - 1];
        rhs[j] = rhs[j].lin(1.0 / dd, rhs[j - 1], -off[j - 1] / dd);
    }
    for j in (0..nu - 1).rev() {
        rhs[j] = rhs[j].lin(1.0, rhs[j + 1], -c[j]);
    }
    q[1..e].copy_from_slice(&rhs);
    q
}

/// `max_{t ∈ [lo, hi]} |a(t) − b(t)|`, span by span over the knot spans of `a` (whose knots
/// must contain those of `b`, so both are smooth on each span): samples, then Brent's method
/// around every local maximum of a span's samples. Only the spans meeting `[lo, hi]` are visited, so a
/// local removal costs O(p) evaluations whatever the size of the curve.
fn max_deviation(a: &BSplineCurve, b: &BSplineCurve, lo: f64, hi: f64) -> f64 {
    let (d0, d1) = a.domain();
    let (lo, hi) = (lo.max(d0), hi.min(d1));
    let dist = |t: f64| (a.eval(t) - b.eval(t)).length();
    let mut best = 0.0_f64;
    let u = a.knots().as_slice();
    let start = u.partition_point(|&k| k < lo).saturating_sub(1);
    // The first knot at or above `hi` closes the last span.
    let end = (u.partition_point(|&k| k < hi) + 1).min(u.len());
    for w in u[start..end].windows(2) {
        let (s0, s1) = (w[0].max(lo), w[1].min(hi));
        if s1 <= s0 {
            continue;
        }
        let h = (s1 - s0) / DEVIATION_SAMPLES_PER_SPAN as f64;
        let at = |j: usize| {
            if j == DEVIATION_SAMPLES_PER_SPAN {
                s1
            } else {
                s0 + h * j as f64
            }
        };
        let samples: [f64; DEVIATION_SAMPLES_PER_SPAN + 1] = std::array::from_fn(|j| dist(at(j)));
        // Every local maximum of the samples is refined, not only the largest: the distance
        // of two rational curves can have two bumps in one span, and the taller one need not
        // have the taller sample (a degree-1 rational removal was 0.08 % under-reported: the
        // case in tests/foundation.proptest-regressions).
        for j in 0..samples.len() {
            let left = j.checked_sub(1).map_or(f64::NEG_INFINITY, |k| samples[k]);
            let right = samples.get(j + 1).copied().unwrap_or(f64::NEG_INFINITY);
            best = best.max(samples[j]);
            if samples[j] < left || samples[j] < right {
                continue;
            }
            let refined = minimize_brent(
                |t| -dist(t),
                at(j.saturating_sub(1)),
                at((j + 1).min(DEVIATION_SAMPLES_PER_SPAN)),
                DEVIATION_REL_TOL,
                DEVIATION_REL_TOL * (s1 - s0),
                100,
            );
            best = best.max(-refined.fx);
        }
    }
    best
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::curve::CurveDeriv;

    fn wavy() -> BSplineCurve {
        let pts = (0..9)
            .map(|i| Point::new(i as f64, ((i * i) % 5) as f64 * 0.3))
            .collect();
        let knots = KnotVector::new(vec![
            0.0, 0.0, 0.0, 0.0, 0.1, 0.3, 0.45, 0.5, 0.8, 1.0, 1.0, 1.0, 1.0,
        ]);
        BSplineCurve::new(3, knots, pts, None)
    }

    #[test]
    fn insert_then_remove_round_trips() {
        let c = wavy();
        let c2 = c.insert_knot(0.6, 2).unwrap();
        assert_eq!(c2.control_points().len(), c.control_points().len() + 2);
        for k in 0..=50 {
            let t = k as f64 / 50.0;
            assert!((c.eval(t) - c2.eval(t)).length() < 1e-13);
        }
        let (c3, removed) = c2.remove_knot(KnotRef::Value(0.6), 2, 1e-12).unwrap();
        assert_eq!(removed, 2);
        assert_eq!(c3.knots(), c.knots());
        for (a, b) in c3.control_points().iter().zip(c.control_points()) {
            assert!((*a - *b).length() < 1e-12);
        }
    }

    #[test]
    fn deviation_covers_partial_spans() {
        // Between a curve and a copy with one control point moved, on windows whose ends are
        // not knots, the measured maximum matches a brute-force sample of the same window.
        let a = wavy();
        let mut b = a.clone();
        b.set_control_point(4, Point::new(4.0, 2.0));
        for (lo, hi) in [(0.2, 0.7), (0.31, 0.44), (0.0, 1.0), (0.46, 0.49)] {
            let got = max_deviation(&a, &b, lo, hi);
            let brute = (0..=20_000)
                .map(|k| lo + (hi - lo) * k as f64 / 20_000.0)
                .map(|t| (a.eval(t) - b.eval(t)).length())
                .fold(0.0, f64::max);
            assert!(
                got >= brute - 1e-12 && got <= brute * (1.0 + 1e-6),
                "{lo} {hi}"
            );
        }
    }

    #[test]
    fn middle_rule_is_farins_formula_for_cubics() {
        let c = wavy();
        let u = c.knots().as_slice().to_vec();
        let d = c.control_points();
        // Knot u_r = 0.3 at r = 5; Farin changes the control point under it, d_{r−2}, to the
        // weighted mean of L (extrapolated from d_{r−4}, d_{r−3}) and R (from d_{r−1}, d_r).
        let r = 5;
        let rem = c
            .remove_knot_exact(KnotRef::Index(r), RemovalRule::Middle)
            .unwrap();
        assert_eq!(rem.changed, vec![r - 2]);
        let v = |i: usize| d[i].to_vec2();
        let l =
            (v(r - 3) * (u[r + 1] - u[r - 3]) - v(r - 4) * (u[r + 1] - u[r])) / (u[r] - u[r - 3]);
        let rr = (v(r - 1) * (u[r + 3] - u[r - 1]) - v(r) * (u[r] - u[r - 1])) / (u[r + 3] - u[r]);
        let farin = (l * (u[r + 2] - u[r]) + rr * (u[r] - u[r - 2])) / (u[r + 2] - u[r - 2]);
        let got = rem.reinserted.control_points()[r - 2];
        assert!(
            (got.to_vec2() - farin).length() < 1e-12,
            "{got:?} {farin:?}"
        );
        // The reinserted curve is C³ at the knot.
        let jump = rem.reinserted.derivatives(0.3).d3 - rem.reinserted.derivatives_left(0.3).d3;
        assert!(jump.length() < 1e-9 * (1.0 + rem.reinserted.derivatives(0.3).d3.length()));
    }
}
