//! The GPU a command runs on: the best adapter present, or the one `--adapter` names. Only on a
//! machine with no adapter at all is Mesa's lavapipe (software Vulkan) installed — with apt, when
//! we run as root — or asked for with the exact command to run; so is Xvfb, the display the
//! viewer's tests open their window on, where there is none.

use gpu::{Gpu, GpuError};
use std::path::Path;
use std::process::Command;

const ICD_DIRS: [&str; 2] = ["/usr/share/vulkan/icd.d", "/etc/vulkan/icd.d"];
const INSTALL: &str = "apt-get update && apt-get install -y --no-install-recommends mesa-vulkan-drivers";

/// Whether a lavapipe ICD manifest (`lvp_icd*.json`) is present.
pub fn installed() -> bool {
    ICD_DIRS.iter().any(|dir| {
        std::fs::read_dir(Path::new(dir))
            .is_ok_and(|entries| entries.flatten().any(|e| e.file_name().to_string_lossy().starts_with("lvp_icd")))
    })
}

fn is_root() -> bool {
    Command::new("id").arg("-u").output().is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

/// Installs lavapipe when missing (as root), or explains how.
pub fn ensure() -> Result<(), String> {
    apt_install("Mesa's lavapipe (software Vulkan)", INSTALL, installed)
}

const XVFB_INSTALL: &str = "apt-get update && apt-get install -y --no-install-recommends xvfb xauth";

/// Whether `xvfb-run` is on the PATH.
pub fn xvfb_installed() -> bool {
    Command::new("sh").args(["-c", "command -v xvfb-run"]).output().is_ok_and(|o| o.status.success())
}

/// Installs Xvfb (with `xvfb-run` and `xauth`) when missing (as root), or explains how: the
/// viewer's tests open their window on it.
pub fn ensure_xvfb() -> Result<(), String> {
    apt_install("Xvfb (the viewer's tests' display)", XVFB_INSTALL, xvfb_installed)
}

/// Runs `install` with apt as root when `present` says `what` is missing, or explains how.
fn apt_install(what: &str, install: &str, present: fn() -> bool) -> Result<(), String> {
    if present() {
        return Ok(());
    }
    if !cfg!(target_os = "linux") || !Path::new("/usr/bin/apt-get").exists() {
        return Err(format!("{what} is missing and this is not a Debian/Ubuntu system (on Debian: {install})"));
    }
    if !is_root() {
        return Err(format!("{what} is missing: run `sudo sh -c '{install}'`"));
    }
    outln!("installing {what}: {install}");
    let status = Command::new("sh")
        .args(["-c", install])
        .env("DEBIAN_FRONTEND", "noninteractive")
        .status()
        .map_err(|e| format!("cannot run apt-get: {e}"))?;
    if !status.success() || !present() {
        return Err(format!("installing {what} failed ({status}); run `{install}` by hand"));
    }
    Ok(())
}

/// The GPU for a command: `adapter` (`--adapter`), else `ENVSHADOW_ADAPTER`, else the best
/// adapter present. Lavapipe is installed (or asked for) only when there is no adapter at all.
pub fn open_gpu(adapter: Option<&str>) -> Result<Gpu, String> {
    let open = || match adapter {
        Some(name) => Gpu::with_adapter(Some(name)),
        None => Gpu::new(),
    };
    match open() {
        Err(GpuError::NoAdapter(_)) => {
            outln!("no GPU adapter found: using Mesa's lavapipe (software Vulkan)");
            ensure()?;
            open().map_err(|e| e.to_string())
        }
        other => other.map_err(|e| e.to_string()),
    }
}

/// Makes sure some adapter exists before GPU tests run: installs lavapipe only when there is none,
/// and checks that `adapter`, when given, names one. Returns the one the tests will use,
/// described.
pub fn ensure_adapter(adapter: Option<&str>) -> Result<String, String> {
    if gpu::adapters(None).is_empty() {
        outln!("no GPU adapter found: using Mesa's lavapipe (software Vulkan)");
        ensure()?;
    }
    let infos = gpu::adapters(None);
    let wanted = adapter.map(str::to_string).or_else(|| std::env::var(gpu::ADAPTER_ENV).ok().filter(|n| !n.is_empty()));
    match gpu::pick_adapter(&infos, wanted.as_deref()) {
        Some(k) => Ok(gpu::describe_adapter(&infos[k])),
        None => Err(GpuError::UnknownAdapter {
            wanted: wanted.unwrap_or_default(),
            found: infos.iter().map(gpu::describe_adapter).collect(),
        }
        .to_string()),
    }
}
