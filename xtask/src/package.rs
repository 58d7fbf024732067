//! The test command's packaging phase: the crates meant for crates.io package and build
//! from their `.crate` files alone (`cargo package`), each with both license files and
//! its README; and the facts the packages state stay true (unit tests below: the
//! `rust-version` is the pinned toolchain's, each README's example is the crate's
//! `examples/readme.rs`, which `cargo test` and clippy compile).

use crate::tools::{self, cargo};

/// The published crates (package name, directory), dependencies first. The C ABI
/// crate depends on the core and (feature `sim-vehicle`) on the vehicle models, which
/// are packaged with it: cargo puts the local dependencies of the listed packages in a
/// temporary local registry (`target/package/tmp-registry`) to verify the dependents.
pub const CRATES: [(&str, &str); 3] = [
    ("ph-formation-core", "controller-core"),
    ("ph-formation-vehicle", "vehicle"),
    ("ph-formation-ffi", "controller-ffi"),
];

/// Files every package must contain (besides its sources and manifest).
pub const REQUIRED: [&str; 3] = ["LICENSE-MIT", "LICENSE-APACHE", "README.md"];

/// `cargo package` of [`CRATES`] with verification (each `.crate` unpacked and built on
/// its own), then `cargo package --list` checked for [`REQUIRED`]. `--allow-dirty`: what
/// is checked is the packaging, not whether the developer has committed.
pub fn run() -> Result<(), String> {
    clear_stale_extracts();
    let mut args = vec!["package", "--allow-dirty"];
    for (name, _) in CRATES {
        args.extend(["-p", name]);
    }
    tools::run(cargo().args(&args))?;
    for (name, _) in CRATES {
        let list = tools::output(cargo().args(["package", "--allow-dirty", "--list", "-p", name]))?;
        missing(&list).map_err(|f| format!("the package {name} lacks {f}"))?;
    }
    println!("packaged: {}", CRATES.map(|c| c.0).join(", "));
    Ok(())
}

/// Removes what earlier `cargo package` runs left of [`CRATES`] in cargo's extracted
/// sources of local registries (`$CARGO_HOME/registry/src/-<hash>/<name>-<version>`).
/// cargo names that directory by the temporary registry's path, not by the `.crate`'s
/// checksum, and does not extract again when it exists: a clone at the same path as an
/// earlier one (a CI checkout) would verify the C ABI crate against the earlier run's
/// core. crates.io's sources (`index.crates.io-…`) are not touched.
fn clear_stale_extracts() {
    let home = std::env::var_os("CARGO_HOME")
        .map(std::path::PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| std::path::Path::new(&h).join(".cargo")));
    let Some(src) = home.map(|h| h.join("registry/src")) else {
        return;
    };
    let Ok(registries) = std::fs::read_dir(&src) else {
        return;
    };
    for reg in registries.flatten() {
        // Local registries have no host name: their directory starts with `-`.
        if !reg.file_name().to_string_lossy().starts_with('-') {
            continue;
        }
        for (name, _) in CRATES {
            let Ok(entries) = std::fs::read_dir(reg.path()) else {
                continue;
            };
            for e in entries.flatten() {
                let file = e.file_name();
                let file = file.to_string_lossy();
                let ours = file
                    .strip_prefix(name)
                    .and_then(|rest| rest.strip_prefix('-'))
                    .is_some_and(|v| v.starts_with(|c: char| c.is_ascii_digit()));
                if ours {
                    let _ = std::fs::remove_dir_all(e.path());
                }
            }
        }
    }
}

/// `Err(file)`: the first of [`REQUIRED`] not among the listed files (one per line).
fn missing(list: &str) -> Result<(), &'static str> {
    let files: Vec<&str> = list.lines().map(str::trim).collect();
    match REQUIRED.iter().find(|f| !files.contains(f)) {
        Some(f) => Err(f),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use qemu_harness::firmware::workspace_root;

    /// The `major.minor` of a toolchain channel such as `1.95.0` (`None` for `stable`,
    /// `nightly`, …: a pinned version is required).
    fn channel_version(channel: &str) -> Option<String> {
        let mut parts = channel.split('.');
        let (major, minor) = (parts.next()?, parts.next()?);
        let numeric = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
        (numeric(major) && numeric(minor)).then(|| format!("{major}.{minor}"))
    }

    /// The first ```` ```rust ```` block of a README.
    fn readme_example(readme: &str) -> Option<&str> {
        let start = readme.find("```rust\n")? + "```rust\n".len();
        let len = readme[start..].find("```")?;
        Some(&readme[start..start + len])
    }

    /// An `examples/readme.rs` without its first line (the `//!` line that says what it is).
    fn example_body(example: &str) -> &str {
        example.split_once('\n').map_or("", |(_, rest)| rest)
    }

    /// A file of the repository as text.
    fn read(path: &str) -> String {
        let p = workspace_root().join(path);
        std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("cannot read {}: {e}", p.display()))
    }

    /// A TOML document's string at `table.key`.
    fn toml_str(doc: &str, table: &str, key: &str) -> Option<String> {
        let v: toml::Table = toml::from_str(doc).ok()?;
        let mut t = &v;
        for part in table.split('.') {
            t = t.get(part)?.as_table()?;
        }
        Some(t.get(key)?.as_str()?.to_owned())
    }

    /// The workspace's `rust-version` (the MSRV every crate inherits) is the toolchain
    /// rust-toolchain.toml pins: the one the project is built and tested with, and the
    /// only one on the machines. Raising the pin without the MSRV (or the reverse) fails.
    #[test]
    fn rust_version_is_the_pinned_toolchain() {
        let pinned = toml_str(&read("rust-toolchain.toml"), "toolchain", "channel")
            .expect("rust-toolchain.toml has toolchain.channel");
        let msrv = toml_str(&read("Cargo.toml"), "workspace.package", "rust-version")
            .expect("Cargo.toml has workspace.package.rust-version");
        assert_eq!(channel_version(&pinned).as_deref(), Some(msrv.as_str()));
        for (_, dir) in CRATES {
            let manifest = read(&format!("{dir}/Cargo.toml"));
            assert!(
                manifest.contains("rust-version.workspace = true"),
                "{dir}/Cargo.toml must inherit the workspace's rust-version"
            );
        }
    }

    /// Negative controls of the version check: another pin does not match, and an
    /// unpinned channel gives no version.
    #[test]
    fn channel_version_refuses_other_and_unpinned_channels() {
        assert_eq!(channel_version("1.95.0").as_deref(), Some("1.95"));
        assert_ne!(channel_version("1.96.0").as_deref(), Some("1.95"));
        assert_eq!(channel_version("stable"), None);
        assert_eq!(channel_version("nightly-2026-01-01"), None);
    }

    /// Each published crate's README shows its `examples/readme.rs` (compiled by
    /// `cargo test` and clippy), character for character; the license files are in its
    /// directory (links to the root's).
    #[test]
    fn readmes_show_the_compiled_examples() {
        for (_, dir) in CRATES {
            let readme = read(&format!("{dir}/README.md"));
            let example = read(&format!("{dir}/examples/readme.rs"));
            assert_eq!(
                readme_example(&readme),
                Some(example_body(&example)),
                "{dir}/README.md's example differs from {dir}/examples/readme.rs"
            );
            for f in ["LICENSE-MIT", "LICENSE-APACHE"] {
                assert_eq!(read(&format!("{dir}/{f}")), read(f), "{dir}/{f}");
            }
        }
    }

    /// Negative controls: an edited README example differs; a listing without a license
    /// file is refused, naming it.
    #[test]
    fn an_edited_example_or_a_missing_license_is_caught() {
        let example = read("controller-core/examples/readme.rs");
        let readme = read("controller-core/README.md").replacen("dt: 0.01", "dt: 0.02", 1);
        assert_ne!(readme_example(&readme), Some(example_body(&example)));
        assert_eq!(
            missing("Cargo.toml\nLICENSE-MIT\nREADME.md\n"),
            Err("LICENSE-APACHE")
        );
        assert_eq!(
            missing("Cargo.toml\nLICENSE-MIT\nLICENSE-APACHE\nREADME.md\n"),
            Ok(())
        );
    }
}
