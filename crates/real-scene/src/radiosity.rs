//! The radiosity solution that stands in for a capture's radiances: every patch's outgoing
//! radiance L_p = E_p + ρ_p (Σ_q F_pq V_pq L_q + L_env,p), gathered by Jacobi iteration. Form
//! factors are point-to-patch from each patch's centre (exact contour integrals, so they sum to
//! 1 in a closed room); visibility is the fraction of sample points of q the centre sees; the
//! environment's share is estimated from escaping rays, cosine-weighted and map-importance
//! samples combined by the balance heuristic.

use envmap_sphere::EnvMap;
use glam::Vec3;
use rayon::prelude::*;

use crate::formfactor::point_to_polygon;
use crate::{RealScene, RealSceneError, Visibility};

/// Knobs of [`solve`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveSettings {
    /// Iterations at most.
    pub max_iterations: u32,
    /// Stop when no patch's radiance changed by more than this fraction of the largest.
    pub tolerance: f32,
    /// n x n points on each patch for the visibility of a link.
    pub visibility_samples: u32,
    /// n x n cosine-weighted directions and as many map samples per patch for the
    /// environment.
    pub environment_samples: u32,
}

impl Default for SolveSettings {
    fn default() -> Self {
        Self { max_iterations: 200, tolerance: 1e-5, visibility_samples: 2, environment_samples: 16 }
    }
}

/// What [`solve`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveReport {
    /// Jacobi iterations run.
    pub iterations: u32,
    /// The last iteration's largest change, relative to the largest radiance.
    pub change: f32,
    /// Patch pairs with a non-zero form factor.
    pub links: usize,
}

/// Solves the scene's radiances in place (each patch's `radiance`), lit by its emitting
/// patches and, when `environment` is given, the map (seen through whatever the patches leave
/// open).
///
/// # Errors
/// [`RealSceneError::NeedsEnvironment`] for an environment-lit scene without a map.
pub fn solve(
    scene: &mut RealScene,
    vis: &impl Visibility,
    environment: Option<&EnvMap>,
    settings: &SolveSettings,
) -> Result<SolveReport, RealSceneError> {
    if scene.environment_lit && environment.is_none() {
        return Err(RealSceneError::NeedsEnvironment(scene.name.clone()));
    }
    let (links, env) = gather_terms(scene, vis, environment, settings);
    let patches = &scene.patches;
    let base: Vec<Vec3> = patches.iter().zip(&env).map(|(p, e)| p.emission + p.reflectance * *e).collect();
    let mut radiance = base.clone();
    let (mut iterations, mut change) = (0, f32::INFINITY);
    while iterations < settings.max_iterations && change > settings.tolerance {
        let next: Vec<Vec3> = links
            .par_iter()
            .enumerate()
            .map(|(k, l)| {
                let gathered: Vec3 = l.iter().map(|&(q, f)| radiance[q as usize] * f).sum();
                base[k] + patches[k].reflectance * gathered
            })
            .collect();
        let peak = next.iter().map(|v| v.max_element()).fold(0.0f32, f32::max).max(f32::MIN_POSITIVE);
        change = next.iter().zip(&radiance).map(|(a, b)| (*a - *b).abs().max_element()).fold(0.0, f32::max) / peak;
        radiance = next;
        iterations += 1;
    }
    let links_count = links.iter().map(Vec::len).sum();
    for (p, l) in scene.patches.iter_mut().zip(radiance) {
        p.radiance = l;
    }
    Ok(SolveReport { iterations, change, links: links_count })
}

/// Sets each patch's reflectance from its radiance as a capture does: measured radiance over
/// the irradiance (over pi) that the other patches' radiances and the map deliver to it,
/// rho = (L - L_e) / (E / pi), per channel, clamped to [0, 0.98] (0 where no light arrives).
/// With the radiances of a radiosity solution it recovers the reflectances solved with.
///
/// # Errors
/// [`RealSceneError::NeedsEnvironment`] for an environment-lit scene without a map.
pub fn estimate_reflectances(
    scene: &mut RealScene,
    vis: &impl Visibility,
    environment: Option<&EnvMap>,
    settings: &SolveSettings,
) -> Result<(), RealSceneError> {
    if scene.environment_lit && environment.is_none() {
        return Err(RealSceneError::NeedsEnvironment(scene.name.clone()));
    }
    let (links, env) = gather_terms(scene, vis, environment, settings);
    let reflectances: Vec<Vec3> = links
        .iter()
        .zip(&env)
        .map(|(l, e)| *e + l.iter().map(|&(q, f)| scene.patches[q as usize].radiance * f).sum::<Vec3>())
        .zip(&scene.patches)
        .map(|(arriving, p)| {
            let out = (p.radiance - p.emission).max(Vec3::ZERO);
            Vec3::from_array(std::array::from_fn(|c| {
                if arriving[c] > 0.0 { (out[c] / arriving[c]).clamp(0.0, 0.98) } else { 0.0 }
            }))
        })
        .collect();
    for (p, r) in scene.patches.iter_mut().zip(reflectances) {
        p.reflectance = r;
    }
    Ok(())
}

/// Per patch, its links (q, F_pq V_pq) to the patches it sees, and the map's irradiance over
/// pi through the openings.
#[allow(clippy::type_complexity)]
fn gather_terms(
    scene: &RealScene,
    vis: &impl Visibility,
    environment: Option<&EnvMap>,
    settings: &SolveSettings,
) -> (Vec<Vec<(u32, f32)>>, Vec<Vec3>) {
    let patches = &scene.patches;
    let eps = vis.epsilon();
    let nv = settings.visibility_samples.max(1);
    let frames: Vec<(Vec3, Vec3)> = patches.iter().map(|p| (p.center(), p.normal())).collect();
    // links: (q, F_pq V_pq) per p
    let links: Vec<Vec<(u32, f32)>> = frames
        .par_iter()
        .enumerate()
        .map(|(k, &(c, n))| {
            let origin = c + n * eps;
            let mut out = Vec::new();
            for (q, patch) in patches.iter().enumerate() {
                let (cq, nq) = frames[q];
                // one-sided: q must face p, and lie (partly) above p's plane
                if q == k || nq.dot(c - cq) <= 0.0 {
                    continue;
                }
                let f = point_to_polygon(origin, n, &patch.corners);
                if f <= 0.0 {
                    continue;
                }
                let mut seen = 0;
                for j in 0..nv {
                    for i in 0..nv {
                        let target = patch.point((i as f32 + 0.5) / nv as f32, (j as f32 + 0.5) / nv as f32) + nq * eps;
                        seen += u32::from(vis.clear(origin, target));
                    }
                }
                if seen > 0 {
                    out.push((q as u32, f * seen as f32 / (nv * nv) as f32));
                }
            }
            out
        })
        .collect();
    // what each patch reflects of the environment: ρ E / π, E estimated from as many
    // cosine-weighted directions as map-importance samples, combined by the balance heuristic
    // (a small sun is found by the map samples, the broad sky by the cosine ones)
    let ne = settings.environment_samples.max(1);
    let dist = environment.map(envmap_sphere::EnvDistribution::for_bilinear);
    let env: Vec<Vec3> = match (environment, &dist) {
        (Some(map), Some(dist)) => frames
            .par_iter()
            .enumerate()
            .map(|(k, &(c, n))| {
                let origin = c + n * eps;
                let (t, b) = n.any_orthonormal_pair();
                // a per-patch rotation of the stratified points (Cranley-Patterson)
                let shift = glam::Vec2::new(hash(k as u32, 1), hash(k as u32, 2));
                let mut e = Vec3::ZERO;
                for j in 0..ne {
                    for i in 0..ne {
                        let u = (glam::Vec2::new((i as f32 + 0.5) / ne as f32, (j as f32 + 0.5) / ne as f32) + shift)
                            .fract();
                        // cosine-weighted
                        let r = u.x.sqrt();
                        let phi = u.y * std::f32::consts::TAU;
                        let d =
                            (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u.x).max(0.0).sqrt()).normalize();
                        let cos = d.dot(n);
                        if cos > 0.0 && vis.escapes(origin, d) {
                            e += map.lookup(d) * cos / (cos / std::f32::consts::PI + dist.dir_pdf(d));
                        }
                        // the map's
                        let m = dist.sample_dir(u);
                        let cos = m.dir.dot(n);
                        if cos > 0.0 && m.pdf > 0.0 && vis.escapes(origin, m.dir) {
                            e += map.lookup_uv(m.uv) * cos / (cos / std::f32::consts::PI + m.pdf);
                        }
                    }
                }
                e / (ne * ne) as f32 / std::f32::consts::PI
            })
            .collect(),
        _ => vec![Vec3::ZERO; patches.len()],
    };
    (links, env)
}

/// A number in [0, 1) from (k, salt): PCG-style integer hashing.
fn hash(k: u32, salt: u32) -> f32 {
    let mut x = k.wrapping_mul(0x9E37_79B9) ^ salt.wrapping_mul(0x85EB_CA6B);
    x ^= x >> 16;
    x = x.wrapping_mul(0x7FEB_352D);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846C_A68B);
    x ^= x >> 16;
    (x >> 8) as f32 / (1u32 << 24) as f32
}
