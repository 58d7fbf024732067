//! `include/ph_formation.h` is what cbindgen generates from the sources now.
//!
//! Regenerate it with `PH_BLESS=1 cargo test -p ph-formation-ffi --test header`.

use std::path::Path;

fn generate() -> String {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let bindings = cbindgen::Builder::new()
        .with_crate(dir)
        .with_config(config)
        .generate()
        .expect("cbindgen generates the header");
    let mut out = Vec::new();
    bindings.write(&mut out);
    String::from_utf8(out).expect("UTF-8 header")
}

#[test]
fn header_is_up_to_date() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("include/ph_formation.h");
    let fresh = generate();
    if std::env::var_os("PH_BLESS").is_some() {
        std::fs::write(&path, &fresh).expect("write the header");
        return;
    }
    let checked_in = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        checked_in == fresh,
        "{} is out of date: regenerate it with `PH_BLESS=1 cargo test -p ph-formation-ffi --test header` and commit it",
        path.display()
    );
}

#[test]
fn header_lists_every_status_code() {
    let header = generate();
    let in_header = header
        .lines()
        .filter(|l| {
            let l = l.trim_start();
            (l.starts_with("PH_OK =") || l.starts_with("PH_ERR_")) && l.contains(" = ")
        })
        .count();
    assert_eq!(
        in_header,
        ph_formation_ffi::status::ALL.len(),
        "status::ALL must list every ph_status"
    );
    for s in ph_formation_ffi::status::ALL {
        assert_eq!(ph_formation_ffi::ph_status::from_code(s as i32), Some(s));
    }
}

/// The header is plain C99 (`-pedantic`, warnings as errors) for the host compiler.
#[test]
fn header_compiles_as_pedantic_c99() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("header-c99");
    std::fs::create_dir_all(&dir).expect("scratch directory");
    let src = dir.join("use_header.c");
    std::fs::write(
        &src,
        "#include \"ph_formation.h\"\n\
         int main(void) { ph_config c; return ph_config_default(&c, 1) == PH_OK ? 0 : 1; }\n",
    )
    .expect("write the C file");
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let out = std::process::Command::new(&cc)
        .args([
            "-std=c99",
            "-pedantic",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-fsyntax-only",
        ])
        .arg(format!(
            "-I{}",
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("include")
                .display()
        ))
        .arg(&src)
        .output()
        .unwrap_or_else(|e| panic!("run {cc}: {e}"));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The flight build carries no vehicle model: `sim-vehicle` is off by default, the
/// Crazyflie firmware's build of the library (crazyflie-app/Kbuild) does not turn it on,
/// and the header declares `ph_vehicle_*` only under `PH_SIM_VEHICLE`.
#[test]
fn flight_build_has_no_vehicle_model() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let manifest = std::fs::read_to_string(dir.join("Cargo.toml")).expect("Cargo.toml");
    assert!(
        manifest.contains("\ndefault = []\n"),
        "ph-formation-ffi's default features must stay empty"
    );
    let kbuild = std::fs::read_to_string(dir.join("../crazyflie-app/Kbuild")).expect("Kbuild");
    let build = kbuild
        .lines()
        .find(|l| l.contains("cargo rustc -p ph-formation-ffi"))
        .expect("crazyflie-app/Kbuild builds the library with cargo rustc");
    assert!(
        !kbuild.contains("sim-vehicle") && !build.contains("--features"),
        "{build}"
    );
    let header = generate();
    let mut guarded = false;
    for line in header.lines() {
        if line.starts_with("#if defined(PH_SIM_VEHICLE)") {
            guarded = true;
        } else if line.starts_with("#endif") {
            guarded = false;
        } else if line.contains("ph_vehicle") && line.starts_with("ph_status ") {
            assert!(
                guarded,
                "{line} is declared outside #if defined(PH_SIM_VEHICLE)"
            );
        }
    }
    assert!(
        header.contains("ph_status ph_vehicle_step("),
        "the test sees the declarations"
    );
}
