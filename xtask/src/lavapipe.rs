//! Makes sure Mesa's lavapipe (software Vulkan) is installed: GPU code is validated on it.
//!
//! Installs `mesa-vulkan-drivers` with apt when it is missing and we run as root; otherwise
//! stops with the exact command to run.

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
    if installed() {
        return Ok(());
    }
    if !cfg!(target_os = "linux") || !Path::new("/usr/bin/apt-get").exists() {
        return Err(format!(
            "Mesa's lavapipe (software Vulkan) is missing and this is not a Debian/Ubuntu system: \
             install Mesa's Vulkan drivers (on Debian: {INSTALL})"
        ));
    }
    if !is_root() {
        return Err(format!("Mesa's lavapipe (software Vulkan) is missing: run `sudo sh -c '{INSTALL}'`"));
    }
    outln!("installing Mesa's lavapipe: {INSTALL}");
    let status = Command::new("sh")
        .args(["-c", INSTALL])
        .env("DEBIAN_FRONTEND", "noninteractive")
        .status()
        .map_err(|e| format!("cannot run apt-get: {e}"))?;
    if !status.success() || !installed() {
        return Err(format!("installing lavapipe failed ({status}); run `{INSTALL}` by hand"));
    }
    Ok(())
}
