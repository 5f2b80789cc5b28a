//! The two forms of the band problem: the unknowns are the points, or the control points of a
//! cubic B-spline through which the points are taken (dense points, `spline.rs`).

use super::design::Design;
use super::energy::{self, Energy, Metric};
use super::solver::Solution;
use super::spline::{Layout, Span, feasible_fit};
use crate::error::Result;

/// Knot spans per tolerance of curve length in the spline form: a span every tolerance
/// resolves every feature the band does not flatten anyway.
pub(super) const SPAN_TOLERANCES: f64 = 1.0;
/// The fewest points a knot span of the spline form must carry on average; with fewer the
/// point form is used.
pub(super) const MIN_POINTS_PER_SPAN: usize = 4;

/// One form of the problem.
#[derive(Debug)]
pub(super) struct Form<const D: usize> {
    /// The map from unknowns to points.
    pub design: Design,
    /// The unknowns that may not move.
    pub held: Vec<bool>,
    /// The points without a band constraint (held on their input points).
    pub pinned: Vec<bool>,
    closed: bool,
    kind: Kind,
}

#[derive(Debug)]
enum Kind {
    /// The unknowns are the points, with the energy's parameter steps.
    Points { chords: Vec<f64> },
    /// The unknowns are control points: the knot spans' energy coefficients and the feasible
    /// start, flat, in the solver's units.
    Spline {
        spans: Vec<Span>,
        fit: Vec<f64>,
        unit: f64,
    },
}

impl<const D: usize> Form<D> {
    /// The point form: `held` marks the held points; `chords` the parameter steps.
    pub(super) fn points(held: &[bool], chords: Vec<f64>, closed: bool) -> Form<D> {
        Form {
            design: Design::Points { n: held.len() },
            held: held.to_vec(),
            pinned: held.to_vec(),
            closed,
            kind: Kind::Points { chords },
        }
    }

    /// The spline form over the parameters of `chords` (the steps between the points, as
    /// the point form's, in the input's units), with a knot span every [`SPAN_TOLERANCES`]
    /// of their length, doubled until a feasible start is found. `scaled` is the input in
    /// the solver's units; `hold_ends` holds the end points (position) of an open curve.
    /// `None` when the spans would carry fewer than [`MIN_POINTS_PER_SPAN`] points.
    pub(super) fn spline(
        chords: &[f64],
        tolerance: f64,
        scaled: &[f64],
        closed: bool,
        hold_ends: bool,
    ) -> Result<Option<Form<D>>> {
        let n = scaled.len() / D;
        let mut t = energy::parameters(chords);
        let period = t[chords.len()];
        t.truncate(n);
        let length = chords.iter().sum::<f64>() / tolerance;
        let min_spans = if closed { 8 } else { 4 };
        let mut spans = ((length / SPAN_TOLERANCES).ceil() as usize).max(min_spans);
        loop {
            if spans * MIN_POINTS_PER_SPAN > n {
                return Ok(None);
            }
            let layout = Layout::new(&t, closed, period, spans);
            let vars = layout.design.vars();
            let mut held = vec![false; vars];
            let mut pinned = vec![false; n];
            let mut fixed = vec![0.0; vars * D];
            if hold_ends && !closed {
                held[0] = true;
                held[vars - 1] = true;
                pinned[0] = true;
                pinned[n - 1] = true;
                fixed[..D].copy_from_slice(&scaled[..D]);
                fixed[(vars - 1) * D..].copy_from_slice(&scaled[(n - 1) * D..]);
            }
            let ctrl = vec![[0.0; D]; vars];
            let unit = layout.energy_unit();
            let jerk = Energy::spline(&ctrl, closed, &layout.spans, unit, Metric::Jerk);
            if let Some(fit) = feasible_fit(&jerk, &layout, &held, &pinned, &fixed, scaled)? {
                return Ok(Some(Form {
                    design: layout.design,
                    held,
                    pinned,
                    closed,
                    kind: Kind::Spline {
                        spans: layout.spans,
                        fit,
                        unit,
                    },
                }));
            }
            spans *= 2;
        }
    }

    /// The energy's scale against the point form's units (see [`Layout::energy_unit`]).
    pub(super) fn unit(&self) -> f64 {
        match &self.kind {
            Kind::Points { .. } => 1.0,
            Kind::Spline { unit, .. } => *unit,
        }
    }

    /// The number of unknowns (points or control points).
    pub(super) fn vars(&self) -> usize {
        self.design.vars()
    }

    /// The first pass's reference, in the solver's units: the points `smoothed()` gives
    /// (flat) in the point form, the feasible start in the spline form.
    pub(super) fn first_reference(&self, smoothed: impl FnOnce() -> Vec<f64>) -> Vec<f64> {
        match &self.kind {
            Kind::Points { .. } => smoothed(),
            Kind::Spline { fit, .. } => fit.clone(),
        }
    }

    /// The energy of a pass with `metric`, its tangents from `shape` (the current points, any
    /// units) in the point form, from the control points of `reference` in the spline form.
    pub(super) fn energy(
        &self,
        shape: &[[f64; D]],
        reference: &[f64],
        metric: Metric,
    ) -> Energy<D> {
        match &self.kind {
            Kind::Points { chords } => {
                Energy::build_with_chords(chords, shape, self.closed, metric)
            }
            Kind::Spline { spans, unit, .. } => {
                let ctrl: Vec<[f64; D]> = reference
                    .chunks_exact(D)
                    .map(|c| std::array::from_fn(|a| c[a]))
                    .collect();
                Energy::spline(&ctrl, self.closed, spans, *unit, metric)
            }
        }
    }

    /// The solver's start relative to `reference`: the point form finds its own; the spline
    /// form starts at its feasible fit.
    pub(super) fn start(&self, reference: &[f64]) -> Option<Vec<f64>> {
        match &self.kind {
            Kind::Points { .. } => None,
            Kind::Spline { fit, .. } => {
                Some(fit.iter().zip(reference).map(|(f, s)| f - s).collect())
            }
        }
    }

    /// The reference after a solve: the solution's unknowns, absolute.
    pub(super) fn next_reference(
        &self,
        reference: &[f64],
        scaled: &[f64],
        sol: &Solution,
    ) -> Vec<f64> {
        match &self.kind {
            Kind::Points { .. } => scaled.iter().zip(&sol.r).map(|(a, r)| a + r).collect(),
            Kind::Spline { .. } => reference.iter().zip(&sol.y).map(|(s, y)| s + y).collect(),
        }
    }

    /// The held unknowns' values relative to a reference whose ball centres are `centres`.
    pub(super) fn fixed(&self, centres: &[f64]) -> Vec<f64> {
        match &self.kind {
            Kind::Points { .. } => centres.to_vec(),
            Kind::Spline { .. } => vec![0.0; self.vars() * D],
        }
    }
}
