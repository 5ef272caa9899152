//! A compositing session on a built-in real scene: the real scene solved and photographed (the
//! capture), its reconstruction solved and pre-processed (what the compositor knows), and the
//! truth and Debevec's render for an object there.

use differential_composite::{CompositeError, Compositor, SyntheticObject};
use envmap_sphere::EnvMap;
use glam::Vec3;
use real_scene::{CameraResponse, Perturbation, RealScene, SolveSettings, estimate_reflectances, solve};
use ref_tracer::SceneBvh;
use scene::DistantLight;
use shaft_hierarchy::preprocess::{PreprocessSettings, build};

use crate::capture::{PhotoSettings, photograph};

/// Knobs of a session.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SessionSettings {
    /// Image size (the scene camera's when `None`).
    pub size: Option<(u32, u32)>,
    /// The photograph's path tracing (and the truth's and Debevec's, with their own seeds).
    pub photo: PhotoSettings,
    /// How the reconstruction differs from the real scene.
    pub reconstruction: Perturbation,
    /// Take the reconstruction's radiances from the capture (the real scene's solution) and
    /// estimate its reflectances from them, radiance over computed irradiance, as a capture
    /// does; otherwise solve the reconstruction with its own reflectances. Needs the
    /// reconstruction's patches to be the real scene's (`coarsen` 1).
    pub estimate_reflectances: bool,
    /// The shaft hierarchy's pre-processing.
    pub preprocess: PreprocessSettings,
}

impl Default for SessionSettings {
    fn default() -> Self {
        Self {
            size: None,
            photo: PhotoSettings { spp: 64, max_depth: 6, seed: 1 },
            reconstruction: Perturbation::NONE,
            estimate_reflectances: false,
            preprocess: PreprocessSettings::PAPER,
        }
    }
}

/// An environment-lit scene's map (the embedded one) and its `k` lights extracted by `method`
/// as distant sources; nothing for a scene lit by its own patches.
///
/// # Errors
/// An unknown method ([`CompositeError::Parameter`]); an extraction that fails.
pub fn environment(
    scene: &RealScene,
    method: &str,
    k: usize,
) -> Result<(Option<EnvMap>, Vec<DistantLight>), CompositeError> {
    if !scene.environment_lit {
        return Ok((None, Vec::new()));
    }
    let map = envmap_sphere::default_map();
    let d = light_extract::extractor(method, k)
        .ok_or_else(|| CompositeError::Parameter(format!("unknown extraction method {method:?}")))?
        .extract(&map)
        .map_err(|e| CompositeError::Parameter(format!("extraction ({method}): {e}")))?;
    Ok((Some(map), d.distant_lights()))
}

/// The real scene, its photograph and the compositor built from its reconstruction.
pub struct Session {
    /// The real scene, solved (the truth renders it).
    pub real: RealScene,
    /// The map lighting it, where it is environment-lit.
    pub map: Option<EnvMap>,
    /// The compositor (the reconstruction, the photograph, the hierarchy).
    pub compositor: Compositor,
    /// The settings.
    pub settings: SessionSettings,
}

impl Session {
    /// Solves and photographs the built-in real scene `name`, reconstructs it with
    /// `settings.reconstruction` and pre-processes the reconstruction. `map` and `lights` (the
    /// map's extracted lights, the distant sources) are for an environment-lit scene.
    ///
    /// # Errors
    /// An unknown scene, a map missing or not wanted, a size of zero, a hierarchy that cannot
    /// be built.
    pub fn new(
        name: &str,
        map: Option<EnvMap>,
        lights: Vec<DistantLight>,
        settings: &SessionSettings,
    ) -> Result<Self, CompositeError> {
        let sized = |mut s: RealScene| -> Result<RealScene, CompositeError> {
            if let Some((w, h)) = settings.size {
                if w == 0 || h == 0 || w > 8192 || h > 8192 {
                    return Err(CompositeError::Parameter(format!("image size {w} x {h} (1 to 8192 a side)")));
                }
                (s.camera.width, s.camera.height) = (w, h);
            }
            Ok(s)
        };
        let mut real = sized(RealScene::builtin(name)?)?;
        let solve_settings = SolveSettings::default();
        let real_bvh = SceneBvh::new(&real.to_scene());
        solve(&mut real, &real_bvh, map.as_ref(), &solve_settings)?;
        let photo = photograph(&real, map.as_ref(), &settings.photo)?.color;
        let response = CameraResponse::auto(&photo);
        let mut model = sized(RealScene::builtin_with(name, &settings.reconstruction)?)?;
        let model_bvh = SceneBvh::new(&model.to_scene());
        if settings.estimate_reflectances {
            if model.patches.len() != real.patches.len() {
                return Err(CompositeError::Parameter(
                    "estimating reflectances needs the real scene's patches (coarsen 1)".into(),
                ));
            }
            for (m, r) in model.patches.iter_mut().zip(&real.patches) {
                m.radiance = r.radiance;
            }
            estimate_reflectances(&mut model, &model_bvh, map.as_ref(), &solve_settings)?;
        } else {
            solve(&mut model, &model_bvh, map.as_ref(), &solve_settings)?;
        }
        let built = build(&model, &lights, &model_bvh, &settings.preprocess)?;
        // the compositor's own ray queries, against the model as solved
        let model_rays = Box::new(SceneBvh::new(&model.to_scene()));
        let compositor = Compositor::new(model, lights, map.clone(), built, photo, response, model_rays)?;
        Ok(Self { real, map, compositor, settings: *settings })
    }

    /// A built-in object at `at`, given from the scene's floor centre (x and z across the
    /// floor, y up from it).
    ///
    /// # Errors
    /// As [`SyntheticObject::builtin`].
    pub fn object(&self, name: &str, at: Vec3) -> Result<SyntheticObject, CompositeError> {
        SyntheticObject::builtin(name, self.real.floor_centre() + at)
    }

    /// The truth for `object`: the real scene photographed with it, through the response.
    ///
    /// # Errors
    /// As [`crate::offline::truth`].
    pub fn truth(&self, object: &SyntheticObject) -> Result<Vec<[u8; 3]>, CompositeError> {
        self.truth_with(object, &self.settings.photo)
    }

    /// The truth for `object` path traced with `photo` (e.g. another seed, for the truth's
    /// own noise), through the response.
    ///
    /// # Errors
    /// As [`crate::offline::truth`].
    pub fn truth_with(&self, object: &SyntheticObject, photo: &PhotoSettings) -> Result<Vec<[u8; 3]>, CompositeError> {
        let hdr = crate::offline::truth(&self.real, object, self.map.as_ref(), photo)?;
        Ok(hdr.iter().map(|c| self.compositor.response.apply(*c)).collect())
    }

    /// Debevec's differential rendering for `object` with the reconstruction, through the
    /// response; its renders use another seed than the photograph (an offline renderer does not
    /// share the photograph's noise).
    ///
    /// # Errors
    /// As [`crate::offline::debevec`].
    pub fn debevec(&self, object: &SyntheticObject) -> Result<Vec<[u8; 3]>, CompositeError> {
        let settings = PhotoSettings { seed: self.settings.photo.seed + 1000, ..self.settings.photo };
        let c = &self.compositor;
        let hdr = crate::offline::debevec(&c.model, object, self.map.as_ref(), &c.photo_hdr, &settings)?;
        Ok(hdr.iter().map(|v| c.response.apply(*v)).collect())
    }
}
