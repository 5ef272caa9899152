//! Axis-aligned boxes: what shafts join and what objects are bounded by.

use glam::Vec3;

/// A closed axis-aligned box. Flat boxes (`min == max` on an axis) are valid; `EMPTY` is the
/// identity of [`Aabb::union`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

impl Aabb {
    /// Contains nothing; the union of nothing.
    pub const EMPTY: Self = Self { min: Vec3::INFINITY, max: Vec3::NEG_INFINITY };

    /// The box with these corners, in any order.
    #[must_use]
    pub fn new(a: Vec3, b: Vec3) -> Self {
        Self { min: a.min(b), max: a.max(b) }
    }

    /// The smallest box holding every point.
    #[must_use]
    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Self {
        points.into_iter().fold(Self::EMPTY, |b, p| Self { min: b.min.min(p), max: b.max.max(p) })
    }

    /// True when the box holds no point.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    /// The smallest box holding both.
    #[must_use]
    pub fn union(&self, other: &Self) -> Self {
        Self { min: self.min.min(other.min), max: self.max.max(other.max) }
    }

    /// Centre.
    #[must_use]
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Edge lengths.
    #[must_use]
    pub fn size(&self) -> Vec3 {
        self.max - self.min
    }

    /// Corner `i` (bit 0: x, bit 1: y, bit 2: z; a set bit takes `max`).
    #[must_use]
    pub fn corner(&self, i: usize) -> Vec3 {
        Vec3::new(
            if i & 1 == 0 { self.min.x } else { self.max.x },
            if i & 2 == 0 { self.min.y } else { self.max.y },
            if i & 4 == 0 { self.min.z } else { self.max.z },
        )
    }

    /// True when the closed boxes share a point.
    #[must_use]
    pub fn overlaps(&self, other: &Self) -> bool {
        self.min.cmple(other.max).all() && other.min.cmple(self.max).all()
    }

    /// True when `other` lies inside this box (closed).
    #[must_use]
    pub fn contains(&self, other: &Self) -> bool {
        self.min.cmple(other.min).all() && other.max.cmple(self.max).all()
    }

    /// True when `p` lies inside (closed).
    #[must_use]
    pub fn contains_point(&self, p: Vec3) -> bool {
        self.min.cmple(p).all() && p.cmple(self.max).all()
    }

    /// True when the closed segment from `a` to `b` meets the closed box: the slab test, exact
    /// for axis-parallel segments and segments in a face's plane.
    #[must_use]
    pub fn segment_hits(&self, a: Vec3, b: Vec3) -> bool {
        let d = b - a;
        let (mut t0, mut t1) = (0.0f32, 1.0f32);
        for i in 0..3 {
            if d[i] == 0.0 {
                if a[i] < self.min[i] || a[i] > self.max[i] {
                    return false;
                }
            } else {
                let (u, v) = ((self.min[i] - a[i]) / d[i], (self.max[i] - a[i]) / d[i]);
                t0 = t0.max(u.min(v));
                t1 = t1.min(u.max(v));
                if t0 > t1 {
                    return false;
                }
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn union_of_nothing_is_empty_and_the_identity() {
        let b = Aabb::new(Vec3::ONE, Vec3::ZERO);
        assert!(Aabb::EMPTY.is_empty() && !b.is_empty());
        assert_eq!(Aabb::EMPTY.union(&b), b);
        assert_eq!(Aabb::from_points([]), Aabb::EMPTY);
    }

    #[test]
    fn segment_hits_agrees_with_dense_sampling() {
        let b = Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(1.0, 0.5, 3.0));
        let cases = [
            (Vec3::new(-3.0, 0.25, 2.5), Vec3::new(3.0, 0.25, 2.5), true),
            (Vec3::new(-3.0, 0.6, 2.5), Vec3::new(3.0, 0.6, 2.5), false),
            // ends on the face
            (Vec3::new(-3.0, 0.25, 2.5), Vec3::new(-1.0, 0.25, 2.5), true),
            // stops short
            (Vec3::new(-3.0, 0.25, 2.5), Vec3::new(-1.01, 0.25, 2.5), false),
            // diagonal passing a corner's outside
            (Vec3::new(-3.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 5.0), false),
            (Vec3::new(0.0, 0.25, 0.0), Vec3::new(0.0, 0.25, 10.0), true),
        ];
        for (a, c, hit) in cases {
            assert_eq!(b.segment_hits(a, c), hit, "{a} -> {c}");
            let sampled = (0..=100_000).any(|k| b.contains_point(a.lerp(c, k as f32 / 100_000.0)));
            assert_eq!(sampled, hit, "{a} -> {c}: sampling");
        }
    }
}
