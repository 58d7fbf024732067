//! The operating-system parts of starting QEMU: finding programs on `PATH`, and on
//! Linux the parent-death signal and CPU pinning of the child.

#[cfg(target_os = "linux")]
use std::io;
use std::path::{Path, PathBuf};
use std::process::Command;

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
/// A QEMU driven byte by byte over its UART runs faster pinned to one CPU: its I/O thread
/// and its vCPU thread hand every received byte to each other, and on one CPU that costs
/// a context switch, across two an inter-processor wake-up (`docs/hil.md`).
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
pub(crate) fn before_exec(cmd: &mut Command, cpu: Option<usize>) {
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
pub(crate) fn before_exec(_cmd: &mut Command, _cpu: Option<usize>) {}
