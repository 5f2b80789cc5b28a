//! The Kjellander–Poliakoff rules at one interior point of Hermite data: the third-derivative
//! jump `J_k`, the moves of Kjellander (eq 4), Poliakoff (eq 8) and the energy-optimal change
//! of position and tangent (eqs 11–12 as fixed in docs/algorithms/kjellander-poliakoff.md §2.5),
//! and the energy change of Lemma 1 (eq 14) (`docs/algorithms/kjellander-poliakoff.md`, "The
//! third-derivative jump and Kjellander", "Poliakoff", "The energy-optimal change of position and
//! tangent", §2.2–§2.5).

use crate::error::{Error, Result};
use crate::fair::engine::JUMP_ZERO_REL;
use crate::geom::{Point, Vec2};
use crate::spline::ParametricCubic;

/// Kjellander's rule (eq 4) needs unit parameter steps; steps within this relative distance
/// of 1 count as unit steps.
pub(super) const UNIT_STEP_REL: f64 = 1e-9;

/// The update rule for the bad point (docs/algorithms/kjellander-poliakoff.md §2.2–2.5).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum KpRule {
    /// Kjellander, eq 4: position only, uniform parameters with unit steps.
    Kjellander,
    /// Poliakoff, eq 8: the position that makes `J_k = 0` with all tangents kept.
    Poliakoff,
    /// The energy-optimal change of position and tangent, `(δ*, η*)` of eqs 11–12
    /// (docs/algorithms/kjellander-poliakoff.md §2.5).
    Energy,
    /// The energy-optimal change of position alone (`η = 0`): the corollary of
    /// docs/algorithms/kjellander-poliakoff.md §2.5, equal to Poliakoff's eq 8, computed from the
    /// energy quadratic.
    EnergyPositionOnly,
}

/// One move of the bad point `k` of Hermite data (see [`hermite_step`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct HermiteMove {
    /// The new position `r_k + δ`.
    pub point: Point,
    /// The new tangent `r'_k + η`.
    pub tangent: Vec2,
    /// The change of position `δ`.
    pub delta: Vec2,
    /// The change of tangent `η` (zero for the position-only rules).
    pub eta: Vec2,
    /// The third-derivative jump `J_k = r'''(t_k+) − r'''(t_k−)` before the move.
    pub jump: Vec2,
}

/// The Hermite data around an interior point k: spans `k−1` (length A) and `k` (length B).
#[derive(Clone, Copy, Debug)]
pub(super) struct Local {
    pub(super) a: f64,
    pub(super) b: f64,
    pub(super) rp: Point,
    pub(super) r: Point,
    pub(super) rn: Point,
    pub(super) mp: Vec2,
    pub(super) m: Vec2,
    pub(super) mn: Vec2,
}

/// KP eq 6: the coefficients `(a2, a3)` of the Hermite span from `(p0, d0)` to `(p1, d1)`
/// of parameter length `h`.
#[inline]
fn hermite_a23(p0: Point, p1: Point, d0: Vec2, d1: Vec2, h: f64) -> (Vec2, Vec2) {
    let dp = p1 - p0;
    let a2 = dp * (3.0 / (h * h)) - (d0 * 2.0 + d1) / h;
    let a3 = dp * (-2.0 / (h * h * h)) + (d0 + d1) / (h * h);
    (a2, a3)
}

impl Local {
    fn spans(&self) -> ((Vec2, Vec2), (Vec2, Vec2)) {
        (
            hermite_a23(self.rp, self.r, self.mp, self.m, self.a),
            hermite_a23(self.r, self.rn, self.m, self.mn, self.b),
        )
    }

    /// `J_k = 6(a_{k,3} − a_{k−1,3})` (docs/algorithms/kjellander-poliakoff.md §2.2).
    pub(super) fn jump(&self) -> Vec2 {
        let ((_, a3p), (_, a3n)) = self.spans();
        (a3n - a3p) * 6.0
    }

    /// `|J_k|`, or 0 when it is within [`JUMP_ZERO_REL`] of the size of the terms of the two
    /// `a_3` it is the difference of (absolute positions included: their rounding is in the
    /// differences).
    pub(super) fn badness(&self) -> f64 {
        // L1 norms: an upper bound of the Euclidean ones, and cheap (no hypot in the hot loop).
        let l1 = |v: Vec2| v.x.abs() + v.y.abs();
        let mag = |p0: Point, p1: Point, d0: Vec2, d1: Vec2, h: f64| {
            2.0 * (l1(p0.to_vec2()) + l1(p1.to_vec2())) / (h * h * h) + (l1(d0) + l1(d1)) / (h * h)
        };
        let floor = 6.0
            * JUMP_ZERO_REL
            * (mag(self.rp, self.r, self.mp, self.m, self.a)
                + mag(self.r, self.rn, self.m, self.mn, self.b));
        let j = self.jump().length();
        if j <= floor { 0.0 } else { j }
    }

    /// The change `(δ, η)` of position and tangent by `rule`.
    pub(super) fn step(&self, rule: KpRule) -> (Vec2, Vec2) {
        let (a, b) = (self.a, self.b);
        match rule {
            KpRule::Kjellander => {
                // Eq 4.
                let new = self.rp.midpoint(self.rn) + (self.mp - self.mn) * 0.25;
                (new - self.r, Vec2::ZERO)
            }
            KpRule::Poliakoff => {
                // Eq 8.
                let (a2, b2) = (a * a, b * b);
                let (a3, b3) = (a2 * a, b2 * b);
                let w = 1.0 / a3 + 1.0 / b3;
                let num = self.rp.to_vec2() / a3 + self.rn.to_vec2() / b3 + self.mp / (2.0 * a2)
                    - self.mn / (2.0 * b2)
                    + self.m * (0.5 * (1.0 / a2 - 1.0 / b2));
                ((num / w).to_point() - self.r, Vec2::ZERO)
            }
            KpRule::Energy => {
                // Eqs 11–12 as fixed in docs/algorithms/kjellander-poliakoff.md §2.5.
                let ((a2p, a3p), (a2n, a3n)) = self.spans();
                let j3 = a3p - a3n;
                let j2 = a2n - a2p - a3p * (3.0 * a);
                let s = a + b;
                let s3 = s * s * s;
                let delta = (j3 * (2.0 * a * b) + j2 * (b - a)) * (a * a * b * b / s3);
                let eta = (j3 * (3.0 * a * b * (b - a)) + j2 * (2.0 * (a * a - a * b + b * b)))
                    * (a * b / s3);
                (delta, eta)
            }
            KpRule::EnergyPositionOnly => {
                // The corollary of docs/algorithms/kjellander-poliakoff.md §2.5: minimise F(δ, 0).
                let ((_, a3p), (_, a3n)) = self.spans();
                let j3 = a3p - a3n;
                (j3 / (2.0 / (a * a * a) + 2.0 / (b * b * b)), Vec2::ZERO)
            }
        }
    }

    /// `F(δ, η)` of Lemma 1 (eq 14, docs/algorithms/kjellander-poliakoff.md §2.5): `W' − W = 4C·F`.
    pub(super) fn energy_f(&self, delta: Vec2, eta: Vec2) -> f64 {
        let (a, b) = (self.a, self.b);
        let ((a2p, a3p), (a2n, a3n)) = self.spans();
        (a3n - a3p).dot(delta) * 3.0
            + (a2p + a3p * (3.0 * a) - a2n).dot(eta)
            + (3.0 / (a * a * a) + 3.0 / (b * b * b)) * delta.length_squared()
            + (1.0 / a + 1.0 / b) * eta.length_squared()
            + (3.0 / (b * b) - 3.0 / (a * a)) * delta.dot(eta)
    }
}

/// Check Hermite data and pick out the neighbourhood of interior point `k` (0-based).
fn hermite_local(t: &[f64], points: &[Point], tangents: &[Vec2], k: usize) -> Result<Local> {
    check_hermite(t, points, tangents)?;
    let n = points.len();
    if k == 0 || k + 1 >= n {
        return Err(Error::InvalidParameter {
            name: "k".into(),
            reason: format!("point {k} is not an interior point of {n} points"),
        });
    }
    Ok(Local {
        a: t[k] - t[k - 1],
        b: t[k + 1] - t[k],
        rp: points[k - 1],
        r: points[k],
        rn: points[k + 1],
        mp: tangents[k - 1],
        m: tangents[k],
        mn: tangents[k + 1],
    })
}

/// Validate Hermite data: equal lengths, at least 3 points, finite values, increasing `t`.
pub(super) fn check_hermite(t: &[f64], points: &[Point], tangents: &[Vec2]) -> Result<()> {
    let n = points.len();
    if n < 3 {
        return Err(Error::TooFewPoints { needed: 3, got: n });
    }
    for (what, len) in [("parameters", t.len()), ("tangents", tangents.len())] {
        if len != n {
            return Err(Error::LengthMismatch {
                what,
                got: len,
                expected: n,
            });
        }
    }
    if let Some(index) = points.iter().position(|p| !p.is_finite()) {
        return Err(Error::NonFinite { index });
    }
    if let Some(index) = tangents.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite { index });
    }
    if let Some(index) = t.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite { index });
    }
    if let Some(i) = t.windows(2).position(|w| w[1] <= w[0]) {
        return Err(Error::NotIncreasing { index: i + 1 });
    }
    Ok(())
}

/// Kjellander's eq 4 assumes `t_{i+1} − t_i = 1`.
pub(super) fn check_unit_steps(t: &[f64]) -> Result<()> {
    if let Some(i) = t
        .windows(2)
        .position(|w| ((w[1] - w[0]) - 1.0).abs() > UNIT_STEP_REL)
    {
        return Err(Error::InvalidParameter {
            name: "t".into(),
            reason: format!(
                "Kjellander's rule (eq 4) needs unit parameter steps; t[{}] − t[{i}] = {}",
                i + 1,
                t[i + 1] - t[i]
            ),
        });
    }
    Ok(())
}

/// One move of the interior point `k` (0-based) of the Hermite data `(t, points, tangents)`
/// by `rule`: the new position and tangent, the changes `δ`, `η` and the jump `J_k` before
/// the move. Nothing else changes: the other points, all other tangents and the parameters
/// are kept (the setting of docs/algorithms/kjellander-poliakoff.md §2.2–2.5).
///
/// Kjellander's and Poliakoff's rules keep the tangent (`η = 0`); [`KpRule::Energy`] returns
/// `(δ*, η*)` of eqs 11–12. For tangents of a C² spline, `δ*` is Poliakoff's move scaled by
/// `4(A³ + B³)/(A + B)³` (docs/algorithms/kjellander-poliakoff.md §2.5).
///
/// # Errors
/// [`Error::TooFewPoints`], [`Error::LengthMismatch`], [`Error::NonFinite`],
/// [`Error::NotIncreasing`] for bad data; [`Error::InvalidParameter`] when `k` is not
/// interior, or for [`KpRule::Kjellander`] when a parameter step is not 1.
pub fn hermite_step(
    rule: KpRule,
    t: &[f64],
    points: &[Point],
    tangents: &[Vec2],
    k: usize,
) -> Result<HermiteMove> {
    let local = hermite_local(t, points, tangents, k)?;
    if rule == KpRule::Kjellander {
        check_unit_steps(t)?;
    }
    let (delta, eta) = local.step(rule);
    Ok(HermiteMove {
        point: local.r + delta,
        tangent: local.m + eta,
        delta,
        eta,
        jump: local.jump(),
    })
}

/// The quadratic `F(δ, η)` of Lemma 1 (eq 14, docs/algorithms/kjellander-poliakoff.md §2.5) at the
/// interior point `k` (0-based) of Hermite data: changing `r_k` by `δ` and `r'_k` by `η`, all other
/// data kept, changes the energy `∫|r''|² dt` by exactly `4F`.
///
/// # Errors
/// As [`hermite_step`].
pub fn energy_change_f(
    t: &[f64],
    points: &[Point],
    tangents: &[Vec2],
    k: usize,
    delta: Vec2,
    eta: Vec2,
) -> Result<f64> {
    Ok(hermite_local(t, points, tangents, k)?.energy_f(delta, eta))
}

/// The parametric energy `∫|r''(t)|² dt` of a cubic spline (docs/algorithms/README.md §0.4, the
/// `W/C` of KP §2.5), in closed form span by span: `4|a2|²Δ + 12(a2·a3)Δ² + 12|a3|²Δ³`.
pub fn parametric_energy(curve: &ParametricCubic) -> f64 {
    let t = curve.knots();
    (0..curve.num_spans())
        .map(|i| {
            let [_, _, a2, a3] = curve.span_coeffs(i);
            let h = t[i + 1] - t[i];
            4.0 * a2.length_squared() * h
                + 12.0 * a2.dot(a3) * h * h
                + 12.0 * a3.length_squared() * h * h * h
        })
        .sum()
}
