//! Settings as data: one value names every knob of a frame, so the trade can be swept, stored,
//! merged and chosen from without knowing the techniques behind it.

use serde::{Deserialize, Serialize};
use shadowmap_paraboloid::{Pcss, ShadowSettings};

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
}

impl Shadow {
    /// A short name: `maps_2048_pcf1`, `pcss_1024`, `maps_1024_x8`, `wedges`, `none`.
    #[must_use]
    pub fn name(&self) -> String {
        match *self {
            Shadow::None => "none".into(),
            Shadow::Maps { resolution, pcf } => format!("maps_{resolution}_pcf{pcf}"),
            Shadow::Pcss { resolution } => format!("pcss_{resolution}"),
            Shadow::MultiSample { n, resolution } => format!("maps_{resolution}_x{n}"),
            Shadow::Wedges => "wedges".into(),
        }
    }

    /// The shadow-map settings of a map technique (`None` for the others).
    #[must_use]
    pub fn map_settings(&self) -> Option<(ShadowSettings, u32)> {
        let base = ShadowSettings::default();
        match *self {
            Shadow::Maps { resolution, pcf } => Some((ShadowSettings { resolution, pcf_radius: pcf, ..base }, 1)),
            Shadow::Pcss { resolution } => {
                Some((ShadowSettings { resolution, pcf_radius: 0, pcss: Some(Pcss::default()), ..base }, 1))
            }
            Shadow::MultiSample { n, resolution } => Some((ShadowSettings { resolution, pcf_radius: 0, ..base }, n)),
            Shadow::None | Shadow::Wedges => None,
        }
    }
}

/// One point of the trade: everything that decides a frame's time and error.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Setting {
    /// The extraction, as `cargo xtask extract --method` (options included); `+residual` makes
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

impl Setting {
    /// The name the report, the CSV and the chooser use: `method/K32/wedges`, with `/ind2`
    /// for a split frame and `/all` when no shadow is skipped by Weber's law.
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

/// The toolkit's most accurate extraction (`validate`'s default).
pub const BEST_METHOD: &str = "emissive-split+moment-cones+above-horizon+residual";

/// Named sweeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preset {
    /// Seven settings spanning the trade (K = 8 and 16), for CI.
    Quick,
    /// Every technique with its main knobs (16 settings): light count, map resolution, PCF,
    /// PCSS, N maps, wedges, the split at 1/2 and 1/4, Weber skipping off and median cut (both with
    /// 1024² maps, the cheaper technique).
    Default,
}

impl Preset {
    /// The settings of the sweep, cheapest-looking first (the order is only for reading).
    #[must_use]
    pub fn settings(self) -> Vec<Setting> {
        let m = BEST_METHOD;
        match self {
            Preset::Quick => vec![
                Setting::new(m, 8, Shadow::None),
                Setting::new(m, 8, Shadow::Maps { resolution: 512, pcf: 1 }),
                Setting::new(m, 8, Shadow::Pcss { resolution: 512 }),
                Setting::new(m, 8, Shadow::Wedges),
                Setting::new(m, 16, Shadow::Maps { resolution: 1024, pcf: 1 }),
                Setting::new(m, 16, Shadow::Wedges),
                Setting { indirect_scale: 2, ..Setting::new(m, 16, Shadow::Wedges) },
            ],
            Preset::Default => {
                let mut v = vec![Setting::new(m, 32, Shadow::None)];
                for k in [8, 16] {
                    v.push(Setting::new(m, k, Shadow::Maps { resolution: 1024, pcf: 1 }));
                    v.push(Setting::new(m, k, Shadow::Wedges));
                }
                for resolution in [512, 1024, 2048] {
                    v.push(Setting::new(m, 32, Shadow::Maps { resolution, pcf: 1 }));
                }
                v.push(Setting::new(m, 32, Shadow::Maps { resolution: 1024, pcf: 0 }));
                v.push(Setting::new(m, 32, Shadow::Pcss { resolution: 1024 }));
                v.push(Setting::new(m, 32, Shadow::MultiSample { n: 4, resolution: 1024 }));
                v.push(Setting::new(m, 32, Shadow::Wedges));
                for scale in [2, 4] {
                    v.push(Setting { indirect_scale: scale, ..Setting::new(m, 32, Shadow::Wedges) });
                }
                // Weber skipping and the method on the cheaper maps
                v.push(Setting { weber: false, ..Setting::new(m, 32, Shadow::Maps { resolution: 1024, pcf: 1 }) });
                v.push(Setting::new("median-cut", 32, Shadow::Maps { resolution: 1024, pcf: 1 }));
                v
            }
        }
    }
}
