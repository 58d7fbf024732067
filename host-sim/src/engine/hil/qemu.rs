//! Starting and stopping one `qemu-system-arm` per emulated agent.
//!
//! The host listens on a free loopback port (bound to port 0, so no race for the port)
//! and QEMU connects USART1 to it as a client chardev
//! (`-chardev socket,host=127.0.0.1,port=P,nodelay=on -serial chardev:…`): no byte can be
//! lost before the host is there, and a QEMU that fails to start is seen as an exit
//! instead of a connection that never comes. The guest's semihosting output (the defmt
//! log, raw) goes to a file, never to a pipe that could close under it.
//!
//! [`QemuProcess`] kills and reaps QEMU when dropped, on every path; on Linux QEMU also
//! gets `SIGKILL` if the thread that started it dies (`PR_SET_PDEATHSIG`), so not even
//! a killed host-sim leaves it behind.

use std::fs::File;
use std::io::{self, Read};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// Environment variable naming the QEMU binary (also used by `scripts/qemu-run.sh`).
pub const QEMU_ENV: &str = "QEMU_SYSTEM_ARM";
/// The QEMU binary looked up on `PATH` by default.
pub const QEMU_DEFAULT: &str = "qemu-system-arm";

/// The QEMU binary to run: `$QEMU_SYSTEM_ARM` or `qemu-system-arm`.
pub fn qemu_program() -> String {
    std::env::var(QEMU_ENV)
        .ok()
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| QEMU_DEFAULT.to_owned())
}

/// Resolves `program` like the shell does: a path with a `/` as is, otherwise the first
/// executable file of that name on `PATH`.
pub fn find_program(program: &str) -> Option<PathBuf> {
    let executable = |p: &Path| {
        p.is_file() && {
            #[cfg(unix)]
            {
                use std::os::unix::fs::PermissionsExt;
                p.metadata()
                    .is_ok_and(|m| m.permissions().mode() & 0o111 != 0)
            }
            #[cfg(not(unix))]
            {
                true
            }
        }
    };
    if program.contains('/') {
        let p = PathBuf::from(program);
        return executable(&p).then_some(p);
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join(program))
        .find(|p| executable(p))
}

/// A running QEMU with one agent's firmware; killed and reaped on drop.
#[derive(Debug)]
pub struct QemuProcess {
    child: Child,
    /// The agent's id.
    pub agent: u8,
    /// Where the guest's semihosting output goes (raw defmt frames).
    pub log: PathBuf,
    /// Where QEMU's own messages go.
    pub stderr_log: PathBuf,
    exited: Option<ExitStatus>,
}

impl QemuProcess {
    /// Starts QEMU with `elf`, USART1 connecting to `127.0.0.1:port`; logs into `log_dir`;
    /// on Linux, pinned to CPU `cpu` if given (see [`allowed_cpus`]).
    pub fn spawn(
        qemu: &Path,
        elf: &Path,
        port: u16,
        agent: u8,
        log_dir: &Path,
        cpu: Option<usize>,
    ) -> io::Result<Self> {
        let log = log_dir.join(format!("qemu-agent-{agent}.log"));
        let stderr_log = log_dir.join(format!("qemu-agent-{agent}.stderr.log"));
        let out = File::create(&log)?;
        let err = File::create(&stderr_log)?;
        let mut cmd = Command::new(qemu);
        cmd.args([
            "-machine",
            "netduinoplus2",
            "-display",
            "none",
            "-monitor",
            "none",
        ])
        .args(["-semihosting-config", "enable=on,target=native"])
        .arg("-chardev")
        .arg(format!(
            "socket,id=hil,host=127.0.0.1,port={port},server=off,nodelay=on"
        ))
        .args(["-serial", "chardev:hil", "-kernel"])
        .arg(elf)
        .stdin(Stdio::null())
        .stdout(Stdio::from(out))
        .stderr(Stdio::from(err));
        before_exec(&mut cmd, cpu);
        let child = cmd.spawn()?;
        Ok(Self {
            child,
            agent,
            log,
            stderr_log,
            exited: None,
        })
    }

    /// The process id.
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// The exit status, if QEMU has exited.
    pub fn try_exit(&mut self) -> Option<ExitStatus> {
        if self.exited.is_none() {
            self.exited = self.child.try_wait().ok().flatten();
        }
        self.exited
    }

    /// Waits up to `limit` for QEMU to exit by itself; kills it otherwise. Returns the
    /// exit status if it exited by itself.
    pub fn wait_or_kill(&mut self, limit: Duration) -> Option<ExitStatus> {
        let end = Instant::now() + limit;
        loop {
            if let Some(s) = self.try_exit() {
                return Some(s);
            }
            if Instant::now() >= end {
                self.kill();
                return None;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    /// Kills and reaps QEMU (no-op if it already exited).
    pub fn kill(&mut self) {
        if self.try_exit().is_none() {
            let _ = self.child.kill();
            self.exited = self.child.wait().ok();
        }
    }

    /// QEMU's own messages, shortened for an error report: its `qemu…:` lines (e.g.
    /// `qemu: fatal: …`), else the first lines.
    pub fn stderr_tail(&self) -> String {
        let mut s = String::new();
        if let Ok(f) = File::open(&self.stderr_log) {
            let _ = f.take(64 * 1024).read_to_string(&mut s);
        }
        let lines: Vec<&str> = s.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
        let tagged: Vec<&str> = lines
            .iter()
            .copied()
            .filter(|l| l.starts_with("qemu"))
            .take(3)
            .collect();
        let picked = if tagged.is_empty() {
            lines.iter().copied().take(3).collect()
        } else {
            tagged
        };
        let mut out = picked.join(" | ");
        if out.chars().count() > 400 {
            out = out.chars().take(400).collect::<String>() + "…";
        }
        out
    }

    /// Waits for QEMU's connection on `listener` until `deadline`; fails early if QEMU
    /// exits.
    pub fn accept(
        &mut self,
        listener: &TcpListener,
        deadline: Instant,
    ) -> Result<TcpStream, String> {
        accept_until(listener, deadline, || match self.try_exit() {
            Some(s) => Err(format!(
                "QEMU exited ({s}) before connecting its USART1{}",
                match self.stderr_tail() {
                    t if t.is_empty() => String::new(),
                    t => format!(": {t}"),
                }
            )),
            None => Ok(()),
        })
    }
}

impl Drop for QemuProcess {
    fn drop(&mut self) {
        self.kill();
    }
}

/// Accepts one connection on `listener` until `deadline`, calling `alive` between polls
/// (an error from it aborts the wait).
pub fn accept_until(
    listener: &TcpListener,
    deadline: Instant,
    mut alive: impl FnMut() -> Result<(), String>,
) -> Result<TcpStream, String> {
    listener
        .set_nonblocking(true)
        .map_err(|e| format!("cannot poll the listening socket: {e}"))?;
    loop {
        match listener.accept() {
            Ok((s, _)) => {
                s.set_nonblocking(false)
                    .map_err(|e| format!("cannot configure the connection: {e}"))?;
                return Ok(s);
            }
            Err(e) if e.kind() == io::ErrorKind::WouldBlock => {}
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(format!("accept failed: {e}")),
        }
        alive()?;
        if Instant::now() >= deadline {
            return Err("no connection before the deadline".to_owned());
        }
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// Words of a Linux `cpu_set_t` (1024 CPUs).
#[cfg(target_os = "linux")]
const CPU_SET_WORDS: usize = 16;

#[cfg(target_os = "linux")]
mod sys {
    use std::os::raw::{c_int, c_ulong};
    // From <sys/prctl.h> and <signal.h> (Linux, every architecture).
    pub const PR_SET_PDEATHSIG: c_int = 1;
    pub const SIGKILL: c_ulong = 9;
    extern "C" {
        // The C library that std already links.
        pub fn prctl(option: c_int, arg2: c_ulong, ...) -> c_int;
        pub fn sched_getaffinity(pid: c_int, size: usize, mask: *mut u64) -> c_int;
        pub fn sched_setaffinity(pid: c_int, size: usize, mask: *const u64) -> c_int;
    }
}

/// The CPUs this process may run on (Linux; empty elsewhere or on failure).
///
/// Each QEMU is pinned to one of them (round robin): its I/O thread and its vCPU thread
/// hand every received serial byte to each other, and on one CPU that costs a context
/// switch, across two an inter-processor wake-up (measured on a 2-CPU VM: 19 µs per
/// byte pinned, 46–56 µs when the scheduler spreads the threads; `docs/hil.md`).
pub fn allowed_cpus() -> Vec<usize> {
    #[cfg(target_os = "linux")]
    {
        let mut mask = [0u64; CPU_SET_WORDS];
        // SAFETY: `mask` is a writable buffer of exactly the size passed.
        let r =
            unsafe { sys::sched_getaffinity(0, std::mem::size_of_val(&mask), mask.as_mut_ptr()) };
        if r != 0 {
            return Vec::new();
        }
        (0..CPU_SET_WORDS * 64)
            .filter(|&c| {
                mask.get(c / 64)
                    .is_some_and(|w| w & (1u64 << (c % 64)) != 0)
            })
            .collect()
    }
    #[cfg(not(target_os = "linux"))]
    {
        Vec::new()
    }
}

/// In the child, before `exec`: die with the parent thread (`PR_SET_PDEATHSIG`), and
/// run on `cpu` only (if given).
#[cfg(target_os = "linux")]
fn before_exec(cmd: &mut Command, cpu: Option<usize>) {
    use std::os::unix::process::CommandExt;
    let mut mask = [0u64; CPU_SET_WORDS];
    let mut pin = false;
    if let Some(c) = cpu {
        if let Some(w) = mask.get_mut(c / 64) {
            *w |= 1u64 << (c % 64);
            pin = true;
        }
    }
    // SAFETY: the closure runs in the child between fork and exec and only calls
    // `prctl` and `sched_setaffinity`, which are async-signal-safe, on memory it owns
    // (its copy of the mask); it allocates nothing.
    unsafe {
        cmd.pre_exec(move || {
            if sys::prctl(sys::PR_SET_PDEATHSIG, sys::SIGKILL) != 0 {
                return Err(io::Error::last_os_error());
            }
            // Pinning only makes QEMU faster: a refusal is not an error.
            if pin {
                let _ = sys::sched_setaffinity(0, std::mem::size_of_val(&mask), mask.as_ptr());
            }
            Ok(())
        });
    }
}

#[cfg(not(target_os = "linux"))]
fn before_exec(_cmd: &mut Command, _cpu: Option<usize>) {}
