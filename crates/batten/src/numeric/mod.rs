//! Numerical building blocks, hand-written for the sizes fairing needs: O(n) banded solves,
//! Gauss–Legendre quadrature, bracketing 1-D minimisers.

mod band_inverse;
mod band_lu;
mod banded;
mod banded_split;
mod bracket;
mod cyclic_banded;
mod minimize;
mod nelder_mead;
mod norm;
mod parallel;
mod quadrature;
mod tridiagonal;

use std::ops::{Add, Mul, Sub};

pub use band_inverse::factorize_with_inverse_band;
pub use band_lu::BandLu;
pub(crate) use banded::BandRows;
pub use banded::SymBanded;
pub(crate) use bracket::Bracket;
#[cfg(test)]
pub(crate) use bracket::SLACK as BRACKET_SLACK;
pub use cyclic_banded::CyclicSymBanded;
pub use minimize::{Minimum, minimize_brent, minimize_golden};
pub use nelder_mead::{NelderMeadParams, SimplexMinimum, minimize_nelder_mead};
pub(crate) use norm::norm;
pub(crate) use parallel::{
    PARALLEL_FROM, beside_in_background, map_indices, map_pieces, max_indices,
};
pub use quadrature::GaussLegendre;
pub use tridiagonal::{solve_cyclic_tridiagonal, solve_tridiagonal};

use crate::geom::Vec2;

/// Values a linear solver can carry on its right-hand side: scalars and plane vectors, so that
/// one factorisation solves for x and y together.
pub trait Linear:
    Copy + Default + Send + Sync + Add<Output = Self> + Sub<Output = Self> + Mul<f64, Output = Self>
{
}

impl Linear for f64 {}
impl Linear for Vec2 {}

/// Relative size below which a pivot counts as zero in the banded solvers.
pub const PIVOT_REL: f64 = 1e-14;
