//! Every command line the README and docs show runs as written: `cargo xtask` lines and the
//! user tool's (`cargo run --release -p envshadow -- …`, or `envshadow …` once installed) parse
//! (the binary with `XTASK_PARSE_ONLY` / `ENVSHADOW_PARSE_ONLY` set: clap's checks, nothing run)
//! and the repository files they name exist; `cargo bench` lines name a bench target of the package cargo would pick;
//! other cargo lines are the ones CI runs; `tools/` scripts exist and take the options shown.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// (file, line number, command) for each command in a code block (one per line, a trailing
/// `# comment` dropped) and each inline code span (it may run over a line break) that starts
/// with `cargo ` or names a script under `tools/`.
fn commands() -> Vec<(String, usize, String)> {
    let mut docs = vec![root().join("README.md")];
    let mut more: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .expect("docs/")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    more.sort();
    docs.extend(more);
    let is_command = |s: &str| {
        s.starts_with("cargo ")
            || s.starts_with("envshadow ")
            || (s.starts_with("tools/")
                && s.split_whitespace().next().is_some_and(|w| w.ends_with(".sh") || w.ends_with(".py")))
    };
    let mut out = Vec::new();
    for doc in docs {
        let name = doc.file_name().map(|n| n.to_string_lossy().to_string()).unwrap_or_default();
        let text = std::fs::read_to_string(&doc).expect("read doc");
        // the prose with code blocks blanked (line numbers kept), for the inline spans
        let mut prose = String::new();
        let mut in_block = false;
        for (k, line) in text.lines().enumerate() {
            let fence = line.trim_start().starts_with("```");
            if fence {
                in_block = !in_block;
            } else if in_block {
                let cmd = line.split(" #").next().unwrap_or_default().trim();
                if is_command(cmd) {
                    out.push((name.clone(), k + 1, cmd.to_string()));
                }
            } else {
                prose.push_str(line);
            }
            prose.push('\n');
        }
        let mut at = 0;
        for (i, span) in prose.split('`').enumerate() {
            let line = prose[..at].matches('\n').count() + 1;
            at += span.len() + 1;
            let span = span.split_whitespace().collect::<Vec<_>>().join(" ");
            if i % 2 == 1 && is_command(&span) {
                out.push((name.clone(), line, span));
            }
        }
    }
    out
}

/// Whether `cargo xtask` arguments are a synopsis (`[--json]`, `a|b`, `PATH`, `N`, `WxH`)
/// rather than a command to copy.
fn is_synopsis(args: &[&str]) -> bool {
    args.iter().any(|a| {
        a.contains('[')
            || a.contains('|')
            || a.contains("...")
            || (a.chars().all(|c| c.is_ascii_uppercase() || c == 'x' || c == '_')
                && a.chars().any(|c| c.is_ascii_uppercase()))
    })
}

/// Why `cargo xtask ARGS` would not run as written, if it would not.
fn xtask_problem(args: &[&str]) -> Option<String> {
    cli_problem(Path::new(env!("CARGO_BIN_EXE_xtask")), "XTASK_PARSE_ONLY", args)
}

/// The user tool's binary: built beside xtask's by `cargo test --workspace` (a test cannot
/// depend on another package's binary).
fn envshadow_binary() -> PathBuf {
    let bin =
        Path::new(env!("CARGO_BIN_EXE_xtask")).with_file_name(format!("envshadow{}", std::env::consts::EXE_SUFFIX));
    assert!(bin.is_file(), "{} is not built: run the tests with `cargo test --workspace`", bin.display());
    bin
}

/// Why `envshadow ARGS` would not run as written, if it would not.
fn envshadow_problem(args: &[&str]) -> Option<String> {
    cli_problem(&envshadow_binary(), "ENVSHADOW_PARSE_ONLY", args)
}

/// Why `BIN ARGS` would not run as written, if it would not (`parse_only`: the variable that
/// makes the binary parse and stop).
fn cli_problem(bin: &Path, parse_only: &str, args: &[&str]) -> Option<String> {
    let run = |args: &[&str]| {
        Command::new(bin).args(args).env(parse_only, "1").current_dir(root()).output().expect("run the binary")
    };
    let first_error =
        |o: &std::process::Output| String::from_utf8_lossy(&o.stderr).lines().next().unwrap_or_default().to_string();
    if args.len() == 1 || is_synopsis(args) {
        // a subcommand named, or its synopsis: the subcommand exists and has every option shown
        let help = run(&[args[0], "--help"]);
        if !help.status.success() {
            return Some(first_error(&help));
        }
        let text = String::from_utf8_lossy(&help.stdout);
        let unknown: Vec<String> = args[1..]
            .iter()
            .map(|a| a.trim_matches(|c| c == '[' || c == ']').to_string())
            .filter(|a| a.starts_with("--") && !text.contains(a.as_str()))
            .collect();
        return (!unknown.is_empty()).then(|| format!("{unknown:?} not among `{} --help`'s options", args[0]));
    }
    let out = run(args);
    let missing: Vec<&&str> = args.iter().filter(|a| a.starts_with("assets/") && !root().join(a).exists()).collect();
    if !out.status.success() {
        Some(first_error(&out))
    } else if !missing.is_empty() {
        Some(format!("no such file {missing:?}"))
    } else {
        None
    }
}

/// (bench targets by package name, the default members' package names), from `cargo metadata`.
fn workspace() -> (Vec<(String, Vec<String>)>, Vec<String>) {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args(["metadata", "--no-deps", "--format-version", "1"])
        .current_dir(root())
        .output()
        .expect("cargo metadata");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("metadata JSON");
    let packages = v["packages"].as_array().cloned().unwrap_or_default();
    let benches = packages
        .iter()
        .map(|p| {
            let targets = p["targets"].as_array().cloned().unwrap_or_default();
            let benches = targets
                .iter()
                .filter(|t| t["kind"].as_array().is_some_and(|k| k.iter().any(|k| k == "bench")))
                .filter_map(|t| t["name"].as_str().map(String::from))
                .collect();
            (p["name"].as_str().unwrap_or_default().to_string(), benches)
        })
        .collect();
    let defaults: Vec<String> = v["workspace_default_members"]
        .as_array()
        .cloned()
        .unwrap_or_default()
        .iter()
        .filter_map(|id| packages.iter().find(|p| p["id"] == *id).and_then(|p| p["name"].as_str()).map(String::from))
        .collect();
    assert!(!defaults.is_empty(), "cargo metadata lists no default members");
    (benches, defaults)
}

/// Why `cargo bench ARGS` would fail to find its target, if it would.
fn bench_problem(args: &[&str], benches: &[(String, Vec<String>)], defaults: &[String]) -> Option<String> {
    let value = |flag: &str| args.iter().position(|a| *a == flag).and_then(|i| args.get(i + 1)).copied();
    let packages: Vec<&str> = match value("-p").or_else(|| value("--package")) {
        Some(p) => vec![p],
        None => defaults.iter().map(String::as_str).collect(),
    };
    let have = |b: &str| benches.iter().any(|(p, list)| packages.contains(&p.as_str()) && list.iter().any(|x| x == b));
    match value("--bench") {
        Some(b) if !have(b) => Some(format!("no bench target {b} in {packages:?}")),
        _ => None,
    }
}

/// `cargo run --release -p KRATE --example NAME`: the example's file must exist.
fn example_problem(krate: &str, name: &str) -> Option<String> {
    let file = root().join("crates").join(krate).join("examples").join(format!("{name}.rs"));
    (!file.exists()).then(|| format!("no example {}", file.display()))
}

#[test]
fn every_command_in_the_readme_and_docs_runs_as_written() {
    let (benches, defaults) = workspace();
    let ci = std::fs::read_to_string(root().join(".ci/run")).expect(".ci/run");
    let cmds = commands();
    assert!(cmds.iter().filter(|c| c.2.starts_with("cargo xtask ")).count() >= 20, "{cmds:?}");
    assert!(cmds.iter().any(|c| c.2.starts_with("cargo bench")), "{cmds:?}");
    let mut problems = Vec::new();
    for (doc, line, cmd) in &cmds {
        let words: Vec<&str> = cmd.split_whitespace().collect();
        let problem = match words.as_slice() {
            // a mention of the alias itself, not a command line
            ["cargo", "xtask"] => None,
            ["cargo", "xtask", args @ ..] => xtask_problem(args),
            ["cargo", "run", "--release", "-p", "envshadow", "--", args @ ..] | ["envshadow", args @ ..] => {
                envshadow_problem(args)
            }
            ["cargo", "install", "--path", path] => {
                (!root().join(path).join("Cargo.toml").is_file()).then(|| format!("no crate at {path}"))
            }
            ["cargo", "bench", args @ ..] => bench_problem(args, &benches, &defaults),
            // an example: its crate's file
            ["cargo", "run", "--release", "-p", krate, "--example", name, ..] => example_problem(krate, name),
            ["cargo", ..] => (!ci.lines().any(|l| l.trim() == cmd)).then(|| "not a line of .ci/run".to_string()),
            [script, args @ ..] => {
                let path = root().join(script);
                match std::fs::read_to_string(path.with_extension("py")).or_else(|_| std::fs::read_to_string(&path)) {
                    Err(_) => Some(format!("no script {script}")),
                    Ok(text) => {
                        let unknown: Vec<&&str> = args
                            .iter()
                            .filter(|a| a.starts_with("--") && !text.contains(&format!("\"{a}\"")))
                            .collect();
                        (!unknown.is_empty()).then(|| format!("options {unknown:?} not in the script"))
                    }
                }
            }
            [] => None,
        };
        if let Some(p) = problem {
            problems.push(format!("{doc}:{line}: `{cmd}`: {p}"));
        }
    }
    assert!(problems.is_empty(), "{} commands fail as written:\n{}", problems.len(), problems.join("\n"));
}

#[test]
fn the_checks_find_what_would_fail() {
    assert!(xtask_problem(&["validate", "--method"]).is_some(), "a missing value");
    assert!(xtask_problem(&["info", "assets/envmaps/nowhere.exr"]).is_some(), "a missing file");
    assert!(xtask_problem(&["shafts", "[--nope]"]).is_some(), "an option the synopsis invents");
    assert!(xtask_problem(&["nope"]).is_some(), "an unknown subcommand");
    assert!(xtask_problem(&["shafts", "[--scene", "ar_room|ar_ground]", "[--json]"]).is_none());
    assert!(envshadow_problem(&["render", "--nope"]).is_some(), "an option render does not have");
    assert!(envshadow_problem(&["validate"]).is_some(), "a job of xtask's, not the user tool's");
    assert!(xtask_problem(&["render", "--scene", "room"]).is_some(), "a user command, not one of xtask's jobs");
    assert!(envshadow_problem(&["info", "assets/envmaps/nowhere.exr"]).is_some(), "a missing file");
    assert!(envshadow_problem(&["render", "[--ground]", "[--aovs]"]).is_none());
    let (benches, defaults) = workspace();
    assert!(bench_problem(&["--bench", "no_such_bench"], &benches, &defaults).is_some());
    assert!(bench_problem(&["-p", "envshadow-benches", "--bench", "shafts"], &benches, &defaults).is_none());
    assert!(example_problem("penumbra-wedge", "no_such_example").is_some());
    assert!(example_problem("penumbra-wedge", "moving_box").is_none());
}
