//! The harness itself: seeds are valid files and mutations of any seed never panic.

use input_fuzz::{Format, mutate, seeds};
use rand::SeedableRng;
use std::path::Path;

#[test]
fn every_seed_loads_with_the_loaders_the_commands_use() {
    for t in seeds::library_targets() {
        assert!(!t.seeds.is_empty(), "{} has no seeds", t.name);
        for (k, s) in t.seeds.iter().enumerate() {
            let result = (t.run)(s, Path::new("seed"));
            // the Y-only EXR is the one seed refused on purpose (no colour channels)
            if let Err(e) = result {
                assert!(e.contains("no R, G, B channels"), "{} seed {k}: {e}", t.name);
            }
        }
    }
}

#[test]
fn mutations_never_panic_and_change_the_file() {
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
    let sets = [
        (Format::Hdr, seeds::hdr()),
        (Format::Exr, seeds::exr()),
        (Format::Json, seeds::lights_json()),
        (Format::Gltf, seeds::gltf()),
        (Format::Glb, seeds::glb()),
        (Format::Png, seeds::photos().0),
    ];
    for (format, seeds) in sets {
        let mut changed = 0;
        for k in 0..20_000 {
            let seed = &seeds[k % seeds.len()];
            let m = mutate::mutate(seed, format, &mut rng);
            changed += usize::from(&m != seed);
        }
        assert!(changed > 19_000, "{format:?}: only {changed} of 20000 mutations changed the file");
        for seed in &seeds {
            assert!(mutate::header_len(seed, format) <= seed.len());
            assert!(mutate::mutate(&[], format, &mut rng).len() <= 1 << 20);
        }
    }
}
