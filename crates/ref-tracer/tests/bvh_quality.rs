//! Every BVH preset is the same scene: the same closest hits and the same occlusion for rays
//! in every direction, from inside and outside the scene (the presets differ only in how long
//! the build takes and how fast traversal is, which the benches and `envshadow render` report).

use glam::Vec3;
use ref_tracer::{BvhQuality, SceneBvh};
use scene::Scene;

/// A fixed-seed xorshift: uniform in [0, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    fn direction(&mut self) -> Vec3 {
        let z = 1.0 - 2.0 * self.next();
        let phi = std::f32::consts::TAU * self.next();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

#[test]
fn every_preset_finds_the_same_hits() {
    for name in ["three_boxes", "spheres_box"] {
        let scene = Scene::builtin(name).expect("built-in");
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for o in &scene.objects {
            for p in &o.mesh.positions {
                (lo, hi) = (lo.min(*p), hi.max(*p));
            }
        }
        let bvhs: Vec<SceneBvh> = BvhQuality::ALL.iter().map(|&q| SceneBvh::with_quality(&scene, q)).collect();
        let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
        let (mut hits, mut same_object) = (0, 0);
        let rays = 20_000;
        for _ in 0..rays {
            // origins in the box grown by half its size each way: inside and outside the scene
            let u = Vec3::new(rng.next(), rng.next(), rng.next()) * 2.0 - 0.5;
            let origin = lo + (hi - lo) * u;
            let dir = rng.direction();
            let reference = bvhs[BvhQuality::ALL.len() - 1].intersect(origin, dir, f32::INFINITY);
            let blocked = bvhs[0].occluded(origin, dir, 1.0);
            for (bvh, q) in bvhs.iter().zip(BvhQuality::ALL) {
                let hit = bvh.intersect(origin, dir, f32::INFINITY);
                match (&hit, &reference) {
                    (Some(a), Some(b)) => {
                        assert!((a.t - b.t).abs() <= 1e-5 * b.t.max(1.0), "{name} {}: t {} vs {}", q.name(), a.t, b.t);
                        same_object += usize::from(a.object == b.object);
                        hits += 1;
                    }
                    (None, None) => {}
                    _ => panic!("{name} {}: {hit:?} vs {reference:?} from {origin} along {dir}", q.name()),
                }
                assert_eq!(bvh.occluded(origin, dir, 1.0), blocked, "{name} {}: occlusion", q.name());
            }
        }
        // a tenth of the rays hit at least (many leave past a flat ground): the test has teeth
        assert!(hits / BvhQuality::ALL.len() > rays / 10, "{name}: {hits} hits over the presets");
        // two objects can share a hit only where they touch
        assert!(same_object as f64 >= 0.999 * hits as f64, "{name}: {same_object} of {hits}");
    }
}

#[test]
fn presets_round_trip_their_names() {
    for q in BvhQuality::ALL {
        assert_eq!(BvhQuality::parse(q.name()), Some(q));
    }
    assert_eq!(BvhQuality::parse("quick"), None);
    assert_eq!(BvhQuality::default(), BvhQuality::VerySlow);
}
