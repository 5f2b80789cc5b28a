//! The choice of p: the smoothest spline within a tolerance ([`Bracket`]), or minimal GCV.

use super::{
    BISECTION_REL_PRECISION, Fit, GCV_LOG_ALPHA_TOL, GCV_MAX_EVALUATIONS, GCV_SCAN_STEP,
    LOG_ALPHA_ABOVE, LOG_ALPHA_BELOW, Problem, SmoothingInfo, SmoothingTrial, max_displacement,
    roughness,
};
use crate::error::{Error, Result};
use crate::numeric::Bracket;
use crate::numeric::minimize_brent;

impl<'a, const D: usize> Problem<'a, D> {
    pub(super) fn trial(&self, fit: &Fit<D>, gcv: Option<f64>) -> SmoothingTrial {
        SmoothingTrial {
            p: fit.p,
            alpha: fit.alpha,
            max_displacement: max_displacement(self.y, &fit.values),
            roughness: roughness(self.t, &fit.second, self.closed),
            gcv,
        }
    }

    /// The `ln(α/α_ref)` search interval.
    pub(super) fn log_alpha_range(&self) -> (f64, f64) {
        (
            -LOG_ALPHA_BELOW,
            4.0 * (self.n() as f64).ln() + LOG_ALPHA_ABOVE,
        )
    }

    /// The result of tolerance mode.
    pub(super) fn finish(
        self,
        fit: Fit<D>,
        trials: Vec<SmoothingTrial>,
        converged: bool,
        notes: Vec<String>,
    ) -> Result<(Fit<D>, SmoothingInfo)> {
        let info = SmoothingInfo {
            p: fit.p,
            alpha: fit.alpha,
            gcv: None,
            degrees_of_freedom: None,
            trials,
            converged,
            notes,
        };
        Ok((fit, info))
    }

    /// Tolerance mode: the largest feasible α, searched in `λ = ln(α/α_ref)` by [`Bracket`]
    /// until the feasible end of the bracket is within [`BISECTION_REL_PRECISION`] of the
    /// infeasible one. Each solved trial is measured once ([`Problem::trial`]), and its largest
    /// displacement decides; a fit that fails counts as infeasible.
    pub(super) fn search_tolerance(
        self,
        tolerance: f64,
        max_steps: usize,
    ) -> Result<(Fit<D>, SmoothingInfo)> {
        let mut trials = Vec::new();
        let mut notes = Vec::new();
        // A solved trial, recorded; whether it is within the tolerance, and
        // `g = ln(d/tolerance)` (NaN when the displacement is not finite).
        let record = |fit: &Fit<D>, trials: &mut Vec<SmoothingTrial>| {
            let trial = self.trial(fit, None);
            trials.push(trial);
            let d = trial.max_displacement;
            let g = if d.is_finite() {
                (d / tolerance).ln()
            } else {
                f64::NAN
            };
            (d <= tolerance, g)
        };
        // The smoothest candidate of an open curve: the least-squares line.
        if !self.closed {
            match self.fit_line() {
                Ok(line) => {
                    if record(&line, &mut trials).0 {
                        notes.push("the least-squares line is within the tolerance".into());
                        return self.finish(line, trials, true, notes);
                    }
                }
                Err(e @ Error::Singular(_)) => return Err(e),
                Err(_) => {} // more than two pins: no line candidate
            }
        }
        let interpolant = |problem: &Problem<'_, D>| problem.solve(1.0, 0.0, 0.0, false);
        if self.m() == 0 {
            let fit = interpolant(&self)?;
            return self.finish(fit, trials, true, notes);
        }
        let alpha_ref = self.alpha_ref()?;
        let (lo, hi) = self.log_alpha_range();
        let top = self.fit_log_alpha(alpha_ref, hi, false);
        let g_hi = match &top {
            Ok(f) => {
                let (feasible, g) = record(f, &mut trials);
                if feasible {
                    notes.push("the smoothest spline searched is within the tolerance".into());
                    let fit = top?;
                    return self.finish(fit, trials, true, notes);
                }
                g
            }
            Err(_) => f64::NAN,
        };
        // (The guard records a solved trial, feasible or not.)
        let bottom = self
            .fit_log_alpha(alpha_ref, lo, false)
            .map(|f| (record(&f, &mut trials), f));
        let (g_lo, mut best) = match bottom {
            // `g` from the exact displacement: the measured one cancels at the bottom.
            Ok(((true, _), f)) => ((self.displacement_from_second(&f) / tolerance).ln(), f),
            _ => {
                notes.push(
                    "the tolerance is below what any smoothing allows; the result interpolates"
                        .into(),
                );
                let fit = interpolant(&self)?;
                return self.finish(fit, trials, true, notes);
            }
        };
        let mut bracket = Bracket::new(lo, g_lo, hi, g_hi, BISECTION_REL_PRECISION.ln_1p());
        let mut steps = 0;
        while !bracket.converged() && steps < max_steps {
            let s = bracket.next();
            let (feasible, g) = match self.fit_log_alpha(alpha_ref, s, false) {
                Ok(fit) => {
                    let (feasible, g) = record(&fit, &mut trials);
                    if feasible {
                        best = fit;
                    }
                    (feasible, g)
                }
                Err(_) => (false, f64::NAN),
            };
            bracket.update(s, feasible, g);
            steps += 1;
        }
        let converged = bracket.converged();
        if !converged {
            notes.push(format!(
                "the search for p stopped after {steps} steps with α known to a factor {:.3e}",
                bracket.width().exp()
            ));
        }
        self.finish(best, trials, converged, notes)
    }

    /// GCV mode: coarse scan of `ln α`, then Brent around the best scan point.
    pub(super) fn search_gcv(self) -> Result<(Fit<D>, SmoothingInfo)> {
        if self.n() < 3 {
            return Err(Error::TooFewPoints {
                needed: 3,
                got: self.n(),
            });
        }
        let alpha_ref = self.alpha_ref()?;
        let n = self.n() as f64;
        let mut trials = Vec::new();
        let score = |s: f64, trials: &mut Vec<SmoothingTrial>| -> f64 {
            match self.fit_log_alpha(alpha_ref, s, true) {
                Ok(f) => {
                    let v = n * f.rss / (f.trace_residual * f.trace_residual);
                    let v = if v.is_finite() { v } else { f64::INFINITY };
                    trials.push(self.trial(&f, Some(v)));
                    v
                }
                Err(_) => f64::INFINITY,
            }
        };
        let (lo, hi) = self.log_alpha_range();
        let steps = ((hi - lo) / GCV_SCAN_STEP).ceil() as usize;
        let mut best = (f64::NAN, f64::INFINITY);
        for k in 0..=steps {
            let s = (lo + k as f64 * GCV_SCAN_STEP).min(hi);
            let v = score(s, &mut trials);
            if v < best.1 {
                best = (s, v);
            }
        }
        if !best.1.is_finite() {
            return Err(Error::NoConvergence(
                "generalised cross-validation: no trial spline could be solved".into(),
            ));
        }
        let (a, b) = (
            (best.0 - GCV_SCAN_STEP).max(lo),
            (best.0 + GCV_SCAN_STEP).min(hi),
        );
        let m = minimize_brent(
            |s| score(s, &mut trials),
            a,
            b,
            0.0,
            GCV_LOG_ALPHA_TOL,
            GCV_MAX_EVALUATIONS,
        );
        let converged = m.evaluations < GCV_MAX_EVALUATIONS;
        let s = if m.fx < best.1 { m.x } else { best.0 };
        let fit = self.fit_log_alpha(alpha_ref, s, true)?;
        let gcv = n * fit.rss / (fit.trace_residual * fit.trace_residual);
        let mut notes = Vec::new();
        if s <= lo || s >= hi {
            notes.push(format!(
                "the GCV minimum is at the end of the searched range (ln(α/α_ref) = {s:.1})"
            ));
        }
        let info = SmoothingInfo {
            p: fit.p,
            alpha: fit.alpha,
            gcv: Some(gcv),
            degrees_of_freedom: Some(n - fit.trace_residual),
            trials,
            converged,
            notes,
        };
        Ok((fit, info))
    }
}

#[cfg(test)]
mod tests {
    use super::super::DEFAULT_MAX_SEARCH_STEPS;
    use super::*;
    use crate::numeric::BRACKET_SLACK as SLACK;
    use crate::test_rng::Rng;
    use proptest::prelude::*;

    /// `ln(1 + BISECTION_REL_PRECISION)`: the widest converged bracket in `ln α`.
    fn precision() -> f64 {
        BISECTION_REL_PRECISION.ln_1p()
    }

    /// Chord-length parameters (one more than points when closed).
    fn chord(y: &[[f64; 2]], closed: bool) -> Vec<f64> {
        let n = y.len();
        let spans = if closed { n } else { n - 1 };
        let mut t = vec![0.0];
        for i in 0..spans {
            let (a, b) = (y[i], y[(i + 1) % n]);
            t.push(t[i] + (b[0] - a[0]).hypot(b[1] - a[1]));
        }
        t
    }

    /// The bisection this search replaced, as it was: the number of fits and the result's α.
    fn bisection(problem: &Problem<'_, 2>, tolerance: f64) -> (usize, f64) {
        let feasible = |fit: &Fit<2>| max_displacement(problem.y, &fit.values) <= tolerance;
        let mut fits = 0;
        if !problem.closed {
            fits += 1;
            if problem.fit_line().is_ok_and(|f| feasible(&f)) {
                return (fits, f64::INFINITY);
            }
        }
        let alpha_ref = problem.alpha_ref().unwrap();
        let (mut lo, mut hi) = problem.log_alpha_range();
        fits += 1;
        if let Ok(top) = problem.fit_log_alpha(alpha_ref, hi, false)
            && feasible(&top)
        {
            return (fits, top.alpha);
        }
        fits += 1;
        let bottom = problem.fit_log_alpha(alpha_ref, lo, false);
        let Ok(mut best) = bottom
            .map_err(|_| ())
            .and_then(|f| if feasible(&f) { Ok(f) } else { Err(()) })
        else {
            return (fits, 0.0);
        };
        while hi - lo > precision() {
            let mid = 0.5 * (lo + hi);
            fits += 1;
            match problem.fit_log_alpha(alpha_ref, mid, false) {
                Ok(f) if feasible(&f) => {
                    lo = mid;
                    best = f;
                }
                _ => hi = mid,
            }
        }
        (fits, best.alpha)
    }

    /// A test curve: points, closed, pinned ends.
    struct Curve {
        name: String,
        y: Vec<[f64; 2]>,
        closed: bool,
        pinned: bool,
    }

    /// Noisy sines, circle arcs (open and closed) and clothoid-like spirals of 10, 200 and
    /// 5000 points, the open ones also with pinned ends.
    fn curves() -> Vec<Curve> {
        let mut rng = Rng::new(17);
        let mut out = Vec::new();
        for n in [10usize, 200, 5000] {
            let mut noisy =
                |p: [f64; 2], s: f64| [p[0] + s * rng.gaussian(), p[1] + s * rng.gaussian()];
            let sine: Vec<[f64; 2]> = (0..n)
                .map(|i| {
                    let x = 6.0 * i as f64 / (n - 1) as f64;
                    noisy([x, x.sin()], 0.01)
                })
                .collect();
            let arc: Vec<[f64; 2]> = (0..n)
                .map(|i| {
                    let a = 2.0 * i as f64 / (n - 1) as f64;
                    noisy([5.0 * a.cos(), 5.0 * a.sin()], 0.02)
                })
                .collect();
            let circle: Vec<[f64; 2]> = (0..n)
                .map(|i| {
                    let a = std::f64::consts::TAU * i as f64 / n as f64;
                    noisy([3.0 * a.cos(), 3.0 * a.sin()], 0.02)
                })
                .collect();
            // Curvature growing linearly with arc length, s ∈ [0, 2.5].
            let h = 2.5 / n as f64;
            let (mut p, mut angle) = ([0.0, 0.0], 0.0f64);
            let clothoid: Vec<[f64; 2]> = (0..n)
                .map(|i| {
                    angle += std::f64::consts::PI * i as f64 * h * h;
                    p = [p[0] + angle.cos() * h, p[1] + angle.sin() * h];
                    noisy(p, 0.002)
                })
                .collect();
            for (name, y, closed) in [
                ("sine", sine, false),
                ("arc", arc, false),
                ("circle", circle, true),
                ("clothoid", clothoid, false),
            ] {
                if !closed {
                    out.push(Curve {
                        name: format!("{name} {n} pinned"),
                        y: y.clone(),
                        closed,
                        pinned: true,
                    });
                }
                out.push(Curve {
                    name: format!("{name} {n}"),
                    y,
                    closed,
                    pinned: false,
                });
            }
        }
        out
    }

    /// Whether a displacement is within the tolerance (NaN is not).
    fn within(d: f64, tolerance: f64) -> bool {
        d <= tolerance
    }

    /// What the guarantee asks of a search's result: within the tolerance, converged, and
    /// either one of the ends of the search (the line, the top of the range, the interpolant,
    /// each with its note) or the feasible end of a bracket at most `ln(1.001)` wide whose
    /// infeasible end is a recorded trial. Returns `λ` of the result (None for the ends).
    fn check_guarantee(
        problem: &Problem<'_, 2>,
        tolerance: f64,
        fit: &Fit<2>,
        info: &SmoothingInfo,
        what: &str,
    ) -> Option<f64> {
        let d = max_displacement(problem.y, &fit.values);
        assert!(d <= tolerance, "{what}: displacement {d} over {tolerance}");
        assert!(info.converged, "{what}: {:?}", info.notes);
        if !info.notes.is_empty() {
            return None;
        }
        let alpha_ref = problem.alpha_ref().unwrap();
        let s = (fit.alpha / alpha_ref).ln();
        let hi = info
            .trials
            .iter()
            .filter(|t| t.alpha > fit.alpha && !within(t.max_displacement, tolerance))
            .map(|t| (t.alpha / alpha_ref).ln())
            .fold(f64::INFINITY, f64::min);
        // Or the infeasible end is a fit that failed (not recorded as a trial): near the top
        // of the range the closed system of 5000 points is barely definite, and some fits fail.
        let failed = || {
            (1..=64).any(|k| {
                let x = s + precision() * k as f64 / 64.0;
                problem.fit_log_alpha(alpha_ref, x, false).is_err()
            })
        };
        assert!(
            hi - s <= precision() * (1.0 + 1e-9) || failed(),
            "{what}: bracket [{s}, {hi}]"
        );
        Some(s)
    }

    /// The fit `ln(1.001)` smoother than `s` breaks the tolerance (where the displacement
    /// grows with α, the bracket says as much; the test curves of 10 and 200 points are such).
    fn check_tight(problem: &Problem<'_, 2>, tolerance: f64, s: f64, what: &str) {
        if s + precision() < problem.log_alpha_range().1 {
            let alpha_ref = problem.alpha_ref().unwrap();
            let rougher = problem
                .fit_log_alpha(alpha_ref, s + precision(), false)
                .unwrap();
            let d = max_displacement(problem.y, &rougher.values);
            assert!(d > tolerance, "{what}: λ + ln(1.001) is feasible ({d})");
        }
    }

    /// On every test curve and tolerance (from far below the noise to above the smoothest
    /// spline's displacement): the guarantee, and at most SLACK fits more than the
    /// bisection. Up to 200 points also: the answer is tight, is the bisection's to within
    /// the precision, and took no more fits than the bisection. (At 5000 points the largest
    /// displacement is not monotone in α near the line's to within 1e-3, and the two searches
    /// may stop at different crossings of the tolerance, each the feasible end of a bracket.)
    #[test]
    fn search_keeps_the_guarantee_with_fewer_fits() {
        let (mut fits_new, mut fits_old) = (0, 0);
        for c in curves() {
            let n = c.y.len();
            let t = chord(&c.y, c.closed);
            let pins: Vec<f64> = (0..n)
                .map(|i| {
                    if c.pinned && (i == 0 || i == n - 1) {
                        f64::INFINITY
                    } else {
                        1.0
                    }
                })
                .collect();
            let weights = c.pinned.then_some(&pins[..]);
            let problem = || {
                Problem::new(&t, &c.y, weights, c.closed)
                    .unwrap()
                    .with_terms()
            };
            let reference = problem();
            let alpha_ref = reference.alpha_ref().unwrap();
            // The displacement of the smoothest spline that can be solved.
            let widest = [0.0, 4.0, 8.0]
                .iter()
                .find_map(|back| {
                    let s = reference.log_alpha_range().1 - back;
                    reference.fit_log_alpha(alpha_ref, s, false).ok()
                })
                .map(|f| max_displacement(&c.y, &f.values))
                .unwrap();
            for f in [1e-9, 1e-4, 0.01, 0.05, 0.2, 0.5, 0.9, 0.999, 1.5] {
                let tolerance = f * widest;
                let what = format!("{} at {tolerance:.3e}", c.name);
                let (fit, info) = problem()
                    .search_tolerance(tolerance, DEFAULT_MAX_SEARCH_STEPS)
                    .unwrap();
                let s = check_guarantee(&reference, tolerance, &fit, &info, &what);
                let (old, alpha_old) = bisection(&reference, tolerance);
                let new = info.trials.len();
                assert!(
                    new <= old + SLACK as usize,
                    "{what}: {new} fits, the bisection {old}"
                );
                if n <= 200 {
                    assert!(new <= old, "{what}: {new} fits, the bisection {old}");
                    if let Some(s) = s {
                        check_tight(&reference, tolerance, s, &what);
                        let s_old = (alpha_old / alpha_ref).ln();
                        assert!(
                            (s - s_old).abs() <= precision(),
                            "{what}: λ {s}, the bisection's {s_old}"
                        );
                    }
                }
                (fits_new, fits_old) = (fits_new + new, fits_old + old);
            }
        }
        // 1782 and 3244 when written.
        assert!(
            5 * fits_new < 3 * fits_old,
            "{fits_new} fits, the bisection {fits_old}"
        );
    }

    /// The step limit: the result still holds the tolerance, says it did not converge, and
    /// the search took exactly that many steps after the bottom fit.
    #[test]
    fn step_limit_keeps_the_tolerance() {
        let c = &curves()[1]; // the open noisy sine of 10 points
        let t = chord(&c.y, false);
        for max_steps in [0, 1, 2, 3] {
            let problem = Problem::new(&t, &c.y, None, false).unwrap().with_terms();
            let (fit, info) = problem.search_tolerance(0.01, max_steps).unwrap();
            assert!(max_displacement(&c.y, &fit.values) <= 0.01);
            assert!(!info.converged);
            assert_eq!(info.trials.len(), 3 + max_steps);
            assert!(
                info.notes[0].contains(&format!("stopped after {max_steps} steps")),
                "{:?}",
                info.notes
            );
        }
    }

    /// The displacement from the second derivatives is the measured one where that does not
    /// cancel, and keeps its digits at the bottom of the range where the measured one loses
    /// them: the same on the data moved far from the origin.
    #[test]
    fn displacement_from_second_derivatives() {
        for c in curves().iter().filter(|c| c.y.len() == 200) {
            let n = c.y.len();
            let pins: Vec<f64> = (0..n)
                .map(|i| {
                    if i == 0 || i == n - 1 {
                        f64::INFINITY
                    } else {
                        1.0
                    }
                })
                .collect();
            let weights = c.pinned.then_some(&pins[..]);
            let far: Vec<[f64; 2]> = c.y.iter().map(|p| [p[0] + 1e3, p[1] - 2e3]).collect();
            let t = chord(&c.y, c.closed);
            let near = Problem::new(&t, &c.y, weights, c.closed).unwrap();
            let moved = Problem::new(&t, &far, weights, c.closed).unwrap();
            let alpha_ref = near.alpha_ref().unwrap();
            for s in [-25.0, -5.0, 0.0, 5.0] {
                let (a, b) = (
                    near.fit_log_alpha(alpha_ref, s, false).unwrap(),
                    moved.fit_log_alpha(alpha_ref, s, false).unwrap(),
                );
                let (exact, exact_far) = (
                    near.displacement_from_second(&a),
                    moved.displacement_from_second(&b),
                );
                assert!(
                    (exact_far / exact - 1.0).abs() < 1e-9,
                    "{} at {s}: {exact} vs {exact_far}",
                    c.name
                );
                let measured = max_displacement(&c.y, &a.values);
                let within = if s < -20.0 { 1e-2 } else { 1e-9 };
                assert!(
                    (measured / exact - 1.0).abs() < within,
                    "{} at {s}: {measured} vs {exact}",
                    c.name
                );
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Random noisy curves and tolerances: the guarantee, and at most SLACK fits more
        /// than the bisection.
        #[test]
        fn guarantee_on_random_curves(
            seed in 0u64..1_000_000,
            n in 4usize..300,
            closed in any::<bool>(),
            noise in 1e-4f64..0.3,
            turn in 0.0f64..6.0,
            fraction in 1e-6f64..1.2,
        ) {
            let mut rng = Rng::new(seed);
            let y: Vec<[f64; 2]> = (0..n)
                .map(|i| {
                    let a = turn * i as f64 / n as f64;
                    let r = 1.0 + 0.3 * (3.0 * a).sin();
                    let (dx, dy) = (noise * rng.gaussian(), noise * rng.gaussian());
                    [r * a.cos() + dx, r * a.sin() + 0.5 * a + dy]
                })
                .collect();
            let t = chord(&y, closed);
            prop_assume!(t.windows(2).all(|w| w[1] > w[0]));
            let reference = Problem::new(&t, &y, None, closed).unwrap();
            let alpha_ref = reference.alpha_ref().unwrap();
            let top = reference.fit_log_alpha(alpha_ref, reference.log_alpha_range().1, false);
            prop_assume!(top.is_ok());
            let tolerance = fraction * max_displacement(&y, &top.unwrap().values);
            prop_assume!(tolerance > 0.0);
            let (fit, info) = Problem::new(&t, &y, None, closed)
                .unwrap()
                .with_terms()
                .search_tolerance(tolerance, DEFAULT_MAX_SEARCH_STEPS)
                .unwrap();
            check_guarantee(&reference, tolerance, &fit, &info, &format!("seed {seed}"));
            let (old, _) = bisection(&reference, tolerance);
            prop_assert!(info.trials.len() <= old + SLACK as usize);
        }
    }
}
