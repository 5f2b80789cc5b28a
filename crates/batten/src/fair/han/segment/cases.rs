//! The case procedures of a function segment: the coarse phase (curvature vibrations, the
//! indicator e) and the fine phase (inflections, c), each a closed-form move from a small
//! linear system in the unit responses (`docs/algorithms/han.md`, "Coarse phase: curvature
//! vibrations" and "Fine phase: inflections", docs/algorithms/han.md §1.7.1–§1.7.3).

use super::{CaseMove, MoveTag, Segment};

/// A 2×2 system is treated as singular (the move is skipped) when `|det|` is at most this
/// fraction of `|a11 a22| + |a12 a21|`. The systems of coarse case 3 and fine case 2 have
/// condition numbers below 30 on sane grids (docs/algorithms/han.md §1.7).
pub(super) const SINGULAR_REL: f64 = 1e-12;

impl Segment {
    // --- sign tests --------------------------------------------------------------------------

    #[inline]
    fn e_sign(&mut self, i: usize) -> i8 {
        self.e_scale.sign(&self.e, &self.e_floor, i)
    }

    #[inline]
    fn c_sign(&mut self, i: usize) -> i8 {
        self.c_scale.sign(&self.c, &self.c_floor, i)
    }

    /// `sgn0(u)·sgn0(v) < 0` on e.
    #[inline]
    fn e_opp(&mut self, i: usize, k: usize) -> bool {
        self.e_sign(i) * self.e_sign(k) < 0
    }

    /// `sgn0(u)·sgn0(v) > 0` on e.
    #[inline]
    fn e_same(&mut self, i: usize, k: usize) -> bool {
        self.e_sign(i) * self.e_sign(k) > 0
    }

    #[inline]
    fn c_opp(&mut self, i: usize, k: usize) -> bool {
        self.c_sign(i) * self.c_sign(k) < 0
    }

    #[inline]
    fn c_same(&mut self, i: usize, k: usize) -> bool {
        self.c_sign(i) * self.c_sign(k) > 0
    }

    /// The α rule: a fraction of whichever neighbour value has the smaller magnitude (left on
    /// a tie).
    fn alpha(&self, left: usize, right: usize) -> f64 {
        let v = if self.c[right].abs() < self.c[left].abs() {
            self.c[right]
        } else {
            self.c[left]
        };
        self.params.alpha_factor * v
    }

    // --- the procedures ----------------------------------------------------------------------

    pub(super) fn coarse_case1_with(&mut self, on_move: &mut impl FnMut(&CaseMove)) {
        let n = self.len();
        let lc = self.params.lambda_coarse;
        for i in 1..=n - 3 {
            if !self.e_opp(i, i + 1) {
                continue;
            }
            let r = &self.resp;
            let p = r.e_at(i, i) - r.e_at(i, i + 1);
            let q = r.e_at(i + 1, i) - r.e_at(i + 1, i + 1);
            let s1 = -self.e[i] / p;
            let s2 = -self.e[i + 1] / q;
            let sigma = if s1.abs() <= s2.abs() { s1 } else { s2 };
            self.apply(MoveTag::C1, i, i, &[lc * sigma, -lc * sigma], on_move);
        }
    }

    pub(super) fn coarse_case2_with(&mut self, on_move: &mut impl FnMut(&CaseMove)) {
        let n = self.len();
        for i in 2..=n - 3 {
            if self.e_opp(i, i - 1) && self.e_opp(i, i + 1) {
                let g = -self.e[i] / self.resp.e_at(i, i);
                self.apply(MoveTag::C2, i, i, &[g], on_move);
            }
        }
        // End rules: the isolated sign has two neighbours on the only available side.
        if self.e_opp(1, 2) && self.e_opp(1, 3) {
            let g = -self.e[1] / self.resp.e_at(1, 1);
            self.apply(MoveTag::C2End, 1, 1, &[g], on_move);
        }
        let m = n - 2;
        if self.e_opp(m, m - 1) && self.e_opp(m, m - 2) {
            let g = -self.e[m] / self.resp.e_at(m, m);
            self.apply(MoveTag::C2End, m, m, &[g], on_move);
        }
    }

    /// Solve `ẽ_i = ẽ_k = 0` for the moves of points i and k.
    fn zero_two_e(&self, i: usize, k: usize) -> Option<(f64, f64)> {
        let r = &self.resp;
        solve2(
            r.e_at(i, i),
            r.e_at(i, k),
            r.e_at(k, i),
            r.e_at(k, k),
            -self.e[i],
            -self.e[k],
        )
    }

    pub(super) fn coarse_case3_with(&mut self, on_move: &mut impl FnMut(&CaseMove)) {
        let n = self.len();
        if n < 6 {
            return;
        }
        for i in 2..=n - 4 {
            let fires = self.e_same(i, i + 1)
                && self.e_opp(i, i - 1)
                && self.e_opp(i, i + 2)
                && self.e_opp(i, i - 2)
                && self.e_opp(i, i + 3);
            if fires && let Some((s, t)) = self.zero_two_e(i, i + 1) {
                self.apply(MoveTag::C3, i, i, &[s, t], on_move);
            }
        }
        if self.e_same(1, 2)
            && self.e_opp(1, 3)
            && self.e_opp(1, 4)
            && let Some((s, t)) = self.zero_two_e(1, 2)
        {
            self.apply(MoveTag::C3End, 1, 1, &[s, t], on_move);
        }
        let m = n - 2;
        if self.e_same(m, m - 1)
            && self.e_opp(m, m - 2)
            && self.e_opp(m, m - 3)
            && let Some((s, t)) = self.zero_two_e(m, m - 1)
        {
            self.apply(MoveTag::C3End, m, m - 1, &[t, s], on_move);
        }
    }

    pub(super) fn fine_case1_with(&mut self, on_move: &mut impl FnMut(&CaseMove)) {
        let n = self.len();
        let lf = self.params.lambda_fine;
        // i = 2 and n−1 (1-based) never fire: c_1 = c_2 and c_{n−1} = c_n hold exactly.
        for i in 2..=n - 3 {
            if !(self.c_opp(i, i - 1) && self.c_opp(i, i + 1)) {
                continue;
            }
            let (sl, sr) = (self.c_sign(i - 1), self.c_sign(i + 1));
            let r = &self.resp;
            let k = r.c_at(i, i) - lf * (r.c_at(i, i - 1) + r.c_at(i, i + 1));
            let sigma = -self.c[i] / k;
            self.apply(
                MoveTag::F1,
                i,
                i - 1,
                &[-lf * sigma, sigma, -lf * sigma],
                on_move,
            );
            if self.c_sign(i - 1) == sl && self.c_sign(i + 1) == sr {
                let sigma = (self.alpha(i - 1, i + 1) - self.c[i]) / k;
                self.apply(
                    MoveTag::F1,
                    i,
                    i - 1,
                    &[-lf * sigma, sigma, -lf * sigma],
                    on_move,
                );
            }
        }
    }

    /// Solve fine case 2's system `c̃_i = c̃_{i+1} = α` for (σ, τ).
    fn fine_pair(&self, i: usize, alpha: f64) -> Option<(f64, f64)> {
        let lf = self.params.lambda_fine;
        let r = &self.resp;
        solve2(
            r.c_at(i, i) - lf * r.c_at(i, i - 1),
            r.c_at(i, i + 1) - lf * r.c_at(i, i + 2),
            r.c_at(i + 1, i) - lf * r.c_at(i + 1, i - 1),
            r.c_at(i + 1, i + 1) - lf * r.c_at(i + 1, i + 2),
            alpha - self.c[i],
            alpha - self.c[i + 1],
        )
    }

    pub(super) fn fine_case2_with(&mut self, on_move: &mut impl FnMut(&CaseMove)) {
        let n = self.len();
        let lf = self.params.lambda_fine;
        // i = 2 (1-based) never fires (c_1 = c_2) and would move the end point.
        for i in 2..=n.saturating_sub(4) {
            let fires = self.c_same(i, i + 1)
                && self.c_opp(i, i - 1)
                && self.c_opp(i, i + 2)
                && self.c_opp(i, i + 3);
            if !fires {
                continue;
            }
            let (sl, sr) = (self.c_sign(i - 1), self.c_sign(i + 2));
            let Some((s, t)) = self.fine_pair(i, 0.0) else {
                continue;
            };
            self.apply(MoveTag::F2, i, i - 1, &[-lf * s, s, t, -lf * t], on_move);
            if self.c_sign(i - 1) == sl
                && self.c_sign(i + 2) == sr
                && let Some((s, t)) = self.fine_pair(i, self.alpha(i - 1, i + 2))
            {
                self.apply(MoveTag::F2, i, i - 1, &[-lf * s, s, t, -lf * t], on_move);
            }
        }
        if self.c_opp(0, 2) && self.c_opp(0, 3) {
            let g = -self.c[1] / self.resp.c_at(1, 1);
            self.apply(MoveTag::F2End, 1, 1, &[g], on_move);
        }
        let m = n - 1;
        if self.c_opp(m, m - 2) && self.c_opp(m, m - 3) {
            let g = -self.c[m - 1] / self.resp.c_at(m - 1, m - 1);
            self.apply(MoveTag::F2End, m - 1, m - 1, &[g], on_move);
        }
    }

    /// Fine case 3 (extension): unknowns `γ_{i−1} = −λ_f σ, γ_i = σ, γ_{i+1} = τ, γ_{i+2} = ρ,
    /// γ_{i+3} = −λ_f ρ`, solved for `c_i = c_{i+1} = c_{i+2} = α`; α = 0 first, then the α
    /// rule from `c_{i−1}, c_{i+3}` if both kept their signs, as in fine case 2.
    pub(super) fn fine_case3_with(&mut self, on_move: &mut impl FnMut(&CaseMove)) {
        let n = self.len();
        let lf = self.params.lambda_fine;
        if n < 8 {
            return;
        }
        for i in 2..=n - 6 {
            // The most selective tests first (on smooth stretches neighbours share a sign).
            let fires = self.c_opp(i, i - 1)
                && self.c_opp(i, i + 3)
                && self.c_same(i, i + 1)
                && self.c_same(i, i + 2)
                && self.c_opp(i, i + 4);
            if !fires {
                continue;
            }
            let (sl, sr) = (self.c_sign(i - 1), self.c_sign(i + 3));
            for pass in 0..2 {
                let alpha = if pass == 0 {
                    0.0
                } else {
                    self.alpha(i - 1, i + 3)
                };
                let r = &self.resp;
                let m = nalgebra::Matrix3::from_fn(|row, col| {
                    let k = i + row;
                    match col {
                        0 => r.c_at(k, i) - lf * r.c_at(k, i - 1),
                        1 => r.c_at(k, i + 1),
                        _ => r.c_at(k, i + 2) - lf * r.c_at(k, i + 3),
                    }
                });
                let rhs = nalgebra::Vector3::new(
                    alpha - self.c[i],
                    alpha - self.c[i + 1],
                    alpha - self.c[i + 2],
                );
                let Some(sol) = m.lu().solve(&rhs) else {
                    break;
                };
                let (s, t, q) = (sol[0], sol[1], sol[2]);
                self.apply(MoveTag::F3, i, i - 1, &[-lf * s, s, t, q, -lf * q], on_move);
                if !(self.c_sign(i - 1) == sl && self.c_sign(i + 3) == sr) {
                    break;
                }
            }
        }
    }
}

/// Solve `[a11 a12; a21 a22] (s, t) = (r1, r2)` by Cramer's rule, `None` when singular.
fn solve2(a11: f64, a12: f64, a21: f64, a22: f64, r1: f64, r2: f64) -> Option<(f64, f64)> {
    let det = a11 * a22 - a12 * a21;
    let size = (a11 * a22).abs() + (a12 * a21).abs();
    if !(det.is_finite() && det.abs() > SINGULAR_REL * size) {
        return None;
    }
    let s = (r1 * a22 - a12 * r2) / det;
    let t = (a11 * r2 - a21 * r1) / det;
    (s.is_finite() && t.is_finite()).then_some((s, t))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solve2_rejects_singular() {
        assert_eq!(solve2(1.0, 2.0, 2.0, 4.0, 1.0, 1.0), None);
        let (s, t) = solve2(2.0, 1.0, 1.0, 3.0, 3.0, 4.0).unwrap_or((f64::NAN, f64::NAN));
        assert!((s - 1.0).abs() < 1e-15 && (t - 1.0).abs() < 1e-15);
    }
}
