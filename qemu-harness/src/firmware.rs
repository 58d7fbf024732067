//! Where the workspace, its target directory and the release firmware ELFs are.

use std::path::{Path, PathBuf};

/// The firmware's target.
pub const TARGET: &str = "thumbv7em-none-eabihf";
/// The firmware package.
pub const PACKAGE: &str = "firmware-example";
/// The firmware binaries whose sizes and stack are budgeted.
pub const BUDGETED: [&str; 4] = ["firmware-example", "measure", "qemu-demo", "qemu-uart"];
/// The handler self-tests (must exit QEMU with code 1).
pub const SELF_TESTS: [&str; 2] = ["selftest-panic", "selftest-hardfault"];

/// The workspace root (the parent of this crate's directory).
pub fn workspace_root() -> PathBuf {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    manifest.parent().unwrap_or(manifest).to_path_buf()
}

/// Cargo's target directory: `$CARGO_TARGET_DIR` (relative paths from the workspace root)
/// or `<workspace>/target`.
pub fn target_dir() -> PathBuf {
    let root = workspace_root();
    std::env::var_os("CARGO_TARGET_DIR")
        .filter(|p| !p.is_empty())
        .map_or_else(|| root.join("target"), |t| root.join(t))
}

/// The release ELF of firmware binary `bin`.
pub fn elf(bin: &str) -> PathBuf {
    target_dir().join(TARGET).join("release").join(bin)
}

/// The release ELF of `bin`, or `$<env_var>` if that is set and not empty.
pub fn elf_or_env(bin: &str, env_var: &str) -> PathBuf {
    std::env::var_os(env_var)
        .filter(|p| !p.is_empty())
        .map_or_else(|| elf(bin), PathBuf::from)
}

/// The command that builds the release ELF of `bin`.
pub fn build_command(bin: &str) -> String {
    format!("cargo build -p {PACKAGE} --target {TARGET} --release --bin {bin}")
}

/// The release ELF of `bin` if it exists, else an error saying how to build it.
pub fn require_elf(path: &Path, bin: &str) -> Result<PathBuf, String> {
    if path.is_file() {
        Ok(path.to_path_buf())
    } else {
        Err(format!(
            "{} not found: build it with `{}`",
            path.display(),
            build_command(bin)
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elf_paths_and_build_command() {
        let e = elf("qemu-uart");
        assert!(
            e.ends_with("thumbv7em-none-eabihf/release/qemu-uart"),
            "{}",
            e.display()
        );
        assert!(workspace_root().join("qemu-harness").is_dir());
        assert_eq!(
            build_command("qemu-demo"),
            "cargo build -p firmware-example --target thumbv7em-none-eabihf --release --bin qemu-demo"
        );
        let err = require_elf(Path::new("/no/such/elf"), "measure").expect_err("missing");
        assert!(
            err.contains("/no/such/elf") && err.contains("--bin measure"),
            "{err}"
        );
    }
}
