//! The integrators: radiance along one camera ray.
//!
//! - `EnvDirect`: direct illumination from the map, multiple importance sampling of one map
//!   sample and one BRDF sample with the power heuristic; the truth approximations are measured
//!   against. `Strategy` isolates either technique for tests.
//! - `Lights`: direct illumination from distant cone lights with ray-traced visibility (cone
//!   sampling, combined by MIS with a BRDF sample on glossy surfaces), plus an ambient term: SH9
//!   irradiance on the diffuse lobe, the ambient map on the specular lobe by MIS pairs of a map
//!   sample and a BRDF sample (unshadowed, or shadowed by sampled visibility).
//! - `Path`: multi-bounce path tracing with the same MIS next-event estimation at every vertex.
//! - `PathEmissive`: the same with emitting objects (one-sided, found by BRDF samples) and the
//!   map optional: the truth for scenes lit by their own lamps and windows.
//!
//! Only `PathEmissive` knows emitting surfaces; elsewhere the map (or the lights) is the only
//! light.

use crate::bvh::{SceneBvh, SurfacePoint};
use crate::emitters::Emitters;
use crate::sampler::PixelSampler;
use envmap_sphere::{EnvDistribution, EnvMap, Sh9};
use glam::Vec3;
use scene::DistantLight;
use scene::brdf::Frame;

/// Which sampling techniques `EnvDirect` combines.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Strategy {
    /// One map sample and one BRDF sample, power heuristic.
    #[default]
    Mis,
    /// Map sampling only.
    EnvOnly,
    /// BRDF sampling only.
    BrdfOnly,
}

/// The environment as a light: radiance (bilinear, like Mitsuba's `envmap`) and its sampler.
pub struct EnvLight<'a> {
    /// The map.
    pub map: &'a EnvMap,
    /// Its importance sampling distribution. An incomplete one (MIS-compensated) is valid with
    /// BRDF samples ([`Strategy::Mis`], path tracing), not for [`Strategy::EnvOnly`]. Drawn by
    /// inverting its cdfs (a guide table makes that O(1) on average), which keeps the Sobol
    /// sampler's stratification: an alias table, as fast here, scrambles it, and needed 1.3x /
    /// 1.8x the samples for the same RMSE at 16 / 64 spp on `spheres_box`.
    pub dist: EnvDistribution,
}

impl<'a> EnvLight<'a> {
    /// The light for MIS ([`Strategy::Mis`] and path tracing): map samples from
    /// [`EnvDistribution::for_bilinear_compensated`], which leaves the map's smooth part to
    /// the BRDF sample.
    #[must_use]
    pub fn new(map: &'a EnvMap) -> Self {
        Self { map, dist: EnvDistribution::for_bilinear_compensated(map) }
    }

    /// The light with the complete distribution ([`EnvDistribution::for_bilinear`]: positive
    /// pdf wherever the map is), which map-only sampling needs.
    #[must_use]
    pub fn complete(map: &'a EnvMap) -> Self {
        Self { map, dist: EnvDistribution::for_bilinear(map) }
    }

    /// The light `strategy` needs: complete for [`Strategy::EnvOnly`], compensated otherwise.
    #[must_use]
    pub fn for_strategy(map: &'a EnvMap, strategy: Strategy) -> Self {
        if strategy == Strategy::EnvOnly { Self::complete(map) } else { Self::new(map) }
    }
}

/// Extracted lights plus ambient, for the `Lights` integrator.
pub struct LightSet<'a> {
    /// Distant cone lights.
    pub lights: &'a [DistantLight],
    /// Extra light sets of interleaved sampling (paper 001, section 3.5): pixel sample k uses
    /// set k mod (sets + 1), `lights` being set 0 — stratified, so with a sample count that is a
    /// multiple of the set count each set lights a pixel equally often: the converged result of
    /// interleaving followed by a perfect filter. Empty: `lights` only.
    pub interleaved: &'a [Vec<DistantLight>],
    /// Ambient radiance as SH9 (its irradiance lights the diffuse lobe), if any. It may be
    /// signed (a residual, see `light_extract::Residual`): its irradiance is added unclamped.
    pub ambient: Option<Sh9>,
    /// The ambient radiance itself, which lights the specular lobe of glossy surfaces (and,
    /// when shadowed, the diffuse lobe's visibility samples): what a prefiltered specular map
    /// gives a renderer, without its approximation. `None`: only the lights reach the specular
    /// lobe.
    pub ambient_map: Option<&'a AmbientMap<'a>>,
    /// Shadow the ambient term by sampling visibility (cosine-weighted) instead of leaving it
    /// unshadowed.
    pub shadow_ambient: bool,
    /// What camera rays that miss see (the original map, usually).
    pub background: Option<&'a EnvMap>,
}

impl<'a> LightSet<'a> {
    /// `lights` alone: no interleaved sets, no ambient, a black background.
    #[must_use]
    pub fn new(lights: &'a [DistantLight]) -> Self {
        Self { lights, interleaved: &[], ambient: None, ambient_map: None, shadow_ambient: false, background: None }
    }
}

/// An ambient map, possibly signed (a residual), with a distribution of its magnitude: the
/// specular lobe's share of it is estimated by MIS of samples of that distribution and BRDF
/// samples, so a residual's spikes (a sun narrower than its light's cone) are found as `EnvDirect`
/// finds the sun.
pub struct AmbientMap<'a> {
    /// The radiance.
    pub map: &'a EnvMap,
    /// Samples |radiance| (luminance), complete.
    pub dist: EnvDistribution,
    /// Pairs of a map sample and a BRDF sample per pixel sample ([`AmbientMap::SAMPLES`]).
    pub samples: u32,
}

impl<'a> AmbientMap<'a> {
    /// `map` and the distribution of its magnitude; `None` for an all-zero map (the remainder
    /// of a partition into lights), which lights nothing and is worth no samples.
    #[must_use]
    pub fn new(map: &'a EnvMap) -> Option<Self> {
        if map.pixels().iter().all(|p| *p == Vec3::ZERO) {
            return None;
        }
        let magnitude = EnvMap::from_texels(map.width(), map.height(), |i, j| map.pixel(i, j).abs());
        Some(Self { map, dist: EnvDistribution::for_bilinear(&magnitude), samples: Self::SAMPLES })
    }

    /// Default pairs of samples per pixel sample: unshadowed, they cost map look-ups only.
    pub const SAMPLES: u32 = 4;
}

/// An integrator and its parameters.
pub enum Integrator<'a> {
    /// Direct illumination from the map.
    EnvDirect(Strategy),
    /// Direct illumination from extracted lights.
    Lights(LightSet<'a>),
    /// Path tracing; `max_depth` = 1 is direct illumination only.
    Path {
        /// Number of scattering events with next-event estimation.
        max_depth: u32,
    },
    /// Path tracing with emitting objects (one-sided, as a lamp's patch: see [`Emitters`]),
    /// the map optional. At every vertex, next-event estimation towards a point of an emitter
    /// (chosen by power) and the BRDF sample that hits one are combined by MIS (power
    /// heuristic). `max_depth` = d collects emitters seen directly and through up to d bounces.
    PathEmissive {
        /// Number of scattering events.
        max_depth: u32,
        /// The scene's emitters.
        emitters: &'a Emitters,
    },
}

fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 == 0.0 { 0.0 } else { a2 / (a2 + b2) }
}

/// Everything an estimator needs at a surface point.
struct Shading {
    p: Vec3,
    ng: Vec3,
    frame: Frame,
    wo: Vec3,
    /// the material at the point, its textures sampled
    material: scene::Material,
    eps: f32,
}

impl Shading {
    fn new(bvh: &SceneBvh, sp: &SurfacePoint, ray_dir: Vec3) -> Self {
        let frame = Frame::new(sp.shading_normal);
        Shading {
            p: sp.position,
            ng: sp.geometric_normal,
            wo: frame.to_local(-ray_dir),
            frame,
            material: bvh.material_at(sp),
            eps: bvh.epsilon(),
        }
    }

    /// f * cos for a world direction, zero when it leaves below the geometric surface.
    fn f_cos(&self, wi_world: Vec3) -> (Vec3, Vec3) {
        let wi = self.frame.to_local(wi_world);
        if wi_world.dot(self.ng) <= 0.0 || wi.z <= 0.0 {
            return (Vec3::ZERO, wi);
        }
        (self.material.eval_brdf(self.wo, wi) * wi.z, wi)
    }

    fn origin(&self) -> Vec3 {
        self.p + self.ng * self.eps
    }
}

impl Integrator<'_> {
    /// Radiance arriving along the camera ray `(origin, dir)`.
    #[must_use]
    pub fn radiance(
        &self,
        bvh: &SceneBvh,
        env: Option<&EnvLight>,
        origin: Vec3,
        dir: Vec3,
        s: &mut PixelSampler,
    ) -> Vec3 {
        match self {
            Self::EnvDirect(strategy) => {
                let env = env.expect("EnvDirect needs the map");
                match bvh.intersect_camera(origin, dir) {
                    None => env.map.lookup(dir),
                    Some(sp) => {
                        bvh.emission_at(&sp) + env_direct(bvh, env, &Shading::new(bvh, &sp, dir), *strategy, false, s).0
                    }
                }
            }
            Self::Lights(set) => match bvh.intersect_camera(origin, dir) {
                None => set.background.map_or(Vec3::ZERO, |m| m.lookup(dir)),
                Some(sp) => bvh.emission_at(&sp) + lights_direct(bvh, set, &Shading::new(bvh, &sp, dir), s),
            },
            Self::Path { max_depth } => {
                path(bvh, Some(env.expect("Path needs the map")), None, origin, dir, *max_depth, s)
            }
            Self::PathEmissive { max_depth, emitters } => path(bvh, env, Some(emitters), origin, dir, *max_depth, s),
        }
    }
}

/// The BRDF-sampled continuation of an `env_direct` estimate.
struct Continuation {
    /// World direction.
    dir: Vec3,
    /// f cos / pdf.
    weight: Vec3,
    /// The BRDF sample's density per solid angle.
    pdf: f32,
    /// What the ray hits (`None`: it escaped, and its light was counted), when asked for.
    hit: Option<SurfacePoint>,
}

/// One MIS estimate of direct light from the map. With `trace_brdf_ray`, the BRDF sample's ray
/// is traced to its closest hit and returned for path tracing to continue from, so the ray is
/// traversed once; without, an any-hit occlusion test decides its visibility.
fn env_direct(
    bvh: &SceneBvh,
    env: &EnvLight,
    sh: &Shading,
    strategy: Strategy,
    trace_brdf_ray: bool,
    s: &mut PixelSampler,
) -> (Vec3, Option<Continuation>) {
    let mut l = Vec3::ZERO;
    let u_env = s.next_2d();
    let (u_brdf, u_lobe) = (s.next_2d(), s.next_1d());
    // Both samples read the map and the pdf table before either ray is traced, the BRDF
    // sample's pdf look-up first: the cache misses of those scattered reads then overlap,
    // instead of each waiting behind a traversal.
    let brdf_sample = sh.material.sample_brdf(sh.wo, u_brdf, u_lobe).and_then(|(wi, pdf)| {
        let wi_world = sh.frame.to_world(wi);
        let (fc, _) = sh.f_cos(wi_world);
        (fc != Vec3::ZERO).then(|| {
            let looked_up = (strategy != Strategy::EnvOnly).then(|| {
                let uv = envmap_sphere::latlong::latlong_dir_to_uv(wi_world);
                (uv, (strategy == Strategy::Mis).then(|| env.dist.uv_pdf(uv)))
            });
            (wi_world, fc, pdf, looked_up)
        })
    });
    let env_sample = if strategy == Strategy::BrdfOnly { None } else { Some(env.dist.sample_dir(u_env)) };
    let brdf_sample = brdf_sample.map(|(wi_world, fc, pdf, looked_up)| {
        let term = looked_up.map(|(uv, env_pdf)| {
            let w = env_pdf.map_or(1.0, |env_pdf| power_heuristic(pdf, env_pdf));
            fc * env.map.lookup_uv(uv) * (w / pdf)
        });
        (wi_world, fc / pdf, pdf, term)
    });
    let env_term = env_sample.and_then(|ls| {
        let (fc, wi) = sh.f_cos(ls.dir);
        (ls.pdf > 0.0 && fc != Vec3::ZERO).then(|| {
            let w =
                if strategy == Strategy::Mis { power_heuristic(ls.pdf, sh.material.brdf_pdf(sh.wo, wi)) } else { 1.0 };
            (ls.dir, fc * env.map.lookup_uv(ls.uv) * (w / ls.pdf))
        })
    });
    if let Some((dir, term)) = env_term
        && !bvh.occluded(sh.origin(), dir, f32::INFINITY)
    {
        l += term;
    }
    let mut next = None;
    if let Some((wi_world, weight, pdf, term)) = brdf_sample {
        let hit = if trace_brdf_ray { bvh.intersect(sh.origin(), wi_world, f32::INFINITY) } else { None };
        let escaped = if trace_brdf_ray { hit.is_none() } else { !bvh.occluded(sh.origin(), wi_world, f32::INFINITY) };
        if escaped && let Some(term) = term {
            l += term;
        }
        next = Some(Continuation { dir: wi_world, weight, pdf, hit });
    }
    (l, next)
}

fn lights_direct(bvh: &SceneBvh, set: &LightSet, sh: &Shading, s: &mut PixelSampler) -> Vec3 {
    let mut l = Vec3::ZERO;
    let lights = if set.interleaved.is_empty() {
        set.lights
    } else {
        let k = (s.sample_index() % (set.interleaved.len() as u64 + 1)) as usize;
        if k == 0 { set.lights } else { &set.interleaved[k - 1] }
    };
    // A glossy lobe narrower than a cone makes cone sampling noisy: there each light combines
    // its cone sample with one BRDF sample shared by all lights (power heuristic, one sample of
    // each technique per light). Lambertian surfaces keep cone sampling alone.
    let glossy = sh.material.specular.is_some();
    for light in lights {
        let (dir, pdf) = light.sample_direction(s.next_2d());
        let (fc, wi) = sh.f_cos(dir);
        if fc != Vec3::ZERO && !bvh.occluded(sh.origin(), dir, f32::INFINITY) {
            let w = if glossy { power_heuristic(pdf, sh.material.brdf_pdf(sh.wo, wi)) } else { 1.0 };
            l += fc * light.radiance * (w / pdf);
        }
    }
    if let Some(sh9) = &set.ambient {
        let diffuse = sh.material.albedo * sh.material.diffuse_weight();
        if set.shadow_ambient {
            // cosine sampling: estimate of albedo/pi * integral L V cos = albedo * L(wi) V
            let wi = sh.frame.to_world(scene::brdf::sample_cosine_hemisphere(s.next_2d()));
            if wi.dot(sh.ng) > 0.0 && !bvh.occluded(sh.origin(), wi, f32::INFINITY) {
                // the map where there is one; SH9 radiance rings below zero near bright texels
                l += diffuse * set.ambient_map.map_or_else(|| sh9.eval(wi).max(Vec3::ZERO), |a| a.map.lookup(wi));
            }
        } else {
            l += diffuse * sh9.irradiance(sh.frame.n) * std::f32::consts::FRAC_1_PI;
        }
    }
    if !glossy {
        return l;
    }
    if let Some((wi, pdf)) = sh.material.sample_brdf(sh.wo, s.next_2d(), s.next_1d()) {
        let wi_world = sh.frame.to_world(wi);
        let (fc, _) = sh.f_cos(wi_world);
        let mut seen = Vec3::ZERO;
        for light in lights.iter().filter(|light| light.contains(wi_world)) {
            seen += light.radiance * power_heuristic(pdf, 1.0 / light.solid_angle);
        }
        l += arriving(bvh, sh, wi_world, fc * seen / pdf, Vec3::ZERO, false);
    }
    if let Some(a) = set.ambient_map {
        l += specular_ambient(bvh, sh, a, set.shadow_ambient, s);
    }
    l
}

/// The specular lobe's share of the ambient map: `a.samples` pairs of a BRDF sample and a map
/// sample, power heuristic. Unshadowed, the samples trace no ray, so several are cheap next to
/// the lights' shadow rays; they average out a residual's positive and negative parts (a sun
/// and the cone that replaced it), which one pair would estimate with much noise.
fn specular_ambient(bvh: &SceneBvh, sh: &Shading, a: &AmbientMap, shadow: bool, s: &mut PixelSampler) -> Vec3 {
    let mut l = Vec3::ZERO;
    // f_spec cos L / pdf with the power-heuristic weight of the pdfs (this, other)
    let term = |wi: Vec3, radiance: Vec3, pdf: f32, other: f32| {
        sh.material.eval_specular(sh.wo, wi) * wi.z * radiance * (power_heuristic(pdf, other) / pdf)
    };
    for _ in 0..a.samples {
        if let Some((wi, pdf)) = sh.material.sample_brdf(sh.wo, s.next_2d(), s.next_1d()) {
            let dir = sh.frame.to_world(wi);
            if sh.f_cos(dir).0 != Vec3::ZERO {
                // one direction -> lat-long conversion for both the radiance and the pdf
                let uv = envmap_sphere::latlong::latlong_dir_to_uv(dir);
                let t = term(wi, a.map.lookup_uv(uv), pdf, a.dist.uv_pdf(uv));
                l += arriving(bvh, sh, dir, Vec3::ZERO, t, shadow);
            }
        }
        let ls = a.dist.sample_dir(s.next_2d());
        let (fc, wi) = sh.f_cos(ls.dir);
        if ls.pdf > 0.0 && fc != Vec3::ZERO {
            let t = term(wi, a.map.lookup_uv(ls.uv), ls.pdf, sh.material.brdf_pdf(sh.wo, wi));
            l += arriving(bvh, sh, ls.dir, Vec3::ZERO, t, shadow);
        }
    }
    l / a.samples.max(1) as f32
}

/// What arrives from `dir`: `lit` (light, always shadowed) and `ambient` (shadowed only when
/// asked), one shadow ray at most.
fn arriving(bvh: &SceneBvh, sh: &Shading, dir: Vec3, lit: Vec3, ambient: Vec3, shadow_ambient: bool) -> Vec3 {
    let (shadowed, free) = if shadow_ambient { (lit + ambient, Vec3::ZERO) } else { (lit, ambient) };
    if shadowed != Vec3::ZERO && !bvh.occluded(sh.origin(), dir, f32::INFINITY) { free + shadowed } else { free }
}

fn path(
    bvh: &SceneBvh,
    env: Option<&EnvLight>,
    emitters: Option<&Emitters>,
    origin: Vec3,
    dir: Vec3,
    max_depth: u32,
    s: &mut PixelSampler,
) -> Vec3 {
    let emitters = emitters.filter(|e| !e.is_empty());
    let emitted = |sp: &SurfacePoint| match emitters {
        Some(e) if sp.front => e.emission(sp.object),
        _ => Vec3::ZERO,
    };
    let Some(mut sp) = bvh.intersect_camera(origin, dir) else {
        return env.map_or(Vec3::ZERO, |e| e.map.lookup(dir));
    };
    // emitting materials are found by BRDF samples only (no next-event estimation toward them)
    let (mut l, mut beta) = (emitted(&sp) + bvh.emission_at(&sp), Vec3::ONE);
    let mut d = dir;
    for depth in 0..max_depth {
        let sh = Shading::new(bvh, &sp, d);
        let last = depth + 1 == max_depth;
        if let Some(e) = emitters {
            l += beta * emitter_direct(bvh, e, &sh, s);
        }
        // the BRDF ray is traced to go on, and from the last vertex only to find emitters
        let next = match env {
            Some(env) => {
                // NEE with MIS; a BRDF ray that escapes is counted inside env_direct, so the
                // path continues only through its hit
                let (direct, next) =
                    env_direct(bvh, env, &sh, Strategy::Mis, !last || emitters.is_some() || bvh.emits(), s);
                l += beta * direct;
                next
            }
            None => brdf_continuation(bvh, &sh, s),
        };
        let Some(Continuation { dir: wi, weight, pdf, hit: Some(hit) }) = next else { break };
        beta *= weight;
        l += beta * bvh.emission_at(&hit);
        let le = emitted(&hit);
        if le != Vec3::ZERO
            && let Some(e) = emitters
        {
            // the emitter sample could have drawn this point too
            let cos = hit.geometric_normal.dot(wi).abs().max(1e-12);
            let light_pdf = e.pdf_area(hit.object) * hit.t * hit.t / cos;
            l += beta * le * power_heuristic(pdf, light_pdf);
        }
        if last {
            break;
        }
        if depth >= 3 {
            // Russian roulette
            let q = beta.max_element().min(0.95);
            if s.next_1d() >= q {
                break;
            }
            beta /= q;
        }
        (sp, d) = (hit, wi);
    }
    l
}

/// Next-event estimation towards a point of an emitter, MIS-weighted against the BRDF sample.
fn emitter_direct(bvh: &SceneBvh, emitters: &Emitters, sh: &Shading, s: &mut PixelSampler) -> Vec3 {
    let (u, uv) = (s.next_1d(), s.next_2d());
    let Some((y, n, le, pdf_area)) = emitters.sample(u, uv) else { return Vec3::ZERO };
    let origin = sh.origin();
    let to = y - origin;
    let dist = to.length();
    if dist <= 0.0 || pdf_area <= 0.0 {
        return Vec3::ZERO;
    }
    let wi = to / dist;
    // one-sided: the point must see the emitter's front
    let cos_light = -n.dot(wi);
    if cos_light <= 0.0 {
        return Vec3::ZERO;
    }
    let (fc, wi_local) = sh.f_cos(wi);
    if fc == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let pdf = pdf_area * dist * dist / cos_light;
    let t_max = (dist - 2.0 * bvh.epsilon()).max(0.0);
    if bvh.occluded(origin, wi, t_max) {
        return Vec3::ZERO;
    }
    fc * le * (power_heuristic(pdf, sh.material.brdf_pdf(sh.wo, wi_local)) / pdf)
}

/// A BRDF-sampled continuation without a map (emitters only), traced to its hit.
fn brdf_continuation(bvh: &SceneBvh, sh: &Shading, s: &mut PixelSampler) -> Option<Continuation> {
    let (u_brdf, u_lobe) = (s.next_2d(), s.next_1d());
    let (wi, pdf) = sh.material.sample_brdf(sh.wo, u_brdf, u_lobe)?;
    let wi_world = sh.frame.to_world(wi);
    let (fc, _) = sh.f_cos(wi_world);
    (fc != Vec3::ZERO && pdf > 0.0).then(|| Continuation {
        dir: wi_world,
        weight: fc / pdf,
        pdf,
        hit: bvh.intersect(sh.origin(), wi_world, f32::INFINITY),
    })
}
