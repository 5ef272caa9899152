//! HDR environment maps on the sphere: the base every other envshadow crate stands on.
//!
//! - [`EnvMap`]: lat-long linear RGB radiance; load `.exr` (every compression the `exr` crate
//!   decodes, DWAB included) and Radiance `.hdr` with typed errors and explicit policies for
//!   NaN, negative values and absurd sizes ([`LoadOptions`]); save `.exr` and `.png` previews.
//! - Parameterizations, each with direction -> coordinates, the inverse and the Jacobian:
//!   [`latlong`], [`cube`], [`paraboloid`] (hemispherical and dual), and resampling between
//!   them ([`SphereImage`], solid-angle weighted).
//! - Integrals: radiant power, irradiance, luminance statistics ([`EnvMap::power`],
//!   [`EnvMap::irradiance`], [`EnvMap::luminance_stats`]); [`Sh9`] projection and the
//!   Ramamoorthy-Hanrahan irradiance.
//! - Sampling in pbrt's style ([`EnvDistribution`]: `sample_dir` / `dir_pdf` /
//!   `invert_dir_sample`, O(1) on average through guide tables, monotonic so stratified points
//!   stay stratified), and a [`SummedAreaTable`] with f64 sums.
//! - [`default_map`]: a real CC0 map embedded in the library (the repository's eleven CC0 test
//!   maps are the `test-set` harness crate's).
//!
//! Conventions (docs/conventions.md): right-handed, +Y up; linear Rec.709 radiance;
//! Y = 0.2126 R + 0.7152 G + 0.0722 B; lat-long pixel (i, j) from the top-left,
//! u = (i + 0.5)/W, v = (j + 0.5)/H, phi = 2 pi u, theta = pi v,
//! dir = (sin theta sin phi, cos theta, -sin theta cos phi) — Mitsuba 3's orientation.
//!
//! ```
//! use envmap_sphere::{EnvMap, EnvDistribution, Sh9};
//! use glam::{Vec2, Vec3};
//! let map = envmap_sphere::default_map();
//! let sh = Sh9::project(&map);
//! let e_up = sh.irradiance(Vec3::Y);
//! let brute = map.resize(128, 64).irradiance(Vec3::Y);
//! assert!((e_up - brute).length() < 0.1 * brute.length());
//! let sample = EnvDistribution::new(&map).sample_dir(Vec2::new(0.5, 0.5));
//! assert!(sample.pdf > 0.0);
//! ```

pub mod color;
pub mod cube;
mod default;
pub mod distribution;
mod envmap;
pub mod error;
mod integrate;
pub mod io;
pub mod latlong;
pub mod layout;
pub mod paraboloid;
pub mod sat;
pub mod sh;
pub mod tonemap;

pub use color::{Chromaticities, luminance};
pub use default::{DEFAULT_MAP_CREDIT, DEFAULT_MAP_NAME, default_map, default_map_bytes};
pub use distribution::{DirSample, Distribution1D, EnvDistribution};
pub use envmap::{EnvMap, texel_centre_dir};
pub use error::EnvMapError;
pub use integrate::LuminanceStats;
pub use io::{
    FileFormat, LoadOptions, LoadReport, NegativePolicy, NonFinitePolicy, PrimariesPolicy, RgbImage, load_rgb_image,
    load_rgb_image_from_bytes,
};
pub use layout::{Layout, RadianceSource, SphereImage};
pub use sat::SummedAreaTable;
pub use sh::Sh9;
pub use tonemap::Tonemap;
