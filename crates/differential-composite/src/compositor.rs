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
    bvh: Box<dyn Visibility>,
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
        let pixels = pixel_refs(&model, &prepared, bvh.as_ref());
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
            bvh,
        })
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
                for &j in self.hierarchy.source_tree.items(rep.node) {
                    if !occluded[j as usize] {
                        continue;
                    }
                    for &s in &receiver_slots {
                        radiance[s] += self.transfer_rgb(j as usize, s);
                    }
                }
                RepTransfer {
                    origin: self.prepared.origin(&self.model, &self.lights, rep.origin),
                    origin_source: rep.origin,
                    radiance,
                    intensity: Vec::new(),
                    transfer: rep.transfer,
                    sources: rep.sources,
                }
            })
            .collect();
        out.sort_by(|a, b| b.transfer.total_cmp(&a.transfer));
        // each representative's set: its origin source's (the sources are split by random ids)
        let sets: Vec<u8> = out.iter().map(|r| self.set_of[r.origin_source as usize]).collect();
        self.intensity_transfers(&mut out, &receiver_slots, &sets);
        let transfers = t.elapsed();
        let t = Instant::now();
        let object_irradiance = self.irradiance_at(object.centre);
        FrameTransfers {
            reps: out,
            occluded_sources: occlusion.sources.len(),
            occluded_receivers: occlusion.receivers.len(),
            traversal,
            transfers,
            shading: t.elapsed(),
            object_irradiance,
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
            column.extend(reps.iter().map(|r| r.radiance[s]));
            let lost = crate::ldr::intensity_transfers(&self.response, self.vertex_radiance[s], &column, sets);
            for (r, v) in reps.iter_mut().zip(lost) {
                r.intensity[s] = v;
            }
        }
    }

    /// SH9 of the radiance arriving at `p` from the model (and the map past it): the object's
    /// lighting, as paper 003's irradiance volume gives it. Where the scene has a map, each
    /// extracted light that `p` sees is added as its cone's power along its axis (a sun of a
    /// few texels is found by no probe ray) and its cone is left out of the probe.
    #[must_use]
    pub fn irradiance_at(&self, p: Vec3) -> Sh9 {
        // 2 x 2 rays a texel: a small bright source (the lamp, a third of a texel at 32 x 16)
        // must not hinge on whether a texel centre finds it
        let (w, h) = (64u32, 32u32);
        let in_a_light = |d: Vec3| self.lights.iter().any(|l| d.dot(l.direction) >= l.cos_half_angle());
        let radiance = |d: Vec3| match self.bvh.first_hit(p, d) {
            Some((patch, _)) => self.model.patches[patch as usize].radiance,
            None if in_a_light(d) => Vec3::ZERO,
            None => self.map.as_ref().map_or(Vec3::ZERO, |m| m.lookup(d)),
        };
        let probe = EnvMap::from_texels(w, h, |i, j| {
            [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)]
                .iter()
                .map(|&(du, dv)| {
                    let uv = glam::Vec2::new((i as f32 + du) / w as f32, (j as f32 + dv) / h as f32);
                    radiance(envmap_sphere::latlong::latlong_uv_to_dir(uv))
                })
                .sum::<Vec3>()
                / 4.0
        });
        let mut sh = Sh9::project(&probe);
        for l in self.lights.iter().filter(|l| self.bvh.escapes(p, l.direction)) {
            let power = l.radiance * l.solid_angle;
            for (c, y) in sh.coeffs.iter_mut().zip(envmap_sphere::sh::sh9_basis(l.direction)) {
                *c += power * y;
            }
        }
        sh
    }
}

/// Each pixel's receiver: the centre ray's first patch, its slot and bilinear weights.
fn pixel_refs(model: &RealScene, prepared: &Prepared, bvh: &dyn Visibility) -> Vec<PixelRef> {
    let cam = &model.camera;
    let rays = cam.rays();
    let mut receiver_of = vec![u32::MAX; model.patches.len()];
    for (k, &r) in prepared.receivers.iter().enumerate() {
        receiver_of[r as usize] = k as u32;
    }
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
