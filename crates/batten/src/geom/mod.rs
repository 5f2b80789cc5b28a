//! Geometry primitives: [`Point`], [`Vec2`], [`BBox`], [`Rigid`] motions, the validated
//! point sequence [`PointSeq`] every fairing method takes, and its space-curve counterpart
//! [`SpaceSeq`] of 3-D points ([`Xyz`]), and [`EndFix`], what to keep at the ends of an open
//! curve.
//!
//! A point is a location and a vector is a displacement (as in kurbo): `Point - Point` is a
//! [`Vec2`], `Point + Vec2` is a [`Point`], and points cannot be added to each other.

mod ends;
mod point;
mod scale;
mod seq;
mod space;
mod transform;

pub use ends::EndFix;
pub use point::{BBox, Point, Vec2, max_abs_coordinate};
pub use scale::{pow2, scale_points, unit_scale, unit_scale_xyz};
pub(crate) use seq::next_index;
pub use seq::{NEAR_DUPLICATE_REL, PointSeq};
pub use space::{SpaceSeq, Xyz};
#[allow(unused_imports)]
pub(crate) use space::{norm as norm3, sub as sub3};
pub use transform::Rigid;
