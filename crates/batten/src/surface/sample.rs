//! Curvature sampled on a regular parameter grid, and the summary of it that
//! `batten analyze-surface` prints ([`SurfaceAnalysis`]).
//!
//! # The grid
//!
//! [`SampleGrid::for_surface`] takes `SAMPLES_PER_SPAN · spans + 1` uniform parameters in each
//! direction ([`SAMPLES_PER_SPAN`] = 4 per non-empty knot span), at least [`MIN_SAMPLES`],
//! the domain's ends included. The same grid serves the analysis, the targets and the
//! measure Π̂ of the `salvi` fairing, so the numbers of `analyze-surface` and of a fairing
//! report agree.

use serde::Serialize;

use super::patch::{BSplineSurface, SurfaceCurvature};
use super::target::{TargetParams, Targets};
use crate::fair::local::uniform_samples;

/// Samples per non-empty knot span in each direction.
pub const SAMPLES_PER_SPAN: usize = 4;

/// The fewest samples in a direction.
pub const MIN_SAMPLES: usize = 17;

/// A point counts as an umbilic when `κ1 − κ2 ≤ UMBILIC_REL · max(|κ1|, |κ2|, 1/D)`, D the
/// diagonal of the control net's bounding box (so that on a plane every point is umbilic and
/// rounding noise on a flat region is not mistaken for a difference).
pub const UMBILIC_REL: f64 = 1e-3;

/// Uniform parameters in u and v.
#[derive(Clone, Debug, PartialEq)]
pub struct SampleGrid {
    /// Parameters along u.
    pub u: Vec<f64>,
    /// Parameters along v.
    pub v: Vec<f64>,
}

impl SampleGrid {
    /// The documented default grid of a surface (see the module docs).
    pub fn for_surface(s: &BSplineSurface) -> SampleGrid {
        SampleGrid::with_density(s, SAMPLES_PER_SPAN)
    }

    /// `per_span · spans + 1` uniform parameters per direction (at least [`MIN_SAMPLES`]).
    pub fn with_density(s: &BSplineSurface, per_span: usize) -> SampleGrid {
        let (du, dv) = s.domain();
        let (su, sv) = s.spans();
        let n = |spans: usize| (per_span.max(1) * spans + 1).max(MIN_SAMPLES);
        SampleGrid {
            u: uniform_samples(du, n(su)),
            v: uniform_samples(dv, n(sv)),
        }
    }

    /// Sample count `n_u · n_v`.
    pub fn len(&self) -> usize {
        self.u.len() * self.v.len()
    }

    /// Whether the grid is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The curvature at every grid sample, row by row (u outer); `None` at singular points.
pub fn sample_curvature(s: &BSplineSurface, grid: &SampleGrid) -> Vec<Option<SurfaceCurvature>> {
    let bv: Vec<_> = grid.v.iter().map(|&v| s.basis_v(v)).collect();
    let mut out = Vec::with_capacity(grid.len());
    for &u in &grid.u {
        let bu = s.basis_u(u);
        for b in &bv {
            let d = super::patch::rational_derivs(&s.homogeneous(&bu, b, 2));
            out.push(super::patch::curvature_of(&d));
        }
    }
    out
}

/// `{min, max}` of a sampled quantity.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MinMax {
    /// The smallest value.
    pub min: f64,
    /// The largest value.
    pub max: f64,
}

impl MinMax {
    fn of(values: impl Iterator<Item = f64>) -> Option<MinMax> {
        values.fold(None, |acc, x| match acc {
            None => Some(MinMax { min: x, max: x }),
            Some(m) => Some(MinMax {
                min: m.min.min(x),
                max: m.max.max(x),
            }),
        })
    }
}

/// What `batten analyze-surface` reports about a surface, measured on
/// [`SampleGrid::for_surface`].
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct SurfaceAnalysis {
    /// Degree in u.
    pub degree_u: usize,
    /// Degree in v.
    pub degree_v: usize,
    /// Control-point counts `[n_u, n_v]`.
    pub control_points: [usize; 2],
    /// The grid size `[n_u, n_v]` the numbers were measured on.
    pub samples: [usize; 2],
    /// Samples where the surface is singular (`S_u × S_v = 0`), left out of everything.
    pub singular_samples: usize,
    /// Range of κ1 (`null` when every sample is singular).
    pub kappa1: Option<MinMax>,
    /// Range of κ2.
    pub kappa2: Option<MinMax>,
    /// Range of the Gaussian curvature K.
    pub gaussian: Option<MinMax>,
    /// Range of the mean curvature H.
    pub mean: Option<MinMax>,
    /// Fraction of the regular samples that are umbilics ([`UMBILIC_REL`]).
    pub umbilic_fraction: f64,
    /// Salvi & Várady's Π̂ (eq 15): `Σ (κ1 − g1)² + (κ2 − g2)²` over the regular samples,
    /// with the default targets g1, g2 ([`super::Targets`]) — how far the principal
    /// curvatures are from smooth versions of themselves. 0 for a sphere or a plane; the
    /// `salvi` fairing lowers it.
    pub fairness_measure: f64,
}

/// Measure a surface on its default grid with the default targets.
pub fn analyze_surface(s: &BSplineSurface) -> SurfaceAnalysis {
    let grid = SampleGrid::for_surface(s);
    let curv = sample_curvature(s, &grid);
    let targets = Targets::fit(s, &grid, &curv, &TargetParams::DEFAULT);
    summarize(s, &grid, &curv, &targets)
}

/// The summary of sampled curvature with given targets.
pub(crate) fn summarize(
    s: &BSplineSurface,
    grid: &SampleGrid,
    curv: &[Option<SurfaceCurvature>],
    targets: &Targets,
) -> SurfaceAnalysis {
    let ok: Vec<&SurfaceCurvature> = curv.iter().flatten().collect();
    let floor = 1.0 / s.control_diagonal().max(f64::MIN_POSITIVE);
    let umbilics = ok
        .iter()
        .filter(|c| {
            c.kappa1 - c.kappa2 <= UMBILIC_REL * c.kappa1.abs().max(c.kappa2.abs()).max(floor)
        })
        .count();
    let (du, dv) = s.degree();
    let (nu, nv) = s.size();
    SurfaceAnalysis {
        degree_u: du,
        degree_v: dv,
        control_points: [nu, nv],
        samples: [grid.u.len(), grid.v.len()],
        singular_samples: curv.len() - ok.len(),
        kappa1: MinMax::of(ok.iter().map(|c| c.kappa1)),
        kappa2: MinMax::of(ok.iter().map(|c| c.kappa2)),
        gaussian: MinMax::of(ok.iter().map(|c| c.gaussian)),
        mean: MinMax::of(ok.iter().map(|c| c.mean)),
        umbilic_fraction: if ok.is_empty() {
            0.0
        } else {
            umbilics as f64 / ok.len() as f64
        },
        fairness_measure: targets.measure(curv),
    }
}
