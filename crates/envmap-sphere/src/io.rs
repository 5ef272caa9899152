//! Loading (.exr, Radiance .hdr) with validation, and saving (.exr, tone-mapped .png).
//!
//! Files are recognised by magic number, not extension. Every failure is an [`EnvMapError`]
//! naming the file and the reason. Policies for real-world input:
//! - size: the header's claimed size is checked against [`LoadOptions::max_pixels`] before any
//!   pixel buffer is allocated (default 2^27 texels = 16384 x 8192, 1.5 GiB as f32 RGB);
//! - aspect: a width/height ratio outside [1, 4] is refused as not lat-long; other ratios than
//!   2:1 load with a warning (the convention works for any W x H, with non-square texels);
//! - NaN / infinity: an error by default; [`NonFinitePolicy::Zero`] zeroes them and counts them;
//! - negative values: lossy EXR compression (DWAB) rings slightly below zero; by default they are
//!   clamped to zero and the count and the fraction of power removed are reported, unless the
//!   negative power exceeds [`DEFAULT_MAX_NEGATIVE_FRACTION`] of the positive power (a broken
//!   file). [`NegativePolicy::Strict`] refuses any negative value; [`NegativePolicy::Keep`]
//!   keeps them, for signed maps (a residual of light extraction);
//! - primaries: an EXR file whose `chromaticities` attribute is not Rec.709 (Blender's
//!   `city.exr` declares sRGB primaries adapted to a D50 white) is converted to Rec.709 of the
//!   same CIE XYZ, as OpenEXR and Mitsuba 3 read it ([`PrimariesPolicy`]). Radiance's
//!   `PRIMARIES` line is ignored.

use crate::color::Chromaticities;
use crate::envmap::EnvMap;
use crate::error::{EnvMapError, one_line};
use crate::tonemap::Tonemap;
use glam::Vec3;
use std::io::Cursor;
use std::path::{Path, PathBuf};

/// Default [`LoadOptions::max_pixels`]: 2^27 texels (16384 x 8192).
pub const DEFAULT_MAX_PIXELS: u64 = 1 << 27;

/// Default limit on negative power / positive power under [`NegativePolicy::Clamp`]:
/// 1e-3. DWAB noise in Blender's maps is a few 1e-7 of the power.
pub const DEFAULT_MAX_NEGATIVE_FRACTION: f64 = 1e-3;

/// What to do with NaN and infinite pixel values.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum NonFinitePolicy {
    /// Refuse the file ([`EnvMapError::NonFinite`]).
    #[default]
    Error,
    /// Replace them by zero and count them in [`LoadReport::non_finite_zeroed`].
    Zero,
}

/// What to do with negative pixel values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NegativePolicy {
    /// Clamp to zero, unless the negative power exceeds `max_power_fraction` of the positive.
    Clamp {
        /// Largest accepted negative power / positive power.
        max_power_fraction: f64,
    },
    /// Refuse any negative value.
    Strict,
    /// Keep negative values as they are: for signed maps, such as the residual of light
    /// extraction (map minus lights), not for radiance.
    Keep,
}

/// What to do with an EXR file's `chromaticities` attribute (its RGB primaries and white).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PrimariesPolicy {
    /// Convert pixels from the file's primaries to Rec.709 of the same CIE XYZ (as OpenEXR's
    /// reference reader and Mitsuba 3 do), and report it in [`LoadReport::converted_from`].
    #[default]
    Convert,
    /// Read the values as Rec.709 whatever the file says (as renderers that ignore the
    /// attribute do).
    Ignore,
}

impl Default for NegativePolicy {
    fn default() -> Self {
        Self::Clamp { max_power_fraction: DEFAULT_MAX_NEGATIVE_FRACTION }
    }
}

/// Options for [`EnvMap::load_with`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoadOptions {
    /// Refuse files whose header claims more texels than this, before allocating.
    pub max_pixels: u64,
    /// NaN and infinity handling.
    pub non_finite: NonFinitePolicy,
    /// Negative value handling.
    pub negative: NegativePolicy,
    /// EXR primaries handling.
    pub primaries: PrimariesPolicy,
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self {
            max_pixels: DEFAULT_MAX_PIXELS,
            non_finite: NonFinitePolicy::default(),
            negative: NegativePolicy::default(),
            primaries: PrimariesPolicy::default(),
        }
    }
}

/// File format of a loaded map.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileFormat {
    /// OpenEXR.
    Exr,
    /// Radiance RGBE.
    Hdr,
}

impl FileFormat {
    /// "exr" or "hdr".
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Exr => "exr",
            Self::Hdr => "hdr",
        }
    }
}

/// What loading found and changed.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadReport {
    /// The file format.
    pub format: FileFormat,
    /// Compression, lower case: "none", "rle", "zip", "zip16", "piz", "pxr24", "b44", "b44a",
    /// "dwaa", "dwab" for EXR; "rle" for Radiance (adaptive run-length).
    pub compression: String,
    /// The primaries an EXR file declared (its `chromaticities` attribute) when they are not
    /// Rec.709's: its pixels were converted to Rec.709 of the same CIE XYZ, without chromatic
    /// adaptation ([`Chromaticities::to_rec709`], as OpenEXR and Mitsuba 3 convert). Saturated
    /// colours may come out negative and then meet the negative policy.
    pub converted_from: Option<Chromaticities>,
    /// Negative channel values clamped to zero.
    pub negatives_clamped: usize,
    /// Power removed by clamping, as a fraction of the positive power (sum over channels).
    pub negative_power_fraction: f64,
    /// NaN or infinite channel values zeroed under [`NonFinitePolicy::Zero`].
    pub non_finite_zeroed: usize,
    /// Human-readable warnings (e.g. an aspect ratio other than 2:1).
    pub warnings: Vec<String>,
}

impl EnvMap {
    /// Loads an .exr or Radiance .hdr file with default [`LoadOptions`].
    ///
    /// # Errors
    /// See [`EnvMap::load_with`].
    pub fn load(path: impl AsRef<Path>) -> Result<Self, EnvMapError> {
        Self::load_with(path, &LoadOptions::default()).map(|(map, _)| map)
    }

    /// Loads an .exr or Radiance .hdr file, applying `options`, and reports what it changed.
    ///
    /// # Errors
    /// Any [`EnvMapError`] file variant: unreadable, empty, unknown format, undecodable, too
    /// large, zero-sized, not lat-long, non-finite or negative values against the policy.
    pub fn load_with(path: impl AsRef<Path>, options: &LoadOptions) -> Result<(Self, LoadReport), EnvMapError> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|e| EnvMapError::io(path, e))?;
        Self::load_from_bytes(&bytes, path, options)
    }

    /// Loads a map from the bytes of an .exr or .hdr file; `name` is used in errors.
    ///
    /// # Errors
    /// As [`EnvMap::load_with`].
    pub fn load_from_bytes(
        bytes: &[u8],
        name: impl AsRef<Path>,
        options: &LoadOptions,
    ) -> Result<(Self, LoadReport), EnvMapError> {
        let path = name.as_ref().to_path_buf();
        let Decoded { width, height, mut pixels, format, compression, converted_from, warnings } =
            decode(bytes, &path, options, true)?;
        let mut report = LoadReport {
            format,
            compression,
            converted_from,
            negatives_clamped: 0,
            negative_power_fraction: 0.0,
            non_finite_zeroed: 0,
            warnings,
        };
        if width != 2 * height {
            report.warnings.push(format!(
                "{}: {width} x {height} is not 2:1; read as lat-long with non-square texels",
                path.display()
            ));
        }
        sanitize(&mut pixels, width, height, &path, options, &mut report)?;
        let map = Self::try_new(width, height, pixels).map_err(|_| EnvMapError::InvalidSize {
            path: path.clone(),
            width: u64::from(width),
            height: u64::from(height),
        })?;
        Ok((map, report))
    }

    /// Saves as a lossless (ZIP) 32-bit float RGB OpenEXR file.
    ///
    /// # Errors
    /// [`EnvMapError::Encode`] when the file cannot be written.
    pub fn save_exr(&self, path: impl AsRef<Path>) -> Result<(), EnvMapError> {
        save_exr_rgb(path.as_ref(), self.width() as usize, self.height() as usize, self.pixels())
    }

    /// Saves a tone-mapped 8-bit sRGB preview (.png) with [`Tonemap::auto`].
    ///
    /// # Errors
    /// [`EnvMapError::Encode`] when the file cannot be written.
    pub fn save_png_preview(&self, path: impl AsRef<Path>) -> Result<(), EnvMapError> {
        let tm = Tonemap::auto(self.pixels());
        save_png_rgb(path.as_ref(), self.width(), self.height(), self.pixels(), &tm)
    }
}

/// Writes row-major linear RGB as a ZIP-compressed float OpenEXR file.
///
/// # Errors
/// [`EnvMapError::Encode`] when the file cannot be written.
pub fn save_exr_rgb(path: &Path, width: usize, height: usize, pixels: &[Vec3]) -> Result<(), EnvMapError> {
    use exr::prelude::*;
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let c = pixels[p.y() * width + p.x()];
        (c.x, c.y, c.z)
    });
    let layer = Layer::new((width, height), LayerAttributes::named("rgb"), Encoding::SMALL_LOSSLESS, channels);
    Image::from_layer(layer).write().to_file(path).map_err(|e| EnvMapError::Encode {
        path: path.to_path_buf(),
        format: "OpenEXR",
        reason: e.to_string(),
    })
}

/// Writes row-major linear RGB as an 8-bit sRGB PNG through `tonemap`.
///
/// # Errors
/// [`EnvMapError::Encode`] when the file cannot be written.
pub fn save_png_rgb(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[Vec3],
    tonemap: &Tonemap,
) -> Result<(), EnvMapError> {
    let bytes: Vec<u8> = pixels.iter().flat_map(|p| tonemap.apply(*p)).collect();
    save_png_srgb8(path, width, height, &bytes)
}

/// Writes row-major 8-bit sRGB triples as a PNG.
///
/// # Errors
/// [`EnvMapError::Encode`] when the file cannot be written or the buffer does not match the size.
pub fn save_png_srgb8(path: &Path, width: u32, height: u32, bytes: &[u8]) -> Result<(), EnvMapError> {
    let png = encode_png_srgb8(width, height, bytes).map_err(|e| match e {
        EnvMapError::Encode { format, reason, .. } => EnvMapError::Encode { path: path.to_path_buf(), format, reason },
        other => other,
    })?;
    std::fs::write(path, png).map_err(|e| EnvMapError::io(path, e))
}

/// Reads back an 8-bit PNG as [`save_png_srgb8`] writes one: its size and row-major RGB
/// triples (alpha dropped), for comparing committed pictures with new ones.
///
/// # Errors
/// [`EnvMapError::Io`]; [`EnvMapError::Decode`] for a file that is not a PNG.
pub fn load_png_srgb8(path: &Path) -> Result<(u32, u32, Vec<[u8; 3]>), EnvMapError> {
    let bytes = std::fs::read(path).map_err(|e| EnvMapError::io(path, e))?;
    let decode = |reason: String| EnvMapError::Decode { path: path.to_path_buf(), format: "PNG", reason };
    let image = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .map_err(|e| decode(crate::error::one_line(&e.to_string())))?
        .into_rgb8();
    Ok((image.width(), image.height(), image.pixels().map(|p| p.0).collect()))
}

/// Encodes row-major 8-bit sRGB triples as PNG file bytes in memory (for embedding, e.g. in an
/// HTML report). Errors name no file.
///
/// # Errors
/// [`EnvMapError::Encode`] when the buffer does not match the size.
pub fn encode_png_srgb8(width: u32, height: u32, bytes: &[u8]) -> Result<Vec<u8>, EnvMapError> {
    use image::ImageEncoder;
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(bytes, width, height, image::ExtendedColorType::Rgb8)
        .map_err(|e| EnvMapError::Encode { path: "(in memory)".into(), format: "PNG", reason: e.to_string() })?;
    Ok(png)
}

/// A decoded file: pixels in linear Rec.709.
struct Decoded {
    width: u32,
    height: u32,
    pixels: Vec<Vec3>,
    format: FileFormat,
    compression: String,
    /// The file's own primaries, when its pixels were converted from them.
    converted_from: Option<Chromaticities>,
    warnings: Vec<String>,
}

fn decode(bytes: &[u8], path: &Path, options: &LoadOptions, latlong: bool) -> Result<Decoded, EnvMapError> {
    if bytes.is_empty() {
        Err(EnvMapError::Empty { path: path.to_path_buf() })
    } else if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        decode_exr(bytes, path, options, latlong)
    } else if bytes.starts_with(b"#?") {
        decode_hdr(bytes, path, options, latlong)
    } else {
        Err(EnvMapError::UnknownFormat { path: path.to_path_buf() })
    }
}

/// A plain linear RGB image (a render, not a map): row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major pixels.
    pub pixels: Vec<Vec3>,
}

/// Loads an .exr or .hdr image of any aspect ratio as it is: no lat-long check, no policy on
/// negative values; NaN and infinity are refused and sizes are checked as for maps.
///
/// # Errors
/// As [`EnvMap::load_with`], without [`EnvMapError::NotLatLong`] and [`EnvMapError::Negative`].
pub fn load_rgb_image(path: impl AsRef<Path>) -> Result<RgbImage, EnvMapError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| EnvMapError::io(path, e))?;
    load_rgb_image_from_bytes(&bytes, path, &LoadOptions::default())
}

/// [`load_rgb_image`] from the bytes of a file; `name` is used in errors, and only
/// `options.max_pixels` applies.
///
/// # Errors
/// As [`load_rgb_image`].
pub fn load_rgb_image_from_bytes(
    bytes: &[u8],
    name: impl AsRef<Path>,
    options: &LoadOptions,
) -> Result<RgbImage, EnvMapError> {
    let path = name.as_ref();
    let Decoded { width, height, pixels, .. } = decode(bytes, path, options, false)?;
    if let Some(k) = pixels.iter().position(|p| !p.is_finite()) {
        let count = pixels.iter().map(|p| p.to_array().iter().filter(|c| !c.is_finite()).count()).sum();
        return Err(EnvMapError::NonFinite {
            path: path.to_path_buf(),
            count,
            first_i: (k % width as usize) as u32,
            first_j: (k / width as usize) as u32,
        });
    }
    Ok(RgbImage { width, height, pixels })
}

fn check_size(path: &Path, w: u64, h: u64, options: &LoadOptions, latlong: bool) -> Result<(u32, u32), EnvMapError> {
    let path = path.to_path_buf();
    if w == 0 || h == 0 {
        return Err(EnvMapError::InvalidSize { path, width: w, height: h });
    }
    if w.saturating_mul(h) > options.max_pixels || w > u64::from(u32::MAX) || h > u64::from(u32::MAX) {
        return Err(EnvMapError::TooLarge { path, width: w, height: h, limit: options.max_pixels });
    }
    if latlong && (w < h || w > 4 * h) {
        return Err(EnvMapError::NotLatLong { path, width: w, height: h });
    }
    Ok((w as u32, h as u32))
}

fn decode_exr(bytes: &[u8], path: &Path, options: &LoadOptions, latlong: bool) -> Result<Decoded, EnvMapError> {
    use exr::prelude::*;
    let err =
        |reason: String| EnvMapError::Decode { path: path.to_path_buf(), format: "OpenEXR", reason: one_line(&reason) };
    // read once through a cursor: where it stops, the chunk offset tables begin
    let mut cursor = Cursor::new(bytes);
    let meta = exr::meta::MetaData::read_from_buffered(&mut cursor, false).map_err(|e| err(e.to_string()))?;
    let table_start = usize::try_from(cursor.position()).unwrap_or(usize::MAX);
    let header = meta.headers.first().ok_or_else(|| err("no layers".into()))?;
    let size = header.layer_size;
    let (w, h) = check_size(path, size.width() as u64, size.height() as u64, options, latlong)?;
    // every chunk has an 8-byte entry in the offset table: a file shorter than the table cannot
    // hold the pixels its header claims (refused before the pixel buffer is allocated)
    let table = meta.headers.iter().map(|h| h.chunk_count as u64).sum::<u64>().saturating_mul(8);
    if (bytes.len() as u64) < table {
        return Err(err(format!(
            "truncated: its {table}-byte chunk offset table alone is longer than the file ({} bytes)",
            bytes.len()
        )));
    }
    check_dwa_chunks(bytes, &meta, table_start).map_err(err)?;
    let compression = format!("{:?}", header.compression);
    let compression = compression.split('(').next().unwrap_or("").to_lowercase();
    let compression = if compression == "uncompressed" { "none".to_string() } else { compression };
    let has = |name: &str| header.channels.list.iter().any(|c| c.name.eq(name));
    if !(has("R") && has("G") && has("B")) {
        let names: Vec<String> = header.channels.list.iter().map(|c| format!("{:?}", c.name.to_string())).collect();
        return Err(err(format!("no R, G, B channels (has {})", names.join(", "))));
    }
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |res, _| vec![Vec3::ZERO; res.width() * res.height()],
            move |px: &mut Vec<Vec3>, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                px[pos.y() * w as usize + pos.x()] = Vec3::new(r, g, b);
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(Cursor::new(bytes))
        .map_err(|e| err(e.to_string()))?;
    let mut pixels = image.layer_data.channel_data.pixels;
    if pixels.len() != w as usize * h as usize {
        return Err(err(format!("decoded {} pixels for {w} x {h}", pixels.len())));
    }
    let (mut converted_from, mut warnings) = (None, Vec::new());
    if let Some(c) = header.shared_attributes.chromaticities.filter(|_| options.primaries == PrimariesPolicy::Convert) {
        let v = |p: exr::math::Vec2<f32>| [p.x(), p.y()];
        let file = Chromaticities { red: v(c.red), green: v(c.green), blue: v(c.blue), white: v(c.white) };
        if !file.is_rec709() {
            match file.to_rec709() {
                Some(m) => {
                    let m = m.as_mat3();
                    pixels.iter_mut().for_each(|p| *p = m * *p);
                    converted_from = Some(file);
                }
                None => warnings.push(format!(
                    "{}: degenerate chromaticities {file:?} ignored: pixels read as Rec.709",
                    path.display()
                )),
            }
        }
    }
    Ok(Decoded { width: w, height: h, pixels, format: FileFormat::Exr, compression, converted_from, warnings })
}

/// DWAA / DWAB chunks whose leading counters claim more values than their block can hold are
/// refused here: the `exr` crate (1.74.2) reserves memory by those counters before checking
/// them, and aborts the process on an absurd one (found by `cargo xtask fuzz`).
/// `table_start` is where the headers end and the offset tables begin.
fn check_dwa_chunks(bytes: &[u8], meta: &exr::meta::MetaData, table_start: usize) -> Result<(), String> {
    use exr::compression::Compression;
    use exr::meta::BlockDescription;
    if !meta.headers.iter().any(|h| matches!(h.compression, Compression::DWAA(_) | Compression::DWAB(_))) {
        return Ok(());
    }
    let multipart = meta.requirements.is_multilayer();
    let u64_at =
        |at: usize| bytes.get(at..at.checked_add(8)?).map(|b| u64::from_le_bytes(b.try_into().unwrap_or([0; 8])));
    let i32_at =
        |at: usize| bytes.get(at..at.checked_add(4)?).map(|b| i32::from_le_bytes(b.try_into().unwrap_or([0; 4])));
    let mut entry = table_start;
    for (part, header) in meta.headers.iter().enumerate() {
        // values a block can hold: its pixels times the channels, with room for rounding
        let block_pixels = match header.blocks {
            BlockDescription::ScanLines => header.layer_size.width() * header.compression.scan_lines_per_block(),
            BlockDescription::Tiles(t) => t.tile_size.width() * t.tile_size.height(),
        };
        let limit =
            (block_pixels.saturating_mul(header.channels.list.len()) as u64).saturating_mul(2).saturating_add(64);
        for chunk in 0..header.chunk_count {
            let Some(offset) = u64_at(entry) else { return Ok(()) };
            entry += 8;
            let Ok(mut at) = usize::try_from(offset) else { continue };
            if multipart {
                at = at.saturating_add(4);
            }
            at = at.saturating_add(match header.blocks {
                BlockDescription::ScanLines => 4,
                BlockDescription::Tiles(_) => 16,
            });
            let Some(size) = i32_at(at) else { continue };
            let data = at.saturating_add(4);
            if size < 88 || !matches!(header.compression, Compression::DWAA(_) | Compression::DWAB(_)) {
                continue;
            }
            // counters 1..=9 after the version: sizes in bytes, then the AC and DC counts
            for k in 1..10 {
                let Some(v) = u64_at(data + 8 * k) else { break };
                let bound = if k >= 8 { limit } else { limit.saturating_mul(8) };
                if v > bound {
                    return Err(format!(
                        "part {part}, chunk {chunk}: a DWA counter claims {v}, more than its block of {block_pixels} pixels can hold"
                    ));
                }
            }
        }
    }
    Ok(())
}

fn decode_hdr(bytes: &[u8], path: &Path, options: &LoadOptions, latlong: bool) -> Result<Decoded, EnvMapError> {
    use image::ImageDecoder;
    let err = |reason: String| EnvMapError::Decode {
        path: path.to_path_buf(),
        format: "Radiance HDR",
        reason: one_line(&reason),
    };
    let decoder = image::codecs::hdr::HdrDecoder::new(Cursor::new(bytes)).map_err(|e| err(e.to_string()))?;
    let (w, h) = decoder.dimensions();
    let (w, h) = check_size(path, u64::from(w), u64::from(h), options, latlong)?;
    // decoded straight into the pixels (f32 RGB in native byte order): one buffer, not two
    let mut pixels = vec![Vec3::ZERO; w as usize * h as usize];
    let buf: &mut [u8] = bytemuck::cast_slice_mut(&mut pixels);
    if buf.len() as u64 != decoder.total_bytes() {
        return Err(err(format!("decoder wants {} bytes for {w} x {h} RGB f32", decoder.total_bytes())));
    }
    decoder.read_image(buf).map_err(|e| err(e.to_string()))?;
    // Radiance's PRIMARIES line is ignored, as Mitsuba 3 and most readers do (files in the wild
    // often carry all zeros there).
    Ok(Decoded {
        width: w,
        height: h,
        pixels,
        format: FileFormat::Hdr,
        compression: "rle".into(),
        converted_from: None,
        warnings: Vec::new(),
    })
}

/// Applies the non-finite and negative policies in place.
fn sanitize(
    pixels: &mut [Vec3],
    width: u32,
    height: u32,
    path: &Path,
    options: &LoadOptions,
    report: &mut LoadReport,
) -> Result<(), EnvMapError> {
    let path: PathBuf = path.to_path_buf();
    // counted, not collected: a broken file may be all NaN
    if let Some(first) = pixels.iter().position(|p| !p.is_finite()) {
        let count: usize = pixels[first..].iter().map(|p| p.to_array().iter().filter(|c| !c.is_finite()).count()).sum();
        match options.non_finite {
            NonFinitePolicy::Error => {
                return Err(EnvMapError::NonFinite {
                    path,
                    count,
                    first_i: (first % width as usize) as u32,
                    first_j: (first / width as usize) as u32,
                });
            }
            NonFinitePolicy::Zero => {
                for p in pixels[first..].iter_mut().filter(|p| !p.is_finite()) {
                    *p = Vec3::from_array(p.to_array().map(|c| if c.is_finite() { c } else { 0.0 }));
                }
                report.non_finite_zeroed = count;
            }
        }
    }
    let (mut negative, mut positive, mut count) = (0.0f64, 0.0f64, 0usize);
    for j in 0..height {
        let sa = crate::latlong::latlong_texel_solid_angle(j, width, height);
        for p in &pixels[(j * width) as usize..((j + 1) * width) as usize] {
            for c in p.to_array() {
                if c < 0.0 {
                    negative -= f64::from(c) * sa;
                    count += 1;
                } else {
                    positive += f64::from(c) * sa;
                }
            }
        }
    }
    if count == 0 {
        return Ok(());
    }
    let fraction = if positive > 0.0 { negative / positive } else { f64::INFINITY };
    let limit = match options.negative {
        NegativePolicy::Keep => {
            report.negative_power_fraction = fraction;
            return Ok(());
        }
        NegativePolicy::Strict => 0.0,
        NegativePolicy::Clamp { max_power_fraction } => max_power_fraction,
    };
    if options.negative == NegativePolicy::Strict || fraction > limit {
        return Err(EnvMapError::Negative { path, count, fraction, limit });
    }
    pixels.iter_mut().for_each(|p| *p = p.max(Vec3::ZERO));
    report.negatives_clamped = count;
    report.negative_power_fraction = fraction;
    Ok(())
}
