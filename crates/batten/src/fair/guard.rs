//! Two safeguards of the common path that every method shares ([`super::fair_with`],
//! [`super::fair_curve`]):
//!
//! - **Any coordinate scale.** A method runs on the input divided by a power of two
//!   ([`crate::geom::unit_scale`], exact) when the larger side of its bounding box is outside
//!   `[2^-METHOD_SCALE_RANGE_LOG2, 2^METHOD_SCALE_RANGE_LOG2]`, and its result is multiplied
//!   back. Inside that range the methods run on the data as given (they are equivariant
//!   under scaling there, which `tests/scale.rs` checks from 10⁻¹⁵⁰ to 10¹⁵⁰); outside it,
//!   squares and cubes of coordinates would over- or underflow. The tolerance is divided by
//!   the same factor, and parameters in data units are converted by the method
//!   ([`super::FairMethod::params_at_scale`], e.g. `mst`'s `p`, the Kjellander family's
//!   `epsilon`, `kuragano`'s `rho_max`).
//! - **Clean curves come back clean.** A result with more inflections, more curvature
//!   vibrations (sign changes of the jumps of dκ/ds) than an input without inflections, or a
//!   higher variation energy `∫(dκ/ds)² ds` than its input (all on the analysis curve,
//!   [`FairnessMetrics`]) is replaced by the input, with status `no_change` and a note. The
//!   comparison allows a relative slack of [`CLEAN_SLACK_REL`] on the energy, the size of
//!   rounding in its computation. `mst` (the csaps baseline) is exempt
//!   ([`super::FairMethod::keeps_clean`]), and [`super::FairOptions::keep_clean`] turns the
//!   guard off. The per-move half of the promise, for clean inputs, is in `clean.rs`. Space
//!   curves ([`super::fair_space`]) have the same guard on their own measures
//!   ([`SpaceMetrics`]: curvature extrema, torsion sign changes, variation energy).

use super::{FairMethod, FairOptions, HistoryRow, Outcome};
use crate::analysis::{FairnessMetrics, SpaceMetrics};
use crate::error::Result;
use crate::geom::{Point, PointSeq, Rigid, Vec2, pow2, scale_points, unit_scale};

/// Methods run on the coordinates as given while the larger side of the bounding box is
/// within `2^±METHOD_SCALE_RANGE_LOG2` (about 5·10⁻²⁰ to 2·10¹⁹), and on coordinates divided
/// by [`unit_scale`] outside it.
pub const METHOD_SCALE_RANGE_LOG2: i32 = 64;

/// Relative slack of the clean-curve guard on the variation energy: a result whose energy
/// exceeds the input's by less than this fraction counts as not higher. The energy is a sum
/// of about 10·n quadrature terms, each exact to a few ulps; 10⁻⁹ is above that rounding
/// for any n this crate handles and far below any change a move makes.
pub const CLEAN_SLACK_REL: f64 = 1e-9;

/// The options a method runs with: the per-move clean-curve check (`clean.rs`, the methods
/// read it from [`FairOptions::keep_clean`]) is on only for an input that is clean as a
/// whole, without inflections or curvature vibrations (`before`). On noisy input the method
/// is there to remove wiggles, and its greedy moves may pass through a locally worse state on
/// the way (checking every move left 2 of the more than 10 inflections of a noisy circle
/// that `han` otherwise removes); the guard on the whole result still applies.
pub(crate) fn per_move_options(options: &FairOptions, before: &FairnessMetrics) -> FairOptions {
    let clean = before.inflections == 0 && before.vibrations == 0;
    options.clone().with_keep_clean(options.keep_clean && clean)
}

/// Run `run` (a method whose steps depend on the orientation of the axes: `salvi`'s
/// Nelder–Mead simplex is axis-aligned) on
/// `input` moved into its principal frame, and move its result back, so that a rigid motion
/// of the input moves the result with it (to rounding) instead of changing it by up to 1 %
/// of the curve's size. The frame: origin at the centroid, x axis along the principal axis of
/// the points' scatter (`½·atan2(2Sxy, Sxx − Syy)`), pointing from the first point towards
/// the last. Points the method left where they were are returned bit for bit.
pub(crate) fn in_principal_frame(
    input: &PointSeq,
    run: impl FnOnce(&PointSeq) -> Result<Outcome>,
) -> Result<Outcome> {
    let pts = input.points();
    let n = pts.len() as f64;
    let c = pts
        .iter()
        .fold(Vec2::ZERO, |a, p| a + p.to_vec2() * (1.0 / n));
    let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
    for p in pts {
        let d = p.to_vec2() - c;
        sxx += d.x * d.x;
        syy += d.y * d.y;
        sxy += d.x * d.y;
    }
    let mut theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    if !theta.is_finite() {
        return run(input);
    }
    let span = pts[pts.len() - 1] - pts[0];
    if span.x * theta.cos() + span.y * theta.sin() < 0.0 {
        theta += std::f64::consts::PI;
    }
    let to_local = Rigid::to_local_frame(Point::new(c.x, c.y), theta);
    let back = to_local.inverse();
    let local: Vec<Point> = pts.iter().map(|&p| to_local.apply(p)).collect();
    let mut outcome = run(&input.with_points(local.clone())?)?;
    for ((o, l), p) in outcome.points.iter_mut().zip(&local).zip(pts) {
        *o = if *o == *l { *p } else { back.apply(*o) };
    }
    if let Some(curve) = &outcome.curve {
        let ctrl = curve
            .control_points()
            .iter()
            .map(|&q| back.apply(q))
            .collect();
        outcome.curve = Some(curve.with_control_points(ctrl)?);
    }
    Ok(outcome)
}

/// The factor a method's coordinates are divided by: `1.0` inside the safe range.
pub(crate) fn method_scale(input: &PointSeq) -> f64 {
    method_scale_of(unit_scale(input.points()))
}

/// The factor a method's coordinates are divided by for data of [`unit_scale`] `s`: `1.0`
/// inside the safe range, else `s`.
pub(crate) fn method_scale_of(s: f64) -> f64 {
    let lim = pow2(METHOD_SCALE_RANGE_LOG2);
    if s > 1.0 / lim && s < lim { 1.0 } else { s }
}

/// The options of a run in coordinates divided by `s`: the method's parameters in data units
/// converted ([`FairMethod::params_at_scale`]), the tolerance divided.
pub(crate) fn unit_options(
    m: &dyn FairMethod,
    options: &FairOptions,
    s: f64,
) -> Result<FairOptions> {
    let mut opts = m.params_at_scale(options, s)?;
    opts.tolerance = options.tolerance.map(|t| t / s);
    // σ̂ of the data, not of these coordinates: the method measures its own.
    opts.measured_noise = None;
    Ok(opts)
}

/// The parts of an outcome computed in coordinates divided by `s` that every method has, back
/// in data units: the history's distances and the reported parameters in data units
/// ([`FairMethod::report_params_at_scale`]), and a note.
pub(crate) fn trace_from_unit(
    m: &dyn FairMethod,
    history: &mut [HistoryRow],
    parameters: &mut serde_json::Map<String, serde_json::Value>,
    notes: &mut Vec<String>,
    s: f64,
) {
    for h in history {
        h.max_distance *= s;
    }
    m.report_params_at_scale(parameters, s);
    notes.push(format!(
        "the method ran on the coordinates divided by 2^{} (the data's scale is outside \
         2^±{METHOD_SCALE_RANGE_LOG2}); displacements, metrics and the curve are in data \
         units, the method's own measures in those units",
        s.log2()
    ));
}

/// The input and the options in unit coordinates (`s` from [`method_scale`]).
pub(crate) fn to_unit(
    m: &dyn FairMethod,
    input: &PointSeq,
    options: &FairOptions,
    s: f64,
) -> Result<(PointSeq, FairOptions)> {
    let unit = input.with_points(scale_points(input.points(), 1.0 / s))?;
    Ok((unit, unit_options(m, options, s)?))
}

/// An outcome computed in unit coordinates, back in data units: points, the curve, move
/// lengths and the history's distances. The method's own measures (move and history
/// `before`/`after`/`measure`) and its reported parameters stay in unit coordinates, which
/// a note says; [`FairMethod::params_at_scale`] methods convert their own.
pub(crate) fn from_unit(m: &dyn FairMethod, outcome: &mut Outcome, s: f64) -> Result<()> {
    outcome.points = scale_points(&outcome.points, s);
    if let Some(c) = &outcome.curve {
        outcome.curve = Some(c.with_control_points(scale_points(c.control_points(), s))?);
    }
    for mv in &mut outcome.moves {
        mv.distance *= s;
    }
    trace_from_unit(
        m,
        &mut outcome.history,
        &mut outcome.parameters,
        &mut outcome.notes,
        s,
    );
    Ok(())
}

/// Why `after` is worse than `before` by the clean-curve rule (more inflections, more
/// curvature vibrations than an input without inflections, or a higher variation energy beyond [`CLEAN_SLACK_REL`]), or `None`. Both are measured in
/// the same coordinates (unit coordinates, so that the energies are finite).
pub(crate) fn worse(before: &FairnessMetrics, after: &FairnessMetrics) -> Option<String> {
    let mut why = Vec::new();
    if after.inflections > before.inflections {
        why.push(format!(
            "more inflections ({} → {})",
            before.inflections, after.inflections
        ));
    }
    // Vibrations count only on an input without inflections (a clean shape: an exact ellipse
    // has 4, at its vertices, and poliakoff took one to 12): on a noisy input their number
    // moves by a few either way while a method removes the noise (salvi on a noisy sine:
    // 48 → 50 with a lower variation energy), and the energy says whether it got worse.
    if before.inflections == 0 && after.vibrations > before.vibrations {
        why.push(format!(
            "more curvature vibrations ({} → {})",
            before.vibrations, after.vibrations
        ));
    }
    why.extend(higher_energy(
        before.variation_energy,
        after.variation_energy,
    ));
    (!why.is_empty()).then(|| why.join(" and "))
}

/// The clean-curve rule's energy part: why the variation energy `after` is higher than
/// `before` beyond [`CLEAN_SLACK_REL`] (or NaN where it was not), or `None`.
fn higher_energy(before: f64, after: f64) -> Option<String> {
    (after > before * (1.0 + CLEAN_SLACK_REL) || (after.is_nan() && !before.is_nan())).then(|| {
        format!(
            "a higher variation energy ∫(dκ/ds)² ds ({before:.6e} → {after:.6e} in units of \
             the data's scale)"
        )
    })
}

/// The clean-curve rule for space curves: why `after` is worse than `before` (more
/// curvature extrema, more torsion sign changes, or a higher variation energy beyond
/// [`CLEAN_SLACK_REL`]), or `None`. Both in the same (unit) coordinates.
pub(crate) fn worse_space(before: &SpaceMetrics, after: &SpaceMetrics) -> Option<String> {
    let mut why = Vec::new();
    if after.curvature_extrema > before.curvature_extrema {
        why.push(format!(
            "more curvature extrema ({} → {})",
            before.curvature_extrema, after.curvature_extrema
        ));
    }
    if after.torsion_sign_changes > before.torsion_sign_changes {
        why.push(format!(
            "more torsion sign changes ({} → {})",
            before.torsion_sign_changes, after.torsion_sign_changes
        ));
    }
    why.extend(higher_energy(
        before.variation_energy,
        after.variation_energy,
    ));
    (!why.is_empty()).then(|| why.join(" and "))
}

/// The note of a result the clean-curve guard replaced by the input; `why` from [`worse`] or
/// [`worse_space`].
pub(crate) fn guard_note(why: &str) -> String {
    format!(
        "the result had {why} than the input, so the input is returned unchanged (the \
         clean-curve guard; keep_clean = false turns it off)"
    )
}

/// Rewrite the parameter `key` of `options`, a quantity of length power `power` given in
/// data units, to its value in coordinates divided by `s` (`value / s^power`). `auto`, an
/// absent key and text that is not a number are left for the method's own check.
pub(crate) fn scale_length_param(options: &mut FairOptions, key: &str, power: i32, s: f64) {
    let Some(Ok(v)) = options.params.get(key).map(|t| t.trim().parse::<f64>()) else {
        return;
    };
    let mut unit = v;
    // One factor at a time: s^power alone may overflow where the product does not.
    for _ in 0..power.unsigned_abs() {
        unit = if power > 0 { unit / s } else { unit * s };
    }
    options.params.insert(key.to_string(), format!("{unit:e}"));
}

/// Convert the reported parameter `key`, a number of length power `power` computed in
/// coordinates divided by `s`, back to data units (`value · s^power`).
pub(crate) fn scale_reported(
    parameters: &mut serde_json::Map<String, serde_json::Value>,
    key: &str,
    power: i32,
    s: f64,
) {
    let Some(v) = parameters.get(key).and_then(serde_json::Value::as_f64) else {
        return;
    };
    let mut data = v;
    for _ in 0..power.unsigned_abs() {
        data = if power > 0 { data * s } else { data / s };
    }
    parameters.insert(key.to_string(), super::local::json_f64(data));
}

/// [`FairMethod::params_at_scale`] for methods whose parameters in data units are the
/// `(name, length power)` pairs of `keys`.
pub(crate) fn length_params_at_scale(
    options: &FairOptions,
    keys: &[(&str, i32)],
    s: f64,
) -> FairOptions {
    let mut o = options.clone();
    for &(k, p) in keys {
        scale_length_param(&mut o, k, p, s);
    }
    o
}

/// [`FairMethod::report_params_at_scale`] for the `(name, length power)` pairs of `keys`.
pub(crate) fn report_length_params(
    parameters: &mut serde_json::Map<String, serde_json::Value>,
    keys: &[(&str, i32)],
    s: f64,
) {
    for &(k, p) in keys {
        scale_reported(parameters, k, p, s);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn metrics(pts: Vec<Point>) -> FairnessMetrics {
        FairnessMetrics::of_seq(&PointSeq::open(pts).expect("points")).expect("metrics")
    }

    /// An arc of radius 2 and the same arc with one point pushed out.
    fn arcs() -> (FairnessMetrics, FairnessMetrics) {
        let arc: Vec<Point> = (0..30)
            .map(|i| {
                let t = 0.1 * f64::from(i);
                Point::new(2.0 * t.cos(), 2.0 * t.sin())
            })
            .collect();
        let mut bumped = arc.clone();
        bumped[15] = Point::new(arc[15].x * 1.01, arc[15].y * 1.01);
        (metrics(arc), metrics(bumped))
    }

    #[test]
    fn a_bump_is_worse_and_its_removal_is_not() {
        let (arc, bumped) = arcs();
        let why = worse(&arc, &bumped).expect("worse");
        assert!(why.contains("variation energy"), "{why}");
        assert!(
            bumped.inflections > 0 && why.contains("more inflections"),
            "{why}"
        );
        assert_eq!(worse(&bumped, &arc), None);
        assert_eq!(worse(&arc, &arc), None);
    }

    #[test]
    fn rounding_of_the_energy_is_within_the_slack() {
        let (arc, _) = arcs();
        let mut after = arc.clone();
        after.variation_energy *= 1.0 + 0.5 * CLEAN_SLACK_REL;
        assert_eq!(worse(&arc, &after), None);
        after.variation_energy = arc.variation_energy * (1.0 + 2.0 * CLEAN_SLACK_REL);
        assert!(worse(&arc, &after).is_some());
        let mut vib = arc.clone();
        vib.vibrations += 1;
        assert!(worse(&arc, &vib).expect("worse").contains("vibrations"));
        // On an input with inflections, their count alone does not decide.
        let mut noisy = arc.clone();
        noisy.inflections = 3;
        noisy.vibrations = 48;
        vib.vibrations = 50;
        assert_eq!(worse(&noisy, &vib), None);
    }
}
