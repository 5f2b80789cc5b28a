//! One function segment `(x_i, y_i)` being faired by HAN's two phases: its parameters, the
//! moves and their tags, the bounds and the exact update of c and e after every move
//! (`docs/algorithms/han.md`, "Fairing one function segment", docs/algorithms/han.md §1.7). The
//! cases themselves are in `segment/cases.rs`.

mod cases;

use std::ops::Range;

use super::params::{DEFAULT_ALPHA_FACTOR, DEFAULT_LAMBDA_COARSE, DEFAULT_LAMBDA_FINE};
use super::responses::{Changed, UnitResponses};
use super::sign::{SignScale, abs_max, count_strict_changes};
use crate::error::{Error, Result};
use crate::geom::Point;
use crate::spline::{CubicSplineFn, FnEndCondition};

/// The fewest points a function segment must have to be faired (docs/algorithms/han.md §1.7).
pub(super) const MIN_SEGMENT_POINTS: usize = 5;
/// Rounding-noise floor of the sign tests \[CHOICE\]. Rounding the coordinates (magnitude R) to
/// double precision puts noise of up to about `0.4·ε·R/h²` into c and `4·0.4·ε·R/h³` into e
/// (measured on 10⁶ samples of a sine, offset by 100, with spacing h): on dense data every e,
/// and the c near a true inflection, can be pure noise, which the spec's relative zero test
/// (§1.7.0) cannot tell from signal. Values of c at most `F·ε·R/h²` and of e at most
/// `4F·ε·R/h³` (h the shorter chord at the point) count as 0 in the sign tests, with this F
/// — the factor of the curve metrics' floor. It changes nothing on data whose noise is above
/// rounding; on a clean curve it keeps `han` from fairing rounding noise (a clean 10⁶-point
/// spiral made 5.4 million moves without it, none with it).
pub(super) const ROUNDING_FLOOR_FACTOR: f64 = 64.0;

/// The parameters of the fairing of one function segment.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct SegmentParams {
    /// Damping `λ_c` of coarse case 1.
    ///
    /// Default value: 0.8.
    pub lambda_coarse: f64,
    /// Weight `λ_f` of the outer points in the fine cases.
    ///
    /// Default value: 0.75.
    pub lambda_fine: f64,
    /// Factor of the α rule of the fine cases.
    ///
    /// Default value: 0.2.
    pub alpha_factor: f64,
    /// Also run fine case 3 ([`Segment::fine_case3`]) after fine case 2 in every iteration:
    /// an extension, not in the paper, for runs of three points of one sign of c, which
    /// neither fine case removes.
    ///
    /// Default value: false here (the paper's method); the `han` method turns it on.
    pub fine_run3: bool,
}

impl SegmentParams {
    /// The paper's values.
    pub const DEFAULT: SegmentParams = SegmentParams {
        lambda_coarse: DEFAULT_LAMBDA_COARSE,
        lambda_fine: DEFAULT_LAMBDA_FINE,
        alpha_factor: DEFAULT_ALPHA_FACTOR,
        fine_run3: false,
    };

    /// Set `λ_c`.
    pub fn with_lambda_coarse(mut self, v: f64) -> SegmentParams {
        self.lambda_coarse = v;
        self
    }

    /// Set `λ_f`.
    pub fn with_lambda_fine(mut self, v: f64) -> SegmentParams {
        self.lambda_fine = v;
        self
    }

    /// Set the α factor.
    pub fn with_alpha_factor(mut self, v: f64) -> SegmentParams {
        self.alpha_factor = v;
        self
    }

    /// Run fine case 3 too (see [`SegmentParams::fine_run3`]).
    pub fn with_fine_run3(mut self, on: bool) -> SegmentParams {
        self.fine_run3 = on;
        self
    }

    pub(super) fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("lambda_coarse", self.lambda_coarse),
            ("lambda_fine", self.lambda_fine),
            ("alpha_factor", self.alpha_factor),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(Error::InvalidParameter {
                    name: name.into(),
                    reason: format!("{v} is outside [0, 1]"),
                });
            }
        }
        Ok(())
    }
}

impl Default for SegmentParams {
    fn default() -> SegmentParams {
        SegmentParams::DEFAULT
    }
}

/// The rule that made a move (the spec's tags, §7).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MoveTag {
    /// Coarse case 1, small vibration: `y_i += λ_c σ`, `y_{i+1} −= λ_c σ`.
    C1,
    /// Coarse case 2, medium vibration: `e_i` set to 0 by moving `y_i`.
    C2,
    /// Coarse case 2 end rule (i = 2 or n−1, 1-based).
    C2End,
    /// Coarse case 3, large vibration: `e_i = e_{i+1} = 0` by moving `y_i`, `y_{i+1}`.
    C3,
    /// Coarse case 3 end rule.
    C3End,
    /// Fine case 1, isolated sign of `c_i`; made once with α = 0 and possibly again.
    F1,
    /// Fine case 2, two-point inflection pair.
    F2,
    /// Fine case 2 end rule: `c_1 = c_2` (or `c_{n−1} = c_n`) set to 0.
    F2End,
    /// Fine case 3 (an extension, not in the paper): a three-point run of one sign of c.
    F3,
}

impl MoveTag {
    /// The tag as written in the test vectors: `C1`, `C2`, `C2end`, `C3`, `C3end`, `F1`,
    /// `F2`, `F2end`.
    pub fn as_str(self) -> &'static str {
        match self {
            MoveTag::C1 => "C1",
            MoveTag::C2 => "C2",
            MoveTag::C2End => "C2end",
            MoveTag::C3 => "C3",
            MoveTag::C3End => "C3end",
            MoveTag::F1 => "F1",
            MoveTag::F2 => "F2",
            MoveTag::F2End => "F2end",
            MoveTag::F3 => "F3",
        }
    }

    /// True for the fine-phase tags (they target `c`), false for the coarse ones (`e`).
    pub fn is_fine(self) -> bool {
        matches!(
            self,
            MoveTag::F1 | MoveTag::F2 | MoveTag::F2End | MoveTag::F3
        )
    }
}

/// One move of a segment: consecutive points `start..start+len` displaced in y.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CaseMove {
    /// The rule.
    pub tag: MoveTag,
    /// The point the rule was tested at (0-based): i of the case, 1 or n−2 for end rules.
    pub i: usize,
    /// The first displaced point (0-based).
    pub start: usize,
    len: usize,
    gammas: [f64; 5],
    /// The targeted indicator at `i` before the move: `e_i` for coarse rules, `c_i` for fine.
    pub before: f64,
    /// The same value after the move.
    pub after: f64,
    /// Fraction of the proposed move that was applied: 1, or less when the tolerance bounds
    /// cut it back.
    pub scale: f64,
}

impl CaseMove {
    /// The applied displacements of points `start, start+1, …`.
    pub fn gammas(&self) -> &[f64] {
        &self.gammas[..self.len]
    }

    /// The displaced points.
    pub fn points(&self) -> Range<usize> {
        self.start..self.start + self.len
    }

    /// The displacement of point `p`, if this move displaced it.
    pub fn gamma_at(&self, p: usize) -> Option<f64> {
        self.points()
            .contains(&p)
            .then(|| self.gammas[p - self.start])
    }

    /// Largest |γ|.
    pub fn max_abs(&self) -> f64 {
        self.gammas().iter().fold(0.0, |m, g| m.max(g.abs()))
    }
}

/// The five case procedures of one iteration, in the spec's order (§1.7.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Procedure {
    /// Coarse case 1 ([`Segment::coarse_case1`]).
    CoarseCase1,
    /// Coarse case 2 with its end rules ([`Segment::coarse_case2`]).
    CoarseCase2,
    /// Coarse case 3 with its end rules ([`Segment::coarse_case3`]).
    CoarseCase3,
    /// Fine case 1 ([`Segment::fine_case1`]).
    FineCase1,
    /// Fine case 2 with its end rules ([`Segment::fine_case2`]).
    FineCase2,
    /// Fine case 3 ([`Segment::fine_case3`]), an extension run after fine case 2 when
    /// [`SegmentParams::fine_run3`] is set.
    FineCase3,
}

impl Procedure {
    /// One iteration: phase 1 (cases 1, 2, 3), then phase 2 (cases 1, 2).
    pub(crate) const ITERATION: [Procedure; 5] = [
        Procedure::CoarseCase1,
        Procedure::CoarseCase2,
        Procedure::CoarseCase3,
        Procedure::FineCase1,
        Procedure::FineCase2,
    ];
}

/// A function segment `(x_i, y_i)`, i = 1..n, being faired by HAN's two phases
/// (docs/algorithms/han.md §1.7).
///
/// It holds y, the spline coefficients c, the indicator e and the unit responses, and keeps
/// c and e exact after every move (eq 13, see `docs/algorithms/han.md`). Only `y_2..y_{n−1}` move;
/// the x values and the end values never change. Indices are 0-based (point k is the paper's
/// k + 1).
///
/// ```
/// use batten::fair::HanSegment;
///
/// let x: Vec<f64> = (0..30).map(|i| i as f64 * 0.4).collect();
/// let y: Vec<f64> = x.iter().enumerate()
///     .map(|(i, v)| (v / 2.0).sin() + if i % 2 == 0 { 0.02 } else { -0.02 })
///     .collect();
/// let mut seg = HanSegment::new(x, y).unwrap();
/// let before = seg.inflection_count();
/// seg.fair(10, |_| {});
/// assert!(seg.inflection_count() < before);
/// ```
#[derive(Clone, Debug)]
pub struct Segment {
    x: Vec<f64>,
    y: Vec<f64>,
    c: Vec<f64>,
    e: Vec<f64>,
    resp: UnitResponses,
    c_scale: SignScale,
    e_scale: SignScale,
    /// Rounding-noise floors of c and e per point ([`ROUNDING_FLOOR_FACTOR`]).
    c_floor: Vec<f64>,
    e_floor: Vec<f64>,
    params: SegmentParams,
    bounds: Option<(Vec<f64>, Vec<f64>)>,
    limited: bool,
    /// Refuse moves that give the points more inflections or a higher variation energy near
    /// them (the per-move clean-curve check, [`Segment::with_keep_clean`]).
    keep_clean: bool,
    /// Moves refused by that check.
    refused: usize,
}

impl Segment {
    /// A segment through `(x[k], y[k])` with the default parameters and no bounds.
    ///
    /// # Errors
    /// [`Error::TooFewPoints`] below 5 points, and the errors of
    /// [`CubicSplineFn::try_new`] (length mismatch, NaN, x not strictly increasing).
    pub fn new(x: Vec<f64>, y: Vec<f64>) -> Result<Segment> {
        if x.len() < MIN_SEGMENT_POINTS {
            return Err(Error::TooFewPoints {
                needed: MIN_SEGMENT_POINTS,
                got: x.len(),
            });
        }
        let spline = CubicSplineFn::try_new(x, y, FnEndCondition::Han)?;
        let resp = UnitResponses::from_spline(&spline)?;
        let n = spline.len();
        let mut c = spline.c().to_vec();
        // The end condition holds exactly, so that the end tests are exact too.
        c[n - 1] = c[n - 2];
        let mut seg = Segment {
            x: spline.x().to_vec(),
            y: spline.y().to_vec(),
            e: vec![0.0; n],
            c_scale: SignScale::new(&c),
            e_scale: SignScale::new(&[]),
            c_floor: Vec::new(),
            e_floor: Vec::new(),
            c,
            resp,
            params: SegmentParams::DEFAULT,
            bounds: None,
            limited: false,
            keep_clean: false,
            refused: 0,
        };
        seg.refresh_e(1, n - 2);
        seg.e_scale = SignScale::new(&seg.e);
        seg.set_floors(0.0);
        Ok(seg)
    }

    /// Refuse (`true`) or allow (`false`, the default) moves that give the polyline's
    /// chord-length cubic more inflections or a higher variation energy `∫(dκ/ds)² ds`
    /// near them. The check is local (a few points either side of a move) and, the cubic
    /// being invariant under rigid motion, the same in the segment's frame as in the
    /// plane. `Han` turns it on unless [`FairOptions::keep_clean`] is false.
    ///
    /// [`FairOptions::keep_clean`]: crate::fair::FairOptions::keep_clean
    pub fn with_keep_clean(mut self, keep: bool) -> Segment {
        self.keep_clean = keep;
        self
    }

    /// Moves refused by the clean-curve check so far.
    pub fn refused_moves(&self) -> usize {
        self.refused
    }

    /// Declare that the points carry the rounding of coordinates of magnitude up to
    /// `magnitude` (e.g. those of the whole curve, before the segment was moved into its
    /// frame), not only of their own: the rounding-noise floors of the sign tests
    /// ([`Segment::c_floor`], [`Segment::e_floor`]) are raised accordingly. A non-finite or negative value is
    /// ignored.
    pub fn with_coordinate_scale(mut self, magnitude: f64) -> Segment {
        if magnitude.is_finite() && magnitude > 0.0 {
            self.set_floors(magnitude);
        }
        self
    }

    /// The rounding-noise floors `F·ε·R/h²` of c and `4F·ε·R/h³` of e at each point, with R
    /// the larger of `magnitude` and the segment's own largest coordinate, and h the shorter
    /// of the point's two chords (\[CHOICE\], see [`ROUNDING_FLOOR_FACTOR`]).
    fn set_floors(&mut self, magnitude: f64) {
        let n = self.len();
        let own = self
            .x
            .iter()
            .chain(&self.y)
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        let scale = ROUNDING_FLOOR_FACTOR * f64::EPSILON * own.max(magnitude);
        self.c_floor = Vec::with_capacity(n);
        self.e_floor = Vec::with_capacity(n);
        for i in 0..n {
            let left = if i > 0 {
                self.x[i] - self.x[i - 1]
            } else {
                f64::INFINITY
            };
            let right = if i + 1 < n {
                self.x[i + 1] - self.x[i]
            } else {
                f64::INFINITY
            };
            let h = left.min(right);
            let c = scale / (h * h);
            self.c_floor.push(c);
            self.e_floor.push(4.0 * c / h);
        }
    }

    /// Use other parameters.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when a parameter is outside [0, 1] or NaN.
    pub fn with_params(mut self, params: SegmentParams) -> Result<Segment> {
        params.validate()?;
        self.params = params;
        Ok(self)
    }

    /// Bound every point: `lo[k] ≤ y[k] ≤ hi[k]` must hold after every move. A move that would
    /// leave the bounds is scaled back as a whole ([`CaseMove::scale`]).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`]; [`Error::InvalidParameter`] when the current y is outside
    /// its bounds (or a bound is NaN).
    pub fn with_bounds(mut self, lo: Vec<f64>, hi: Vec<f64>) -> Result<Segment> {
        let n = self.len();
        for (what, v) in [("lower bounds", &lo), ("upper bounds", &hi)] {
            if v.len() != n {
                return Err(Error::LengthMismatch {
                    what,
                    got: v.len(),
                    expected: n,
                });
            }
        }
        if let Some(k) = (0..n).find(|&k| !(lo[k] <= self.y[k] && self.y[k] <= hi[k])) {
            return Err(Error::InvalidParameter {
                name: "bounds".into(),
                reason: format!("y[{k}] = {} is outside [{}, {}]", self.y[k], lo[k], hi[k]),
            });
        }
        self.bounds = Some((lo, hi));
        Ok(self)
    }

    /// Number of points n.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Always false (n ≥ 5).
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// The abscissae.
    pub fn x(&self) -> &[f64] {
        &self.x
    }

    /// The current ordinates.
    pub fn y(&self) -> &[f64] {
        &self.y
    }

    /// The current `c_i = y''(x_i)/6` (the x–c plot).
    pub fn c(&self) -> &[f64] {
        &self.c
    }

    /// The current indicator `e` (`e_1 = e_n = 0`).
    pub fn e(&self) -> &[f64] {
        &self.e
    }

    /// The rounding-noise floor of each `c_i`: values of c at most `64·ε·R/h²` (R the
    /// coordinate magnitude, h the shorter chord at the point) count as 0 in the sign tests.
    pub fn c_floor(&self) -> &[f64] {
        &self.c_floor
    }

    /// The rounding-noise floor of each `e_i`: values of e at most `4·64·ε·R/h³` count as 0
    /// in the sign tests.
    pub fn e_floor(&self) -> &[f64] {
        &self.e_floor
    }

    /// The parameters in use.
    pub fn params(&self) -> SegmentParams {
        self.params
    }

    /// True when some move was scaled back by the bounds.
    pub fn was_limited(&self) -> bool {
        self.limited
    }

    /// HAN's `Infl_num = #{i : c_i c_{i+1} < 0}` with the zero tolerance of §1.7.0.
    pub fn inflection_count(&self) -> usize {
        count_strict_changes(&self.c, &self.c_floor, abs_max(&self.c))
    }

    /// HAN's `Vib_num = #{i : e_i e_{i+1} < 0}` with the zero tolerance of §1.7.0.
    pub fn vibration_count(&self) -> usize {
        count_strict_changes(&self.e, &self.e_floor, abs_max(&self.e))
    }

    /// Run `iterations` iterations of the case procedures (coarse cases 1–3, fine cases 1 and
    /// 2, and fine case 3 when [`SegmentParams::fine_run3`] is set), calling `on_move` for every
    /// move. Stops early when an iteration makes no move (the state is then a fixed point).
    /// Returns the number of iterations that made at least one move.
    pub fn fair(&mut self, iterations: usize, mut on_move: impl FnMut(&CaseMove)) -> usize {
        let mut active = 0;
        for _ in 0..iterations {
            let mut moved = false;
            for p in Procedure::ITERATION {
                self.run_procedure(p, &mut |m: &CaseMove| {
                    moved = true;
                    on_move(m);
                });
            }
            if self.params.fine_run3 {
                self.run_procedure(Procedure::FineCase3, &mut |m: &CaseMove| {
                    moved = true;
                    on_move(m);
                });
            }
            if !moved {
                break;
            }
            active += 1;
        }
        active
    }

    /// Run one case procedure over the segment, calling `on_move` for every move.
    pub(crate) fn run_procedure(&mut self, p: Procedure, on_move: &mut impl FnMut(&CaseMove)) {
        match p {
            Procedure::CoarseCase1 => self.coarse_case1_with(on_move),
            Procedure::CoarseCase2 => self.coarse_case2_with(on_move),
            Procedure::CoarseCase3 => self.coarse_case3_with(on_move),
            Procedure::FineCase1 => self.fine_case1_with(on_move),
            Procedure::FineCase2 => self.fine_case2_with(on_move),
            Procedure::FineCase3 => self.fine_case3_with(on_move),
        }
    }

    /// Move the consecutive interior points `start..start+gammas.len()` (one to five of them, as many as a case move
    /// displaces)
    /// by `gammas`, with c and e updated exactly by eq 13 as after a case move, and the bounds
    /// applied the same way. Returns the fraction of the move that was applied (0 when the
    /// bounds or the resolution of y left nothing to do).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when a moved point is not interior or there are not one to
    /// five displacements; [`Error::NonFinite`] for a non-finite displacement.
    pub fn displace(&mut self, start: usize, gammas: &[f64]) -> Result<f64> {
        if gammas.is_empty() || gammas.len() > 5 || start == 0 || start + gammas.len() >= self.len()
        {
            return Err(Error::InvalidParameter {
                name: "displace".into(),
                reason: format!(
                    "points {start}..{} are not 1 to 5 interior points of {}",
                    start + gammas.len(),
                    self.len()
                ),
            });
        }
        if let Some(index) = gammas.iter().position(|g| !g.is_finite()) {
            return Err(Error::NonFinite { index });
        }
        Ok(self
            .move_points(start, gammas)
            .map_or(0.0, |(scale, _)| scale))
    }

    /// Coarse case 1 (small vibration, docs/algorithms/han.md §1.7.1): for i = 2..n−2 (1-based)
    /// with `e_i e_{i+1} < 0`, move `y_i += λ_c σ`, `y_{i+1} −= λ_c σ` with σ the smaller root of
    /// `ẽ_i ẽ_{i+1} = 0`. Returns the moves.
    pub fn coarse_case1(&mut self) -> Vec<CaseMove> {
        self.collect(Procedure::CoarseCase1)
    }

    /// Coarse case 2 (medium vibration, §1.7.1): `e_i` of the other sign than both neighbours
    /// is set to 0 by moving `y_i`, i = 3..n−2; then the end rules at i = 2 and n−1.
    pub fn coarse_case2(&mut self) -> Vec<CaseMove> {
        self.collect(Procedure::CoarseCase2)
    }

    /// Coarse case 3 (large vibration, §1.7.1): a same-sign pair `e_i, e_{i+1}` between two
    /// opposite neighbours on each side is set to 0 by moving `y_i, y_{i+1}`; then the end
    /// rules (n ≥ 6).
    pub fn coarse_case3(&mut self) -> Vec<CaseMove> {
        self.collect(Procedure::CoarseCase3)
    }

    /// Fine case 1 (§1.7.2): `c_i` of the other sign than both neighbours is set to 0, then, if
    /// the neighbours kept their signs, to α.
    pub fn fine_case1(&mut self) -> Vec<CaseMove> {
        self.collect(Procedure::FineCase1)
    }

    /// Fine case 2 (§1.7.2): a same-sign pair `c_i, c_{i+1}` with opposite `c_{i−1}`,
    /// `c_{i+2}`, `c_{i+3}` is set to 0 (then α); then the end rules.
    pub fn fine_case2(&mut self) -> Vec<CaseMove> {
        self.collect(Procedure::FineCase2)
    }

    /// Fine case 3, an extension not in the paper ([`SegmentParams::fine_run3`]): a run
    /// `c_i, c_{i+1}, c_{i+2}` of one sign between `c_{i−1}` and `c_{i+3}, c_{i+4}` of the other
    /// is set to 0 (then α) by moving `y_{i−1}..y_{i+3}`, the outer two by `−λ_f` times their
    /// neighbours, as fine case 2 does for a pair.
    pub fn fine_case3(&mut self) -> Vec<CaseMove> {
        self.collect(Procedure::FineCase3)
    }

    fn collect(&mut self, p: Procedure) -> Vec<CaseMove> {
        let mut moves = Vec::new();
        self.run_procedure(p, &mut |m: &CaseMove| moves.push(*m));
        moves
    }

    // --- applying a move ---------------------------------------------------------------------

    /// Move points `start..start+gammas.len()` by `gammas` (scaled back to the bounds), update
    /// c by eq 13 and e on the changed range, and report the move.
    fn apply(
        &mut self,
        tag: MoveTag,
        i: usize,
        start: usize,
        gammas: &[f64],
        on_move: &mut impl FnMut(&CaseMove),
    ) {
        let before = if tag.is_fine() { self.c[i] } else { self.e[i] };
        if let Some((scale, applied)) = self.move_points(start, gammas) {
            let after = if tag.is_fine() { self.c[i] } else { self.e[i] };
            let len = gammas.len();
            on_move(&CaseMove {
                tag,
                i,
                start,
                len,
                gammas: applied,
                before,
                after,
                scale,
            });
        }
    }

    /// Move points `start..start+gammas.len()` (interior, at most 5: fine case 3) by `gammas`, scaled back
    /// to the bounds, and update c (eq 13), e and their maxima on the changed range. Returns
    /// the scale and the applied displacements, or `None` when nothing moved.
    fn move_points(&mut self, start: usize, gammas: &[f64]) -> Option<(f64, [f64; 5])> {
        let len = gammas.len();
        if gammas.iter().any(|g| !g.is_finite()) || gammas.iter().all(|g| *g == 0.0) {
            return None;
        }
        let mut scale = 1.0_f64;
        if let Some((lo, hi)) = &self.bounds {
            for (k, &g) in gammas.iter().enumerate() {
                let p = start + k;
                if g > 0.0 {
                    scale = scale.min((hi[p] - self.y[p]) / g);
                } else if g < 0.0 {
                    scale = scale.min((lo[p] - self.y[p]) / g);
                }
            }
            scale = scale.max(0.0);
            if scale < 1.0 {
                self.limited = true;
            }
            if scale == 0.0 {
                return None;
            }
        }
        let mut targets = [0.0; 5];
        let mut applied = [0.0; 5];
        for (k, &g) in gammas.iter().enumerate() {
            let p = start + k;
            let mut target = self.y[p] + scale * g;
            if let Some((lo, hi)) = &self.bounds {
                target = target.clamp(lo[p], hi[p]);
            }
            targets[k] = target;
            applied[k] = target - self.y[p];
        }
        // A move below the resolution of y (e.g. one driven by rounding noise in c or e on
        // exactly fair data) changes nothing and is not made.
        if applied[..len].iter().all(|d| *d == 0.0) {
            return None;
        }
        if self.keep_clean {
            let moved: Vec<(usize, Point)> = (0..len)
                .map(|k| (start + k, Point::new(self.x[start + k], targets[k])))
                .collect();
            let (x, y) = (&self.x, &self.y);
            if crate::fair::clean::move_is_worse_by(
                x.len(),
                false,
                |i| Point::new(x[i], y[i]),
                &moved,
            ) {
                self.refused += 1;
                return None;
            }
        }
        self.y[start..start + len].copy_from_slice(&targets[..len]);
        let w = self.resp.add_columns(start, &applied[..len], &mut self.c);
        self.c_scale.wrote(&self.c, w);
        let (elo, ehi) = (
            w.lo.saturating_sub(1).max(1),
            (w.hi + 1).min(self.len() - 2),
        );
        let we = self.refresh_e(elo, ehi);
        self.e_scale.wrote(&self.e, we);
        Some((scale, applied))
    }

    /// Recompute `e_i = s_i − s_{i−1}`, `s_i = (c_{i+1} − c_i)/h_i`, from c for `lo..=hi`
    /// (interior indices); each slope is computed once. Returns what changed.
    fn refresh_e(&mut self, lo: usize, hi: usize) -> Changed {
        let c = &self.c[lo - 1..=hi + 1];
        let h = &self.resp.inv_h[lo - 1..=hi];
        let e = &mut self.e[lo..=hi];
        let mut prev = (c[1] - c[0]) * h[0];
        for (k, ek) in e.iter_mut().enumerate() {
            let next = (c[k + 2] - c[k + 1]) * h[k + 1];
            *ek = next - prev;
            prev = next;
        }
        Changed::of(&self.e, lo, hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn add_columns_keeps_end_condition_bitwise() {
        let x: Vec<f64> = (0..12).map(|i| (i as f64).powf(1.3)).collect();
        let y: Vec<f64> = x.iter().map(|v| (v * 0.7).sin()).collect();
        let mut seg = Segment::new(x, y).unwrap_or_else(|e| panic!("{e}"));
        let n = seg.len();
        for start in 1..n - 1 {
            let len = (n - 1 - start).min(4);
            let g: Vec<f64> = (0..len).map(|k| 0.01 * (k as f64 + 1.0)).collect();
            seg.apply(MoveTag::C1, start, start, &g, &mut |_| {});
            assert_eq!(seg.c[0], seg.c[1]);
            assert_eq!(seg.c[n - 1], seg.c[n - 2]);
        }
    }
}
