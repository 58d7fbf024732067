//! `cargo xtask qemu-run <elf> [qemu args…]`: the cargo runner for
//! `thumbv7em-none-eabihf` (`.cargo/config.toml`). Runs the ELF on QEMU's netduinoplus2
//! (through `qemu_harness`, like every other QEMU run) and decodes its defmt output live
//! with `defmt-print`.
//!
//! Exit code: QEMU's, i.e. the firmware's semihosting exit code (0 = success; the panic
//! and HardFault handlers exit with 1); 124 if the run timed out; if QEMU succeeded but
//! `defmt-print` failed, 1.
//!
//! Environment: `QEMU_TIMEOUT` (seconds, default 60), `QEMU_SYSTEM_ARM`, `DEFMT_PRINT`,
//! `QEMU_RAW_OUT` (also save the raw defmt stream there), `QEMU_SERIAL` (the `-serial`
//! backend of USART1, default `null`; e.g.
//! `tcp:127.0.0.1:4444,server=on,wait=on,nodelay=on` for `qemu-uart`: stdout carries the
//! defmt log, so USART1 is never `stdio`).

use qemu_harness::firmware::target_dir;
use qemu_harness::qemu::{find_program, qemu_program, INSTALL_HINT};
use qemu_harness::{defmt, Qemu, Serial};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::time::Duration;

/// Runs `elf` with the extra QEMU arguments `args`; returns the process exit code.
pub fn run(elf: &Path, args: &[String]) -> ExitCode {
    match run_inner(elf, args) {
        Ok(code) => ExitCode::from(code),
        Err((code, msg)) => {
            eprintln!("qemu-run: {msg}");
            ExitCode::from(code)
        }
    }
}

fn env(name: &str) -> Option<String> {
    std::env::var(name).ok().filter(|v| !v.trim().is_empty())
}

fn run_inner(elf: &Path, args: &[String]) -> Result<u8, (u8, String)> {
    let limit: u64 = match env("QEMU_TIMEOUT") {
        Some(v) => v.trim().parse().map_err(|_| {
            (
                2,
                format!("QEMU_TIMEOUT={v:?}: expected a whole number of seconds"),
            )
        })?,
        None => 60,
    };
    for program in [qemu_program(), defmt::program()] {
        if find_program(&program).is_none() {
            return Err((127, format!("'{program}' not found; {INSTALL_HINT}")));
        }
    }
    if !elf.is_file() {
        return Err((2, format!("no such ELF: {}", elf.display())));
    }
    let name = elf.file_name().map_or_else(
        || PathBuf::from("firmware"),
        |n| PathBuf::from(n.to_os_string()),
    );
    let serial = env("QEMU_SERIAL").map_or(Serial::Null, Serial::Spec);
    let qemu = Qemu::new(elf, target_dir().join("qemu-run").join(name))
        .serial(serial)
        .args(args.iter().cloned())
        .pipe_stdout();
    let mut process = qemu
        .spawn()
        .map_err(|e| (127, format!("{e} ({})", qemu.display())))?;
    let mut guest = process
        .take_stdout()
        .ok_or((1, "no pipe from QEMU".to_owned()))?;
    let mut print = Command::new(defmt::program())
        .arg("-e")
        .arg(elf)
        .stdin(Stdio::piped())
        .spawn()
        .map_err(|e| (127, format!("cannot run {}: {e}", defmt::program())))?;
    let mut to_print = print
        .stdin
        .take()
        .ok_or((1, "no pipe to defmt-print".into()))?;
    let mut raw = match env("QEMU_RAW_OUT") {
        Some(p) => {
            Some(std::fs::File::create(&p).map_err(|e| (2, format!("cannot create {p}: {e}")))?)
        }
        None => None,
    };
    // Copies the guest's output to defmt-print (and the raw file) until QEMU exits; it
    // keeps reading even if defmt-print stops, so the guest never blocks on its stdout.
    let copier = std::thread::spawn(move || {
        let mut buf = [0u8; 4096];
        let mut print_ok = true;
        while let Ok(n) = guest.read(&mut buf) {
            let Some(chunk) = buf.get(..n).filter(|c| !c.is_empty()) else {
                break;
            };
            if let Some(f) = raw.as_mut() {
                let _ = f.write_all(chunk);
            }
            if print_ok {
                print_ok = to_print.write_all(chunk).is_ok();
            }
        }
        // Dropping `to_print` closes defmt-print's stdin: it ends after the last frame.
    });

    let status = process.wait_or_kill(Duration::from_secs(limit));
    let _ = copier.join();
    let print_status = print.wait();
    let Some(status) = status else {
        return Err((
            124,
            format!(
                "QEMU did not exit within {limit}s (killed); the firmware hung or never called exit"
            ),
        ));
    };
    match status.code() {
        Some(0) => {}
        Some(c) => {
            let tail = process.stderr_tail();
            let note = if tail.is_empty() {
                String::new()
            } else {
                format!(" ({tail})")
            };
            return Err((
                u8::try_from(c).unwrap_or(1),
                format!("firmware exited with code {c}{note}"),
            ));
        }
        None => return Err((137, "QEMU was killed by a signal".into())),
    }
    match print_status {
        Ok(s) if s.success() => Ok(0),
        Ok(s) => Err((1, format!("defmt-print failed ({s})"))),
        Err(e) => Err((1, format!("defmt-print: {e}"))),
    }
}
