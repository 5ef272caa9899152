//! What the viewer draws: a scene lit by a map's decomposition, with every shadow technique
//! made once, drawn through the toolkit's recorded frame (`gpu::LitFrame`) as any renderer
//! would embed it: the libraries' public API only, nothing of the harnesses.

use envmap_sphere::EnvMap;
use glam::{Affine3A, Vec3};
use gpu::{
    Background, FrameLights, FrameShadows, GBufferPass, Gpu, GpuError, JointBilateral, LightShape, LitFrame,
    LitSettings, PrefilterSettings, RenderedFrame, SceneGeometry, ShadeLight, ShadowTechnique, SpecularAmbient,
    SplitSettings,
};
use light_extract::Decomposition;
use penumbra_wedge::{WedgeSettings, Wedges};
use shadowmap_paraboloid::{MapTechnique, Pcss, ShadowSettings, Technique};

/// The shadow techniques the viewer switches between.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ViewTechnique {
    /// Paper 001's frame: penumbra wedges for the EnvDirects at full resolution, 1024²
    /// orthographic maps (3 x 3 PCF) for the EnvIndirects at half, joint-bilateral upsampled.
    Paper001,
    /// Penumbra wedges (paper 000) for every light.
    Wedges,
    /// 1024² orthographic maps with 3 x 3 PCF for every light.
    Maps,
    /// 1024² orthographic maps with percentage-closer soft shadows for every light.
    Pcss,
    /// No shadows: the lights and ambient unshadowed.
    None,
}

impl ViewTechnique {
    /// Every technique, in the order the `T` key cycles through them.
    pub(crate) const ALL: [Self; 5] = [Self::Paper001, Self::Wedges, Self::Maps, Self::Pcss, Self::None];

    /// Its name on the command line and in the JSON.
    pub(crate) fn name(self) -> &'static str {
        match self {
            Self::Paper001 => "paper001",
            Self::Wedges => "wedges",
            Self::Maps => "maps",
            Self::Pcss => "pcss",
            Self::None => "none",
        }
    }

    /// The technique named `name`.
    ///
    /// # Errors
    /// An unknown name, listing the known ones.
    pub(crate) fn parse(name: &str) -> Result<Self, String> {
        super::named(&Self::ALL, Self::name, "technique", name)
    }

    /// The next one in [`ViewTechnique::ALL`].
    pub(crate) fn next(self) -> Self {
        super::after(&Self::ALL, self)
    }
}

/// The map's side of the stage: its decomposition and what the GPU keeps of it.
struct Lighting {
    decomposition: Decomposition,
    background: Background,
    specular: SpecularAmbient,
    /// The map's turn about +Y, radians: the lights, the ambient's SH9, the background and the
    /// specular ambient turn together, nothing extracted again.
    turn: f32,
    /// The decomposition's lights and ambient turned by `turn`, as frames draw them (made when
    /// the turn changes, not each frame).
    shade: Vec<ShadeLight>,
    shapes: Vec<LightShape>,
    ambient: envmap_sphere::Sh9,
    /// A white ground under the map, exposed to middle grey.
    exposure: f32,
}

impl Lighting {
    fn new(gpu: &Gpu, map: &EnvMap, lights: usize) -> Result<Self, String> {
        let extractor = light_extract::extractor(light_extract::DEFAULT_METHOD, lights)
            .ok_or_else(|| format!("cannot extract {lights} lights"))?;
        let mut decomposition = extractor.extract(map).map_err(|e| e.to_string())?;
        decomposition.sort_directs_first();
        let e = |e: GpuError| e.to_string();
        // a white Lambertian ground facing up has radiance E(up) / pi: that goes to 0.18
        let ground =
            envmap_sphere::luminance(envmap_sphere::Sh9::project(map).irradiance(Vec3::Y)) / std::f32::consts::PI;
        let exposure = if ground.is_finite() && ground > 0.0 { 0.18 / ground } else { 1.0 };
        let mut lighting = Self {
            background: Background::upload(gpu, map).map_err(e)?,
            specular: SpecularAmbient::new(gpu, &decomposition.ambient, &PrefilterSettings::default()).map_err(e)?,
            decomposition,
            exposure,
            turn: 0.0,
            shade: Vec::new(),
            shapes: Vec::new(),
            ambient: envmap_sphere::Sh9::default(),
        };
        lighting.set_turn(0.0);
        Ok(lighting)
    }

    fn set_turn(&mut self, radians: f32) {
        self.background.set_turn(radians);
        self.specular.set_turn(radians);
        self.turn = self.background.turn();
        let q = glam::Quat::from_rotation_y(self.turn);
        let d = &self.decomposition;
        let turned: Vec<scene::DistantLight> =
            d.lights.iter().map(|l| scene::DistantLight { direction: q * l.light.direction, ..l.light }).collect();
        self.shade = turned.iter().map(ShadeLight::from).collect();
        self.shapes = turned.iter().map(LightShape::from).collect();
        self.ambient = d.ambient_sh.rotated(q);
    }
}

/// The scene's side: its geometry and the techniques made for it.
struct Geometry {
    scene: scene::Scene,
    geometry: SceneGeometry,
    wedges: Wedges,
    maps: MapTechnique,
    pcss: MapTechnique,
    /// The object the keyboard and mouse move, and its offset on the ground.
    moving: Option<usize>,
    offset: Vec3,
}

impl Geometry {
    fn new(gpu: &Gpu, scene: scene::Scene) -> Result<Self, String> {
        let e = |e: GpuError| e.to_string();
        let maps_settings = ShadowSettings { resolution: 1024, pcf_radius: 1, ..ShadowSettings::default() };
        let maps = MapTechnique::new(gpu, &scene, Technique::Orthographic, maps_settings, 1).map_err(e)?;
        let pcss =
            maps.variant(Technique::Orthographic, ShadowSettings { pcss: Some(Pcss::default()), ..maps_settings }, 1);
        let moving = scene.objects.iter().position(|o| o.name != "ground");
        Ok(Self {
            geometry: SceneGeometry::upload(gpu, &scene).map_err(e)?,
            wedges: Wedges::new(gpu, &scene, WedgeSettings::default()),
            maps,
            pcss,
            scene,
            moving,
            offset: Vec3::ZERO,
        })
    }
}

/// Everything the viewer draws, and the frame it draws through.
pub(crate) struct Stage {
    lighting: Lighting,
    content: Geometry,
    lit: LitFrame,
    /// The technique drawn.
    pub technique: ViewTechnique,
    /// Lights extracted from the map.
    pub lights: usize,
}

impl Stage {
    /// `scene` (its camera's size is the frame's) lit by `map` decomposed into `lights` lights.
    ///
    /// # Errors
    /// Extraction or GPU failures, as one line.
    pub(crate) fn new(
        gpu: &Gpu,
        scene: scene::Scene,
        map: &EnvMap,
        lights: usize,
        technique: ViewTechnique,
    ) -> Result<Self, String> {
        let size = (scene.camera.width, scene.camera.height);
        Ok(Self {
            lighting: Lighting::new(gpu, map, lights)?,
            content: Geometry::new(gpu, scene)?,
            lit: LitFrame::new(gpu, size).map_err(|e| e.to_string())?,
            technique,
            lights,
        })
    }

    /// The scene as loaded (objects at rest).
    pub(crate) fn scene(&self) -> &scene::Scene {
        &self.content.scene
    }

    /// The exposure that shows a white ground under the map as middle grey.
    pub(crate) fn exposure(&self) -> f32 {
        self.lighting.exposure
    }

    /// The frame's size.
    pub(crate) fn size(&self) -> (u32, u32) {
        self.lit.size()
    }

    /// Frames of `size` from now on (a resized window).
    ///
    /// # Errors
    /// Sizes beyond the adapter's limits.
    pub(crate) fn resize(&mut self, gpu: &Gpu, size: (u32, u32)) -> Result<(), String> {
        if size != self.size() {
            self.lit = LitFrame::new(gpu, size).map_err(|e| e.to_string())?;
            (self.content.scene.camera.width, self.content.scene.camera.height) = size;
        }
        Ok(())
    }

    /// A new map: decomposed again, its lights and ambient replacing the old.
    ///
    /// # Errors
    /// As [`Stage::new`]; the stage is unchanged then.
    pub(crate) fn set_map(&mut self, gpu: &Gpu, map: &EnvMap) -> Result<(), String> {
        let mut lighting = Lighting::new(gpu, map, self.lights)?;
        lighting.set_turn(self.lighting.turn);
        self.lighting = lighting;
        Ok(())
    }

    /// Turns the map about +Y to `radians`: its lights, ambient and background together.
    pub(crate) fn set_turn(&mut self, radians: f32) {
        self.lighting.set_turn(radians);
    }

    /// The map's turn about +Y, radians in [0, 2 pi).
    pub(crate) fn turn(&self) -> f32 {
        self.lighting.turn
    }

    /// `lights` lights from `map` (the decomposition again).
    ///
    /// # Errors
    /// As [`Stage::set_map`].
    pub(crate) fn set_lights(&mut self, gpu: &Gpu, map: &EnvMap, lights: usize) -> Result<(), String> {
        let mut lighting = Lighting::new(gpu, map, lights)?;
        lighting.set_turn(self.lighting.turn);
        (self.lighting, self.lights) = (lighting, lights);
        Ok(())
    }

    /// A new scene (the frame's size kept): geometry and techniques made for it.
    ///
    /// # Errors
    /// GPU failures; the stage is unchanged then.
    pub(crate) fn set_scene(&mut self, gpu: &Gpu, mut scene: scene::Scene) -> Result<(), String> {
        (scene.camera.width, scene.camera.height) = self.size();
        self.content = Geometry::new(gpu, scene)?;
        Ok(())
    }

    /// The moving object's name, if the scene has one besides its ground.
    pub(crate) fn moving_object(&self) -> Option<&str> {
        self.content.moving.map(|k| self.content.scene.objects[k].name.as_str())
    }

    /// The moving object's index in the scene.
    pub(crate) fn moving_index(&self) -> Option<usize> {
        self.content.moving
    }

    /// The moving object's offset on the ground from its rest pose.
    pub(crate) fn offset(&self) -> Vec3 {
        self.content.offset
    }

    /// Moves the moving object to `offset` (x, z; y ignored) from its rest pose: a transform
    /// for the frame's geometry and every technique's, nothing rebuilt.
    ///
    /// # Errors
    /// A non-finite offset; GPU failures.
    pub(crate) fn move_object(&mut self, gpu: &Gpu, offset: Vec3) -> Result<(), String> {
        let Some(k) = self.content.moving else { return Ok(()) };
        let offset = Vec3::new(offset.x, 0.0, offset.z);
        if !offset.is_finite() {
            return Err(format!("object offset {offset} is not finite"));
        }
        let t = Affine3A::from_translation(offset);
        let c = &mut self.content;
        let e = |e: GpuError| e.to_string();
        c.geometry.set_transform(gpu, k, t).map_err(e)?;
        c.wedges.set_transform(gpu, k, t).map_err(e)?;
        // the PCSS variant shares the maps' geometry
        c.maps.set_transform(gpu, k, t).map_err(e)?;
        c.offset = offset;
        Ok(())
    }

    /// The scene's bounding box (the objects where they are now).
    pub(crate) fn bounds(&self) -> (Vec3, Vec3) {
        self.content.geometry.bounds
    }

    /// Records and submits one frame from `camera` (of the frame's size): the toolkit's
    /// recorded frame, submitted and not waited for.
    ///
    /// # Errors
    /// GPU failures.
    pub(crate) fn render(&self, gpu: &Gpu, camera: &scene::Camera) -> Result<RenderedFrame, GpuError> {
        let l = &self.lighting;
        let lights = &l.shade;
        let c = &self.content;
        let view = GBufferPass::camera_view(&c.geometry, camera);
        let (directs, shadows): (usize, Option<FrameShadows>) = match self.technique {
            ViewTechnique::Paper001 => {
                (l.decomposition.directs(), Some(FrameShadows { direct: &c.wedges, indirect: &c.maps }))
            }
            ViewTechnique::Wedges => (lights.len(), Some(both(&c.wedges))),
            ViewTechnique::Maps => (lights.len(), Some(both(&c.maps))),
            ViewTechnique::Pcss => (lights.len(), Some(both(&c.pcss))),
            ViewTechnique::None => (lights.len(), None),
        };
        let frame_lights = FrameLights {
            lights,
            shapes: &l.shapes,
            directs,
            ambient: Some(&l.ambient),
            specular_ambient: Some(&l.specular),
            background: Some(&l.background),
        };
        // paper 001's half resolution where the size halves evenly (a window can be any size)
        let (w, h) = self.size();
        let indirect_scale = if w % 2 == 0 && h % 2 == 0 { 2 } else { 1 };
        let settings = LitSettings {
            split: SplitSettings { indirect_scale, upsample: JointBilateral::PAPER },
            ..LitSettings::default()
        };
        self.lit.render(gpu, &c.geometry, &view, &frame_lights, shadows, &settings)
    }
}

fn both(t: &dyn ShadowTechnique) -> FrameShadows<'_> {
    FrameShadows { direct: t, indirect: t }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_technique_parses_from_its_name_and_the_cycle_visits_each_once() {
        let mut t = ViewTechnique::Paper001;
        for _ in 0..ViewTechnique::ALL.len() {
            assert_eq!(ViewTechnique::parse(t.name()), Ok(t));
            t = t.next();
        }
        assert_eq!(t, ViewTechnique::Paper001);
        let err = ViewTechnique::parse("raytraced").unwrap_err();
        assert!(err.contains("raytraced") && err.contains("pcss"), "{err}");
    }

    fn frame(gpu: &Gpu, stage: &Stage) -> Vec<Vec3> {
        let camera = stage.scene().camera;
        let f = stage.render(gpu, &camera).unwrap_or_else(|e| panic!("{e}"));
        gpu.wait(None).unwrap_or_else(|e| panic!("{e}"));
        gpu::read_hdr(gpu, &f.texture).unwrap_or_else(|e| panic!("{e}"))
    }

    /// Pixels whose channels differ by more than 1 % of the larger (and 1e-4).
    fn differing(a: &[Vec3], b: &[Vec3]) -> usize {
        a.iter()
            .zip(b)
            .filter(|(x, y)| (**x - **y).abs().max_element() > (0.01 * x.max(**y).max_element()).max(1e-4))
            .count()
    }

    #[test]
    fn a_turned_map_draws_as_the_world_turned_the_other_way() {
        // the map turned by a about +Y (its lights, ambient and background together, nothing
        // extracted again) against the scene and camera turned by -a under the map as it is
        let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
        let map = envmap_sphere::default_map();
        let mut scene = scene::Scene::builtin("spheres_box").unwrap_or_else(|e| panic!("{e}"));
        (scene.camera.width, scene.camera.height) = (64, 48);
        let a = 1.1f32;
        let back = glam::Quat::from_rotation_y(-a);
        let mut world = scene.clone();
        for o in &mut world.objects {
            o.mesh.transform(&Affine3A::from_quat(back));
        }
        (world.camera.eye, world.camera.target) = (back * scene.camera.eye, back * scene.camera.target);
        for technique in [ViewTechnique::None, ViewTechnique::Paper001] {
            let mut stage = Stage::new(&gpu, scene.clone(), &map, 8, technique).unwrap_or_else(|e| panic!("{e}"));
            let still = frame(&gpu, &stage);
            stage.set_turn(a);
            assert!((stage.turn() - a).abs() < 1e-6);
            let turned = frame(&gpu, &stage);
            let want =
                frame(&gpu, &Stage::new(&gpu, world.clone(), &map, 8, technique).unwrap_or_else(|e| panic!("{e}")));
            let changed = differing(&still, &turned);
            assert!(changed > still.len() / 4, "{}: the turn changed {changed} pixels", technique.name());
            let off = differing(&turned, &want);
            // measured: none differ by 1 %
            assert!(off <= still.len() / 1000, "{}: {off} of {} pixels differ", technique.name(), still.len());
        }
    }

    #[test]
    fn a_moved_object_draws_as_one_built_where_it_went_and_moving_back_restores_the_frame() {
        let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
        let map = envmap_sphere::default_map();
        let mut scene = scene::Scene::builtin("spheres_box").unwrap_or_else(|e| panic!("{e}"));
        (scene.camera.width, scene.camera.height) = (64, 48);
        for technique in [ViewTechnique::Paper001, ViewTechnique::Pcss] {
            let mut stage = Stage::new(&gpu, scene.clone(), &map, 4, technique).unwrap_or_else(|e| panic!("{e}"));
            let k = stage.content.moving.unwrap_or_else(|| panic!("spheres_box has an object"));
            let rest = frame(&gpu, &stage);
            let offset = Vec3::new(0.4, 0.0, -0.2);
            stage.move_object(&gpu, offset).unwrap_or_else(|e| panic!("{e}"));
            let moved = frame(&gpu, &stage);
            // the object and its shadows went somewhere else
            let changed = differing(&rest, &moved);
            assert!(changed > rest.len() / 50, "{}: {changed} pixels changed", technique.name());
            // as drawn by a stage built with the object there from the start
            let mut there = scene.clone();
            there.objects[k].mesh.transform(&Affine3A::from_translation(offset));
            let built = Stage::new(&gpu, there, &map, 4, technique).unwrap_or_else(|e| panic!("{e}"));
            let off = differing(&moved, &frame(&gpu, &built));
            assert!(off <= rest.len() / 1000, "{}: {off} pixels differ from the built scene", technique.name());
            stage.move_object(&gpu, Vec3::ZERO).unwrap_or_else(|e| panic!("{e}"));
            let back = differing(&rest, &frame(&gpu, &stage));
            assert!(back <= rest.len() / 1000, "{}: {back} pixels differ after moving back", technique.name());
            assert!(stage.move_object(&gpu, Vec3::new(f32::NAN, 0.0, 0.0)).is_err());
        }
    }
}
