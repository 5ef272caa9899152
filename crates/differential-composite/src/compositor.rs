//! Paper 003's compositor (Sections 7-8), the part that does not depend on how masks are
//! made: the static setup (each pixel's receiver and bilinear weights, per-source colours, the
//! vertices' radiances) and each frame's transfers: traversal, the representative set, per
//! representative the summed radiance transfers L_ij at the receiver vertices (HDR) and the
//! intensity transfers S_ij of the two-set split (LDR, Figure 4). `cpu` and `gpu` make the
//! masks M_ij and subtract.

use std::time::{Duration, Instant};

use envmap_sphere::{EnvMap, Sh9};
use glam::Vec3;
use rand::{Rng, SeedableRng};
use rayon::prelude::*;
use real_scene::{CameraResponse, RealScene, Visibility, luminance};
use scene::DistantLight;
use shaft_hierarchy::preprocess::{Origin, Prepared, Source};
use shaft_hierarchy::{Occlusion, ShaftHierarchy, Traversal};

use crate::{CompositeError, SyntheticObject};

/// What a pixel of the photograph shows, for compositing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelRef {
    /// First transfer column (receiver vertex) of the receiver it shows, `u32::MAX` for none
    /// (background, or a patch that is not a receiver).
    pub slot: u32,
    /// Bilinear weights of the receiver's four vertices at the pixel.
    pub weights: [f32; 4],
    /// The surface point the pixel's centre ray hits (NaN where it misses).
    pub position: Vec3,
    /// Its unit normal, facing the camera.
    pub normal: Vec3,
}

impl PixelRef {
    const NONE: Self = Self { slot: u32::MAX, weights: [0.0; 4], position: Vec3::NAN, normal: Vec3::ZERO };
}

/// The compositor's knowledge of the real scene: its reconstruction (solved), the pre-process
/// and the photograph. Built once per scene and camera.
pub struct Compositor {
    /// The reconstructed model (radiosity solved).
    pub model: RealScene,
    /// Distant sources (an environment-lit scene's extracted lights).
    pub lights: Vec<DistantLight>,
    /// The map lighting the model, where it is environment-lit.
    pub map: Option<EnvMap>,
    /// Source set, receivers, transfers.
    pub prepared: Prepared,
    /// The shaft hierarchy.
    pub hierarchy: ShaftHierarchy,
    /// Image size.
    pub size: (u32, u32),
    /// The HDR photograph (row-major).
    pub photo_hdr: Vec<Vec3>,
    /// The camera's response.
    pub response: CameraResponse,
    /// The 8-bit photograph: the response applied to `photo_hdr`.
    pub photo_ldr: Vec<[u8; 3]>,
    /// Per pixel, its receiver.
    pub pixels: Vec<PixelRef>,
    /// Per receiver vertex, its radiance L_i (RGB): the model's, standing for the capture's.
    pub vertex_radiance: Vec<Vec3>,
    /// Per source, its colour over its luminance (RGB L_ij = scalar L_ij x this x the
    /// receiver's reflectance over its luminance).
    source_colour: Vec<Vec3>,
    /// Per receiver vertex, its reflectance over its luminance.
    vertex_colour: Vec<Vec3>,
    /// Per source, its set in the two-set split (paper: the parity of a random id).
    pub set_of: Vec<u8>,
    /// Per pixel, what its darkening is multiplied by: the pixel's own reflectance over its
    /// receiver's, where the photograph's texture varies within a patch (a backdrop's ground;
    /// [`Compositor::with_pixel_reflectance`]); 1 elsewhere.
    pub pixel_scale: Vec<Vec3>,
    /// How the object's irradiance probe sees the map ([`ObjectProbe`]).
    pub probe: ObjectProbe,
    /// Lights the object is shaded by per pixel (a sun: SH9 rings around it), each where its
    /// direction escapes the model from the object's centre; the probe leaves them out.
    pub object_lights: Vec<DistantLight>,
    /// Whether a blocked source's darkening is reduced by the object's own radiance seen in
    /// its place (the object hides the sky but reflects light itself): the transfer times
    /// 1 - L_object / L_sources per channel, L_object the object's radiance facing away from
    /// the representative's direction. `false`: the paper's, the source's light removed whole.
    pub object_replaces_sources: bool,
    /// Whether the object's irradiance probe sees the model darkened by the object's own
    /// shadow (each representative whose direction a sphere standing for the object blocks
    /// from the model point takes its transfer there): the light the object's underside gets
    /// back from the ground it shadows. `false`: the model as captured.
    pub object_shadows_probe: bool,
    /// The radiance the photograph saturates at, if it clips: the HDR composite is clipped
    /// there as the camera would have (its clipped pixels in `photo_hdr` may be raised above
    /// it, so that a shadow cast on them darkens from their estimated radiance).
    pub clip: Option<f32>,
    /// Per model patch, its index among the prepared receivers (`u32::MAX` for none).
    receiver_of: Vec<u32>,
    bvh: Box<dyn Visibility>,
}

/// How [`Compositor::irradiance_at`] takes the map: the object's lighting.
#[derive(Clone, Debug, PartialEq)]
pub enum ObjectProbe {
    /// Probe rays see the model and the map, except inside the cones of the first this many
    /// lights, which are added as their cones' power along their axes (a sun of a few texels
    /// is found by no probe ray).
    Lights(usize),
    /// The map's own SH9 projection, every texel exact (its sun included), with what probe rays
    /// find of the model in place of the map where they meet it: for a model that hides only a
    /// little of the sky (a backdrop's ground), whose lights tile the map.
    Map(Sh9),
}

/// One representative's share of a frame.
#[derive(Clone, Debug)]
pub struct RepTransfer {
    /// Where its shadow is cast from.
    pub origin: Origin,
    /// The source (hierarchy order) it is cast from: the one among its sources that sends the
    /// most.
    pub origin_source: u32,
    /// Its sources' summed RGB radiance transfer per receiver vertex (zero for receivers the
    /// object cannot darken).
    pub radiance: Vec<Vec3>,
    /// Its intensity transfer S per receiver vertex, in 8-bit codes (Figure 4).
    pub intensity: Vec<Vec3>,
    /// Its total transfer (luminance), the order of the split.
    pub transfer: f64,
    /// Sources it stands for.
    pub sources: u32,
    /// For a distant origin, the angular radius (radians) of the cone around its direction
    /// that holds every occluded source it stands for, their own cones included: its shadow's
    /// penumbra (0 for a point origin).
    pub half_angle: f32,
    /// The mean radiance over the solid angle of the distant sources it stands for (zero for
    /// patches).
    pub source_radiance: Vec3,
    /// What of its `radiance` a blocked receiver loses, per channel, where the object stands
    /// in its sources' place with its own radiance ([`Compositor::object_replaces_sources`]);
    /// 1 elsewhere. `radiance` is the sources' whole transfer: the darkening is it times this
    /// (the GPU's soft masks lift it toward 1 at contact, where the receiver sees the object's
    /// underside, not the side the sources face).
    pub keep: Vec3,
}

/// A frame's transfers.
#[derive(Clone, Debug, Default)]
pub struct FrameTransfers {
    /// Representatives, in decreasing transfer.
    pub reps: Vec<RepTransfer>,
    /// Sources the traversal reported.
    pub occluded_sources: usize,
    /// Receivers the traversal reported.
    pub occluded_receivers: usize,
    /// Traversal and representative set.
    pub traversal: Duration,
    /// Transfers (HDR and LDR).
    pub transfers: Duration,
    /// The object's irradiance probe.
    pub shading: Duration,
    /// The object's SH9 irradiance at its centre (its shading).
    pub object_irradiance: Sh9,
    /// The lights it is shaded by per pixel besides ([`Compositor::object_lights`] that reach
    /// its centre).
    pub object_lights: Vec<DistantLight>,
}

impl FrameTransfers {
    /// The object's irradiance for unit normal `n`: the probe's SH9 plus its lights.
    #[must_use]
    pub fn object_irradiance_at(&self, n: Vec3) -> Vec3 {
        let lights: Vec3 = self.object_lights.iter().map(|l| l.power() * n.dot(l.direction).max(0.0)).sum();
        self.object_irradiance.irradiance(n) + lights
    }
}

impl FrameTransfers {
    /// The frame's CPU work: traversal, transfers and the object's irradiance probe.
    #[must_use]
    pub fn cpu(&self) -> Duration {
        self.traversal + self.transfers + self.shading
    }
}

impl Compositor {
    /// The compositor for `model` (radiosity solved) photographed as `photo_hdr` through
    /// `response`, with `prepared` and `hierarchy` built from it; `model_rays` answers ray
    /// queries against the model, one object per patch of [`RealScene::to_scene`] (the
    /// caller's tracer: the compositor traces no rays of its own).
    ///
    /// # Errors
    /// [`CompositeError::Parameter`] when the photograph's size is not the model camera's.
    pub fn new(
        model: RealScene,
        lights: Vec<DistantLight>,
        map: Option<EnvMap>,
        (prepared, hierarchy): (Prepared, ShaftHierarchy),
        photo_hdr: Vec<Vec3>,
        response: CameraResponse,
        model_rays: Box<dyn Visibility>,
    ) -> Result<Self, CompositeError> {
        let size = (model.camera.width, model.camera.height);
        if photo_hdr.len() != size.0 as usize * size.1 as usize {
            return Err(CompositeError::Parameter(format!(
                "the photograph has {} pixels, the camera {} x {}",
                photo_hdr.len(),
                size.0,
                size.1
            )));
        }
        let bvh = model_rays;
        let photo_ldr = photo_hdr.iter().map(|c| response.apply(*c)).collect();
        let over_luminance = |c: Vec3| {
            let y = luminance(c);
            if y > 0.0 && y.is_finite() { c / y } else { Vec3::ZERO }
        };
        let source_colour = prepared
            .sources
            .iter()
            .map(|s| match *s {
                Source::Patch(j) => over_luminance(model.patches[j as usize].radiance),
                Source::Distant(k) => over_luminance(lights[k as usize].radiance),
            })
            .collect();
        let vertex_colour: Vec<Vec3> = prepared
            .receivers
            .iter()
            .flat_map(|&r| [over_luminance(model.patches[r as usize].reflectance); 4])
            .collect();
        let vertex_radiance =
            prepared.receivers.iter().flat_map(|&r| [model.patches[r as usize].radiance; 4]).collect();
        let mut rng = rand_pcg::Pcg32::seed_from_u64(3);
        let set_of = prepared.sources.iter().map(|_| (rng.random::<u32>() & 1) as u8).collect();
        let mut receiver_of = vec![u32::MAX; model.patches.len()];
        for (k, &r) in prepared.receivers.iter().enumerate() {
            receiver_of[r as usize] = k as u32;
        }
        let pixels = pixel_refs(&model, &receiver_of, bvh.as_ref());
        let pixel_scale = vec![Vec3::ONE; pixels.len()];
        let probe = ObjectProbe::Lights(lights.len());
        Ok(Self {
            model,
            lights,
            map,
            prepared,
            hierarchy,
            size,
            photo_hdr,
            response,
            photo_ldr,
            pixels,
            vertex_radiance,
            source_colour,
            vertex_colour,
            set_of,
            pixel_scale,
            probe,
            object_lights: Vec::new(),
            object_replaces_sources: false,
            object_shadows_probe: false,
            clip: None,
            receiver_of,
            bvh,
        })
    }

    /// Scales each receiver pixel's darkening by `reflectance` there (the photograph's own
    /// estimate, per pixel, row-major) over its receiver's reflectance: transfers are per
    /// patch, a textured ground is not, and a shadow darkens each texel in proportion to it.
    /// Channels where the receiver reflects nothing keep 1.
    ///
    /// # Errors
    /// [`CompositeError::Parameter`] when `reflectance` is not one value per pixel.
    pub fn with_pixel_reflectance(mut self, reflectance: &[Vec3]) -> Result<Self, CompositeError> {
        if reflectance.len() != self.pixels.len() {
            return Err(CompositeError::Parameter(format!(
                "{} reflectances for {} pixels",
                reflectance.len(),
                self.pixels.len()
            )));
        }
        for ((scale, px), rho) in self.pixel_scale.iter_mut().zip(&self.pixels).zip(reflectance) {
            if px.slot == u32::MAX {
                continue;
            }
            let patch = self.prepared.receivers[px.slot as usize / 4] as usize;
            let mine = self.model.patches[patch].reflectance;
            *scale = Vec3::from_array(std::array::from_fn(|c| {
                let (r, m) = (rho[c], mine[c]);
                if m > 0.0 && r.is_finite() { (r / m).clamp(0.0, 1e3) } else { 1.0 }
            }));
        }
        Ok(self)
    }

    /// The model's visibility queries.
    #[must_use]
    pub fn model_bvh(&self) -> &dyn Visibility {
        self.bvh.as_ref()
    }

    /// RGB transfer of source `j` (hierarchy order) to receiver vertex `slot`.
    #[must_use]
    pub fn transfer_rgb(&self, j: usize, slot: usize) -> Vec3 {
        let v = self.prepared.transfers.row(j)[slot];
        if v == 0.0 { Vec3::ZERO } else { v * self.source_colour[j] * self.vertex_colour[slot] }
    }

    /// A frame for `object`: traversal, `passes` representatives (0: one per occluded source),
    /// and their transfers.
    #[must_use]
    pub fn frame(&self, object: &SyntheticObject, passes: usize) -> FrameTransfers {
        let t = Instant::now();
        let mut scratch = Traversal::default();
        let mut occlusion = Occlusion::default();
        self.hierarchy.traverse(&object.bounds(), &mut scratch, &mut occlusion);
        let n = if passes == 0 { occlusion.sources.len().max(1) } else { passes };
        let reps = self.hierarchy.representatives(&occlusion, n);
        let traversal = t.elapsed();
        let t = Instant::now();
        let slots = self.prepared.transfers.slots;
        let mut occluded = vec![false; self.prepared.sources.len()];
        for &j in &occlusion.sources {
            occluded[j as usize] = true;
        }
        // receivers (hierarchy order) -> their vertices' slots
        let receiver_slots: Vec<usize> =
            occlusion.receivers.iter().flat_map(|&r| (0..4).map(move |k| 4 * r as usize + k)).collect();
        let mut out: Vec<RepTransfer> = reps
            .iter()
            .map(|rep| {
                let mut radiance = vec![Vec3::ZERO; slots];
                let origin = self.prepared.origin(&self.model, &self.lights, rep.origin);
                let mut half_angle = 0.0f32;
                let (mut power, mut solid_angle) = (Vec3::ZERO, 0.0f32);
                for &j in self.hierarchy.source_tree.items(rep.node) {
                    if !occluded[j as usize] {
                        continue;
                    }
                    for &s in &receiver_slots {
                        radiance[s] += self.transfer_rgb(j as usize, s);
                    }
                    if let (Origin::Direction(d), Source::Distant(k)) = (origin, self.prepared.sources[j as usize]) {
                        let l = &self.lights[k as usize];
                        let apart = d.dot(l.direction).clamp(-1.0, 1.0).acos();
                        half_angle = half_angle.max(apart + l.half_angle());
                        power += l.power();
                        solid_angle += l.solid_angle;
                    }
                }
                RepTransfer {
                    origin,
                    origin_source: rep.origin,
                    radiance,
                    intensity: Vec::new(),
                    transfer: rep.transfer,
                    sources: rep.sources,
                    half_angle: half_angle.min(std::f32::consts::FRAC_PI_2 * 0.9),
                    source_radiance: if solid_angle > 0.0 { power / solid_angle } else { Vec3::ZERO },
                    keep: Vec3::ONE,
                }
            })
            .collect();
        out.sort_by(|a, b| b.transfer.total_cmp(&a.transfer));
        // each representative's set: its origin source's (the sources are split by random ids)
        let sets: Vec<u8> = out.iter().map(|r| self.set_of[r.origin_source as usize]).collect();
        let transfers = t.elapsed();
        let t = Instant::now();
        let probes = {
            let shadow = self.object_shadows_probe.then(|| self.object_shadow(object, &out));
            self.probes_at(object.centre, shadow.as_ref().map(|f| f as &(dyn Fn(u32, Vec3) -> Vec3 + Sync)))
        };
        let object_irradiance = probes.shadowed;
        let object_lights: Vec<DistantLight> =
            self.object_lights.iter().filter(|l| self.bvh.escapes(object.centre, l.direction)).copied().collect();
        let shading = t.elapsed();
        let t = Instant::now();
        if self.object_replaces_sources {
            // the object's side that stands in a source's place faces the receivers below the
            // sources: seen from high sources' receivers, under the object, it faces ground in
            // its own shadow (its light from the sky alone); from low ones', the lit ground
            // beyond (all of its light): blended by the source's elevation
            // (the object as captured: the light its shadow takes from the ground under it is
            // the ground's own loss, already in the representatives' transfers)
            let full = FrameTransfers {
                object_irradiance: probes.full,
                object_lights: object_lights.clone(),
                ..Default::default()
            };
            let sky = FrameTransfers { object_irradiance: probes.sky, ..full.clone() };
            for rep in &mut out {
                let Origin::Direction(d) = rep.origin else { continue };
                let sources = rep.source_radiance;
                let facing = |f: &FrameTransfers| f.object_irradiance_at(-d).max(Vec3::ZERO);
                let e = facing(&full).lerp(facing(&sky), d.y.clamp(0.0, 1.0));
                let own = object.albedo / std::f32::consts::PI * e;
                let keep = Vec3::from_array(std::array::from_fn(|c| {
                    let k = 1.0 - own[c] / sources[c];
                    if sources[c] > 0.0 && k.is_finite() { k.clamp(0.0, 1.0) } else { 1.0 }
                }));
                rep.keep = keep;
            }
        }
        self.intensity_transfers(&mut out, &receiver_slots, &sets);
        let transfers = transfers + t.elapsed();
        FrameTransfers {
            reps: out,
            occluded_sources: occlusion.sources.len(),
            occluded_receivers: occlusion.receivers.len(),
            traversal,
            transfers,
            shading,
            object_irradiance,
            object_lights,
        }
    }

    /// Figure 4 per receiver vertex, the representatives in decreasing transfer.
    fn intensity_transfers(&self, reps: &mut [RepTransfer], slots: &[usize], sets: &[u8]) {
        let slots_total = self.prepared.transfers.slots;
        for r in reps.iter_mut() {
            r.intensity = vec![Vec3::ZERO; slots_total];
        }
        let mut column = Vec::with_capacity(reps.len());
        for &s in slots {
            column.clear();
            column.extend(reps.iter().map(|r| r.radiance[s] * r.keep));
            let lost = crate::ldr::intensity_transfers(&self.response, self.vertex_radiance[s], &column, sets);
            for (r, v) in reps.iter_mut().zip(lost) {
                r.intensity[s] = v;
            }
        }
    }

    /// SH9 of the radiance arriving at `p` from the model (and the map past it): the object's
    /// lighting, as paper 003's irradiance volume gives it, the map taken as [`ObjectProbe`]
    /// says.
    #[must_use]
    pub fn irradiance_at(&self, p: Vec3) -> Sh9 {
        self.probes_at(p, None).full
    }

    /// [`Compositor::irradiance_at`] with what the model reflects left out (the directions
    /// where probe rays meet it are black): the light from the sky alone.
    #[must_use]
    pub fn sky_irradiance_at(&self, p: Vec3) -> Sh9 {
        self.probes_at(p, None).sky
    }

    /// What a ground point `q` of model patch `patch` keeps of its radiance under the object's
    /// shadow ([`Compositor::object_shadows_probe`]): each representative whose direction the
    /// sphere of the object's bounding box's mean half side, about the box's centre, blocks
    /// from `q` takes its transfer there.
    fn object_shadow<'a>(
        &'a self,
        object: &SyntheticObject,
        reps: &'a [RepTransfer],
    ) -> impl Fn(u32, Vec3) -> Vec3 + Sync + 'a {
        let b = object.bounds();
        let (centre, radius) = (0.5 * (b.min + b.max), (b.max - b.min).dot(Vec3::ONE) / 6.0);
        let blocks = move |q: Vec3, d: Vec3| {
            let oc = q - centre;
            let (b, c) = (oc.dot(d), oc.length_squared() - radius * radius);
            let disc = b * b - c;
            disc > 0.0 && -b + disc.sqrt() > 0.0 && c > 0.0
        };
        move |patch: u32, q: Vec3| {
            let Some(&k) = self.receiver_of.get(patch as usize).filter(|&&k| k != u32::MAX) else { return Vec3::ONE };
            let slots = 4 * k as usize..4 * k as usize + 4;
            let l: Vec3 = self.vertex_radiance[slots.clone()].iter().sum();
            let mut lost = Vec3::ZERO;
            for rep in reps {
                if let Origin::Direction(d) = rep.origin
                    && blocks(q, d)
                {
                    lost += rep.radiance[slots.clone()].iter().sum::<Vec3>();
                }
            }
            Vec3::from_array(std::array::from_fn(
                |c| if l[c] > 0.0 { (1.0 - lost[c] / l[c]).clamp(0.0, 1.0) } else { 1.0 },
            ))
        }
    }

    /// The probe at `p` from one set of rays: the model as captured ([`Compositor::irradiance_at`]),
    /// the sky alone ([`Compositor::sky_irradiance_at`]), and the model times `shade` (the
    /// object's shadow; the captured model's without one).
    fn probes_at(&self, p: Vec3, shade: Option<&(dyn Fn(u32, Vec3) -> Vec3 + Sync)>) -> Probes {
        // 2 x 2 rays a texel: a small bright source (the lamp, a third of a texel at 32 x 16)
        // must not hinge on whether a texel centre finds it
        let (w, h) = (64u32, 32u32);
        const SUB: [(f32, f32); 4] = [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)];
        let lights = match &self.probe {
            ObjectProbe::Lights(n) => &self.lights[..(*n).min(self.lights.len())],
            ObjectProbe::Map(_) => &[],
        };
        let in_a_light = |d: Vec3| lights.iter().any(|l| d.dot(l.direction) >= l.cos_half_angle());
        let map = |d: Vec3| self.map.as_ref().map_or(Vec3::ZERO, |m| m.lookup(d));
        // per ray: the map's part (what replaces or stands beside the model) and the model's
        // radiance where it is met, as captured and shaded
        let rays: Vec<(Vec3, Vec3, Vec3)> = (0..w * h * 4)
            .into_par_iter()
            .map(|k| {
                let (texel, (du, dv)) = (k / 4, SUB[k as usize % 4]);
                let uv = glam::Vec2::new(((texel % w) as f32 + du) / w as f32, ((texel / w) as f32 + dv) / h as f32);
                let d = envmap_sphere::latlong::latlong_uv_to_dir(uv);
                match (self.bvh.first_hit(p, d), &self.probe) {
                    (Some((patch, t)), probe) => {
                        let l = self.model.patches[patch as usize].radiance;
                        let shaded = shade.map_or(l, |f| l * f(patch, p + d * t));
                        // the model in place of the map, which the exact projection already holds
                        let base = if matches!(probe, ObjectProbe::Map(_)) { -map(d) } else { Vec3::ZERO };
                        (base, l, shaded)
                    }
                    (None, ObjectProbe::Map(_)) => (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO),
                    (None, _) if in_a_light(d) => (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO),
                    (None, _) => (map(d), Vec3::ZERO, Vec3::ZERO),
                }
            })
            .collect();
        let escaping: Vec<&DistantLight> = lights.iter().filter(|l| self.bvh.escapes(p, l.direction)).collect();
        let project = |pick: &dyn Fn(&(Vec3, Vec3, Vec3)) -> Vec3| {
            let probe = EnvMap::from_texels(w, h, |i, j| {
                let k = 4 * (j * w + i) as usize;
                rays[k..k + 4].iter().map(pick).sum::<Vec3>() / 4.0
            });
            let mut sh = match &self.probe {
                ObjectProbe::Map(map_sh) => signed_projection(&probe, map_sh),
                ObjectProbe::Lights(_) => Sh9::project(&probe),
            };
            for l in &escaping {
                let power = l.radiance * l.solid_angle;
                for (c, y) in sh.coeffs.iter_mut().zip(envmap_sphere::sh::sh9_basis(l.direction)) {
                    *c += power * y;
                }
            }
            sh
        };
        let full = project(&|r| r.0 + r.1);
        Probes { full, sky: project(&|r| r.0), shadowed: if shade.is_some() { project(&|r| r.0 + r.2) } else { full } }
    }
}

/// [`Compositor::probes_at`]'s three projections of one set of rays.
struct Probes {
    full: Sh9,
    sky: Sh9,
    shadowed: Sh9,
}

/// `base` plus the SH9 projection of `signed` (a map of signed radiance differences, which
/// [`Sh9::project`] takes as they are).
fn signed_projection(signed: &EnvMap, base: &Sh9) -> Sh9 {
    let mut sh = Sh9::project(signed);
    for (c, b) in sh.coeffs.iter_mut().zip(base.coeffs) {
        *c += b;
    }
    sh
}

/// Each pixel's receiver: the centre ray's first patch, its slot and bilinear weights.
fn pixel_refs(model: &RealScene, receiver_of: &[u32], bvh: &dyn Visibility) -> Vec<PixelRef> {
    let cam = &model.camera;
    let rays = cam.rays();
    let mut out = Vec::with_capacity(cam.width as usize * cam.height as usize);
    for y in 0..cam.height {
        for x in 0..cam.width {
            let (o, d) = rays.ray(x as f32 + 0.5, y as f32 + 0.5);
            let Some((patch, t)) = bvh.first_hit(o, d) else {
                out.push(PixelRef::NONE);
                continue;
            };
            let p = &model.patches[patch as usize];
            let position = o + d * t;
            let n = p.normal();
            let normal = if n.dot(d) > 0.0 { -n } else { n };
            let r = receiver_of[patch as usize];
            if r == u32::MAX {
                out.push(PixelRef { position, normal, ..PixelRef::NONE });
                continue;
            }
            let (u, v) = patch_uv(&p.corners, position);
            // the vertices sit 2 % in from the corners (see `preprocess::prepare`)
            let s = ((u - 0.01) / 0.98).clamp(0.0, 1.0);
            let t = ((v - 0.01) / 0.98).clamp(0.0, 1.0);
            out.push(PixelRef {
                slot: 4 * r,
                weights: [(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t],
                position,
                normal,
            });
        }
    }
    out
}

/// (u, v) of `p` on the parallelogram `corners` (a + u (b - a) + v (d - a)), least squares.
#[must_use]
pub fn patch_uv(corners: &[Vec3; 4], p: Vec3) -> (f32, f32) {
    let [a, b, _, d] = *corners;
    let (e1, e2, q) = (b - a, d - a, p - a);
    let (g11, g12, g22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let det = g11 * g22 - g12 * g12;
    if det.abs() <= f32::MIN_POSITIVE {
        return (0.5, 0.5);
    }
    let (r1, r2) = (q.dot(e1), q.dot(e2));
    (((g22 * r1 - g12 * r2) / det).clamp(0.0, 1.0), ((g11 * r2 - g12 * r1) / det).clamp(0.0, 1.0))
}
