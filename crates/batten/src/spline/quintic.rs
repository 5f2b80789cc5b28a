//! The uniform quintic B-spline of Kuragano & Yamaguchi (KY), *NURBS curve shape modification
//! and fairness evaluation* (`../shared/papers/kuragano-nurbs-roc-fairness.txt`, §2–§3), as
//! specified in `../shared/spec/ALGORITHMS.md` §5.1 and §5.3.
//!
//! # Representation (eqs 1–4, docs/algorithms/kuragano.md §5.1)
//!
//! `n` control points `q_0..q_{n−1}` (n ≥ 6) and the uniform knots `−5, −4, …, n` give `n − 5`
//! segments; segment `i` uses `q_i..q_{i+5}` and the global parameter `u ∈ [i, i + 1]`, so the
//! domain is `[0, n − 5]`. The paper's weights "are not used": [`QuinticForm::Nurbs`] carries
//! them as `Some(all 1)` (the NURBS form, identical in shape), [`QuinticForm::BSpline`] as `None`.
//!
//! At `t = 0` of a segment the derivatives `d^r R/dt^r` are the five-wide stencils [`ROWS`]
//! on `q_i..q_{i+4}`: row 0 is eq 8 (`(1, 26, 66, 26, 1)/120`), row 1 is eq 9
//! (`(−1, −10, 0, 10, 1)/24`), rows 2 and 4 give the end conditions.
//!
//! # Constructors (docs/algorithms/kuragano.md §5.3)
//!
//! - [`interpolate`] with [`Ends::Natural`]: `m` points give `m + 4` unknowns; eq 8 at
//!   `i = 0..m−1` (point `P_i` at `u = i`) plus `R'' = 0` and `R'''' = 0` at both ends. The
//!   curvature is zero at both ends, so ρ is infinite there (docs/algorithms/kuragano.md §5.3,
//!   "keep this in mind").
//! - [`interpolate`] with [`Ends::Gradients`]: four gradients `R'(u = i) = d_i` (eq 9) at
//!   distinct point indices replace the end conditions. [`end_gradients`] makes the default:
//!   locations `0, 1, m−2, m−1` (the paper's "0, 1, n−2, n−1" reuses n for m), directions
//!   estimated from the points, magnitude [`DEFAULT_GRADIENT_FRACTION`] (one third) of the
//!   adjacent chord.
//! - [`interpolate_hermite`]: a gradient at every point (§3.2, Table 1), `2m` equations in
//!   `m + 4` unknowns: determined for `m = 4` (solved exactly), overdetermined for `m > 4`
//!   (least squares), underdetermined for `m < 4`: **\[CHOICE\]** of the spec, the solution
//!   minimising `Σ_j |q_{j+1} − 2q_j + q_{j−1}|²` subject to the equations (a KKT solve; the
//!   paper's "auxiliary function" is unnamed). Unlike the minimum-norm solution it is
//!   translation-equivariant.
//!
//! The square systems are banded (each row has five consecutive non-zeros) and are solved in
//! O(m) by Gaussian elimination with partial pivoting on the band (the end-condition rows are
//! not diagonally dominant, so the pivot-free [`crate::numeric::BandLu`] is not used). The
//! least-squares normal equations are a symmetric band of half-width 4
//! ([`crate::numeric::SymBanded`]); the tiny KKT system is solved densely (nalgebra).

use super::{BSplineCurve, KnotVector};
use crate::error::{Error, Result};
use crate::geom::{Point, Vec2};
use crate::numeric::{PIVOT_REL, SymBanded};

/// The degree of the KY curve: quintic (order 6).
pub(crate) const DEGREE: usize = 5;

/// Width of the stencils: the derivatives of orders 0..4 at `t = 0` of a segment involve
/// `q_i..q_{i+4}` only.
pub(crate) const STENCIL_WIDTH: usize = 5;

/// `d^r R/dt^r` at `t = 0` of segment `i`, as coefficients of `q_i..q_{i+4}`, for r = 0..4
/// (docs/algorithms/kuragano.md §5.1 table). Row 0 is eq 8, row 1 eq 9, rows 2 and 4 the end
/// conditions.
///
/// **\[FIX\]** Row 3 is `(−1, 2, 0, −2, 1)/2`, not the spec table's `(−1, −2, 0, 2, 1)/2`: eq 3
/// gives `N_1'''(0) = 6·20/120 = 1`, de Boor–Cox agrees, and only this row reproduces cubics
/// (`q_j = j³` must give `R''' = 6`; the printed row gives 58). Row 3 is not used by any
/// construction here.
pub(crate) const ROWS: [[f64; STENCIL_WIDTH]; 5] = [
    [
        1.0 / 120.0,
        26.0 / 120.0,
        66.0 / 120.0,
        26.0 / 120.0,
        1.0 / 120.0,
    ],
    [-1.0 / 24.0, -10.0 / 24.0, 0.0, 10.0 / 24.0, 1.0 / 24.0],
    [1.0 / 6.0, 2.0 / 6.0, -6.0 / 6.0, 2.0 / 6.0, 1.0 / 6.0],
    [-0.5, 1.0, 0.0, -1.0, 0.5],
    [1.0, -4.0, 6.0, -4.0, 1.0],
];

/// The six basis functions of one segment as polynomials in the local `t ∈ [0, 1]` (eq 3),
/// times 120, coefficients in ascending powers of t.
const BASIS_COEFFS: [[f64; 6]; 6] = [
    [1.0, -5.0, 10.0, -10.0, 5.0, -1.0],
    [26.0, -50.0, 20.0, 20.0, -20.0, 5.0],
    [66.0, 0.0, -60.0, 0.0, 30.0, -10.0],
    [26.0, 50.0, 20.0, -20.0, -20.0, 10.0],
    [1.0, 5.0, 10.0, 10.0, 5.0, -5.0],
    [0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
];

/// The basis functions of one segment at the local parameter `t` (eq 3) and their first and
/// second derivatives (eq 4 and its derivative): `out[r][j] = d^r N_j/dt^r`, j = 0..5 for the
/// control points `q_i..q_{i+5}` of segment i. Closed form, no allocation: the fast path of
/// the KY shape modification.
pub(crate) fn basis(t: f64) -> [[f64; 6]; 3] {
    let mut out = [[0.0; 6]; 3];
    for (j, c) in BASIS_COEFFS.iter().enumerate() {
        let (mut v, mut d1, mut d2) = (0.0, 0.0, 0.0);
        for e in (0..6).rev() {
            v = v * t + c[e];
            if e >= 1 {
                d1 = d1 * t + e as f64 * c[e];
            }
            if e >= 2 {
                d2 = d2 * t + (e * (e - 1)) as f64 * c[e];
            }
        }
        out[0][j] = v / 120.0;
        out[1][j] = d1 / 120.0;
        out[2][j] = d2 / 120.0;
    }
    out
}

/// Segment `i` in power form: `R(t) = Σ_e c_e t^e` (e = 0..5, local `t ∈ [0, 1]`) for its six
/// control points `q_i..q_{i+5}` (eq 3 expanded). Derivatives follow by differentiating the
/// polynomial, which is how the KY shape modification evaluates speed cheaply.
pub(crate) fn power_form(q: [Point; 6]) -> [Vec2; 6] {
    let mut c = [Vec2::ZERO; 6];
    for (e, ce) in c.iter_mut().enumerate() {
        for (j, qj) in q.iter().enumerate() {
            *ce += qj.to_vec2() * (BASIS_COEFFS[j][e] / 120.0);
        }
    }
    c
}

/// The default gradient magnitude, as a fraction of the adjacent chord (paper §3.1: "one third
/// value of the distance of adjacent given points is assigned as a default value").
pub const DEFAULT_GRADIENT_FRACTION: f64 = 1.0 / 3.0;

/// Fewest points an interpolant can have: two points give one segment (six control points).
pub(crate) const MIN_POINTS: usize = 2;

/// Largest width (in columns) a row may reach during the banded elimination. Every row ends
/// at most five columns after its first one, and at column c every active row started at or
/// before c, so rows never grow beyond the stencil; the margin only guards the invariant.
const MAX_ROW_WIDTH: usize = 8;

/// Whether the curve carries weights.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum QuinticForm {
    /// A plain B-spline (`weights = None`).
    #[default]
    BSpline,
    /// The paper's NURBS form with every weight 1 (`weights = Some(vec![1.0; n])`).
    Nurbs,
}

/// End conditions of [`interpolate`].
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Ends {
    /// `R'' = 0` and `R'''' = 0` at both ends (docs/algorithms/kuragano.md §5.3.1).
    Natural,
    /// Exactly four gradients `(point index, dR/du)` at distinct point indices, replacing the
    /// end conditions (eq 9, docs/algorithms/kuragano.md §5.3.2).
    Gradients(Vec<(usize, Vec2)>),
}

/// How the system of [`interpolate_hermite`] was posed (paper Table 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HermiteSystem {
    /// `m < 4`: fewer equations than unknowns; the KKT solution of the spec's \[CHOICE\].
    Underdetermined,
    /// `m = 4`: square, solved exactly.
    Determined,
    /// `m > 4`: more equations than unknowns; least squares.
    Overdetermined,
}

/// The uniform knot vector `−5, −4, …, n_ctrl` of a quintic with `n_ctrl` control points:
/// segment `i` is `u ∈ [i, i + 1]` and the domain is `[0, n_ctrl − 5]`.
///
/// # Errors
/// [`Error::TooFewPoints`] for fewer than six control points.
pub(crate) fn uniform_knots(n_ctrl: usize) -> Result<KnotVector> {
    if n_ctrl < DEGREE + 1 {
        return Err(Error::TooFewPoints {
            needed: DEGREE + 1,
            got: n_ctrl,
        });
    }
    KnotVector::try_new(
        (0..n_ctrl + DEGREE + 1)
            .map(|j| j as f64 - DEGREE as f64)
            .collect(),
    )
}

/// The uniform quintic with these control points (knots [`uniform_knots`]).
///
/// # Errors
/// [`Error::TooFewPoints`] for fewer than six control points, [`Error::NonFinite`].
pub(crate) fn from_control_points(
    control_points: Vec<Point>,
    form: QuinticForm,
) -> Result<BSplineCurve> {
    let n = control_points.len();
    let knots = uniform_knots(n)?;
    let weights = match form {
        QuinticForm::BSpline => None,
        QuinticForm::Nurbs => Some(vec![1.0; n]),
    };
    BSplineCurve::try_new(DEGREE, knots, control_points, weights)
}

/// True when `curve` is a quintic on uniform unit-spaced knots starting at −5 with all weights
/// equal (absent or all one): the form this module builds.
pub(crate) fn is_uniform_quintic(curve: &BSplineCurve) -> bool {
    curve.degree() == DEGREE
        && curve
            .knots()
            .as_slice()
            .iter()
            .enumerate()
            .all(|(j, &k)| k == j as f64 - DEGREE as f64)
        && curve.weights().is_none_or(|w| w.iter().all(|&x| x == 1.0))
}

/// The default gradients of docs/algorithms/kuragano.md §5.3.2: at point indices `0, 1, m−2, m−1`,
/// in the direction of the parabola through three neighbouring points (`(−3P_0 + 4P_1 − P_2)/2` at
/// the start, `(P_{i+1} − P_{i−1})/2` inside, mirrored at the end; the chord when `m < 3`), with
/// length `fraction` times the adjacent chord. The adjacent chord is the one on the side of the
/// nearer end (`|P_1 − P_0|` for indices 0 and 1, `|P_{m−1} − P_{m−2}|` for `m−2` and `m−1`).
///
/// # Errors
/// [`Error::TooFewPoints`] for fewer than four points (the four locations must be distinct),
/// [`Error::InvalidParameter`] for a non-positive or non-finite `fraction`, and
/// [`Error::DuplicatePoint`] / [`Error::NonFinite`] for bad points.
pub fn end_gradients(points: &[Point], fraction: f64) -> Result<Vec<(usize, Vec2)>> {
    let m = points.len();
    if m < 4 {
        return Err(Error::TooFewPoints { needed: 4, got: m });
    }
    check_points(points)?;
    if !(fraction.is_finite() && fraction > 0.0) {
        return Err(Error::InvalidParameter {
            name: "gradient fraction".into(),
            reason: format!("must be positive and finite, got {fraction}"),
        });
    }
    [0, 1, m - 2, m - 1]
        .into_iter()
        .map(|i| Ok((i, gradient_estimate(points, i, fraction)?)))
        .collect()
}

/// A gradient at point `i` as [`end_gradients`] makes it.
fn gradient_estimate(points: &[Point], i: usize, fraction: f64) -> Result<Vec2> {
    let m = points.len();
    let p = |k: usize| points[k].to_vec2();
    let dir = if m < 3 {
        p(1) - p(0)
    } else if i == 0 {
        (p(0) * -3.0 + p(1) * 4.0 - p(2)) * 0.5
    } else if i == m - 1 {
        (p(m - 1) * 3.0 - p(m - 2) * 4.0 + p(m - 3)) * 0.5
    } else {
        (p(i + 1) - p(i - 1)) * 0.5
    };
    let chord = if 2 * i < m {
        points[i.max(1)] - points[i.max(1) - 1]
    } else {
        points[(i + 1).min(m - 1)] - points[(i + 1).min(m - 1) - 1]
    };
    let unit = dir.normalize().ok_or_else(|| {
        Error::Degenerate(format!("cannot estimate a tangent direction at point {i}"))
    })?;
    Ok(unit * (fraction * chord.length()))
}

fn check_points(points: &[Point]) -> Result<()> {
    if let Some(index) = points.iter().position(|p| !p.is_finite()) {
        return Err(Error::NonFinite { index });
    }
    if let Some(w) = points.windows(2).position(|w| w[0] == w[1]) {
        return Err(Error::DuplicatePoint { index: w + 1 });
    }
    Ok(())
}

fn check_gradients(gradients: &[Vec2]) -> Result<()> {
    if let Some(index) = gradients.iter().position(|g| !g.is_finite()) {
        return Err(Error::NonFinite { index });
    }
    Ok(())
}

/// One equation: `Σ_k coef[k] q_{start+k} = rhs`.
#[derive(Clone, Copy, Debug)]
struct StencilRow {
    start: usize,
    coef: [f64; STENCIL_WIDTH],
    rhs: Vec2,
}

/// The uniform quintic through `points` (point `P_i` at `u = i`) with the given end
/// conditions (docs/algorithms/kuragano.md §5.3.1–2). The result has `m + 4` control points and `m
/// − 1` segments.
///
/// # Errors
/// [`Error::TooFewPoints`] (fewer than two points; fewer than four with gradients),
/// [`Error::NonFinite`], [`Error::DuplicatePoint`] (a zero chord, docs/algorithms/README.md §0.2),
/// [`Error::InvalidParameter`] for gradients that are not four, at indices out of range or
/// repeated, and [`Error::Singular`] if the system cannot be solved.
pub fn interpolate(points: &[Point], ends: &Ends, form: QuinticForm) -> Result<BSplineCurve> {
    let m = points.len();
    if m < MIN_POINTS {
        return Err(Error::TooFewPoints {
            needed: MIN_POINTS,
            got: m,
        });
    }
    check_points(points)?;
    let mut rows: Vec<StencilRow> = points
        .iter()
        .enumerate()
        .map(|(i, p)| StencilRow {
            start: i,
            coef: ROWS[0],
            rhs: p.to_vec2(),
        })
        .collect();
    match ends {
        Ends::Natural => {
            for start in [0, m - 1] {
                for r in [2, 4] {
                    rows.push(StencilRow {
                        start,
                        coef: ROWS[r],
                        rhs: Vec2::ZERO,
                    });
                }
            }
        }
        Ends::Gradients(g) => {
            if g.len() != 4 {
                return Err(Error::InvalidParameter {
                    name: "gradients".into(),
                    reason: format!("exactly four are needed, {} given", g.len()),
                });
            }
            let mut seen = Vec::with_capacity(4);
            for &(i, d) in g {
                if i >= m || seen.contains(&i) {
                    return Err(Error::InvalidParameter {
                        name: "gradients".into(),
                        reason: format!("point index {i} is out of range 0..{m} or given twice"),
                    });
                }
                if !d.is_finite() {
                    return Err(Error::NonFinite { index: i });
                }
                seen.push(i);
                rows.push(StencilRow {
                    start: i,
                    coef: ROWS[1],
                    rhs: d,
                });
            }
        }
    }
    // A stable sort keeps each point row before the extra rows at the same index.
    rows.sort_by_key(|r| r.start);
    let q = solve_square_banded(&rows, m + 4)?;
    from_control_points(q.into_iter().map(Vec2::to_point).collect(), form)
}

/// The uniform quintic through `points` with a gradient `dR/du` at every point (paper §3.2,
/// docs/algorithms/kuragano.md §5.3.3): exact for `m = 4`, least squares for `m > 4`, and for `m <
/// 4` the exact solution with the least `Σ |q_{j+1} − 2q_j + q_{j−1}|²` (spec \[CHOICE\]).
///
/// # Errors
/// [`Error::TooFewPoints`] (fewer than two), [`Error::LengthMismatch`] when the gradient
/// count differs from the point count, [`Error::NonFinite`], [`Error::DuplicatePoint`],
/// [`Error::Singular`].
pub fn interpolate_hermite(
    points: &[Point],
    gradients: &[Vec2],
    form: QuinticForm,
) -> Result<(BSplineCurve, HermiteSystem)> {
    let m = points.len();
    if m < MIN_POINTS {
        return Err(Error::TooFewPoints {
            needed: MIN_POINTS,
            got: m,
        });
    }
    if gradients.len() != m {
        return Err(Error::LengthMismatch {
            what: "gradients",
            got: gradients.len(),
            expected: m,
        });
    }
    check_points(points)?;
    check_gradients(gradients)?;
    let n = m + 4;
    let mut rows = Vec::with_capacity(2 * m);
    for (i, (p, d)) in points.iter().zip(gradients).enumerate() {
        rows.push(StencilRow {
            start: i,
            coef: ROWS[0],
            rhs: p.to_vec2(),
        });
        rows.push(StencilRow {
            start: i,
            coef: ROWS[1],
            rhs: *d,
        });
    }
    let (q, kind) = match m.cmp(&4) {
        std::cmp::Ordering::Equal => (solve_square_banded(&rows, n)?, HermiteSystem::Determined),
        std::cmp::Ordering::Greater => (
            solve_least_squares_banded(&rows, n)?,
            HermiteSystem::Overdetermined,
        ),
        std::cmp::Ordering::Less => (
            solve_kkt_smoothest(&rows, n)?,
            HermiteSystem::Underdetermined,
        ),
    };
    let curve = from_control_points(q.into_iter().map(Vec2::to_point).collect(), form)?;
    Ok((curve, kind))
}

/// A row during elimination: coefficients of columns `start..start + len`.
#[derive(Clone, Copy)]
struct WorkRow {
    start: usize,
    len: usize,
    coef: [f64; MAX_ROW_WIDTH],
    rhs: Vec2,
}

impl WorkRow {
    fn at(&self, col: usize) -> f64 {
        if col >= self.start && col < self.start + self.len {
            self.coef[col - self.start]
        } else {
            0.0
        }
    }

    fn end(&self) -> usize {
        self.start + self.len
    }
}

/// Solve the square system given by `rows` (sorted by `start`) for `n` unknowns, by Gaussian
/// elimination with partial pivoting restricted to the band: at column `c` the candidates
/// are the unused rows whose first column is `c`; the one with the largest entry is the pivot
/// and is subtracted from the others. O(n) for a bounded band.
fn solve_square_banded(rows: &[StencilRow], n: usize) -> Result<Vec<Vec2>> {
    if rows.len() != n {
        return Err(Error::Singular(format!(
            "{} equations for {n} unknowns",
            rows.len()
        )));
    }
    let scale = rows
        .iter()
        .flat_map(|r| r.coef.iter())
        .fold(0.0_f64, |a, v| a.max(v.abs()));
    let to_work = |r: &StencilRow| {
        let mut coef = [0.0; MAX_ROW_WIDTH];
        coef[..STENCIL_WIDTH].copy_from_slice(&r.coef);
        WorkRow {
            start: r.start,
            len: STENCIL_WIDTH,
            coef,
            rhs: r.rhs,
        }
    };
    let mut pivots: Vec<WorkRow> = Vec::with_capacity(n);
    let mut active: Vec<WorkRow> = Vec::new();
    let mut next = 0;
    for c in 0..n {
        while next < rows.len() && rows[next].start <= c {
            active.push(to_work(&rows[next]));
            next += 1;
        }
        let (best, best_abs) = active
            .iter()
            .enumerate()
            .map(|(k, r)| (k, r.at(c).abs()))
            .fold(
                (usize::MAX, 0.0),
                |acc, x| if x.1 > acc.1 { x } else { acc },
            );
        if best == usize::MAX || best_abs <= PIVOT_REL * scale {
            return Err(Error::Singular(format!(
                "quintic interpolation system: no pivot in column {c}"
            )));
        }
        let piv = active.swap_remove(best);
        let pv = piv.at(c);
        for r in &mut active {
            let f = r.at(c) / pv;
            // Re-base r to start at c + 1 and extend it to the pivot row's end.
            let new_end = r.end().max(piv.end());
            let new_start = c + 1;
            if new_end - new_start > MAX_ROW_WIDTH {
                return Err(Error::Singular(
                    "quintic interpolation system: fill-in beyond the band".into(),
                ));
            }
            let mut coef = [0.0; MAX_ROW_WIDTH];
            for (col, slot) in (new_start..new_end).zip(coef.iter_mut()) {
                *slot = r.at(col) - f * piv.at(col);
            }
            *r = WorkRow {
                start: new_start,
                len: new_end - new_start,
                coef,
                rhs: r.rhs - piv.rhs * f,
            };
        }
        pivots.push(piv);
    }
    // Back substitution: pivot row c has its leading entry in column c.
    let mut x = vec![Vec2::ZERO; n];
    for c in (0..n).rev() {
        let r = &pivots[c];
        let mut s = r.rhs;
        let end = r.end().min(n);
        for (col, xc) in x.iter().enumerate().take(end).skip(c + 1) {
            s -= *xc * r.at(col);
        }
        x[c] = s / r.at(c);
    }
    if x.iter().any(|v| !v.is_finite()) {
        return Err(Error::Singular(
            "quintic interpolation system: non-finite solution".into(),
        ));
    }
    Ok(x)
}

/// Least squares `min Σ |row·q − rhs|²` through the normal equations, a symmetric band of
/// half-width 4 (every row spans five consecutive unknowns).
fn solve_least_squares_banded(rows: &[StencilRow], n: usize) -> Result<Vec<Vec2>> {
    let mut a = SymBanded::zeros(n, STENCIL_WIDTH - 1);
    let mut b = vec![Vec2::ZERO; n];
    for r in rows {
        for (j, &cj) in r.coef.iter().enumerate() {
            b[r.start + j] += r.rhs * cj;
            for (k, &ck) in r.coef.iter().enumerate().take(j + 1) {
                a.add(r.start + j, r.start + k, cj * ck);
            }
        }
    }
    a.factorize()?;
    a.solve_in_place(&mut b)?;
    Ok(b)
}

/// The exact solution of the (underdetermined) `rows` with the least
/// `Σ_{j=1}^{n−2} |q_{j+1} − 2q_j + q_{j−1}|²`: the KKT system
/// `[2DᵀD Aᵀ; A 0] [q; λ] = [0; b]`, solved densely (n ≤ 7 here).
fn solve_kkt_smoothest(rows: &[StencilRow], n: usize) -> Result<Vec<Vec2>> {
    let k = rows.len();
    let size = n + k;
    let mut m = nalgebra::DMatrix::<f64>::zeros(size, size);
    for j in 1..n - 1 {
        let d = [(j - 1, 1.0), (j, -2.0), (j + 1, 1.0)];
        for &(a, va) in &d {
            for &(b, vb) in &d {
                m[(a, b)] += 2.0 * va * vb;
            }
        }
    }
    let mut rhs = nalgebra::DMatrix::<f64>::zeros(size, 2);
    for (ri, r) in rows.iter().enumerate() {
        // Each constraint row scaled to unit largest coefficient, for a balanced saddle point.
        let f = 1.0 / r.coef.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        for (j, &c) in r.coef.iter().enumerate() {
            m[(n + ri, r.start + j)] = c * f;
            m[(r.start + j, n + ri)] = c * f;
        }
        rhs[(n + ri, 0)] = r.rhs.x * f;
        rhs[(n + ri, 1)] = r.rhs.y * f;
    }
    let sol = m
        .full_piv_lu()
        .solve(&rhs)
        .ok_or_else(|| Error::Singular("quintic KKT system".into()))?;
    let q: Vec<Vec2> = (0..n)
        .map(|j| Vec2::new(sol[(j, 0)], sol[(j, 1)]))
        .collect();
    if q.iter().any(|v| !v.is_finite()) {
        return Err(Error::Singular(
            "quintic KKT system: non-finite solution".into(),
        ));
    }
    Ok(q)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::curve::{Curve, CurveDeriv};

    fn arc(m: usize) -> Vec<Point> {
        (0..m)
            .map(|i| {
                let a = 0.3 * i as f64;
                Point::new(5.0 * a.cos() + 0.1 * i as f64, 4.0 * a.sin())
            })
            .collect()
    }

    #[test]
    fn natural_ends_interpolate_and_meet_conditions() {
        for m in [2, 3, 4, 5, 8, 31] {
            let pts = arc(m);
            let c = interpolate(&pts, &Ends::Natural, QuinticForm::BSpline)
                .expect("test data is valid");
            assert_eq!(c.control_points().len(), m + 4);
            assert_eq!(c.domain(), (0.0, (m - 1) as f64));
            for (i, p) in pts.iter().enumerate() {
                assert!((c.eval(i as f64) - *p).length() < 1e-12, "m={m} i={i}");
            }
            for u in [0.0, (m - 1) as f64] {
                let d = c.derivatives(u);
                assert!(d.d2.length() < 1e-10, "m={m}");
            }
        }
    }

    #[test]
    fn hermite_underdetermined_is_exact_and_translation_equivariant() {
        for m in [2, 3] {
            let pts = arc(m);
            let g: Vec<Vec2> = (0..m)
                .map(|i| {
                    let a = 0.3 * i as f64;
                    Vec2::new(-1.5 * a.sin() + 0.1, 1.2 * a.cos())
                })
                .collect();
            let (c, kind) =
                interpolate_hermite(&pts, &g, QuinticForm::BSpline).expect("test data is valid");
            assert_eq!(kind, HermiteSystem::Underdetermined);
            let scale = c
                .control_points()
                .iter()
                .fold(1.0_f64, |a, q| a.max(q.to_vec2().length()));
            for i in 0..m {
                let d = c.derivatives(i as f64);
                assert!((d.point - pts[i]).length() < 1e-13 * scale);
                assert!((d.d1 - g[i]).length() < 1e-13 * scale);
            }
            let shift = Vec2::new(3.0, -7.0);
            let moved: Vec<Point> = pts.iter().map(|p| *p + shift).collect();
            let (c2, _) =
                interpolate_hermite(&moved, &g, QuinticForm::BSpline).expect("test data is valid");
            for (a, b) in c.control_points().iter().zip(c2.control_points()) {
                assert!((*b - *a - shift).length() < 1e-11);
            }
        }
    }

    #[test]
    fn hermite_overdetermined_matches_dense_least_squares() {
        let m = 9;
        let pts = arc(m);
        let g: Vec<Vec2> = (0..m)
            .map(|i| Vec2::new(-(0.3 * i as f64).sin(), (0.3 * i as f64).cos()) * 1.4)
            .collect();
        let (c, kind) =
            interpolate_hermite(&pts, &g, QuinticForm::BSpline).expect("test data is valid");
        assert_eq!(kind, HermiteSystem::Overdetermined);
        let n = m + 4;
        let mut a = nalgebra::DMatrix::<f64>::zeros(2 * m, n);
        let mut b = nalgebra::DMatrix::<f64>::zeros(2 * m, 2);
        for i in 0..m {
            for j in 0..5 {
                a[(2 * i, i + j)] = ROWS[0][j];
                a[(2 * i + 1, i + j)] = ROWS[1][j];
            }
            b[(2 * i, 0)] = pts[i].x;
            b[(2 * i, 1)] = pts[i].y;
            b[(2 * i + 1, 0)] = g[i].x;
            b[(2 * i + 1, 1)] = g[i].y;
        }
        let x = a
            .svd(true, true)
            .solve(&b, 1e-14)
            .expect("test data is valid");
        for (j, q) in c.control_points().iter().enumerate() {
            assert!((q.x - x[(j, 0)]).abs() < 1e-10 && (q.y - x[(j, 1)]).abs() < 1e-10);
        }
    }

    #[test]
    fn rejects_bad_input() {
        let pts = arc(6);
        assert!(interpolate(&pts[..1], &Ends::Natural, QuinticForm::BSpline).is_err());
        let mut dup = pts.clone();
        dup[3] = dup[2];
        assert!(matches!(
            interpolate(&dup, &Ends::Natural, QuinticForm::BSpline),
            Err(Error::DuplicatePoint { index: 3 })
        ));
        let mut nan = pts.clone();
        nan[1].x = f64::NAN;
        assert!(matches!(
            interpolate(&nan, &Ends::Natural, QuinticForm::BSpline),
            Err(Error::NonFinite { index: 1 })
        ));
        let g = vec![(0, Vec2::new(1.0, 0.0)); 4];
        assert!(interpolate(&pts, &Ends::Gradients(g), QuinticForm::BSpline).is_err());
        assert!(end_gradients(&pts, 0.0).is_err());
    }

    #[test]
    fn nurbs_form_carries_unit_weights() {
        let c =
            interpolate(&arc(5), &Ends::Natural, QuinticForm::Nurbs).expect("test data is valid");
        assert_eq!(c.weights(), Some(&[1.0; 9][..]));
        assert!(is_uniform_quintic(&c));
    }

    /// The "kuragano" vectors of `tests/data/test-vectors.json` on the quintic's basis and
    /// interpolation (moved here from `tests/kuragano.rs`: they check `ROWS` and `basis`,
    /// which are not public).
    mod vectors {
        use serde_json::Value;

        use super::super::*;
        use crate::curve::{Curve, CurveDeriv};
        use crate::test_vectors::{self, close, num, nums, points};

        fn vector(id: &str) -> Value {
            test_vectors::vector("kuragano", id)
        }

        /// A curve with six control points on the knots −5..6: its only segment is the paper's eq 3.
        fn one_segment() -> BSplineCurve {
            let q = (0..6)
                .map(|i| Point::new(i as f64, (i * i) as f64))
                .collect();
            from_control_points(q, QuinticForm::BSpline).expect("curve")
        }

        #[test]
        fn ky_basis_rows_follow_from_the_basis() {
            let v = vector("ky.basis.rows");
            let tol = &v["tolerance"];
            let c = one_segment();
            let mut b = [[0.0; crate::spline::MAX_ORDER]; 4];
            c.basis_derivs(c.find_span(0.0), 0.0, 3, &mut b);
            // r = 4: N''' of a segment is a quadratic in t, so its derivative at 0 is exactly
            // (−3 f(0) + 4 f(h) − f(2h)) / 2h (up to rounding).
            let h = 0.25;
            let third = |t: f64| {
                let mut o = [[0.0; crate::spline::MAX_ORDER]; 4];
                c.basis_derivs(c.find_span(t), t, 3, &mut o);
                o[3]
            };
            let (f0, f1, f2) = (third(0.0), third(h), third(2.0 * h));
            let derived: Vec<Vec<f64>> = (0..=4)
                .map(|r| {
                    (0..6)
                        .map(|j| {
                            if r <= 3 {
                                b[r][j]
                            } else {
                                (-3.0 * f0[j] + 4.0 * f1[j] - f2[j]) / (2.0 * h)
                            }
                        })
                        .collect()
                })
                .collect();
            for (r, row) in derived.iter().enumerate() {
                // The coefficient of q_{i+5} is zero for r ≤ 4.
                assert!(row[5].abs() < 1e-12, "r={r}");
                // The named stencils agree with de Boor–Cox (Piegl & Tiller A2.3).
                let t = if r <= 3 { 1e-15 } else { 1e-12 };
                for j in 0..5 {
                    assert!((row[j] - ROWS[r][j]).abs() < t, "r={r} j={j}");
                }
                // Polynomial reproduction: for q_j = j^k the curve is a degree-k polynomial in u with
                // leading coefficient 1, so d^r R/du^r = r! when k = r and 0 when k < r.
                for k in 0..=r {
                    let moment: f64 = (0..5).map(|j| ROWS[r][j] * (j as f64).powi(k as i32)).sum();
                    let expected = if k == r {
                        (1..=r).product::<usize>() as f64
                    } else {
                        0.0
                    };
                    assert!((moment - expected).abs() < 1e-12, "r={r} k={k}: {moment}");
                }
            }
            // The vector: rows 0, 1 (eq 8, eq 9), 2 and 4 as given.
            for r in [0, 1, 2, 4] {
                for (j, &e) in nums(&v["expected"][format!("r{r}")]).iter().enumerate() {
                    close(ROWS[r][j], e, tol, &format!("ROWS[{r}][{j}]"));
                }
            }
            // Row 3 of the vector (and of the spec table) has the signs of q_{i+1} and q_{i+3}
            // swapped: it fails the reproduction test above (q_j = j³ gives 58, not 6), so the
            // derived row is asserted and the vector's row only up to those two signs.
            let r3 = nums(&v["expected"]["r3"]);
            for (j, &e) in r3.iter().enumerate() {
                let sign = if j == 1 || j == 3 { -1.0 } else { 1.0 };
                close(ROWS[3][j], sign * e, tol, &format!("ROWS[3][{j}]"));
            }
        }

        #[test]
        fn ky_basis_values_t0_3() {
            let v = vector("ky.basis.values_t0_3");
            let tol = &v["tolerance"];
            let t = num(&v["inputs"]["t"]);
            let c = one_segment();
            let mut b = [[0.0; crate::spline::MAX_ORDER]; 4];
            c.basis_derivs(c.find_span(t), t, 2, &mut b);
            let closed_form = basis(t);
            for (r, key) in ["N", "dN", "d2N"].iter().enumerate() {
                for (j, &e) in nums(&v["expected"][*key]).iter().enumerate() {
                    close(b[r][j], e, tol, &format!("basis_derivs {key}[{j}]"));
                    close(
                        closed_form[r][j],
                        e,
                        tol,
                        &format!("quintic::basis {key}[{j}]"),
                    );
                }
            }
        }

        #[test]
        fn ky_interpolate_natural_ends() {
            let v = vector("ky.interpolate.natural_ends");
            let tol = &v["tolerance"];
            let pts = points(&v["inputs"]["points"]);
            let c = interpolate(&pts, &Ends::Natural, QuinticForm::Nurbs).expect("interpolant");
            let exp = points(&v["expected"]["control_points"]);
            assert_eq!(c.control_points().len(), exp.len());
            for (j, (q, e)) in c.control_points().iter().zip(&exp).enumerate() {
                close(q.x, e.x, tol, &format!("q[{j}].x"));
                close(q.y, e.y, tol, &format!("q[{j}].y"));
            }
            // NURBS form with unit weights; passes through the points at u = i.
            assert!(c.weights().is_some_and(|w| w.iter().all(|&x| x == 1.0)));
            for (i, p) in pts.iter().enumerate() {
                assert!((c.eval(i as f64) - *p).length() < 1e-12);
            }
            // R'' = 0 and R'''' = 0 at both ends (rows 2 and 4 on q_0..q_4 and q_{m−1}..q_{m+3}).
            let q = c.control_points();
            let m = pts.len();
            for start in [0, m - 1] {
                for r in [2, 4] {
                    let v: Vec2 =
                        (0..5).fold(Vec2::ZERO, |a, k| a + q[start + k].to_vec2() * ROWS[r][k]);
                    assert!(v.length() < 1e-12, "row {r} at {start}");
                }
            }
            assert!(c.derivatives(0.0).d2.length() < 1e-12);
            assert!(c.derivatives((m - 1) as f64).d2.length() < 1e-12);
        }
    }
}
