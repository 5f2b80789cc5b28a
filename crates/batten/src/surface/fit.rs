//! A tensor-product interpolating B-spline surface through a regular grid of points
//! (Piegl & Tiller, *The NURBS Book*, §9.2.5): parameters by chord length averaged over the
//! rows (and columns), knots by averaging (eq 9.8), then a curve interpolation of every row
//! followed by one of every column of the resulting control points, each with one
//! factorisation of the collocation matrix shared by all right-hand sides.

use nalgebra::{DMatrix, DVector};

use super::patch::{BSplineSurface, Xyz, distance};
use crate::error::{Error, Result};
use crate::spline::{KnotVector, MAX_ORDER, basis_derivs};

/// The degree used by [`interpolate_grid`] in a direction with enough points (bicubic).
pub const GRID_FIT_DEGREE: usize = 3;

/// The B-spline surface of degree `min(3, n − 1)` in each direction that passes through every
/// point of `grid` (`grid[i][j]`, i along u, j along v) at averaged chord-length parameters.
///
/// # Errors
/// - [`Error::TooFewPoints`] for fewer than 2 rows or 2 points per row;
/// - [`Error::LengthMismatch`] when the rows differ in length;
/// - [`Error::NonFinite`] for a non-finite coordinate (index in row order);
/// - [`Error::Degenerate`] when every row (or every column) has zero length, or two
///   successive parameters coincide (a repeated row or column);
/// - [`Error::Singular`] when a collocation matrix cannot be factorised.
pub fn interpolate_grid(grid: &[Vec<Xyz>]) -> Result<BSplineSurface> {
    let nu = grid.len();
    if nu < 2 {
        return Err(Error::TooFewPoints { needed: 2, got: nu });
    }
    let nv = grid[0].len();
    if nv < 2 {
        return Err(Error::TooFewPoints { needed: 2, got: nv });
    }
    if let Some(row) = grid.iter().find(|r| r.len() != nv) {
        return Err(Error::LengthMismatch {
            what: "grid row",
            got: row.len(),
            expected: nv,
        });
    }
    let flat: Vec<Xyz> = grid.iter().flatten().copied().collect();
    if let Some(index) = flat.iter().position(|c| c.iter().any(|x| !x.is_finite())) {
        return Err(Error::NonFinite { index });
    }
    let at = |i: usize, j: usize| flat[i * nv + j];
    // Parameters along u from the columns, along v from the rows.
    let su = averaged_chord_parameters(nu, nv, at)?;
    let sv = averaged_chord_parameters(nv, nu, |k, a| at(a, k))?;
    let (p, q) = (GRID_FIT_DEGREE.min(nu - 1), GRID_FIT_DEGREE.min(nv - 1));
    let ku = averaged_knots(&su, p)?;
    let kv = averaged_knots(&sv, q)?;
    let lu = collocation(&ku, p, &su)?;
    let lv = collocation(&kv, q, &sv)?;
    // Rows: interpolate along v, for every i.
    let mut r = vec![[0.0; 3]; nu * nv];
    for i in 0..nu {
        for k in 0..3 {
            let rhs = DVector::from_iterator(nv, (0..nv).map(|j| at(i, j)[k]));
            let x = lv.solve(&rhs).ok_or_else(singular)?;
            for j in 0..nv {
                r[i * nv + j][k] = x[j];
            }
        }
    }
    // Columns: interpolate those control values along u, for every j.
    let mut control = vec![[0.0; 3]; nu * nv];
    for j in 0..nv {
        for k in 0..3 {
            let rhs = DVector::from_iterator(nu, (0..nu).map(|i| r[i * nv + j][k]));
            let x = lu.solve(&rhs).ok_or_else(singular)?;
            for i in 0..nu {
                control[i * nv + j][k] = x[i];
            }
        }
    }
    BSplineSurface::try_new((p, q), (ku, kv), (nu, nv), control, None)
}

fn singular() -> Error {
    Error::Singular("the grid's collocation matrix".into())
}

/// Chord-length parameters on `[0, 1]` of `n` points, averaged over `m` lines
/// (`point(k, a)` is the k-th point of line a); lines of zero length are left out.
fn averaged_chord_parameters(
    n: usize,
    m: usize,
    point: impl Fn(usize, usize) -> Xyz,
) -> Result<Vec<f64>> {
    let mut t = vec![0.0; n];
    let mut used = 0usize;
    for a in 0..m {
        let chords: Vec<f64> = (1..n)
            .map(|k| distance(point(k, a), point(k - 1, a)))
            .collect();
        let total: f64 = chords.iter().sum();
        if total <= 0.0 {
            continue;
        }
        used += 1;
        let mut acc = 0.0;
        for k in 1..n {
            acc += chords[k - 1];
            t[k] += acc / total;
        }
    }
    if used == 0 {
        return Err(Error::Degenerate(
            "every line of the grid has zero length".into(),
        ));
    }
    for x in &mut t {
        *x /= used as f64;
    }
    t[n - 1] = 1.0;
    if let Some(k) = t.windows(2).position(|w| w[1] <= w[0]) {
        return Err(Error::Degenerate(format!(
            "grid lines {k} and {} coincide (equal parameters)",
            k + 1
        )));
    }
    Ok(t)
}

/// Clamped knots by averaging (Piegl & Tiller eq 9.8) for interpolation at `t`.
fn averaged_knots(t: &[f64], p: usize) -> Result<KnotVector> {
    let n = t.len();
    let mut k = vec![0.0; p + 1];
    for j in 1..n - p {
        k.push(t[j..j + p].iter().sum::<f64>() / p as f64);
    }
    k.extend(std::iter::repeat_n(1.0, p + 1));
    KnotVector::try_new(k)
}

/// The LU factorisation of the collocation matrix `N_j(t_i)`.
fn collocation(
    k: &KnotVector,
    p: usize,
    t: &[f64],
) -> Result<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>> {
    let n = t.len();
    let mut a = DMatrix::zeros(n, n);
    let mut out = [[0.0; MAX_ORDER]; 4];
    for (i, &ti) in t.iter().enumerate() {
        let span = k.find_span(p, n, ti);
        basis_derivs(k.as_slice(), p, span, ti, 0, &mut out);
        for a_ in 0..=p {
            a[(i, span - p + a_)] = out[0][a_];
        }
    }
    let lu = a.lu();
    if !lu.is_invertible() {
        return Err(singular());
    }
    Ok(lu)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn every_grid_point_is_interpolated() {
        let (nu, nv) = (7, 5);
        let grid: Vec<Vec<Xyz>> = (0..nu)
            .map(|i| {
                (0..nv)
                    .map(|j| {
                        let (x, y) = (i as f64 + 0.1 * (j * j) as f64, j as f64 * 0.7);
                        [x, y, (0.5 * x).cos() + 0.2 * y * y]
                    })
                    .collect()
            })
            .collect();
        let s = interpolate_grid(&grid).unwrap();
        let flat: Vec<Xyz> = grid.iter().flatten().copied().collect();
        let tu = averaged_chord_parameters(nu, nv, |k, a| flat[k * nv + a]).unwrap();
        let tv = averaged_chord_parameters(nv, nu, |k, a| flat[a * nv + k]).unwrap();
        for i in 0..nu {
            for j in 0..nv {
                let p = s.point(tu[i], tv[j]);
                for k in 0..3 {
                    assert!((p[k] - grid[i][j][k]).abs() < 1e-12, "{i},{j}");
                }
            }
        }
        // Three points in a direction give a quadratic there.
        let small: Vec<Vec<Xyz>> = grid[..3].to_vec();
        assert_eq!(interpolate_grid(&small).unwrap().degree(), (2, 3));
    }

    #[test]
    fn repeated_rows_are_degenerate() {
        let row: Vec<Xyz> = (0..4).map(|j| [0.0, j as f64, 0.0]).collect();
        let grid = vec![row.clone(), row.clone(), row];
        assert!(matches!(interpolate_grid(&grid), Err(Error::Degenerate(_))));
    }
}
