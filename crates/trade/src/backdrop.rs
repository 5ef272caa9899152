//! Compositing onto a user's HDRI (the backdrop): the map's decomposition as the sources, its
//! ground-projected lower hemisphere as the real scene ([`real_scene::Backdrop`]), the
//! compositor built on them; and on the CPU the truth and the offline baseline, both the local
//! scene (the ground with its estimated reflectance, the map around it) path traced with and
//! without the object, differentially, as a shadow catcher does.

use std::time::{Duration, Instant};

use differential_composite::{CompositeError, Compositor, SyntheticObject};
use envmap_sphere::EnvMap;
use glam::Vec3;
use light_extract::LightExtractor;
use real_scene::{Backdrop, CameraResponse, PhotoGround, Photograph, luminance};
use ref_tracer::SceneBvh;
use scene::DistantLight;
use shaft_hierarchy::preprocess::{PreprocessSettings, build};

/// The extraction of a backdrop's lights: the default method's, without its signed residual
/// (the sources must be light that an object can block).
pub const BACKDROP_METHOD: &str = "emissive-split+moment-cones+above-horizon";

/// The widest EnvDirect shaded per pixel on the object (3 degrees): a compact sun, which SH9
/// rings around; wider lights are smooth enough for SH9 (measured on `venice_sunset_1k.hdr`,
/// whose 9-degree glows per pixel made the sphere's error 1.9 -> 3.0 codes).
pub const COMPACT_HALF_ANGLE: f32 = 0.052;

/// A backdrop's pruning of the shaft hierarchy: a source-receiver pair below this fraction of
/// every reached vertex's radiance is dropped (the paper's 2 % drops a sunny sky's every dim
/// source).
pub const BACKDROP_PRUNE: f32 = 0.002;

/// Knobs of a backdrop session.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BackdropSettings {
    /// The ground projection.
    pub backdrop: Backdrop,
    /// Lights extracted from the map ([`BACKDROP_METHOD`]).
    pub lights: usize,
    /// Cones the rest of the sky above the horizon is split into (median cut), shadow sources
    /// for the soft shadow an overcast sky casts.
    pub residual_lights: usize,
    /// n x n positions a backplate pixel averages.
    pub plate_samples: u32,
    /// The truth's ground texture, texels a side.
    pub ground_texels: u32,
    /// The shaft hierarchy's pre-processing.
    pub preprocess: PreprocessSettings,
}

impl Default for BackdropSettings {
    fn default() -> Self {
        Self {
            backdrop: Backdrop {
                camera_height: Backdrop::DEFAULT_CAMERA_HEIGHT,
                ground_radius: Backdrop::DEFAULT_GROUND_RADIUS,
                segments: Backdrop::DEFAULT_SEGMENTS,
            },
            lights: 32,
            residual_lights: 32,
            plate_samples: 4,
            ground_texels: 2048,
            // every source of the sky (the ground lights nothing it could darken), and pairs
            // down to 0.2 % of a vertex's radiance: a sky of many dim sources each below the
            // paper's 2 % casts a contact shadow they make together
            preprocess: PreprocessSettings {
                source_share: 1.0,
                patch_sources: false,
                hierarchy: shaft_hierarchy::Settings {
                    prune_fraction: BACKDROP_PRUNE,
                    ..shaft_hierarchy::Settings::PAPER
                },
                ..PreprocessSettings::PAPER
            },
        }
    }
}

/// Refuses an image size of 0 or over 8192 a side, and a camera below the ground or not a view.
fn check_view(camera: &scene::Camera) -> Result<(), CompositeError> {
    let (w, h) = (camera.width, camera.height);
    if w == 0 || h == 0 || w > 8192 || h > 8192 {
        return Err(CompositeError::Parameter(format!("image size {w} x {h} (1 to 8192 a side)")));
    }
    Backdrop::check_camera(camera)?;
    Ok(())
}

/// A map's shadow sources above the ground: its extracted lights, then the rest of its upper
/// hemisphere split by median cut into `residual` cones (those with any power). Returns the
/// sources, how many of them are the extracted lights, and the extraction's compact EnvDirects
/// (its emissive lights no wider than [`COMPACT_HALF_ANGLE`]: the suns an object is shaded by
/// per pixel).
///
/// # Errors
/// [`CompositeError::Parameter`] when an extraction fails.
pub fn sources(
    map: &EnvMap,
    lights: usize,
    residual: usize,
) -> Result<(Vec<DistantLight>, usize, Vec<DistantLight>), CompositeError> {
    let failed = |e: light_extract::ExtractError| CompositeError::Parameter(format!("light extraction: {e}"));
    let d = light_extract::extractor(BACKDROP_METHOD, lights.max(1))
        .ok_or_else(|| CompositeError::Parameter(format!("unknown extraction method {BACKDROP_METHOD:?}")))?
        .extract(map)
        .map_err(failed)?;
    let mut out: Vec<DistantLight> = d.distant_lights();
    let main = out.len();
    let direct = d
        .lights
        .iter()
        .filter(|l| !l.indirect && l.light.half_angle() <= COMPACT_HALF_ANGLE)
        .map(|l| l.light)
        .collect();
    if residual > 0 {
        let sky = light_extract::upper_hemisphere(&d.ambient, Vec3::Y);
        let rest = light_extract::MedianCut::with_lights(residual).extract(&sky).map_err(failed)?;
        out.extend(
            rest.distant_lights()
                .into_iter()
                .filter(|l| l.direction.y > 0.0 && l.power().max_element() > 0.0 && l.power().is_finite()),
        );
    }
    Ok((out, main, direct))
}

/// A backdrop compositing session: the map, the view, the compositor and the truth's ground.
pub struct BackdropSession {
    /// The map (in photograph mode the light probe).
    pub map: EnvMap,
    /// The ground projection.
    pub backdrop: Backdrop,
    /// The compositor: the ground as the real scene, the backplate as the photograph.
    pub compositor: Compositor,
    /// The truth's ground and its reflectance texture.
    pub ground: (scene::Object, scene::Texture),
    /// Extracted lights and residual cones among the sources.
    pub lights: (usize, usize),
    /// In photograph mode, how the photograph was fitted to the probe.
    pub photo: Option<PhotoFit>,
}

/// How a photograph was fitted to its probe ([`BackdropSession::with_photo`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotoFit {
    /// The scale that brought the photograph to the probe's units.
    pub exposure: f32,
    /// Pixels whose clipped channels the probe raised ([`PhotoGround`]).
    pub raised: usize,
}

impl BackdropSession {
    /// The session for `map` seen by `camera`: the backplate is the map, its lower hemisphere
    /// projected onto the ground.
    ///
    /// # Errors
    /// A camera below the ground or not a view, a size of 0 or over 8192, an extraction or a
    /// hierarchy that fails.
    pub fn new(map: EnvMap, camera: scene::Camera, settings: &BackdropSettings) -> Result<Self, CompositeError> {
        check_view(&camera)?;
        Self::build(map, camera, settings, None)
    }

    /// The session for a user's `photo` taken by `camera` (its size the photograph's) where
    /// `probe` was captured (the backdrop's centre of projection: `settings.backdrop`'s
    /// height above the ground under the origin). The photograph is brought to the probe's
    /// units by [`Photograph::exposure_against`] what the probe sees along each pixel's ray;
    /// its ground pixels are the receivers ([`PhotoGround`]).
    ///
    /// # Errors
    /// As [`BackdropSession::new`]; a photograph of another size than the camera's, or one
    /// with too few pixels to match its exposure (black, or clipped throughout).
    pub fn with_photo(
        probe: EnvMap,
        photo: &Photograph,
        camera: scene::Camera,
        settings: &BackdropSettings,
    ) -> Result<Self, CompositeError> {
        check_view(&camera)?;
        let backdrop = settings.backdrop;
        let seen = backdrop.plate(&probe, &camera, 1);
        let scale = photo.exposure_against(&seen).ok_or_else(|| {
            CompositeError::Parameter(
                "the photograph's exposure cannot be matched to the probe's: fewer than 16 pixels lit and unclipped"
                    .into(),
            )
        })?;
        let ground = PhotoGround::new(backdrop, &probe, (photo, scale), camera)?;
        Self::build(probe, camera, settings, Some((ground, scale, photo.gamma)))
    }

    /// The session, its camera checked; `photo` is a photograph's ground, its exposure and its
    /// response's gamma.
    fn build(
        map: EnvMap,
        camera: scene::Camera,
        settings: &BackdropSettings,
        photo: Option<(PhotoGround, f32, f32)>,
    ) -> Result<Self, CompositeError> {
        let (w, h) = (camera.width, camera.height);
        let backdrop = settings.backdrop;
        let (lights, main, mut direct) = sources(&map, settings.lights, settings.residual_lights)?;
        let e = Backdrop::ground_irradiance(&map);
        let radiance = |p: Vec3| match &photo {
            Some((g, ..)) => g.radiance(&map, p),
            None => backdrop.ground_radiance(&map, p),
        };
        let model = backdrop.real_scene_from(&radiance, e, &camera);
        let ground = backdrop.ground_from(&radiance, e, settings.ground_texels);
        // each receiver pixel's own reflectance: the ground point its centre ray meets (the
        // photograph's pixel itself in photograph mode)
        let camera_rays = camera.rays();
        let per_pixel: Vec<Vec3> = (0..w * h)
            .map(|k| {
                let (o, d) = camera_rays.ray((k % w) as f32 + 0.5, (k / w) as f32 + 0.5);
                backdrop.ground_hit(o, d).map_or(Vec3::ZERO, |p| match &photo {
                    Some((g, ..)) => Backdrop::reflectance(g.plate[k as usize], e),
                    None => Backdrop::reflectance(backdrop.ground_radiance(&map, p), e),
                })
            })
            .collect();
        let (plate, response, clip, fit) = match photo {
            Some((g, exposure, gamma)) => {
                let response = match g.clip {
                    // the photograph's own clip is the response's white
                    Some(c) if c > 0.0 => CameraResponse { exposure: 1.0 / c, gamma, white: 1.0 },
                    _ => CameraResponse { gamma, ..CameraResponse::auto(&g.plate) },
                };
                (g.plate, response, g.clip, Some(PhotoFit { exposure, raised: g.raised }))
            }
            None => {
                let plate = backdrop.plate(&map, &camera, settings.plate_samples);
                let response = CameraResponse::auto(&plate);
                (plate, response, None, None)
            }
        };
        let bvh = SceneBvh::new(&model.to_scene());
        let built = build(&model, &lights, &bvh, &settings.preprocess)?;
        // the compositor's own ray queries: the BVH the pre-process used
        let rays = Box::new(bvh);
        let mut compositor = Compositor::new(model, lights, Some(map.clone()), built, plate, response, rays)?
            .with_pixel_reflectance(&per_pixel)?;
        compositor.clip = clip;
        // the object: its suns per pixel (SH9 rings around a sun), the rest of the map by SH9
        direct.sort_by(|a, b| luminance(b.power()).total_cmp(&luminance(a.power())));
        direct.truncate(differential_composite::gpu::MAX_OBJECT_LIGHTS);
        let mut sh = envmap_sphere::Sh9::project(&map);
        for l in &direct {
            for (c, y) in sh.coeffs.iter_mut().zip(envmap_sphere::sh::sh9_basis(l.direction)) {
                *c -= l.power() * y;
            }
        }
        compositor.probe = differential_composite::ObjectProbe::Map(sh);
        compositor.object_lights = direct;
        compositor.object_replaces_sources = true;
        compositor.object_shadows_probe = true;
        let residual = compositor.lights.len() - main;
        Ok(Self { map, backdrop, compositor, ground, lights: (main, residual), photo: fit })
    }

    /// The local scene path traced with `object` and without it, `spp` samples a pixel each
    /// (the same seed, so their noise cancels where the object changes nothing), composed as
    /// a differential render: the object's own radiance where a pixel's centre sees it, the
    /// backplate plus the difference elsewhere. HDR, row-major, and the time it took.
    #[must_use]
    pub fn differential(&self, object: &SyntheticObject, spp: u32, seed: u64) -> (Vec<Vec3>, Duration) {
        let t = Instant::now();
        let c = &self.compositor;
        let mut local = scene::Scene {
            name: "backdrop".into(),
            objects: vec![self.ground.0.clone()],
            camera: c.model.camera,
            point_lights: Vec::new(),
            textures: vec![self.ground.1.clone()],
        };
        let env = ref_tracer::EnvLight::new(&self.map);
        let settings = ref_tracer::RenderSettings { spp: spp.max(1), seed, ..ref_tracer::RenderSettings::default() };
        let integrator = ref_tracer::Integrator::Path { max_depth: 4 };
        let without =
            ref_tracer::render(&local, &SceneBvh::new(&local), Some(&env), &integrator, &settings, &|_, _| {});
        local.objects.push(object.to_object());
        let with = ref_tracer::render(&local, &SceneBvh::new(&local), Some(&env), &integrator, &settings, &|_, _| {});
        let image = (0..c.photo_hdr.len())
            .map(|k| {
                if with.object_id.get(k) == Some(&1) {
                    with.color[k]
                } else {
                    (c.photo_hdr[k] + with.color[k] - without.color[k]).max(Vec3::ZERO)
                }
            })
            // the camera's clip, where the photograph has one
            .map(|l: Vec3| match c.clip {
                Some(clip) => l.min(Vec3::splat(clip)),
                None => l,
            })
            .collect();
        (image, t.elapsed())
    }

    /// [`BackdropSession::differential`] through the camera response (8-bit).
    #[must_use]
    pub fn codes(&self, hdr: &[Vec3]) -> Vec<[u8; 3]> {
        hdr.iter().map(|v| self.compositor.response.apply(*v)).collect()
    }
}
