//! The external programs the tasks run: cargo, rustc's `llvm-tools`, the plugin build.

use qemu_harness::firmware::{target_dir, workspace_root};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// `$CARGO` (the cargo that runs this xtask) or `cargo`.
pub fn cargo() -> Command {
    let mut c = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()));
    c.current_dir(workspace_root());
    c
}

/// Builds the `host-sim` binary as `cargo test` builds it (no `-p`: the default members'
/// feature set; dev profile) and returns its path. After `cargo test` nothing is rebuilt,
/// so the simulator the tests ran is the one used (no release build of host-sim and its
/// dependencies only for this: Rust's floating point is the same at every opt-level,
/// so a run's outputs are the same byte for byte).
pub fn host_sim_dev() -> Result<PathBuf, String> {
    run(cargo().args(["test", "--no-run", "--test", "sweep"]))?;
    let exe = target_dir().join("debug/host-sim");
    if exe.is_file() {
        Ok(exe)
    } else {
        Err(format!("{} was not built", exe.display()))
    }
}

/// Runs `cmd` with inherited output; an error names the command and its exit status.
pub fn run(cmd: &mut Command) -> Result<(), String> {
    let shown = show(cmd);
    println!("$ {shown}");
    let status = cmd
        .status()
        .map_err(|e| format!("cannot run `{shown}`: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("`{shown}` failed ({status})"))
    }
}

/// Runs `cmd` with stdout and stderr into the file `log`; returns whether it succeeded.
pub fn run_logged(cmd: &mut Command, log: &Path) -> Result<bool, String> {
    let shown = show(cmd);
    let file =
        std::fs::File::create(log).map_err(|e| format!("cannot create {}: {e}", log.display()))?;
    let err = file
        .try_clone()
        .map_err(|e| format!("cannot create {}: {e}", log.display()))?;
    let status = cmd
        .stdout(Stdio::from(file))
        .stderr(Stdio::from(err))
        .status()
        .map_err(|e| format!("cannot run `{shown}`: {e}"))?;
    Ok(status.success())
}

/// Runs `cmd` and returns its stdout; an error names the command and shows its stderr.
pub fn output(cmd: &mut Command) -> Result<String, String> {
    let shown = show(cmd);
    let out = cmd
        .stdin(Stdio::null())
        .output()
        .map_err(|e| format!("cannot run `{shown}`: {e}"))?;
    if out.status.success() {
        Ok(String::from_utf8_lossy(&out.stdout).into_owned())
    } else {
        Err(format!(
            "`{shown}` failed ({}): {}",
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        ))
    }
}

/// A command as a shell line, for messages.
pub fn show(cmd: &Command) -> String {
    let mut s = cmd.get_program().to_string_lossy().into_owned();
    for a in cmd.get_args() {
        s.push(' ');
        s.push_str(&a.to_string_lossy());
    }
    s
}

/// `llvm-size`, `llvm-nm` and `llvm-objdump` of the pinned toolchain's `llvm-tools`
/// component.
#[derive(Clone, Debug)]
pub struct Llvm {
    /// `llvm-size`.
    pub size: PathBuf,
    /// `llvm-nm`.
    pub nm: PathBuf,
    /// `llvm-objdump`.
    pub objdump: PathBuf,
}

impl Llvm {
    /// Finds them under `$(rustc --print sysroot)/lib/rustlib/<host>/bin`.
    pub fn find() -> Result<Self, String> {
        let rustc = || {
            let mut c = Command::new("rustc");
            c.current_dir(workspace_root());
            c
        };
        let sysroot = output(rustc().args(["--print", "sysroot"]))?;
        let version = output(rustc().arg("-vV"))?;
        let host = version
            .lines()
            .find_map(|l| l.strip_prefix("host: "))
            .ok_or("`rustc -vV` printed no host line")?;
        let bin = Path::new(sysroot.trim())
            .join("lib/rustlib")
            .join(host.trim())
            .join("bin");
        let llvm = Self {
            size: bin.join("llvm-size"),
            nm: bin.join("llvm-nm"),
            objdump: bin.join("llvm-objdump"),
        };
        if [&llvm.size, &llvm.nm, &llvm.objdump]
            .iter()
            .all(|p| p.is_file())
        {
            Ok(llvm)
        } else {
            Err(format!(
                "llvm-size/llvm-nm/llvm-objdump missing in {}; run: rustup component add llvm-tools",
                bin.display()
            ))
        }
    }

    /// `(text, data, bss)` of an ELF (`llvm-size -B`).
    pub fn sizes(&self, elf: &Path) -> Result<(u64, u64, u64), String> {
        let out = output(Command::new(&self.size).arg("-B").arg(elf))?;
        let row = out.lines().nth(1).unwrap_or("");
        let n: Vec<u64> = row
            .split_whitespace()
            .take(3)
            .filter_map(|x| x.parse().ok())
            .collect();
        match n[..] {
            [text, data, bss] => Ok((text, data, bss)),
            _ => Err(format!(
                "cannot read the sizes of {} from llvm-size: {out:?}",
                elf.display()
            )),
        }
    }

    /// The names of the symbols `elf` defines.
    pub fn defined_symbols(&self, elf: &Path) -> Result<Vec<String>, String> {
        let out = output(Command::new(&self.nm).arg("--defined-only").arg(elf))?;
        Ok(out
            .lines()
            .filter_map(|l| l.split_whitespace().last())
            .map(str::to_owned)
            .collect())
    }

    /// The address of symbol `name` in `elf`, as `0x…`.
    pub fn symbol_address(&self, elf: &Path, name: &str) -> Result<String, String> {
        let out = output(Command::new(&self.nm).arg(elf))?;
        out.lines()
            .find_map(|l| {
                let f: Vec<&str> = l.split_whitespace().collect();
                (f.len() == 3 && f[2] == name).then(|| format!("0x{}", f[0]))
            })
            .ok_or_else(|| format!("symbol {name} not found in {}", elf.display()))
    }
}

/// Builds the qemu-insn TCG plugin if needed (`tools/qemu-insn/build.sh`, which picks
/// the plugin API of the installed QEMU) and returns its path.
pub fn qemu_insn_plugin() -> Result<PathBuf, String> {
    let script = workspace_root().join("tools/qemu-insn/build.sh");
    let out = output(Command::new("bash").arg(&script))?;
    let path = PathBuf::from(out.trim());
    if path.is_file() {
        Ok(path)
    } else {
        Err(format!(
            "{} printed {out:?}, which is not the plugin",
            script.display()
        ))
    }
}
