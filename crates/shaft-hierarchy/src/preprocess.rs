//! Paper 003's pre-processing on a reconstructed scene (Sections 4-6): the source set (patches
//! by power down to a share of the total, and distant lights), the receivers (patches the camera
//! sees, four vertices each), the radiance transfers L_ij (form factor x ray-cast visibility x
//! reflectance), then the trees and the shaft hierarchy.

use glam::Vec3;
use rayon::prelude::*;
use real_scene::formfactor::point_to_polygon;
use real_scene::{RealScene, Visibility, luminance};
use scene::DistantLight;

use crate::{Aabb, BuildError, Receiver, Settings, ShaftHierarchy, SourceShape, Transfers, cone_direction_bounds};

/// A source of the source set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// A patch of the scene (its index).
    Patch(u32),
    /// A distant light (its index in the lights given).
    Distant(u32),
}

/// Where a representative's shadow map is rendered from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Origin {
    /// A point: the centre of a source patch.
    Point(Vec3),
    /// A direction towards a distant light (an orthographic map).
    Direction(Vec3),
}

impl Prepared {
    /// The shadow map origin of source `s` of the source set (paper 003, Section 8: a cluster's
    /// map is rendered from its strongest patch's centre).
    #[must_use]
    pub fn origin(&self, scene: &RealScene, lights: &[DistantLight], s: u32) -> Origin {
        match self.sources[s as usize] {
            Source::Patch(j) => Origin::Point(scene.patches[j as usize].center()),
            Source::Distant(k) => Origin::Direction(lights[k as usize].direction),
        }
    }
}

/// Knobs of the pre-processing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreprocessSettings {
    /// The source set carries this share of the total power (the paper: 70 %).
    pub source_share: f32,
    /// n x n points of a source patch (or directions of a distant light) for each transfer's
    /// visibility.
    pub visibility_samples: u32,
    /// The hierarchy's knobs.
    pub hierarchy: Settings,
    /// Whether the scene's patches are candidate sources (the paper's); without, the distant
    /// lights alone are (a backdrop's ground lights nothing the compositor darkens).
    pub patch_sources: bool,
}

impl PreprocessSettings {
    /// The paper's: 70 % of the power, 8 receivers a leaf, 2 % pruning; 2 x 2 visibility rays.
    pub const PAPER: Self =
        Self { source_share: 0.7, visibility_samples: 2, hierarchy: Settings::PAPER, patch_sources: true };
}

impl Default for PreprocessSettings {
    fn default() -> Self {
        Self::PAPER
    }
}

/// The pre-processed scene: what the hierarchy was built from.
#[derive(Clone, Debug)]
pub struct Prepared {
    /// The source set, in the hierarchy's source order.
    pub sources: Vec<Source>,
    /// Power of the source set and of every candidate (luminance, W-like units).
    pub power: (f64, f64),
    /// Receiver patches (scene indices), in the hierarchy's receiver order.
    pub receivers: Vec<u32>,
    /// The receiver vertices (transfer columns): positions, 4 per receiver.
    pub vertices: Vec<Vec3>,
    /// L_ij and the vertices' radiances.
    pub transfers: Transfers,
}

/// Power a distant light delivers onto the scene's patches, unshadowed (luminance): its
/// counterpart of a patch's π L A.
fn delivered_power(scene: &RealScene, light: &DistantLight) -> f64 {
    let l = f64::from(luminance(light.radiance));
    scene
        .patches
        .iter()
        .map(|p| f64::from(p.area()) * l * f64::from(light.cosine_integral(p.normal().dot(light.direction))))
        .sum()
}

/// Chooses the source set, the receivers, and computes the transfers.
#[must_use]
pub fn prepare(
    scene: &RealScene,
    lights: &[DistantLight],
    vis: &impl Visibility,
    settings: &PreprocessSettings,
) -> Prepared {
    // the source set: every candidate by power, the largest first, down to the share
    let mut candidates: Vec<(Source, f64)> = scene
        .patches
        .iter()
        .enumerate()
        .map(|(k, p)| (Source::Patch(k as u32), f64::from(p.power())))
        .filter(|_| settings.patch_sources)
        .chain(lights.iter().enumerate().map(|(k, l)| (Source::Distant(k as u32), delivered_power(scene, l))))
        .filter(|(_, w)| *w > 0.0 && w.is_finite())
        .collect();
    candidates.sort_by(|a, b| b.1.total_cmp(&a.1));
    let total: f64 = candidates.iter().map(|c| c.1).sum();
    let mut sources = Vec::new();
    let mut kept = 0.0;
    for (s, w) in candidates {
        if kept >= f64::from(settings.source_share.clamp(0.0, 1.0)) * total && !sources.is_empty() {
            break;
        }
        sources.push(s);
        kept += w;
    }
    let receivers = scene.visible_patches(vis);
    let eps = vis.epsilon();
    // four vertices a receiver, pulled 2 % towards its centre (off the edges other patches
    // share) and off its surface
    let vertices: Vec<(Vec3, Vec3, u32)> = receivers
        .iter()
        .flat_map(|&r| {
            let p = &scene.patches[r as usize];
            let (c, n) = (p.center(), p.normal());
            p.corners.map(|x| (x.lerp(c, 0.02) + n * eps, n, r))
        })
        .collect();
    let nv = settings.visibility_samples.max(1);
    let values: Vec<f32> = sources
        .par_iter()
        .flat_map_iter(|&s| {
            let row: Vec<f32> = vertices
                .iter()
                .map(|&(x, n, r)| {
                    let rho = luminance(scene.patches[r as usize].reflectance);
                    if rho <= 0.0 {
                        return 0.0;
                    }
                    match s {
                        Source::Patch(j) if j == r => 0.0,
                        Source::Patch(j) => {
                            let q = &scene.patches[j as usize];
                            let nq = q.normal();
                            // one-sided sources, and only what lies above the vertex's horizon
                            if nq.dot(x - q.center()) <= 0.0 {
                                return 0.0;
                            }
                            let f = point_to_polygon(x, n, &q.corners);
                            if f <= 0.0 {
                                return 0.0;
                            }
                            let seen = grid(nv).filter(|&(u, v)| vis.clear(x, q.point(u, v) + nq * eps)).count();
                            rho * luminance(q.radiance) * f * seen as f32 / (nv * nv) as f32
                        }
                        Source::Distant(k) => {
                            let l = &lights[k as usize];
                            let e = luminance(l.radiance) * l.cosine_integral(n.dot(l.direction));
                            if e <= 0.0 {
                                return 0.0;
                            }
                            let open = grid(nv)
                                .filter(|&(u, v)| {
                                    let (d, _) = l.sample_direction(glam::Vec2::new(u, v));
                                    d.dot(n) > 0.0 && vis.escapes(x, d)
                                })
                                .count();
                            rho / std::f32::consts::PI * e * open as f32 / (nv * nv) as f32
                        }
                    }
                })
                .collect();
            row
        })
        .collect();
    let totals = vertices.iter().map(|&(_, _, r)| luminance(scene.patches[r as usize].radiance)).collect();
    Prepared {
        sources,
        power: (kept, total),
        receivers,
        vertices: vertices.iter().map(|v| v.0).collect(),
        transfers: Transfers { slots: vertices.len(), values, totals },
    }
}

/// Stratified (u, v) in [0, 1)², n x n.
fn grid(n: u32) -> impl Iterator<Item = (f32, f32)> {
    (0..n * n).map(move |k| (((k % n) as f32 + 0.5) / n as f32, ((k / n) as f32 + 0.5) / n as f32))
}

/// The hierarchy's inputs from a prepared scene.
#[must_use]
pub fn inputs(scene: &RealScene, lights: &[DistantLight], prepared: &Prepared) -> (Vec<SourceShape>, Vec<Receiver>) {
    let shapes = prepared
        .sources
        .iter()
        .map(|&s| match s {
            Source::Patch(j) => SourceShape::Local(Aabb::from_points(scene.patches[j as usize].corners)),
            Source::Distant(k) => {
                let l = &lights[k as usize];
                SourceShape::Distant(cone_direction_bounds(l.direction, l.half_angle()))
            }
        })
        .collect();
    let receivers = prepared
        .receivers
        .iter()
        .enumerate()
        .map(|(k, &r)| Receiver {
            bounds: Aabb::from_points(scene.patches[r as usize].corners),
            slots: 4 * k as u32..4 * k as u32 + 4,
        })
        .collect();
    (shapes, receivers)
}

/// Pre-processes and builds: the source set, receivers, transfers, trees and shafts.
///
/// # Errors
/// As [`ShaftHierarchy::build`] (a non-finite patch or transfer).
pub fn build(
    scene: &RealScene,
    lights: &[DistantLight],
    vis: &impl Visibility,
    settings: &PreprocessSettings,
) -> Result<(Prepared, ShaftHierarchy), BuildError> {
    let prepared = prepare(scene, lights, vis, settings);
    let (shapes, receivers) = inputs(scene, lights, &prepared);
    let h = ShaftHierarchy::build(&shapes, &receivers, &prepared.transfers, &settings.hierarchy)?;
    Ok((prepared, h))
}
