//! Decomposes an HDR environment map into a few shadow-casting distant area lights (cones) plus
//! an ambient remainder, and keeps the books: for methods that partition the map's pixels, light
//! power + remainder power = map power.
//!
//! Methods, each a type implementing [`LightExtractor`] with its parameters as fields:
//! - [`CenterSurround`] (paper 000): circular centre-surround filters, iterative extraction,
//!   Weber's 2 % stop; the remainder is the ambient map.
//! - [`MedianCut`] (Debevec 2005): 2^n regions of equal energy, a light at each energy centroid.
//! - [`VarianceMinimization`] (Viriyothai and Debevec 2009): 2^n regions, each cut where the
//!   parts' energy-weighted angular variance is smallest.
//! - [`ImportanceSampled`]: K samples of the map's luminance distribution as equal-power
//!   lights (a baseline).
//!
//! - [`EmissiveSplit`] (paper 001): emissive texels -> EnvDirects (importance sampling, masking,
//!   k-means), the rest -> EnvIndirects (an illumination cut over a binary light tree).
//!
//! [`AboveHorizon`] wraps any of them (our option, not a paper's): for scenes on an opaque
//! ground it models only the hemisphere that can reach the receivers. [`Residual`] (ours too)
//! keeps any method's lights for the shadows and makes the remainder the signed residual, map
//! minus lights, so glossy surfaces reflect the map's detail the cones average away. [`Weber`]
//! (ours) gives every compact source whose shadow would be visible (over 2 % of some receiver's
//! irradiance) a light of its own, within the budget.
//!
//! Outputs: [`Decomposition::to_json`] (`lights.json`), [`Decomposition::to_gltf`] (glTF 2.0 with
//! `KHR_lights_punctual` directional lights), the remainder map (`ambient.exr`) and an overlay of
//! the lights on the map ([`overlay`]).
//!
//! ```
//! use light_extract::{LightExtractor, MedianCut};
//! let map = envmap_sphere::default_map();
//! let d = MedianCut { depth: 3 }.extract(&map).unwrap();
//! assert_eq!(d.lights.len(), 8);
//! assert!(d.power_balance_error() < 1e-4);
//! ```
//!
//! Architecture invariant: knows lights, never wgpu.

mod above_horizon;
mod center_surround;
mod decomposition;
mod emissive_split;
mod importance;
mod median_cut;
pub mod output;
pub mod overlay;
mod regions;
mod residual;
mod variance;
mod weber;

pub use above_horizon::{AboveHorizon, narrow_to_horizon, upper_hemisphere};
pub use center_surround::CenterSurround;
pub use decomposition::{
    Decomposition, ExtractError, ExtractedLight, INTERLEAVED_JITTER, INTERLEAVED_SETS, LightExtractor, WriteError,
    interleaved_sets,
};
pub use emissive_split::EmissiveSplit;
pub use importance::ImportanceSampled;
pub use median_cut::MedianCut;
pub use residual::{Residual, splat_lights};
pub use variance::VarianceMinimization;
pub use weber::{COVERED_SHARE, CompactSource, Weber, compact_sources};

/// The toolkit's default extraction, the most accurate in `eval-lights` (the README's
/// extraction section has its error against median cut's): paper 001's emissive split with our
/// options. `validate`, the
/// trade, the benches and the examples all draw it from here.
pub const DEFAULT_METHOD: &str = "emissive-split+moment-cones+above-horizon+residual";

/// The methods by name, as `lights.json` and the commands name them.
pub const METHODS: [&str; 5] = ["emissive-split", "center-surround", "median-cut", "variance-min", "importance"];

/// Our options (not the papers'), appended to a method's name with `+`: `moment-cones`
/// (emissive split only, [`EmissiveSplit::moment_cones`]), then `weber` (any method,
/// [`Weber`]), then `above-horizon` (any method, [`AboveHorizon`]), then `residual` (any
/// method, [`Residual`]).
pub const OPTIONS: [&str; 4] = ["moment-cones", "weber", "above-horizon", "residual"];

/// The extractor named `method` (one of [`METHODS`], optionally followed by [`OPTIONS`] in that
/// order, e.g. `emissive-split+moment-cones+weber+above-horizon+residual`) with a budget of `k` lights and the
/// papers' defaults otherwise; `None` for an unknown name or option.
#[must_use]
pub fn extractor(method: &str, k: usize) -> Option<Box<dyn LightExtractor>> {
    if let Some(inner) = method.strip_suffix("+residual") {
        return Some(Box::new(Residual::new(extractor(inner, k)?)));
    }
    let (base, above_horizon) = method.strip_suffix("+above-horizon").map_or((method, false), |b| (b, true));
    let (base, weber) = base.strip_suffix("+weber").map_or((base, false), |b| (b, true));
    let inner: Box<dyn LightExtractor> = match base {
        "emissive-split" => Box::new(EmissiveSplit { lights: k, ..EmissiveSplit::default() }),
        "emissive-split+moment-cones" => {
            Box::new(EmissiveSplit { lights: k, moment_cones: true, ..EmissiveSplit::default() })
        }
        "center-surround" => Box::new(CenterSurround { max_lights: k, ..CenterSurround::default() }),
        "median-cut" => Box::new(MedianCut::with_lights(k)),
        "variance-min" => Box::new(VarianceMinimization::with_lights(k)),
        "importance" => Box::new(ImportanceSampled { count: k, seed: 0 }),
        _ => return None,
    };
    let inner: Box<dyn LightExtractor> = if weber { Box::new(Weber::new(inner)) } else { inner };
    Some(if above_horizon { Box::new(AboveHorizon::new(inner)) } else { inner })
}
