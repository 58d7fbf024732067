//! `cargo xtask firmware-check`: builds the release firmware and checks its on-target
//! resource use against `firmware-example/budgets.toml`. Deterministic: nothing depends
//! on wall-clock time. Prints one table per measurement and fails on any regression.
//!
//! * (a) sizes (text/data/bss) of the release ELFs: `llvm-size`;
//! * (b) instructions per control step, per configuration: QEMU + the `tools/qemu-insn`
//!   plugin on the `measure` binary (decode+receive, `Agent::step`, encode, whole step);
//! * (c) peak stack and static RAM + stack: painted stack, reported by each firmware;
//! * (d) no soft-float f64 routine linked (`__aeabi_d*`, …): `llvm-nm`;
//!
//! and: `firmware-example` and `measure` exit 0, the panic and HardFault self-tests exit
//! 1, and the QEMU tests of the `tests` crate pass: `qemu_demo` (the demo converges to the
//! square and matches host-sim) and `qemu_uart` (the host-in-the-loop session). Those two
//! are where `qemu-demo` and `qemu-uart` run (once each); they write their decoded logs
//! for the stack figures.

mod tables;

use crate::budgets::Budgets;
use crate::check::Checker;
use crate::fwlog;
use crate::tools::{self, Llvm};
use qemu_harness::firmware::{self, PACKAGE, SELF_TESTS, TARGET};
use qemu_harness::qemu::{find_program, qemu_program, INSTALL_HINT};
use qemu_harness::{defmt, Exit, Qemu};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Where the inputs and outputs of a check are.
#[derive(Clone, Debug)]
pub struct Options {
    /// The budget file.
    pub budgets: PathBuf,
    /// Logs and plugin output.
    pub out: PathBuf,
    /// Time limit of each QEMU run of the check itself.
    pub timeout: Duration,
}

/// Runs every check; `Ok(true)` if all passed, `Ok(false)` after the verdict listing the
/// failures, `Err` if the check could not run at all (a missing tool, a bad budget file,
/// a failed build).
pub fn run(o: &Options) -> Result<bool, String> {
    let budgets = Budgets::load(&o.budgets)?;
    for program in [qemu_program(), defmt::program()] {
        if find_program(&program).is_none() {
            return Err(format!("'{program}' not found; {INSTALL_HINT}"));
        }
    }
    let llvm = Llvm::find()?;
    prepare(&o.out)?;
    let mut c = Checker::new(o.budgets.display().to_string());

    println!("== build (release, {TARGET})");
    tools::run(tools::cargo().args([
        "build",
        "-p",
        PACKAGE,
        "--target",
        TARGET,
        "--release",
        "--bins",
    ]))?;
    let plugin = tools::qemu_insn_plugin()?;
    let mut peaks: BTreeMap<&str, u64> = BTreeMap::new();

    println!("== run firmware-example under QEMU");
    let (exit, log) = run_firmware(&mut c, o, "firmware-example", None)?;
    c.expect(exit == Exit::Code(0), || {
        format!(
            "firmware-example: {exit} under QEMU (see {})",
            o.out.join("firmware-example.log").display()
        )
    });
    stack_of(&mut c, &mut peaks, "firmware-example", &log, &o.out);

    qemu_tests(&mut c, &mut peaks, &o.out)?;

    println!("== run measure under QEMU with the instruction-count plugin");
    let measure_elf = firmware::elf("measure");
    let marker = llvm.symbol_address(&measure_elf, "PH_INSN_MARKERS")?;
    let insn_file = o.out.join("measure-insn.txt");
    let out_arg = insn_file.display().to_string();
    let plugin_args = [("marker", marker.as_str()), ("out", out_arg.as_str())];
    let (exit, measure_log) = run_firmware(&mut c, o, "measure", Some((&plugin, &plugin_args)))?;
    let measure_path = o.out.join("measure.log");
    if exit != Exit::Code(0) {
        c.fail(format!(
            "measure: {exit} under QEMU (see {})",
            measure_path.display()
        ));
        for e in fwlog::errors(&measure_log) {
            c.fail(format!("measure: {e}"));
        }
    } else if fwlog::last_with(&measure_log, "FWCHECK done").is_none() {
        c.fail(format!(
            "measure did not print 'FWCHECK done' (see {})",
            measure_path.display()
        ));
    } else {
        c.pass();
    }
    stack_of(&mut c, &mut peaks, "measure", &measure_log, &o.out);

    println!("== handler self-tests (must exit with code 1)");
    for name in SELF_TESTS {
        let (exit, _) = run_firmware(&mut c, o, name, None)?;
        if exit == Exit::Code(1) {
            c.pass();
            println!("   {name}: exit code 1 (ok)");
        } else {
            c.fail(format!(
                "{name}: expected exit code 1 from the handler, got {exit} (see {})",
                o.out.join(format!("{name}.log")).display()
            ));
        }
    }

    let sizes = tables::sizes(&mut c, &budgets, &llvm);
    tables::instructions(&mut c, &budgets, &measure_log, &insn_file);
    tables::stack(&mut c, &budgets, &sizes, &peaks);
    tables::no_f64(&mut c, &llvm);

    println!();
    println!("logs: {}", o.out.display());
    if !c.failures.is_empty() {
        eprintln!("firmware-check: FAILED ({}):", c.failures.len());
        for f in &c.failures {
            eprintln!("  - {f}");
        }
    }
    println!(
        "firmware-check: {} passed, {} failed",
        c.passed,
        c.failures.len()
    );
    Ok(c.failures.is_empty())
}

/// Creates the output directory and removes the logs of a previous run.
fn prepare(out: &Path) -> Result<(), String> {
    std::fs::create_dir_all(out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
    let entries =
        std::fs::read_dir(out).map_err(|e| format!("cannot read {}: {e}", out.display()))?;
    for entry in entries.flatten() {
        let p = entry.path();
        if matches!(
            p.extension().and_then(|e| e.to_str()),
            Some("log" | "txt" | "raw")
        ) {
            let _ = std::fs::remove_file(&p);
        }
    }
    Ok(())
}

/// Runs release firmware `name` under QEMU (with the plugin if given); writes its decoded
/// log to `<out>/<name>.log` and returns the exit and the log.
fn run_firmware(
    c: &mut Checker,
    o: &Options,
    name: &str,
    plugin: Option<(&Path, &[(&str, &str)])>,
) -> Result<(Exit, String), String> {
    let elf = firmware::elf(name);
    let mut q = Qemu::new(&elf, o.out.join(name));
    if let Some((so, args)) = plugin {
        q = q.plugin(so, args);
    }
    let exit = q
        .run(o.timeout)
        .map_err(|e| format!("{name}: {e} ({})", q.display()))?;
    let log = match defmt::decode(&elf, q.stdout_path()) {
        Ok(log) => log,
        Err(e) => {
            c.fail(format!("{name}: {e}"));
            String::new()
        }
    };
    let mut text = log.clone();
    if exit != Exit::Code(0) {
        text.push_str(&format!("qemu: {exit}\n"));
        let stderr = std::fs::read_to_string(q.stderr_path()).unwrap_or_default();
        text.push_str(&stderr);
    }
    let path = o.out.join(format!("{name}.log"));
    std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    Ok((exit, log))
}

/// Records the peak stack of `name` from its log, or fails.
fn stack_of<'a>(
    c: &mut Checker,
    peaks: &mut BTreeMap<&'a str, u64>,
    name: &'a str,
    log: &str,
    out: &Path,
) {
    match fwlog::stack_peak(log) {
        Some(p) => {
            peaks.insert(name, p);
        }
        None => c.fail(format!(
            "{name}: no 'FWCHECK stack' line in its output (see {})",
            out.join(format!("{name}.log")).display()
        )),
    }
}

/// The QEMU tests of the `tests` crate: the one run of `qemu-demo` and of `qemu-uart`.
fn qemu_tests(c: &mut Checker, peaks: &mut BTreeMap<&str, u64>, out: &Path) -> Result<(), String> {
    println!("== QEMU tests: qemu-demo converges and matches host-sim (tests/tests/qemu_demo.rs),");
    println!("   qemu-uart host-in-the-loop session (tests/tests/qemu_uart.rs)");
    let demo_log = out.join("qemu-demo.log");
    let uart_log = out.join("qemu-uart.log");
    let test_log = out.join("qemu-tests.log");
    let summary = host_sim_paper(out)?;
    // No `-p`: the default members' feature set, so the test binaries and their
    // dependencies are the ones `cargo test` already built.
    let ok = tools::run_logged(
        tools::cargo()
            .args(["test", "--test", "qemu_demo", "--test", "qemu_uart"])
            .args(["--", "--include-ignored", "--nocapture"])
            .env("PH_QEMU_DEMO_LOG", &demo_log)
            .env("PH_QEMU_UART_LOG", &uart_log)
            .env("PH_HOST_SIM_SUMMARY", &summary),
        &test_log,
    )?;
    let output = std::fs::read_to_string(&test_log).unwrap_or_default();
    if ok {
        c.pass();
    } else {
        let failed: Vec<&str> = output
            .lines()
            .filter_map(|l| l.strip_prefix("test ")?.strip_suffix(" ... FAILED"))
            .collect();
        c.fail(format!(
            "the QEMU tests failed{} (see {})",
            if failed.is_empty() {
                String::new()
            } else {
                format!(": {}", failed.join(", "))
            },
            test_log.display()
        ));
    }
    let demo = std::fs::read_to_string(&demo_log).unwrap_or_default();
    for tag in ["DEMO final", "DEMO result"] {
        println!(
            "   {}",
            fwlog::last_with(&demo, tag).unwrap_or_else(|| format!("no '{tag}' line"))
        );
    }
    for tag in ["qemu-demo (f32) vs host-sim", "lock-step ticks in"] {
        if let Some(l) = output.lines().rev().find(|l| l.contains(tag)) {
            println!("   {}", l.trim());
        }
    }
    stack_of(c, peaks, "qemu-demo", &demo, out);
    let uart = std::fs::read_to_string(&uart_log).unwrap_or_default();
    stack_of(c, peaks, "qemu-uart", &uart, out);
    Ok(())
}

/// The host simulator's `paper` run that `demo_matches_host_sim` compares the demo with
/// (its `summary.json`, passed as `PH_HOST_SIM_SUMMARY`): run by the dev binary `cargo
/// test` built ([`tools::host_sim_dev`]) rather than by the test's own `cargo run
/// --release -p ph-formation-sim`, a release build (fat LTO) of the simulator and its
/// dependencies for a run of about a second. The same code and the same `f64` results.
fn host_sim_paper(out: &Path) -> Result<PathBuf, String> {
    let ph_formation_sim = tools::host_sim_dev()?;
    let dir = out.join("host-sim-paper");
    let _ = std::fs::remove_dir_all(&dir);
    tools::run(
        std::process::Command::new(ph_formation_sim)
            .args(["run", "paper", "--quiet", "--no-plots", "--out"])
            .arg(&dir),
    )?;
    Ok(dir.join("summary.json"))
}
