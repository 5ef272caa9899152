//! The CPU ground truth: an obvhs BVH over a [`scene::Scene`], rayon over tiles, and integrators
//! whose images every GPU approximation is measured against.
//!
//! - Deterministic: every (seed, pixel, sample) has its own random stream, so the same seed
//!   gives the same image bits for any thread count.
//! - Box pixel filter: a pixel is the plain mean of its samples, jittered uniformly (and
//!   stratified: Owen-scrambled Sobol points by default, see [`sampler`]).
//! - Integrators ([`Integrator`]): `EnvDirect` (MIS of the map and the BRDF, the truth for
//!   direct light), `Lights` (extracted cone lights with ray-traced visibility plus SH9 ambient)
//!   and `Path` (multi-bounce).
//! - AOVs: albedo, shading normal, depth, object id ([`Render`]).
//!
//! ```
//! use ref_tracer::{EnvLight, Integrator, RenderSettings, SceneBvh, Strategy, render};
//! let mut scene = scene::Scene::builtin("three_boxes").unwrap();
//! scene.camera.width = 32;
//! scene.camera.height = 24;
//! let map = envmap_sphere::default_map().resize(64, 32);
//! let env = EnvLight::new(&map);
//! let bvh = SceneBvh::new(&scene);
//! let settings = RenderSettings { spp: 2, seed: 1, ..RenderSettings::default() };
//! let img = render(&scene, &bvh, Some(&env), &Integrator::EnvDirect(Strategy::Mis), &settings, &|_, _| {});
//! assert_eq!((img.width, img.height, img.spp), (32, 24, 2));
//! assert!(img.color.iter().all(|c| c.is_finite()));
//! ```
//!
//! Architecture invariant: never depends on wgpu.

mod bvh;
mod emitters;
mod integrator;
pub mod metrics;
mod render;
pub mod sampler;
pub mod visibility;

pub use bvh::{BvhQuality, SceneBvh, SurfacePoint};
pub use emitters::Emitters;
pub use integrator::{AmbientMap, EnvLight, Integrator, LightSet, Strategy};
pub use render::{Progressive, Render, RenderSettings, render};
pub use sampler::SamplerKind;
