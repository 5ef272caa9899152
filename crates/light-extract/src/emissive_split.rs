//! The emissive split of paper 001 (Sections 3.2-3.4): classify texels as emissive, split the
//! light budget by importance, place *EnvDirects* on the emissive texels (importance sampling with
//! neighbourhood masking, then k-means to energy centroids) and *EnvIndirects* on the rest (an
//! illumination cut over a binary light tree, splitting the node with the largest
//! Obj = w_V V + w_D D + w_E E, each term divided by its maximum over the cut).
//!
//! Readings where the paper is open:
//! - the masking radius "s 4 pi / K" is read as a solid angle: the masked cap has solid angle
//!   s 4 pi / K (radius acos(1 - 2 s / K), 7.8 degrees for K = 32); emissive texels farther than
//!   twice that radius from every k-means centre are reset to non-emissive;
//! - the light tree's leaves are the non-emissive texels of the map downsampled (solid-angle box
//!   filter, after masking the emissive ones at full resolution) to `leaf_resolution`; the tree
//!   splits leaf sets at the median of their widest direction coordinate;
//! - V is the energy-weighted angular variance on the sphere, W - |S|^2 / W; D the largest angle
//!   from the node's energy centroid to its leaves; E the node's energy (luminance x solid angle).
//!
//! Both light sets partition the map: light power = map power, the remainder is zero.

use crate::decomposition::{Decomposition, ExtractError, ExtractedLight, LightExtractor};
use envmap_sphere::color::luminance_f64;
use envmap_sphere::latlong::TexelDirections;
use envmap_sphere::{Distribution1D, EnvMap, luminance};
use glam::{DVec3, Vec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg32;
use scene::DistantLight;
use std::time::Instant;

/// Paper 001's light extraction, with its parameters as defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmissiveSplit {
    /// Total light budget K.
    pub lights: usize,
    /// L_T = max(L_b, lambda L_avg, gamma L_max): lambda (paper: 3).
    pub lambda: f64,
    /// gamma (paper: 0.001).
    pub gamma: f64,
    /// L_b is this percentile of texel luminance (paper: 98).
    pub percentile: f64,
    /// Importance Gamma = L^a dw^b: a (paper: 1).
    pub a: f64,
    /// b (paper: 1/4).
    pub b: f64,
    /// Masking scale s (paper: 0.15).
    pub s: f64,
    /// Neighbourhood masking on (the paper's Table 2 ablation turns it off).
    pub masking: bool,
    /// k-means refinement on (ablation: off).
    pub kmeans: bool,
    /// Weights of the illumination cut (paper: 1, 5, 1).
    pub w_v: f64,
    /// Weight of the directional extent.
    pub w_d: f64,
    /// Weight of the energy.
    pub w_e: f64,
    /// Leaves of the light tree: the map downsampled to this width (height = width / 2).
    pub leaf_resolution: u32,
    /// Seed of the EnvDirects sampling.
    pub seed: u64,
    /// Our option, not the paper's (off by default): give each light the cone whose angular
    /// spread matches its cluster's energy-weighted spread (same power, same centroid) instead
    /// of the cluster's whole solid angle, so a sun with a faint halo casts a sun's penumbra.
    pub moment_cones: bool,
}

impl Default for EmissiveSplit {
    fn default() -> Self {
        Self {
            lights: 32,
            lambda: 3.0,
            gamma: 0.001,
            percentile: 98.0,
            a: 1.0,
            b: 0.25,
            s: 0.15,
            masking: true,
            kmeans: true,
            w_v: 1.0,
            w_d: 5.0,
            w_e: 1.0,
            leaf_resolution: 128,
            seed: 0,
            moment_cones: false,
        }
    }
}

/// A set of texels (or leaves) standing for one light.
#[derive(Default)]
struct Cluster {
    power: DVec3,
    weighted_dir: DVec3,
    solid_angle: f64,
    /// (direction, luminance x solid angle, solid angle) per member
    members: Vec<(DVec3, f64, f64)>,
}

impl Cluster {
    fn add(&mut self, dir: DVec3, rgb: DVec3, sa: f64) {
        let w = luminance_f64(rgb.to_array()) * sa;
        self.power += rgb * sa;
        self.weighted_dir += dir * w;
        self.solid_angle += sa;
        self.members.push((dir, w, sa));
    }

    /// The cone standing for the cluster: its whole solid angle, or with `moment_cone` the cone
    /// of equal energy-weighted mean of 1 - cos(angle to the centre). A uniform cone of
    /// solid angle W has that mean W / 4 pi, and a texel of solid angle w adds its own w / 4 pi.
    fn light(&self, moment_cone: bool) -> Option<ExtractedLight> {
        let brightest = self.power.max_element();
        if brightest.is_nan() || brightest <= 0.0 || self.solid_angle <= 0.0 {
            return None;
        }
        let c = self
            .weighted_dir
            .try_normalize()
            .or_else(|| self.members.iter().map(|m| m.0).sum::<DVec3>().try_normalize())?;
        let extent = self.members.iter().map(|(d, ..)| c.dot(*d).clamp(-1.0, 1.0).acos()).fold(0.0, f64::max);
        let total: f64 = if moment_cone { self.members.iter().map(|m| m.1.max(0.0)).sum() } else { 0.0 };
        let solid_angle = if total > 0.0 {
            let four_pi = 4.0 * std::f64::consts::PI;
            let spread: f64 = self
                .members
                .iter()
                .map(|&(d, w, sa)| w.max(0.0) * ((1.0 - c.dot(d)).max(0.0) + sa / four_pi))
                .sum::<f64>()
                / total;
            (four_pi * spread).min(four_pi)
        } else {
            self.solid_angle
        };
        Some(ExtractedLight {
            light: DistantLight {
                direction: c.as_vec3(),
                solid_angle: solid_angle as f32,
                radiance: (self.power / solid_angle).as_vec3(),
            },
            extent: extent as f32,
            indirect: false,
        })
    }
}

/// A node of the light tree over leaves [lo, hi).
struct Node {
    lo: usize,
    hi: usize,
    children: Option<(usize, usize)>,
    energy: f64,
    variance: f64,
    extent: f64,
}

struct Leaf {
    dir: DVec3,
    rgb: DVec3,
    sa: f64,
    w: f64,
}

fn build_tree(leaves: &mut [Leaf], lo: usize, hi: usize, nodes: &mut Vec<Node>) -> usize {
    let slice = &leaves[lo..hi];
    let energy: f64 = slice.iter().map(|l| l.w).sum();
    let s: DVec3 = slice.iter().map(|l| l.dir * l.w).sum();
    let variance = if energy > 0.0 { (energy - s.length_squared() / energy).max(0.0) } else { 0.0 };
    let c = s.try_normalize().unwrap_or_else(|| slice.iter().map(|l| l.dir).sum::<DVec3>().normalize_or(DVec3::Y));
    let extent = slice.iter().map(|l| c.dot(l.dir).clamp(-1.0, 1.0).acos()).fold(0.0, f64::max);
    let id = nodes.len();
    nodes.push(Node { lo, hi, children: None, energy, variance, extent });
    if hi - lo > 1 {
        let (mn, mx) =
            slice.iter().fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(a, b), l| {
                (a.min(l.dir), b.max(l.dir))
            });
        let axis = (mx - mn).max_position();
        let mid = lo + (hi - lo) / 2;
        leaves[lo..hi].select_nth_unstable_by(mid - lo, |a, b| a.dir[axis].total_cmp(&b.dir[axis]));
        let left = build_tree(leaves, lo, mid, nodes);
        let right = build_tree(leaves, mid, hi, nodes);
        nodes[id].children = Some((left, right));
    }
    id
}

impl EmissiveSplit {
    fn check(&self) -> Result<(), ExtractError> {
        let ok = self.lights >= 1
            && self.lights <= 1 << 16
            && (0.0..=100.0).contains(&self.percentile)
            && self.s >= 0.0
            && self.leaf_resolution >= 2
            && self.leaf_resolution.is_multiple_of(2);
        if ok {
            Ok(())
        } else {
            Err(ExtractError::Parameter(format!("emissive split parameters out of range: {self:?}")))
        }
    }
}

impl LightExtractor for EmissiveSplit {
    fn budget(&self) -> Option<usize> {
        Some(self.lights)
    }

    fn with_budget(&self, lights: usize) -> Option<Box<dyn LightExtractor>> {
        Some(Box::new(Self { lights, ..*self }))
    }

    fn extract(&self, map: &EnvMap) -> Result<Decomposition, ExtractError> {
        self.check()?;
        let start = Instant::now();
        let (w, h) = (map.width(), map.height());
        let row_sa = map.row_solid_angles();
        let dirs = TexelDirections::new(w, h);
        let lum: Vec<f64> = map.pixels().iter().map(|p| f64::from(luminance(*p)).max(0.0)).collect();
        // Section 3.2: the emissive threshold; L_b by selection (nearest rank), not a full sort.
        let l_b = {
            let mut v = lum.clone();
            let rank = ((self.percentile / 100.0) * v.len() as f64).ceil() as usize;
            let k = rank.clamp(1, v.len()) - 1;
            *v.select_nth_unstable_by(k, f64::total_cmp).1
        };
        let l_avg = lum.iter().sum::<f64>() / lum.len() as f64;
        let l_max = lum.iter().copied().fold(0.0, f64::max);
        let l_t = l_b.max(self.lambda * l_avg).max(self.gamma * l_max);
        let mut emissive: Vec<usize> = (0..lum.len()).filter(|&k| lum[k] > l_t && lum[k] > 0.0).collect();
        let sa_of = |k: usize| row_sa[k / w as usize];
        let dir_of = |k: usize| dirs.dir((k % w as usize) as u32, (k / w as usize) as u32).as_dvec3();
        // The budget split, Gamma = L^a dw^b.
        let (mut l_em, mut w_em, mut l_all, w_all) = (0.0, 0.0, 0.0, 4.0 * std::f64::consts::PI);
        for &k in &emissive {
            l_em += lum[k] * sa_of(k);
            w_em += sa_of(k);
        }
        for (k, y) in lum.iter().enumerate() {
            l_all += y * sa_of(k);
        }
        let gamma = |l: f64, dw: f64| if l > 0.0 && dw > 0.0 { l.powf(self.a) * dw.powf(self.b) } else { 0.0 };
        let (g_em, g_nem) = (gamma(l_em, w_em), gamma(l_all - l_em, w_all - w_em));
        let n = if g_em + g_nem > 0.0 {
            ((self.lights as f64 * g_em / (g_em + g_nem)).round() as usize).min(self.lights)
        } else {
            0
        };
        // Section 3.3: EnvDirects.
        let mask_sa = self.s * 4.0 * std::f64::consts::PI / self.lights as f64;
        let mask_cos = (1.0 - mask_sa / (2.0 * std::f64::consts::PI)).clamp(-1.0, 1.0);
        let mut rng = Pcg32::seed_from_u64(self.seed);
        let mut weight: Vec<f64> = emissive.iter().map(|&k| lum[k] * sa_of(k)).collect();
        let mut centres: Vec<DVec3> = Vec::new();
        while centres.len() < n && weight.iter().any(|x| *x > 0.0) {
            let dist = Distribution1D::new(weight.iter().copied());
            let (cell, _) = dist.sample(rng.random());
            let c = dir_of(emissive[cell]);
            centres.push(c);
            if self.masking {
                for (x, &k) in weight.iter_mut().zip(&emissive) {
                    if dir_of(k).dot(c) >= mask_cos {
                        *x = 0.0;
                    }
                }
            } else {
                weight[cell] = 0.0; // a texel is drawn once
            }
        }
        let mut assign = vec![0usize; emissive.len()];
        let nearest = |d: DVec3, centres: &[DVec3]| {
            centres.iter().enumerate().map(|(i, c)| (i, c.dot(d))).max_by(|a, b| a.1.total_cmp(&b.1)).map_or(0, |x| x.0)
        };
        if !centres.is_empty() {
            for (a, &k) in assign.iter_mut().zip(&emissive) {
                *a = nearest(dir_of(k), &centres);
            }
            if self.kmeans {
                for _ in 0..100 {
                    let mut sums = vec![DVec3::ZERO; centres.len()];
                    for (a, &k) in assign.iter().zip(&emissive) {
                        sums[*a] += dir_of(k) * lum[k] * sa_of(k);
                    }
                    for (c, s) in centres.iter_mut().zip(&sums) {
                        if let Some(n) = s.try_normalize() {
                            *c = n;
                        }
                    }
                    let mut changed = false;
                    for (a, &k) in assign.iter_mut().zip(&emissive) {
                        let b = nearest(dir_of(k), &centres);
                        changed |= b != *a;
                        *a = b;
                    }
                    if !changed {
                        break;
                    }
                }
            }
        }
        // Texels farther than twice the masking radius from their centre are non-emissive.
        let far_cos = (2.0 * mask_cos.clamp(-1.0, 1.0).acos()).min(std::f64::consts::PI).cos();
        let mut clusters: Vec<Cluster> = (0..centres.len()).map(|_| Cluster::default()).collect();
        let mut is_emissive = vec![false; lum.len()];
        if !centres.is_empty() {
            emissive.retain(|&k| {
                let d = dir_of(k);
                let c = nearest(d, &centres);
                if centres[c].dot(d) < far_cos {
                    return false;
                }
                clusters[c].add(d, map.pixels()[k].max(Vec3::ZERO).as_dvec3(), sa_of(k));
                is_emissive[k] = true;
                true
            });
        }
        let directs: Vec<ExtractedLight> = clusters.iter().filter_map(|c| c.light(self.moment_cones)).collect();
        // Section 3.4: EnvIndirects over the rest, on a light tree of downsampled leaves.
        let m = self.lights.saturating_sub(directs.len());
        let mut masked = map.clone();
        for (k, p) in masked.pixels_mut().iter_mut().enumerate() {
            *p = if is_emissive[k] { Vec3::ZERO } else { p.max(Vec3::ZERO) };
        }
        let lw = self.leaf_resolution.min(w);
        let lh = (lw / 2).max(1).min(h);
        let coarse = if w.is_multiple_of(lw) && h.is_multiple_of(lh) { masked.resize(lw, lh) } else { masked.clone() };
        let cdirs = TexelDirections::new(coarse.width(), coarse.height());
        let mut leaves: Vec<Leaf> = Vec::with_capacity((coarse.width() * coarse.height()) as usize);
        for j in 0..coarse.height() {
            let sa = coarse.texel_solid_angle(j);
            for i in 0..coarse.width() {
                let rgb = coarse.pixel(i, j).as_dvec3();
                let y = luminance_f64(rgb.to_array());
                leaves.push(Leaf { dir: cdirs.dir(i, j).as_dvec3(), rgb, sa, w: y * sa });
            }
        }
        let mut indirects = Vec::new();
        if m > 0 && !leaves.is_empty() {
            let mut nodes = Vec::new();
            let n_leaves = leaves.len();
            let root = build_tree(&mut leaves, 0, n_leaves, &mut nodes);
            let mut cut = vec![root];
            while cut.len() < m {
                let splittable: Vec<usize> = (0..cut.len()).filter(|&i| nodes[cut[i]].children.is_some()).collect();
                if splittable.is_empty() {
                    break;
                }
                let max = |f: &dyn Fn(&Node) -> f64| splittable.iter().map(|&i| f(&nodes[cut[i]])).fold(0.0, f64::max);
                let (mv, md, me) = (max(&|n| n.variance), max(&|n| n.extent), max(&|n| n.energy));
                let norm = |x: f64, mx: f64| if mx > 0.0 { x / mx } else { 0.0 };
                let obj = |n: &Node| {
                    self.w_v * norm(n.variance, mv) + self.w_d * norm(n.extent, md) + self.w_e * norm(n.energy, me)
                };
                let best =
                    splittable.iter().copied().max_by(|&a, &b| obj(&nodes[cut[a]]).total_cmp(&obj(&nodes[cut[b]])));
                let Some(i) = best else { break };
                let (l, r) = nodes[cut[i]].children.unwrap_or((cut[i], cut[i]));
                cut[i] = l;
                cut.push(r);
            }
            for &id in &cut {
                let mut cl = Cluster::default();
                for leaf in &leaves[nodes[id].lo..nodes[id].hi] {
                    cl.add(leaf.dir, leaf.rgb, leaf.sa);
                }
                indirects.extend(cl.light(self.moment_cones));
            }
        }
        let n_directs = directs.len();
        for l in &mut indirects {
            l.indirect = true;
        }
        let mut lights = directs;
        lights.extend(indirects);
        let params = serde_json::json!({
            "lights": self.lights, "lambda": self.lambda, "gamma": self.gamma, "percentile": self.percentile,
            "a": self.a, "b": self.b, "s": self.s, "masking": self.masking, "kmeans": self.kmeans,
            "w_v": self.w_v, "w_d": self.w_d, "w_e": self.w_e, "leaf_resolution": self.leaf_resolution,
            "seed": self.seed, "moment_cones": self.moment_cones, "threshold": l_t, "env_directs": n_directs,
        });
        let ambient = EnvMap::constant(w, h, Vec3::ZERO);
        let name = if self.moment_cones { "emissive-split+moment-cones" } else { "emissive-split" };
        let mut d = Decomposition::new(name, params, map, lights, ambient, true);
        d.time_ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(d)
    }
}
