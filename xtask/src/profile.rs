//! `cargo xtask firmware-profile [REGION] [TOP]`: where do the instructions of one
//! measured control step go?
//!
//! Runs `measure` under QEMU twice: once to learn the region ids, once with the qemu-insn
//! plugin's per-address profile of REGION (counts over all its occurrences, divided by
//! their number). Maps every address to its inlining chain with binutils' `addr2line`
//! and prints the instructions per step by source file, by innermost function (after
//! inlining) and by the outermost function of the chain. Deterministic, like the checks.
//! The report is also written to `<out>/profile-<REGION>.txt`.

use crate::fwlog;
use crate::tools::{self, Llvm};
use qemu_harness::firmware::{self, PACKAGE, TARGET};
use qemu_harness::{defmt, Exit, Qemu};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

/// Profiles region `region` of `measure`; prints the `top` largest entries per table.
pub fn run(region: &str, top: usize, out: &Path, timeout: Duration) -> Result<(), String> {
    std::fs::create_dir_all(out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
    tools::run(tools::cargo().args([
        "build",
        "-q",
        "-p",
        PACKAGE,
        "--target",
        TARGET,
        "--release",
        "--bin",
        "measure",
    ]))?;
    let elf = firmware::elf("measure");
    let plugin = tools::qemu_insn_plugin()?;
    let marker = Llvm::find()?.symbol_address(&elf, "PH_INSN_MARKERS")?;

    // Pass 1: region names -> ids.
    let q = Qemu::new(&elf, out.join("profile-measure"));
    let exit = q.run(timeout).map_err(|e| e.to_string())?;
    let log = defmt::decode(&elf, q.stdout_path())?;
    if exit != Exit::Code(0) {
        return Err(format!("measure: {exit}"));
    }
    let regions = fwlog::regions(&log);
    let Some(r) = regions.iter().find(|r| r.name == region) else {
        let names: Vec<&str> = regions.iter().map(|r| r.name.as_str()).collect();
        return Err(format!(
            "no region named '{region}'; regions: {}",
            names.join(", ")
        ));
    };

    // Pass 2: the per-address profile of that region.
    let raw = out.join(format!("profile-{region}.raw"));
    let (id, raw_arg) = (r.id.to_string(), raw.display().to_string());
    let args = [
        ("marker", marker.as_str()),
        ("out", raw_arg.as_str()),
        ("profile", id.as_str()),
    ];
    let q = Qemu::new(&elf, out.join(format!("profile-{region}-qemu"))).plugin(&plugin, &args);
    let exit = q.run(timeout).map_err(|e| e.to_string())?;
    if exit != Exit::Code(0) {
        return Err(format!("measure with the profile: {exit}"));
    }
    let text =
        std::fs::read_to_string(&raw).map_err(|e| format!("cannot read {}: {e}", raw.display()))?;
    let total: u64 = fwlog::insn_counts(&text)
        .get(&r.id)
        .map_or(0, |v| v.iter().sum());
    let pcs = profile_pcs(&text);
    let chains = inlining_chains(&elf, pcs.iter().map(|(pc, _)| *pc))?;
    let report = report(region, r.repeats.max(1), total, &pcs, &chains, top);
    print!("{report}");
    let path = out.join(format!("profile-{region}.txt"));
    std::fs::write(&path, report).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// `qemu-insn profile pc=0x<addr> insns=<n>` lines: `(address, count)`.
fn profile_pcs(text: &str) -> Vec<(u64, u64)> {
    text.lines()
        .filter_map(|l| {
            let rest = l.strip_prefix("qemu-insn profile pc=0x")?;
            let (pc, n) = rest.split_once(" insns=")?;
            Some((u64::from_str_radix(pc, 16).ok()?, n.trim().parse().ok()?))
        })
        .collect()
}

/// One level of an inlining chain: function and `file:line`.
type Frame = (String, String);

/// `addr2line -a -f -i -C` for each address (innermost frame first), in input order.
fn inlining_chains(elf: &Path, pcs: impl Iterator<Item = u64>) -> Result<Vec<Vec<Frame>>, String> {
    let program = std::env::var("ADDR2LINE").unwrap_or_else(|_| "addr2line".into());
    let mut child = Command::new(&program)
        .args(["-a", "-f", "-i", "-C", "-e"])
        .arg(elf)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot run {program} (binutils): {e}"))?;
    let mut input = String::new();
    for pc in pcs {
        let _ = writeln!(input, "0x{pc:x}");
    }
    let mut stdin = child.stdin.take().ok_or("no pipe to addr2line")?;
    // Written from a thread: addr2line answers while it reads.
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let out = child
        .wait_with_output()
        .map_err(|e| format!("{program}: {e}"))?;
    let _ = writer.join();
    if !out.status.success() {
        return Err(format!("{program} failed ({})", out.status));
    }
    let mut chains: Vec<Vec<Frame>> = Vec::new();
    let mut pending: Option<String> = None;
    for line in String::from_utf8_lossy(&out.stdout).lines() {
        if line.starts_with("0x") && pending.is_none() {
            chains.push(Vec::new());
            continue;
        }
        match (pending.take(), chains.last_mut()) {
            (None, Some(_)) => pending = Some(line.to_owned()),
            (Some(f), Some(chain)) => chain.push((f, line.to_owned())),
            (_, None) => {}
        }
    }
    Ok(chains)
}

/// A source location shortened to a crate-relative file or a library name.
fn source(file_line: &str) -> String {
    let mut s = file_line.to_owned();
    // Strip `:line` and `:line:column` (and addr2line's " (discriminator n)").
    if let Some(i) = s.find(" (discriminator") {
        s.truncate(i);
    }
    for _ in 0..2 {
        if let Some((head, tail)) = s.rsplit_once(':') {
            if tail.chars().all(|c| c.is_ascii_digit() || c == '?') {
                s = head.to_owned();
            }
        }
    }
    for krate in ["controller-core/src/", "firmware-example/src/"] {
        if let Some(i) = s.find(krate) {
            let name = krate.trim_end_matches("src/");
            return format!("{name}{}", &s[i + krate.len()..]);
        }
    }
    if let Some(i) = s.find("/library/") {
        let lib = &s[i + "/library/".len()..];
        return format!("std: {}", lib.split('/').next().unwrap_or(lib));
    }
    if let Some(i) = s.find("registry/src/") {
        let rest = &s[i + "registry/src/".len()..];
        let krate = rest.split('/').nth(1).unwrap_or(rest);
        return format!("crate {krate}");
    }
    if s.contains("compiler-builtins") || s.contains("compiler_builtins") {
        return "compiler_builtins".into();
    }
    s
}

/// The three tables of the report.
fn report(
    region: &str,
    repeats: usize,
    total: u64,
    pcs: &[(u64, u64)],
    chains: &[Vec<Frame>],
    top: usize,
) -> String {
    let reps = repeats as f64;
    let per_step = total as f64 / reps;
    let (mut by_file, mut by_fn, mut by_outer) = (
        BTreeMap::<String, f64>::new(),
        BTreeMap::<String, f64>::new(),
        BTreeMap::<String, f64>::new(),
    );
    for (k, (_, count)) in pcs.iter().enumerate() {
        let c = *count as f64 / reps;
        let chain = chains.get(k).map_or(&[][..], Vec::as_slice);
        let (file, inner, outer) = match (chain.first(), chain.last()) {
            (Some(first), Some(last)) => (source(&first.1), first.0.clone(), last.0.clone()),
            _ => ("?".into(), "?".into(), "?".into()),
        };
        *by_file.entry(file).or_default() += c;
        *by_fn.entry(inner).or_default() += c;
        *by_outer.entry(outer).or_default() += c;
    }
    let mut s = format!(
        "region {region}: {} instructions per step ({repeats} occurrences profiled)\n",
        per_step as u64
    );
    for (title, table) in [
        ("by source file (std/crates: by library)", by_file),
        ("by innermost function (after inlining)", by_fn),
        ("by outermost function of the inlining chain", by_outer),
    ] {
        let _ = writeln!(s, "\n{title}");
        let mut rows: Vec<(String, f64)> = table.into_iter().collect();
        rows.sort_by(|a, b| b.1.total_cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
        for (name, c) in rows.into_iter().take(top) {
            let share = if per_step > 0.0 {
                100.0 * c / per_step
            } else {
                0.0
            };
            let _ = writeln!(s, "{}\t{share:5.1}%\t{name}", (c + 0.5) as u64);
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shortens_sources() {
        assert_eq!(
            source("/work/x/controller-core/src/agent/mod.rs:812:9"),
            "controller-core/agent/mod.rs"
        );
        assert_eq!(
            source("/rustc/abc/library/core/src/num/f32.rs:100"),
            "std: core"
        );
        assert_eq!(
            source("/root/.cargo/registry/src/index.crates.io-1/heapless-0.9.3/src/vec.rs:5"),
            "crate heapless-0.9.3"
        );
        assert_eq!(source("??:0"), "??");
    }

    #[test]
    fn aggregates_per_step() {
        let pcs = [(0x100, 40), (0x104, 20)];
        let chains = vec![
            vec![
                (
                    "inner".to_owned(),
                    "/w/controller-core/src/law.rs:3".to_owned(),
                ),
                (
                    "outer".to_owned(),
                    "/w/firmware-example/src/workload.rs:9".to_owned(),
                ),
            ],
            vec![],
        ];
        let r = report("tri2", 2, 60, &pcs, &chains, 5);
        assert!(r.starts_with("region tri2: 30 instructions per step (2 occurrences"));
        assert!(r.contains("20\t 66.7%\tcontroller-core/law.rs"), "{r}");
        assert!(r.contains("10\t 33.3%\t?"), "{r}");
        assert!(r.contains("20\t 66.7%\touter"), "{r}");
        assert_eq!(
            profile_pcs("qemu-insn profile pc=0x8001a2 insns=7\nqemu-insn total=1 errors=0\n"),
            [(0x8001a2, 7)]
        );
    }
}
