//! `cargo xtask fuzz --cases N [--seed S]`: structured fuzzing of every file a command reads
//! (`input-fuzz`'s targets, plus `validate --thresholds`), with each case's memory limited by the
//! global allocator. Prints the findings (their inputs saved in target/fuzz/findings), then the
//! summary line last: `fuzz: N cases, P panics, ...`; exits 1 when anything was found. A case
//! that aborts the process (an allocation beyond its limit) leaves its input in the file named
//! by `ENVSHADOW_FUZZ_LAST_INPUT`, when set.

use input_fuzz::{Format, MemoryWatch, Target};
use std::process::ExitCode;
use std::time::Instant;

/// The global allocator's accounts (see `main.rs`).
struct Allocator;

impl MemoryWatch for Allocator {
    fn allocated(&self) -> usize {
        crate::ALLOCATOR.allocated()
    }
    fn peak(&self) -> usize {
        crate::ALLOCATOR.max_allocated()
    }
    fn limit(&self, bytes: usize) {
        // refused only below what is allocated now, which a limit above it never is
        let _ = crate::ALLOCATOR.set_limit(bytes);
    }
}

/// `validate --thresholds FILE`.
fn thresholds_target() -> Target {
    let minimal = br#"{"thresholds": {"spheres_box@city.exr:gpu_shadow_maps.rmse": 0.07}}"#.to_vec();
    Target {
        name: "thresholds.json",
        extension: "json",
        format: Format::Json,
        seeds: vec![crate::thresholds::THRESHOLDS.as_bytes().to_vec(), minimal],
        run: Box::new(|bytes, path| {
            let text = std::str::from_utf8(bytes).map_err(|e| format!("{}: not UTF-8: {e}", path.display()))?;
            crate::thresholds::parse_thresholds(text, &path.display().to_string()).map(|_| ())
        }),
    }
}

pub fn run(cases: usize, seed: u64) -> ExitCode {
    let mut targets = input_fuzz::seeds::library_targets();
    targets.push(thresholds_target());
    let names: Vec<String> = targets.iter().map(|t| format!("{} ({} seeds)", t.name, t.seeds.len())).collect();
    outln!("fuzz: {cases} cases, seed {seed}, over {}", names.join(", "));
    let start = Instant::now();
    let report = input_fuzz::run(&targets, cases, seed, Some(&Allocator), &mut |done| {
        if done % 100_000 == 0 {
            outln!("  {done} cases, {:.0} s", start.elapsed().as_secs_f64());
        }
    });
    let dir = std::path::Path::new("target/fuzz/findings");
    for f in &report.findings {
        let path = dir.join(&f.name);
        let saved = std::fs::create_dir_all(dir).and_then(|()| std::fs::write(&path, &f.input));
        let at = if saved.is_ok() { path.display().to_string() } else { "(not saved)".into() };
        outln!("  finding: {} ({}): {}; input {at}", f.name, f.target, f.what);
    }
    let per: Vec<String> = report.per_target.iter().map(|(n, c)| format!("{n} {c}")).collect();
    outln!("  cases per target: {}; {:.1} s", per.join(", "), start.elapsed().as_secs_f64());
    outln!("{}", report.summary());
    if report.is_clean() { ExitCode::SUCCESS } else { ExitCode::FAILURE }
}
