//! `cargo xtask test`: the whole test suite, as CI runs it.
//!
//! Unit, integration and doc tests of every crate (the GPU ones on lavapipe where there is no
//! GPU), one smoke run of every criterion bench (so benches never rot), and — when no test
//! filter is given — the main job, `cargo xtask validate --quick`, with its thresholds. Prints
//! the wall time.

use std::process::Command;
use std::time::Instant;

pub fn run(extra: &[String]) -> Result<(), String> {
    crate::lavapipe::ensure()?;
    let start = Instant::now();
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    // --all-targets covers libs, bins, tests and benches (criterion runs each bench once under
    // `cargo test`); doc tests need their own run.
    let runs: [&[&str]; 2] = [&["test", "--workspace", "--all-targets"], &["test", "--workspace", "--doc"]];
    for args in runs {
        let mut cmd = Command::new(&cargo);
        cmd.args(args);
        if !extra.is_empty() {
            cmd.arg("--").args(extra);
        }
        outln!("xtask test: cargo {}", args.join(" "));
        let status = cmd.status().map_err(|e| format!("cannot run cargo: {e}"))?;
        if !status.success() {
            return Err(format!("cargo {} failed ({status})", args.join(" ")));
        }
    }
    if extra.is_empty() {
        outln!("xtask test: cargo xtask validate --quick");
        // the command's own defaults, as a user gets them
        crate::validate::run(&clap::Parser::parse_from(["validate", "--quick"]))?;
    }
    outln!("xtask test: all passed in {:.0} s", start.elapsed().as_secs_f64());
    Ok(())
}
