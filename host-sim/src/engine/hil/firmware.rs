//! Where the firmware ELF of a host-in-the-loop run comes from, and how to build it: in a
//! module of its own, which the options (`options.rs`) and the errors' messages
//! (`error.rs`) both read.

use std::path::{Path, PathBuf};

/// Environment variable overriding the default firmware ELF.
pub const FIRMWARE_ENV: &str = "HOST_SIM_FIRMWARE";
/// The firmware ELF, relative to the cargo target directory.
pub const FIRMWARE_REL: &str = "thumbv7em-none-eabihf/release/qemu-uart";
/// The command that builds the firmware ELF.
pub const FIRMWARE_BUILD: &str =
    "cargo build -p firmware-example --target thumbv7em-none-eabihf --release --bin qemu-uart";
/// The default firmware ELF: `$HOST_SIM_FIRMWARE`, else
/// `<target dir>/thumbv7em-none-eabihf/release/qemu-uart`, where the target directory is
/// `$CARGO_TARGET_DIR` (relative paths from the workspace root) or `<workspace>/target`.
pub fn default_firmware() -> PathBuf {
    if let Some(p) = std::env::var_os(FIRMWARE_ENV).filter(|p| !p.is_empty()) {
        return PathBuf::from(p);
    }
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let workspace = manifest.parent().unwrap_or(manifest);
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .filter(|p| !p.is_empty())
        .map_or_else(|| workspace.join("target"), |t| workspace.join(t));
    target.join(FIRMWARE_REL)
}
