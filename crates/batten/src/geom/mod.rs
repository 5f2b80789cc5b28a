//! Planar geometry primitives: [`Point`], [`Vec2`], [`BBox`], [`Rigid`] motions and the
//! validated point sequence [`PointSeq`] every fairing method takes.
//!
//! A point is a location and a vector is a displacement (as in kurbo): `Point - Point` is a
//! [`Vec2`], `Point + Vec2` is a [`Point`], and points cannot be added to each other.

mod point;
mod scale;
mod seq;
mod transform;

pub use point::{BBox, Point, Vec2, max_abs_coordinate};
pub use scale::{pow2, scale_points, unit_scale};
pub use seq::{NEAR_DUPLICATE_REL, PointSeq};
pub use transform::Rigid;
