//! The C firmware (`c/firmware/*.c` + `c/demo/*.c`, linked by `c/build.sh firmware`
//! with arm-none-eabi-gcc against the thumbv7em-none-eabihf staticlib) on QEMU's
//! netduinoplus2 (an STM32F405): the paper's four agents through the C API.
//!
//! * `c_firmware_converges_on_qemu`: exits 0 through semihosting (converged by the
//!   demo's criteria, see `c_host.rs`) and ends on the square 1-2-4-3 within
//!   [`common::TOLERANCE`].
//! * `c_firmware_links_no_panic_path`: the linked ELF contains neither the panic
//!   handler (`rust_begin_unwind`) nor `ph_panic_hook` (the firmware defines it; the
//!   linker drops it when nothing calls it), nor any soft-float `f64` routine: nothing
//!   the C API reaches can panic.
//! * `c_firmware_figures`: text size by origin (from the linker map), RAM, stack, and
//!   instructions per whole tick through the C API (QEMU with `tools/qemu-insn`), with
//!   the functions robot 3's tick spends them in; printed for docs/c-api.md (run with
//!   `--nocapture`).
//!
//! Ignored by default: they need `arm-none-eabi-gcc` (scripts/firmware-deps.sh) and
//! `qemu-system-arm`. Run them with
//! `cargo test -p ph-formation-ffi --test c_firmware -- --include-ignored`.
//! Environment: `QEMU_TIMEOUT` (seconds, default 120), `QEMU_SYSTEM_ARM`,
//! `ARM_NM` (default arm-none-eabi-nm).

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use common::{build, max_difference, parse_demo_final, root, scratch, SQUARE, TOLERANCE};

fn firmware() -> &'static Path {
    static ELF: OnceLock<PathBuf> = OnceLock::new();
    ELF.get_or_init(|| build("firmware", &scratch("c-firmware")))
}

/// Runs the firmware under QEMU (always inside `timeout`): `(exit code, output)`.
/// The firmware writes through semihosting (QEMU's stderr).
fn run_qemu(elf: &Path, extra: &[String]) -> (Option<i32>, String) {
    let limit = std::env::var("QEMU_TIMEOUT").unwrap_or_else(|_| "120".into());
    let qemu = std::env::var("QEMU_SYSTEM_ARM").unwrap_or_else(|_| "qemu-system-arm".into());
    let out = Command::new("timeout")
        .args(["-k", "5", &limit, &qemu])
        .args([
            "-machine",
            "netduinoplus2",
            "-display",
            "none",
            "-monitor",
            "none",
        ])
        .args([
            "-serial",
            "null",
            "-semihosting-config",
            "enable=on,target=native",
        ])
        .arg("-kernel")
        .arg(elf)
        .args(extra)
        .stdin(std::process::Stdio::null())
        .output()
        .expect("run timeout + qemu-system-arm (scripts/firmware-deps.sh installs QEMU)");
    let mut log = String::from_utf8_lossy(&out.stdout).into_owned();
    log.push_str(&String::from_utf8_lossy(&out.stderr));
    (out.status.code(), log)
}

fn demo_run() -> &'static (Option<i32>, String) {
    static RUN: OnceLock<(Option<i32>, String)> = OnceLock::new();
    RUN.get_or_init(|| run_qemu(firmware(), &[]))
}

fn nm(elf: &Path) -> String {
    nm_with(elf, &[])
}

fn nm_with(elf: &Path, args: &[&str]) -> String {
    let tool = std::env::var("ARM_NM").unwrap_or_else(|_| "arm-none-eabi-nm".into());
    let out = Command::new(&tool)
        .args(args)
        .arg(elf)
        .output()
        .unwrap_or_else(|e| panic!("run {tool}: {e}"));
    assert!(out.status.success(), "{tool} failed");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
#[ignore = "needs arm-none-eabi-gcc and qemu-system-arm (scripts/firmware-deps.sh)"]
fn c_firmware_converges_on_qemu() {
    let (code, log) = demo_run();
    assert_eq!(*code, Some(0), "the C firmware did not exit 0:\n{log}");
    assert!(log.contains("DEMO result converged=true"), "{log}");
    let (t, rel) = parse_demo_final(log).unwrap_or_else(|e| panic!("{e}\n{log}"));
    let d = max_difference(&rel, &SQUARE).unwrap_or_else(|e| panic!("{e}\n{log}"));
    println!("C firmware on QEMU: converged at t = {t} s, q_i - q_1 = {rel:?}, {d:.2e} m from the square");
    assert!(
        d <= TOLERANCE,
        "final shape {rel:?} is {d} m from {SQUARE:?}"
    );
}

#[test]
#[ignore = "needs arm-none-eabi-gcc (scripts/firmware-deps.sh)"]
fn c_firmware_links_no_panic_path() {
    let symbols = nm(firmware());
    let names: Vec<&str> = symbols
        .lines()
        .filter_map(|l| l.split_whitespace().last())
        .collect();
    let panics: Vec<&&str> = names
        .iter()
        .filter(|n| {
            n.contains("rust_begin_unwind")
                || n.contains("panicking")
                || n.contains("panic_fmt")
                || **n == "ph_panic_hook"
        })
        .collect();
    assert!(panics.is_empty(), "panic machinery linked: {panics:?}");
    assert!(
        names.contains(&"ph_step") && names.contains(&"ph_agent_init"),
        "the C API is not in the ELF?"
    );
    let soft_f64: Vec<&&str> = names
        .iter()
        .filter(|n| n.starts_with("__aeabi_d") || n.ends_with("df3") || n.contains("extendsfdf"))
        .collect();
    assert!(
        soft_f64.is_empty(),
        "soft-float f64 routines linked: {soft_f64:?}"
    );
}

/// Bytes of code and read-only data per origin, from the GNU ld map: every input
/// section placed in the output sections `.isr_vector`, `.text` and `.ARM.exidx`.
fn text_by_origin(map: &str) -> BTreeMap<&'static str, u64> {
    let mut sizes = BTreeMap::new();
    let mut in_text = false;
    let mut pending = false;
    for line in map.lines() {
        if !line.starts_with(' ') && line.starts_with('.') {
            let name = line.split_whitespace().next().unwrap_or("");
            in_text = matches!(name, ".isr_vector" | ".text" | ".ARM.exidx");
            pending = false;
            continue;
        }
        if !in_text {
            continue;
        }
        let fields: Vec<&str> = line.split_whitespace().collect();
        // ` .text.foo  0xADDR  0xSIZE  file` or ` .text.foo` then `  0xADDR 0xSIZE file`.
        let rest = match fields.as_slice() {
            [sec, rest @ ..] if line.starts_with(" .") && sec.starts_with('.') => {
                pending = rest.is_empty();
                rest
            }
            rest if pending && line.starts_with("   ") => {
                pending = false;
                rest
            }
            _ => continue,
        };
        let [addr, size, file, ..] = rest else {
            continue;
        };
        if !addr.starts_with("0x") {
            continue;
        }
        let Ok(size) = u64::from_str_radix(size.trim_start_matches("0x"), 16) else {
            continue;
        };
        let origin = if file.contains("libph_formation_ffi.a(compiler_builtins") {
            "Rust compiler_builtins (memcpy, memset, ...)"
        } else if file.contains("libph_formation_ffi.a") {
            "controller (Rust: controller-ffi, controller-core, deps)"
        } else if file.contains("libgcc") {
            "libgcc"
        } else {
            "C: demo, plant, start-up"
        };
        *sizes.entry(origin).or_default() += size;
    }
    sizes
}

#[test]
#[ignore = "needs arm-none-eabi-gcc, qemu-system-arm and gcc for the plugin (scripts/firmware-deps.sh)"]
fn c_firmware_figures() {
    let elf = firmware();
    // Sizes.
    let map = std::fs::read_to_string(elf.with_file_name("c-firmware.map")).expect("linker map");
    let by_origin = text_by_origin(&map);
    let total: u64 = by_origin.values().sum();
    println!(
        "text (code + rodata + vectors) of {}: {total} bytes",
        elf.display()
    );
    for (origin, bytes) in &by_origin {
        println!("  {bytes:>7}  {origin}");
    }
    assert!(
        by_origin
            .get("controller (Rust: controller-ffi, controller-core, deps)")
            .is_some_and(|&b| b > 10_000),
        "the controller's code was not found in the map: {by_origin:?}"
    );

    // Instructions per whole tick through the C API.
    let plugin = Command::new("bash")
        .arg(root().join("tools/qemu-insn/build.sh"))
        .output()
        .expect("build the qemu-insn plugin");
    assert!(
        plugin.status.success(),
        "{}",
        String::from_utf8_lossy(&plugin.stderr)
    );
    let plugin = String::from_utf8_lossy(&plugin.stdout).trim().to_string();
    let marker = nm(elf)
        .lines()
        .find_map(|l| match l.split_whitespace().collect::<Vec<_>>()[..] {
            [addr, _, "PH_INSN_MARKERS"] => Some(format!("0x{addr}")),
            _ => None,
        })
        .expect("symbol PH_INSN_MARKERS");
    let counts = elf.with_file_name("insn.txt");
    let _ = std::fs::remove_file(&counts);
    let (code, log) = run_qemu(
        elf,
        &[
            "-plugin".into(),
            format!(
                "{plugin},marker={marker},regions=32,out={}",
                counts.display()
            ),
        ],
    );
    assert_eq!(code, Some(0), "{log}");
    let counts = std::fs::read_to_string(&counts).expect("plugin output");
    assert!(counts.contains("errors=0"), "{counts}");
    let region = |id: u32| -> Vec<u64> {
        counts
            .lines()
            .filter(|l| l.contains(&format!("region={id} ")))
            .filter_map(|l| l.rsplit("insns=").next()?.trim().parse().ok())
            .collect()
    };
    let overhead = region(0);
    assert_eq!(overhead.len(), 1, "{counts}");
    println!("instructions per whole tick through the C API (ph_receive of the inbox, ph_step, ph_frames*), tick 3000:");
    println!("  overhead (empty region): {}", overhead[0]);
    for robot in 1..=4 {
        let n = region(robot);
        assert_eq!(
            n.len(),
            1,
            "robot {robot}: one measured tick expected\n{counts}"
        );
        assert!(n[0] > 1000, "robot {robot}: {} instructions?", n[0]);
        let line = log
            .lines()
            .find(|l| l.starts_with(&format!("CABI region id={robot} ")))
            .unwrap_or("");
        println!("  robot {robot}: {:>5}   ({line})", n[0]);
    }
    for line in log
        .lines()
        .filter(|l| l.starts_with("CABI stack") || l.starts_with("CABI agent"))
    {
        println!("  {line}");
    }

    // Where robot 3's tick goes: the plugin's per-address profile of region 3, by
    // function (symbol sizes from nm).
    let profile = elf.with_file_name("profile.txt");
    let _ = std::fs::remove_file(&profile);
    let (code, log) = run_qemu(
        elf,
        &[
            "-plugin".into(),
            format!(
                "{plugin},marker={marker},regions=32,out={},profile=3",
                profile.display()
            ),
        ],
    );
    assert_eq!(code, Some(0), "{log}");
    let mut symbols: Vec<(u64, u64, String)> = nm_with(elf, &["-n", "-S", "--defined-only"])
        .lines()
        .filter_map(|l| match l.split_whitespace().collect::<Vec<_>>()[..] {
            [a, s, _, n] => Some((
                u64::from_str_radix(a, 16).ok()?,
                u64::from_str_radix(s, 16).ok()?,
                n.to_string(),
            )),
            _ => None,
        })
        .collect();
    symbols.sort();
    let mut by_function: BTreeMap<String, u64> = BTreeMap::new();
    for line in std::fs::read_to_string(&profile).expect("profile").lines() {
        let (Some(pc), Some(n)) = (
            line.split("pc=0x")
                .nth(1)
                .and_then(|x| x.split_whitespace().next()),
            line.split("insns=").nth(1),
        ) else {
            continue;
        };
        let (Ok(pc), Ok(n)) = (u64::from_str_radix(pc, 16), n.trim().parse::<u64>()) else {
            continue;
        };
        let name = symbols
            .iter()
            .rev()
            .find(|(a, size, _)| *a <= pc && pc < a + (*size).max(1))
            .map_or("?".to_string(), |(_, _, n)| n.clone());
        *by_function.entry(name).or_default() += n;
    }
    let mut rows: Vec<_> = by_function.into_iter().collect();
    rows.sort_by_key(|r| std::cmp::Reverse(r.1));
    println!("robot 3's tick by function (instructions):");
    for (name, n) in &rows {
        println!("  {n:>5}  {name}");
    }
    assert_eq!(
        rows.iter().map(|r| r.1).sum::<u64>(),
        region(3)[0],
        "profile total"
    );
}
