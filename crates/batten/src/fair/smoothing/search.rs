//! The choice of p: bisection for a tolerance, or minimal GCV.

use super::{
    BISECTION_REL_PRECISION, Fit, GCV_LOG_ALPHA_TOL, GCV_MAX_EVALUATIONS, GCV_SCAN_STEP,
    LOG_ALPHA_ABOVE, LOG_ALPHA_BELOW, Problem, SmoothingInfo, SmoothingTrial, max_displacement,
    roughness,
};
use crate::error::{Error, Result};
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

    /// Tolerance mode: bisection on `ln α` for the largest feasible α. Each solved trial is
    /// measured once ([`Problem::trial`]), and its largest displacement decides.
    pub(super) fn search_tolerance(
        self,
        tolerance: f64,
        max_steps: usize,
    ) -> Result<(Fit<D>, SmoothingInfo)> {
        let mut trials = Vec::new();
        let mut notes = Vec::new();
        // A solved trial, recorded; whether it is within the tolerance.
        let record = |fit: &Fit<D>, trials: &mut Vec<SmoothingTrial>| {
            let trial = self.trial(fit, None);
            trials.push(trial);
            trial.max_displacement <= tolerance
        };
        // The smoothest candidate of an open curve: the least-squares line.
        if !self.closed {
            match self.fit_line() {
                Ok(line) => {
                    if record(&line, &mut trials) {
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
        let (mut lo, mut hi) = self.log_alpha_range();
        let top = self.fit_log_alpha(alpha_ref, hi, false);
        if top.as_ref().is_ok_and(|f| record(f, &mut trials)) {
            notes.push("the smoothest spline searched is within the tolerance".into());
            let fit = top?;
            return self.finish(fit, trials, true, notes);
        }
        // (The guard records a solved trial, feasible or not.)
        let mut best = match self.fit_log_alpha(alpha_ref, lo, false) {
            Ok(f) if record(&f, &mut trials) => f,
            _ => {
                notes.push(
                    "the tolerance is below what any smoothing allows; the result interpolates"
                        .into(),
                );
                let fit = interpolant(&self)?;
                return self.finish(fit, trials, true, notes);
            }
        };
        let precision = BISECTION_REL_PRECISION.ln_1p();
        let mut steps = 0;
        while hi - lo > precision && steps < max_steps {
            let mid = 0.5 * (lo + hi);
            let fit = self.fit_log_alpha(alpha_ref, mid, false);
            if fit.as_ref().is_ok_and(|f| record(f, &mut trials)) {
                lo = mid;
                best = fit?;
            } else {
                hi = mid;
            }
            steps += 1;
        }
        let converged = hi - lo <= precision;
        if !converged {
            notes.push(format!(
                "bisection stopped after {steps} steps with α known to a factor {:.3e}",
                (hi - lo).exp()
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
