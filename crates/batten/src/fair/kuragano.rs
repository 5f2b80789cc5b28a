//! `kuragano`: radius-of-curvature specification, shape modification and fairness evaluation
//! of Kuragano & Yamaguchi, *NURBS curve shape modification and fairness evaluation*
//! (`../shared/papers/kuragano-nurbs-roc-fairness.txt`, §4–§5), as specified (with fixes) in
//! `../shared/spec/ALGORITHMS.md` §5.2 and §5.4–§5.6. The curve is the uniform quintic of
//! [`crate::spline::quintic`] (§5.1, §5.3).
//!
//! # Radius-of-curvature specification (paper §4, spec §5.4)
//!
//! The curve is sampled at `N_s` equally spaced fractions of its normalised arc length,
//! `s_i = i/(N_s − 1)` ([`sample_rho`]; arc length by Gauss–Legendre per span and Newton
//! inversion, spec §0.5). **\[CHOICE\]** `N_s` is [`DEFAULT_SAMPLES`] (41, the test vectors'
//! value) or [`SAMPLES_PER_SEGMENT`] per segment plus one, whichever is larger
//! ([`default_samples`]): with fewer samples than unknowns the shape modification is
//! under-determined. ρ is the signed radius (spec §5.2), capped at `±ρ_max` **\[CHOICE\]**,
//! default [`DEFAULT_RHO_MAX_REL`] times the arc length: a sample whose curvature is smaller in
//! magnitude than `1/ρ_max` counts as straight and gets `σ·ρ_max`, where `σ` is the
//! orientation of the curve (the sign of its total sampled curvature). [`RhoFit`] fits a
//! polynomial `ρ̂(s)` of degree 1..=6 by linear least squares on the Chebyshev basis
//! `T_k(2s − 1)` (a scaled basis, as the spec asks); it reports monomial coefficients too.
//! A degree is **not applicable** when `σ·ρ̂(s_i) ≤ 0` at some sample (paper: "if the radius of
//! curvature is negative"); a designed curve with an inflection (a sample with `σκ < −1/ρ_max`)
//! or with no curvature at all has no valid ρ distribution, and every degree is not
//! applicable.
//!
//! # Shape modification (paper eqs 10–13, spec §5.5)
//!
//! [`modify_shape`] moves the interior control points `q_1..q_{n−2}` (both coordinates; `q_0`
//! and `q_{n−1}` are fixed \[PAPER\]) to minimise `S = Σ δ_i²`, `δ_i = ρ_i(q) − ρ̂_i` (eqs 10–11)
//! with `ρ̂_i` fixed. The Jacobian holds each sample's parameter `u_i` fixed
//! ([`rho_gradient`], the formula of spec §5.5); after every step `L` is recomputed and the
//! `s_i` re-sampled to new `u_i` \[PAPER\]. **\[FIX\]** the literal Gauss–Newton step of eqs 12–13
//! diverges (spec §5.5); this is Levenberg–Marquardt exactly as the spec prescribes:
//! `A = JᵀJ + μ·diag(JᵀJ)`, `μ_0 =` [`MU_INITIAL`], a step is accepted only if S decreases,
//! then `μ /= 10`, else `μ *= 10`; it stops when no step can be accepted (μ beyond
//! [`MU_MAX`]) or after the iteration cap ([`DEFAULT_MAX_ITERATIONS`], counted in
//! linearisations). `JᵀJ` is a symmetric band (a sample touches six consecutive control
//! points, twelve unknowns), so each step is an O(n) [`SymBanded`] solve; the diagonal used for
//! the Marquardt scaling is floored at [`DIAG_FLOOR_REL`] times its largest entry, so that
//! unknowns no sample sees do not make `A` singular.
//!
//! Residual forms ([`Residual`]): `Rho` uses `δ_i = ρ_i − ρ̂_i`, **switching automatically to
//! the curvature form** `(1/ρ̂_i − κ_i)·ρ̂_i²` at samples where ρ is infinite or capped (an
//! inflection or a straight part: `σκ_i < 1/ρ_max`). The two agree to first order at
//! `ρ = ρ̂`, and the curvature form stays finite where ρ does not (the paper: the radius "is
//! converted to curvature value for computation"). The choice is made per sample at each
//! linearisation and kept for its trial steps, so the S values compared are consistent.
//! `Kappa` uses `κ_i − 1/ρ̂_i` everywhere, with `∂κ = −∂ρ/ρ²` (spec §5.5, the equivalent
//! variant); its S is in curvature units.
//!
//! # Fairness evaluation (paper §5, spec §5.6)
//!
//! [`evaluate`] runs the specification and the shape modification for every applicable
//! degree, giving the "predefined" curves `C_d`; the similarity is the cosine of the designed
//! ρ samples and those of `C_d` at the same `s_i`, **not mean-centred** \[PAPER\]; its angle in
//! degrees is `arccos(cos)·180/π` (the paper's tables *truncate* it to two decimals:
//! [`truncate_angle`]). The best degree is the one with the largest cosine; cosines within
//! [`TIE_TOLERANCE`] (10⁻⁴) of the largest are a tie, resolved to the lowest degree, so that
//! exact samples of a log spiral (ρ linear in s) evaluate as degree 1 and a curve with ρ
//! quadratic in s as degree 2; the paper breaks ties at its printed precision, which
//! [`select_best_within`] with [`PAPER_TIE_TOLERANCE`] reproduces. The fairness of
//! the design is that cosine. Remark (spec §5.6.5): with a perfect shape modification the
//! cosine would be non-decreasing in d, so the paper's non-monotone tables reflect imperfect
//! modification.
//!
//! # The fairing method
//!
//! [`Kuragano`] fairs a point sequence: the quintic interpolant (ends: see
//! [`DesignEnds`]; default natural ends would make ρ infinite at both ends, spec §5.3, so the
//! default is [`DesignEnds::Gradients`] with estimated end gradients of magnitude
//! [`DEFAULT_METHOD_GRADIENT_FRACTION`] of the end chord), the degree (`degree=d`, default:
//! the best degree of [`evaluate`]), the shape modification, and the modified curve evaluated
//! at the input points' parameters `u = 0, 1, …, m−1` (same count and order).
//!
//! - `--tolerance` is a hard bound: a trial step that would move any output point farther
//!   than the tolerance from its input is rejected like a step that does not decrease S
//!   (`μ *= 10`, so the next trial is shorter). The interpolant starts at zero displacement,
//!   so the bound always holds.
//! - `--fix-ends`: `q_0` and `q_{n−1}` are fixed anyway, but the curve's end points
//!   `R(0) = (q_0 + 26q_1 + 66q_2 + 26q_3 + q_4)/120` (eq 8) move with `q_1..q_4`. With
//!   fix-ends, `q_2` (and `q_{n−3}` at the other end, the control points with the largest eq-8
//!   weight) are eliminated: they are recomputed from the other control points after every step
//!   so that `R(0) = P_0` and `R(m−1) = P_{m−1}` hold exactly (to rounding); the Jacobian is
//!   taken through the elimination (chain rule). The output's end points are the input's.
//! - The report's parameters carry the degree, `N_s`, `ρ_max`, the initial and final S and the
//!   RMS of `ρ_i − ρ̂_i` after the modification.
//!
//! Straight input, and input whose interpolant has an inflection, have no applicable degree
//! (spec §5.4.4): with `degree=auto` the method returns the input unchanged (status
//! `no_change`) with a note. **\[CHOICE\]** With an explicit `degree=d` and an inflected design
//! (typically noise), ρ̂ is fitted to the samples where ρ is valid (finite, with the curve's
//! orientation) and the shape modification, whose residual takes the curvature form at the
//! inflected samples, removes the inflections; without inflections the explicit degree uses the
//! spec's fit. A degree whose ρ̂ changes sign is an error.
//!
//! **What to expect.** The method specifies the *shape* (ρ as a function of normalised arc
//! length), not closeness to the points: a small change of ρ(s) integrates twice along the arc,
//! and the fixed-u Jacobian lets the parametrisation drift, so without a tolerance the output
//! points can move by a sizeable fraction of the point spacing even on mildly noisy data (a
//! 25-point spiral with 3·10⁻⁴ radial noise: ρ matched to an RMS of 2·10⁻⁴, points moved by
//! 0.16 at a spacing of 0.25). Use `--tolerance` to bound that; heavy noise can also make the
//! parametrisation degenerate between samples (near-zero speed, a curvature spike no ρ sample
//! sees), which more `samples` mitigate.
//!
//! # Performance
//!
//! The uniform quintic is evaluated in closed form ([`quintic::basis`], and the segments'
//! power form for the speed), the arc-length inversion continues Newton's iteration from the
//! previous sample, and each LM step is a band solve: one linearisation costs O(n + N_s).
//!
//! # Where this departs from the paper or the spec
//!
//! - Levenberg–Marquardt instead of the printed Gauss–Newton step: the spec's \[FIX\] (§5.5).
//! - The r = 3 row of the spec's §5.1 table has two signs flipped (see [`quintic::ROWS`]).
//! - \[CHOICE\]s made here: `N_s` ([`default_samples`]), `ρ_max` ([`DEFAULT_RHO_MAX_REL`]),
//!   the orientation and inflection rule, the curvature form at infinite ρ, the method's end
//!   gradients (a full end chord instead of the paper's third,
//!   [`DEFAULT_METHOD_GRADIENT_FRACTION`]), the valid-sample fit for an explicit degree on an
//!   inflected design, and `fix_ends` by elimination. With `--fix-ends=tangent` or
//!   `curvature` every control point whose basis function is non-zero at a domain end is
//!   held instead ([`ShapeConstraints::hold_end_derivatives`]), which keeps the end points,
//!   tangents and curvatures of the quintic exactly.

use std::sync::OnceLock;

use serde::Serialize;
use serde_json::{Map, Value, json};

use super::{FairMethod, FairOptions, FairStatus, HistoryRow, Outcome, ParamSpec};
use crate::curve::{Curve, Piecewise};
use crate::error::{Error, Result};
use crate::geom::{Point, PointSeq, Vec2};
use crate::numeric::{GaussLegendre, SymBanded};
use crate::spline::quintic::{self, Ends, QuinticForm};
use crate::spline::{BSplineCurve, MAX_ORDER};

/// Default number of ρ samples `N_s` (spec §5.4 and the test vectors).
pub const DEFAULT_SAMPLES: usize = 41;

/// Samples per segment in the automatic `N_s` (spec §5.4: "about 10 per segment").
pub const SAMPLES_PER_SEGMENT: usize = 10;

/// Fewest samples accepted: a degree-6 fit needs seven.
pub const MIN_SAMPLES: usize = MAX_DEGREE + 1;

/// Most samples accepted when given (`samples`, `evaluate --samples`): each iteration
/// samples ρ and fits the design at every one, about 1 s per 10⁵ for the evaluation and the
/// shape modification (10⁶ took 11 s and 200 MB, 10⁷ 49 s and 1.9 GB; 2⁶⁴ overflowed the
/// allocation). The automatic count, 10 per segment, is not capped.
pub const MAX_SAMPLES: usize = 100_000;

/// The default cap `ρ_max`, relative to the arc length of the curve: a sample whose radius
/// exceeds 100 curve lengths (an arc turning by less than about 0.6°) counts as straight.
pub const DEFAULT_RHO_MAX_REL: f64 = 100.0;

/// Lowest polynomial degree of the specification (linear).
pub const MIN_DEGREE: usize = 1;

/// Highest polynomial degree of the specification ("six degrees", paper §5).
pub const MAX_DEGREE: usize = 6;

/// Initial Levenberg–Marquardt damping (spec §5.5).
pub const MU_INITIAL: f64 = 1e-3;

/// Factor by which μ is divided after an accepted step and multiplied after a rejected one
/// (spec §5.5).
pub const MU_FACTOR: f64 = 10.0;

/// Damping beyond which no step is deemed acceptable and the iteration stops: the step is
/// then shorter than rounding of the control points.
pub const MU_MAX: f64 = 1e12;

/// Default cap on linearisations of the shape modification (the test vectors' 60).
pub const DEFAULT_MAX_ITERATIONS: usize = 60;

/// Floor of the Marquardt scaling `diag(JᵀJ)`, relative to its largest entry.
pub const DIAG_FLOOR_REL: f64 = 1e-12;

/// Cosines within this of the largest are a tie, resolved to the lowest degree (spec §5.6):
/// a higher degree is chosen only when it follows the design's ρ better by more than this.
///
/// The paper breaks ties at its printed precision (Table 3 prints three decimals, Table 4
/// the angle to 0.01°). 10⁻⁴ is the size of what separates degrees on exact samples of
/// curves whose ρ *is* a low-degree polynomial: the design's ρ comes from the quintic
/// interpolant with estimated end gradients, whose ρ is off by about 1 % near the ends, and
/// higher degrees follow that error a little better (a 60-point log spiral, ρ linear in s:
/// 0.999688 for degree 1, 0.999778 for degree 6; a curve with ρ quadratic in s: 0.999736
/// for degree 2, 0.999800 for degree 6). The paper's own choices in Table 2 (six, 0.99993
/// against 0.99981 for quintic) and Table 4 (curves A, E, F, H) are kept; its curve B
/// (quintic 1.56° against quartic 1.58°, cosines 10⁻⁵ apart) would be quartic.
/// [`select_best_within`] with [`PAPER_TIE_TOLERANCE`] reproduces the paper's choices.
pub const TIE_TOLERANCE: f64 = 1e-4;

/// The tie tolerance that reproduces every choice of the paper's Table 4 (curve B
/// included): two cosines near 1.5° that print as angles 0.02° apart differ by about 10⁻⁵.
pub const PAPER_TIE_TOLERANCE: f64 = 1e-6;

/// End-gradient magnitude used by the fairing method, as a fraction of the end chord. The
/// interpolant's parameter advances by one per point, so `|dR/du|` is about one chord; the
/// paper's default of one third ([`quintic::DEFAULT_GRADIENT_FRACTION`]) slows the curve
/// down near its ends and puts curvature peaks there.
pub const DEFAULT_METHOD_GRADIENT_FRACTION: f64 = 1.0;

/// Which residual the shape modification minimises (spec §5.5).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum Residual {
    /// `ρ_i − ρ̂_i`, with the curvature form where ρ is infinite or capped.
    #[default]
    Rho,
    /// `κ_i − 1/ρ̂_i` everywhere.
    Kappa,
}

/// The end conditions of the designed curve when [`evaluate`] or the method starts from
/// points.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum DesignEnds {
    /// `R'' = 0`, `R'''' = 0` at both ends (ρ is infinite there).
    Natural,
    /// Gradients at point indices `0, 1, m−2, m−1` estimated by
    /// [`quintic::end_gradients`] with this fraction of the end chord as magnitude.
    Gradients {
        /// Magnitude of each gradient relative to the end chord.
        fraction: f64,
    },
}

/// Options of the specification, shape modification and evaluation.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct KuraganoOptions {
    /// Number of ρ samples `N_s`, in [`MIN_SAMPLES`]`..=`[`MAX_SAMPLES`]; `None`: [`default_samples`].
    ///
    /// Default value: `None`.
    pub samples: Option<usize>,
    /// The cap `ρ_max` in data units; `None`: [`DEFAULT_RHO_MAX_REL`] times the arc length.
    ///
    /// Default value: `None`.
    pub rho_max: Option<f64>,
    /// The residual of the shape modification.
    ///
    /// Default value: [`Residual::Rho`].
    pub residual: Residual,
    /// Cap on Levenberg–Marquardt linearisations.
    ///
    /// Default value: [`DEFAULT_MAX_ITERATIONS`].
    pub max_iterations: usize,
    /// Ends of the interpolant when the design is given as points.
    ///
    /// Default value: `Gradients { fraction: DEFAULT_METHOD_GRADIENT_FRACTION }`.
    pub ends: DesignEnds,
}

impl KuraganoOptions {
    /// The defaults listed on the fields.
    pub const DEFAULT: KuraganoOptions = KuraganoOptions {
        samples: None,
        rho_max: None,
        residual: Residual::Rho,
        max_iterations: DEFAULT_MAX_ITERATIONS,
        ends: DesignEnds::Gradients {
            fraction: DEFAULT_METHOD_GRADIENT_FRACTION,
        },
    };

    /// Set `N_s`.
    pub fn with_samples(mut self, n: usize) -> KuraganoOptions {
        self.samples = Some(n);
        self
    }

    /// Set `ρ_max` (data units).
    pub fn with_rho_max(mut self, rho_max: f64) -> KuraganoOptions {
        self.rho_max = Some(rho_max);
        self
    }

    /// Set the residual form.
    pub fn with_residual(mut self, residual: Residual) -> KuraganoOptions {
        self.residual = residual;
        self
    }

    /// Set the iteration cap.
    pub fn with_max_iterations(mut self, n: usize) -> KuraganoOptions {
        self.max_iterations = n;
        self
    }

    /// Set the ends of the interpolant of a point design.
    pub fn with_ends(mut self, ends: DesignEnds) -> KuraganoOptions {
        self.ends = ends;
        self
    }

    fn check(&self) -> Result<()> {
        if let Some(n) = self.samples
            && !(MIN_SAMPLES..=MAX_SAMPLES).contains(&n)
        {
            return Err(Error::InvalidParameter {
                name: "samples".into(),
                reason: format!("{n} is outside [{MIN_SAMPLES}, {MAX_SAMPLES}]"),
            });
        }
        if let Some(r) = self.rho_max
            && !(r.is_finite() && r > 0.0)
        {
            return Err(Error::InvalidParameter {
                name: "rho_max".into(),
                reason: format!("must be positive and finite, got {r}"),
            });
        }
        if let DesignEnds::Gradients { fraction } = self.ends
            && !(fraction.is_finite() && fraction > 0.0)
        {
            return Err(Error::InvalidParameter {
                name: "gradient_fraction".into(),
                reason: format!("must be positive and finite, got {fraction}"),
            });
        }
        Ok(())
    }
}

impl Default for KuraganoOptions {
    fn default() -> KuraganoOptions {
        KuraganoOptions::DEFAULT
    }
}

/// The automatic `N_s` for a curve of `segments` spans: `max(41, 10·segments + 1)`.
pub fn default_samples(segments: usize) -> usize {
    DEFAULT_SAMPLES.max(SAMPLES_PER_SEGMENT * segments + 1)
}

/// ρ sampled at equally spaced fractions of the normalised arc length (spec §5.4 steps 1–2).
#[derive(Clone, Debug, PartialEq)]
pub struct RhoSamples {
    /// The fractions `s_i = i/(N_s − 1)`.
    pub s: Vec<f64>,
    /// The curve parameters `u_i` with arc length `s_i·L`.
    pub u: Vec<f64>,
    /// Signed curvature at `u_i`.
    pub kappa: Vec<f64>,
    /// Signed radius of curvature `1/κ_i`, or `σ·ρ_max` where `|κ_i| < 1/ρ_max`.
    pub rho: Vec<f64>,
    /// The arc length L.
    pub length: f64,
    /// The cap `ρ_max` used.
    pub rho_max: f64,
    /// The orientation σ: +1 when the total sampled curvature is non-negative, else −1.
    pub sigma: f64,
    /// True when some sample bends against the orientation (`σκ_i < −1/ρ_max`): an inflection.
    pub inflected: bool,
    /// True when every sample is straight (`|κ_i| < 1/ρ_max`).
    pub straight: bool,
}

impl RhoSamples {
    /// Fill `rho`, `sigma`, `inflected` and `straight` from `kappa` and `rho_max`:
    /// `ρ_i = 1/κ_i` where `|κ_i| ≥ 1/ρ_max`, else `σ·ρ_max`.
    fn orient_and_cap(&mut self, sigma: Option<f64>) {
        let k_min = 1.0 / self.rho_max;
        let total: f64 = self.kappa.iter().filter(|k| k.abs() >= k_min).sum();
        self.sigma = sigma.unwrap_or(if total >= 0.0 { 1.0 } else { -1.0 });
        self.straight = self.kappa.iter().all(|k| k.abs() < k_min);
        self.inflected = self.kappa.iter().any(|k| self.sigma * k <= -k_min);
        let (sigma, rho_max) = (self.sigma, self.rho_max);
        self.rho = self
            .kappa
            .iter()
            .map(|&k| {
                if k.abs() >= k_min {
                    1.0 / k
                } else {
                    sigma * rho_max
                }
            })
            .collect();
    }
}

/// Sample ρ at `n_samples` equally spaced normalised arc-length fractions (spec §5.4 steps
/// 1–2). `rho_max: None` caps at [`DEFAULT_RHO_MAX_REL`] times the length.
///
/// # Errors
/// [`Error::InvalidParameter`] for fewer than two samples or a bad `rho_max`,
/// [`Error::Degenerate`] for a curve of zero or non-finite length.
pub fn sample_rho(
    curve: &BSplineCurve,
    n_samples: usize,
    rho_max: Option<f64>,
) -> Result<RhoSamples> {
    if n_samples < 2 {
        return Err(Error::InvalidParameter {
            name: "samples".into(),
            reason: format!("at least two are needed, got {n_samples}"),
        });
    }
    let mut out = sample_at_fractions(curve, n_samples)?;
    out.rho_max = match rho_max {
        None => DEFAULT_RHO_MAX_REL * out.length,
        Some(r) if r.is_finite() && r > 0.0 => r,
        Some(r) => {
            return Err(Error::InvalidParameter {
                name: "rho_max".into(),
                reason: format!("must be positive and finite, got {r}"),
            });
        }
    };
    out.orient_and_cap(None);
    Ok(out)
}

/// Arc length, parameters and curvature at the fractions; `rho` etc. left for the caller.
///
/// Arc length by Gauss–Legendre on every span (spec §0.5); each `s_i·L` is inverted by
/// Newton's method on `s(u) − s_i·L` inside its span, safeguarded by bisection, with the
/// integral continued from the previous iterate. The samples are increasing, so the spans are
/// visited once: O(spans + N_s) evaluations of the closed-form basis.
fn sample_at_fractions(curve: &BSplineCurve, n_samples: usize) -> Result<RhoSamples> {
    let ev = Evaluator::new(curve);
    let (gl, gl_short) = rules();
    let breaks = curve.breakpoints();
    // |r'| without hypot: the speed never comes near overflow here.
    let speed = |u: f64| ev.d1(u).length_squared().sqrt();
    let mut cumulative = Vec::with_capacity(breaks.len());
    cumulative.push(0.0);
    let mut total = 0.0;
    for w in breaks.windows(2) {
        total += gl.integrate(w[0], w[1], speed);
        cumulative.push(total);
    }
    let length = total;
    if !(length.is_finite() && length > 0.0) {
        return Err(Error::Degenerate(format!("the curve has length {length}")));
    }
    let last = (n_samples - 1) as f64;
    let s: Vec<f64> = (0..n_samples).map(|i| i as f64 / last).collect();
    let nspan = breaks.len() - 1;
    let mut u = Vec::with_capacity(n_samples);
    let mut span = 0;
    // The last point whose arc length is known: (parameter, length from its span's start).
    let mut known = (breaks[0], 0.0);
    for (i, &si) in s.iter().enumerate() {
        if i == 0 {
            u.push(breaks[0]);
            continue;
        }
        if i + 1 == n_samples {
            u.push(breaks[nspan]);
            continue;
        }
        let target = si * length;
        while span + 1 < nspan && cumulative[span + 1] < target {
            span += 1;
            known = (breaks[span], 0.0);
        }
        let (a, b) = (breaks[span], breaks[span + 1]);
        let goal = target - cumulative[span];
        let (mut lo, mut hi) = (a, b);
        let (mut t, mut at) = known;
        for _ in 0..NEWTON_MAX {
            let f = at - goal;
            if f > 0.0 {
                hi = t;
            } else {
                lo = t;
            }
            let v = speed(t);
            let step = if v > 0.0 { f / v } else { f64::INFINITY };
            // What the parameter can resolve: relative to the span, and to |u| itself (far
            // from 0 one ulp of u exceeds NEWTON_REL of a unit span).
            let resolution = NEWTON_REL * (b - a) + PARAM_ULPS * f64::EPSILON * t.abs();
            if step.abs() <= resolution {
                // Converged: test before the bracket, which the root may have become.
                t = (t - step).clamp(a, b);
                break;
            }
            let mut next = t - step;
            if !(next > lo && next < hi) {
                next = 0.5 * (lo + hi);
            }
            let rule = if (next - t).abs() <= SHORT_RULE_MAX * (b - a) {
                &gl_short
            } else {
                &gl
            };
            at += rule.integrate(t, next, speed);
            t = next;
        }
        known = (t, goal);
        u.push(t);
    }
    let kappa: Vec<f64> = u.iter().map(|&t| ev.local(t).kappa).collect();
    if let Some(i) = kappa.iter().position(|k| k.is_nan()) {
        return Err(Error::Degenerate(format!(
            "zero speed at the sample s = {} (u = {})",
            s[i], u[i]
        )));
    }
    Ok(RhoSamples {
        s,
        u,
        kappa,
        rho: Vec::new(),
        length,
        rho_max: f64::INFINITY,
        sigma: 1.0,
        inflected: false,
        straight: false,
    })
}

/// The Gauss–Legendre rules of the sampler (the default rule per span and the short rule),
/// built once.
fn rules() -> (&'static GaussLegendre, &'static GaussLegendre) {
    static RULES: OnceLock<(GaussLegendre, GaussLegendre)> = OnceLock::new();
    let r = RULES.get_or_init(|| {
        (
            GaussLegendre::default(),
            GaussLegendre::new(SHORT_RULE_NODES),
        )
    });
    (&r.0, &r.1)
}

/// Gauss–Legendre nodes for the Newton corrections of the arc-length inversion, on intervals
/// no longer than [`SHORT_RULE_MAX`] of a span: the integrand is smooth there, and eight
/// nodes are exact to degree 15.
const SHORT_RULE_NODES: usize = 8;

/// Longest interval, as a fraction of the span, integrated with the short rule.
const SHORT_RULE_MAX: f64 = 0.25;

/// Newton iterations allowed when inverting the arc length inside one span.
const NEWTON_MAX: usize = 50;

/// Relative accuracy of a sample's parameter against the span width.
const NEWTON_REL: f64 = 1e-14;

/// The arc-length inversion also stops when its Newton step is below this many ulps of the
/// parameter: the parameter cannot be resolved more finely.
const PARAM_ULPS: f64 = 4.0;

/// Evaluates derivatives of a non-rational B-spline: closed-form (eq 3) for the uniform
/// quintic, Piegl & Tiller's basis otherwise.
struct Evaluator<'a> {
    curve: &'a BSplineCurve,
    /// Number of segments when the curve is the uniform quintic of [`quintic`].
    uniform: Option<usize>,
    /// The uniform quintic's segments in power form ([`quintic::power_form`]).
    power: Vec<[Vec2; 6]>,
}

impl<'a> Evaluator<'a> {
    fn new(curve: &'a BSplineCurve) -> Evaluator<'a> {
        let uniform = quintic::is_uniform_quintic(curve)
            .then(|| curve.control_points().len() - quintic::DEGREE);
        let cp = curve.control_points();
        let power = match uniform {
            Some(segs) => (0..segs)
                .map(|i| quintic::power_form(std::array::from_fn(|j| cp[i + j])))
                .collect(),
            None => Vec::new(),
        };
        Evaluator {
            curve,
            uniform,
            power,
        }
    }

    /// Segment and local parameter of the uniform quintic.
    fn locate(segs: usize, u: f64) -> (usize, f64) {
        // `as usize` truncates toward zero and saturates negative values at 0: the floor on
        // the domain, without a libm call.
        let first = (u as usize).min(segs - 1);
        (first, u - first as f64)
    }

    /// The first control point of the span containing `u`, and the basis functions' first
    /// and second derivatives there (`basis[1]`, `basis[2]`).
    fn basis(&self, u: f64) -> (usize, [[f64; MAX_ORDER]; 4]) {
        let mut basis = [[0.0; MAX_ORDER]; 4];
        match self.uniform {
            Some(segs) => {
                let (first, t) = Evaluator::locate(segs, u);
                let b = quintic::basis(t);
                for r in 0..3 {
                    basis[r][..6].copy_from_slice(&b[r]);
                }
                (first, basis)
            }
            None => {
                let span = self.curve.find_span(u);
                self.curve.basis_derivs(span, u, 2, &mut basis);
                (span - self.curve.degree(), basis)
            }
        }
    }

    fn d1(&self, u: f64) -> Vec2 {
        if let Some(segs) = self.uniform {
            let (i, t) = Evaluator::locate(segs, u);
            let c = &self.power[i];
            let mut d = c[5] * 5.0;
            for e in (1..5).rev() {
                d = d * t + c[e] * e as f64;
            }
            return d;
        }
        let (first, basis) = self.basis(u);
        let cp = &self.curve.control_points()[first..=first + self.curve.degree()];
        cp.iter()
            .zip(&basis[1])
            .fold(Vec2::ZERO, |acc, (q, b)| acc + q.to_vec2() * *b)
    }

    fn local(&self, u: f64) -> LocalCurvature {
        let (first, basis) = self.basis(u);
        let (mut d1, mut d2) = (Vec2::ZERO, Vec2::ZERO);
        let cp = &self.curve.control_points()[first..=first + self.curve.degree()];
        for (j, q) in cp.iter().enumerate() {
            d1 += q.to_vec2() * basis[1][j];
            d2 += q.to_vec2() * basis[2][j];
        }
        let w = d1.length_squared();
        let k = d1.cross(d2);
        LocalCurvature {
            first,
            d1,
            d2,
            w,
            k,
            kappa: k / (w * w.sqrt()),
            basis,
        }
    }
}

/// A least-squares polynomial `ρ̂(s)` of degree d on [0, 1] (spec §5.4 step 3), held in the
/// Chebyshev basis `T_k(2s − 1)`.
#[derive(Clone, Debug, PartialEq)]
pub struct RhoFit {
    degree: usize,
    chebyshev: Vec<f64>,
}

impl RhoFit {
    /// Fit a polynomial of degree `degree` (1..=6) to `(s_i, rho_i)`, `s_i ∈ [0, 1]`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a degree outside 1..=6, [`Error::LengthMismatch`],
    /// [`Error::TooFewPoints`] for fewer than `degree + 1` samples, [`Error::NonFinite`],
    /// [`Error::Singular`].
    pub fn fit(s: &[f64], rho: &[f64], degree: usize) -> Result<RhoFit> {
        if !(MIN_DEGREE..=MAX_DEGREE).contains(&degree) {
            return Err(Error::InvalidParameter {
                name: "degree".into(),
                reason: format!("{degree} is outside {MIN_DEGREE}..={MAX_DEGREE}"),
            });
        }
        if s.len() != rho.len() {
            return Err(Error::LengthMismatch {
                what: "rho samples",
                got: rho.len(),
                expected: s.len(),
            });
        }
        if s.len() < degree + 1 {
            return Err(Error::TooFewPoints {
                needed: degree + 1,
                got: s.len(),
            });
        }
        if let Some(index) = s.iter().chain(rho).position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                index: index % s.len(),
            });
        }
        let a = nalgebra::DMatrix::from_fn(s.len(), degree + 1, |i, k| {
            chebyshev_values(2.0 * s[i] - 1.0, degree)[k]
        });
        let b = nalgebra::DVector::from_column_slice(rho);
        let c = a
            .svd(true, true)
            .solve(&b, f64::EPSILON)
            .map_err(|e| Error::Singular(format!("radius-of-curvature fit: {e}")))?;
        Ok(RhoFit {
            degree,
            chebyshev: c.iter().copied().collect(),
        })
    }

    /// The degree d.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// `ρ̂(s)`.
    pub fn eval(&self, s: f64) -> f64 {
        let t = chebyshev_values(2.0 * s - 1.0, self.degree);
        self.chebyshev.iter().zip(&t).map(|(c, t)| c * t).sum()
    }

    /// The coefficients `c_0..c_d` of `ρ̂(s) = Σ c_e s^e` (monomial basis in s).
    pub fn coefficients_ascending(&self) -> Vec<f64> {
        // T_k(2s − 1) as polynomials in s, by the recurrence T_{k+1} = 2x T_k − T_{k−1}.
        let d = self.degree;
        let mut out = vec![0.0; d + 1];
        let mut prev = vec![0.0; d + 2];
        let mut cur = vec![0.0; d + 2];
        prev[0] = 1.0; // T_0
        cur[0] = -1.0; // T_1 = 2s − 1
        cur[1] = 2.0;
        out[0] += self.chebyshev[0];
        for k in 1..=d {
            for (o, c) in out.iter_mut().zip(&cur) {
                *o += self.chebyshev[k] * c;
            }
            // next = 2(2s − 1)·cur − prev
            let mut next = vec![0.0; d + 2];
            for e in 0..=d {
                next[e] += -2.0 * cur[e] - prev[e];
                next[e + 1] += 4.0 * cur[e];
            }
            prev = std::mem::replace(&mut cur, next);
        }
        out
    }

    /// `ρ̂(s_i)` for every `s_i`.
    pub fn eval_all(&self, s: &[f64]) -> Vec<f64> {
        s.iter().map(|&x| self.eval(x)).collect()
    }
}

/// `T_0(x)..T_d(x)` (d ≤ 6).
fn chebyshev_values(x: f64, d: usize) -> [f64; MAX_DEGREE + 1] {
    let mut t = [0.0; MAX_DEGREE + 1];
    t[0] = 1.0;
    if d >= 1 {
        t[1] = x;
    }
    for k in 2..=d.min(MAX_DEGREE) {
        t[k] = 2.0 * x * t[k - 1] - t[k - 2];
    }
    t
}

/// The cosine of two sample vectors, not mean-centred (spec §5.6 step 2); `None` when either
/// is zero.
pub fn cosine(a: &[f64], b: &[f64]) -> Option<f64> {
    let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    let na = a.iter().map(|x| x * x).sum::<f64>().sqrt();
    let nb = b.iter().map(|x| x * x).sum::<f64>().sqrt();
    (na > 0.0 && nb > 0.0).then(|| (dot / (na * nb)).clamp(-1.0, 1.0))
}

/// The angle `arccos(cos)` in degrees (spec §5.6 step 3).
pub fn angle_degrees(cos: f64) -> f64 {
    cos.clamp(-1.0, 1.0).acos().to_degrees()
}

/// Relative guard of [`truncate_angle`] against values that are a hair below a printed
/// decimal only through rounding (1.14 is stored as 1.13999…).
const TRUNCATE_GUARD_REL: f64 = 1e-9;

/// Truncate (not round) a non-negative angle to `decimals` places, as the paper's Table 4
/// and text print it (spec §5.6 step 3): 3.0061° → 3.00, 1.1459° → 1.14.
pub fn truncate_angle(deg: f64, decimals: u32) -> f64 {
    let f = 10f64.powi(decimals as i32);
    let scaled = deg * f;
    (scaled + TRUNCATE_GUARD_REL * scaled.abs().max(1.0)).floor() / f
}

/// ρ at parameter `u` of a non-rational B-spline and its gradient with respect to the control
/// points of the span, holding `u` fixed (spec §5.5):
///
/// ```text
/// ∂ρ/∂q_r^x = 3 W^{1/2} x' N'_r / K − W^{3/2} (N'_r y'' − y' N''_r) / K²
/// ∂ρ/∂q_r^y = 3 W^{1/2} y' N'_r / K − W^{3/2} (x' N''_r − N'_r x'') / K²
/// ```
///
/// with `W = x'² + y'²`, `K = x'y'' − y'x''`. Returns `(ρ, first control-point index,
/// gradients)`; entry j of the gradients belongs to control point `first + j`. Where `K = 0`
/// the values are infinite.
///
/// # Errors
/// [`Error::InvalidParameter`] for a rational curve with unequal weights.
pub fn rho_gradient(curve: &BSplineCurve, u: f64) -> Result<(f64, usize, Vec<Vec2>)> {
    check_polynomial(curve)?;
    let local = Evaluator::new(curve).local(u);
    let rho = 1.0 / local.kappa;
    let g = (0..=curve.degree())
        .map(|j| local.dkappa(j) * (-rho * rho))
        .collect();
    Ok((rho, local.first, g))
}

fn check_polynomial(curve: &BSplineCurve) -> Result<()> {
    match curve.weights() {
        Some(w) if w.iter().any(|&x| x != w[0]) => Err(Error::InvalidParameter {
            name: "curve".into(),
            reason: "the shape modification needs a non-rational curve (equal weights)".into(),
        }),
        _ => Ok(()),
    }
}

/// Curvature at one parameter and what its gradient needs.
struct LocalCurvature {
    first: usize,
    d1: Vec2,
    d2: Vec2,
    w: f64,
    k: f64,
    kappa: f64,
    basis: [[f64; MAX_ORDER]; 4],
}

impl LocalCurvature {
    /// `(∂κ/∂q_j^x, ∂κ/∂q_j^y)` for local control point j: `κ = K W^{−3/2}`, so
    /// `∂κ = ∂K/W^{3/2} − 3 K (r'·∂r')/W^{5/2}`.
    fn dkappa(&self, j: usize) -> Vec2 {
        let (n1, n2) = (self.basis[1][j], self.basis[2][j]);
        let w15 = self.w * self.w.sqrt();
        let w25 = w15 * self.w;
        let dk_x = n1 * self.d2.y - self.d1.y * n2;
        let dk_y = self.d1.x * n2 - n1 * self.d2.x;
        Vec2::new(
            dk_x / w15 - 3.0 * self.k * self.d1.x * n1 / w25,
            dk_y / w15 - 3.0 * self.k * self.d1.y * n1 / w25,
        )
    }
}

/// Why the shape modification stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum StopReason {
    /// No step decreased S (μ grew beyond [`MU_MAX`]): converged as far as LM can tell.
    NoAcceptableStep,
    /// The iteration cap was reached.
    IterationLimit,
    /// S reached zero.
    ZeroResidual,
    /// No sample depends on any free control point.
    NothingToMove,
}

/// Constraints of [`modify_shape`] beyond the fixed `q_0` and `q_{n−1}`.
#[derive(Clone, Copy, Debug, Default)]
pub struct ShapeConstraints<'a> {
    /// Output points to watch: `(parameters u_k, original points P_k)`. The history records
    /// the largest `|C(u_k) − P_k|` after every accepted step.
    pub anchors: Option<(&'a [f64], &'a [Point])>,
    /// A hard bound on `|C(u_k) − P_k|` over the anchors: a trial step that breaks it is
    /// rejected. Needs `anchors`.
    pub tolerance: Option<f64>,
    /// Keep the curve's end points at these positions (see the module docs).
    pub fix_ends: Option<(Point, Point)>,
    /// Keep every control point whose basis function is non-zero at a domain end, so that the
    /// curve's end points, tangents and curvatures stay exactly as they are
    /// (`--fix-ends=tangent` / `curvature`; `fix_ends` is then not needed).
    pub hold_end_derivatives: bool,
}

impl ShapeConstraints<'_> {
    /// The largest distance of the anchors from the curve, `None` without anchors.
    fn max_distance(&self, curve: &BSplineCurve) -> Option<f64> {
        self.anchors.map(|(params, original)| {
            params
                .iter()
                .zip(original)
                .map(|(&u, &p)| (curve.eval(u) - p).length())
                .fold(0.0_f64, f64::max)
        })
    }
}

/// One accepted step of [`modify_shape`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModificationStep {
    /// S after the step.
    pub s: f64,
    /// The largest anchor distance after the step (`None` without anchors).
    pub max_distance: Option<f64>,
}

/// The result of [`modify_shape`].
#[derive(Clone, Debug)]
pub struct Modification {
    /// The modified curve.
    pub curve: BSplineCurve,
    /// Its ρ samples at the same fractions (capped with the target's ρ_max and orientation).
    pub samples: RhoSamples,
    /// S of the starting curve.
    pub s_initial: f64,
    /// S of the result.
    pub s_final: f64,
    /// RMS of `ρ_i − ρ̂_i` over the samples after the modification.
    pub rho_rms: f64,
    /// Linearisations performed.
    pub iterations: usize,
    /// Steps accepted.
    pub accepted: usize,
    /// Trial steps rejected because they broke the tolerance.
    pub tolerance_rejections: usize,
    /// Every accepted step in order.
    pub history: Vec<ModificationStep>,
    /// Why it stopped.
    pub stop: StopReason,
}

/// Smallest basis weight of a free control point at a curve end for `fix_ends` to eliminate
/// it; an end with no such weight is a fixed control point already.
const ELIMINATION_MIN_WEIGHT: f64 = 1e-12;

fn too_small_for_fix_ends(n_ctrl: usize) -> Error {
    Error::InvalidParameter {
        name: "fix_ends".into(),
        reason: format!(
            "{n_ctrl} control points are too few to hold both curve ends independently"
        ),
    }
}

/// How one unknown or control point enters the optimisation.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Role {
    Fixed,
    /// Column index of its x coordinate (y is the next column).
    Free(usize),
    /// Recomputed from the others: index into the eliminations.
    Eliminated(usize),
}

/// `q_e = (P − Σ_{j≠e} b_j q_j)/b_e` over the stencil `first..first + b.len()`.
#[derive(Clone, Debug)]
struct Elimination {
    index: usize,
    first: usize,
    basis: Vec<f64>,
    target: Point,
}

impl Elimination {
    fn apply(&self, q: &mut [Point]) {
        let be = self.basis[self.index - self.first];
        let mut s = self.target.to_vec2();
        for (j, &b) in self.basis.iter().enumerate() {
            let idx = self.first + j;
            if idx != self.index {
                s -= q[idx].to_vec2() * b;
            }
        }
        q[self.index] = (s / be).to_point();
    }
}

/// The unknowns of the modification.
struct Layout {
    roles: Vec<Role>,
    elim: Vec<Elimination>,
    unknowns: usize,
}

impl Layout {
    fn new(
        curve: &BSplineCurve,
        fix_ends: Option<(Point, Point)>,
        hold_end_derivatives: bool,
    ) -> Result<Layout> {
        let n = curve.control_points().len();
        let mut roles = vec![Role::Fixed; n];
        let mut elim = Vec::new();
        // Control points acting at a domain end, kept where they are.
        let mut held = vec![false; n];
        if hold_end_derivatives {
            let (a, b) = curve.domain();
            for u in [a, b] {
                let first = curve.find_span(u) - curve.degree();
                held[first..=first + curve.degree()].fill(true);
            }
        }
        if let Some((p0, p1)) = fix_ends.filter(|_| !hold_end_derivatives) {
            let (a, b) = curve.domain();
            for (u, target) in [(a, p0), (b, p1)] {
                let span = curve.find_span(u);
                let mut basis = [[0.0; MAX_ORDER]; 4];
                curve.basis_derivs(span, u, 0, &mut basis);
                let first = span - curve.degree();
                let vals: Vec<f64> = basis[0][..=curve.degree()].to_vec();
                // The free control point with the largest weight at the end.
                let best = (0..vals.len())
                    .filter(|&j| first + j != 0 && first + j != n - 1)
                    .max_by(|&x, &y| vals[x].total_cmp(&vals[y]));
                match best {
                    Some(j) if vals[j] > ELIMINATION_MIN_WEIGHT => {
                        let index = first + j;
                        if roles[index] != Role::Fixed {
                            return Err(too_small_for_fix_ends(n));
                        }
                        roles[index] = Role::Eliminated(elim.len());
                        elim.push(Elimination {
                            index,
                            first,
                            basis: vals,
                            target,
                        });
                    }
                    // The end is a fixed control point (clamped knots): nothing to eliminate.
                    _ => {}
                }
            }
            // An eliminated point must not depend on the other one.
            for e in &elim {
                let stencil = &roles[e.first..e.first + e.basis.len()];
                let clash = stencil
                    .iter()
                    .enumerate()
                    .any(|(j, r)| e.first + j != e.index && matches!(r, Role::Eliminated(_)));
                if clash {
                    return Err(too_small_for_fix_ends(n));
                }
            }
        }
        let mut unknowns = 0;
        for (j, r) in roles.iter_mut().enumerate() {
            if j != 0 && j != n - 1 && *r == Role::Fixed && !held[j] {
                *r = Role::Free(unknowns);
                unknowns += 2;
            }
        }
        Ok(Layout {
            roles,
            elim,
            unknowns,
        })
    }

    /// Add `g` (the gradient with respect to control point `idx`) to the sparse row.
    fn scatter(&self, idx: usize, g: Vec2, row: &mut Vec<(usize, f64)>) {
        match self.roles[idx] {
            Role::Fixed => {}
            Role::Free(c) => {
                row.push((c, g.x));
                row.push((c + 1, g.y));
            }
            Role::Eliminated(e) => {
                let el = &self.elim[e];
                let be = el.basis[el.index - el.first];
                for (j, &b) in el.basis.iter().enumerate() {
                    let other = el.first + j;
                    if other != el.index
                        && let Role::Free(c) = self.roles[other]
                    {
                        let f = -b / be;
                        row.push((c, g.x * f));
                        row.push((c + 1, g.y * f));
                    }
                }
            }
        }
    }

    /// The control points after adding `step` to the free ones.
    fn apply(&self, q: &[Point], step: &[f64]) -> Vec<Point> {
        let mut out = q.to_vec();
        for (p, r) in out.iter_mut().zip(&self.roles) {
            if let Role::Free(c) = *r {
                *p = Point::new(p.x + step[c], p.y + step[c + 1]);
            }
        }
        for e in &self.elim {
            e.apply(&mut out);
        }
        out
    }
}

/// The residual form of one sample, fixed within a linearisation.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Form {
    Rho,
    /// `(1/ρ̂ − κ)·ρ̂²`.
    ScaledKappa,
    /// `κ − 1/ρ̂`.
    Kappa,
}

fn choose_forms(samples: &RhoSamples, residual: Residual) -> Vec<Form> {
    let k_min = 1.0 / samples.rho_max;
    samples
        .kappa
        .iter()
        .map(|&k| match residual {
            Residual::Kappa => Form::Kappa,
            Residual::Rho if samples.sigma * k >= k_min => Form::Rho,
            Residual::Rho => Form::ScaledKappa,
        })
        .collect()
}

fn residuals(samples: &RhoSamples, target: &[f64], forms: &[Form]) -> Vec<f64> {
    samples
        .kappa
        .iter()
        .zip(&samples.rho)
        .zip(target.iter().zip(forms))
        .map(|((&k, &rho), (&t, f))| match f {
            Form::Rho => rho - t,
            Form::ScaledKappa => (1.0 / t - k) * t * t,
            Form::Kappa => k - 1.0 / t,
        })
        .collect()
}

fn sum_sq(r: &[f64]) -> f64 {
    r.iter().map(|x| x * x).sum()
}

/// Re-sample a curve at the target's fractions with the target's cap and orientation.
fn resample(curve: &BSplineCurve, like: &RhoSamples) -> Result<RhoSamples> {
    let mut s = sample_at_fractions(curve, like.s.len())?;
    s.rho_max = like.rho_max;
    s.orient_and_cap(Some(like.sigma));
    Ok(s)
}

/// Modify the shape of `curve` so that its ρ at the fractions `start.s` approaches `target`
/// (`ρ̂_i`, fixed), by Levenberg–Marquardt (spec §5.5; see the module docs). `start` are the
/// samples of `curve` itself (from [`sample_rho`]), which fix `N_s`, `ρ_max` and σ.
///
/// # Errors
/// [`Error::LengthMismatch`] when `target` and `start` differ in length,
/// [`Error::InvalidParameter`] for a rational curve with unequal weights or a target whose
/// sign is not σ at some sample, [`Error::TooFewPoints`] when `fix_ends` leaves nothing to
/// move, and [`Error::Degenerate`] when the curve collapses.
pub fn modify_shape(
    curve: &BSplineCurve,
    start: &RhoSamples,
    target: &[f64],
    residual: Residual,
    max_iterations: usize,
    constraints: &ShapeConstraints<'_>,
) -> Result<Modification> {
    check_polynomial(curve)?;
    if target.len() != start.s.len() {
        return Err(Error::LengthMismatch {
            what: "target radii",
            got: target.len(),
            expected: start.s.len(),
        });
    }
    if let Some(i) = target
        .iter()
        .position(|&t| !(t.is_finite() && start.sigma * t > 0.0))
    {
        return Err(Error::InvalidParameter {
            name: "target".into(),
            reason: format!("ρ̂ at sample {i} is not finite or has the wrong sign"),
        });
    }
    if constraints.tolerance.is_some() && constraints.anchors.is_none() {
        return Err(Error::InvalidParameter {
            name: "tolerance".into(),
            reason: "a tolerance needs anchor points".into(),
        });
    }
    let layout = Layout::new(
        curve,
        constraints.fix_ends,
        constraints.hold_end_derivatives,
    )?;
    let mut q: Vec<Point> = curve.control_points().to_vec();
    for e in &layout.elim {
        e.apply(&mut q);
    }
    let mut cur_curve = curve.with_control_points(q.clone())?;
    let mut cur = if layout.elim.is_empty() {
        start.clone()
    } else {
        resample(&cur_curve, start)?
    };
    let s_initial = sum_sq(&residuals(&cur, target, &choose_forms(&cur, residual)));
    let mut mu = MU_INITIAL;
    let mut history = Vec::new();
    let (mut iterations, mut accepted, mut tolerance_rejections) = (0, 0, 0);
    let mut row: Vec<(usize, f64)> = Vec::with_capacity(4 * MAX_ORDER);
    let stop = loop {
        if iterations >= max_iterations {
            break StopReason::IterationLimit;
        }
        iterations += 1;
        let forms = choose_forms(&cur, residual);
        let r = residuals(&cur, target, &forms);
        let s_cur = sum_sq(&r);
        if s_cur == 0.0 {
            break StopReason::ZeroResidual;
        }
        // Assemble JᵀJ (banded) and Jᵀr.
        let mut rows: Vec<(usize, usize, f64)> = Vec::new();
        let mut bw = 0;
        let ev = Evaluator::new(&cur_curve);
        for (i, (&u, form)) in cur.u.iter().zip(&forms).enumerate() {
            let local = ev.local(u);
            let t = target[i];
            // d(residual)/dκ for the form.
            let scale = match form {
                Form::Rho => {
                    let rho = 1.0 / local.kappa;
                    -rho * rho
                }
                Form::ScaledKappa => -t * t,
                Form::Kappa => 1.0,
            };
            row.clear();
            for j in 0..=cur_curve.degree() {
                layout.scatter(local.first + j, local.dkappa(j) * scale, &mut row);
            }
            if let (Some(lo), Some(hi)) =
                (row.iter().map(|e| e.0).min(), row.iter().map(|e| e.0).max())
            {
                bw = bw.max(hi - lo);
            }
            rows.extend(row.iter().map(|&(c, v)| (i, c, v)));
        }
        let m = layout.unknowns;
        let mut jtj_band: Vec<(usize, usize, f64)> = Vec::new();
        let mut jtr = vec![0.0; m];
        let mut diag = vec![0.0; m];
        let mut k = 0;
        while k < rows.len() {
            let i = rows[k].0;
            let mut e = k;
            while e < rows.len() && rows[e].0 == i {
                e += 1;
            }
            for a in k..e {
                let (_, ca, va) = rows[a];
                jtr[ca] += va * r[i];
                for &(_, cb, vb) in &rows[k..e] {
                    if cb <= ca {
                        jtj_band.push((ca, cb, va * vb));
                        if cb == ca {
                            diag[ca] += va * vb;
                        }
                    }
                }
            }
            k = e;
        }
        let dmax = diag.iter().fold(0.0_f64, |a, v| a.max(*v));
        if dmax <= 0.0 || !dmax.is_finite() {
            break StopReason::NothingToMove;
        }
        let floor = DIAG_FLOOR_REL * dmax;
        let mut base = SymBanded::zeros(m, bw);
        for &(a, b, v) in &jtj_band {
            base.add(a, b, v);
        }
        // Inner loop: raise μ until a step is accepted or μ exceeds MU_MAX.
        let mut stepped = false;
        while mu <= MU_MAX {
            let mut a = base.clone();
            for (c, d) in diag.iter().enumerate() {
                a.add(c, c, mu * d.max(floor));
            }
            let mut step: Vec<f64> = jtr.iter().map(|g| -g).collect();
            if a.factorize().is_err() || a.solve_in_place(&mut step).is_err() {
                mu *= MU_FACTOR;
                continue;
            }
            let trial_q = layout.apply(&q, &step);
            let Ok(trial_curve) = cur_curve.with_control_points(trial_q.clone()) else {
                mu *= MU_FACTOR;
                continue;
            };
            let max_distance = constraints.max_distance(&trial_curve);
            if let (Some(tol), Some(d)) = (constraints.tolerance, max_distance)
                && (d > tol || d.is_nan())
            {
                tolerance_rejections += 1;
                mu *= MU_FACTOR;
                continue;
            }
            let Ok(trial) = resample(&trial_curve, &cur) else {
                mu *= MU_FACTOR;
                continue;
            };
            let s_trial = sum_sq(&residuals(&trial, target, &forms));
            if s_trial < s_cur {
                q = trial_q;
                cur_curve = trial_curve;
                cur = trial;
                mu /= MU_FACTOR;
                accepted += 1;
                stepped = true;
                history.push(ModificationStep {
                    s: s_trial,
                    max_distance,
                });
                break;
            }
            mu *= MU_FACTOR;
        }
        if !stepped {
            break StopReason::NoAcceptableStep;
        }
    };
    let forms = choose_forms(&cur, residual);
    let s_final = sum_sq(&residuals(&cur, target, &forms));
    let rho_rms = (cur
        .rho
        .iter()
        .zip(target)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f64>()
        / target.len() as f64)
        .sqrt();
    Ok(Modification {
        curve: cur_curve,
        samples: cur,
        s_initial,
        s_final,
        rho_rms,
        iterations,
        accepted,
        tolerance_rejections,
        history,
        stop,
    })
}

/// The designed curve of [`evaluate`]: points (interpolated with [`KuraganoOptions::ends`])
/// or a curve.
#[derive(Clone, Copy, Debug)]
pub enum Design<'a> {
    /// A point sequence; the design is its uniform quintic interpolant.
    Points(&'a [Point]),
    /// A non-rational B-spline (any degree and knots; the quintic of
    /// [`crate::spline::quintic`] in the paper).
    Curve(&'a BSplineCurve),
}

impl<'a> From<&'a [Point]> for Design<'a> {
    fn from(p: &'a [Point]) -> Design<'a> {
        Design::Points(p)
    }
}

impl<'a> From<&'a Vec<Point>> for Design<'a> {
    fn from(p: &'a Vec<Point>) -> Design<'a> {
        Design::Points(p)
    }
}

impl<'a> From<&'a BSplineCurve> for Design<'a> {
    fn from(c: &'a BSplineCurve) -> Design<'a> {
        Design::Curve(c)
    }
}

/// One row of the evaluation (a row of the paper's Tables 3 and 4).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DegreeResult {
    /// The polynomial degree d.
    pub degree: usize,
    /// False when `ρ̂` changes sign (or the design has no valid ρ distribution).
    pub applicable: bool,
    /// The cosine between the designed and the predefined curve's ρ samples (`None` when not
    /// applicable).
    pub correlation: Option<f64>,
    /// `arccos(correlation)` in degrees, not truncated (`None` when not applicable).
    pub angle_deg: Option<f64>,
    /// S after the shape modification (not serialised).
    #[serde(skip)]
    pub s_final: Option<f64>,
    /// RMS of `ρ − ρ̂` after the shape modification (not serialised).
    #[serde(skip)]
    pub rho_rms: Option<f64>,
}

/// The fairness evaluation of a design (paper §5, spec §5.6). Serialised as
/// `{"degrees": [{"degree", "applicable", "correlation", "angle_deg"}, ...],
/// "best_degree", "fairness"}`, with `null` where a value does not exist.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Evaluation {
    /// Degrees 1..=6 in order.
    pub degrees: Vec<DegreeResult>,
    /// The degree with the largest cosine (ties within [`TIE_TOLERANCE`] to the lowest);
    /// `None` when no degree is applicable.
    pub best_degree: Option<usize>,
    /// The cosine of the best degree: the fairness of the design.
    pub fairness: Option<f64>,
}

/// The selected row (spec §5.6 step 4): the applicable row with the largest correlation, where
/// correlations within [`TIE_TOLERANCE`] of the largest tie and the lowest degree wins.
/// `None` when no row has a correlation.
pub fn select_best(rows: &[DegreeResult]) -> Option<&DegreeResult> {
    select_best_within(rows, TIE_TOLERANCE)
}

/// [`select_best`] with ties within `tie` (e.g. [`PAPER_TIE_TOLERANCE`]).
pub fn select_best_within(rows: &[DegreeResult], tie: f64) -> Option<&DegreeResult> {
    let best = rows
        .iter()
        .filter(|d| d.applicable)
        .filter_map(|d| d.correlation)
        .fold(f64::NEG_INFINITY, f64::max);
    rows.iter()
        .filter(|d| d.applicable)
        .filter(|d| d.correlation.is_some_and(|c| c >= best - tie))
        .min_by_key(|d| d.degree)
}

/// Everything [`evaluate`] computed, for the fairing method.
struct Detailed {
    design: BSplineCurve,
    samples: RhoSamples,
    evaluation: Evaluation,
    modifications: Vec<Option<Modification>>,
}

/// The designed curve for a design.
fn design_curve(design: Design<'_>, opts: &KuraganoOptions) -> Result<BSplineCurve> {
    match design {
        Design::Curve(c) => {
            check_polynomial(c)?;
            Ok(c.clone())
        }
        Design::Points(p) => {
            let ends = match opts.ends {
                DesignEnds::Natural => Ends::Natural,
                DesignEnds::Gradients { fraction } => {
                    Ends::Gradients(quintic::end_gradients(p, fraction)?)
                }
            };
            quintic::interpolate(p, &ends, QuinticForm::BSpline)
        }
    }
}

/// Number of spans of a curve.
fn segments(curve: &BSplineCurve) -> usize {
    curve.breakpoints().len().saturating_sub(1).max(1)
}

/// The samples of the design with the options' `N_s` and `ρ_max`.
fn design_samples(curve: &BSplineCurve, opts: &KuraganoOptions) -> Result<RhoSamples> {
    let n = opts
        .samples
        .unwrap_or_else(|| default_samples(segments(curve)));
    sample_rho(curve, n, opts.rho_max)
}

/// The fits of every degree and whether each is applicable.
fn fits(samples: &RhoSamples) -> Result<Vec<(RhoFit, Vec<f64>, bool)>> {
    (MIN_DEGREE..=MAX_DEGREE)
        .map(|d| {
            let fit = RhoFit::fit(&samples.s, &samples.rho, d)?;
            let spec = fit.eval_all(&samples.s);
            let ok = !samples.inflected
                && !samples.straight
                && spec.iter().all(|&r| samples.sigma * r > 0.0);
            Ok((fit, spec, ok))
        })
        .collect()
}

fn evaluate_detailed(
    design: Design<'_>,
    opts: &KuraganoOptions,
    anchors: Option<(&[f64], &[Point])>,
) -> Result<Detailed> {
    opts.check()?;
    let curve = design_curve(design, opts)?;
    let samples = design_samples(&curve, opts)?;
    let mut degrees = Vec::with_capacity(MAX_DEGREE);
    let mut modifications = Vec::with_capacity(MAX_DEGREE);
    for (fit, spec, ok) in fits(&samples)? {
        let degree = fit.degree();
        if !ok {
            degrees.push(DegreeResult {
                degree,
                applicable: false,
                correlation: None,
                angle_deg: None,
                s_final: None,
                rho_rms: None,
            });
            modifications.push(None);
            continue;
        }
        let m = modify_shape(
            &curve,
            &samples,
            &spec,
            opts.residual,
            opts.max_iterations,
            &ShapeConstraints {
                anchors,
                ..ShapeConstraints::default()
            },
        )?;
        let c = cosine(&samples.rho, &m.samples.rho);
        degrees.push(DegreeResult {
            degree,
            applicable: true,
            correlation: c,
            angle_deg: c.map(angle_degrees),
            s_final: Some(m.s_final),
            rho_rms: Some(m.rho_rms),
        });
        modifications.push(Some(m));
    }
    let best = select_best(&degrees);
    let evaluation = Evaluation {
        best_degree: best.map(|d| d.degree),
        fairness: best.and_then(|d| d.correlation),
        degrees,
    };
    Ok(Detailed {
        design: curve,
        samples,
        evaluation,
        modifications,
    })
}

/// The fairness evaluation of a design (paper §5, spec §5.6): for every applicable degree
/// d = 1..6 the specification `ρ̂_d` and the shape modification towards it, then the cosine
/// of the designed and the modified ρ samples. A design with an inflection (or straight) has
/// no applicable degree: every row is not applicable and `best_degree` is `None`.
///
/// ```
/// use batten::Point;
/// use batten::fair::kuragano::{KuraganoOptions, evaluate};
///
/// // A spiral arc: ρ grows with the arc length, no inflection.
/// let pts: Vec<Point> = (0..16)
///     .map(|i| {
///         let a = 0.2 * i as f64;
///         let r = 2.0 + 0.5 * a;
///         Point::new(r * a.cos(), r * a.sin())
///     })
///     .collect();
/// let e = evaluate(&pts, &KuraganoOptions::default())?;
/// assert_eq!(e.degrees.len(), 6);
/// assert!(e.best_degree.is_some() && e.fairness.is_some_and(|c| c > 0.99));
/// // An S-shaped design has no applicable degree.
/// let s: Vec<Point> = (0..16).map(|i| Point::new(i as f64, (0.4 * i as f64).sin())).collect();
/// assert_eq!(evaluate(&s, &KuraganoOptions::default())?.best_degree, None);
/// # Ok::<(), batten::Error>(())
/// ```
///
/// # Errors
/// Option errors ([`Error::InvalidParameter`]), the interpolation's errors for a point design,
/// [`Error::InvalidParameter`] for a rational curve with unequal weights, and
/// [`Error::Degenerate`] for a curve of zero length or with a zero-speed sample.
pub fn evaluate<'a>(design: impl Into<Design<'a>>, opts: &KuraganoOptions) -> Result<Evaluation> {
    evaluate_detailed(design.into(), opts, None).map(|d| d.evaluation)
}

/// The parameters of [`Kuragano`].
const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "degree",
        default: "auto",
        doc: "degree 1..6 of the ρ(s) polynomial; auto: the best degree of the evaluation",
    },
    ParamSpec {
        name: "samples",
        default: "auto",
        doc: "number N_s of ρ samples along the normalised arc length, 7..=100000; auto: max(41, 10 per segment + 1)",
    },
    ParamSpec {
        name: "rho_max",
        default: "auto",
        doc: "cap on |ρ| in data units (straight parts); auto: 100 × the curve length",
    },
    ParamSpec {
        name: "residual",
        default: "rho",
        doc: "rho: ρ − ρ̂ (curvature form where ρ is infinite); kappa: κ − 1/ρ̂",
    },
    ParamSpec {
        name: "ends",
        default: "gradients",
        doc: "ends of the quintic interpolant: gradients (estimated at points 0, 1, m−2, m−1) or natural (R'' = R'''' = 0)",
    },
    ParamSpec {
        name: "gradient_fraction",
        default: "1",
        doc: "end-gradient magnitude as a fraction of the end chord (the paper's default is 1/3)",
    },
];

/// The `kuragano` fairing method (see the module docs).
#[derive(Clone, Copy, Debug, Default)]
pub struct Kuragano;

impl Kuragano {
    fn options(options: &FairOptions) -> Result<(KuraganoOptions, Option<usize>)> {
        let mut k = KuraganoOptions::DEFAULT
            .with_max_iterations(options.iterations_or(DEFAULT_MAX_ITERATIONS));
        let degree = options.param_auto_usize_in("degree", MIN_DEGREE, MAX_DEGREE)?;
        if let Some(samples) = options.param_auto_usize_in("samples", MIN_SAMPLES, MAX_SAMPLES)? {
            k.samples = Some(samples);
        }
        if let Some(rho) = options.param_auto_f64_in("rho_max", f64::MIN_POSITIVE, f64::MAX)? {
            k.rho_max = Some(rho);
        }
        k.residual = match options.param_choice("residual", "rho", &["rho", "kappa"])? {
            "kappa" => Residual::Kappa,
            _ => Residual::Rho,
        };
        let fraction = options.param_f64_in(
            "gradient_fraction",
            DEFAULT_METHOD_GRADIENT_FRACTION,
            f64::MIN_POSITIVE,
            f64::MAX,
        )?;
        k.ends = match options.param_choice("ends", "gradients", &["gradients", "natural"])? {
            "natural" => DesignEnds::Natural,
            _ => DesignEnds::Gradients { fraction },
        };
        Ok((k, degree))
    }
}

/// Parameters in data units and their power of length.
const LENGTH_PARAMS: &[(&str, i32)] = &[("rho_max", 1), ("arc_length", 1)];

impl FairMethod for Kuragano {
    fn name(&self) -> &'static str {
        "kuragano"
    }

    fn description(&self) -> &'static str {
        "Kuragano & Yamaguchi: uniform quintic B-spline, radius-of-curvature specification \
         by a polynomial in arc length, Levenberg–Marquardt shape modification"
    }

    fn parameters(&self) -> &'static [ParamSpec] {
        PARAMS
    }

    fn supports_closed(&self) -> bool {
        false
    }

    fn params_at_scale(&self, options: &FairOptions, s: f64) -> Result<FairOptions> {
        Ok(super::guard::length_params_at_scale(
            options,
            LENGTH_PARAMS,
            s,
        ))
    }

    fn report_params_at_scale(
        &self,
        parameters: &mut serde_json::Map<String, serde_json::Value>,
        s: f64,
    ) {
        super::guard::report_length_params(parameters, LENGTH_PARAMS, s);
    }

    fn check_params(&self, options: &FairOptions) -> Result<()> {
        Kuragano::options(options)?.0.check()
    }

    fn run(&self, input: &PointSeq, options: &FairOptions) -> Result<Outcome> {
        // Not rotation invariant: the spec's Marquardt scaling diag(JᵀJ) depends on the
        // axes. Neither the principal frame nor a rotation-invariant scaling (the x and y
        // entries of a control point averaged) helped: each converged worse on the spec's
        // tests (degree 6: S 69 instead of below 1 % of S₀).
        run_points(input, options)
    }
}

/// [`Kuragano`] on point input, in whatever frame it is given.
fn run_points(input: &PointSeq, options: &FairOptions) -> Result<Outcome> {
    let points = input.points();
    let m = points.len();
    let (kopts, degree) = Kuragano::options(options)?;
    kopts.check()?;
    let params_u: Vec<f64> = (0..m).map(|i| i as f64).collect();
    let anchors = Some((&params_u[..], points));
    let mut parameters = Map::new();
    let mut notes = Vec::new();
    // The designed curve and, when the degree is automatic, the evaluation.
    let (design, samples, evaluation, mut reusable) = match degree {
        Some(_) => {
            let design = design_curve(Design::Points(points), &kopts)?;
            let samples = design_samples(&design, &kopts)?;
            (design, samples, None, Vec::new())
        }
        None => {
            let d = evaluate_detailed(Design::Points(points), &kopts, anchors)?;
            (d.design, d.samples, Some(d.evaluation), d.modifications)
        }
    };
    parameters.insert("samples".into(), json!(samples.s.len()));
    parameters.insert("rho_max".into(), json!(samples.rho_max));
    parameters.insert("residual".into(), json!(kopts.residual));
    let ends = match kopts.ends {
        DesignEnds::Natural => "natural",
        DesignEnds::Gradients { .. } => "gradients",
    };
    parameters.insert("ends".into(), json!(ends));
    if let DesignEnds::Gradients { fraction } = kopts.ends {
        parameters.insert("gradient_fraction".into(), json!(fraction));
    }
    parameters.insert("arc_length".into(), json!(samples.length));
    if let Some(e) = &evaluation {
        parameters.insert(
            "evaluation".into(),
            serde_json::to_value(e).unwrap_or(Value::Null),
        );
    }
    let all_fits = fits(&samples)?;
    let why_not = || {
        if samples.inflected {
            "the designed curve has an inflection"
        } else if samples.straight {
            "the designed curve is straight"
        } else {
            "the fitted radius of curvature changes sign"
        }
    };
    let (chosen, target) = match degree {
        Some(d) if samples.inflected => {
            // [CHOICE] Fair through the inflections: ρ̂ from the valid samples only.
            let (vs, vr): (Vec<f64>, Vec<f64>) = samples
                .s
                .iter()
                .zip(&samples.rho)
                .zip(&samples.kappa)
                .filter(|(_, k)| samples.sigma * **k >= 1.0 / samples.rho_max)
                .map(|((s, r), _)| (*s, *r))
                .unzip();
            let fit = RhoFit::fit(&vs, &vr, d)?;
            let spec = fit.eval_all(&samples.s);
            if spec.iter().any(|&r| samples.sigma * r <= 0.0 || r.is_nan()) {
                return Err(Error::InvalidParameter {
                    name: "degree".into(),
                    reason: format!(
                        "degree {d} is not applicable: the radius of curvature fitted to \
                         the samples without inflection changes sign"
                    ),
                });
            }
            notes.push(format!(
                "the designed curve has an inflection: ρ̂ of degree {d} is fitted to the {} \
                 of {} samples where ρ is finite and has the curve's orientation",
                vs.len(),
                samples.s.len()
            ));
            (d, spec)
        }
        Some(d) if all_fits[d - MIN_DEGREE].2 => (d, all_fits[d - MIN_DEGREE].1.clone()),
        Some(d) => {
            return Err(Error::InvalidParameter {
                name: "degree".into(),
                reason: format!("degree {d} is not applicable: {}", why_not()),
            });
        }
        None => match evaluation.as_ref().and_then(|e| e.best_degree) {
            Some(d) => (d, all_fits[d - MIN_DEGREE].1.clone()),
            None => {
                notes.push(format!(
                    "no polynomial degree is applicable ({}); the points are returned \
                     unchanged (with an inflection, --set degree=d fairs through it)",
                    why_not()
                ));
                return Ok(Outcome {
                    points: points.to_vec(),
                    status: FairStatus::NoChange,
                    parameters,
                    notes,
                    curve: Some(design),
                    ..Outcome::default()
                });
            }
        },
    };
    parameters.insert("degree".into(), json!(chosen));
    let constrained = options.tolerance.is_some() || options.fix_ends.is_fixed();
    let reuse = reusable
        .get_mut(chosen - MIN_DEGREE)
        .and_then(Option::take)
        .filter(|_| !constrained);
    let modification = match reuse {
        Some(done) => done,
        None => modify_shape(
            &design,
            &samples,
            &target,
            kopts.residual,
            kopts.max_iterations,
            &ShapeConstraints {
                anchors,
                tolerance: options.tolerance,
                fix_ends: options
                    .fix_ends
                    .is_fixed()
                    .then(|| (points[0], points[m - 1])),
                hold_end_derivatives: options.fix_ends.held() >= 2,
            },
        )?,
    };
    let mut out: Vec<Point> = params_u
        .iter()
        .map(|&u| modification.curve.eval(u))
        .collect();
    if options.fix_ends.is_fixed() {
        out[0] = points[0];
        out[m - 1] = points[m - 1];
    }
    parameters.insert("s_initial".into(), json!(modification.s_initial));
    parameters.insert("s_final".into(), json!(modification.s_final));
    parameters.insert("rho_rms".into(), json!(modification.rho_rms));
    parameters.insert("accepted_steps".into(), json!(modification.accepted));
    parameters.insert("stop".into(), json!(modification.stop));
    notes.push(format!(
        "degree {chosen}: S {:.6e} -> {:.6e}, RMS(ρ − ρ̂) = {:.6e} over {} samples",
        modification.s_initial,
        modification.s_final,
        modification.rho_rms,
        samples.s.len()
    ));
    if modification.tolerance_rejections > 0 {
        notes.push(format!(
            "{} trial steps were rejected because they would exceed the tolerance",
            modification.tolerance_rejections
        ));
    }
    let history = modification
        .history
        .iter()
        .enumerate()
        .map(|(k, step)| HistoryRow {
            iteration: k + 1,
            measure: step.s,
            max_distance: step.max_distance.unwrap_or(0.0),
        })
        .collect();
    let status = match modification.stop {
        _ if modification.tolerance_rejections > 0 => FairStatus::ToleranceLimited,
        StopReason::IterationLimit => FairStatus::IterationLimit,
        _ if modification.accepted == 0 => FairStatus::NoChange,
        _ => FairStatus::Converged,
    };
    Ok(Outcome {
        points: out,
        status,
        iterations: modification.iterations,
        history,
        parameters,
        notes,
        curve: Some(modification.curve),
        ..Outcome::default()
    })
}
