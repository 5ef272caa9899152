//! Settings as data: one value names every knob of a frame, so the trade can be swept, stored,
//! merged and chosen from without knowing the techniques behind it.

use crate::techniques::TechniqueSpec;
use serde::{Deserialize, Serialize};
use shadowmap_paraboloid::{Pcss, Rejection, ShadowSettings, Technique};

/// How the extracted lights are shadowed on the GPU: each becomes a `gpu::ShadowTechnique`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Shadow {
    /// No shadows: the unshadowed lights (the trade's cheapest point).
    None,
    /// Orthographic shadow maps of `resolution`², PCF over (2 `pcf` + 1)² texels.
    Maps {
        /// Map resolution in texels.
        resolution: u32,
        /// PCF radius in texels.
        pcf: u32,
    },
    /// Percentage-closer soft shadows on maps of `resolution`².
    Pcss {
        /// Map resolution in texels.
        resolution: u32,
    },
    /// The average of `n` hard maps from points spread over the light's disk.
    MultiSample {
        /// Maps per light.
        n: u32,
        /// Map resolution in texels.
        resolution: u32,
    },
    /// Penumbra wedges (paper 000).
    Wedges,
    /// Paper 004's paraboloid maps from a point light (two for an omnidirectional light) of
    /// `resolution`², PCF over (2 `pcf` + 1)² texels; `subdivide`: the triangles split to 0.2 rad
    /// as seen from the light (a paraboloid bends straight edges; without, long ones miss).
    Paraboloid {
        /// Side of each paraboloid map, texels.
        resolution: u32,
        /// PCF radius in texels.
        pcf: u32,
        /// Triangles subdivided for the paraboloid's curvature.
        subdivide: bool,
    },
    /// Six 90° perspective maps of `resolution`² from a point light (the baseline).
    Cube {
        /// Side of each face, texels.
        resolution: u32,
        /// PCF radius in texels.
        pcf: u32,
    },
}

impl Shadow {
    /// A short name: `maps_2048_pcf1`, `pcss_1024`, `maps_1024_x8`, `wedges`, `none`,
    /// `paraboloid_1024` (`_pcf1`, `_unsubdivided`), `cube_592` (`_pcf1`).
    #[must_use]
    pub fn name(&self) -> String {
        match *self {
            Shadow::None => "none".into(),
            Shadow::Maps { resolution, pcf } => format!("maps_{resolution}_pcf{pcf}"),
            Shadow::Pcss { resolution } => format!("pcss_{resolution}"),
            Shadow::MultiSample { n, resolution } => format!("maps_{resolution}_x{n}"),
            Shadow::Wedges => "wedges".into(),
            Shadow::Paraboloid { resolution, pcf, subdivide } => format!(
                "paraboloid_{resolution}{}{}",
                if pcf > 0 { format!("_pcf{pcf}") } else { String::new() },
                if subdivide { "" } else { "_unsubdivided" }
            ),
            Shadow::Cube { resolution, pcf } => {
                format!("cube_{resolution}{}", if pcf > 0 { format!("_pcf{pcf}") } else { String::new() })
            }
        }
    }

    /// How to build this technique ([`crate::TechniqueBuilder`]), `None` for [`Shadow::None`].
    #[must_use]
    pub fn spec(&self) -> Option<TechniqueSpec> {
        let base = ShadowSettings::default();
        let maps = |projection, settings, samples| Some(TechniqueSpec::Maps { projection, settings, samples });
        match *self {
            Shadow::Maps { resolution, pcf } => {
                TechniqueSpec::orthographic(ShadowSettings { resolution, pcf_radius: pcf, ..base }, 1).into()
            }
            Shadow::Pcss { resolution } => TechniqueSpec::orthographic(
                ShadowSettings { resolution, pcf_radius: 0, pcss: Some(Pcss::default()), ..base },
                1,
            )
            .into(),
            Shadow::MultiSample { n, resolution } => {
                TechniqueSpec::orthographic(ShadowSettings { resolution, pcf_radius: 0, ..base }, n).into()
            }
            Shadow::Paraboloid { resolution, pcf, subdivide } => maps(
                Technique::DualParaboloid,
                ShadowSettings {
                    resolution,
                    pcf_radius: pcf,
                    subdivide_angle: if subdivide { base.subdivide_angle } else { None },
                    ..base
                },
                1,
            ),
            // cube faces are perspective views: straight edges stay straight
            Shadow::Cube { resolution, pcf } => {
                maps(Technique::Cube, ShadowSettings { resolution, pcf_radius: pcf, subdivide_angle: None, ..base }, 1)
            }
            Shadow::Wedges => Some(TechniqueSpec::wedges()),
            Shadow::None => None,
        }
    }

    /// Whether it shadows point lights (paraboloid and cube maps) rather than distant ones.
    #[must_use]
    pub fn for_point_lights(&self) -> bool {
        matches!(self, Shadow::Paraboloid { .. } | Shadow::Cube { .. })
    }
}

/// What a setting draws, and so which truth its error is measured against.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Family {
    /// A scene lit by an environment map through its extracted lights, against the
    /// `env-direct` truth (RMSE in linear radiance).
    Env,
    /// A scene's point lights, shadowed by point-light maps, against the same shading with
    /// ray-traced visibility (RMSE in linear radiance).
    Point,
    /// A synthetic object composited into a real scene's photograph (paper 003), against the
    /// real scene path traced with the object (RMSE in 8-bit codes over the pixels it changed).
    Composite,
}

impl Family {
    /// Every family, in report order.
    pub const ALL: [Family; 3] = [Family::Env, Family::Point, Family::Composite];

    /// `env`, `point` or `composite`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Family::Env => "env",
            Family::Point => "point",
            Family::Composite => "composite",
        }
    }

    /// What the error axis is: the truth and the unit.
    #[must_use]
    pub fn error_axis(self) -> &'static str {
        match self {
            Family::Env => "RMSE against env-direct",
            Family::Point => "RMSE against ray-traced visibility",
            Family::Composite => "RMSE (8-bit codes) against the path-traced truth",
        }
    }

    /// A heading for the report.
    #[must_use]
    pub fn title(self) -> &'static str {
        match self {
            Family::Env => "Environment-lit scenes: the extracted lights and their shadows",
            Family::Point => "Point lights: paraboloid against cube maps",
            Family::Composite => "Compositing into a photograph (paper 003)",
        }
    }
}

/// One point of the trade: everything that decides a frame's time and error. Each family has
/// its own knobs and its own truth; fronts and choices never mix families.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(tag = "family", rename_all = "snake_case")]
pub enum Setting {
    /// An environment-lit frame.
    Env(EnvSetting),
    /// A point-lit frame.
    Point(PointSetting),
    /// A composite.
    Composite(CompositeSetting),
}

impl Setting {
    /// The name the report, the CSV and the chooser use (see each family's `name`).
    #[must_use]
    pub fn name(&self) -> String {
        match self {
            Setting::Env(s) => s.name(),
            Setting::Point(s) => s.name(),
            Setting::Composite(s) => s.name(),
        }
    }

    /// Its family.
    #[must_use]
    pub fn family(&self) -> Family {
        match self {
            Setting::Env(_) => Family::Env,
            Setting::Point(_) => Family::Point,
            Setting::Composite(_) => Family::Composite,
        }
    }

    /// Its knobs, if it is environment-lit.
    #[must_use]
    pub fn as_env(&self) -> Option<&EnvSetting> {
        if let Setting::Env(e) = self { Some(e) } else { None }
    }

    /// Its knobs, if it is point-lit.
    #[must_use]
    pub fn as_point(&self) -> Option<&PointSetting> {
        if let Setting::Point(p) = self { Some(p) } else { None }
    }

    /// Its knobs, if it is a composite.
    #[must_use]
    pub fn as_composite(&self) -> Option<&CompositeSetting> {
        if let Setting::Composite(c) = self { Some(c) } else { None }
    }

    /// An environment-lit setting: `method` with K lights and `shadow`, full resolution, Weber
    /// skipping on.
    #[must_use]
    pub fn new(method: &str, lights: usize, shadow: Shadow) -> Self {
        Setting::Env(EnvSetting::new(method, lights, shadow))
    }
}

/// The knobs of an environment-lit frame.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct EnvSetting {
    /// The extraction, as `envshadow extract --method` (options included); `+residual` makes
    /// the ambient the signed residual, else it is the method's SH9 remainder.
    pub method: String,
    /// Lights K.
    pub lights: usize,
    /// How every light is shadowed (the EnvDirects' technique when `indirect_scale` > 1).
    pub shadow: Shadow,
    /// 1: every light at full resolution. 2 or 4: paper 001's split, the EnvIndirects shadowed
    /// by the same technique at 1 / scale of the resolution and joint-bilaterally upsampled.
    pub indirect_scale: u32,
    /// Shadows skipped by Weber's law (`gpu::weber_negligible`): the shadows of lights that
    /// together stay under 2 % of every visible receiver's light.
    pub weber: bool,
}

impl EnvSetting {
    /// `method/K32/wedges`, with `/ind2` for a split frame and `/all` when no shadow is skipped
    /// by Weber's law.
    #[must_use]
    pub fn name(&self) -> String {
        let mut s = format!("{}/K{}/{}", self.method, self.lights, self.shadow.name());
        if self.indirect_scale > 1 {
            s.push_str(&format!("/ind{}", self.indirect_scale));
        }
        if !self.weber {
            s.push_str("/all");
        }
        s
    }

    /// A frame of `method` with K lights and `shadow`, full resolution, Weber skipping on.
    #[must_use]
    pub fn new(method: &str, lights: usize, shadow: Shadow) -> Self {
        Self { method: method.into(), lights, shadow, indirect_scale: 1, weber: true }
    }
}

/// The knobs of a point-lit frame: the technique of every point light.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct PointSetting {
    /// [`Shadow::Paraboloid`] or [`Shadow::Cube`] (others cannot shadow a point light).
    pub shadow: Shadow,
}

impl PointSetting {
    /// `point/paraboloid_1024`.
    #[must_use]
    pub fn name(&self) -> String {
        format!("point/{}", self.shadow.name())
    }
}

/// A source patch's shadow map in a composite.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PatchMaps {
    /// One hemispherical paraboloid map (paper 004): the patch emits into one hemisphere.
    Paraboloid,
    /// Six cube faces: the baseline that does not know it.
    Cube,
}

/// The knobs of a composite (paper 003): passes, HDR or LDR, the shadow maps.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct CompositeSetting {
    /// Shadow passes (representative sources); 0: one per occluded source.
    pub passes: usize,
    /// Intensity transfers subtracted from the 8-bit photograph instead of radiance transfers
    /// from the HDR one.
    pub ldr: bool,
    /// Source patches' maps.
    pub patch_maps: PatchMaps,
    /// Side of every shadow map, texels (paper: 256).
    pub map_resolution: u32,
}

impl CompositeSetting {
    /// The paper's maps (256², hemispherical paraboloids) with `passes` in HDR or LDR.
    #[must_use]
    pub fn new(passes: usize, ldr: bool) -> Self {
        Self { passes, ldr, patch_maps: PatchMaps::Paraboloid, map_resolution: 256 }
    }

    /// The patches' maps: `paraboloid_256`, `cube_256`.
    #[must_use]
    pub fn maps_name(&self) -> String {
        let maps = match self.patch_maps {
            PatchMaps::Paraboloid => "paraboloid",
            PatchMaps::Cube => "cube",
        };
        format!("{maps}_{}", self.map_resolution)
    }

    /// `composite/50/hdr/paraboloid_256` (`all` for one pass per occluded source).
    #[must_use]
    pub fn name(&self) -> String {
        let passes = if self.passes == 0 { "all".to_string() } else { self.passes.to_string() };
        format!("composite/{passes}/{}/{}", if self.ldr { "ldr" } else { "hdr" }, self.maps_name())
    }
}

/// Named sweeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preset {
    /// Eleven settings spanning the trade (seven environment-lit with K = 8 and 16, two point,
    /// two composite), for CI.
    Quick,
    /// Every technique with its main knobs: 16 environment-lit settings (light count, map
    /// resolution, PCF, PCSS, N maps, wedges, the split at 1/2 and 1/4, Weber skipping off and
    /// median cut, both with 1024² maps, the cheaper technique); 8 point-light settings
    /// (paraboloid and cube maps of equal texel counts, PCF, the paraboloid unsubdivided); 14
    /// composite settings (1, 10, 20, 50 and all passes in HDR and LDR, cube maps, 128² and
    /// 512² maps).
    Default,
}

impl Preset {
    /// The settings of the sweep, cheapest-looking first within a family (the order is only
    /// for reading).
    #[must_use]
    pub fn settings(self) -> Vec<Setting> {
        let m = light_extract::DEFAULT_METHOD;
        let env = |k, shadow| Setting::new(m, k, shadow);
        let point = |shadow| Setting::Point(PointSetting { shadow });
        let paraboloid = |resolution, pcf, subdivide| point(Shadow::Paraboloid { resolution, pcf, subdivide });
        let cube = |resolution, pcf| point(Shadow::Cube { resolution, pcf });
        let composite = |passes, ldr| Setting::Composite(CompositeSetting::new(passes, ldr));
        match self {
            Preset::Quick => vec![
                env(8, Shadow::None),
                env(8, Shadow::Maps { resolution: 512, pcf: 1 }),
                env(8, Shadow::Pcss { resolution: 512 }),
                env(8, Shadow::Wedges),
                env(16, Shadow::Maps { resolution: 1024, pcf: 1 }),
                env(16, Shadow::Wedges),
                Setting::Env(EnvSetting { indirect_scale: 2, ..EnvSetting::new(m, 16, Shadow::Wedges) }),
                paraboloid(512, 0, true),
                cube(296, 0),
                composite(10, false),
                composite(0, true),
            ],
            Preset::Default => {
                let mut v = vec![env(32, Shadow::None)];
                for k in [8, 16] {
                    v.push(env(k, Shadow::Maps { resolution: 1024, pcf: 1 }));
                    v.push(env(k, Shadow::Wedges));
                }
                for resolution in [512, 1024, 2048] {
                    v.push(env(32, Shadow::Maps { resolution, pcf: 1 }));
                }
                v.push(env(32, Shadow::Maps { resolution: 1024, pcf: 0 }));
                v.push(env(32, Shadow::Pcss { resolution: 1024 }));
                v.push(env(32, Shadow::MultiSample { n: 4, resolution: 1024 }));
                v.push(env(32, Shadow::Wedges));
                for scale in [2, 4] {
                    v.push(Setting::Env(EnvSetting {
                        indirect_scale: scale,
                        ..EnvSetting::new(m, 32, Shadow::Wedges)
                    }));
                }
                // Weber skipping and the method on the cheaper maps
                v.push(Setting::Env(EnvSetting {
                    weber: false,
                    ..EnvSetting::new(m, 32, Shadow::Maps { resolution: 1024, pcf: 1 })
                }));
                v.push(Setting::new("median-cut", 32, Shadow::Maps { resolution: 1024, pcf: 1 }));
                // point lights: paraboloid and cube maps of equal texel counts (paper 004)
                for (p, c) in EQUAL_TEXEL_SIDES {
                    v.push(paraboloid(p, 0, true));
                    v.push(cube(c, 0));
                }
                v.push(paraboloid(1024, 1, true));
                v.push(paraboloid(1024, 0, false));
                // compositing: passes in HDR and LDR, then the maps at 50 passes
                for passes in [1, 10, 20, 50, 0] {
                    v.push(composite(passes, false));
                    v.push(composite(passes, true));
                }
                let at50 = CompositeSetting::new(50, false);
                v.push(Setting::Composite(CompositeSetting { patch_maps: PatchMaps::Cube, ..at50.clone() }));
                for map_resolution in [128, 512] {
                    v.push(Setting::Composite(CompositeSetting { map_resolution, ..at50.clone() }));
                }
                v.push(Setting::Composite(CompositeSetting {
                    patch_maps: PatchMaps::Cube,
                    ..CompositeSetting::new(0, false)
                }));
                v
            }
        }
    }
}

/// Map sides with (nearly) equal texel counts: a dual paraboloid map of side `p` (2 p² texels)
/// against a cube map of side `c` (6 c² texels), c = p / √3 rounded to a multiple of 8. The
/// accuracy and speed comparisons use these pairs.
pub const EQUAL_TEXEL_SIDES: [(u32, u32); 3] = [(512, 296), (1024, 592), (2048, 1184)];

/// A named shadow-map configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct MapVariant {
    /// Name, e.g. `paraboloid_1024_clip_subdivided`.
    pub name: String,
    /// The technique.
    pub technique: Technique,
    /// Its settings.
    pub settings: ShadowSettings,
}

/// The paraboloid-against-cube comparison of the validate report and the bench: for each pair of
/// [`EQUAL_TEXEL_SIDES`], the cube map and the dual paraboloid map with clip distances (plain and
/// subdivided) and with a discard (subdivided).
#[must_use]
pub fn equal_texel_variants() -> Vec<MapVariant> {
    let mut out = Vec::new();
    for (p, c) in EQUAL_TEXEL_SIDES {
        let base = ShadowSettings::default();
        let variant = |name: String, technique, resolution, rejection, subdivide_angle| MapVariant {
            name,
            technique,
            settings: ShadowSettings { resolution, rejection, subdivide_angle, ..base },
        };
        out.push(variant(format!("cube_{c}"), Technique::Cube, c, Rejection::ClipDistance, None));
        out.push(variant(format!("paraboloid_{p}_clip"), Technique::DualParaboloid, p, Rejection::ClipDistance, None));
        out.push(variant(
            format!("paraboloid_{p}_clip_subdivided"),
            Technique::DualParaboloid,
            p,
            Rejection::ClipDistance,
            base.subdivide_angle,
        ));
        out.push(variant(
            format!("paraboloid_{p}_discard_subdivided"),
            Technique::DualParaboloid,
            p,
            Rejection::Discard,
            base.subdivide_angle,
        ));
    }
    out
}
