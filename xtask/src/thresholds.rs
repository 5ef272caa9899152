//! `validate`'s thresholds: the checked-in file (embedded in the binary), its parsing, and the
//! check of a run's measured values against it.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The checked-in thresholds, embedded so that a binary copied elsewhere still has them.
pub const THRESHOLDS: &str = include_str!("../../validate/thresholds.json");

/// The thresholds file: a limit per measured key, and the keys measured for the report only.
#[derive(Debug, Default)]
pub struct Thresholds {
    /// Key -> the most the measured value may be.
    pub limits: BTreeMap<String, f64>,
    /// Rows (the part of a key between ':' and the metric) reported without limits in every
    /// run: listed, so that they are chosen, not forgotten.
    pub report_only: BTreeSet<String>,
    /// The file's name, for messages.
    pub name: String,
}

impl Thresholds {
    /// (failures, thresholds checked). A measured key `run:row.metric` fails when it exceeds its
    /// limit, and when it has no limit although its run has limits and its row is not
    /// `report_only`: a renamed or new row cannot drop out of the checks unnoticed. Runs with no
    /// limits at all (another map or scene) are only reported.
    #[must_use]
    pub fn check(&self, measured: &BTreeMap<String, f64>) -> (Vec<String>, usize) {
        let runs: BTreeSet<&str> = self.limits.keys().map(|k| key_parts(k).0).collect();
        let mut failures = Vec::new();
        let mut checked = 0;
        for (k, v) in measured {
            match self.limits.get(k) {
                Some(t) => {
                    checked += 1;
                    // a NaN measurement fails too
                    if v.is_nan() || v > t {
                        failures.push(format!("{k} = {v:.5} exceeds {t}"));
                    }
                }
                None if runs.contains(key_parts(k).0) && !self.report_only.contains(key_parts(k).1) => {
                    failures.push(format!(
                        "{k} = {v:.5} has no threshold in {}: add one, or list its row under \"report_only\"",
                        self.name
                    ))
                }
                None => {}
            }
        }
        (failures, checked)
    }
}

/// (run, row) of a measured key `run:row.metric`.
fn key_parts(key: &str) -> (&str, &str) {
    let (run, rest) = key.split_once(':').unwrap_or((key, ""));
    (run, rest.rsplit_once('.').map_or(rest, |(row, _)| row))
}

/// The thresholds of `path`, or the embedded checked-in ones.
pub(super) fn load_thresholds(path: Option<&Path>) -> Result<Thresholds, String> {
    match path {
        Some(p) => {
            let text = std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?;
            parse_thresholds(&text, &p.display().to_string())
        }
        None => parse_thresholds(THRESHOLDS, "validate/thresholds.json (embedded)"),
    }
}

/// `{"thresholds": {"key": number, ...}, "report_only": ["row", ...]}` (`report_only` optional);
/// `name` is the file's name in errors.
pub fn parse_thresholds(text: &str, name: &str) -> Result<Thresholds, String> {
    let one_line = envmap_sphere::error::one_line;
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| format!("{name}: {}", one_line(&e.to_string())))?;
    let obj = value
        .get("thresholds")
        .and_then(|v| v.as_object())
        .ok_or_else(|| format!("{name}: no \"thresholds\" object"))?;
    let mut limits = BTreeMap::new();
    for (k, v) in obj {
        let t = v
            .as_f64()
            .filter(|t| t.is_finite())
            .ok_or_else(|| format!("{name}: threshold {} is not a finite number", one_line(k)))?;
        limits.insert(k.clone(), t);
    }
    let mut report_only = BTreeSet::new();
    if let Some(list) = value.get("report_only") {
        let list = list.as_array().ok_or_else(|| format!("{name}: \"report_only\" is not a list"))?;
        for k in list {
            let k = k.as_str().ok_or_else(|| format!("{name}: a \"report_only\" entry is not a string"))?;
            if limits.keys().any(|key| key_parts(key).1 == k) {
                return Err(format!("{name}: row {} has thresholds and is listed as report_only", one_line(k)));
            }
            report_only.insert(k.to_string());
        }
    }
    Ok(Thresholds { limits, report_only, name: name.to_string() })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn thresholds() -> Thresholds {
        let text = r#"{"thresholds": {"s@m:a.rmse": 0.1, "s@m:b.rmse": 0.2}, "report_only": ["c"]}"#;
        parse_thresholds(text, "t.json").unwrap_or_else(|e| panic!("{e}"))
    }

    fn measured(pairs: &[(&str, f64)]) -> BTreeMap<String, f64> {
        pairs.iter().map(|(k, v)| ((*k).to_string(), *v)).collect()
    }

    #[test]
    fn a_value_over_its_limit_fails() {
        let (f, checked) = thresholds().check(&measured(&[("s@m:a.rmse", 0.05), ("s@m:b.rmse", 0.25)]));
        assert_eq!(checked, 2);
        assert_eq!(f.len(), 1);
        assert!(f[0].starts_with("s@m:b.rmse = 0.25000 exceeds 0.2"), "{f:?}");
        let (f, _) = thresholds().check(&measured(&[("s@m:a.rmse", f64::NAN)]));
        assert_eq!(f.len(), 1, "NaN fails");
    }

    #[test]
    fn a_measured_key_without_a_threshold_fails_in_a_run_that_has_thresholds() {
        let (f, checked) = thresholds().check(&measured(&[("s@m:a.rmse", 0.05), ("s@m:renamed.rmse", 0.01)]));
        assert_eq!(checked, 1);
        assert_eq!(f.len(), 1);
        assert!(f[0].contains("s@m:renamed.rmse") && f[0].contains("no threshold in t.json"), "{f:?}");
        // a report-only row: fine; another run (map, scene) without any thresholds: fine
        let (f, checked) = thresholds().check(&measured(&[("s@m:c.rmse", 9.0), ("s@other:a.rmse", 9.0)]));
        assert!(f.is_empty() && checked == 0, "{f:?}");
    }

    /// Another method's run (`scene@map[method]`) measures the same rows as the default's, so
    /// each must limit the same rows, or `validate --method` fails on a row nobody limited.
    #[test]
    fn every_method_limits_the_rows_of_the_default_run() {
        let t = parse_thresholds(THRESHOLDS, "validate/thresholds.json").unwrap_or_else(|e| panic!("{e}"));
        let mut rows: BTreeMap<&str, BTreeSet<&str>> = BTreeMap::new();
        for k in t.limits.keys() {
            let (run, row) = key_parts(k);
            rows.entry(run).or_default().insert(row);
        }
        let mut compared = 0;
        for (run, set) in &rows {
            let Some((head, rest)) = run.split_once('[') else { continue };
            let Some((_, tail)) = rest.split_once(']') else { panic!("{run}: an unclosed method") };
            let default = format!("{head}{tail}");
            if let Some(default_rows) = rows.get(default.as_str()) {
                assert_eq!(set, default_rows, "{run} against {default}");
                compared += 1;
            }
        }
        assert!(compared > 0, "no method's run to compare");
    }

    #[test]
    fn a_key_both_limited_and_report_only_is_refused() {
        let text = r#"{"thresholds": {"s@m:a.rmse": 0.1}, "report_only": ["a"]}"#;
        let e = parse_thresholds(text, "t.json").map(|_| ()).unwrap_err();
        assert!(e.contains("t.json") && e.contains("report_only"), "{e}");
    }
}
