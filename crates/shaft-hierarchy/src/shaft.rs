//! One shaft (Haines and Wallace 1994): the region of line space between two boxes, as their
//! joint box cut by the planes that join them. It is exactly the convex hull of the two boxes,
//! so it holds every segment from a point of one to a point of the other.

use glam::Vec3;

use crate::Aabb;

/// A half-space `normal · x <= offset`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Outward unit normal; one component is zero (the plane holds an edge direction).
    pub normal: Vec3,
    /// Offset along the normal, rounded outward so that rounding never cuts a box's corner.
    pub offset: f32,
}

/// How a box meets a shaft.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Overlap {
    /// No point in common: no segment between the shaft's boxes can touch the box.
    Outside,
    /// Possibly in common (conservative: a box near a shaft's edge may be reported here).
    Partial,
    /// Wholly inside the shaft.
    Inside,
}

/// The convex hull of two boxes: their joint box and 0 to 8 joining planes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shaft {
    /// The joint box of the two boxes.
    pub extent: Aabb,
    planes: [Plane; 8],
    count: u8,
}

/// An edge of the joint box whose two faces come from different boxes: its two axes (i, j),
/// the matching edge of `a` and of `b`, and the joint box's corner, all in (i, j).
type JoiningEdge = (usize, usize, [f32; 2], [f32; 2], [f32; 2]);

/// Which box defines each face of the joint box of `a` and `b`, per axis, for the min and the
/// max faces: +1 `a`, -1 `b`, 0 both.
#[inline]
fn face_owners(a: &Aabb, b: &Aabb) -> ([i8; 3], [i8; 3]) {
    let owner = |x: f32, y: f32, max: bool| -> i8 {
        if x == y {
            0
        } else if (x > y) == max {
            1
        } else {
            -1
        }
    };
    let (mut lo, mut hi) = ([0i8; 3], [0i8; 3]);
    for k in 0..3 {
        lo[k] = owner(a.min[k], b.min[k], false);
        hi[k] = owner(a.max[k], b.max[k], true);
    }
    (lo, hi)
}

/// The 12 edges of a joint box: axis pairs and corners (max on axis i, max on axis j).
const EDGES: [(usize, usize, bool, bool); 12] = {
    let mut e = [(0, 0, false, false); 12];
    let pairs = [(0, 1), (1, 2), (2, 0)];
    let mut k = 0;
    while k < 12 {
        e[k] = (pairs[k / 4].0, pairs[k / 4].1, k & 2 != 0, k & 1 != 0);
        k += 1;
    }
    e
};

/// The joining edges of `a` and `b` (at most 8 of the 12).
fn joining_edges(a: &Aabb, b: &Aabb) -> Vec<JoiningEdge> {
    let extent = a.union(b);
    let (lo, hi) = face_owners(a, b);
    let pick = |bx: &Aabb, k: usize, max: bool| if max { bx.max[k] } else { bx.min[k] };
    EDGES
        .iter()
        .filter(|&&(i, j, max_i, max_j)| {
            let (oi, oj) = (if max_i { hi[i] } else { lo[i] }, if max_j { hi[j] } else { lo[j] });
            oi != 0 && oj != 0 && oi != oj
        })
        .map(|&(i, j, max_i, max_j)| {
            (
                i,
                j,
                [pick(a, i, max_i), pick(a, j, max_j)],
                [pick(b, i, max_i), pick(b, j, max_j)],
                [pick(&extent, i, max_i), pick(&extent, j, max_j)],
            )
        })
        .collect()
}

/// How an object's box meets a shaft, as [`meets`] answers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Meet {
    /// No point in common.
    Outside,
    /// Possibly in common.
    Partial,
    /// The object's box holds the whole shaft (and so every shaft inside it).
    Covers,
}

/// How `object` meets the shaft between `a` and `b`, without building it: the joint box first,
/// then each joining plane as it is found, stopping at the first that rejects. Conservative as
/// [`Shaft::classify`]; what traversal uses, as it stores no planes.
#[must_use]
pub fn meets(a: &Aabb, b: &Aabb, object: &Aabb) -> Meet {
    let extent = a.union(b);
    if !extent.overlaps(object) {
        return Meet::Outside;
    }
    if object.contains(&extent) {
        return Meet::Covers;
    }
    // the planes written out here, not through `joining_edges`: traversal's hot path, and a
    // hand-written iterator over the edges measured 28 % slower per frame (ar_room, no pruning)
    let (lo, hi) = face_owners(a, b);
    for &(i, j, max_i, max_j) in &EDGES {
        let oi = if max_i { hi[i] } else { lo[i] };
        let oj = if max_j { hi[j] } else { lo[j] };
        if oi == 0 || oj == 0 || oi == oj {
            continue;
        }
        let pick = |bx: &Aabb, k: usize, max: bool| if max { bx.max[k] } else { bx.min[k] };
        let pa = [pick(a, i, max_i), pick(a, j, max_j)];
        let pb = [pick(b, i, max_i), pick(b, j, max_j)];
        let corner = [pick(&extent, i, max_i), pick(&extent, j, max_j)];
        let mut n = [pb[1] - pa[1], pa[0] - pb[0]];
        if n[0] * (corner[0] - pa[0]) + n[1] * (corner[1] - pa[1]) < 0.0 {
            n = [-n[0], -n[1]];
        }
        let near = [
            if n[0] > 0.0 { object.min[i] } else { object.max[i] },
            if n[1] > 0.0 { object.min[j] } else { object.max[j] },
        ];
        let offset = (n[0] * pa[0] + n[1] * pa[1]).max(n[0] * pb[0] + n[1] * pb[1]);
        // f32 rounding of every product here: outward by more than it can be
        let scale = n[0].abs() * pa[0].abs().max(pb[0].abs()).max(near[0].abs())
            + n[1].abs() * pa[1].abs().max(pb[1].abs()).max(near[1].abs());
        if n[0] * near[0] + n[1] * near[1] > offset + 16.0 * f32::EPSILON * scale {
            return Meet::Outside;
        }
    }
    Meet::Partial
}

impl Shaft {
    /// The shaft between `a` and `b` (either may be flat; both must be non-empty).
    ///
    /// For each edge of the joint box whose two faces come from different boxes, one plane
    /// through the matching edges of `a` and `b`; equal coordinates and nested boxes give
    /// fewer planes (none when one box holds the other).
    #[must_use]
    pub fn new(a: &Aabb, b: &Aabb) -> Self {
        let extent = a.union(b);
        let mut shaft = Self { extent, planes: [Plane { normal: Vec3::ZERO, offset: 0.0 }; 8], count: 0 };
        for (i, j, pa, pb, corner) in joining_edges(a, b) {
            let (pa, pb, corner) = (pa.map(f64::from), pb.map(f64::from), corner.map(f64::from));
            let d = [pb[0] - pa[0], pb[1] - pa[1]];
            let mut n = [d[1], -d[0]];
            // outward: towards the joint box's corner, which the plane cuts off
            if n[0] * (corner[0] - pa[0]) + n[1] * (corner[1] - pa[1]) < 0.0 {
                n = [-n[0], -n[1]];
            }
            let len = n[0].hypot(n[1]);
            let n = [n[0] / len, n[1] / len];
            let offset = (n[0] * pa[0] + n[1] * pa[1]).max(n[0] * pb[0] + n[1] * pb[1]);
            // f32 evaluation of n·x errs by a few ulps of |n_i x_i|: round outward by more
            let scale =
                (n[0] * pa[0]).abs().max((n[1] * pa[1]).abs()).max((n[0] * pb[0]).abs()).max((n[1] * pb[1]).abs());
            let offset = offset + scale * 8.0 * f64::from(f32::EPSILON);
            let mut normal = Vec3::ZERO;
            normal[i] = n[0] as f32;
            normal[j] = n[1] as f32;
            shaft.planes[usize::from(shaft.count)] = Plane { normal, offset: offset as f32 };
            shaft.count += 1;
        }
        shaft
    }

    /// The joining planes (0 to 8).
    #[must_use]
    pub fn planes(&self) -> &[Plane] {
        &self.planes[..usize::from(self.count)]
    }

    /// True when `p` lies in the shaft (closed).
    #[must_use]
    pub fn contains_point(&self, p: Vec3) -> bool {
        self.extent.contains_point(p) && self.planes().iter().all(|pl| pl.normal.dot(p) <= pl.offset)
    }

    /// How `c` meets the shaft. Never `Outside` for a box that shares a point with it; the
    /// test has no cross-product axes, so some boxes near an edge are `Partial` though outside.
    #[must_use]
    pub fn classify(&self, c: &Aabb) -> Overlap {
        if !self.extent.overlaps(c) {
            return Overlap::Outside;
        }
        let mut inside = self.extent.contains(c);
        for pl in self.planes() {
            // the box's corner furthest inside, and furthest outside, along the normal
            let lo = pl.normal.cmpgt(Vec3::ZERO);
            let near = Vec3::select(lo, c.min, c.max);
            if pl.normal.dot(near) > pl.offset {
                return Overlap::Outside;
            }
            let far = Vec3::select(lo, c.max, c.min);
            inside &= pl.normal.dot(far) <= pl.offset;
        }
        if inside { Overlap::Inside } else { Overlap::Partial }
    }
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    use super::*;

    /// Random boxes that often share coordinates, are flat, or nest, at scale `s`.
    fn random_box(rng: &mut Pcg64, s: f32) -> Aabb {
        let mut v = || {
            let x: f32 = rng.random_range(-4..=4) as f32 * 0.25;
            if rng.random_bool(0.5) { x + rng.random_range(-0.3..0.3) } else { x }
        };
        Aabb::new(Vec3::new(v(), v(), v()) * s, Vec3::new(v(), v(), v()) * s)
    }

    /// conv(A ∪ B) = {λa + (1-λ)b}: p is in it iff some λ in [0, 1] puts p, on every axis,
    /// between λA.min + (1-λ)B.min and λA.max + (1-λ)B.max: an interval of λ per inequality.
    fn hull_contains(a: &Aabb, b: &Aabb, p: Vec3, tol: f64) -> bool {
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for i in 0..3 {
            // λ (a_lo - b_lo) <= p - b_lo + tol  and  λ (a_hi - b_hi) >= p - b_hi - tol
            for (coef, rhs, le) in [
                (f64::from(a.min[i] - b.min[i]), f64::from(p[i] - b.min[i]) + tol, true),
                (f64::from(a.max[i] - b.max[i]), f64::from(p[i] - b.max[i]) - tol, false),
            ] {
                if coef == 0.0 {
                    if (le && rhs < 0.0) || (!le && rhs > 0.0) {
                        return false;
                    }
                } else {
                    let t = rhs / coef;
                    // coef·λ <= rhs: λ <= t (coef > 0) or λ >= t (coef < 0); >= flips it
                    if (coef > 0.0) == le {
                        hi = hi.min(t);
                    } else {
                        lo = lo.max(t);
                    }
                }
            }
        }
        lo <= hi
    }

    #[test]
    fn every_corner_of_both_boxes_satisfies_every_plane() {
        let mut rng = Pcg64::seed_from_u64(1);
        for s in [1e-3, 1.0, 1e3, 1e6] {
            for _ in 0..5_000 {
                let (a, b) = (random_box(&mut rng, s), random_box(&mut rng, s));
                let shaft = Shaft::new(&a, &b);
                assert!(shaft.planes().len() <= 8);
                for k in 0..8 {
                    for c in [a.corner(k), b.corner(k)] {
                        assert!(shaft.contains_point(c), "{a:?} {b:?}: corner {c} outside");
                    }
                }
                for pl in shaft.planes() {
                    assert_eq!(pl.normal.to_array().iter().filter(|&&x| x == 0.0).count(), 1, "{pl:?}");
                    assert!((pl.normal.length() - 1.0).abs() < 1e-6);
                    // the plane touches both boxes (to its outward rounding)
                    let slack =
                        |bx: &Aabb| (0..8).map(|k| pl.offset - pl.normal.dot(bx.corner(k))).fold(f32::MAX, f32::min);
                    let tol = 1e-5 * s;
                    assert!(slack(&a) <= tol && slack(&b) <= tol, "{a:?} {b:?} {pl:?}: {} {}", slack(&a), slack(&b));
                }
            }
        }
    }

    #[test]
    fn nested_equal_and_aligned_boxes_give_fewer_planes() {
        let a = Aabb::new(Vec3::ZERO, Vec3::ONE);
        assert!(Shaft::new(&a, &a).planes().is_empty());
        let inner = Aabb::new(Vec3::splat(0.25), Vec3::splat(0.5));
        assert!(Shaft::new(&a, &inner).planes().is_empty());
        assert!(Shaft::new(&inner, &a).planes().is_empty());
        // two unit boxes side by side along x: the joint box is their hull
        let b = Aabb::new(Vec3::X * 2.0, Vec3::new(3.0, 1.0, 1.0));
        assert!(Shaft::new(&a, &b).planes().is_empty());
        // shifted diagonally in x and y: 2 planes (the two x-y edges cut off), none along z
        let c = Aabb::new(Vec3::new(2.0, 2.0, 0.0), Vec3::new(3.0, 3.0, 1.0));
        assert_eq!(Shaft::new(&a, &c).planes().len(), 2);
        // in general position: 6 planes
        let d = Aabb::new(Vec3::splat(2.0), Vec3::splat(3.5));
        assert_eq!(Shaft::new(&a, &d).planes().len(), 6);
    }

    /// The shaft is the hull of its boxes: membership agrees with an independent test of
    /// conv(A ∪ B) away from the boundary.
    #[test]
    fn shaft_is_exactly_the_convex_hull() {
        let mut rng = Pcg64::seed_from_u64(2);
        let mut checked = 0;
        for _ in 0..2_000 {
            let (a, b) = (random_box(&mut rng, 1.0), random_box(&mut rng, 1.0));
            let shaft = Shaft::new(&a, &b);
            let e = shaft.extent;
            for _ in 0..200 {
                let p = Vec3::new(
                    rng.random_range(e.min.x..=e.max.x),
                    rng.random_range(e.min.y..=e.max.y),
                    rng.random_range(e.min.z..=e.max.z),
                );
                let (wide, narrow) = (hull_contains(&a, &b, p, 1e-4), hull_contains(&a, &b, p, -1e-4));
                if wide == narrow {
                    assert_eq!(shaft.contains_point(p), wide, "{a:?} {b:?} at {p}");
                    checked += 1;
                }
            }
        }
        assert!(checked > 300_000, "{checked}");
    }

    /// `Outside` is never wrong: no segment from a point of A to a point of B meets a box the
    /// shaft rejects (random segments, and all 64 corner pairs), and `Inside` boxes lie in the
    /// hull.
    /// The lazy test agrees with the built shaft: never `Outside` for a box a segment meets,
    /// `Covers` only for boxes holding the joint box, and the same verdict nearly always.
    #[test]
    fn meets_agrees_with_classify() {
        let mut rng = Pcg64::seed_from_u64(4);
        let mut differ = 0;
        for _ in 0..20_000 {
            let (a, b, c) = (random_box(&mut rng, 1.0), random_box(&mut rng, 1.0), random_box(&mut rng, 1.0));
            let fast = meets(&a, &b, &c);
            let slow = Shaft::new(&a, &b).classify(&c);
            if fast == Meet::Covers {
                assert!(c.contains(&a.union(&b)));
            }
            if (fast == Meet::Outside) != (slow == Overlap::Outside) {
                differ += 1;
            }
            if fast == Meet::Outside {
                for k in 0..64 {
                    assert!(!c.segment_hits(a.corner(k % 8), b.corner(k / 8)), "{a:?} {b:?} {c:?}");
                }
            }
        }
        assert!(differ < 20, "{differ} verdicts differ");
    }

    #[test]
    fn classify_is_conservative() {
        let mut rng = Pcg64::seed_from_u64(3);
        let (mut outside, mut partial_missed) = (0, 0);
        for _ in 0..3_000 {
            let (a, b) = (random_box(&mut rng, 1.0), random_box(&mut rng, 1.0));
            let shaft = Shaft::new(&a, &b);
            let c = random_box(&mut rng, 1.0);
            let point = |rng: &mut Pcg64, bx: &Aabb| {
                Vec3::new(
                    rng.random_range(bx.min.x..=bx.max.x),
                    rng.random_range(bx.min.y..=bx.max.y),
                    rng.random_range(bx.min.z..=bx.max.z),
                )
            };
            let mut segments: Vec<(Vec3, Vec3)> = (0..64).map(|k| (a.corner(k % 8), b.corner(k / 8))).collect();
            segments.extend((0..400).map(|_| (point(&mut rng, &a), point(&mut rng, &b))));
            let hit = segments.iter().any(|&(p, q)| c.segment_hits(p, q));
            match shaft.classify(&c) {
                Overlap::Outside => {
                    outside += 1;
                    assert!(!hit, "{a:?} {b:?}: rejected {c:?}, which a segment meets");
                }
                Overlap::Inside => {
                    for k in 0..8 {
                        assert!(hull_contains(&a, &b, c.corner(k), 1e-4), "{c:?} called inside");
                    }
                }
                Overlap::Partial => partial_missed += usize::from(!hit),
            }
        }
        assert!(outside > 300, "the test rejected only {outside} boxes");
        // false positives are allowed, but not most of them
        assert!(partial_missed < 3_000 - outside, "{partial_missed}");
    }
}
