/// The result of a 1-D minimisation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Minimum {
    /// The argument found.
    pub x: f64,
    /// The function value there.
    pub fx: f64,
    /// Function evaluations used.
    pub evaluations: usize,
}

const GOLDEN: f64 = 0.381_966_011_250_105_1; // (3 − √5)/2

/// Golden-section search for a minimum of `f` on `[a, b]` to absolute tolerance `tol` in x.
/// The two end points are evaluated too, and the best of all evaluated points is returned, so
/// a minimum at the boundary of the interval is found (docs/algorithms/cali.md §4.5).
pub fn minimize_golden(mut f: impl FnMut(f64) -> f64, a: f64, b: f64, tol: f64) -> Minimum {
    let (mut lo, mut hi) = if a <= b { (a, b) } else { (b, a) };
    let tol = tol.max(f64::EPSILON * (lo.abs() + hi.abs()));
    let mut best = Minimum {
        x: lo,
        fx: f(lo),
        evaluations: 1,
    };
    let consider = |x: f64, fx: f64, best: &mut Minimum| {
        if fx < best.fx || best.fx.is_nan() {
            best.x = x;
            best.fx = fx;
        }
    };
    let fb = f(hi);
    best.evaluations += 1;
    consider(hi, fb, &mut best);
    let mut x1 = lo + GOLDEN * (hi - lo);
    let mut x2 = hi - GOLDEN * (hi - lo);
    let mut f1 = f(x1);
    let mut f2 = f(x2);
    best.evaluations += 2;
    consider(x1, f1, &mut best);
    consider(x2, f2, &mut best);
    while hi - lo > tol {
        if f1 <= f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = lo + GOLDEN * (hi - lo);
            f1 = f(x1);
            consider(x1, f1, &mut best);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = hi - GOLDEN * (hi - lo);
            f2 = f(x2);
            consider(x2, f2, &mut best);
        }
        best.evaluations += 1;
    }
    best
}

/// Brent's method (parabolic interpolation safeguarded by golden sections) for a minimum of `f`
/// on `[a, b]`, to relative tolerance `rel_tol` and absolute tolerance `abs_tol` in x.
/// At most `max_eval` evaluations. The end points are not evaluated.
pub fn minimize_brent(
    mut f: impl FnMut(f64) -> f64,
    a: f64,
    b: f64,
    rel_tol: f64,
    abs_tol: f64,
    max_eval: usize,
) -> Minimum {
    let (mut a, mut b) = if a <= b { (a, b) } else { (b, a) };
    let mut x = a + GOLDEN * (b - a);
    let (mut w, mut v) = (x, x);
    let mut fx = f(x);
    let (mut fw, mut fv) = (fx, fx);
    let mut evaluations = 1;
    let (mut d, mut e) = (0.0_f64, 0.0_f64);
    while evaluations < max_eval {
        let m = 0.5 * (a + b);
        let tol = rel_tol * x.abs() + abs_tol;
        let t2 = 2.0 * tol;
        if (x - m).abs() <= t2 - 0.5 * (b - a) {
            break;
        }
        let mut use_golden = true;
        if e.abs() > tol {
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            } else {
                q = -q;
            }
            if p.abs() < (0.5 * q * e).abs() && p > q * (a - x) && p < q * (b - x) {
                e = d;
                d = p / q;
                let u = x + d;
                if u - a < t2 || b - u < t2 {
                    d = if x < m { tol } else { -tol };
                }
                use_golden = false;
            }
        }
        if use_golden {
            e = if x < m { b - x } else { a - x };
            d = GOLDEN * e;
        }
        let u = if d.abs() >= tol {
            x + d
        } else if d > 0.0 {
            x + tol
        } else {
            x - tol
        };
        let fu = f(u);
        evaluations += 1;
        if fu <= fx {
            if u < x {
                b = x;
            } else {
                a = x;
            }
            v = w;
            fv = fw;
            w = x;
            fw = fx;
            x = u;
            fx = fu;
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                v = w;
                fv = fw;
                w = u;
                fw = fu;
            } else if fu <= fv || v == x || v == w {
                v = u;
                fv = fu;
            }
        }
    }
    Minimum { x, fx, evaluations }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn golden_finds_interior_and_boundary_minima() {
        let m = minimize_golden(|x| (x - 0.3).powi(2), 0.0, 1.0, 1e-9);
        assert!((m.x - 0.3).abs() < 1e-8);
        let m = minimize_golden(|x| x, 0.0, 1.0, 1e-6);
        assert_eq!(m.x, 0.0);
        let m = minimize_golden(|x| -x, 0.0, 1.0, 1e-6);
        assert_eq!(m.x, 1.0);
    }

    #[test]
    fn brent_converges_fast() {
        let m = minimize_brent(|x| (x - 2.0).powi(2) + 1.0, -5.0, 5.0, 1e-10, 1e-12, 200);
        assert!((m.x - 2.0).abs() < 1e-7, "{m:?}");
        assert!(m.evaluations < 40, "{m:?}");
        let m = minimize_brent(|x: f64| x.cosh() - 0.5 * x, -3.0, 3.0, 1e-10, 1e-12, 200);
        assert!((m.x - 0.5f64.asinh()).abs() < 1e-7);
    }
}
