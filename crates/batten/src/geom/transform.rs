use serde::{Deserialize, Serialize};

use super::{Point, Vec2};

/// A rigid motion of the plane: a rotation by `angle` about the origin followed by a
/// translation. Curvature, arc length and every fairness measure are invariant under it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Rigid {
    cos: f64,
    sin: f64,
    translation: Vec2,
}

impl Rigid {
    /// The identity motion.
    pub const IDENTITY: Rigid = Rigid {
        cos: 1.0,
        sin: 0.0,
        translation: Vec2::ZERO,
    };

    /// Rotation by `angle` radians (counter-clockwise) about the origin, then translation.
    pub fn new(angle: f64, translation: Vec2) -> Rigid {
        let (sin, cos) = angle.sin_cos();
        Rigid {
            cos,
            sin,
            translation,
        }
    }

    /// Pure rotation about the origin.
    pub fn rotation(angle: f64) -> Rigid {
        Rigid::new(angle, Vec2::ZERO)
    }

    /// Pure translation.
    pub fn translation(v: Vec2) -> Rigid {
        Rigid {
            translation: v,
            ..Rigid::IDENTITY
        }
    }

    /// The motion that maps `origin` to (0, 0) and the direction `x_axis` (an angle in radians)
    /// to the positive x axis: the change into a local frame.
    pub fn to_local_frame(origin: Point, x_axis: f64) -> Rigid {
        let rot = Rigid::rotation(-x_axis);
        let t = rot.apply_vec(-origin.to_vec2());
        Rigid {
            translation: t,
            ..rot
        }
    }

    /// The rotation angle in radians.
    pub fn angle(&self) -> f64 {
        self.sin.atan2(self.cos)
    }

    /// Apply to a point (rotate, then translate).
    #[inline]
    pub fn apply(&self, p: Point) -> Point {
        Point::new(
            self.cos * p.x - self.sin * p.y + self.translation.x,
            self.sin * p.x + self.cos * p.y + self.translation.y,
        )
    }

    /// Apply to a vector (rotation only: vectors do not translate).
    #[inline]
    pub fn apply_vec(&self, v: Vec2) -> Vec2 {
        Vec2::new(
            self.cos * v.x - self.sin * v.y,
            self.sin * v.x + self.cos * v.y,
        )
    }

    /// The inverse motion.
    pub fn inverse(&self) -> Rigid {
        let r = Rigid {
            cos: self.cos,
            sin: -self.sin,
            translation: Vec2::ZERO,
        };
        let t = -r.apply_vec(self.translation);
        Rigid {
            translation: t,
            ..r
        }
    }

    /// `self` after `first`: the motion `p ↦ self(first(p))`.
    pub fn then_after(&self, first: &Rigid) -> Rigid {
        let cos = self.cos * first.cos - self.sin * first.sin;
        let sin = self.sin * first.cos + self.cos * first.sin;
        let translation = self.apply_vec(first.translation) + self.translation;
        Rigid {
            cos,
            sin,
            translation,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_round_trips() {
        let m = Rigid::new(0.7, Vec2::new(3.0, -2.0));
        let p = Point::new(1.5, -4.0);
        let q = m.inverse().apply(m.apply(p));
        assert!((q - p).length() < 1e-14);
        let v = Vec2::new(0.3, 0.4);
        assert!((m.apply_vec(v).length() - 0.5).abs() < 1e-15);
    }

    #[test]
    fn local_frame_maps_origin_and_axis() {
        let origin = Point::new(2.0, 1.0);
        let f = Rigid::to_local_frame(origin, std::f64::consts::FRAC_PI_2);
        assert!((f.apply(origin) - Point::ORIGIN).length() < 1e-15);
        let q = f.apply(Point::new(2.0, 3.0));
        assert!((q - Point::new(2.0, 0.0)).length() < 1e-14);
    }

    #[test]
    fn composition() {
        let a = Rigid::new(0.3, Vec2::new(1.0, 0.0));
        let b = Rigid::new(-1.1, Vec2::new(0.0, 2.0));
        let p = Point::new(0.5, 0.25);
        let ab = a.then_after(&b);
        assert!((ab.apply(p) - a.apply(b.apply(p))).length() < 1e-14);
    }
}
