//! Shadow maps behind [`gpu::ShadowTechnique`]: a hard (or PCF) map from the light's centre,
//! PCSS on it, or the mean of N hard maps from directions spread over the light (Heckbert and
//! Herf 1997, paper 000's reference method).

use crate::mapper::{ShadowMapper, VisibilityTarget};
use crate::{ShadowLight, ShadowSettings, Technique, shadow_triangles};
use glam::Vec3;
use gpu::accumulate::{Accumulator, ResolvePass};
use gpu::{Gpu, GpuError, LightShape, Receivers, ShadowGeometry, ShadowPassReport, ShadowTechnique};
use std::rc::Rc;
use std::time::Duration;

/// A shadow-map technique for one scene: one setting of shared pipelines and geometry
/// ([`MapTechnique::variant`] makes others without rebuilding them).
pub struct MapTechnique {
    shared: Rc<Shared>,
    technique: Technique,
    settings: ShadowSettings,
    samples: u32,
}

/// What every setting of a scene's maps shares: pipelines and geometry.
struct Shared {
    mapper: ShadowMapper,
    triangles: Vec<[Vec3; 3]>,
    geometry: ShadowGeometry,
    resolve: ResolvePass,
}

/// `n` directions spread over the cone of half-angle `half_angle` about `axis`, uniform in
/// solid angle: a Vogel spiral through the cone's own sampling (`DistantLight::sample_direction`);
/// the centre alone for n = 1.
#[must_use]
pub fn cone_directions(axis: Vec3, half_angle: f32, n: u32) -> Vec<Vec3> {
    let axis = axis.normalize_or(Vec3::Y);
    if n <= 1 {
        return vec![axis];
    }
    let cone = scene::DistantLight {
        direction: axis,
        solid_angle: std::f32::consts::TAU * (1.0 - half_angle.clamp(0.0, std::f32::consts::FRAC_PI_2).cos()),
        radiance: Vec3::ZERO,
    };
    // the golden angle as a fraction of a turn
    let turn = 0.381_966_f32;
    (0..n)
        .map(|k| cone.sample_direction(glam::Vec2::new((k as f32 + 0.5) / n as f32, (k as f32 * turn).fract())).0)
        .collect()
}

impl MapTechnique {
    /// `technique` maps of `scene` with `settings`, the mean of `samples` maps per light
    /// (1: one map from the light's centre).
    ///
    /// # Errors
    /// Scenes beyond the buffer limits.
    pub fn new(
        gpu: &Gpu,
        scene: &scene::Scene,
        technique: Technique,
        settings: ShadowSettings,
        samples: u32,
    ) -> Result<Self, GpuError> {
        let triangles = gpu::scene_triangles(scene);
        let geometry = ShadowGeometry::upload(gpu, &triangles, ShadowGeometry::CHUNK_TRIANGLES)?;
        let shared = Shared { mapper: ShadowMapper::new(gpu), triangles, geometry, resolve: ResolvePass::new(gpu) };
        Ok(Self { shared: Rc::new(shared), technique, settings, samples: samples.max(1) })
    }

    /// Another setting on the same scene, sharing this one's pipelines and geometry.
    #[must_use]
    pub fn variant(&self, technique: Technique, settings: ShadowSettings, samples: u32) -> Self {
        Self { shared: Rc::clone(&self.shared), technique, settings, samples: samples.max(1) }
    }

    /// The shadow mapper (its pipelines).
    #[must_use]
    pub fn mapper(&self) -> &ShadowMapper {
        &self.shared.mapper
    }
}

impl ShadowTechnique for MapTechnique {
    fn name(&self) -> String {
        let res = self.settings.resolution;
        match (self.technique, self.samples, self.settings.pcss) {
            (Technique::Orthographic, 1, Some(p)) => format!("pcss_{res}_f{}", p.filter_samples),
            (Technique::Orthographic, 1, None) => format!("shadow_maps_{res}_pcf{}", self.settings.pcf_radius),
            (Technique::Orthographic, n, _) => format!("shadow_maps_{res}_x{n}"),
            (Technique::Cube, ..) => format!("cube_{res}"),
            (Technique::DualParaboloid, ..) => format!("paraboloid_{res}"),
        }
    }

    fn supports(&self, light: &LightShape) -> bool {
        match light {
            LightShape::Distant { .. } => self.technique == Technique::Orthographic,
            // point-light maps give a sphere light its centre's hard shadow
            LightShape::Sphere { .. } => self.technique != Technique::Orthographic && self.samples == 1,
        }
    }

    fn write_visibility(
        &self,
        gpu: &Gpu,
        receivers: &Receivers,
        light: &LightShape,
        target: &wgpu::TextureView,
    ) -> Result<ShadowPassReport, GpuError> {
        if !self.supports(light) {
            return Err(GpuError::Failed(format!("{} cannot shadow {light:?}", self.name())));
        }
        let settings = ShadowSettings { focus: self.settings.focus.or(receivers.focus), ..self.settings };
        let (lights, half_angle): (Vec<ShadowLight>, f32) = match *light {
            LightShape::Distant { direction, half_angle } => (
                cone_directions(direction, half_angle, self.samples)
                    .into_iter()
                    .map(|direction| ShadowLight::Distant { direction })
                    .collect(),
                half_angle,
            ),
            LightShape::Sphere { center, .. } => (vec![ShadowLight::omni(center)], 0.0),
        };
        let subdivided;
        let geometry = if self.technique == Technique::DualParaboloid && settings.subdivide_angle.is_some() {
            let t = shadow_triangles(&self.shared.triangles, &lights[0], self.technique, &settings);
            subdivided = ShadowGeometry::upload(gpu, &t, ShadowGeometry::CHUNK_TRIANGLES)?;
            &subdivided
        } else {
            &self.shared.geometry
        };
        let mut time = Duration::ZERO;
        let mut clock = None;
        let mut primitives = 0u64;
        let acc = if lights.len() > 1 { Some(Accumulator::new(gpu, receivers.gbuffer.size())?) } else { None };
        for (k, l) in lights.iter().enumerate() {
            let map = self.shared.mapper.render(gpu, geometry, l, self.technique, &settings)?;
            primitives += u64::from(map.triangles_drawn());
            let out = match &acc {
                Some(a) => VisibilityTarget::Add(a, k == 0),
                None => VisibilityTarget::Layer(target),
            };
            let (t, c) = gpu.measure(|encoder| {
                self.shared.mapper.record_visibility(gpu, encoder, &map, receivers.gbuffer, out, half_angle);
            })?;
            time += map.time + t;
            clock = Some(c);
        }
        if let Some(a) = &acc {
            let (t, _) = gpu.measure(|encoder| {
                let scale = [1.0 / lights.len() as f32, 0.0, 0.0, 0.0];
                self.shared.resolve.record(
                    gpu,
                    encoder,
                    receivers.gbuffer,
                    a,
                    bytemuck::cast_slice(&scale),
                    &[],
                    target,
                );
            })?;
            time += t;
        }
        Ok(ShadowPassReport { time, clock, skipped: None, primitives, culled: Vec::new() })
    }
}
