//! Kuragano & Yamaguchi's radius-of-curvature specification, shape modification and fairness
//! evaluation, *NURBS curve shape modification and fairness evaluation*
//! (`../shared/papers/kuragano-nurbs-roc-fairness.txt`, §4–§5), as specified (with fixes) in
//! `../shared/spec/ALGORITHMS.md` §5.2 and §5.4–§5.6 (`docs/algorithms/kuragano.md`,
//! "Radius-of-curvature specification", "Shape modification", "Fairness evaluation"). The
//! curve is the uniform quintic of [`crate::spline::quintic`] (§5.1, §5.3).
//!
//! The evaluation is a measurement (`batten evaluate`: which polynomial ρ(s) a curve follows
//! best), so it lives in `analysis`; the shape modification lives with it because the
//! evaluation is defined through it (the predefined curves `C_d`). The fairing method
//! [`crate::fair::kuragano`] applies the same shape modification to a point sequence.
//!
//! # Radius-of-curvature specification (paper §4, docs/algorithms/kuragano.md §5.4)
//!
//! The curve is sampled at `N_s` equally spaced fractions of its normalised arc length,
//! `s_i = i/(N_s − 1)` ([`sample_rho`]; arc length by Gauss–Legendre per span and Newton
//! inversion, docs/algorithms/README.md §0.5). **\[CHOICE\]** `N_s` is [`DEFAULT_SAMPLES`] (41, the
//! test vectors' value) or [`SAMPLES_PER_SEGMENT`] per segment plus one, whichever is larger
//! ([`default_samples`]): with fewer samples than unknowns the shape modification is
//! under-determined. ρ is the signed radius (docs/algorithms/kuragano.md §5.2), capped at `±ρ_max`
//! **\[CHOICE\]**, default [`DEFAULT_RHO_MAX_REL`] times the arc length: a sample whose curvature
//! is smaller in magnitude than `1/ρ_max` counts as straight and gets `σ·ρ_max`, where `σ` is the
//! orientation of the curve (the sign of its total sampled curvature). [`RhoFit`] fits a
//! polynomial `ρ̂(s)` of degree 1..=6 by linear least squares on the Chebyshev basis
//! `T_k(2s − 1)` (a scaled basis, as the spec asks); it reports monomial coefficients too.
//! A degree is **not applicable** when `σ·ρ̂(s_i) ≤ 0` at some sample (paper: "if the radius of
//! curvature is negative"); a designed curve with an inflection (a sample with `σκ < −1/ρ_max`)
//! or with no curvature at all has no valid ρ distribution, and every degree is not
//! applicable.
//!
//! # Shape modification (paper eqs 10–13, docs/algorithms/kuragano.md §5.5)
//!
//! [`modify_shape`] moves the interior control points `q_1..q_{n−2}` (both coordinates; `q_0`
//! and `q_{n−1}` are fixed \[PAPER\]) to minimise `S = Σ δ_i²`, `δ_i = ρ_i(q) − ρ̂_i` (eqs 10–11)
//! with `ρ̂_i` fixed. The Jacobian holds each sample's parameter `u_i` fixed
//! ([`rho_gradient`], the formula of docs/algorithms/kuragano.md §5.5); after every step `L` is
//! recomputed and the `s_i` re-sampled to new `u_i` \[PAPER\]. **\[FIX\]** the literal Gauss–Newton
//! step of eqs 12–13 diverges (docs/algorithms/kuragano.md §5.5); this is Levenberg–Marquardt
//! exactly as the spec prescribes: `A = JᵀJ + μ·diag(JᵀJ)`, `μ_0 =` [`MU_INITIAL`], a step is
//! accepted only if S decreases, then `μ /= 10`, else `μ *= 10`; it stops when no step can be
//! accepted (μ beyond [`MU_MAX`]) or after the iteration cap ([`DEFAULT_MAX_ITERATIONS`], counted
//! in linearisations). `JᵀJ` is a symmetric band (a sample touches six consecutive control
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
//! `Kappa` uses `κ_i − 1/ρ̂_i` everywhere, with `∂κ = −∂ρ/ρ²` (docs/algorithms/kuragano.md §5.5,
//! the equivalent variant); its S is in curvature units.
//!
//! # Fairness evaluation (paper §5, docs/algorithms/kuragano.md §5.6)
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
//! the design is that cosine. Remark (docs/algorithms/kuragano.md §5.6.5): with a perfect shape
//! modification the cosine would be non-decreasing in d, so the paper's non-monotone tables reflect
//! imperfect modification.
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
//! - The r = 3 row of docs/algorithms/kuragano.md §5.1 table has two signs flipped (see
//!   [`quintic::ROWS`]).
//! - \[CHOICE\]s made here: `N_s` ([`default_samples`]), `ρ_max` ([`DEFAULT_RHO_MAX_REL`]),
//!   the orientation and inflection rule, the curvature form at infinite ρ, the method's end
//!   gradients (a full end chord instead of the paper's third,
//!   [`DEFAULT_METHOD_GRADIENT_FRACTION`]), the valid-sample fit for an explicit degree on an
//!   inflected design, and `fix_ends` by elimination. With `--fix-ends=tangent` or
//!   `curvature` every control point whose basis function is non-zero at a domain end is
//!   held instead ([`ShapeConstraints::ends`]), which keeps the end points,
//!   tangents and curvatures of the quintic exactly.
//!
//! # Files
//!
//! - `options.rs`: the options of the specification, modification and evaluation;
//! - `samples.rs`: ρ sampled along the normalised arc length (docs/algorithms/kuragano.md §5.4
//!   steps 1–2) and the derivatives of the curve;
//! - `fit.rs`: the polynomial `ρ̂(s)` (docs/algorithms/kuragano.md §5.4 step 3);
//! - `layout.rs` and `modify.rs`: the shape modification by Levenberg–Marquardt
//!   (docs/algorithms/kuragano.md §5.5);
//! - `evaluate.rs`: the fairness evaluation (docs/algorithms/kuragano.md §5.6).
//!
//! [`SymBanded`]: crate::numeric::SymBanded
//! [`quintic::basis`]: crate::spline::quintic::basis
//! [`quintic::ROWS`]: crate::spline::quintic::ROWS

mod evaluate;
mod fit;
mod layout;
mod modify;
mod options;
mod samples;
#[cfg(test)]
mod tests;

pub use evaluate::{
    DegreeResult, Design, Evaluation, TIE_TOLERANCE, angle_degrees, evaluate, truncate_angle,
};
pub(crate) use evaluate::{design_curve, design_samples, evaluate_detailed, fits};
pub(crate) use fit::{MAX_DEGREE, MIN_DEGREE, RhoFit};
pub(crate) use modify::{
    DEFAULT_MAX_ITERATIONS, Modification, ShapeConstraints, StopReason, modify_shape,
};
pub use options::{DEFAULT_METHOD_GRADIENT_FRACTION, DesignEnds, KuraganoOptions, Residual};
pub use samples::MAX_SAMPLES;
pub(crate) use samples::{MIN_SAMPLES, RhoSamples};
