use glam::Vec3;

/// Axis-aligned bounding box. `EMPTY` is the identity of [`Bounds3::union`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds3 {
    pub min: Vec3,
    pub max: Vec3,
}

impl Bounds3 {
    pub const EMPTY: Bounds3 = Bounds3 {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    pub fn union_point(self, p: Vec3) -> Bounds3 {
        Bounds3 {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    pub fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// Point at fractional coordinates `t` in `[0,1]^3` (for sampling inside the box).
    pub fn lerp(&self, t: Vec3) -> Vec3 {
        self.min + t * (self.max - self.min)
    }
}
