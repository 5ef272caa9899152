//! Structured fuzzing of every file a command reads, on stable Rust (no nightly, so no
//! `cargo fuzz`): small valid files ([`seeds`]) are mutated with format-aware operators
//! ([`mutate`]: bit flips, truncation at every length of the header, header fields replaced by
//! extremes, dimensions up to 2^31, wrong channel counts, NaN / infinity / negative values,
//! broken JSON, glTF containers, sizes and binary data) and handed to the loaders the commands
//! use. The harness ([`run`]) counts
//! panics (caught, with the first messages kept), errors that are not one line naming the file,
//! and — through a [`MemoryWatch`] the binary provides — the most memory a case allocated.
//!
//! Loads run with [`FUZZ_MAX_PIXELS`] as `LoadOptions::max_pixels`: the same size check as the
//! default limit, with a number that keeps a case that claims the most texels allowed at 48 MiB
//! instead of 1.5 GiB, so a million cases run in minutes.
//!
//! Architecture invariant: reads files only through the library crates' own loaders; never
//! wgpu.

pub mod model;
pub mod mutate;
pub mod seeds;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use std::sync::{Arc, Mutex};

/// `max_pixels` of the fuzzed loads: 2^22 texels (48 MiB of f32 RGB).
pub const FUZZ_MAX_PIXELS: u64 = 1 << 22;

/// The most a case may allocate: the pixels at the fuzzed limit (12 bytes a texel) twice over
/// (a decoder's buffer and the map), plus 64 MiB for decoders' working memory.
pub const CASE_ALLOCATION_LIMIT: usize = 2 * 12 * (FUZZ_MAX_PIXELS as usize) + (64 << 20);

/// When set, each case's input is written to the file it names before the case runs, so a case
/// that aborts the process (an allocation beyond the limit) can be found and replayed.
pub const LAST_INPUT_ENV: &str = "ENVSHADOW_FUZZ_LAST_INPUT";

/// What kind of file a target reads: the mutations it gets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Radiance RGBE (`.hdr`).
    Hdr,
    /// OpenEXR.
    Exr,
    /// JSON.
    Json,
    /// glTF 2.0 JSON (`.gltf`, its buffer embedded as a data URI).
    Gltf,
    /// Binary glTF 2.0 (`.glb`).
    Glb,
    /// A PNG or JPEG photograph (`--photo`).
    Png,
}

/// Loads a file's bytes under a name: `Err` is the loader's message.
pub type Loader = dyn Fn(&[u8], &Path) -> Result<(), String>;

/// A loader under test: its seeds and how to run it on a file's bytes.
pub struct Target {
    /// Short name, used in the case's file name.
    pub name: &'static str,
    /// File extension of its cases.
    pub extension: &'static str,
    /// The format its mutations know.
    pub format: Format,
    /// Valid files to start from.
    pub seeds: Vec<Vec<u8>>,
    /// Loads `bytes` as the file `name`: `Err` carries the loader's one-line message.
    pub run: Box<Loader>,
}

/// Memory accounting the fuzzing binary provides (a global allocator is the binary's choice).
pub trait MemoryWatch {
    /// Bytes allocated now.
    fn allocated(&self) -> usize;
    /// The most bytes allocated at once so far.
    fn peak(&self) -> usize;
    /// Makes any allocation that would take the total above `bytes` fail (and the process
    /// abort, as an allocation failure does): set to the run's baseline plus
    /// [`CASE_ALLOCATION_LIMIT`] at its start (cases free what they allocate).
    fn limit(&self, bytes: usize);
}

/// What a run found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Report {
    /// Cases run.
    pub cases: usize,
    /// Cases whose loader panicked.
    pub panics: usize,
    /// Cases refused with an error.
    pub errors: usize,
    /// Cases loaded (a mutation may leave a file valid).
    pub accepted: usize,
    /// Errors that were not one line naming the file and a reason.
    pub bad_messages: usize,
    /// The most bytes allocated at once above the run's baseline, when watched.
    pub peak_bytes: Option<usize>,
    /// Cases per target name.
    pub per_target: Vec<(&'static str, usize)>,
    /// The first findings (panics, bad messages): what happened, and the case's file name and
    /// bytes.
    pub findings: Vec<Finding>,
}

impl Report {
    /// The summary line: `fuzz: N cases, P panics, ...`.
    #[must_use]
    pub fn summary(&self) -> String {
        let peak = self.peak_bytes.map_or_else(
            || "memory not watched".to_string(),
            |p| format!("peak {:.1} MiB of {} MiB allowed", p as f64 / 1048576.0, CASE_ALLOCATION_LIMIT >> 20),
        );
        format!(
            "fuzz: {} cases, {} panics, {} errors not one line naming the file, {} refused, {} loaded, {peak}",
            self.cases, self.panics, self.bad_messages, self.errors, self.accepted
        )
    }

    /// Whether nothing was found.
    #[must_use]
    pub fn is_clean(&self) -> bool {
        self.panics == 0 && self.bad_messages == 0
    }
}

/// A panic hook, as `std::panic::take_hook` returns it.
type PanicHook = Box<dyn Fn(&std::panic::PanicHookInfo<'_>) + Sync + Send + 'static>;

/// The panic hook to put back when a run ends, however it ends.
struct HookGuard(Option<PanicHook>);

impl Drop for HookGuard {
    fn drop(&mut self) {
        // set_hook may not be called while unwinding (a bug of the harness itself)
        if let Some(h) = self.0.take().filter(|_| !std::thread::panicking()) {
            std::panic::set_hook(h);
        }
    }
}

/// A case that broke a rule.
#[derive(Clone, Debug, PartialEq)]
pub struct Finding {
    /// The case's file name.
    pub name: String,
    /// The target that read it.
    pub target: &'static str,
    /// What happened: the panic's message, or the message that was not one line naming the file.
    pub what: String,
    /// The case's bytes, to replay it.
    pub input: Vec<u8>,
}

/// Findings kept in [`Report::findings`].
const MAX_FINDINGS: usize = 20;

/// Whether `message` is one line that names `file` and says more than that.
#[must_use]
pub fn is_good_message(message: &str, file: &str) -> bool {
    !message.contains('\n') && message.contains(file) && message.trim().len() > file.len() + 8
}

/// Runs `cases` cases over `targets` (round robin), mutations drawn from `seed`. Every other case
/// of a target is a truncation of one of its seeds, at every length of the seed's header in
/// turn, until all are done; the rest are random mutations. `progress` is called now and then with the cases done.
pub fn run(
    targets: &[Target],
    cases: usize,
    seed: u64,
    memory: Option<&dyn MemoryWatch>,
    progress: &mut dyn FnMut(usize),
) -> Report {
    let mut report = Report { per_target: targets.iter().map(|t| (t.name, 0)).collect(), ..Report::default() };
    if targets.is_empty() {
        return report;
    }
    // panics are counted, not printed: keep the message of the latest one for the findings
    let last_panic: Arc<Mutex<String>> = Arc::default();
    let _restore = HookGuard(Some(std::panic::take_hook()));
    {
        let last = Arc::clone(&last_panic);
        std::panic::set_hook(Box::new(move |info| {
            if let Ok(mut l) = last.lock() {
                *l = info.to_string().replace('\n', " ");
            }
        }));
    }
    // one limit for the whole run (cases leave nothing allocated): moving it while a decoder's
    // threads allocate would race with the allocator's accounts
    let baseline = memory.map(MemoryWatch::allocated);
    if let (Some(m), Some(b)) = (memory, baseline) {
        m.limit(b.saturating_add(CASE_ALLOCATION_LIMIT));
    }
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    // per target: the truncations of its seeds at every length of their headers, taken on
    // every other of its cases until done; the rest are random mutations
    let truncations: Vec<Vec<(usize, usize)>> = targets
        .iter()
        .map(|t| {
            t.seeds
                .iter()
                .enumerate()
                .flat_map(|(s, bytes)| (0..mutate::header_len(bytes, t.format)).map(move |len| (s, len)))
                .collect()
        })
        .collect();
    let mut next_truncation = vec![0usize; targets.len()];
    let last_input = std::env::var_os(LAST_INPUT_ENV);
    for case in 0..cases {
        let t = case % targets.len();
        let target = &targets[t];
        let round = case / targets.len();
        let input = match truncations[t].get(next_truncation[t]).filter(|_| round.is_multiple_of(2)) {
            Some(&(s, len)) => {
                next_truncation[t] += 1;
                target.seeds[s][..len].to_vec()
            }
            None => {
                let s = rng.random_range(0..target.seeds.len().max(1));
                match target.seeds.get(s) {
                    Some(bytes) => mutate::mutate(bytes, target.format, &mut rng),
                    None => Vec::new(),
                }
            }
        };
        let name = format!("fuzz-case-{case}.{}", target.extension);
        if let Some(m) = memory {
            m.limit(m.allocated().saturating_add(CASE_ALLOCATION_LIMIT));
        }
        if let Some(path) = &last_input {
            // for a case that aborts the process (an allocation failure): its input survives
            let _ = std::fs::write(path, &input);
        }
        let outcome = catch_unwind(AssertUnwindSafe(|| (target.run)(&input, Path::new(&name))));
        report.cases += 1;
        report.per_target[t].1 += 1;
        let broken = match outcome {
            Ok(Ok(())) => {
                report.accepted += 1;
                None
            }
            Ok(Err(message)) => {
                report.errors += 1;
                let bad = !is_good_message(&message, &name);
                report.bad_messages += usize::from(bad);
                bad.then(|| format!("message {message:?}"))
            }
            Err(_) => {
                report.panics += 1;
                Some(format!("panic: {}", last_panic.lock().map(|l| l.clone()).unwrap_or_default()))
            }
        };
        if let Some(what) = broken.filter(|_| report.findings.len() < MAX_FINDINGS) {
            report.findings.push(Finding { name, target: target.name, what, input });
        }
        if case % 1000 == 999 {
            progress(case + 1);
        }
    }
    if let (Some(m), Some(b)) = (memory, baseline) {
        report.peak_bytes = Some(m.peak().saturating_sub(b));
        m.limit(usize::MAX);
    }
    report
}
