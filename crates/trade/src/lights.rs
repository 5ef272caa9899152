//! The extraction methods measured against the `env-direct` truth (paper 001's Table 1, its
//! Table 2 ablation and our options): the methods, the truth and its noise floor, each method's
//! error, per-method summaries (mean, rank) and shard merges. `cargo xtask eval-lights` parses
//! arguments, shows progress and writes the tables.

use crate::TradeError;
use envmap_sphere::EnvMap;
use light_extract::{EmissiveSplit, LightExtractor};
use ref_tracer::metrics::{FlipTonemap, flip, rmse};
use ref_tracer::{AmbientMap, EnvLight, Integrator, LightSet, RenderSettings, SceneBvh, Strategy};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// How a run measured: shards must agree on it to merge.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LightsConfig {
    /// The built-in scenes.
    pub scenes: Vec<String>,
    /// Lights per method K.
    pub lights: usize,
    /// The method labels, in table order.
    pub methods: Vec<String>,
    /// Samples per pixel of the truth.
    pub spp: u32,
    /// Samples per pixel of the lights renders.
    pub lights_spp: u32,
    /// Image size.
    pub size: (u32, u32),
}

/// A run: its configuration, the shards it holds and its rows (`eval-lights.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct LightsRun {
    /// How it measured.
    pub config: LightsConfig,
    /// The shards, `I/N`.
    pub shards: Vec<String>,
    /// One row per map, scene and method, the noise floor's included.
    pub rows: Vec<LightsRow>,
}

/// One method on one map and scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LightsRow {
    /// The map's file name.
    pub map: String,
    /// The scene.
    pub scene: String,
    /// The method's label; [`NOISE_FLOOR`] for the truth against itself.
    pub method: String,
    /// Lights the method gave.
    pub lights: usize,
    /// RMSE against the truth.
    pub rmse: f64,
    /// RMSE against the converged truth, estimated: the truth's own noise variance (half the
    /// floor's mean square) taken out of the mean square error, clamped at zero.
    pub converged_rmse: f64,
    /// FLIP against the truth.
    pub flip: f64,
    /// Extraction time, ms.
    pub extract_ms: f64,
}

/// The row label of the noise floor: the truth rendered again with another seed.
pub const NOISE_FLOOR: &str = "(reference, other seed)";

/// A row of the table: its label and its extractor.
pub type Method = (String, Box<dyn LightExtractor>);

/// The methods labelled in `only` and median cut (all when `only` is empty), in table order.
///
/// # Errors
/// A label that names no method.
pub fn chosen_methods(k: usize, only: &[String]) -> Result<Vec<Method>, TradeError> {
    let all = methods(k);
    if let Some(unknown) = only.iter().find(|m| !all.iter().any(|(label, _)| label == *m)) {
        let labels: Vec<&str> = all.iter().map(|(label, _)| label.as_str()).collect();
        return Err(TradeError::Method(format!("unknown method {unknown:?}; available: {}", labels.join(", "))));
    }
    Ok(all.into_iter().filter(|(label, _)| only.is_empty() || label == "median-cut" || only.contains(label)).collect())
}

/// (label, extractor): Table 1's methods, then Table 2's ablation of EmissiveSplit, then our
/// options (not the papers'): above-horizon (only the hemisphere above the ground reaches the
/// receivers), moment cones, the residual as the remainder (median cut's too, for a fair
/// comparison), and a light for every compact source of visible shadow (weber).
#[must_use]
pub fn methods(k: usize) -> Vec<Method> {
    let es = EmissiveSplit { lights: k, ..EmissiveSplit::default() };
    let ablations: [(&str, Box<dyn LightExtractor>); 3] = [
        ("emissive-split/no-masking", Box::new(EmissiveSplit { masking: false, ..es })),
        ("emissive-split/no-kmeans", Box::new(EmissiveSplit { kmeans: false, ..es })),
        ("emissive-split/neither", Box::new(EmissiveSplit { masking: false, kmeans: false, ..es })),
    ];
    let named = |name: &str| light_extract::extractor(name, k).map(|e| (name.to_string(), e));
    light_extract::METHODS
        .iter()
        .filter_map(|m| named(m))
        .chain(ablations.into_iter().map(|(n, e)| (n.to_string(), e)))
        .chain(
            [
                "emissive-split+above-horizon",
                "emissive-split+moment-cones",
                "emissive-split+moment-cones+above-horizon",
                "emissive-split+moment-cones+above-horizon+residual",
                "emissive-split+weber",
                "emissive-split+moment-cones+weber+above-horizon+residual",
                "median-cut+above-horizon",
                "median-cut+above-horizon+residual",
            ]
            .into_iter()
            .filter_map(named),
        )
        .collect()
}

/// A scene to measure on, with its BVH built once for every map.
pub struct LightsScene {
    /// Its name.
    pub name: String,
    /// The scene, at the run's size.
    pub scene: scene::Scene,
    /// Its BVH.
    pub bvh: SceneBvh,
}

impl LightsScene {
    /// Built-in scene `name` at `size`.
    ///
    /// # Errors
    /// An unknown scene.
    pub fn builtin(name: &str, size: (u32, u32)) -> Result<Self, TradeError> {
        let mut scene = scene::Scene::builtin(name).map_err(|e| TradeError::Scene(e.to_string()))?;
        (scene.camera.width, scene.camera.height) = size;
        let bvh = SceneBvh::new(&scene);
        Ok(Self { name: name.to_string(), scene, bvh })
    }
}

/// Every method of `methods` on map `map` (named `map_name`) and each of `scenes`: per scene
/// the truth (`env-direct` with MIS at `spp`), its noise floor (the truth with another seed,
/// row [`NOISE_FLOOR`]) and each method's lights render at `lights_spp` (8 interleaved sets,
/// paper 001's section 3.5). Every render goes through the same `lights_spp` sub-pixel
/// positions, so an error holds no antialiasing noise, only lighting error and noise.
/// `progress` is called after each render with the map and scene.
///
/// # Errors
/// An extraction that fails on the map.
pub fn measure_lights(
    map_name: &str,
    map: &EnvMap,
    methods: &[Method],
    scenes: &[LightsScene],
    (spp, lights_spp): (u32, u32),
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<LightsRow>, TradeError> {
    let env = EnvLight::new(map);
    let decompositions: Vec<_> = methods
        .iter()
        .map(|(label, m)| {
            let mut d = m.extract(map).map_err(|e| TradeError::Method(format!("{map_name}: {label}: {e}")))?;
            d.method.clone_from(label);
            // paper 001, section 3.5: 8 sets; the extra 7 as renderers take them
            let (lights, sets) = (d.distant_lights(), d.interleaved_distant_lights());
            Ok::<_, TradeError>((d, lights, sets))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let ambient_maps: Vec<_> = decompositions.iter().map(|(d, _, _)| AmbientMap::new(&d.ambient)).collect();
    let mut rows = Vec::new();
    for s in scenes {
        let (scene, bvh) = (&s.scene, &s.bvh);
        let what = format!("{map_name} / {}", s.name);
        let positions = Some(lights_spp.max(1));
        let truth = RenderSettings { spp, seed: 1, aovs: false, pixel_positions: positions, ..Default::default() };
        let reference =
            ref_tracer::render(scene, bvh, Some(&env), &Integrator::EnvDirect(Strategy::Mis), &truth, &|_, _| {});
        progress(&what);
        let tm = FlipTonemap::for_reference(&reference.color);
        let again = RenderSettings { seed: 3, ..truth };
        let floor =
            ref_tracer::render(scene, bvh, Some(&env), &Integrator::EnvDirect(Strategy::Mis), &again, &|_, _| {});
        progress(&what);
        // two truths differ by twice the truth's noise variance
        let floor_rmse = rmse(&reference.color, &floor.color);
        let truth_variance = floor_rmse * floor_rmse / 2.0;
        let converged = |e: f64| (e * e - truth_variance).max(0.0).sqrt();
        rows.push(LightsRow {
            map: map_name.to_string(),
            scene: s.name.clone(),
            method: NOISE_FLOOR.into(),
            lights: 0,
            rmse: floor_rmse,
            converged_rmse: converged(floor_rmse),
            flip: flip(&reference.color, &floor.color, floor.width, floor.height, &tm),
            extract_ms: 0.0,
        });
        for ((d, lights, sets), ambient_map) in decompositions.iter().zip(&ambient_maps) {
            let set = LightSet {
                lights,
                interleaved: sets,
                ambient: Some(d.ambient_sh),
                ambient_map: ambient_map.as_ref(),
                shadow_ambient: false,
                background: Some(map),
            };
            let settings = RenderSettings { spp: lights_spp.max(1), seed: 2, ..truth };
            let img = ref_tracer::render(scene, bvh, None, &Integrator::Lights(set), &settings, &|_, _| {});
            progress(&what);
            let error = rmse(&reference.color, &img.color);
            rows.push(LightsRow {
                map: map_name.to_string(),
                scene: s.name.clone(),
                method: d.method.clone(),
                lights: d.lights.len(),
                rmse: error,
                converged_rmse: converged(error),
                flip: flip(&reference.color, &img.color, img.width, img.height, &tm),
                extract_ms: d.time_ms,
            });
        }
    }
    Ok(rows)
}

/// Mean of `value` per method, and its mean rank over the (map, scene) cases.
#[must_use]
pub fn summary(rows: &[LightsRow], value: impl Fn(&LightsRow) -> f64) -> Vec<(String, f64, f64)> {
    let mut names: Vec<String> = rows.iter().map(|r| r.method.clone()).collect();
    names.sort();
    names.dedup();
    let cases: Vec<(String, String)> = {
        let mut c: Vec<_> = rows.iter().map(|r| (r.map.clone(), r.scene.clone())).collect();
        c.dedup();
        c
    };
    names
        .iter()
        .map(|m| {
            let mine: Vec<&LightsRow> = rows.iter().filter(|r| &r.method == m).collect();
            let mean = mine.iter().map(|r| value(r)).sum::<f64>() / mine.len().max(1) as f64;
            let rank = cases
                .iter()
                .map(|(map, scene)| {
                    let case: Vec<&LightsRow> = rows.iter().filter(|r| &r.map == map && &r.scene == scene).collect();
                    let mine = case.iter().find(|r| &r.method == m).map_or(f64::INFINITY, |r| value(r));
                    1.0 + case.iter().filter(|r| value(r) < mine).count() as f64
                })
                .sum::<f64>()
                / cases.len().max(1) as f64;
            (m.clone(), mean, rank)
        })
        .collect()
}

/// Joins the runs read from `eval-lights.json` in each of `dirs`: the unsharded run's rows,
/// the shards sorted.
///
/// # Errors
/// An unreadable file or one that is not a run; runs measured differently; a shard or map
/// twice; no folder.
pub fn merge_lights(dirs: &[PathBuf]) -> Result<LightsRun, TradeError> {
    let mut merged: Option<LightsRun> = None;
    for dir in dirs {
        let path = dir.join("eval-lights.json");
        let text = std::fs::read_to_string(&path).map_err(|source| TradeError::Io { path: path.clone(), source })?;
        let run: LightsRun = serde_json::from_str(&text)
            .map_err(|e| TradeError::Json { path: path.clone(), message: format!("not an eval-lights run: {e}") })?;
        let m = merged.get_or_insert_with(|| LightsRun {
            config: run.config.clone(),
            shards: Vec::new(),
            rows: Vec::new(),
        });
        if run.config != m.config {
            return Err(TradeError::Mismatch {
                path,
                other: dirs[0].clone(),
                what: format!("{:?} vs {:?}", run.config, m.config),
            });
        }
        for s in run.shards {
            if m.shards.contains(&s) {
                return Err(TradeError::Duplicate { path, what: format!("shard {s}") });
            }
            m.shards.push(s);
        }
        if let Some(r) = run.rows.iter().find(|r| m.rows.iter().any(|o| o.map == r.map)) {
            return Err(TradeError::Duplicate { path, what: format!("map {}", r.map) });
        }
        m.rows.extend(run.rows);
    }
    let mut m = merged.ok_or(TradeError::NothingToMerge)?;
    m.shards.sort();
    Ok(m)
}
