//! The downhill simplex method of Nelder and Mead (1965) for small dimensions, in the form of
//! Lagarias, Reeds, Wright and Wright (*SIAM J. Optim.* 9, 1998) with the standard
//! coefficients (reflection 1, expansion 2, contraction ½, shrink ½).
//!
//! Salvi and Várady (`../shared/papers/salvi-varady-local-fairing.txt`, §4.2, citing Numerical
//! Recipes) move one control point at a time with it: a 2-D search for curves, 3-D for
//! surfaces. The spec (§3 step 6) fixes the initial simplex `{x₀, x₀ + s e₁, …, x₀ + s e_D}` and
//! the stopping rule (simplex size `xatol` or an evaluation budget); both are
//! [`NelderMeadParams`].
//!
//! Degenerate input, on purpose:
//! - a NaN value counts as `+∞`, so a function may return `f64::INFINITY` (or NaN) outside its
//!   domain and the simplex contracts away from there;
//! - the starting point is evaluated first and the best vertex is returned, so the result is
//!   never worse than `f(x₀)`;
//! - a zero or non-finite step gives no simplex: `x₀` is returned after one evaluation.

/// Reflection coefficient ρ.
const REFLECT: f64 = 1.0;
/// Expansion coefficient χ.
const EXPAND: f64 = 2.0;
/// Contraction coefficient γ.
const CONTRACT: f64 = 0.5;
/// Shrink coefficient σ.
const SHRINK: f64 = 0.5;

/// Initial simplex and stopping rule of [`minimize_nelder_mead`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct NelderMeadParams {
    /// Edge `s` of the initial simplex `{x₀, x₀ + s e₁, …, x₀ + s e_D}`.
    ///
    /// Default value: `1.0`.
    pub step: f64,
    /// Stop when every vertex is within `xatol` of the best one in every coordinate.
    ///
    /// Default value: `1e-9` (the spec's `1e-9·s` for `s = 1`).
    pub xatol: f64,
    /// Stop after this many function evaluations.
    ///
    /// Default value: `400` (docs/algorithms/salvi-varady.md §3 step 6).
    pub max_evaluations: usize,
}

impl NelderMeadParams {
    /// The spec's rule (§3 step 6) for a unit step: `s = 1`, `xatol = 1e-9·s`, 400 evaluations.
    pub const DEFAULT: NelderMeadParams = NelderMeadParams {
        step: 1.0,
        xatol: 1e-9,
        max_evaluations: 400,
    };

    /// The spec's rule scaled to the step `s`: `xatol = 1e-9·s`, 400 evaluations.
    pub fn with_scaled_step(s: f64) -> NelderMeadParams {
        NelderMeadParams {
            step: s,
            xatol: NelderMeadParams::DEFAULT.xatol * s,
            ..NelderMeadParams::DEFAULT
        }
    }

    /// Set the initial step `s` (and nothing else).
    pub fn with_step(mut self, step: f64) -> NelderMeadParams {
        self.step = step;
        self
    }

    /// Set the simplex-size tolerance.
    pub fn with_xatol(mut self, xatol: f64) -> NelderMeadParams {
        self.xatol = xatol;
        self
    }

    /// Set the evaluation budget.
    pub fn with_max_evaluations(mut self, n: usize) -> NelderMeadParams {
        self.max_evaluations = n;
        self
    }
}

impl Default for NelderMeadParams {
    fn default() -> NelderMeadParams {
        NelderMeadParams::DEFAULT
    }
}

/// The result of [`minimize_nelder_mead`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimplexMinimum<const D: usize> {
    /// The best point found.
    pub x: [f64; D],
    /// `f(x)` (`+∞` where f returned NaN).
    pub fx: f64,
    /// Function evaluations used.
    pub evaluations: usize,
    /// True when the simplex shrank below `xatol`; false when the budget ran out.
    pub converged: bool,
}

/// Minimise `f` over `R^D` by the downhill simplex method, starting from the simplex
/// `{x₀, x₀ + s e₁, …, x₀ + s e_D}` (`s = params.step`).
///
/// Stops when `max_i max_k |x_i[k] − x_best[k]| ≤ params.xatol` or after
/// `params.max_evaluations` evaluations, whichever comes first. NaN values are treated as
/// `+∞`. The returned value is never larger than `f(x₀)`.
pub fn minimize_nelder_mead<const D: usize>(
    mut f: impl FnMut(&[f64; D]) -> f64,
    x0: [f64; D],
    params: &NelderMeadParams,
) -> SimplexMinimum<D> {
    let mut eval = |x: &[f64; D]| {
        let v = f(x);
        if v.is_nan() { f64::INFINITY } else { v }
    };
    let f0 = eval(&x0);
    let s = params.step;
    if D == 0 || !(s.is_finite() && s != 0.0) {
        return SimplexMinimum {
            x: x0,
            fx: f0,
            evaluations: 1,
            converged: D == 0,
        };
    }
    let budget = params.max_evaluations.max(1);
    // Vertices with their values, kept sorted best first.
    let mut simplex: Vec<([f64; D], f64)> = Vec::with_capacity(D + 1);
    simplex.push((x0, f0));
    for k in 0..D {
        if simplex.len() >= budget {
            break;
        }
        let mut x = x0;
        x[k] += s;
        let fx = eval(&x);
        simplex.push((x, fx));
    }
    let mut used = simplex.len();
    let mut converged = false;
    if simplex.len() == D + 1 {
        loop {
            sort(&mut simplex);
            if size(&simplex) <= params.xatol {
                converged = true;
                break;
            }
            if used >= budget {
                break;
            }
            let worst = simplex[D];
            let second_worst_f = simplex[D - 1].1;
            let best_f = simplex[0].1;
            let c = centroid(&simplex[..D]);
            let xr = affine(&c, &worst.0, -REFLECT);
            let fr = eval(&xr);
            used += 1;
            if fr < best_f {
                if used >= budget {
                    simplex[D] = (xr, fr);
                    continue;
                }
                let xe = affine(&c, &worst.0, -REFLECT * EXPAND);
                let fe = eval(&xe);
                used += 1;
                simplex[D] = if fe < fr { (xe, fe) } else { (xr, fr) };
                continue;
            }
            if fr < second_worst_f {
                simplex[D] = (xr, fr);
                continue;
            }
            if used >= budget {
                if fr < worst.1 {
                    simplex[D] = (xr, fr);
                }
                continue;
            }
            // Contraction: outside when the reflection improved on the worst, else inside.
            let (xc, fc, ok) = if fr < worst.1 {
                let xc = affine(&c, &worst.0, -REFLECT * CONTRACT);
                let fc = eval(&xc);
                (xc, fc, fc <= fr)
            } else {
                let xc = affine(&c, &worst.0, CONTRACT);
                let fc = eval(&xc);
                (xc, fc, fc < worst.1)
            };
            used += 1;
            if ok {
                simplex[D] = (xc, fc);
                continue;
            }
            // Shrink towards the best vertex.
            let best = simplex[0].0;
            for v in simplex.iter_mut().skip(1) {
                if used >= budget {
                    break;
                }
                for (vk, bk) in v.0.iter_mut().zip(&best) {
                    *vk = bk + SHRINK * (*vk - bk);
                }
                v.1 = eval(&v.0);
                used += 1;
            }
        }
    }
    sort(&mut simplex);
    let (x, fx) = simplex[0];
    SimplexMinimum {
        x,
        fx,
        evaluations: used,
        converged,
    }
}

/// Sort vertices by value, best first (a stable sort keeps older vertices first among ties).
fn sort<const D: usize>(simplex: &mut [([f64; D], f64)]) {
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
}

/// The largest coordinate distance of a vertex from the best one.
fn size<const D: usize>(simplex: &[([f64; D], f64)]) -> f64 {
    let best = simplex[0].0;
    simplex[1..]
        .iter()
        .flat_map(|v| v.0.iter().zip(&best).map(|(a, b)| (a - b).abs()))
        .fold(0.0, f64::max)
}

/// The centroid of the given vertices.
fn centroid<const D: usize>(vertices: &[([f64; D], f64)]) -> [f64; D] {
    let mut c = [0.0; D];
    for v in vertices {
        for (ck, vk) in c.iter_mut().zip(&v.0) {
            *ck += vk;
        }
    }
    let n = vertices.len() as f64;
    for ck in &mut c {
        *ck /= n;
    }
    c
}

/// `c + a·(x − c)`.
fn affine<const D: usize>(c: &[f64; D], x: &[f64; D], a: f64) -> [f64; D] {
    let mut out = [0.0; D];
    for k in 0..D {
        out[k] = c[k] + a * (x[k] - c[k]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rosenbrock(x: &[f64; 2]) -> f64 {
        (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2)
    }

    #[test]
    fn rosenbrock_2d() {
        let p = NelderMeadParams::DEFAULT
            .with_step(0.5)
            .with_xatol(1e-10)
            .with_max_evaluations(2000);
        let m = minimize_nelder_mead(rosenbrock, [-1.2, 1.0], &p);
        assert!(m.converged, "{m:?}");
        assert!(
            (m.x[0] - 1.0).abs() < 1e-6 && (m.x[1] - 1.0).abs() < 1e-6,
            "{m:?}"
        );
        assert!(m.fx < 1e-12);
        assert!(m.evaluations <= 2000);
    }

    #[test]
    fn rosenbrock_3d() {
        let f = |x: &[f64; 3]| {
            (0..2)
                .map(|i| (1.0 - x[i]).powi(2) + 100.0 * (x[i + 1] - x[i] * x[i]).powi(2))
                .sum::<f64>()
        };
        let p = NelderMeadParams::DEFAULT
            .with_step(0.5)
            .with_xatol(1e-10)
            .with_max_evaluations(5000);
        let m = minimize_nelder_mead(f, [0.0, 0.0, 0.0], &p);
        assert!(m.converged, "{m:?}");
        for xk in m.x {
            assert!((xk - 1.0).abs() < 1e-5, "{m:?}");
        }
    }

    #[test]
    fn anisotropic_quadratic_meets_xatol() {
        // f = (x−3)² + 10(y+2)² + (x−3)(y+2): positive definite, minimum at (3, −2).
        let f = |x: &[f64; 2]| {
            let (a, b) = (x[0] - 3.0, x[1] + 2.0);
            a * a + 10.0 * b * b + a * b + 7.0
        };
        let p = NelderMeadParams::with_scaled_step(0.1);
        assert!((p.xatol - 1e-10).abs() < 1e-24);
        let m = minimize_nelder_mead(f, [0.0, 0.0], &p.with_max_evaluations(1000));
        assert!(m.converged);
        // f is flat to rounding within ~sqrt(ε·f) ≈ 4e-8 of the minimum.
        assert!(
            (m.x[0] - 3.0).abs() < 1e-6 && (m.x[1] + 2.0).abs() < 1e-6,
            "{m:?}"
        );
        assert!((m.fx - 7.0).abs() < 1e-14);
    }

    #[test]
    fn minimum_on_a_boundary() {
        // Defined only on x + y ≤ 1 (+∞ outside, NaN in one corner); the unconstrained minimum
        // (2, 1) is outside, the constrained one is its projection (1, 0) on the boundary.
        let f = |x: &[f64; 2]| {
            if x[0] + x[1] > 1.0 {
                if x[0] > 5.0 { f64::NAN } else { f64::INFINITY }
            } else {
                (x[0] - 2.0).powi(2) + (x[1] - 1.0).powi(2)
            }
        };
        let p = NelderMeadParams::DEFAULT
            .with_step(0.25)
            .with_xatol(1e-12)
            .with_max_evaluations(4000);
        let m = minimize_nelder_mead(f, [-1.0, -1.0], &p);
        assert!(m.fx.is_finite());
        assert!(m.x[0] + m.x[1] <= 1.0);
        assert!((m.x[0] - 1.0).abs() < 1e-3 && m.x[1].abs() < 1e-3, "{m:?}");
        assert!((m.fx - 2.0).abs() < 1e-3);
    }

    #[test]
    fn budget_and_monotonicity() {
        let p = NelderMeadParams::DEFAULT.with_max_evaluations(10);
        let m = minimize_nelder_mead(rosenbrock, [-1.2, 1.0], &p);
        assert!(m.evaluations <= 10);
        assert!(!m.converged);
        assert!(m.fx <= rosenbrock(&[-1.2, 1.0]));
        // A start at the minimum stays there.
        let m = minimize_nelder_mead(rosenbrock, [1.0, 1.0], &NelderMeadParams::DEFAULT);
        assert_eq!(m.fx, 0.0);
        assert_eq!(m.x, [1.0, 1.0]);
    }

    #[test]
    fn degenerate_step_and_flat_function() {
        let m = minimize_nelder_mead(
            rosenbrock,
            [0.0, 0.0],
            &NelderMeadParams::DEFAULT.with_step(0.0),
        );
        assert_eq!((m.x, m.evaluations, m.converged), ([0.0, 0.0], 1, false));
        // A constant function: the simplex shrinks onto the start.
        let m = minimize_nelder_mead(|_: &[f64; 2]| 1.0, [0.5, 0.5], &NelderMeadParams::DEFAULT);
        assert!(m.converged);
        assert_eq!(m.x, [0.5, 0.5]);
    }
}
