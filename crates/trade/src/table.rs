//! A run's outputs: `trade.json` (everything), `trade.csv` (one row per setting x scene x map),
//! and the merge of shards.

use crate::TradeError;
use crate::front::{Measurement, mark_fronts};
use crate::setting::Setting;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::Path;

/// How a run measured: equal for every shard of one run, and checked when shards merge.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunConfig {
    /// Image size.
    pub size: (u32, u32),
    /// Samples per pixel of the `env-direct` truth.
    pub truth_spp: u32,
    /// Frames timed per measurement (the median is kept).
    pub repeats: u32,
    /// GPU frames on a rotated grid of k² + 1 samples per pixel: k.
    pub supersample: u32,
    /// Samples per pixel of a composite's photograph and truth.
    #[serde(default)]
    pub photo_spp: u32,
    /// The GPU adapter.
    pub adapter: String,
    /// The preset's name, or "custom".
    pub preset: String,
}

/// Everything a run (or a merge of shards) measured.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Run {
    /// How it measured.
    pub config: RunConfig,
    /// The shards merged into it, as `I/N` (one entry for an unsharded run: `0/1`).
    pub shards: Vec<String>,
    /// The measurements, in canonical order (scene, map, setting).
    pub rows: Vec<Measurement>,
}

impl Run {
    /// Sorts the rows canonically and marks every (scene, map)'s Pareto front.
    pub fn finish(&mut self) {
        self.rows.sort_by(|a, b| (&a.scene, &a.map, &a.setting).cmp(&(&b.scene, &b.map, &b.setting)));
        mark_fronts(&mut self.rows);
        self.shards.sort();
    }

    /// The CSV: a header and one row per measurement.
    #[must_use]
    pub fn csv(&self) -> String {
        let mut s = String::from(
            "setting,family,scene,map,ms,clock,shadow_ms,shadow_clock,extract_ms,rmse,flip,truth_noise,pareto,method,lights,shadow,indirect_scale,weber,passes,ldr,shadowed,skipped,culled\n",
        );
        for r in &self.rows {
            let skipped: Vec<String> = r.skipped.iter().map(|(why, n)| format!("{n} {why}")).collect();
            let culled: Vec<String> = r.culled.iter().map(|(what, n)| format!("{n} {what}")).collect();
            // the knobs a family has; the others' cells stay empty
            let none = String::new;
            let (method, lights, shadow, scale, weber, passes, ldr) = match &r.knobs {
                Setting::Env(e) => (
                    e.method.clone(),
                    e.lights.to_string(),
                    e.shadow.name(),
                    e.indirect_scale.to_string(),
                    e.weber.to_string(),
                    none(),
                    none(),
                ),
                Setting::Point(p) => (none(), none(), p.shadow.name(), none(), none(), none(), none()),
                Setting::Composite(c) => (
                    none(),
                    none(),
                    c.maps_name(),
                    none(),
                    none(),
                    if c.passes == 0 { "all".to_string() } else { c.passes.to_string() },
                    c.ldr.to_string(),
                ),
            };
            let _ = writeln!(
                s,
                "{},{},{},{},{:.4},{},{:.4},{},{:.3},{:.6},{:.6},{:.6},{},{},{},{},{},{},{},{},{},{},{}",
                csv_field(&r.setting),
                r.family().name(),
                csv_field(&r.scene),
                csv_field(&r.map),
                r.ms,
                csv_field(&r.clock),
                r.shadow_ms,
                csv_field(&r.shadow_clock),
                r.extract_ms,
                r.rmse,
                r.flip,
                r.truth_noise,
                r.pareto,
                csv_field(&method),
                lights,
                shadow,
                scale,
                weber,
                passes,
                ldr,
                r.shadowed,
                csv_field(&skipped.join("; ")),
                csv_field(&culled.join("; ")),
            );
        }
        s
    }

    /// Writes `trade.json` and `trade.csv` into `dir` (created).
    ///
    /// # Errors
    /// The folder or a file cannot be written.
    pub fn write(&self, dir: &Path) -> Result<(), TradeError> {
        std::fs::create_dir_all(dir).map_err(|source| TradeError::Io { path: dir.to_path_buf(), source })?;
        let json = serde_json::to_string_pretty(self)
            .map_err(|e| TradeError::Json { path: dir.join("trade.json"), message: format!("not a trade run: {e}") })?;
        for (name, text) in [("trade.json", json), ("trade.csv", self.csv())] {
            let p = dir.join(name);
            std::fs::write(&p, text).map_err(|source| TradeError::Io { path: p, source })?;
        }
        Ok(())
    }

    /// Reads `dir/trade.json`.
    ///
    /// # Errors
    /// A missing or unreadable file; JSON that is not a run.
    pub fn read(dir: &Path) -> Result<Self, TradeError> {
        let p = dir.join("trade.json");
        let text = std::fs::read_to_string(&p).map_err(|source| TradeError::Io { path: p.clone(), source })?;
        serde_json::from_str(&text).map_err(|e| TradeError::Json { path: p, message: format!("not a trade run: {e}") })
    }
}

/// A CSV field, quoted when it holds a comma, a quote or a line break.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_string() }
}

/// The merge of shards' runs: their rows together, in canonical order with the fronts marked
/// anew, equal to the unsharded run's.
///
/// # Errors
/// No runs; runs measured with different configurations; a shard given twice or a (setting,
/// scene, map) measured twice.
pub fn merge(runs: &[(std::path::PathBuf, Run)]) -> Result<Run, TradeError> {
    let (first_path, first) = runs.first().ok_or(TradeError::NothingToMerge)?;
    let mut out = Run { config: first.config.clone(), shards: Vec::new(), rows: Vec::new() };
    for (path, run) in runs {
        if run.config != first.config {
            return Err(TradeError::Mismatch {
                path: path.clone(),
                other: first_path.clone(),
                what: format!("{:?} vs {:?}", run.config, first.config),
            });
        }
        for s in &run.shards {
            if out.shards.contains(s) {
                return Err(TradeError::Duplicate { path: path.clone(), what: format!("shard {s}") });
            }
            out.shards.push(s.clone());
        }
        for r in &run.rows {
            if out.rows.iter().any(|o| o.setting == r.setting && o.scene == r.scene && o.map == r.map) {
                return Err(TradeError::Duplicate {
                    path: path.clone(),
                    what: format!("{} on {} under {}", r.setting, r.scene, r.map),
                });
            }
            out.rows.push(r.clone());
        }
    }
    out.finish();
    Ok(out)
}
