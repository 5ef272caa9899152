//! Typed errors. File errors name the file and the reason; nothing here panics on bad input.

use std::path::PathBuf;

/// Everything that can go wrong when making, loading or saving an environment map.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum EnvMapError {
    /// The file could not be opened, read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// The file has no bytes.
    #[error("{path}: the file is empty")]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// Neither an OpenEXR nor a Radiance file, by extension or by magic number.
    #[error("{path}: not an OpenEXR (.exr) or Radiance (.hdr) image")]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// The decoder gave up: truncated data, a corrupt header or missing channels.
    #[error("{path}: cannot decode {format} image: {reason}")]
    Decode {
        /// The file.
        path: PathBuf,
        /// "OpenEXR", "Radiance HDR" or "PNG".
        format: &'static str,
        /// The decoder's reason.
        reason: String,
    },
    /// The header claims more pixels than the configured limit; refused before allocating.
    #[error(
        "{path}: {width} x {height} pixels exceeds the limit of {limit} pixels \
         (LoadOptions::max_pixels)"
    )]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Claimed width.
        width: u64,
        /// Claimed height.
        height: u64,
        /// The limit in force.
        limit: u64,
    },
    /// Width or height is zero (or the pixel buffer does not match them).
    #[error("{path}: invalid size {width} x {height}")]
    InvalidSize {
        /// The file, or `<memory>` for in-memory maps.
        path: PathBuf,
        /// Width.
        width: u64,
        /// Height.
        height: u64,
    },
    /// The aspect ratio is too far from 2:1 to be a lat-long map.
    #[error(
        "{path}: {width} x {height} is not a lat-long map (width/height must be between 1 and 4; \
         lat-long maps are 2:1)"
    )]
    NotLatLong {
        /// The file.
        path: PathBuf,
        /// Width.
        width: u64,
        /// Height.
        height: u64,
    },
    /// NaN or infinite pixels, refused under [`crate::NonFinitePolicy::Error`].
    #[error(
        "{path}: {count} pixel values are NaN or infinite (first at column {first_i}, row {first_j}); \
         load with NonFinitePolicy::Zero to zero them"
    )]
    NonFinite {
        /// The file.
        path: PathBuf,
        /// Number of non-finite channel values.
        count: usize,
        /// Column of the first one.
        first_i: u32,
        /// Row of the first one.
        first_j: u32,
    },
    /// Writing an image failed in the encoder.
    #[error("{path}: cannot write {format} image: {reason}")]
    Encode {
        /// The file.
        path: PathBuf,
        /// "OpenEXR" or "PNG".
        format: &'static str,
        /// The encoder's reason.
        reason: String,
    },
    /// Negative radiance beyond compression noise (or any, in strict mode).
    #[error(
        "{path}: {count} negative pixel values carrying {fraction:.3e} of the power \
         (limit {limit:.1e}): a broken file, not compression noise"
    )]
    Negative {
        /// The file.
        path: PathBuf,
        /// Number of negative channel values.
        count: usize,
        /// Negative power / positive power.
        fraction: f64,
        /// The limit in force.
        limit: f64,
    },
}

impl EnvMapError {
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io { path: path.into(), source }
    }
}

/// Path used in errors about maps that never came from a file.
pub const MEMORY_PATH: &str = "<memory>";

/// `text` on one line: line breaks, tabs and other control characters escaped as Rust writes
/// them (`\n`), so a decoder's reason or a name read from a file cannot break an error message
/// across lines.
#[must_use]
pub fn one_line(text: &str) -> String {
    if !text.chars().any(char::is_control) {
        return text.to_string();
    }
    text.chars().map(|c| if c.is_control() { c.escape_default().to_string() } else { c.to_string() }).collect()
}
