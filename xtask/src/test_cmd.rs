//! `cargo xtask test`: every check of the project, in order, stopping at the first
//! failure; then the duration of each phase (informational, never asserted).
//!
//! `scripts/test.sh` installs what this needs (rustup target and components,
//! `scripts/firmware-deps.sh`) and then runs it. Each QEMU run happens once: the firmware
//! checks run `firmware-example`, `measure` and the self-tests themselves and the demo
//! and UART sessions through the QEMU tests of the `tests` crate; the host-in-the-loop
//! runs are host-sim's QEMU tests.

use crate::firmware_check;
use crate::tools::{self, cargo};
use qemu_harness::firmware::TARGET;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// Environment variable: Unix time (s) when `scripts/test.sh` started.
pub const STARTED_ENV: &str = "XTASK_TEST_STARTED";
/// Environment variable: Unix time (s) when `scripts/test.sh` finished installing.
pub const INSTALLED_ENV: &str = "XTASK_TEST_INSTALLED";

/// Runs the phases; `Ok(())` if every one passed.
pub fn run(fw: &firmware_check::Options) -> Result<(), String> {
    let mut durations: Vec<(String, Duration)> = Vec::new();
    // What happened before this process: scripts/test.sh's installation and the build of
    // this xtask (both measured from the timestamps scripts/test.sh exports).
    let now = unix_now();
    let started = env_time(STARTED_ENV);
    let installed = env_time(INSTALLED_ENV);
    if let (Some(s), Some(i)) = (started, installed) {
        durations.push(("install (scripts/test.sh)".into(), secs(i - s)));
    }
    if let Some(i) = installed {
        durations.push(("build xtask".into(), secs(now - i)));
    }

    let result = phases(fw, &mut durations);

    println!();
    println!("== durations (wall clock; informational)");
    let mut total = Duration::ZERO;
    for (name, d) in &durations {
        total += *d;
        println!("   {name:<42} {:>7.1} s", d.as_secs_f64());
    }
    println!("   {:<42} {:>7.1} s", "total", total.as_secs_f64());
    match &result {
        Ok(()) => println!("xtask test: all checks passed"),
        Err(e) => eprintln!("xtask test: FAILED: {e}"),
    }
    result
}

fn phases(
    fw: &firmware_check::Options,
    durations: &mut Vec<(String, Duration)>,
) -> Result<(), String> {
    let mut phase = |name: &str, f: &mut dyn FnMut() -> Result<(), String>| {
        println!("\n==> {name}");
        let t = Instant::now();
        let r = f();
        durations.push((name.to_owned(), t.elapsed()));
        r.map_err(|e| format!("{name}: {e}"))
    };
    let thumb = ["--target", TARGET];
    let deny = ["--", "-D", "warnings"];

    phase("format", &mut || {
        tools::run(cargo().args(["fmt", "--all", "--check"]))
    })?;
    phase("clippy (host)", &mut || {
        tools::run(
            cargo()
                .args(["clippy", "--workspace", "--all-targets"])
                .args(deny),
        )
    })?;
    phase("rustdoc (host, warnings denied)", &mut || {
        tools::run(
            cargo()
                .args(["doc", "--workspace", "--no-deps"])
                .env("RUSTDOCFLAGS", "-D warnings"),
        )
    })?;
    phase("clippy and builds (thumbv7em-none-eabihf)", &mut || {
        let core = ["-p", "ph-formation-core"];
        tools::run(cargo().arg("clippy").args(core).args(thumb).args(deny))?;
        // The other no_std crate: the vehicle models (in the C API's QEMU tests).
        let vehicle = ["-p", "ph-formation-vehicle"];
        tools::run(cargo().arg("clippy").args(vehicle).args(thumb).args(deny))?;
        tools::run(
            cargo()
                .arg("clippy")
                .args(core)
                .args(thumb)
                .args(["--features", "defmt"])
                .args(deny),
        )?;
        tools::run(cargo().arg("build").args(core).args(thumb).arg("--release"))?;
        tools::run(cargo().arg("build").args(core).args(thumb).args([
            "--release",
            "--features",
            "defmt",
        ]))?;
        tools::run(
            cargo()
                .args(["clippy", "-p", "firmware-example"])
                .args(thumb)
                .args(["--release", "--all-targets"])
                .args(deny),
        )
    })?;
    phase("host tests (cargo test)", &mut || {
        tools::run(cargo().arg("test"))
    })?;
    phase(
        "cargo package (core, vehicle, C ABI; built from the .crate files)",
        &mut crate::package::run,
    )?;
    phase(
        "firmware-check (QEMU)",
        &mut || match firmware_check::run(fw)? {
            true => Ok(()),
            false => Err("regressions (listed above)".into()),
        },
    )?;
    phase(
        "C ABI on target (controller-ffi: C firmware under QEMU, Crazyflie app)",
        &mut || {
            // The tests that need arm-none-eabi-gcc and QEMU (ignored by plain `cargo test`):
            // the C firmware converges, links no panic path, and prints its figures (text of
            // the staticlib's code, RAM per agent, instructions per tick through the C API);
            // the Crazyflie app compiles against the header stub. The staticlibs are
            // release builds (`controller-ffi/c/build.sh`); the test binaries themselves
            // are the ones `cargo test` built (no `-p`, no `--release`: nothing rebuilt).
            tools::run(
                cargo()
                    .arg("test")
                    .args(["--test", "c_firmware", "--test", "crazyflie_app"])
                    .args([
                        "--",
                        "--include-ignored",
                        "--nocapture",
                        "--test-threads",
                        "1",
                    ]),
            )
        },
    )?;
    phase("slow tests (host-sim, ignored by cargo test)", &mut || {
        // The 100,000-point design and load, the 3,000-agent runs, the 100 s paper run
        // pinned to wire v3 (`#[ignore = "slow lane…"]`), out of the fast `cargo test`.
        tools::run(
            cargo()
                .args(["test", "--test", "design", "--test", "design_cli"])
                .args([
                    "--test",
                    "diagnostics",
                    "--test",
                    "monitor",
                    "--test",
                    "wire_v3",
                ])
                .args(["--", "--ignored"]),
        )
    })?;
    phase("bench-counts (host-sim under callgrind)", &mut || {
        // The dev profile, but `-p ph-formation-sim`'s own feature set (the binary the budgets
        // were measured on): host-sim and the crates whose features differ from the
        // workspace's (postcard, controller-core, …) compile again (docs/performance.md).
        let o = crate::bench_counts::Options {
            profile: "dev".into(),
            budgets: crate::bench_counts::default_budgets(),
            no_check: false,
            all: false,
        };
        match crate::bench_counts::run(&o)? {
            true => Ok(()),
            false => Err("regressions (listed above)".into()),
        }
    })?;
    phase(
        "Slurm job array (cargo xtask cluster-test)",
        &mut crate::cluster::run,
    )?;
    phase("replay.html in headless Chromium (host-sim)", &mut || {
        // The ignored browser test of tests/replay.rs (Chromium from scripts/browser-deps.sh).
        tools::run(cargo().args(["test", "--test", "replay", "--", "--ignored"]))
    })?;
    phase("cflib flies host-sim serve (end to end)", &mut || {
        // Bitcraze's cflib (scripts/python-deps.sh) against `host-sim serve
        // crazyflie-app/formation.toml --set world=crazyflie` (docs/crazyflie.md), the
        // ignored test of host-sim/tests/serve.rs; the binary `cargo test` built.
        tools::run(cargo().args(["test", "--test", "serve", "--", "--ignored", "--nocapture"]))
    })?;
    phase(
        "run.mcap read back by the PyPI mcap reader (host-sim)",
        &mut || {
            // The ignored test of tests/mcap.rs (the venv of scripts/python-deps.sh).
            tools::run(cargo().args(["test", "--test", "mcap", "--", "--ignored"]))
        },
    )?;
    phase("host-in-the-loop (host-sim QEMU tests)", &mut || {
        // No `-p ph-formation-sim`: the default members' feature set, as `cargo test` built it.
        tools::run(cargo().args(["test", "--test", "hil", "--", "--include-ignored"]))
    })?;
    Ok(())
}

fn unix_now() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}

fn env_time(name: &str) -> Option<f64> {
    std::env::var(name).ok()?.trim().parse().ok()
}

fn secs(s: f64) -> Duration {
    Duration::try_from_secs_f64(s).unwrap_or(Duration::ZERO)
}
