//! What an extraction produces: lights, the ambient remainder and its SH9 irradiance, and the
//! power books.

use envmap_sphere::{EnvMap, Sh9};
use glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg32;
use scene::DistantLight;
use scene::brdf::Frame;
use std::borrow::Cow;

/// One extracted light: a distant cone and the extent of the pixel cluster it stands for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExtractedLight {
    /// Direction, solid angle and mean radiance of the cone; power = radiance x solid angle.
    pub light: DistantLight,
    /// Angular radius of the cluster of texels the light replaces, radians.
    pub extent: f32,
    /// One of paper 001's EnvIndirects (a low-frequency cluster of non-emissive texels), which
    /// a renderer may shade at reduced resolution; `false` for every other light.
    pub indirect: bool,
}

impl ExtractedLight {
    /// RGB power: radiance x solid angle (the irradiance it gives a surface facing it).
    #[must_use]
    pub fn power(&self) -> Vec3 {
        self.light.power()
    }
}

/// Errors of light extraction.
#[derive(Debug, thiserror::Error)]
pub enum ExtractError {
    /// A parameter is outside its range.
    #[error("invalid parameter: {0}")]
    Parameter(String),
}

/// Why a decomposition's files could not be written; the message names the file.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// Creating the folder or writing a file failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The folder or file.
        path: std::path::PathBuf,
        /// The reason.
        source: std::io::Error,
    },
    /// A JSON document could not be serialized.
    #[error("{}: {source}", path.display())]
    Json {
        /// The file.
        path: std::path::PathBuf,
        /// The reason.
        source: serde_json::Error,
    },
    /// An image (EXR or PNG) could not be written; the error names its file.
    #[error(transparent)]
    Image(#[from] envmap_sphere::EnvMapError),
}

/// An environment map decomposed into lights and an ambient remainder.
#[derive(Clone, Debug)]
pub struct Decomposition {
    /// Method name, as in `lights.json`.
    pub method: String,
    /// The method's parameters, as in `lights.json`.
    pub params: serde_json::Value,
    /// The shadow-casting lights.
    pub lights: Vec<ExtractedLight>,
    /// The map with the lights' texels removed (zero where a light took them).
    pub ambient: EnvMap,
    /// SH9 projection of the ambient remainder (its irradiance is the unshadowed ambient term).
    pub ambient_sh: Sh9,
    /// Radiant power of the input map per channel.
    pub map_power: [f64; 3],
    /// Whether the lights partition the map's texels (light + remainder power = map power).
    pub partitions: bool,
    /// Wall time of the extraction, milliseconds.
    pub time_ms: f64,
}

impl Decomposition {
    /// Assembles a decomposition, projecting the remainder to SH9.
    #[must_use]
    pub fn new(
        method: &str,
        params: serde_json::Value,
        map: &EnvMap,
        lights: Vec<ExtractedLight>,
        ambient: EnvMap,
        partitions: bool,
    ) -> Self {
        let ambient_sh = Sh9::project(&ambient);
        Self {
            method: method.into(),
            params,
            lights,
            ambient,
            ambient_sh,
            map_power: map.power(),
            partitions,
            time_ms: 0.0,
        }
    }

    /// Total RGB power of the lights.
    #[must_use]
    pub fn light_power(&self) -> [f64; 3] {
        let p: glam::DVec3 = self.lights.iter().map(|l| l.power().as_dvec3()).sum();
        p.to_array()
    }

    /// The books: max over channels of |light + ambient - map| / map power (0 for a black map).
    #[must_use]
    pub fn power_balance_error(&self) -> f64 {
        let (l, a, m) = (self.light_power(), self.ambient.power(), self.map_power);
        (0..3)
            .map(|c| if m[c] > 0.0 { (l[c] + a[c] - m[c]).abs() / m[c] } else { (l[c] + a[c]).abs() })
            .fold(0.0, f64::max)
    }

    /// Puts the EnvDirects before the EnvIndirects (order kept within each), as renderers that
    /// shade the EnvIndirects apart take them; returns how many EnvDirects there are.
    pub fn sort_directs_first(&mut self) -> usize {
        self.lights.sort_by_key(|l| l.indirect);
        self.directs()
    }

    /// How many lights are not EnvIndirects.
    #[must_use]
    pub fn directs(&self) -> usize {
        self.lights.iter().filter(|l| !l.indirect).count()
    }

    /// The lights as renderers take them.
    #[must_use]
    pub fn distant_lights(&self) -> Vec<DistantLight> {
        self.lights.iter().map(|l| l.light).collect()
    }

    /// The extra light sets of interleaved sampling with the paper's defaults
    /// ([`INTERLEAVED_SETS`] sets in all, the first being the lights themselves, which is left
    /// out here; [`INTERLEAVED_JITTER`]; seed 0).
    #[must_use]
    pub fn interleaved(&self) -> Vec<Vec<ExtractedLight>> {
        interleaved_sets(&self.lights, INTERLEAVED_SETS, INTERLEAVED_JITTER, 0).split_off(1)
    }

    /// [`Decomposition::interleaved`] as renderers take them.
    #[must_use]
    pub fn interleaved_distant_lights(&self) -> Vec<Vec<DistantLight>> {
        self.interleaved().iter().map(|set| set.iter().map(|l| l.light).collect()).collect()
    }
}

/// Paper 001, section 3.5: light sets of interleaved sampling, the lights included.
pub const INTERLEAVED_SETS: usize = 8;
/// Paper 001, section 3.5: each extra set perturbs a light's direction within this fraction of
/// its cluster's extent.
pub const INTERLEAVED_JITTER: f32 = 0.1;

/// Paper 001's interleaved sampling (section 3.5): `sets` light sets, the first the lights
/// themselves, the others with each direction perturbed uniformly within a cone of half-angle
/// `jitter` x its extent (paper: 0.1). Fixed seed: the same input gives the same sets.
#[must_use]
pub fn interleaved_sets(lights: &[ExtractedLight], sets: usize, jitter: f32, seed: u64) -> Vec<Vec<ExtractedLight>> {
    let mut rng = Pcg32::seed_from_u64(seed);
    (0..sets)
        .map(|k| {
            lights
                .iter()
                .map(|l| {
                    if k == 0 {
                        return *l;
                    }
                    let cos_max = (jitter * l.extent).cos();
                    let cos = 1.0 - rng.random::<f32>() * (1.0 - cos_max);
                    let sin = (1.0 - cos * cos).max(0.0).sqrt();
                    let phi = rng.random::<f32>() * std::f32::consts::TAU;
                    let f = Frame::new(l.light.direction);
                    let d = f.to_world(Vec3::new(sin * phi.cos(), sin * phi.sin(), cos)).normalize();
                    ExtractedLight { light: DistantLight { direction: d, ..l.light }, ..*l }
                })
                .collect()
        })
        .collect()
}

/// A method that decomposes a map. Parameters live in the implementing type.
pub trait LightExtractor {
    /// Decomposes `map`.
    ///
    /// # Errors
    /// [`ExtractError::Parameter`] when a parameter is out of range.
    fn extract(&self, map: &EnvMap) -> Result<Decomposition, ExtractError>;

    /// The light budget K, for methods that take one.
    fn budget(&self) -> Option<usize> {
        None
    }

    /// The same extractor with a budget of `lights` (`None` for methods without a budget).
    fn with_budget(&self, lights: usize) -> Option<Box<dyn LightExtractor>> {
        let _ = lights;
        None
    }

    /// The part of `map` the lights and remainder stand for (what the books cover): the map
    /// itself, except for wrappers that hand their inner method less ([`crate::AboveHorizon`]).
    fn modelled_map<'m>(&self, map: &'m EnvMap) -> Cow<'m, EnvMap> {
        Cow::Borrowed(map)
    }
}

impl<T: LightExtractor + ?Sized> LightExtractor for Box<T> {
    fn extract(&self, map: &EnvMap) -> Result<Decomposition, ExtractError> {
        (**self).extract(map)
    }

    fn budget(&self) -> Option<usize> {
        (**self).budget()
    }

    fn with_budget(&self, lights: usize) -> Option<Box<dyn LightExtractor>> {
        (**self).with_budget(lights)
    }

    fn modelled_map<'m>(&self, map: &'m EnvMap) -> Cow<'m, EnvMap> {
        (**self).modelled_map(map)
    }
}
