//! The shaft hierarchy against brute force: random rooms, objects and segments.

use glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use shaft_hierarchy::{
    Aabb, BuildError, Kind, Occlusion, Receiver, Settings, ShaftHierarchy, SourceShape, Transfers, Traversal,
    cone_direction_bounds,
};
use trade::shafts::covered_pairs;

/// A distant source for sampling: its cone.
#[derive(Clone, Copy)]
struct Cone {
    axis: Vec3,
    half_angle: f32,
}

struct Room {
    sources: Vec<SourceShape>,
    cones: Vec<Option<Cone>>,
    receivers: Vec<Receiver>,
    transfers: Transfers,
}

/// A 4 x 3 x 4 room: ceiling lamps and wall patches as local sources, a few distant cones
/// through the open side, floor and wall patches (4 vertices each) as receivers. Transfers fall
/// off with distance, some are zero (back-facing), totals hold a little more than the sources.
fn room(rng: &mut Pcg64, locals: usize, distant: usize, tiles: usize) -> Room {
    let mut sources = Vec::new();
    let mut cones = Vec::new();
    for _ in 0..locals {
        let c = Vec3::new(rng.random_range(0.2..3.8), 3.0, rng.random_range(0.2..3.8));
        let h = Vec3::new(rng.random_range(0.05..0.3), 0.0, rng.random_range(0.05..0.3));
        sources.push(SourceShape::Local(Aabb::new(c - h, c + h)));
        cones.push(None);
    }
    for _ in 0..distant {
        let axis =
            Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(0.2..1.0), rng.random_range(0.3..1.0)).normalize();
        let half_angle = rng.random_range(0.001..0.4f32);
        sources.push(SourceShape::Distant(cone_direction_bounds(axis, half_angle)));
        cones.push(Some(Cone { axis, half_angle }));
    }
    let mut receivers = Vec::new();
    let step = 4.0 / tiles as f32;
    for a in 0..tiles {
        for b in 0..tiles {
            let (x, z) = (a as f32 * step, b as f32 * step);
            // floor, and the back wall (z = 0)
            receivers.push(Aabb::new(Vec3::new(x, 0.0, z), Vec3::new(x + step, 0.0, z + step)));
            let y = b as f32 * 3.0 / tiles as f32;
            receivers.push(Aabb::new(Vec3::new(x, y, 0.0), Vec3::new(x + step, y + 3.0 / tiles as f32, 0.0)));
        }
    }
    let receivers: Vec<Receiver> = receivers
        .into_iter()
        .enumerate()
        .map(|(k, bounds)| Receiver { bounds, slots: 4 * k as u32..4 * k as u32 + 4 })
        .collect();
    let slots = 4 * receivers.len();
    let mut values = vec![0.0f32; sources.len() * slots];
    for (j, s) in sources.iter().enumerate() {
        let power = rng.random_range(0.1..10.0f32);
        for r in &receivers {
            let d = match s {
                SourceShape::Local(b) => (b.center() - r.bounds.center()).length(),
                SourceShape::Distant(_) => 1.0,
            };
            for i in r.slots.clone() {
                values[j * slots + i as usize] =
                    if rng.random_bool(0.1) { 0.0 } else { power / (1.0 + d * d) * rng.random_range(0.5..1.0) };
            }
        }
    }
    let totals =
        (0..slots).map(|i| 1.1 * (0..sources.len()).map(|j| values[j * slots + i]).sum::<f32>() + 0.01).collect();
    Room { sources, cones, receivers, transfers: Transfers { slots, values, totals } }
}

fn point_in(rng: &mut Pcg64, b: &Aabb) -> Vec3 {
    Vec3::new(
        rng.random_range(b.min.x..=b.max.x),
        rng.random_range(b.min.y..=b.max.y),
        rng.random_range(b.min.z..=b.max.z),
    )
}

/// A unit direction uniformly within a cone.
fn direction_in(rng: &mut Pcg64, c: &Cone) -> Vec3 {
    let cos_max = c.half_angle.cos();
    let z = rng.random_range(cos_max..=1.0);
    let phi = rng.random_range(0.0..std::f32::consts::TAU);
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (t, b) = c.axis.any_orthonormal_pair();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + c.axis * z).normalize()
}

/// Random objects: small and large, inside, touching, around and outside the room, flat.
fn object(rng: &mut Pcg64) -> Aabb {
    match rng.random_range(0..6) {
        0 => {
            let c = point_in(rng, &Aabb::new(Vec3::ZERO, Vec3::new(4.0, 3.0, 4.0)));
            Aabb::new(c - Vec3::splat(0.2), c + Vec3::splat(0.2))
        }
        1 => {
            // resting on the floor
            let c = Vec3::new(rng.random_range(0.0..4.0), 0.0, rng.random_range(0.0..4.0));
            Aabb::new(c - Vec3::new(0.3, 0.0, 0.3), c + Vec3::new(0.3, 0.5, 0.3))
        }
        2 => Aabb::new(Vec3::splat(-1.0), Vec3::new(5.0, 4.0, 5.0)),
        3 => {
            // outside, towards the distant sources
            let c = Vec3::new(rng.random_range(-2.0..6.0), rng.random_range(3.0..8.0), rng.random_range(4.0..9.0));
            Aabb::new(c - Vec3::splat(0.5), c + Vec3::splat(0.5))
        }
        4 => {
            // flat
            let c = point_in(rng, &Aabb::new(Vec3::ZERO, Vec3::new(4.0, 3.0, 4.0)));
            Aabb::new(c - Vec3::new(0.5, 0.0, 0.5), c + Vec3::new(0.5, 0.0, 0.5))
        }
        _ => {
            let c = point_in(rng, &Aabb::new(Vec3::ZERO, Vec3::new(4.0, 3.0, 4.0)));
            let h = Vec3::new(rng.random_range(0.01..1.0), rng.random_range(0.01..1.0), rng.random_range(0.01..1.0));
            Aabb::new(c - h, c + h)
        }
    }
}

#[test]
fn hierarchy_validates() {
    let mut rng = Pcg64::seed_from_u64(7);
    for (locals, distant, tiles) in [(40, 4, 8), (1, 0, 1), (0, 3, 4), (100, 0, 12)] {
        let r = room(&mut rng, locals, distant, tiles);
        for fraction in [0.0, 0.02, 0.3] {
            let settings = Settings { prune_fraction: fraction, ..Settings::PAPER };
            let h = ShaftHierarchy::build(&r.sources, &r.receivers, &r.transfers, &settings).unwrap();
            h.validate().unwrap_or_else(|e| panic!("{locals}/{distant}/{tiles} at {fraction}: {e}"));
            assert!(h.source_tree.nodes.iter().filter(|n| n.is_leaf()).all(|n| n.count == 1));
            assert!(h.receiver_tree.nodes.iter().filter(|n| n.is_leaf()).all(|n| n.count <= 8));
        }
    }
}

#[test]
fn validate_catches_a_broken_hierarchy() {
    let mut rng = Pcg64::seed_from_u64(8);
    let r = room(&mut rng, 20, 2, 6);
    let h = ShaftHierarchy::build(&r.sources, &r.receivers, &r.transfers, &Settings::PAPER).unwrap();
    let inner = h.shafts.iter().position(|s| s.kind != Kind::Leaf && s.children > 1).unwrap();
    let mut broken = h.clone();
    broken.shafts[inner].children -= 1;
    assert!(broken.validate().is_err(), "a dropped child");
    let mut broken = h.clone();
    broken.shafts[inner].pruned ^= 1;
    assert!(broken.validate().is_err(), "a child marked pruned");
    let leaf = h.shafts.iter().position(|s| s.kind == Kind::Leaf).unwrap();
    let mut broken = h.clone();
    broken.shafts[leaf].kind = Kind::SplitSource;
    assert!(broken.validate().is_err(), "a leaf made a split");
    let mut broken = h.clone();
    broken.leaf_transfer[0] *= 2.0;
    assert!(broken.validate().is_err(), "a leaf's transfer");
    let mut broken = h.clone();
    broken.receiver_tree.order.swap(0, 1);
    broken.receiver_tree.order[0] = broken.receiver_tree.order[1];
    assert!(broken.validate().is_err(), "a receiver twice");
}

/// Paper 003's promise, checked by brute force: every segment from a source to a receiver that
/// meets the object lies in a shaft the traversal reported, or in a pruned one it reported.
#[test]
fn traversal_misses_no_occluded_segment() {
    let mut rng = Pcg64::seed_from_u64(9);
    let r = room(&mut rng, 60, 5, 8);
    let h = ShaftHierarchy::build(&r.sources, &r.receivers, &r.transfers, &Settings::PAPER).unwrap();
    h.validate().unwrap();
    let mut scratch = Traversal::default();
    let mut o = Occlusion::default();
    let (mut segments, mut hits, mut misses, mut in_pruned) = (0usize, 0usize, 0usize, 0usize);
    let mut reported = 0usize;
    for _ in 0..120 {
        let obj = object(&mut rng);
        h.traverse(&obj, &mut scratch, &mut o);
        let (leaf_pairs, pruned_pairs) = covered_pairs(&h, &o);
        reported += leaf_pairs.len();
        for _ in 0..1_000 {
            let j = rng.random_range(0..r.sources.len());
            let p = rng.random_range(0..r.receivers.len());
            let x = point_in(&mut rng, &r.receivers[p].bounds);
            let y = match (r.sources[j], r.cones[j]) {
                (SourceShape::Local(b), _) => point_in(&mut rng, &b),
                (SourceShape::Distant(_), Some(c)) => x + direction_in(&mut rng, &c) * h.reach(),
                (SourceShape::Distant(_), None) => unreachable!(),
            };
            segments += 1;
            if obj.segment_hits(x, y) {
                hits += 1;
                let pair = (j as u32, p as u32);
                if leaf_pairs.contains(&pair) {
                    continue;
                }
                if pruned_pairs.contains(&pair) {
                    in_pruned += 1;
                } else {
                    misses += 1;
                }
            }
        }
    }
    assert!(segments >= 100_000);
    assert!(hits > 5_000, "only {hits} segments met an object");
    assert_eq!(misses, 0, "{misses} of {hits} occluded segments in no reported shaft ({in_pruned} in pruned ones)");
    assert!(reported > 0);
}

#[test]
fn extremes_have_stated_results() {
    let mut rng = Pcg64::seed_from_u64(10);
    let r = room(&mut rng, 30, 3, 6);
    let h = ShaftHierarchy::build(&r.sources, &r.receivers, &r.transfers, &Settings::PAPER).unwrap();
    let mut scratch = Traversal::default();
    let mut o = Occlusion::default();
    // bigger than the room: every kept pair and every pruned one is reported
    h.traverse(&Aabb::new(Vec3::splat(-1e3), Vec3::splat(1e3)), &mut scratch, &mut o);
    assert_eq!(o.leaf_shafts.len(), h.leaf_shafts());
    assert_eq!(o.pruned.len(), h.pruned_pairs());
    assert_eq!(o.tested, 1, "a box around everything is decided at the root");
    // an empty box: nothing
    h.traverse(&Aabb::EMPTY, &mut scratch, &mut o);
    assert!(o.sources.is_empty() && o.leaf_shafts.is_empty());
    // far away on the other side of the floor: nothing
    h.traverse(&Aabb::new(Vec3::new(-50.0, -60.0, -50.0), Vec3::new(-40.0, -50.0, -40.0)), &mut scratch, &mut o);
    assert!(o.sources.is_empty(), "{:?}", o.sources);
    // inside a source's box: that source is reported (for some receiver it reaches)
    let (j, b) = r
        .sources
        .iter()
        .enumerate()
        .find_map(|(j, s)| match s {
            SourceShape::Local(b) => Some((j, *b)),
            SourceShape::Distant(_) => None,
        })
        .unwrap();
    let reaches = h.shafts.iter().any(|s| s.kind == Kind::Leaf && h.source_tree.items(s.source).contains(&(j as u32)));
    h.traverse(&Aabb::new(b.center(), b.center()), &mut scratch, &mut o);
    assert_eq!(o.sources.contains(&(j as u32)), reaches);
    // a flat box lying on the floor touches receivers there
    h.traverse(&Aabb::new(Vec3::new(1.0, 0.0, 1.0), Vec3::new(2.0, 0.0, 2.0)), &mut scratch, &mut o);
    assert!(!o.receivers.is_empty());
    // each once
    let mut s = o.sources.clone();
    s.sort_unstable();
    s.dedup();
    assert_eq!(s.len(), o.sources.len());
}

#[test]
fn representatives_account_for_every_occluded_source() {
    let mut rng = Pcg64::seed_from_u64(11);
    let r = room(&mut rng, 50, 4, 8);
    let h = ShaftHierarchy::build(&r.sources, &r.receivers, &r.transfers, &Settings::PAPER).unwrap();
    let mut scratch = Traversal::default();
    let mut o = Occlusion::default();
    let mut frames = 0;
    for _ in 0..60 {
        h.traverse(&object(&mut rng), &mut scratch, &mut o);
        if o.sources.is_empty() {
            continue;
        }
        frames += 1;
        // each source's transfer through the met leaf shafts, from the matrix
        let send = |j: u32| {
            o.leaf_shafts
                .iter()
                .map(|&k| h.shafts[k as usize])
                .filter(|n| h.source_tree.items(n.source).contains(&j))
                .flat_map(|n| {
                    h.receiver_tree.items(n.receiver).iter().flat_map(|&p| r.receivers[p as usize].slots.clone())
                })
                .map(|i| f64::from(r.transfers.row(j as usize)[i as usize]))
                .sum::<f64>()
        };
        let total: f64 = o.sources.iter().map(|&j| send(j)).sum();
        for n in [0, 1, 2, 5, o.sources.len(), o.sources.len() + 10] {
            let reps = h.representatives(&o, n);
            assert!(reps.len() <= n.max(1).min(o.sources.len()), "n {n}: {} nodes", reps.len());
            let got: f64 = reps.iter().map(|r| r.transfer).sum();
            assert!((got - total).abs() <= 1e-4 * total.max(1e-9), "n {n}: {got} of {total}");
            // disjoint, covering, and the origin is the strongest of each node's sources
            let mut stood_for: Vec<u32> = Vec::new();
            for rep in &reps {
                let mine: Vec<u32> =
                    h.source_tree.items(rep.node).iter().copied().filter(|j| o.sources.contains(j)).collect();
                assert_eq!(mine.len() as u32, rep.sources);
                let strongest = mine.iter().copied().max_by(|&a, &b| send(a).total_cmp(&send(b))).unwrap();
                assert!((send(rep.origin) - send(strongest)).abs() <= 1e-5 * send(strongest).max(1e-30));
                stood_for.extend(mine);
            }
            stood_for.sort_unstable();
            let mut all = o.sources.clone();
            all.sort_unstable();
            assert_eq!(stood_for, all, "n {n}");
            if n >= o.sources.len() {
                assert!(reps.iter().all(|r| r.sources == 1), "n {n}: every source on its own");
            }
        }
    }
    assert!(frames > 20, "{frames}");
}

#[test]
fn pruning_more_keeps_fewer_leaves() {
    let mut rng = Pcg64::seed_from_u64(12);
    let r = room(&mut rng, 60, 4, 8);
    let leaves: Vec<usize> = [0.0, 0.02, 0.1, 0.5]
        .iter()
        .map(|&f| {
            let h = ShaftHierarchy::build(
                &r.sources,
                &r.receivers,
                &r.transfers,
                &Settings { prune_fraction: f, ..Settings::PAPER },
            )
            .unwrap();
            h.validate().unwrap();
            h.leaf_shafts()
        })
        .collect();
    assert!(leaves.windows(2).all(|w| w[0] >= w[1]) && leaves[0] > leaves[3], "{leaves:?}");
}

#[test]
fn bad_input_is_an_error() {
    let mut rng = Pcg64::seed_from_u64(13);
    let r = room(&mut rng, 5, 1, 2);
    let mut t = r.transfers.clone();
    t.values.pop();
    assert!(matches!(
        ShaftHierarchy::build(&r.sources, &r.receivers, &t, &Settings::PAPER),
        Err(BuildError::Transfers(_))
    ));
    let mut s = r.sources.clone();
    s[0] = SourceShape::Local(Aabb { min: Vec3::NAN, max: Vec3::ONE });
    assert!(matches!(
        ShaftHierarchy::build(&s, &r.receivers, &r.transfers, &Settings::PAPER),
        Err(BuildError::NotFinite(_))
    ));
    let mut rc = r.receivers.clone();
    rc[0].slots = 0..10_000;
    assert!(ShaftHierarchy::build(&r.sources, &rc, &r.transfers, &Settings::PAPER).is_err());
    let mut t = r.transfers.clone();
    t.totals[0] = f32::INFINITY;
    assert!(ShaftHierarchy::build(&r.sources, &r.receivers, &t, &Settings::PAPER).is_err());
    // nothing at all is fine
    let empty = ShaftHierarchy::build(&[], &[], &Transfers::default(), &Settings::PAPER).unwrap();
    empty.validate().unwrap();
    assert_eq!(empty.leaf_shafts(), 0);
}

/// An object of several boxes reports exactly the union of what each box reports.
#[test]
fn several_boxes_report_the_union_of_each() {
    let mut rng = Pcg64::seed_from_u64(14);
    let r = room(&mut rng, 40, 3, 8);
    let h = ShaftHierarchy::build(&r.sources, &r.receivers, &r.transfers, &Settings::PAPER).unwrap();
    let mut scratch = Traversal::default();
    let mut o = Occlusion::default();
    for _ in 0..40 {
        let boxes = [object(&mut rng), object(&mut rng), Aabb::EMPTY];
        let mut expected = std::collections::BTreeSet::new();
        for b in &boxes {
            h.traverse(b, &mut scratch, &mut o);
            expected.extend(o.sources.iter().copied());
        }
        h.traverse_boxes(&boxes, &mut scratch, &mut o);
        let got: std::collections::BTreeSet<u32> = o.sources.iter().copied().collect();
        assert_eq!(got, expected);
    }
}
