//! The measurements, their Pareto fronts and the time-budget chooser.

use serde::{Deserialize, Serialize};

/// One setting on one scene under one map: its time and its error against the truth.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Measurement {
    /// [`crate::Setting::name`].
    pub setting: String,
    /// The setting itself.
    pub knobs: crate::Setting,
    /// Built-in scene (a real scene's name for a composite).
    pub scene: String,
    /// Map file name (the embedded default map's name for it); `-` where no map lights the
    /// frame (point lights; a real scene lit by its own patches).
    pub map: String,
    /// Milliseconds per frame: everything the frame waits for (env and point: G-buffer,
    /// shadows, shading; composite: the CPU traversal too), median of the repeats; `clock` says
    /// which clock.
    pub ms: f64,
    /// Where `ms` comes from.
    pub clock: String,
    /// The shadow passes' share of `ms` on the GPU, summed over lights (`shadow_clock` says
    /// which clock: GPU timestamps where the adapter has them).
    pub shadow_ms: f64,
    /// Where `shadow_ms` comes from.
    pub shadow_clock: String,
    /// Extraction time on the CPU (ms), once per map and method, not per frame (0 where
    /// nothing is extracted).
    pub extract_ms: f64,
    /// RMSE against the family's truth ([`crate::Family::error_axis`]): linear radiance for env
    /// and point frames, 8-bit codes over the pixels the object changed for composites.
    pub rmse: f64,
    /// Mean FLIP against the truth.
    pub flip: f64,
    /// The truth's own noise: RMSE between two truths of independent seeds, / sqrt 2 (the RMSE
    /// of one truth against the converged image). Errors near it are not resolved. 0 for a
    /// truth without noise (point lights: rays to the light from the frame's own points).
    pub truth_noise: f64,
    /// Lights (composite: representative sources) with a shadow pass.
    pub shadowed: usize,
    /// Lights or sources without one, and why (e.g. no visible receiver faces them; Weber's
    /// law; the shaft hierarchy found the object occludes none of their light).
    pub skipped: Vec<(String, usize)>,
    /// Work the techniques left out because it could not matter, summed over lights (e.g.
    /// wedges of edges whose shadow cannot reach a visible receiver; paraboloid hemispheres
    /// a source does not light).
    pub culled: Vec<(String, u64)>,
    /// On the Pareto front of its scene and map (no other setting there is at most as slow and
    /// at most as wrong, and better in one).
    pub pareto: bool,
}

impl Measurement {
    /// The setting's family.
    #[must_use]
    pub fn family(&self) -> crate::Family {
        self.knobs.family()
    }
}

/// A point of a front: a name, ms, RMSE, FLIP.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Point {
    /// Setting name.
    pub setting: String,
    /// Milliseconds per frame.
    pub ms: f64,
    /// RMSE.
    pub rmse: f64,
    /// FLIP.
    pub flip: f64,
}

/// Whether each point is on the Pareto front of (ms, rmse), both minimized: no other point is
/// at most as slow and at most as wrong while better in one. Equal points are all on it.
/// Non-finite points are never on it, nor do they dominate.
#[must_use]
pub fn pareto(points: &[(f64, f64)]) -> Vec<bool> {
    let ok = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite();
    points
        .iter()
        .map(|p| ok(p) && !points.iter().any(|q| ok(q) && q.0 <= p.0 && q.1 <= p.1 && (q.0 < p.0 || q.1 < p.1)))
        .collect()
}

/// Marks each measurement's `pareto` within its (scene, map).
pub fn mark_fronts(rows: &mut [Measurement]) {
    let mut groups: Vec<(String, String)> = rows.iter().map(|r| (r.scene.clone(), r.map.clone())).collect();
    groups.sort();
    groups.dedup();
    for (scene, map) in groups {
        let idx: Vec<usize> = (0..rows.len()).filter(|&i| rows[i].scene == scene && rows[i].map == map).collect();
        let front = pareto(&idx.iter().map(|&i| (rows[i].ms, rows[i].rmse)).collect::<Vec<_>>());
        for (&i, f) in idx.iter().zip(front) {
            rows[i].pareto = f;
        }
    }
}

/// One point per setting of `family` over every (scene, map) of that family: mean ms, mean
/// RMSE, mean FLIP. Only settings measured on every (scene, map) of the family are kept, so the
/// means compare like with like; families have their own truths and never mix. Sorted by ms.
#[must_use]
pub fn overall(rows: &[Measurement], family: crate::Family) -> Vec<Point> {
    let rows: Vec<&Measurement> = rows.iter().filter(|r| r.family() == family).collect();
    let mut cases: Vec<(&str, &str)> = rows.iter().map(|r| (r.scene.as_str(), r.map.as_str())).collect();
    cases.sort_unstable();
    cases.dedup();
    let mut names: Vec<&str> = rows.iter().map(|r| r.setting.as_str()).collect();
    names.sort_unstable();
    names.dedup();
    let mut out: Vec<Point> = names
        .into_iter()
        .filter_map(|name| {
            let mine: Vec<&Measurement> = rows.iter().filter(|r| r.setting == name).copied().collect();
            let complete = cases.iter().all(|(s, m)| mine.iter().any(|r| r.scene == *s && r.map == *m));
            let n = mine.len() as f64;
            complete.then(|| Point {
                setting: name.to_string(),
                ms: mine.iter().map(|r| r.ms).sum::<f64>() / n,
                rmse: mine.iter().map(|r| r.rmse).sum::<f64>() / n,
                flip: mine.iter().map(|r| r.flip).sum::<f64>() / n,
            })
        })
        .collect();
    out.sort_by(|a, b| a.ms.total_cmp(&b.ms).then_with(|| a.setting.cmp(&b.setting)));
    out
}

/// The points of `points` on their Pareto front, by ms.
#[must_use]
pub fn front(points: &[Point]) -> Vec<Point> {
    let on = pareto(&points.iter().map(|p| (p.ms, p.rmse)).collect::<Vec<_>>());
    let mut f: Vec<Point> = points.iter().zip(on).filter(|(_, o)| *o).map(|(p, _)| p.clone()).collect();
    f.sort_by(|a, b| a.ms.total_cmp(&b.ms));
    f
}

/// Why no setting fits a budget.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ChooseError {
    /// Nothing was measured.
    #[error("no measured setting to choose from")]
    Empty,
    /// The budget is not a positive finite number of milliseconds.
    #[error("budget {0} ms is not a positive number of milliseconds")]
    BadBudget(f64),
    /// Every setting is slower than the budget.
    #[error("no setting fits in {budget} ms: the cheapest, {cheapest}, takes {ms:.3} ms")]
    OverBudget {
        /// The budget asked for.
        budget: f64,
        /// The fastest setting measured.
        cheapest: String,
        /// Its time.
        ms: f64,
    },
}

/// The setting with the least RMSE among those within `budget_ms` (ties: the faster). The
/// choice is on the Pareto front of `points`: a point that beat it would fit the budget too.
///
/// # Errors
/// No points; a budget that is not positive and finite; a budget below every point (the error
/// names the cheapest setting and its time).
pub fn choose(points: &[Point], budget_ms: f64) -> Result<Point, ChooseError> {
    if !(budget_ms.is_finite() && budget_ms > 0.0) {
        return Err(ChooseError::BadBudget(budget_ms));
    }
    let valid: Vec<&Point> = points.iter().filter(|p| p.ms.is_finite() && p.rmse.is_finite()).collect();
    let cheapest = valid.iter().min_by(|a, b| a.ms.total_cmp(&b.ms)).ok_or(ChooseError::Empty)?;
    valid
        .iter()
        .filter(|p| p.ms <= budget_ms)
        .min_by(|a, b| a.rmse.total_cmp(&b.rmse).then_with(|| a.ms.total_cmp(&b.ms)))
        .map(|p| (*p).clone())
        .ok_or_else(|| ChooseError::OverBudget {
            budget: budget_ms,
            cheapest: cheapest.setting.clone(),
            ms: cheapest.ms,
        })
}
