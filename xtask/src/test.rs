//! `cargo xtask test`: the whole test suite, as CI runs it.
//!
//! Unit, integration and doc tests of every crate (the GPU ones on the best adapter present, or
//! the one `--adapter` names; lavapipe where there is no GPU; the viewer's window on Xvfb,
//! installed where missing) and one smoke run of every
//! criterion bench (so benches never rot). The main job is among the tests: `cargo xtask
//! validate --quick` from a copied binary, with its thresholds, checking that docs/measured.md's
//! quick validate figures are this code's (xtask's `cli` test; the full run took 650-800 s of a
//! 2-core machine, which CI's 30 minutes cannot hold beside the tests). Prints the wall time.

use std::process::Command;
use std::time::Instant;

pub fn run(adapter: Option<&str>, extra: &[String]) -> Result<(), String> {
    let chosen = crate::lavapipe::ensure_adapter(adapter)?;
    crate::lavapipe::ensure_xvfb()?;
    outln!("xtask test: GPU tests on {chosen}");
    let start = Instant::now();
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    // --all-targets covers libs, bins, tests and benches (criterion runs each bench once under
    // `cargo test`); doc tests need their own run.
    let runs: [&[&str]; 2] = [&["test", "--workspace", "--all-targets"], &["test", "--workspace", "--doc"]];
    for args in runs {
        let mut cmd = Command::new(&cargo);
        cmd.args(args);
        if let Some(name) = adapter {
            cmd.env(gpu::ADAPTER_ENV, name);
        }
        if !extra.is_empty() {
            cmd.arg("--").args(extra);
        }
        outln!("xtask test: cargo {}", args.join(" "));
        let status = cmd.status().map_err(|e| format!("cannot run cargo: {e}"))?;
        if !status.success() {
            return Err(format!("cargo {} failed ({status})", args.join(" ")));
        }
    }
    outln!("xtask test: all passed in {:.0} s", start.elapsed().as_secs_f64());
    Ok(())
}
