//! The KP rules on Hermite data `(t, points, tangents)`: parameters and the other tangents
//! kept, no re-interpolation, the `energy` rule carrying the tangent change `η*`
//! (`docs/algorithms/kjellander-poliakoff.md`, "Hermite data").

use super::rules::{KpRule, Local, check_hermite, check_unit_steps};
use crate::error::{Error, Result};
use crate::fair::engine::{
    JUMP_PARAMS, LocalProblem, MIN_CHORD_REL, MaxTree, Threshold, drive, driven_parameters,
    move_limit, step_fraction,
};
use crate::fair::{FairOptions, Outcome, ParamSpec};
use crate::geom::{BBox, Point, Vec2};

/// Hermite data faired in place: parameters fixed, tangents carried.
#[derive(Clone, Debug)]
struct HermiteState {
    rule: KpRule,
    /// Points held at each end (at least the end point; `--fix-ends`).
    held: usize,
    t: Vec<f64>,
    r: Vec<Point>,
    m: Vec<Vec2>,
    origin: Vec<Point>,
    disp: MaxTree,
    min_chord: f64,
    planned: (Vec2, Vec2),
}

impl HermiteState {
    fn local(&self, k: usize) -> Local {
        Local {
            a: self.t[k] - self.t[k - 1],
            b: self.t[k + 1] - self.t[k],
            rp: self.r[k - 1],
            r: self.r[k],
            rn: self.r[k + 1],
            mp: self.m[k - 1],
            m: self.m[k],
            mn: self.m[k + 1],
        }
    }
}

impl LocalProblem for HermiteState {
    fn slots(&self) -> usize {
        self.r.len()
    }

    fn is_candidate(&self, i: usize) -> bool {
        i >= self.held && i + self.held < self.r.len()
    }

    fn badness(&self, i: usize) -> f64 {
        self.local(i).badness()
    }

    fn plan(&mut self, k: usize, tolerance: Option<f64>) -> Option<f64> {
        let (delta, eta) = self.local(k).step(self.rule);
        if !(delta.is_finite() && eta.is_finite()) {
            return None;
        }
        let s = step_fraction(self.r[k] - self.origin[k], delta, tolerance);
        let new = self.r[k] + delta * s;
        if (new - self.r[k - 1]).length() < self.min_chord
            || (self.r[k + 1] - new).length() < self.min_chord
        {
            return None;
        }
        self.planned = (delta, eta);
        Some(s)
    }

    fn commit(&mut self, k: usize, s: f64, changed: &mut Vec<usize>) -> Result<(usize, f64)> {
        // F(sδ*, sη*) = −Q·s(2 − s) < 0 for s in (0, 1]: a scaled energy move still helps.
        let (delta, eta) = self.planned;
        self.r[k] += delta * s;
        self.m[k] += eta * s;
        self.disp.set(k, (self.r[k] - self.origin[k]).length());
        changed.extend([k - 1, k, k + 1]);
        Ok((k, (delta * s).length()))
    }

    fn max_displacement(&self) -> f64 {
        self.disp.max_value()
    }
}

/// The method parameters [`fair_hermite`] accepts.
pub(super) const HERMITE_PARAMS: &[ParamSpec] = &JUMP_PARAMS;

/// Fair Hermite data `(t, points, tangents)` by `rule` (docs/algorithms/kjellander-poliakoff.md
/// §2.6 without re-interpolation): the bad point is the interior point with the largest `|J_k|` of
/// the C¹ Hermite curve, it moves (and, for [`KpRule::Energy`], its tangent changes by `η*`), the
/// parameters and all other data are kept, and only the jumps at `k−1, k, k+1` change. Stopping,
/// tolerance and the report are as for the point methods ([`Kjellander`](super::Kjellander)); the
/// method parameters are
/// `threshold` and `epsilon`.
///
/// Returns an [`Outcome`] with the moved points and `tangents: Some(..)`.
///
/// # Errors
/// The data errors of [`hermite_step`]; [`Error::UnknownOption`] or
/// [`Error::InvalidParameter`] for bad options; for [`KpRule::Kjellander`], parameter steps
/// that are not 1.
///
/// [`hermite_step`]: super::hermite_step
pub fn fair_hermite(
    rule: KpRule,
    t: &[f64],
    points: &[Point],
    tangents: &[Vec2],
    options: &FairOptions,
) -> Result<Outcome> {
    check_hermite(t, points, tangents)?;
    if rule == KpRule::Kjellander {
        check_unit_steps(t)?;
    }
    options.validate()?;
    if let Some(key) = options
        .params
        .keys()
        .find(|k| !HERMITE_PARAMS.iter().any(|s| s.name == k.as_str()))
    {
        return Err(Error::UnknownOption {
            method: "hermite".into(),
            key: key.clone(),
            known: HERMITE_PARAMS
                .iter()
                .map(|s| s.name)
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    let threshold = Threshold::from_options(options)?;
    let n = points.len();
    let scale = BBox::from_points(points).map_or(0.0, |b| b.diagonal());
    let held = options.fix_ends.held().max(1);
    let mut state = HermiteState {
        rule,
        held,
        t: t.to_vec(),
        r: points.to_vec(),
        m: tangents.to_vec(),
        origin: points.to_vec(),
        disp: MaxTree::zeros(n),
        min_chord: MIN_CHORD_REL * scale,
        planned: (Vec2::ZERO, Vec2::ZERO),
    };
    let max_moves = move_limit(options, n.saturating_sub(2 * held));
    let driven = drive(&mut state, threshold, max_moves, options.tolerance)?;
    let parameters = driven_parameters(&driven, threshold, max_moves);
    Ok(Outcome {
        tangents: Some(state.m),
        ..driven.into_outcome(state.r, parameters)
    })
}
