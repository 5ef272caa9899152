//! Shadow-boundary banding, measured: what paper 001's interleaved light sets (section 3.5)
//! remove and what they cost. A global set of K lights draws a penumbra as a staircase; 8 sets
//! with perturbed directions, interleaved over the pixels, trade the steps for noise.
//!
//! The case is an exact one: a long thin wall on a ground plane, turned to face the
//! decomposition's strongest light above the horizon and sized so that light's shadow edge falls
//! mid-image, seen straight from above, so every shadow edge of the wall runs down the image's
//! columns. The truth per column is the map itself (not its lights) integrated over every
//! direction of the upper hemisphere with ray-traced visibility: no noise, no lights, so a step
//! the truth lacks is the lights'. [`ref_tracer::metrics::banding`] compares the two.

use crate::TradeError;
use crate::measure::{Passes, technique};
use crate::setting::Shadow;
use envmap_sphere::EnvMap;
use glam::{DVec3, Vec3};
use gpu::{
    FrameLights, FrameShadows, GBufferPass, Gpu, LightShape, LitSettings, RotatedGrid, SceneGeometry, ShadeLight,
    WEBER_FRACTION,
};
use light_extract::Decomposition;
use rayon::prelude::*;
use ref_tracer::SceneBvh;
use ref_tracer::metrics::{Banding, banding, column_means};
use scene::{Camera, DistantLight, Material, Mesh, Object, Scene};
use std::time::Instant;

/// The ground's albedo (Lambertian).
pub const GROUND_ALBEDO: f32 = 0.5;
/// Where the strongest light's shadow edge falls, this far from the wall: the wall's height is
/// this times the tangent of the light's elevation (clamped to 0.05..50).
const EDGE_DISTANCE: f32 = 2.0;
/// The ground seen across the wall: from just past the wall's foot to a little beyond twice
/// [`EDGE_DISTANCE`].
const VIEW_ACROSS: f32 = 2.2 * EDGE_DISTANCE;
/// Half the wall's length and the ground's half-size: long enough that light passing the wall's
/// ends reaches the rows seen only from a few degrees above the horizon (the long-wall closed
/// form holds to 1 % in the tests).
const WALL_HALF_LENGTH: f32 = 40.0;
const GROUND_HALF: f32 = 120.0;
const WALL_THICKNESS: f32 = 0.02;
/// The truth integrates the map on at most this many columns (by luminance-weighted blocks, so
/// a sun keeps its exact direction).
const TRUTH_MAP_WIDTH: u32 = 512;
/// Lights below this elevation cast no shadow edge into the view worth measuring.
const MIN_ELEVATION_DEGREES: f32 = 3.0;

/// The wall scene of a decomposition and its truth per output column.
pub struct BandingCase {
    /// The wall, the ground and the camera (at the output size).
    pub scene: Scene,
    /// The light the wall faces (the strongest on the ground above the horizon).
    pub facing: DistantLight,
    /// The lights, their residual ambient and their clusters' extents (for interleaving).
    pub decomposition: Decomposition,
    /// Luminance of the ground per output column at its middle row, `None` where the column's
    /// first, middle or last row does not see the ground.
    truth: Vec<Option<f64>>,
}

impl BandingCase {
    /// The case of `decomposition`'s lights under `map` at `size` (width x height pixels).
    ///
    /// # Errors
    /// [`TradeError::Render`] when no light stands above the horizon (nothing casts an edge)
    /// or the size is empty.
    pub fn new(map: &EnvMap, decomposition: &Decomposition, size: (u32, u32)) -> Result<Self, TradeError> {
        if size.0 < 8 || size.1 < 2 {
            return Err(TradeError::Render(format!("banding: image {}x{} is too small", size.0, size.1)));
        }
        let min_y = MIN_ELEVATION_DEGREES.to_radians().sin();
        let facing = decomposition
            .lights
            .iter()
            .map(|l| l.light)
            .filter(|l| l.direction.y > min_y && envmap_sphere::color::luminance(l.power()) > 0.0)
            .max_by(|a, b| {
                let e = |l: &DistantLight| envmap_sphere::color::luminance(l.power()) * l.direction.y;
                e(a).total_cmp(&e(b))
            })
            .ok_or_else(|| {
                TradeError::Render(format!(
                    "banding: no light above {MIN_ELEVATION_DEGREES}° elevation to cast a shadow edge"
                ))
            })?;
        let scene = wall_scene(facing.direction, size);
        let truth = truth_columns(&scene, map);
        Ok(Self { scene, facing, decomposition: decomposition.clone(), truth })
    }

    /// Columns the truth measures.
    #[must_use]
    pub fn columns(&self) -> usize {
        self.truth.iter().flatten().count()
    }

    /// The truth's luminance per output column (`None`: not measured).
    #[must_use]
    pub fn truth(&self) -> &[Option<f64>] {
        &self.truth
    }

    /// (column, luminance) of the truth, or of `image`'s mean down each column, over the
    /// measured columns: the profiles [`ref_tracer::metrics::banding`] compares, unfiltered.
    #[must_use]
    pub fn profile(&self, image: Option<&[Vec3]>) -> Vec<(f64, f64)> {
        let means = image.map(|i| column_means(i, self.truth.len()));
        self.truth
            .iter()
            .enumerate()
            .filter_map(|(x, t)| t.map(|t| (x as f64, means.as_ref().map_or(t, |m| m[x]))))
            .collect()
    }
}

/// The wall facing `toward` (a unit direction above the horizon), the ground, and a camera
/// straight above the shadow side whose columns run along the wall.
fn wall_scene(toward: Vec3, (width, height): (u32, u32)) -> Scene {
    let h = Vec3::new(toward.x, 0.0, toward.z).try_normalize().unwrap_or(Vec3::X);
    // (h, Y, along) is right-handed: the cuboid keeps its winding
    let along = h.cross(Vec3::Y);
    let elevation_tan = toward.y / toward.x.hypot(toward.z).max(1e-6);
    let wall_height = (EDGE_DISTANCE * elevation_tan).clamp(0.05, 50.0);
    // the wall's lit face at h-distance WALL_THICKNESS, its shadowed face through the origin
    let corner = -along * WALL_HALF_LENGTH;
    let wall = {
        let mut m = Mesh::cuboid(Vec3::ZERO, Vec3::new(WALL_THICKNESS, wall_height, 2.0 * WALL_HALF_LENGTH));
        for p in &mut m.positions {
            *p = corner + h * p.x + Vec3::Y * p.y + along * p.z;
        }
        if let Some(normals) = m.normals.as_mut() {
            for n in normals.iter_mut() {
                *n = h * n.x + Vec3::Y * n.y + along * n.z;
            }
        }
        m
    };
    let ground = Mesh::quad(
        Vec3::new(-GROUND_HALF, 0.0, GROUND_HALF),
        Vec3::new(2.0 * GROUND_HALF, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -2.0 * GROUND_HALF),
        1,
        1,
    );
    let centre = -h * (VIEW_ACROSS * 0.5 - 0.05 * EDGE_DISTANCE);
    let eye_height = 20.0 + 2.0 * wall_height;
    let hfov_degrees = 2.0 * (VIEW_ACROSS * 0.5 / eye_height).atan().to_degrees();
    Scene {
        name: "banding_wall".into(),
        objects: vec![
            Object { name: "ground".into(), mesh: ground, material: Material::lambert(GROUND_ALBEDO) },
            Object { name: "wall".into(), mesh: wall, material: Material::lambert(GROUND_ALBEDO) },
        ],
        camera: Camera { eye: centre + Vec3::Y * eye_height, target: centre, up: along, hfov_degrees, width, height },
        point_lights: Vec::new(),
        textures: Vec::new(),
    }
}

/// The map as (direction, radiance x solid angle) per block of texels of at most
/// [`TRUTH_MAP_WIDTH`] columns, upper hemisphere only; each block's direction is its
/// luminance-weighted mean, so a sun smaller than a block keeps its direction.
fn map_directions(map: &EnvMap) -> Vec<(Vec3, DVec3)> {
    let (w, h) = (map.width(), map.height());
    let f = w.div_ceil(TRUTH_MAP_WIDTH).max(1);
    let mut out = Vec::new();
    for bj in (0..h).step_by(f as usize) {
        for bi in (0..w).step_by(f as usize) {
            let (mut power, mut weighted, mut plain) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
            for j in bj..(bj + f).min(h) {
                let omega = map.texel_solid_angle(j);
                for i in bi..(bi + f).min(w) {
                    let d = map.texel_dir(i, j).as_dvec3();
                    let l = map.pixel(i, j).as_dvec3() * omega;
                    power += l;
                    weighted += d * envmap_sphere::color::luminance_f64(l.to_array()).max(0.0);
                    plain += d;
                }
            }
            let dir = weighted.try_normalize().or_else(|| plain.try_normalize()).unwrap_or(DVec3::Y).as_vec3();
            if dir.y > 0.0 && power != DVec3::ZERO {
                out.push((dir, power));
            }
        }
    }
    out
}

/// The ground's luminance per output column at the middle row, by the map integrated with
/// ray-traced visibility; `None` for a column whose first, middle or last row does not see
/// the ground on the wall's shadow side.
fn truth_columns(scene: &Scene, map: &EnvMap) -> Vec<Option<f64>> {
    let bvh = SceneBvh::new(scene);
    let cam = scene.camera;
    let rays = cam.rays();
    let directions = map_directions(map);
    let ground = |x: u32, y: u32| -> Option<Vec3> {
        let (o, d) = rays.ray(x as f32 + 0.5, y as f32 + 0.5);
        let hit = bvh.intersect(o, d, f32::INFINITY)?;
        (hit.object == 0 && hit.position.y.abs() < 1e-3).then_some(hit.position)
    };
    let eps = bvh.epsilon();
    (0..cam.width)
        .into_par_iter()
        .map(|x| {
            for y in [0, cam.height - 1] {
                ground(x, y)?;
            }
            let p = ground(x, cam.height / 2)?;
            let origin = p + Vec3::Y * eps;
            let e: DVec3 = directions
                .iter()
                .filter(|(d, _)| !bvh.occluded(origin, *d, f32::INFINITY))
                .map(|(d, l)| *l * f64::from(d.y))
                .sum();
            Some(envmap_sphere::color::luminance_f64((e * f64::from(GROUND_ALBEDO) / std::f64::consts::PI).to_array()))
        })
        .collect()
}

/// How a frame interleaves light sets (paper 001, section 3.5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interleave {
    /// Light sets, the lights themselves first (1: no interleaving).
    pub sets: usize,
    /// Each extra set's directions perturbed within this fraction of the light's cluster
    /// extent (`light_extract::interleaved_sets`).
    pub jitter: f32,
}

impl Interleave {
    /// The lights alone.
    pub const NONE: Interleave = Interleave { sets: 1, jitter: 0.0 };
    /// Paper 001's: 8 sets, perturbed within 0.1 of the extent.
    pub const PAPER: Interleave =
        Interleave { sets: light_extract::INTERLEAVED_SETS, jitter: light_extract::INTERLEAVED_JITTER };

    /// `1`, or `8 x 0.1` (sets x jitter).
    #[must_use]
    pub fn name(&self) -> String {
        if self.sets <= 1 { "1".into() } else { format!("{} x {}", self.sets, self.jitter) }
    }
}

/// One banding measurement: a technique with one light set or the interleaved sets.
#[derive(Clone, Debug, PartialEq)]
pub struct BandingRow {
    /// The technique's [`Shadow::name`].
    pub technique: String,
    /// The light sets.
    pub interleave: Interleave,
    /// The figures; `None` when the columns show no contrast to measure against.
    pub banding: Option<Banding>,
    /// The shadow passes' time, ms, over all sets (their clocks as `gpu::totals` sums them).
    pub shadow_ms: f64,
    /// The frame's wall time, ms: G-buffer (its points read back), shadows, shading, gathering,
    /// the image read back.
    pub frame_ms: f64,
    /// The frame, resolved to the output's pixels.
    pub image: Vec<Vec3>,
}

/// Renders `case` with its lights shadowed by `shadow` on a rotated grid of `supersample`² + 1
/// samples per pixel, with `interleave`'s light sets, and measures its banding against the
/// truth at the scale of the interleaving tile's width in pixels (4 for paper 001's 8 sets,
/// whatever the row's sets: a coarser scale than the grid's rolled tile needs, and the same for
/// every row). Every light is shadowed (no Weber skipping: a skipped shadow has no edge to band).
///
/// # Errors
/// No set, or more than `gpu::MAX_SETS`; a technique that cannot shadow distant lights; GPU
/// failures.
pub fn measure_banding(
    gpu: &Gpu,
    passes: &Passes,
    case: &BandingCase,
    shadow: &Shadow,
    interleave: Interleave,
    supersample: u32,
) -> Result<BandingRow, TradeError> {
    let sets = interleave.sets;
    if sets == 0 || sets > gpu::MAX_SETS as usize || shadow.for_point_lights() {
        return Err(TradeError::Render(format!("banding: {} with {sets} light sets", shadow.name())));
    }
    let decomposition = &case.decomposition;
    let grid = RotatedGrid::new(&case.scene.camera, supersample.max(1));
    let mut scene = case.scene.clone();
    scene.camera = *grid.camera();
    let geometry = SceneGeometry::upload(gpu, &scene)?;
    let technique = technique(gpu, &scene, shadow)?;
    let light_sets: Vec<Vec<DistantLight>> =
        light_extract::interleaved_sets(&decomposition.lights, sets, interleave.jitter, 0)
            .into_iter()
            .map(|set| set.iter().map(|l| l.light).collect())
            .collect();
    // the toolkit's recorded frame, every light of every set shadowed (no Weber skipping)
    let lit = passes.lit_frame(gpu, (scene.camera.width, scene.camera.height))?;
    let view = GBufferPass::camera_view(&geometry, &scene.camera);
    let shade: Vec<Vec<ShadeLight>> = light_sets.iter().map(|s| s.iter().map(ShadeLight::from).collect()).collect();
    let shapes: Vec<Vec<LightShape>> = light_sets.iter().map(|s| s.iter().map(LightShape::from).collect()).collect();
    let frames: Vec<FrameLights> = shade
        .iter()
        .zip(&shapes)
        .map(|(lights, shapes)| FrameLights {
            lights,
            shapes,
            directs: lights.len(),
            ambient: Some(&decomposition.ambient_sh),
            // the camera sees only ground where it measures
            specular_ambient: None,
            background: None,
        })
        .collect();
    let settings = LitSettings { weber: false, time_lights: true, ..LitSettings::default() };
    let t = Instant::now();
    let (texture, reports) = match technique.as_deref() {
        None => {
            let frame = lit.render(gpu, &geometry, &view, &frames[0], None, &settings)?;
            gpu.wait(None)?;
            frame.finish_reports(gpu)?
        }
        // one set too: its gathering is a copy, and every row takes the same path
        Some(technique) => {
            let shadows = FrameShadows { direct: technique, indirect: technique };
            let image = lit.render_interleaved(gpu, &geometry, &view, &frames, shadows, &settings, None)?;
            gpu.wait(None)?;
            image.finish_reports(gpu)?
        }
    };
    let image = gpu::read_hdr(gpu, &texture)?;
    let frame_ms = t.elapsed().as_secs_f64() * 1e3;
    let image = grid.resolve(&image);
    // every row at the scale of paper 001's tile (or a larger one's), so rows compare
    let scale = gpu::interleave_tile(sets.max(light_extract::INTERLEAVED_SETS) as u32).0 as usize;
    Ok(BandingRow {
        technique: shadow.name(),
        interleave,
        banding: banding(&image, case.scene.camera.width as usize, &case.truth, f64::from(WEBER_FRACTION), scale),
        shadow_ms: gpu::totals(&reports).0.as_secs_f64() * 1e3,
        frame_ms,
        image,
    })
}
