//! The one technique builder: every shadow technique the trade, `validate` and the benches
//! measure is described by a [`TechniqueSpec`] and made by a [`TechniqueBuilder`], so a
//! technique's construction (and its defaults) is written once. [`traced_visibility`] is the
//! truth drawn as a technique: the lights' visibility ray traced on the CPU and uploaded.

use gpu::{GpuError, LightShape, PrecomputedVisibility, Receivers, ShadowTechnique};
use penumbra_wedge::{WedgeSettings, Wedges};
use ref_tracer::SceneBvh;
use ref_tracer::visibility::{Weighting, area_light_visibility_refined};
use shadowmap_paraboloid::{MapTechnique, ShadowSettings, Technique};

/// A technique with its name (a row label, a bench's family).
pub type Named<N> = (N, Box<dyn ShadowTechnique>);

/// How to make one shadow technique.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TechniqueSpec {
    /// Shadow maps: `projection` (orthographic for distant lights, paraboloid or cube for
    /// point lights) with `settings`, averaged over `samples` maps per cone light.
    Maps {
        /// The maps' projection.
        projection: Technique,
        /// Their knobs.
        settings: ShadowSettings,
        /// Maps per light (spread over a cone light's directions), at least 1.
        samples: u32,
    },
    /// Penumbra wedges (paper 000) with these knobs.
    Wedges(WedgeSettings),
}

impl TechniqueSpec {
    /// Orthographic maps with `settings`, `samples` per light (the distant lights' maps).
    #[must_use]
    pub fn orthographic(settings: ShadowSettings, samples: u32) -> Self {
        Self::Maps { projection: Technique::Orthographic, settings, samples }
    }

    /// Penumbra wedges with their default knobs.
    #[must_use]
    pub fn wedges() -> Self {
        Self::Wedges(WedgeSettings::default())
    }
}

/// Makes the techniques of one scene. Map techniques share one set of pipelines and shadow
/// geometry (the first one made is the others' source), so a list of map settings compiles its
/// shaders once.
pub struct TechniqueBuilder<'a> {
    gpu: &'a gpu::Gpu,
    scene: &'a scene::Scene,
    maps: Option<MapTechnique>,
}

impl<'a> TechniqueBuilder<'a> {
    /// A builder for `scene` on `gpu`.
    #[must_use]
    pub fn new(gpu: &'a gpu::Gpu, scene: &'a scene::Scene) -> Self {
        Self { gpu, scene, maps: None }
    }

    /// The technique `spec` describes.
    ///
    /// # Errors
    /// Scenes beyond the GPU's buffer limits.
    pub fn build(&mut self, spec: &TechniqueSpec) -> Result<Box<dyn ShadowTechnique>, GpuError> {
        Ok(match *spec {
            TechniqueSpec::Wedges(settings) => Box::new(Wedges::new(self.gpu, self.scene, settings)),
            TechniqueSpec::Maps { projection, settings, samples } => {
                let maps = match &mut self.maps {
                    Some(maps) => maps,
                    none => none.insert(MapTechnique::new(self.gpu, self.scene, projection, settings, samples)?),
                };
                Box::new(maps.variant(projection, settings, samples))
            }
        })
    }

    /// Every technique of `specs`, with its name.
    ///
    /// # Errors
    /// As [`TechniqueBuilder::build`].
    pub fn build_all<N: Clone>(&mut self, specs: &[(N, TechniqueSpec)]) -> Result<Vec<Named<N>>, GpuError> {
        specs.iter().map(|(name, spec)| Ok((name.clone(), self.build(spec)?))).collect()
    }
}

/// Ray-traced visibility of each of `shapes` from the receivers' points (2 × 2 stratified
/// directions, `n` × `n` in and next to penumbrae; pixels the light cannot reach stay lit),
/// weighted by the cosine as the shading needs it (`unshadowed irradiance × visibility`), as a
/// technique whose layers are these.
///
/// # Errors
/// Layers beyond the GPU's limits.
pub fn traced_visibility(
    gpu: &gpu::Gpu,
    scene: &scene::Scene,
    receivers: &Receivers,
    shapes: &[LightShape],
    n: u32,
) -> Result<PrecomputedVisibility, GpuError> {
    let bvh = SceneBvh::new(scene);
    let width = receivers.gbuffer.size().0 as usize;
    let layers = shapes
        .iter()
        .map(|s| {
            let v = area_light_visibility_refined(&bvh, receivers.points, *s, width, (2, n), Weighting::Cosine);
            (*s, v.into_iter().map(|v| v.unwrap_or(1.0)).collect())
        })
        .collect();
    PrecomputedVisibility::new(
        gpu,
        &format!("ray-traced visibility ({n}x{n} directions)"),
        receivers.gbuffer.size(),
        layers,
    )
}
