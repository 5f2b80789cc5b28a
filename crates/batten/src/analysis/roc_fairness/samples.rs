//! ρ sampled at equally spaced fractions of the normalised arc length (docs/algorithms/kuragano.md
//! §5.4 steps 1–2: arc length by Gauss–Legendre, Newton inversion), with the orientation, the cap
//! `ρ_max` and the inflection test; and the closed-form derivatives of the uniform quintic that the
//! sampler and the shape modification evaluate (`docs/algorithms/kuragano.md`, "Curvature and ρ",
//! "Radius-of-curvature specification").

use std::sync::OnceLock;

use super::fit::MAX_DEGREE;
use crate::curve::Piecewise;
use crate::error::{Error, Result};
use crate::geom::Vec2;
use crate::numeric::GaussLegendre;
use crate::spline::quintic;
use crate::spline::{BSplineCurve, MAX_ORDER};

/// Default number of ρ samples `N_s` (docs/algorithms/kuragano.md §5.4 and the test vectors).
pub(super) const DEFAULT_SAMPLES: usize = 41;

/// Samples per segment in the automatic `N_s` (docs/algorithms/kuragano.md §5.4: "about 10 per
/// segment").
pub(super) const SAMPLES_PER_SEGMENT: usize = 10;

/// Fewest samples accepted: a degree-6 fit needs seven.
pub(crate) const MIN_SAMPLES: usize = MAX_DEGREE + 1;

/// Most samples accepted when given (`samples`, `evaluate --samples`): each iteration
/// samples ρ and fits the design at every one, about 1 s per 10⁵ for the evaluation and the
/// shape modification (10⁶ took 11 s and 200 MB, 10⁷ 49 s and 1.9 GB; 2⁶⁴ overflowed the
/// allocation). The automatic count, 10 per segment, is not capped.
pub const MAX_SAMPLES: usize = 100_000;

/// The default cap `ρ_max`, relative to the arc length of the curve: a sample whose radius
/// exceeds 100 curve lengths (an arc turning by less than about 0.6°) counts as straight.
pub(super) const DEFAULT_RHO_MAX_REL: f64 = 100.0;

/// The automatic `N_s` for a curve of `segments` spans: `max(41, 10·segments + 1)`.
pub(super) fn default_samples(segments: usize) -> usize {
    DEFAULT_SAMPLES.max(SAMPLES_PER_SEGMENT * segments + 1)
}

/// ρ sampled at equally spaced fractions of the normalised arc length (docs/algorithms/kuragano.md
/// §5.4 steps 1–2).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct RhoSamples {
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
    pub(super) fn orient_and_cap(&mut self, sigma: Option<f64>) {
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

/// Sample ρ at `n_samples` equally spaced normalised arc-length fractions
/// (docs/algorithms/kuragano.md §5.4 steps 1–2). `rho_max: None` caps at [`DEFAULT_RHO_MAX_REL`]
/// times the length.
///
/// # Errors
/// [`Error::InvalidParameter`] for fewer than two samples or a bad `rho_max`,
/// [`Error::Degenerate`] for a curve of zero or non-finite length.
pub(super) fn sample_rho(
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
/// Arc length by Gauss–Legendre on every span (docs/algorithms/README.md §0.5); each `s_i·L` is
/// inverted by Newton's method on `s(u) − s_i·L` inside its span, safeguarded by bisection, with
/// the integral continued from the previous iterate. The samples are increasing, so the spans are
/// visited once: O(spans + N_s) evaluations of the closed-form basis.
pub(super) fn sample_at_fractions(curve: &BSplineCurve, n_samples: usize) -> Result<RhoSamples> {
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
pub(super) struct Evaluator<'a> {
    curve: &'a BSplineCurve,
    /// Number of segments when the curve is the uniform quintic of [`quintic`].
    uniform: Option<usize>,
    /// The uniform quintic's segments in power form ([`quintic::power_form`]).
    power: Vec<[Vec2; 6]>,
}

impl<'a> Evaluator<'a> {
    pub(super) fn new(curve: &'a BSplineCurve) -> Evaluator<'a> {
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

    pub(super) fn local(&self, u: f64) -> LocalCurvature {
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

pub(super) fn check_polynomial(curve: &BSplineCurve) -> Result<()> {
    match curve.weights() {
        Some(w) if w.iter().any(|&x| x != w[0]) => Err(Error::InvalidParameter {
            name: "curve".into(),
            reason: "the shape modification needs a non-rational curve (equal weights)".into(),
        }),
        _ => Ok(()),
    }
}

/// Curvature at one parameter and what its gradient needs.
pub(super) struct LocalCurvature {
    pub(super) first: usize,
    d1: Vec2,
    d2: Vec2,
    w: f64,
    k: f64,
    pub(super) kappa: f64,
    basis: [[f64; MAX_ORDER]; 4],
}

impl LocalCurvature {
    /// `(∂κ/∂q_j^x, ∂κ/∂q_j^y)` for local control point j: `κ = K W^{−3/2}`, so
    /// `∂κ = ∂K/W^{3/2} − 3 K (r'·∂r')/W^{5/2}`.
    pub(super) fn dkappa(&self, j: usize) -> Vec2 {
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
