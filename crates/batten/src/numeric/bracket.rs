//! A bracketing root finder for a monotone verdict: where to evaluate next, given what the
//! evaluations so far said. It serves `mst`'s tolerance mode (below, in its terms) and
//! `band`'s discrepancy weight (`fair/band/debias.rs`).
//!
//! The search looks for the largest `λ = ln(α/α_ref)` whose fit is feasible (largest
//! displacement `d(λ) ≤ tol`), to a bracket `[lo, hi]` — `lo` feasible, `hi` infeasible or the
//! end of the range — of width at most `precision`. It works on `g(λ) = ln(d(λ)/tol)`, which
//! is negative where a fit is feasible: `g` rises with slope 1 at the bottom of the range
//! (`d ∝ α` there) and flattens towards the line's displacement at the top, but between the
//! two it has plateaus (the noise smoothed away, the signal not yet) and kinks (another point
//! takes the largest displacement), so no one model of it holds (see "Choosing p" in
//! `fair/smoothing/mod.rs`).
//!
//! Chandrupatla's method (1997): inverse quadratic interpolation through the two ends of the
//! bracket and the point last dropped when the data say that the inverse quadratic is
//! monotone on the bracket, bisection otherwise. Adapted here in four ways:
//!
//! - The first step is the slope-1 guess from the bottom fit, `λ = lo − g(lo)`: exact while
//!   `d ∝ α`, so small tolerances are found in a step or two.
//! - Where Chandrupatla would bisect, a step that moved the same end of the bracket and
//!   brought `|g|` down by a factor over `1/`[`EXTRAPOLATE`] is followed by the secant through
//!   that end's last two points: `g` is then close to linear (as after the slope-1 guess in
//!   the regime `d ∝ α`), where the secant is nearly exact. A weaker reduction says `g` bends
//!   (a plateau, a kink), where extrapolating crawls.
//! - Every step keeps [`CLOSING`]`·precision` away from the ends of the bracket. When the
//!   interpolation lands within that of an end, the step goes that far past it, so that once
//!   the root is known to a fraction of the precision the bracket closes in one or two fits.
//! - Each step is projected towards the midpoint as in the ITP method (Oliveira & Takahashi
//!   2020): step `j` is at most `ε·2^(n_max − j) − w/2` from the midpoint of a bracket of width
//!   `w`, with `2ε` the precision and `n_max` the bisection's step count plus [`SLACK`]. Every
//!   step then leaves a bracket no wider than `ε·2^(n_max − j)`, so the search never takes more
//!   than [`SLACK`] steps more than the bisection would, whatever the data.
//!
//! The bracket only moves on the fits' verdicts (feasible or not), never on the values of
//! `g`, which only choose the next point: a fit that fails or whose displacement is not
//! finite counts as infeasible and makes the next step a bisection.

/// How far from the ends of the bracket every step keeps, in units of the precision (a
/// little under one, so that a step past an end closes the bracket when the root is in it).
const CLOSING: f64 = 0.99;

/// The secant extrapolates from the last two points on one side when the newer has
/// `|g|` below this fraction of the older's.
const EXTRAPOLATE: f64 = 0.02;

/// The steps the search may take beyond the bisection's count (the ITP method's `n₀`). Three
/// leaves room for the interpolation to approach from one side, as it must across a plateau,
/// before the projection forces bisection steps (with two, python_speed's curves take half a
/// fit more on average; with none, the bisection's count is the typical one). On the test
/// curves of up to 200 points the search never takes more fits than the bisection
/// (`fair/smoothing/search.rs`).
pub(crate) const SLACK: i32 = 3;

/// The state of the search: Chandrupatla's three points and the step budget.
#[derive(Clone, Debug)]
pub(crate) struct Bracket {
    /// The newest end of the bracket, `g` there, and whether its fit is feasible.
    x1: f64,
    f1: f64,
    feasible1: bool,
    /// The other end of the bracket and `g` there.
    x2: f64,
    f2: f64,
    /// The point the newest end replaced (NaN before the first step) and `g` there.
    x3: f64,
    f3: f64,
    /// The next point as a fraction of the way from `x1` to `x2`.
    t: f64,
    /// The largest width of a converged bracket.
    precision: f64,
    /// Half the width the projection aims for, a hair under half the precision so that
    /// rounding cannot leave the last bracket just wider than the precision.
    eps: f64,
    /// The step budget: the bisection's step count plus [`SLACK`].
    budget: i32,
    /// Steps taken.
    steps: i32,
    /// Whether the newest point moved the same end as the one before (`x3` is then that
    /// end's previous place).
    same_end: bool,
}

impl Bracket {
    /// The bracket `[lo, hi]` with `lo` feasible and `hi` infeasible or the end of the range,
    /// and `g` at both (NaN where unknown: a failed fit). The first step is the slope-1 guess
    /// from `lo`, or the midpoint when `g(lo)` is not finite (a zero displacement).
    pub(crate) fn new(lo: f64, g_lo: f64, hi: f64, g_hi: f64, precision: f64) -> Bracket {
        let eps = 0.5 * precision * (1.0 - 1e-9);
        let halvings = ((hi - lo) / (2.0 * eps)).log2().ceil().max(0.0);
        let t = -g_lo / (hi - lo);
        Bracket {
            x1: lo,
            f1: g_lo,
            feasible1: true,
            x2: hi,
            f2: g_hi,
            x3: f64::NAN,
            f3: f64::NAN,
            t: if t.is_finite() { t } else { 0.5 },
            precision,
            eps,
            budget: halvings as i32 + SLACK,
            steps: 0,
            same_end: false,
        }
    }

    /// The feasible end.
    pub(crate) fn lo(&self) -> f64 {
        if self.feasible1 { self.x1 } else { self.x2 }
    }

    /// The infeasible end (or the end of the range).
    pub(crate) fn hi(&self) -> f64 {
        if self.feasible1 { self.x2 } else { self.x1 }
    }

    /// `hi − lo`.
    pub(crate) fn width(&self) -> f64 {
        self.hi() - self.lo()
    }

    /// Whether the bracket is at most the precision wide.
    pub(crate) fn converged(&self) -> bool {
        self.width() <= self.precision
    }

    /// Where to fit next: strictly inside the bracket.
    pub(crate) fn next(&self) -> f64 {
        let (lo, hi) = (self.lo(), self.hi());
        let w = hi - lo;
        let mid = lo + 0.5 * w;
        let keep = CLOSING * self.precision / w;
        let t = if keep < 0.5 {
            self.t.clamp(keep, 1.0 - keep)
        } else {
            0.5
        };
        let x = self.x1 + t * (self.x2 - self.x1);
        let radius = (self.eps * 2f64.powi(self.budget - self.steps) - 0.5 * w).max(0.0);
        let x = x.clamp(mid - radius, mid + radius);
        if x > lo && x < hi { x } else { mid }
    }

    /// Take the verdict of the fit at `x` (from [`Bracket::next`]): whether it is feasible,
    /// and `g` there (NaN when unknown).
    pub(crate) fn update(&mut self, x: f64, feasible: bool, g: f64) {
        self.same_end = feasible == self.feasible1;
        if self.same_end {
            (self.x3, self.f3) = (self.x1, self.f1);
        } else {
            (self.x3, self.f3) = (self.x2, self.f2);
            (self.x2, self.f2) = (self.x1, self.f1);
        }
        (self.x1, self.f1, self.feasible1) = (x, g, feasible);
        self.steps += 1;
        self.t = self
            .interpolate()
            .or_else(|| self.extrapolate())
            .unwrap_or(0.5);
    }

    /// The secant through the newest point and the one it replaced, when both are on the
    /// same side and `|g|` fell by a factor over `1/`[`EXTRAPOLATE`], if it lands inside the
    /// bracket.
    fn extrapolate(&self) -> Option<f64> {
        let (x1, x2, x3) = (self.x1, self.x2, self.x3);
        let (f1, f3) = (self.f1, self.f3);
        let fast = f1.abs() < EXTRAPOLATE * f3.abs();
        if !(self.same_end && fast && f1.is_finite() && f3.is_finite()) {
            return None;
        }
        let e = x1 - f1 * (x1 - x3) / (f1 - f3);
        let t = (e - x1) / (x2 - x1);
        (t > 0.0 && t < 1.0).then_some(t)
    }

    /// Chandrupatla's step: inverse quadratic interpolation through the three points when
    /// `ξ = (x1 − x2)/(x3 − x2)` and `Φ = (f1 − f2)/(f3 − f2)` satisfy
    /// `1 − √(1 − ξ) < Φ < √ξ` (the inverse quadratic is then monotone between the ends).
    fn interpolate(&self) -> Option<f64> {
        let (x1, x2, x3) = (self.x1, self.x2, self.x3);
        let (f1, f2, f3) = (self.f1, self.f2, self.f3);
        if ![x3, f1, f2, f3].iter().all(|v| v.is_finite()) {
            return None;
        }
        let xi = (x1 - x2) / (x3 - x2);
        let phi = (f1 - f2) / (f3 - f2);
        if !(1.0 - (1.0 - xi).sqrt() < phi && phi < xi.sqrt()) {
            return None;
        }
        let alpha = (x3 - x1) / (x2 - x1);
        let t = f1 / (f2 - f1) * f3 / (f2 - f3) + alpha * f1 / (f3 - f1) * f2 / (f3 - f2);
        t.is_finite().then_some(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PRECISION: f64 = 9.995003330835332e-4; // ln(1.001)

    /// One synthetic case: its name, `g`, and the most steps it may take.
    type Case = (&'static str, Box<dyn Fn(f64) -> f64>, usize);

    /// Whether a fit with this `g` is feasible (NaN, a failed fit, is not).
    fn feasible(g: f64) -> bool {
        g <= 0.0
    }

    /// Run the search on `g` over `[lo, hi]` (feasible where `g ≤ 0`; NaN is a failed fit):
    /// the final bracket and the number of steps.
    fn run(g: impl Fn(f64) -> f64, lo: f64, hi: f64) -> (f64, f64, usize) {
        let mut b = Bracket::new(lo, g(lo), hi, g(hi), PRECISION);
        let mut steps = 0;
        while !b.converged() {
            let x = b.next();
            assert!(
                x > b.lo() && x < b.hi(),
                "step {x} outside [{}, {}]",
                b.lo(),
                b.hi()
            );
            let v = g(x);
            b.update(x, feasible(v), v);
            steps += 1;
            assert!(steps < 1000, "no convergence");
        }
        (b.lo(), b.hi(), steps)
    }

    /// The bisection's step count on `[lo, hi]`.
    fn bisection_steps(lo: f64, hi: f64) -> usize {
        ((hi - lo) / PRECISION).log2().ceil() as usize
    }

    /// Every function: the bracket holds its root, is at most the precision wide, and took
    /// at most SLACK steps more than the bisection; smooth ones take far fewer.
    #[test]
    fn brackets_the_root_of_awkward_functions() {
        let (lo, hi) = (-25.0, 29.2);
        let cases: Vec<Case> = vec![
            ("slope 1", Box::new(|x: f64| x - 3.0), 3),
            (
                "saturating",
                Box::new(|x: f64| (0.2 + x.exp()).ln() - (0.2 + 3f64.exp()).ln()),
                9,
            ),
            (
                "plateau then rise",
                Box::new(|x: f64| (x.min(0.0) - 0.4).max(0.45 * (x - 8.0))),
                5,
            ),
            (
                "flat near the top",
                Box::new(|x: f64| 0.05 - 1.2 * (-(x - 18.0)).exp().min(3.0)),
                12,
            ),
            (
                "zero displacement below",
                Box::new(|x: f64| if x < 0.0 { f64::NEG_INFINITY } else { x - 4.0 }),
                6,
            ),
            (
                "step",
                Box::new(|x: f64| if x < 7.3 { -1.0 } else { 1.0 }),
                19,
            ),
            (
                "failed fits above",
                Box::new(|x: f64| if x < 2.0 { x - 2.5 } else { f64::NAN }),
                19,
            ),
            (
                "non-monotone",
                Box::new(|x: f64| (x - 5.0) * 0.1 + (3.0 * x).sin() * 0.3),
                19,
            ),
        ];
        for (name, g, most) in cases {
            let (a, b, steps) = run(&g, lo, hi);
            assert!(feasible(g(a)) && !feasible(g(b)), "{name}: [{a}, {b}]");
            assert!(b - a <= PRECISION, "{name}: width {}", b - a);
            let bisection = bisection_steps(lo, hi);
            assert!(steps <= bisection + SLACK as usize, "{name}: {steps} steps");
            assert!(
                steps <= most,
                "{name}: {steps} steps, expected at most {most}"
            );
        }
    }

    /// The bracket closes when the step lands on the root exactly, and at either end of the
    /// range.
    #[test]
    fn roots_at_awkward_places() {
        for root in [-24.9999, -12.0, 0.0, 28.9, 29.1999] {
            let (a, b, _) = run(|x| x - root, -25.0, 29.2);
            assert!(
                a <= root && root < b && b - a <= PRECISION,
                "{root}: [{a}, {b}]"
            );
        }
    }
}
