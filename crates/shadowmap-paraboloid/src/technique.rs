//! Shadow maps behind [`gpu::ShadowTechnique`]: a hard (or PCF) map from the light's centre,
//! PCSS on it, or the mean of N hard maps from directions spread over the light (Heckbert and
//! Herf 1997, paper 000's reference method).

use crate::mapper::{DepthCalls, ShadowMapper, VisibilityTarget};
use crate::{MapView, ShadowSettings, Technique, shadow_triangles};
use glam::Vec3;
use gpu::accumulate::{Accumulator, ResolvePass};
use gpu::{Gpu, GpuError, LightShape, Receivers, ShadowGeometry, ShadowPassReport, ShadowTechnique};
use std::cell::RefCell;
use std::rc::Rc;
use std::time::Duration;

/// A shadow-map technique for one scene: one setting of shared pipelines and geometry
/// ([`MapTechnique::variant`] makes others without rebuilding them).
pub struct MapTechnique {
    shared: Rc<Shared>,
    technique: Technique,
    settings: ShadowSettings,
    samples: u32,
    scratch: RefCell<Option<Scratch>>,
}

/// What every setting of a scene's maps shares: pipelines and geometry.
struct Shared {
    mapper: ShadowMapper,
    // the scene's triangles in chunks, updated in place when an object moves
    geometry: RefCell<ShadowGeometry>,
    // per object, its first triangle in the geometry and its triangle count
    objects: Vec<(usize, usize)>,
    resolve: ResolvePass,
}

/// A setting's scratch targets, reused from light to light (passes recorded in order).
#[derive(Clone)]
struct Scratch {
    key: ((u32, u32), (u32, u32), bool),
    map: wgpu::Texture,
    accumulator: Option<Accumulator>,
}

/// `n` directions spread over the cone of half-angle `half_angle` about `axis`, uniform in
/// solid angle: a Vogel spiral through the cone's own sampling (`DistantLight::sample_direction`);
/// the centre alone for n = 1.
#[must_use]
pub fn cone_sample_directions(axis: Vec3, half_angle: f32, n: u32) -> Vec<Vec3> {
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
        let triangles: Vec<Vec<[Vec3; 3]>> =
            scene.objects.iter().map(|o| (0..o.mesh.indices.len()).map(|t| o.mesh.triangle(t)).collect()).collect();
        let objects: Vec<&[[Vec3; 3]]> = triangles.iter().map(Vec::as_slice).collect();
        let geometry = ShadowGeometry::upload_objects(gpu, &objects, ShadowGeometry::CHUNK_TRIANGLES)?;
        let mut first = 0;
        let objects = scene
            .objects
            .iter()
            .map(|o| {
                let range = (first, o.mesh.indices.len());
                first += o.mesh.indices.len();
                range
            })
            .collect();
        let shared = Shared {
            mapper: ShadowMapper::new(gpu),
            geometry: RefCell::new(geometry),
            objects,
            resolve: ResolvePass::new(gpu),
        };
        Ok(Self { shared: Rc::new(shared), technique, settings, samples: samples.max(1), scratch: RefCell::new(None) })
    }

    /// Another setting on the same scene, sharing this one's pipelines and geometry.
    #[must_use]
    pub fn variant(&self, technique: Technique, settings: ShadowSettings, samples: u32) -> Self {
        Self {
            shared: Rc::clone(&self.shared),
            technique,
            settings,
            samples: samples.max(1),
            scratch: RefCell::new(None),
        }
    }

    /// Moves object `object` to its mesh in `scene` (same triangles, new positions: a pose
    /// change) without building anything: its triangles are written into the shadow geometry
    /// with `queue.write_buffer` and their chunks' bounds recomputed. Every variant sharing
    /// this one's geometry sees the new pose.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for an object out of range or with another triangle count.
    pub fn update_object(&self, gpu: &Gpu, scene: &scene::Scene, object: usize) -> Result<(), GpuError> {
        let (first, count) = self.shared.objects.get(object).copied().unwrap_or((0, usize::MAX));
        let mesh = scene.objects.get(object).map(|o| &o.mesh);
        let Some(mesh) = mesh.filter(|m| m.indices.len() == count) else {
            return Err(GpuError::Failed(format!(
                "shadow maps: object {object} is not the same mesh with new positions (triangles {:?}, had {count})",
                mesh.map(|m| m.indices.len())
            )));
        };
        let moved: Vec<[Vec3; 3]> = (0..count).map(|t| mesh.triangle(t)).collect();
        self.shared.geometry.borrow_mut().update(gpu, first, &moved)
    }

    /// Sets object `object`'s transform (from its mesh as this technique was made with, to the
    /// world): a rigid (or any affine) motion without building anything, one
    /// `queue.write_buffer`; the next depth pass places its vertices on the GPU. Every variant
    /// sharing this one's geometry sees it.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for an object out of range or a non-finite transform.
    pub fn set_transform(&self, gpu: &Gpu, object: usize, transform: glam::Affine3A) -> Result<(), GpuError> {
        if object >= self.shared.objects.len() {
            return Err(GpuError::Failed(format!("shadow maps: no object {object}")));
        }
        self.shared.geometry.borrow_mut().set_transform(gpu, object, transform)
    }

    /// The scratch targets for `size` images, `map` (resolution, layers) maps and an
    /// accumulator when `accumulate`; made when one of them changes.
    fn scratch(&self, gpu: &Gpu, size: (u32, u32), map: (u32, u32), accumulate: bool) -> Result<Scratch, GpuError> {
        let key = (size, map, accumulate);
        let mut cached = self.scratch.borrow_mut();
        if let Some(s) = cached.as_ref().filter(|s| s.key == key) {
            return Ok(s.clone());
        }
        let s = Scratch {
            key,
            map: gpu::render_target(gpu, "shadow map", (map.0, map.0, map.1), crate::mapper::DEPTH_FORMAT)?,
            accumulator: accumulate.then(|| Accumulator::new(gpu, size)).transpose()?,
        };
        *cached = Some(s.clone());
        Ok(s)
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

    fn record(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        receivers: &Receivers,
        light: &LightShape,
        gate: Option<gpu::Gate<'_>>,
        target: &wgpu::TextureView,
    ) -> Result<ShadowPassReport, GpuError> {
        if !self.supports(light) {
            return Err(GpuError::Failed(format!("{} cannot shadow {light:?}", self.name())));
        }
        let settings = ShadowSettings { focus: self.settings.focus.or(receivers.focus), ..self.settings };
        let (lights, half_angle): (Vec<MapView>, f32) = match *light {
            LightShape::Distant { direction, half_angle } => (
                cone_sample_directions(direction, half_angle, self.samples)
                    .into_iter()
                    .map(|direction| MapView::Distant { direction })
                    .collect(),
                half_angle,
            ),
            LightShape::Sphere { center, .. } => (vec![MapView::omni(center)], 0.0),
        };
        let shared = &self.shared;
        let subdivided;
        let geometry = shared.geometry.borrow();
        let geometry = if self.technique == Technique::DualParaboloid && settings.subdivide_angle.is_some() {
            let soup = geometry.triangle_soup();
            let t = shadow_triangles(&soup, &lights[0], self.technique, &settings);
            subdivided = ShadowGeometry::upload(gpu, &t, ShadowGeometry::CHUNK_TRIANGLES)?;
            &subdivided
        } else {
            &*geometry
        };
        let mut primitives = 0u64;
        let size = receivers.gbuffer.size();
        let layers = ShadowMapper::view_count(&lights[0], self.technique);
        let scratch = self.scratch(gpu, size, (settings.resolution, layers), lights.len() > 1)?;
        // every sample's calls (its depth draws, its visibility pass) and the resolve's go
        // through one gate: one gate pass a light, however many samples
        let into = Some((&scratch.map, 0));
        let mut args = Vec::new();
        let mut prepared = Vec::with_capacity(lights.len());
        for l in &lights {
            let p = shared.mapper.prepare(gpu, geometry, l, self.technique, &settings, into)?;
            let (depth, depth_args) = DepthCalls::of(geometry, &p);
            let first = args.len();
            args.extend(depth_args);
            // the sample's visibility pass follows its depth draws
            let visibility_call = args.len();
            args.push(gpu::Indirect::draw(0..3));
            prepared.push((p, depth, first, visibility_call));
        }
        let resolve_call = args.len();
        if scratch.accumulator.is_some() {
            args.push(gpu::Indirect::draw(0..3));
        }
        let calls = gpu::Calls::new(gpu, encoder, gate, args);
        let stats = receivers.on_gpu.as_ref();
        for (k, (l, (p, depth, first, visibility_call))) in lights.iter().zip(prepared).enumerate() {
            // one map texture for all of them: the passes run in the order recorded
            let lit = (l, &settings, stats);
            let map = shared.mapper.record_prepared(gpu, encoder, geometry, p, lit, (depth, &calls, first));
            primitives += u64::from(map.triangles_drawn());
            let out = match &scratch.accumulator {
                Some(a) => VisibilityTarget::Add(a, k == 0),
                None => VisibilityTarget::Layer(target),
            };
            let call = (&calls, visibility_call);
            shared.mapper.record_visibility(gpu, encoder, &map, receivers.gbuffer, out, half_angle, call);
        }
        if let Some(a) = &scratch.accumulator {
            let scale = [1.0 / lights.len() as f32, 0.0, 0.0, 0.0];
            let params = bytemuck::cast_slice(&scale);
            let call = Some((&calls, resolve_call));
            shared.resolve.record(gpu, encoder, receivers.gbuffer, a, params, &[], call, target)?;
        }
        Ok(ShadowPassReport { time: Duration::ZERO, clock: None, skipped: None, primitives, culled: Vec::new() })
    }
}
