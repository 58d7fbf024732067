//! Build script: provide `memory.x` to cortex-m-rt's `link.x` and pass the
//! linker scripts.
//!
//! The link arguments are only emitted for bare-metal targets and only for
//! this crate's binaries (`cargo:rustc-link-arg-bins`), so neither the host
//! crates nor `controller-core` built for the thumb target are affected.

use std::{env, fs, path::PathBuf};

fn main() {
    let manifest_dir =
        PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR"));
    let memory_x = manifest_dir.join("..").join("memory.x");
    println!("cargo:rerun-if-changed={}", memory_x.display());
    println!("cargo:rerun-if-changed=build.rs");

    // On the host the binaries are stubs; nothing to link specially.
    if env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }

    let out_dir = PathBuf::from(env::var_os("OUT_DIR").expect("OUT_DIR"));
    fs::copy(&memory_x, out_dir.join("memory.x"))
        .unwrap_or_else(|e| panic!("copying {} to OUT_DIR: {e}", memory_x.display()));
    println!("cargo:rustc-link-search={}", out_dir.display());

    // `--nmagic`: no page alignment of sections (saves flash, avoids
    // overlapping-segment issues with some linkers).
    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
