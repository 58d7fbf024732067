//! `crazyflie-app/src/*.c` compile against the C API and the header-only stub of the
//! Crazyflie firmware (`crazyflie-app/stub/`), warnings as errors: with the host C
//! compiler (`-fsyntax-only`, always) and for the Crazyflie's Cortex-M4F with
//! `arm-none-eabi-gcc -c` (ignored by default: needs scripts/firmware-deps.sh). The app
//! cannot be built or linked against the real firmware here (crazyflie-app/README.md).

mod common;

use std::path::PathBuf;
use std::process::Command;

fn sources() -> Vec<PathBuf> {
    let dir = common::root().join("crazyflie-app/src");
    vec![dir.join("app.c"), dir.join("formation.c")]
}

fn compile(compiler: &str, extra: &[&str]) {
    let root = common::root();
    let out = common::scratch(&format!("crazyflie-app-{compiler}"));
    for src in sources() {
        let obj = out.join(src.with_extension("o").file_name().expect("file name"));
        let run = Command::new(compiler)
            .args(["-std=gnu11", "-Wall", "-Wextra", "-Werror", "-Wshadow"])
            .args(["-Wstrict-prototypes", "-Wmissing-prototypes"])
            .arg(format!("-I{}", root.join("crazyflie-app/stub").display()))
            .arg(format!("-I{}", root.join("crazyflie-app/src").display()))
            .arg(format!(
                "-I{}",
                root.join("controller-ffi/include").display()
            ))
            .args(extra)
            .arg("-o")
            .arg(&obj)
            .arg(&src)
            .output()
            .unwrap_or_else(|e| panic!("run {compiler}: {e}"));
        assert!(
            run.status.success(),
            "{compiler} {}:\n{}",
            src.display(),
            String::from_utf8_lossy(&run.stderr)
        );
    }
}

#[test]
fn app_compiles_with_the_host_compiler() {
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    compile(&cc, &["-fsyntax-only"]);
}

#[test]
#[ignore = "needs arm-none-eabi-gcc (scripts/firmware-deps.sh)"]
fn app_compiles_for_the_crazyflie_mcu() {
    compile(
        "arm-none-eabi-gcc",
        &[
            "-c",
            "-O2",
            "-ffreestanding",
            "-mcpu=cortex-m4",
            "-mthumb",
            "-mfpu=fpv4-sp-d16",
            "-mfloat-abi=hard",
        ],
    );
}
