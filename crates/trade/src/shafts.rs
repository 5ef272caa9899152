//! What `cargo xtask shafts` and the bench measure: a built-in object path, the
//! conservativeness check by brute-force segments, per-frame timing, and an overlay image.

use std::collections::HashSet;
use std::time::Instant;

use glam::{Vec2, Vec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use real_scene::{RealScene, Visibility, luminance};
use scene::DistantLight;

use shaft_hierarchy::preprocess::{Prepared, Source};
use shaft_hierarchy::{Aabb, BuildError, Occlusion, ShaftHierarchy, Traversal};

/// A box a tenth of the scene's width flying a loop through it, `frames` positions: around
/// the scene's centre at 35 % of its width and depth, bobbing between 5 % and 55 % of its
/// height.
#[must_use]
pub fn object_path(scene: &RealScene, frames: usize) -> Vec<Aabb> {
    let (lo, hi) = scene.bounds();
    let size = hi - lo;
    let centre = (lo + hi) * 0.5;
    let half = 0.05 * (size.x + size.z) * 0.5;
    (0..frames)
        .map(|k| {
            let t = k as f32 / frames.max(1) as f32 * std::f32::consts::TAU;
            let c = Vec3::new(
                centre.x + 0.35 * size.x * t.cos(),
                lo.y + size.y * (0.3 + 0.25 * (3.0 * t).sin()),
                centre.z + 0.35 * size.z * t.sin(),
            );
            Aabb::new(c - Vec3::splat(half), c + Vec3::splat(half))
        })
        .collect()
}

/// The brute-force check of a hierarchy against its objects.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Check {
    /// Segments drawn, source point to receiver point.
    pub segments: usize,
    /// Those that meet the object's box.
    pub hits: usize,
    /// Hits in no reported leaf or pruned shaft: must be 0.
    pub misses: usize,
    /// Hits in a reported pruned shaft (below the threshold by design).
    pub in_pruned: usize,
    /// Sources with a hitting segment, summed over frames.
    pub true_occluders: usize,
    /// Of those, the ones the traversal reported.
    pub found: usize,
    /// Sources reported, summed over frames.
    pub reported: usize,
    /// Reported sources none of whose [`CONFIRM_SEGMENTS`] segments to the receivers of their
    /// met leaf shafts meets the object: the false positives, as far as sampling tells.
    pub unconfirmed: usize,
}

/// Segments drawn per reported source to confirm it.
pub const CONFIRM_SEGMENTS: usize = 64;

/// A point of source `s` for a segment from receiver point `x` (a distant light's: `reach` along
/// a direction in its cone).
fn source_point(scene: &RealScene, lights: &[DistantLight], s: Source, x: Vec3, reach: f32, rng: &mut Pcg64) -> Vec3 {
    match s {
        Source::Patch(j) => scene.patches[j as usize].point(rng.random(), rng.random()),
        Source::Distant(k) => x + lights[k as usize].sample_direction(Vec2::new(rng.random(), rng.random())).0 * reach,
    }
}

/// (source, receiver) index pairs.
pub type Pairs = HashSet<(u32, u32)>;

/// Every (source, receiver) pair in a met leaf shaft, and in a met pruned pair.
#[must_use]
pub fn covered_pairs(h: &ShaftHierarchy, o: &Occlusion) -> (Pairs, Pairs) {
    let expand = |nodes: &mut dyn Iterator<Item = (u32, u32)>| {
        let mut set = HashSet::new();
        for (source, receiver) in nodes {
            for &j in h.source_tree.items(source) {
                for &p in h.receiver_tree.items(receiver) {
                    set.insert((j, p));
                }
            }
        }
        set
    };
    let kept = expand(&mut o.leaf_shafts.iter().map(|&k| (h.shafts[k as usize].source, h.shafts[k as usize].receiver)));
    (kept, expand(&mut o.pruned.iter().copied()))
}

/// For each object, `per_object` segments from a random point of a random source to a random
/// point of a random receiver patch (fixed seed); a segment that meets the object's box must lie
/// in a shaft the traversal reported.
#[must_use]
pub fn check(
    h: &ShaftHierarchy,
    prepared: &Prepared,
    scene: &RealScene,
    lights: &[DistantLight],
    objects: &[Aabb],
    per_object: usize,
    seed: u64,
) -> Check {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut scratch = Traversal::default();
    let mut o = Occlusion::default();
    let mut c = Check::default();
    if prepared.sources.is_empty() || prepared.receivers.is_empty() {
        return c;
    }
    for object in objects {
        h.traverse(object, &mut scratch, &mut o);
        let (kept, pruned) = covered_pairs(h, &o);
        let reported: HashSet<u32> = o.sources.iter().copied().collect();
        let mut occluders = HashSet::new();
        for _ in 0..per_object {
            let j = rng.random_range(0..prepared.sources.len());
            let r = rng.random_range(0..prepared.receivers.len());
            let x = scene.patches[prepared.receivers[r] as usize].point(rng.random(), rng.random());
            let y = source_point(scene, lights, prepared.sources[j], x, h.reach(), &mut rng);
            c.segments += 1;
            if !object.segment_hits(x, y) {
                continue;
            }
            c.hits += 1;
            occluders.insert(j as u32);
            let pair = (j as u32, r as u32);
            if kept.contains(&pair) {
                continue;
            }
            if pruned.contains(&pair) {
                c.in_pruned += 1;
            } else {
                c.misses += 1;
            }
        }
        c.true_occluders += occluders.len();
        c.found += occluders.iter().filter(|j| reported.contains(j)).count();
        c.reported += o.sources.len();
        // false positives: a reported source that no segment to its reported receivers meets
        // in a fixed order, so that the seed fixes the segments
        let mut receivers_of: std::collections::BTreeMap<u32, Vec<u32>> = std::collections::BTreeMap::new();
        for &(j, p) in &kept {
            receivers_of.entry(j).or_default().push(p);
        }
        receivers_of.values_mut().for_each(|rs| rs.sort_unstable());
        for (&j, rs) in &receivers_of {
            let confirmed = (0..CONFIRM_SEGMENTS).any(|_| {
                let r = rs[rng.random_range(0..rs.len())];
                let x = scene.patches[prepared.receivers[r as usize] as usize].point(rng.random(), rng.random());
                let y = source_point(scene, lights, prepared.sources[j as usize], x, h.reach(), &mut rng);
                object.segment_hits(x, y)
            });
            c.unconfirmed += usize::from(!confirmed);
        }
    }
    c
}

/// Microseconds per frame of the traversal plus a representative set of `n`, for each object.
#[must_use]
pub fn frame_times(h: &ShaftHierarchy, objects: &[Aabb], n: usize) -> Vec<f64> {
    let mut scratch = Traversal::default();
    let mut o = Occlusion::default();
    objects
        .iter()
        .map(|object| {
            let t = Instant::now();
            h.traverse(object, &mut scratch, &mut o);
            let reps = h.representatives(&o, n);
            std::hint::black_box(&reps);
            t.elapsed().as_secs_f64() * 1e6
        })
        .collect()
}

/// The median of some values (0 for none).
#[must_use]
pub fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    if v.is_empty() { 0.0 } else { v[v.len() / 2] }
}

/// An image of the scene from its camera (patch radiances, tone-mapped) with the receivers an
/// object may darken tinted blue, the source patches it may occlude red, and the object's box
/// yellow: 8-bit RGB, row-major, the camera's size.
#[must_use]
pub fn overlay(
    scene: &RealScene,
    vis: &impl Visibility,
    prepared: &Prepared,
    occlusion: &Occlusion,
    object: &Aabb,
) -> Vec<[u8; 3]> {
    let mut receiver = vec![false; scene.patches.len()];
    for &r in &occlusion.receivers {
        receiver[prepared.receivers[r as usize] as usize] = true;
    }
    let mut source = vec![false; scene.patches.len()];
    for &s in &occlusion.sources {
        if let Source::Patch(j) = prepared.sources[s as usize] {
            source[j as usize] = true;
        }
    }
    let peak = {
        let mut l: Vec<f32> = scene.patches.iter().map(|p| luminance(p.radiance)).collect();
        l.sort_by(f32::total_cmp);
        l.get(l.len() * 9 / 10).copied().unwrap_or(1.0).max(1e-6)
    };
    let rays = scene.camera.rays();
    let mut out = Vec::with_capacity((scene.camera.width * scene.camera.height) as usize);
    for y in 0..scene.camera.height {
        for x in 0..scene.camera.width {
            let (o, d) = rays.ray(x as f32 + 0.5, y as f32 + 0.5);
            let hit = vis.first_hit(o, d);
            let mut c = hit.map_or(Vec3::ZERO, |(p, _)| {
                let l = scene.patches[p as usize].radiance / peak;
                (l / (l + Vec3::ONE)).powf(1.0 / 2.2)
            });
            if let Some((p, t)) = hit {
                if source[p as usize] {
                    c = c.lerp(Vec3::new(1.0, 0.1, 0.1), 0.6);
                } else if receiver[p as usize] {
                    c = c.lerp(Vec3::new(0.2, 0.4, 1.0), 0.45);
                }
                if ray_box(o, d, object).is_some_and(|tb| tb < t) {
                    c = c.lerp(Vec3::new(1.0, 0.85, 0.0), 0.75);
                }
            }
            out.push((c.clamp(Vec3::ZERO, Vec3::ONE) * 255.0 + 0.5).to_array().map(|v| v as u8));
        }
    }
    out
}

/// Entry distance of a ray into a box.
fn ray_box(o: Vec3, d: Vec3, b: &Aabb) -> Option<f32> {
    let inv = d.recip();
    let (t0, t1) = ((b.min - o) * inv, (b.max - o) * inv);
    let (near, far) = (t0.min(t1).max_element().max(0.0), t0.max(t1).min_element());
    (near <= far).then_some(near)
}

/// Everything `cargo xtask shafts` reports for one setting.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Figures {
    /// The source set's size.
    pub sources: usize,
    /// Receiver patches.
    pub receivers: usize,
    /// Shaft nodes stored.
    pub shafts: usize,
    /// Leaf shafts (kept pairs).
    pub leaf_shafts: usize,
    /// Pairs pruned.
    pub pruned_pairs: usize,
    /// Bytes traversal needs ([`ShaftHierarchy::bytes`]).
    pub bytes: usize,
    /// Bytes of the transfer sums, besides.
    pub transfer_bytes: usize,
    /// The source set's share of the power.
    pub power_share: f64,
    /// Source set, receivers, transfers, trees and shafts, seconds.
    pub preprocess_s: f64,
    /// Traversal plus representative set, median microseconds per frame.
    pub traversal_us: f64,
    /// The brute-force check.
    pub check: Check,
}

/// Pre-processes `scene` with `settings` (timed), validates, checks `per_frame` segments at
/// each of `frames` positions of [`object_path`], and times three passes over the path with a
/// representative set of `representatives`.
///
/// # Errors
/// A build error, or [`BuildError::Broken`] when the hierarchy fails its `validate`.
pub fn figures(
    scene: &RealScene,
    lights: &[DistantLight],
    vis: &impl Visibility,
    settings: &shaft_hierarchy::preprocess::PreprocessSettings,
    (frames, per_frame, representatives): (usize, usize, usize),
) -> Result<(Figures, Prepared, ShaftHierarchy), BuildError> {
    let t = Instant::now();
    let (prepared, h) = shaft_hierarchy::preprocess::build(scene, lights, vis, settings)?;
    let preprocess_s = t.elapsed().as_secs_f64();
    h.validate().map_err(BuildError::Broken)?;
    let objects = object_path(scene, frames);
    let check = check(&h, &prepared, scene, lights, &objects, per_frame, 1);
    let times: Vec<f64> = (0..3).flat_map(|_| frame_times(&h, &objects, representatives)).collect();
    let f = Figures {
        sources: prepared.sources.len(),
        receivers: prepared.receivers.len(),
        shafts: h.shafts.len(),
        leaf_shafts: h.leaf_shafts(),
        pruned_pairs: h.pruned_pairs(),
        bytes: h.bytes(),
        transfer_bytes: h.transfer_bytes(),
        power_share: prepared.power.0 / prepared.power.1.max(f64::MIN_POSITIVE),
        preprocess_s,
        traversal_us: median(&times),
        check,
    };
    Ok((f, prepared, h))
}

/// The knobs swept by `cargo xtask shafts --sweep`: the paper's setting, then one knob at a
/// time (source share, receivers per leaf, pruning threshold).
#[must_use]
pub fn sweep() -> Vec<(String, shaft_hierarchy::preprocess::PreprocessSettings)> {
    use shaft_hierarchy::preprocess::PreprocessSettings as P;
    let paper = P::PAPER;
    let mut out = vec![("paper (70 %, 8 a leaf, 2 %)".to_string(), paper)];
    for share in [0.5, 0.9] {
        out.push((format!("source share {:.0} %", share * 100.0), P { source_share: share, ..paper }));
    }
    for leaf in [4, 16] {
        out.push((
            format!("{leaf} receivers a leaf"),
            P { hierarchy: shaft_hierarchy::Settings { leaf_size: leaf, ..paper.hierarchy }, ..paper },
        ));
    }
    for prune in [0.0, 0.1] {
        out.push((
            format!("pruning {:.0} %", prune * 100.0),
            P { hierarchy: shaft_hierarchy::Settings { prune_fraction: prune, ..paper.hierarchy }, ..paper },
        ));
    }
    out
}
