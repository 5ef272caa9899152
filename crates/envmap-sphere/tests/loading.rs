//! Loading real maps, and every class of bad input returning its typed error naming the file.

mod common;

use envmap_sphere::{
    Chromaticities, EnvMap, EnvMapError, FileFormat, LoadOptions, NegativePolicy, NonFinitePolicy, PrimariesPolicy,
    luminance,
};
use glam::{Mat3, Vec3};
use std::path::Path;

#[test]
fn every_shared_map_loads() {
    // (file, max luminance, mean luminance) from assets/envmaps/README.md
    let readme = [
        ("adams_place_bridge_1k.hdr", 110.7, 1.30),
        ("empty_warehouse_01_1k.hdr", 400.3, 0.65),
        ("forest_slope_1k.hdr", 59.4, 0.70),
        ("kiara_1_dawn_1k.hdr", 46.2, 0.70),
        ("lebombo_1k.hdr", 23.3, 0.65),
        ("potsdamer_platz_1k.hdr", 10.9, 0.68),
        ("st_fagans_interior_1k.hdr", 1110.9, 0.73),
        ("venice_sunset_1k.hdr", 2090.5, 0.43),
        ("studio.exr", 110.9, 0.25),
        ("courtyard.exr", 52.9, 0.54),
        ("city.exr", 31749.0, 1.05),
    ];
    let maps = common::shared_maps();
    // the README gives the files' own values: city.exr's primaries are not converted there
    let as_stored = LoadOptions { primaries: PrimariesPolicy::Ignore, ..LoadOptions::default() };
    for (name, max, mean) in readme {
        let path = maps.iter().find(|p| p.ends_with(name)).unwrap_or_else(|| panic!("{name} missing"));
        let (map, report) = EnvMap::load_with(path, &as_stored).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!((map.width(), map.height()), (1024, 512), "{name}");
        let stats = map.luminance_stats();
        // the README rounds to one decimal (city.exr to the unit)
        assert!((f64::from(stats.max) - max).abs() <= 0.05 + 1e-4 * max, "{name}: max {}", stats.max);
        assert!((stats.mean_per_pixel - mean).abs() < 0.006, "{name}: mean {}", stats.mean_per_pixel);
        assert!(map.pixels().iter().all(|p| p.is_finite() && p.min_element() >= 0.0));
        if name.ends_with(".exr") {
            assert_eq!((report.format, report.compression.as_str()), (FileFormat::Exr, "dwab"), "{name}");
        } else {
            assert_eq!(report.format, FileFormat::Hdr);
        }
    }
}

#[test]
fn dwab_negative_ringing_is_clamped_and_reported() {
    // Counts are channel values below zero, as the test set's README gives them (of the values as
    // stored: city.exr's primaries unconverted).
    let as_stored = LoadOptions { primaries: PrimariesPolicy::Ignore, ..LoadOptions::default() };
    for (name, count) in [("city.exr", 506), ("courtyard.exr", 1818), ("studio.exr", 3)] {
        let path = common::envmaps_dir().join(name);
        let (map, report) = EnvMap::load_with(&path, &as_stored).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(report.negatives_clamped, count, "{name}");
        assert!(
            report.negative_power_fraction > 0.0 && report.negative_power_fraction < 1e-6,
            "{name}: {}",
            report.negative_power_fraction
        );
        assert!(map.pixels().iter().all(|p| p.min_element() >= 0.0));
        let strict = LoadOptions { negative: NegativePolicy::Strict, ..as_stored };
        let err = EnvMap::load_with(&path, &strict).expect_err("strict mode refuses negatives");
        assert!(matches!(err, EnvMapError::Negative { count: c, .. } if c == count), "{err}");
        let keep = LoadOptions { negative: NegativePolicy::Keep, ..as_stored };
        let (signed, report) = EnvMap::load_with(&path, &keep).unwrap_or_else(|e| panic!("{e}"));
        let kept = signed.pixels().iter().map(|p| p.to_array().iter().filter(|c| **c < 0.0).count()).sum::<usize>();
        assert_eq!((kept, report.negatives_clamped), (count, 0), "{name}: signed maps keep their values");
        assert!(signed.pixels().iter().zip(map.pixels()).all(|(s, c)| s.max(Vec3::ZERO) == *c));
    }
}

fn expect_error(path: &Path, options: &LoadOptions) -> EnvMapError {
    let err = EnvMap::load_with(path, options).expect_err("bad input must be refused");
    let message = err.to_string();
    assert!(message.contains(&path.display().to_string()), "message does not name the file: {message}");
    assert!(!message.contains('\n'), "one line: {message}");
    err
}

#[test]
fn missing_empty_and_non_image_files_are_refused() {
    let dir = common::scratch_dir("bad-input-basic");
    let err = expect_error(&dir.join("nope.exr"), &LoadOptions::default());
    assert!(matches!(err, EnvMapError::Io { .. }), "{err}");
    std::fs::write(dir.join("empty.hdr"), b"").unwrap();
    assert!(matches!(expect_error(&dir.join("empty.hdr"), &LoadOptions::default()), EnvMapError::Empty { .. }));
    std::fs::write(dir.join("notes.exr"), b"this is text, not an image\n").unwrap();
    assert!(matches!(expect_error(&dir.join("notes.exr"), &LoadOptions::default()), EnvMapError::UnknownFormat { .. }));
    let err = expect_error(&dir, &LoadOptions::default());
    assert!(matches!(err, EnvMapError::Io { .. }), "a directory: {err}");
}

#[test]
fn truncated_files_are_refused() {
    let dir = common::scratch_dir("bad-input-truncated");
    for name in ["city.exr", "venice_sunset_1k.hdr"] {
        let bytes = std::fs::read(common::envmaps_dir().join(name)).unwrap();
        for cut in [8, 200, bytes.len() / 2, bytes.len() - 10] {
            let path = dir.join(format!("cut{cut}-{name}"));
            std::fs::write(&path, &bytes[..cut]).unwrap();
            let err = expect_error(&path, &LoadOptions::default());
            assert!(matches!(err, EnvMapError::Decode { .. }), "{name} cut at {cut}: {err}");
        }
    }
}

#[test]
fn huge_claimed_sizes_are_refused_before_allocating() {
    let dir = common::scratch_dir("bad-input-huge");
    // Radiance: the header claims 2,000,000 x 1,000,000 over a few bytes of data.
    let hdr = dir.join("huge.hdr");
    std::fs::write(&hdr, b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1000000 +X 2000000\n\x02\x02\x00\x00").unwrap();
    let err = expect_error(&hdr, &LoadOptions::default());
    assert!(matches!(err, EnvMapError::TooLarge { width: 2_000_000, height: 1_000_000, .. }), "{err}");
    // OpenEXR: a valid small file whose data window is patched to 200000 x 100000.
    let exr = dir.join("huge.exr");
    EnvMap::constant(8, 4, Vec3::ONE).save_exr(&exr).unwrap();
    let mut bytes = std::fs::read(&exr).unwrap();
    let key = b"dataWindow\0box2i\0";
    let at = bytes.windows(key.len()).position(|w| w == key).expect("dataWindow attribute") + key.len() + 4;
    bytes[at + 8..at + 12].copy_from_slice(&199_999i32.to_le_bytes());
    bytes[at + 12..at + 16].copy_from_slice(&99_999i32.to_le_bytes());
    std::fs::write(&exr, &bytes).unwrap();
    let err = expect_error(&exr, &LoadOptions::default());
    assert!(matches!(err, EnvMapError::TooLarge { width: 200_000, height: 100_000, .. }), "{err}");
    // A smaller limit applies too.
    let small = LoadOptions { max_pixels: 1000, ..LoadOptions::default() };
    let city = common::envmaps_dir().join("city.exr");
    assert!(matches!(expect_error(&city, &small), EnvMapError::TooLarge { limit: 1000, .. }));
}

#[test]
fn zero_sized_images_are_refused() {
    let dir = common::scratch_dir("bad-input-zero");
    let hdr = dir.join("zero.hdr");
    std::fs::write(&hdr, b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 0 +X 0\n").unwrap();
    let err = expect_error(&hdr, &LoadOptions::default());
    assert!(matches!(err, EnvMapError::InvalidSize { .. } | EnvMapError::Decode { .. }), "{err}");
    assert!(EnvMap::try_new(0, 4, vec![]).is_err());
    assert!(EnvMap::try_new(2, 1, vec![Vec3::ZERO]).is_err());
}

#[test]
fn non_finite_pixels_are_an_error_or_zeroed_on_request() {
    let dir = common::scratch_dir("bad-input-nan");
    let path = dir.join("nan.exr");
    let mut map = EnvMap::constant(16, 8, Vec3::ONE);
    map.set_pixel(3, 2, Vec3::new(f32::NAN, 1.0, 1.0));
    map.set_pixel(5, 6, Vec3::new(1.0, f32::INFINITY, f32::NEG_INFINITY));
    map.save_exr(&path).unwrap();
    let err = expect_error(&path, &LoadOptions::default());
    assert!(matches!(err, EnvMapError::NonFinite { count: 3, first_i: 3, first_j: 2, .. }), "{err}");
    let zero = LoadOptions { non_finite: NonFinitePolicy::Zero, ..LoadOptions::default() };
    let (loaded, report) = EnvMap::load_with(&path, &zero).unwrap();
    assert_eq!(report.non_finite_zeroed, 3);
    assert_eq!(loaded.pixel(3, 2), Vec3::new(0.0, 1.0, 1.0));
    assert_eq!(loaded.pixel(5, 6), Vec3::new(1.0, 0.0, 0.0));
}

#[test]
fn large_negative_power_is_a_broken_file() {
    let dir = common::scratch_dir("bad-input-negative");
    let path = dir.join("negative.exr");
    let mut map = EnvMap::constant(16, 8, Vec3::ONE);
    map.set_pixel(4, 4, Vec3::splat(-5.0));
    map.save_exr(&path).unwrap();
    let err = expect_error(&path, &LoadOptions::default());
    assert!(matches!(err, EnvMapError::Negative { count: 3, .. }), "{err}");
    // A looser limit accepts and clamps it.
    let loose = LoadOptions { negative: NegativePolicy::Clamp { max_power_fraction: 0.5 }, ..LoadOptions::default() };
    let (loaded, report) = EnvMap::load_with(&path, &loose).unwrap();
    assert_eq!((report.negatives_clamped, loaded.pixel(4, 4)), (3, Vec3::ZERO));
}

#[test]
fn aspect_ratios_other_than_two_to_one() {
    let dir = common::scratch_dir("bad-input-aspect");
    for (w, h, ok) in [(64, 16, true), (64, 64, true), (48, 32, true), (16, 64, false), (80, 16, false)] {
        let path = dir.join(format!("{w}x{h}.exr"));
        EnvMap::try_new(w, h, vec![Vec3::ONE; (w * h) as usize]).unwrap().save_exr(&path).unwrap();
        if ok {
            let (_, report) = EnvMap::load_with(&path, &LoadOptions::default()).unwrap();
            assert_eq!(report.warnings.len(), 1, "{w}x{h}: {:?}", report.warnings);
        } else {
            assert!(matches!(expect_error(&path, &LoadOptions::default()), EnvMapError::NotLatLong { .. }));
        }
    }
}

#[test]
fn exr_without_rgb_channels_is_refused() {
    use exr::prelude::*;
    let dir = common::scratch_dir("bad-input-channels");
    let path = dir.join("gray.exr");
    let channel = AnyChannel::new("Y", FlatSamples::F32(vec![0.5; 32]));
    let layer = Layer::new(
        (8, 4),
        LayerAttributes::named("gray"),
        Encoding::UNCOMPRESSED,
        AnyChannels::sort(SmallVec::from_vec(vec![channel])),
    );
    Image::from_layer(layer).write().to_file(&path).unwrap();
    let err = expect_error(&path, &LoadOptions::default());
    assert!(err.to_string().contains("no R, G, B channels"), "{err}");
}

#[test]
fn saved_exr_round_trips_exactly_and_previews_are_written() {
    let dir = common::scratch_dir("round-trip");
    let map = envmap_sphere::default_map().resize(256, 128);
    map.save_exr(dir.join("a.exr")).unwrap();
    let (back, report) = EnvMap::load_with(dir.join("a.exr"), &LoadOptions::default()).unwrap();
    assert_eq!(back, map);
    assert_eq!(report.compression, "zip16");
    map.save_png_preview(dir.join("a.png")).unwrap();
    let png = std::fs::read(dir.join("a.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG"));
    let err = map.save_exr(dir.join("no/such/dir/a.exr")).expect_err("unwritable");
    assert!(err.to_string().contains("no/such/dir"), "{err}");
}

#[test]
fn embedded_default_map_is_the_shared_city_map() {
    let map = envmap_sphere::default_map();
    let shared = EnvMap::load(common::envmaps_dir().join("city.exr")).unwrap();
    assert_eq!(map, shared);
    assert!(luminance(map.pixels().iter().copied().fold(Vec3::ZERO, Vec3::max)) > 10_000.0);
}

/// An 8 x 4 RGB EXR file of `rgb` everywhere, declaring `chromaticities` if given.
fn exr_with_primaries(path: &Path, rgb: impl Fn(usize) -> Vec3 + Sync, chromaticities: Option<Chromaticities>) {
    use exr::prelude::*;
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let c = rgb(p.y() * 8 + p.x());
        (c.x, c.y, c.z)
    });
    let mut image = Image::from_channels((8, 4), channels);
    image.attributes.chromaticities = chromaticities.map(|c| {
        let v = |[x, y]: [f32; 2]| Vec2(x, y);
        exr::meta::attribute::Chromaticities { red: v(c.red), green: v(c.green), blue: v(c.blue), white: v(c.white) }
    });
    image.write().to_file(path).unwrap();
}

/// sRGB primaries adapted to a D50 white, as Blender's `city.exr` declares them.
const SRGB_D50: Chromaticities = Chromaticities {
    red: [0.648_447_4, 0.330_876_6],
    green: [0.321_187_1, 0.597_894_3],
    blue: [0.155_901_4, 0.066_056_3],
    white: [0.345_708_4, 0.358_541_3],
};

#[test]
fn exr_primaries_are_converted_to_rec709_of_the_same_xyz() {
    let dir = common::scratch_dir("primaries");
    let colour =
        |k: usize| Vec3::new(0.2 + 0.1 * (k % 5) as f32, 0.3 + 0.05 * (k % 7) as f32, 0.1 + 0.2 * (k % 3) as f32);
    // Published matrices, independent of the code under test: linear sRGB / Rec.709 (IEC
    // 61966-2-1) and Adobe RGB (1998), RGB -> XYZ.
    let rec709_to_xyz =
        Mat3::from_cols_array(&[0.4124, 0.2126, 0.0193, 0.3576, 0.7152, 0.1192, 0.1805, 0.0722, 0.9505]);
    let adobe_to_xyz = Mat3::from_cols_array(&[
        0.576_67, 0.297_34, 0.027_03, 0.185_56, 0.627_36, 0.070_69, 0.188_23, 0.075_29, 0.991_34,
    ]);
    let adobe = Chromaticities { red: [0.64, 0.33], green: [0.21, 0.71], blue: [0.15, 0.06], white: [0.3127, 0.3290] };
    let path = dir.join("adobe.exr");
    exr_with_primaries(&path, colour, Some(adobe));
    let (map, report) = EnvMap::load_with(&path, &LoadOptions::default()).unwrap();
    assert_eq!(report.converted_from, Some(adobe));
    for (k, p) in map.pixels().iter().enumerate() {
        let (want, got) = (adobe_to_xyz * colour(k), rec709_to_xyz * *p);
        assert!((want - got).abs().max_element() < 1e-3, "texel {k}: XYZ {got} vs {want}");
    }
    // No chromatic adaptation: the D50 white of city.exr's primaries stays D50 (XYZ 0.9642, 1,
    // 0.8249) and reads warm in Rec.709: the standard XYZ -> sRGB matrix gives these values.
    let path = dir.join("d50.exr");
    exr_with_primaries(&path, |_| Vec3::ONE, Some(SRGB_D50));
    let (map, _) = EnvMap::load_with(&path, &LoadOptions::default()).unwrap();
    let want = Vec3::new(1.1762, 0.9758, 0.7216);
    assert!(map.pixels().iter().all(|p| (*p - want).abs().max_element() < 2e-3), "{}", map.pixel(0, 0));
    // Rec.709 declared, nothing declared, or the attribute ignored: the values as stored.
    let ignore = LoadOptions { primaries: PrimariesPolicy::Ignore, ..LoadOptions::default() };
    for (name, declared, options) in [
        ("709.exr", Some(Chromaticities::REC709), LoadOptions::default()),
        ("none.exr", None, LoadOptions::default()),
        ("ignored.exr", Some(adobe), ignore),
    ] {
        let path = dir.join(name);
        exr_with_primaries(&path, colour, declared);
        let (map, report) = EnvMap::load_with(&path, &options).unwrap();
        assert_eq!(report.converted_from, None, "{name}");
        assert!(map.pixels().iter().enumerate().all(|(k, p)| *p == colour(k)), "{name}");
    }
    // Degenerate primaries (a zero y, collinear): read as Rec.709, with a warning naming the file.
    for (k, bad) in [
        Chromaticities { red: [0.64, 0.0], ..adobe },
        Chromaticities { red: [0.2, 0.2], green: [0.3, 0.3], blue: [0.4, 0.4], white: [0.3127, 0.3290] },
    ]
    .into_iter()
    .enumerate()
    {
        let path = dir.join(format!("bad{k}.exr"));
        exr_with_primaries(&path, colour, Some(bad));
        let (map, report) = EnvMap::load_with(&path, &LoadOptions::default()).unwrap();
        assert_eq!(report.converted_from, None);
        assert!(report.warnings.iter().any(|w| w.contains("degenerate") && w.contains(&path.display().to_string())));
        assert!(map.pixels().iter().enumerate().all(|(k, p)| *p == colour(k)));
    }
}

#[test]
fn city_exr_is_read_from_its_d50_primaries() {
    // Blender's city.exr declares sRGB primaries adapted to D50: read as Mitsuba 3 reads it, its
    // grey sky turns warm (about 1.18, 0.98, 0.72 of the stored values).
    let path = common::envmaps_dir().join("city.exr");
    let (map, report) = EnvMap::load_with(&path, &LoadOptions::default()).unwrap();
    let stored = LoadOptions { primaries: PrimariesPolicy::Ignore, ..LoadOptions::default() };
    let (raw, _) = EnvMap::load_with(&path, &stored).unwrap();
    let c = report.converted_from.expect("city.exr declares its primaries");
    let near = |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).abs() < 1e-5 && (a[1] - b[1]).abs() < 1e-5;
    assert!(near(c.red, SRGB_D50.red) && near(c.white, SRGB_D50.white), "{c:?}");
    let sum = |m: &EnvMap| m.pixels().iter().fold(Vec3::ZERO, |a, p| a + *p);
    let ratio = sum(&map) / sum(&raw);
    assert!((ratio - Vec3::new(1.176, 0.976, 0.722)).abs().max_element() < 0.02, "{ratio}");
    assert_eq!(envmap_sphere::default_map(), map, "the embedded copy reads the same");
}

/// A small RGB f32 OpenEXR file with `compression`, in memory.
fn exr_bytes(compression: exr::compression::Compression, channels: [&str; 3]) -> Vec<u8> {
    use exr::prelude::*;
    let (w, h) = (64usize, 32usize);
    let list: Vec<AnyChannel<FlatSamples>> = channels
        .iter()
        .enumerate()
        .map(|(c, name)| {
            let values = (0..w * h).map(|k| ((k * (c + 3)) % 17) as f32 * 0.25).collect();
            AnyChannel::new(*name, FlatSamples::F32(values))
        })
        .collect();
    let encoding = Encoding { compression, ..Encoding::UNCOMPRESSED };
    let layer =
        Layer::new((w, h), LayerAttributes::named("rgb"), encoding, AnyChannels::sort(SmallVec::from_vec(list)));
    let mut bytes = Vec::new();
    Image::from_layer(layer).write().to_buffered(std::io::Cursor::new(&mut bytes)).expect("write exr");
    bytes
}

#[test]
fn dwa_chunks_claiming_absurd_counts_are_refused_before_decoding() {
    // found by `cargo xtask fuzz`: the exr crate reserved memory by a chunk's AC count and
    // aborted the process on 2^60
    let bytes = exr_bytes(exr::compression::Compression::DWAB(None), ["R", "G", "B"]);
    let (map, _) = EnvMap::load_from_bytes(&bytes, "dwab.exr", &LoadOptions::default()).expect("the valid file loads");
    assert_eq!((map.width(), map.height()), (64, 32));
    // 32 rows are one DWAB block: the offset table is one entry pointing just past itself, and
    // the chunk there is (y: i32, size: i32, then 11 u64 counters: version, 7 sizes, AC and DC
    // counts, AC compression)
    let offset = |k: usize| u64::from_le_bytes(bytes[k..k + 8].try_into().unwrap_or([0; 8])) as usize;
    let table = (8..bytes.len() - 8).find(|&k| offset(k) == k + 8).expect("the offset table");
    let counters = table + 8 + 8;
    for counter in [8usize, 9, 1, 6] {
        let mut bad = bytes.clone();
        let at = counters + 8 * counter;
        bad[at..at + 8].copy_from_slice(&(1u64 << 60).to_le_bytes());
        let err = EnvMap::load_from_bytes(&bad, "bad-dwab.exr", &LoadOptions::default()).expect_err("refused");
        let text = err.to_string();
        assert!(text.contains("bad-dwab.exr") && text.contains("DWA counter claims"), "{text}");
    }
}

#[test]
fn text_from_the_file_cannot_break_an_error_across_lines() {
    // channel names are the file's own text: a newline among them is escaped
    let bytes = exr_bytes(exr::compression::Compression::Uncompressed, ["R", "G", "B\nX"]);
    let err = EnvMap::load_from_bytes(&bytes, "names.exr", &LoadOptions::default()).expect_err("no B channel");
    let text = err.to_string();
    assert!(!text.contains('\n') && text.contains("names.exr") && text.contains("\\n"), "{text}");
    assert_eq!(envmap_sphere::error::one_line("a\tb\r\nc"), "a\\tb\\r\\nc");
    assert_eq!(envmap_sphere::error::one_line("plain"), "plain");
}

/// A 4 x 2 Radiance file (flat scanlines: too narrow for run-length encoding), every pixel the
/// RGBE bytes `rgbe`, with `extra` header lines.
fn rgbe_file(extra: &str, rgbe: [u8; 4]) -> Vec<u8> {
    let mut bytes = format!("#?RADIANCE\n{extra}FORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n").into_bytes();
    for _ in 0..8 {
        bytes.extend_from_slice(&rgbe);
    }
    bytes
}

#[test]
fn radiance_primaries_line_is_ignored() {
    // (1, 0.5, 0.25): mantissas 128, 64, 32 at exponent 2^1 (byte 129)
    let rgbe = [128, 64, 32, 129];
    let plain = EnvMap::load_from_bytes(&rgbe_file("", rgbe), "plain.hdr", &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    // wide-gamut primaries that a conversion would visibly change (Rec.2020's)
    let primaries = "PRIMARIES=0.708 0.292 0.170 0.797 0.131 0.046 0.3127 0.3290\n";
    let declared = EnvMap::load_from_bytes(&rgbe_file(primaries, rgbe), "declared.hdr", &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(declared.1.converted_from.is_none(), "{:?}", declared.1.converted_from);
    assert_eq!(plain.0.pixels(), declared.0.pixels(), "the values as stored");
    let p = plain.0.pixel(1, 1);
    assert!((p - Vec3::new(1.0, 0.5, 0.25)).abs().max_element() < 0.01, "{p}");
}

#[test]
fn b44_blocks_that_wrap_decode_without_aborting() {
    // found by `cargo xtask fuzz`: a B44 block whose deltas wrap below zero made the exr crate's
    // decoder thread panic under dev's overflow checks, aborting the process; its arithmetic
    // wraps by design (the workspace turns the checks off for it)
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz_b44_wrap.exr");
    let bytes = std::fs::read(&path).expect("the case");
    let result = envmap_sphere::load_rgb_image_from_bytes(&bytes, &path, &LoadOptions::default());
    match result {
        Ok(image) => assert_eq!(image.pixels.len(), image.width as usize * image.height as usize),
        Err(e) => assert!(e.to_string().contains("fuzz_b44_wrap.exr") && !e.to_string().contains('\n'), "{e}"),
    }
}
