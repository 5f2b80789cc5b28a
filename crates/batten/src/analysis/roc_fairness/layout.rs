//! The unknowns of the shape modification: which control points are fixed, free (two columns
//! each) or, for `fix_ends`, eliminated and recomputed from the others so that the curve's end
//! points stay put (`docs/algorithms/kuragano.md`, "The fairing method `kuragano`", and the
//! module docs).

use crate::curve::Curve;
use crate::error::{Error, Result};
use crate::geom::{EndFix, Point, Vec2};
use crate::spline::{BSplineCurve, MAX_ORDER};

/// Smallest basis weight of a free control point at a curve end for `fix_ends` to eliminate
/// it; an end with no such weight is a fixed control point already.
const ELIMINATION_MIN_WEIGHT: f64 = 1e-12;

fn too_small_for_fix_ends(n_ctrl: usize) -> Error {
    Error::InvalidParameter {
        name: "fix_ends".into(),
        reason: format!(
            "{n_ctrl} control points are too few to hold both curve ends independently"
        ),
    }
}

/// How one unknown or control point enters the optimisation.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Role {
    Fixed,
    /// Column index of its x coordinate (y is the next column).
    Free(usize),
    /// Recomputed from the others: index into the eliminations.
    Eliminated(usize),
}

/// `q_e = (P − Σ_{j≠e} b_j q_j)/b_e` over the stencil `first..first + b.len()`.
#[derive(Clone, Debug)]
pub(super) struct Elimination {
    index: usize,
    first: usize,
    basis: Vec<f64>,
    target: Point,
}

impl Elimination {
    pub(super) fn apply(&self, q: &mut [Point]) {
        let be = self.basis[self.index - self.first];
        let mut s = self.target.to_vec2();
        for (j, &b) in self.basis.iter().enumerate() {
            let idx = self.first + j;
            if idx != self.index {
                s -= q[idx].to_vec2() * b;
            }
        }
        q[self.index] = (s / be).to_point();
    }
}

/// The unknowns of the modification.
pub(super) struct Layout {
    roles: Vec<Role>,
    pub(super) elim: Vec<Elimination>,
    pub(super) unknowns: usize,
}

impl Layout {
    pub(super) fn new(
        curve: &BSplineCurve,
        ends: EndFix,
        end_points: Option<(Point, Point)>,
    ) -> Result<Layout> {
        let hold_end_derivatives = ends.held() >= 2;
        let n = curve.control_points().len();
        let mut roles = vec![Role::Fixed; n];
        let mut elim = Vec::new();
        // Control points acting at a domain end, kept where they are.
        let mut held = vec![false; n];
        if hold_end_derivatives {
            let (a, b) = curve.domain();
            for u in [a, b] {
                let first = curve.find_span(u) - curve.degree();
                held[first..=first + curve.degree()].fill(true);
            }
        }
        if let Some((p0, p1)) = end_points.filter(|_| ends == EndFix::Position) {
            let (a, b) = curve.domain();
            for (u, target) in [(a, p0), (b, p1)] {
                let span = curve.find_span(u);
                let mut basis = [[0.0; MAX_ORDER]; 4];
                curve.basis_derivs(span, u, 0, &mut basis);
                let first = span - curve.degree();
                let vals: Vec<f64> = basis[0][..=curve.degree()].to_vec();
                // The free control point with the largest weight at the end.
                let best = (0..vals.len())
                    .filter(|&j| first + j != 0 && first + j != n - 1)
                    .max_by(|&x, &y| vals[x].total_cmp(&vals[y]));
                match best {
                    Some(j) if vals[j] > ELIMINATION_MIN_WEIGHT => {
                        let index = first + j;
                        if roles[index] != Role::Fixed {
                            return Err(too_small_for_fix_ends(n));
                        }
                        roles[index] = Role::Eliminated(elim.len());
                        elim.push(Elimination {
                            index,
                            first,
                            basis: vals,
                            target,
                        });
                    }
                    // The end is a fixed control point (clamped knots): nothing to eliminate.
                    _ => {}
                }
            }
            // An eliminated point must not depend on the other one.
            for e in &elim {
                let stencil = &roles[e.first..e.first + e.basis.len()];
                let clash = stencil
                    .iter()
                    .enumerate()
                    .any(|(j, r)| e.first + j != e.index && matches!(r, Role::Eliminated(_)));
                if clash {
                    return Err(too_small_for_fix_ends(n));
                }
            }
        }
        let mut unknowns = 0;
        for (j, r) in roles.iter_mut().enumerate() {
            if j != 0 && j != n - 1 && *r == Role::Fixed && !held[j] {
                *r = Role::Free(unknowns);
                unknowns += 2;
            }
        }
        Ok(Layout {
            roles,
            elim,
            unknowns,
        })
    }

    /// Add `g` (the gradient with respect to control point `idx`) to the sparse row.
    pub(super) fn scatter(&self, idx: usize, g: Vec2, row: &mut Vec<(usize, f64)>) {
        match self.roles[idx] {
            Role::Fixed => {}
            Role::Free(c) => {
                row.push((c, g.x));
                row.push((c + 1, g.y));
            }
            Role::Eliminated(e) => {
                let el = &self.elim[e];
                let be = el.basis[el.index - el.first];
                for (j, &b) in el.basis.iter().enumerate() {
                    let other = el.first + j;
                    if other != el.index
                        && let Role::Free(c) = self.roles[other]
                    {
                        let f = -b / be;
                        row.push((c, g.x * f));
                        row.push((c + 1, g.y * f));
                    }
                }
            }
        }
    }

    /// The control points after adding `step` to the free ones.
    pub(super) fn apply(&self, q: &[Point], step: &[f64]) -> Vec<Point> {
        let mut out = q.to_vec();
        for (p, r) in out.iter_mut().zip(&self.roles) {
            if let Role::Free(c) = *r {
                *p = Point::new(p.x + step[c], p.y + step[c + 1]);
            }
        }
        for e in &self.elim {
            e.apply(&mut out);
        }
        out
    }
}
