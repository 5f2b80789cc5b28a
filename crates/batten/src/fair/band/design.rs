//! How the solver's unknowns give the faired points: `q = B x`.
//!
//! In the point form (`Design::Points`) the unknowns are the points themselves, `B = I`. In
//! the spline form (`Design::Spline`, for dense points, see `spline.rs`) they are the control
//! points of a cubic B-spline and point `i` is `Σ_k b_ik x_{f_i + k}`: four basis values and
//! four consecutive control points, so every matrix the solver builds keeps the band of the
//! energy (half-bandwidth `4D − 1` in the interleaved numbering).

use super::energy::four_from;
use crate::numeric::{BandRows, PARALLEL_FROM, SymBanded};
use rayon::prelude::*;

/// Points a task of [`Design::eval`] evaluates.
const EVAL_CHUNK: usize = 1 << 14;

/// From this many points [`SplineMap::add_blocks_open`] assembles on two threads (the
/// working sets of long dense curves: 28 000–53 000 points on #14's sine).
const SPLIT_ASSEMBLY_FROM: usize = 1 << 14;

/// The map from unknowns to points.
#[derive(Clone, Debug)]
pub(super) enum Design {
    /// The unknowns are the `n` points.
    Points { n: usize },
    /// The unknowns are the control points of a cubic B-spline.
    Spline(SplineMap),
}

/// Point `i` of a spline: `Σ_k basis[i][k] · x[(first[i] + k) mod vars]`.
#[derive(Clone, Debug)]
pub(super) struct SplineMap {
    /// The number of control points.
    pub vars: usize,
    /// The first control point of each point's span.
    pub first: Vec<usize>,
    /// The four basis values of each point.
    pub basis: Vec<[f64; 4]>,
}

impl SplineMap {
    /// Point `i` of the spline with control points `x` (flat, `D` numbers each).
    pub(super) fn point<const D: usize>(&self, i: usize, x: &[f64]) -> [f64; D] {
        self.point_at::<D>(self.first[i], &self.basis[i], x)
    }

    /// `Σ_k b_k x_{f+k}` (indices wrapped for closed curves).
    #[inline]
    fn point_at<const D: usize>(&self, f: usize, b: &[f64; 4], x: &[f64]) -> [f64; D] {
        let mut q = [0.0; D];
        if f + 4 <= self.vars {
            let x = &x[f * D..(f + 4) * D];
            for (k, bk) in b.iter().enumerate() {
                for a in 0..D {
                    q[a] += bk * x[k * D + a];
                }
            }
        } else {
            for (k, bk) in b.iter().enumerate() {
                let j = (f + k) % self.vars;
                for a in 0..D {
                    q[a] += bk * x[j * D + a];
                }
            }
        }
        q
    }

    /// Cuts of the points into pieces of about `size`, each cut where a knot span begins
    /// (`first` changes), from 0 to the number of points.
    pub(super) fn span_cuts(&self, size: usize) -> Vec<usize> {
        let n = self.first.len();
        let mut cuts = vec![0];
        let mut at = size;
        while at < n {
            while at < n && self.first[at] == self.first[at - 1] {
                at += 1;
            }
            if at < n {
                cuts.push(at);
            }
            at += size;
        }
        cuts.push(n);
        cuts
    }

    /// Call `add(row, col, value)` for the entries with `row ≥ col` of the 4×4 block `acc`
    /// (every coordinate) of the span whose first control point is `f`.
    pub(super) fn add_span_lower<const D: usize>(
        &self,
        f: usize,
        acc: &[[f64; 4]; 4],
        add: &mut impl FnMut(usize, usize, f64),
    ) {
        let at = four_from(f, self.vars).map(|j| j * D);
        for (row, &r0) in acc.iter().zip(&at) {
            for (v, &c0) in row.iter().zip(&at) {
                if r0 >= c0 {
                    for a in 0..D {
                        add(r0 + a, c0 + a, *v);
                    }
                }
            }
        }
    }

    /// Set the lower band of `m` to that of `base` plus `Σ_i B_iᵀ M_i B_i` (`M_i =
    /// blocks[i]`, points with `skip[i]` left out, entries of `held` unknowns left out), for
    /// an open curve (no control point wraps), and return its largest diagonal entry (or 0):
    /// what [`Design::for_each_block_lower`] reports, added in the same order (the same sums,
    /// bit for bit), written straight into the band. The interior point assembles this at
    /// every iteration, and through a callback per entry it was a tenth of a dense run's
    /// time; each thread copies and measures its own rows while they are in its cache.
    pub(super) fn add_blocks_open<const D: usize>(
        &self,
        blocks: &[[[f64; D]; D]],
        skip: &[bool],
        held: &[bool],
        base: &SymBanded,
        m: &mut SymBanded,
    ) -> f64 {
        let n = blocks.len();
        let cut = if n >= SPLIT_ASSEMBLY_FROM {
            self.first[n / 2]
        } else {
            0
        };
        // Every row is set from `base` below: the last factors are overwritten.
        m.reassemble();
        let assemble = |points: std::ops::Range<usize>, mut rows: BandRows<'_>| {
            rows.assign_from(base);
            self.add_blocks_rows::<D>(blocks, skip, held, points, &mut rows);
            rows.max_diagonal()
        };
        if cut < 4 {
            return assemble(0..n, m.rows_mut(0, m.n()));
        }
        // Two threads, each writing the rows it owns: the first the rows of control points
        // before `cut` (from the spans before it), the second the others (from the spans
        // from `cut − 3` on, which reach them). Every entry gets the same terms in the same
        // order as one sweep: the same sums, bit for bit.
        let from = |span: usize| self.first[..n].partition_point(|&f| f < span);
        let (top, bottom) = m.split_rows_mut(cut * D);
        let (a, b) = rayon::join(
            || assemble(0..from(cut), top),
            || assemble(from(cut - 3)..n, bottom),
        );
        a.max(b)
    }

    /// [`SplineMap::add_blocks_open`] for the points `points`, into the rows `rows` holds
    /// (the entries of other rows left out).
    fn add_blocks_rows<const D: usize>(
        &self,
        blocks: &[[[f64; D]; D]],
        skip: &[bool],
        held: &[bool],
        points: std::ops::Range<usize>,
        rows: &mut BandRows<'_>,
    ) {
        let mut acc = [[[[0.0; D]; D]; 4]; 4];
        let flush = |f: usize, acc: &mut [[[[f64; D]; D]; 4]; 4], m: &mut BandRows<'_>| {
            let any_held = (0..4).any(|k| held[f + k]);
            for k in 0..4 {
                let r0 = (f + k) * D;
                if !m.holds(r0) {
                    continue;
                }
                // Blocks right of the diagonal block hold no entry of the lower triangle.
                for l in 0..=k {
                    if any_held && (held[f + k] || held[f + l]) {
                        continue;
                    }
                    let c0 = (f + l) * D;
                    for a in 0..D {
                        for c in 0..D {
                            if r0 + a >= c0 + c {
                                m.add_lower(r0 + a, c0 + c, acc[k][l][a][c]);
                            }
                        }
                    }
                }
            }
            *acc = [[[[0.0; D]; D]; 4]; 4];
        };
        let mut current = None;
        for i in points {
            if skip[i] {
                continue;
            }
            let (f, b, mb) = (self.first[i], &self.basis[i], &blocks[i]);
            if current != Some(f) {
                if let Some(g) = current {
                    flush(g, &mut acc, rows);
                }
                current = Some(f);
            }
            for k in 0..4 {
                for l in 0..=k {
                    let bb = b[k] * b[l];
                    for a in 0..D {
                        for c in 0..D {
                            acc[k][l][a][c] += bb * mb[a][c];
                        }
                    }
                }
            }
        }
        if let Some(g) = current {
            flush(g, &mut acc, rows);
        }
    }

    /// Call `add(row, col, value)` for the entries with `row ≥ col` of `w B_iᵀ B_i` (point
    /// `i` alone, `w` on every coordinate), and add `w B_iᵀ v` to `out`.
    pub(super) fn add_point<const D: usize>(
        &self,
        i: usize,
        w: f64,
        v: &[f64; D],
        mut add: impl FnMut(usize, usize, f64),
        out: &mut [f64],
    ) {
        let (f, b) = (self.first[i], self.basis[i]);
        let acc: [[f64; 4]; 4] = std::array::from_fn(|k| std::array::from_fn(|l| w * b[k] * b[l]));
        self.add_span_lower::<D>(f, &acc, &mut add);
        for (k, bk) in b.iter().enumerate() {
            let j = (f + k) % self.vars;
            for a in 0..D {
                out[j * D + a] += w * bk * v[a];
            }
        }
    }
}

impl Design {
    /// The number of points.
    pub(super) fn points(&self) -> usize {
        match self {
            Design::Points { n } => *n,
            Design::Spline(s) => s.first.len(),
        }
    }

    /// The number of unknown points (control points in the spline form).
    pub(super) fn vars(&self) -> usize {
        match self {
            Design::Points { n } => *n,
            Design::Spline(s) => s.vars,
        }
    }

    /// `(B x)_i`: point `i` of the unknowns `x`.
    pub(super) fn value<const D: usize>(&self, i: usize, x: &[f64]) -> [f64; D] {
        match self {
            Design::Points { .. } => std::array::from_fn(|a| x[i * D + a]),
            Design::Spline(s) => s.point::<D>(i, x),
        }
    }

    /// `out = B x` (flat, `D` numbers a point).
    pub(super) fn eval<const D: usize>(&self, x: &[f64], out: &mut [f64]) {
        self.eval_then::<D>(x, out, |_, q| q);
    }

    /// `out = B x − c` (flat, `c` the ball centres `centres`), zero at the points `pinned`
    /// marks, where given.
    pub(super) fn residual<const D: usize>(
        &self,
        x: &[f64],
        centres: &[f64],
        pinned: Option<&[bool]>,
        out: &mut [f64],
    ) {
        self.eval_then::<D>(x, out, |i, q| {
            if pinned.is_some_and(|p| p[i]) {
                [0.0; D]
            } else {
                std::array::from_fn(|a| q[a] - centres[i * D + a])
            }
        });
    }

    /// `out_i = then(i, (B x)_i)` for every point `i` (flat, `D` numbers a point): what a
    /// sweep does with each point's value, in the same parallel pieces as the evaluation.
    pub(super) fn eval_then<const D: usize>(
        &self,
        x: &[f64],
        out: &mut [f64],
        then: impl Fn(usize, [f64; D]) -> [f64; D] + Sync,
    ) {
        match self {
            Design::Points { .. } => {
                for (i, (o, v)) in out.chunks_exact_mut(D).zip(x.chunks_exact(D)).enumerate() {
                    o.copy_from_slice(&then(i, std::array::from_fn(|a| v[a])));
                }
            }
            Design::Spline(s) => {
                // Every point on its own: in chunks on the pool's threads (the same sums
                // whatever the split).
                out.par_chunks_mut(EVAL_CHUNK * D)
                    .enumerate()
                    .for_each(|(c, out)| {
                        let from = c * EVAL_CHUNK;
                        for (k, (o, (&f, b))) in out
                            .chunks_exact_mut(D)
                            .zip(s.first[from..].iter().zip(&s.basis[from..]))
                            .enumerate()
                        {
                            o.copy_from_slice(&then(from + k, s.point_at::<D>(f, b, x)));
                        }
                    });
            }
        }
    }

    /// Whether `test(i, (B x)_i)` holds at some point `i`: the sweep of
    /// [`Design::eval_then`] without its output, in parallel pieces that stop once one is
    /// found (a check that only asks whether any point is outside its ball writes no vector
    /// of every point).
    pub(super) fn any_point<const D: usize>(
        &self,
        x: &[f64],
        test: impl Fn(usize, [f64; D]) -> bool + Sync,
    ) -> bool {
        let n = self.points();
        match self {
            Design::Points { .. } => (0..n).any(|i| test(i, std::array::from_fn(|a| x[i * D + a]))),
            Design::Spline(s) => (0..n.div_ceil(EVAL_CHUNK)).into_par_iter().any(|c| {
                let from = c * EVAL_CHUNK;
                let to = (from + EVAL_CHUNK).min(n);
                (from..to).any(|i| test(i, s.point_at::<D>(s.first[i], &s.basis[i], x)))
            }),
        }
    }

    /// `out += Bᵀ r`.
    pub(super) fn eval_t_add<const D: usize>(&self, r: &[f64], out: &mut [f64]) {
        match self {
            Design::Points { .. } => {
                for (o, v) in out.iter_mut().zip(r) {
                    *o += v;
                }
            }
            Design::Spline(s) => {
                for (i, (&f, b)) in s.first.iter().zip(&s.basis).enumerate() {
                    let r = &r[i * D..(i + 1) * D];
                    if f + 4 <= s.vars {
                        let out = &mut out[f * D..(f + 4) * D];
                        for (k, bk) in b.iter().enumerate() {
                            for a in 0..D {
                                out[k * D + a] += bk * r[a];
                            }
                        }
                    } else {
                        for (k, bk) in b.iter().enumerate() {
                            let j = (f + k) % s.vars;
                            for a in 0..D {
                                out[j * D + a] += bk * r[a];
                            }
                        }
                    }
                }
            }
        }
    }

    /// Call `add(row, col, value)` for the entries with `row ≥ col` of `Σ_i B_iᵀ M_i B_i`
    /// (`M_i = blocks[i]`, points with `skip[i]` left out), as the energy reports its own.
    pub(super) fn for_each_block_lower<const D: usize>(
        &self,
        blocks: &[[[f64; D]; D]],
        skip: &[bool],
        mut add: impl FnMut(usize, usize, f64),
    ) {
        match self {
            Design::Points { .. } => {
                for (i, b) in blocks.iter().enumerate() {
                    if skip[i] {
                        continue;
                    }
                    for a in 0..D {
                        for c in 0..=a {
                            add(i * D + a, i * D + c, b[a][c]);
                        }
                    }
                }
            }
            Design::Spline(s) => {
                // The points come in runs on the same span (their parameters increase): each
                // run's blocks are summed locally and reported once.
                let mut acc = [[[[0.0; D]; D]; 4]; 4];
                let mut current = None;
                let mut flush = |f: usize, acc: &mut [[[[f64; D]; D]; 4]; 4]| {
                    for (k, row) in acc.iter_mut().enumerate() {
                        let r0 = ((f + k) % s.vars) * D;
                        for (l, m) in row.iter_mut().enumerate() {
                            let c0 = ((f + l) % s.vars) * D;
                            for (a, m_a) in m.iter_mut().enumerate() {
                                for (c, v) in m_a.iter_mut().enumerate() {
                                    if r0 + a >= c0 + c {
                                        add(r0 + a, c0 + c, *v);
                                    }
                                    *v = 0.0;
                                }
                            }
                        }
                    }
                };
                for (i, m) in blocks.iter().enumerate() {
                    if skip[i] {
                        continue;
                    }
                    let (f, b) = (s.first[i], &s.basis[i]);
                    if current != Some(f) {
                        if let Some(g) = current {
                            flush(g, &mut acc);
                        }
                        current = Some(f);
                    }
                    for k in 0..4 {
                        for l in 0..4 {
                            let bb = b[k] * b[l];
                            for a in 0..D {
                                for c in 0..D {
                                    acc[k][l][a][c] += bb * m[a][c];
                                }
                            }
                        }
                    }
                }
                if let Some(g) = current {
                    flush(g, &mut acc);
                }
            }
        }
    }

    /// Call `add(row, col, value)` for the entries with `row ≥ col` of `Σ_i w_i B_iᵀ B_i`
    /// (`w_i = weight(i)` on every coordinate, points with `skip[i]` left out): the blocks of
    /// [`Design::for_each_block_lower`] when each is `w_i I`, at a quarter of the work in 2-D.
    pub(super) fn for_each_weight_lower<const D: usize>(
        &self,
        weight: impl Fn(usize) -> f64 + Sync,
        skip: &[bool],
        mut add: impl FnMut(usize, usize, f64),
    ) {
        match self {
            Design::Points { n } => {
                for i in (0..*n).filter(|i| !skip[*i]) {
                    let w = weight(i);
                    for a in 0..D {
                        add(i * D + a, i * D + a, w);
                    }
                }
            }
            Design::Spline(s) => {
                // Each knot span's sum over its points, in point order, in pieces that start
                // where a span does (in parallel on long curves), then reported span by span
                // in order: the same sums and the same calls as one sweep. A span that does
                // not wrap reports only its entries with `k ≥ l` (its control points
                // increase), so only those are summed.
                let lower_only = |f: usize| f + 4 <= s.vars;
                let piece = |from: usize, to: usize| -> Vec<(usize, [[f64; 4]; 4])> {
                    let mut out: Vec<(usize, [[f64; 4]; 4])> = Vec::new();
                    for i in from..to {
                        if skip[i] {
                            continue;
                        }
                        let (f, b) = (s.first[i], &s.basis[i]);
                        if out.last().is_none_or(|(g, _)| *g != f) {
                            out.push((f, [[0.0; 4]; 4]));
                        }
                        let Some((_, acc)) = out.last_mut() else {
                            continue;
                        };
                        let w = weight(i);
                        if lower_only(f) {
                            for k in 0..4 {
                                let wb = w * b[k];
                                for l in 0..=k {
                                    acc[k][l] += wb * b[l];
                                }
                            }
                        } else {
                            for k in 0..4 {
                                let wb = w * b[k];
                                for l in 0..4 {
                                    acc[k][l] += wb * b[l];
                                }
                            }
                        }
                    }
                    out
                };
                let n = s.first.len();
                let pieces: Vec<Vec<(usize, [[f64; 4]; 4])>> = if n >= PARALLEL_FROM {
                    let cuts = s.span_cuts(EVAL_CHUNK);
                    cuts.par_windows(2).map(|c| piece(c[0], c[1])).collect()
                } else {
                    vec![piece(0, n)]
                };
                for (f, acc) in pieces.iter().flatten() {
                    s.add_span_lower::<D>(*f, acc, &mut add);
                }
            }
        }
    }

    /// `out += Σ_i B_iᵀ M_i B_i v` (points with `skip[i]` left out); `work` holds `B v`.
    pub(super) fn apply_blocks_add<const D: usize>(
        &self,
        blocks: &[[[f64; D]; D]],
        skip: &[bool],
        v: &[f64],
        work: &mut [f64],
        out: &mut [f64],
    ) {
        self.eval::<D>(v, work);
        for (i, m) in blocks.iter().enumerate() {
            let mut mv = [0.0; D];
            if !skip[i] {
                for a in 0..D {
                    mv[a] = (0..D).map(|c| m[a][c] * work[i * D + c]).sum::<f64>();
                }
            }
            work[i * D..(i + 1) * D].copy_from_slice(&mv);
        }
        self.eval_t_add::<D>(work, out);
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// A small spline map (cyclic when `closed`), with runs of points on each span and
    /// uneven basis values.
    pub(crate) fn map(closed: bool) -> SplineMap {
        let vars = 7;
        let spans = if closed { vars } else { vars - 3 };
        let mut first = Vec::new();
        let mut basis = Vec::new();
        for span in 0..spans {
            for j in 0..3 {
                let u = (j as f64 + 0.5) / 3.0 + 0.01 * span as f64;
                let b = [
                    (1.0 - u).powi(3) / 6.0,
                    (3.0 * u.powi(3) - 6.0 * u * u + 4.0) / 6.0,
                    (-3.0 * u.powi(3) + 3.0 * u * u + 3.0 * u + 1.0) / 6.0,
                    u.powi(3) / 6.0,
                ];
                first.push(span);
                basis.push(b);
            }
        }
        SplineMap { vars, first, basis }
    }

    /// The blocks written straight into the band are the entries the callback reports,
    /// the same sums bit for bit, held unknowns left out.
    #[test]
    fn blocks_into_the_band_match_the_callback() {
        let map = map(false);
        let n = map.first.len();
        assert_blocks_match(&map, &(0..n).map(|i| i % 4 == 3).collect::<Vec<_>>(), 1);
    }

    /// A long open spline map (more points near the middle of the spans), as the long curves
    /// of the tests below.
    fn long_map(n: usize, spans: usize) -> SplineMap {
        let vars = spans + 3;
        let first: Vec<usize> = (0..n)
            .map(|i| {
                let u = i as f64 / n as f64;
                let v = u + 0.1 * (std::f64::consts::TAU * u).sin() / std::f64::consts::TAU;
                ((v * spans as f64) as usize).min(spans - 1)
            })
            .collect();
        let basis: Vec<[f64; 4]> = (0..n)
            .map(|i| {
                let u = (i as f64 * 0.37).fract();
                [(1.0 - u) / 3.0, 0.4, u / 3.0, 0.1 + 0.01 * u]
            })
            .collect();
        SplineMap { vars, first, basis }
    }

    /// [`SplineMap::add_blocks_open`] on `map` (points `skip` left out) writes the entries
    /// [`Design::for_each_block_lower`] reports, bit for bit, with nothing held and with
    /// `ends` control points held at each end.
    fn assert_blocks_match(map: &SplineMap, skip: &[bool], ends: usize) {
        let design = Design::Spline(map.clone());
        let (n, vars) = (map.first.len(), map.vars);
        let blocks: Vec<[[f64; 2]; 2]> = (0..n)
            .map(|i| {
                let a = 1.0 + (i as f64 * 0.3).sin().abs();
                let b = 0.2 * (i as f64 * 0.9).cos();
                [[a, b], [b, 0.5 * a + 0.1]]
            })
            .collect();
        let dim = 2 * vars;
        for held_ends in [false, true] {
            let held: Vec<bool> = (0..vars)
                .map(|j| held_ends && (j < ends || j + ends >= vars))
                .collect();
            // A base with entries in every stored place, which the blocks are added to
            // (diagonally dominant, so that the sum can be factorised).
            let mut base = SymBanded::zeros(dim, 7);
            for r in 0..dim {
                for c in r.saturating_sub(7)..=r {
                    base.add(r, c, 0.1 + (r as f64 * 0.7 + c as f64).sin());
                }
                base.add(r, r, 20.0);
            }
            let mut want = base.clone();
            design.for_each_block_lower::<2>(&blocks, skip, |r, c, v| {
                if !held[r / 2] && !held[c / 2] {
                    want.add(r, c, v);
                }
            });
            // Whatever the matrix held before is replaced.
            let mut got = SymBanded::zeros(dim, 7);
            got.add(3, 2, 7.0);
            // Again into the factors of the first (the interior point's every iteration).
            for again in [false, true] {
                if again {
                    got.factorize_regularized_split(1e-12).expect("factors");
                }
                let top = map.add_blocks_open::<2>(&blocks, skip, &held, &base, &mut got);
                for r in 0..dim {
                    for c in r.saturating_sub(7)..=r {
                        let (g, w) = (got.get(r, c), want.get(r, c));
                        assert_eq!(g.to_bits(), w.to_bits(), "{r} {c}");
                    }
                }
                let want_top = (0..dim).fold(0.0_f64, |m, k| m.max(want.get(k, k)));
                assert_eq!(top.to_bits(), want_top.to_bits());
            }
        }
    }

    /// On a long curve (two threads, each on its own rows) the blocks written into the band
    /// are the callback's entries, bit for bit, held ends left out.
    #[test]
    fn blocks_into_the_band_on_two_threads_match_the_callback() {
        let map = long_map(SPLIT_ASSEMBLY_FROM + 3001, 2000);
        let n = map.first.len();
        assert_blocks_match(&map, &(0..n).map(|i| i % 7 == 3).collect::<Vec<_>>(), 2);
    }

    /// On a long curve (pieces in parallel) the weighted Gram matrix is reported in the
    /// calls one sweep makes, with the same sums bit for bit.
    #[test]
    fn weight_gram_in_pieces_matches_one_sweep() {
        let map = long_map(PARALLEL_FROM + 5000, 3000);
        let n = map.first.len();
        let skip: Vec<bool> = (0..n).map(|i| i % 11 == 5).collect();
        let weight = |i: usize| 1.0 + (i as f64 * 0.01).sin().abs();
        let mut want = Vec::new();
        let mut acc = [[0.0; 4]; 4];
        let mut current = None;
        for i in 0..n {
            if skip[i] {
                continue;
            }
            let f = map.first[i];
            if current != Some(f) {
                if let Some(g) = current {
                    map.add_span_lower::<2>(g, &acc, &mut |r, c, v| want.push((r, c, v)));
                }
                acc = [[0.0; 4]; 4];
                current = Some(f);
            }
            for k in 0..4 {
                let wb = weight(i) * map.basis[i][k];
                for l in 0..4 {
                    acc[k][l] += wb * map.basis[i][l];
                }
            }
        }
        if let Some(g) = current {
            map.add_span_lower::<2>(g, &acc, &mut |r, c, v| want.push((r, c, v)));
        }
        let mut got = Vec::new();
        Design::Spline(map).for_each_weight_lower::<2>(weight, &skip, |r, c, v| {
            got.push((r, c, v));
        });
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(&want) {
            assert_eq!((g.0, g.1, g.2.to_bits()), (w.0, w.1, w.2.to_bits()));
        }
    }

    /// The scalar-weight Gram matrix equals the block one with blocks `w_i I`.
    #[test]
    fn weight_gram_matches_blocks() {
        for closed in [false, true] {
            let design = Design::Spline(map(closed));
            let n = design.points();
            let weight = |i: usize| 1.0 + (i as f64 * 0.7).sin().abs();
            let skip: Vec<bool> = (0..n).map(|i| i % 5 == 2).collect();
            let blocks: Vec<[[f64; 2]; 2]> = (0..n)
                .map(|i| [[weight(i), 0.0], [0.0, weight(i)]])
                .collect();
            let dim = 2 * design.vars();
            let mut want = vec![0.0; dim * dim];
            design.for_each_block_lower::<2>(&blocks, &skip, |r, c, v| want[r * dim + c] += v);
            let mut got = vec![0.0; dim * dim];
            design.for_each_weight_lower::<2>(weight, &skip, |r, c, v| {
                assert!(r >= c);
                got[r * dim + c] += v;
            });
            for (g, w) in got.iter().zip(&want) {
                assert!((g - w).abs() < 1e-14, "{g} {w}");
            }
        }
    }

    /// `any_point` finds a point exactly when the sweep's values do: on a long map (many
    /// parallel pieces), for a point in the first piece, one in the last, none, and the
    /// point form.
    #[test]
    fn any_point_agrees_with_the_sweep() {
        let design = Design::Spline(long_map(3 * EVAL_CHUNK + 77, 2000));
        let n = design.points();
        let x: Vec<f64> = (0..2 * design.vars())
            .map(|k| (k as f64 * 0.7).sin())
            .collect();
        let mut values = vec![0.0; 2 * n];
        design.eval::<2>(&x, &mut values);
        for target in [Some(5), Some(n - 1), None] {
            let found = design.any_point::<2>(&x, |i, q| {
                Some(i) == target && q[0] == values[2 * i] && q[1] == values[2 * i + 1]
            });
            assert_eq!(found, target.is_some(), "{target:?}");
        }
        let points = Design::Points { n: 4 };
        let x = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0];
        assert!(points.any_point::<2>(&x, |i, q| i == 2 && q == [4.0, 5.0]));
        assert!(!points.any_point::<2>(&x, |_, q| q[0] > 6.0));
    }
}
