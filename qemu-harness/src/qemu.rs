//! Building and starting `qemu-system-arm -machine netduinoplus2` for one firmware ELF.
//!
//! Every QEMU of the project is started here, with the same command line:
//!
//! ```text
//! qemu-system-arm -machine netduinoplus2 -display none -monitor none \
//!     -semihosting-config enable=on,target=native -serial <serial> \
//!     [-plugin <so>,<k>=<v>,…] [extra…] -kernel <elf>
//! ```
//!
//! * The guest's semihosting output (its defmt stream, raw) goes to a file, never to a pipe
//!   that could close under it (a guest writing to a closed semihosting stdout spins
//!   forever); [`crate::defmt::decode`] turns it into text afterwards.
//! * USART1 (QEMU's `serial0`) is [`Serial::Null`], or a TCP client connecting to a port the
//!   host listens on ([`Serial::TcpClient`]): the host binds port 0 first, so there is no
//!   race for the port, no byte can be lost before the host is there, and a QEMU that fails
//!   to start is seen as an exit instead of a connection that never comes.
//! * [`QemuProcess`] kills and reaps QEMU when dropped, on every path; on Linux QEMU also
//!   gets `SIGKILL` when the thread that started it dies (`PR_SET_PDEATHSIG`), so not even
//!   a killed host process leaves it behind. Optionally it is pinned to one CPU
//!   ([`allowed_cpus`]).
//! * [`QemuProcess::wait_or_kill`] is the time limit of a run (what `timeout` did for the
//!   shell scripts): it waits for the exit without polling and kills QEMU at the limit.

use std::ffi::OsString;
use std::fs::File;
use std::io::{self, Read};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};
use wait_timeout::ChildExt;

use crate::os::before_exec;
pub use crate::os::{allowed_cpus, find_program};

/// Environment variable naming the QEMU binary.
pub const QEMU_ENV: &str = "QEMU_SYSTEM_ARM";
/// The QEMU binary looked up on `PATH` by default.
pub const QEMU_DEFAULT: &str = "qemu-system-arm";
/// The emulated board: an STM32F405 (FLASH 0x0800_0000, RAM 0x2000_0000).
pub const MACHINE: &str = "netduinoplus2";
/// What to install when QEMU is missing.
pub const INSTALL_HINT: &str = "run `bash scripts/firmware-deps.sh` (as root) to install it";

/// The QEMU binary to run: `$QEMU_SYSTEM_ARM` or `qemu-system-arm`.
pub fn qemu_program() -> String {
    std::env::var(QEMU_ENV)
        .ok()
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| QEMU_DEFAULT.to_owned())
}

/// The backend of the board's USART1 (QEMU's `serial0`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Serial {
    /// Not connected (`-serial null`).
    Null,
    /// A TCP client connecting to `127.0.0.1:port` with `TCP_NODELAY` (without it every
    /// reply waits for Nagle's timer). The host must be listening before QEMU starts.
    TcpClient {
        /// The loopback port the host listens on.
        port: u16,
    },
    /// Any `-serial` backend as QEMU spells it, e.g.
    /// `tcp:127.0.0.1:4444,server=on,wait=on,nodelay=on`.
    Spec(String),
}

/// How a run under [`Qemu::run`] ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Exit {
    /// QEMU exited with this code: the firmware's semihosting exit code (0 = success; the
    /// panic and HardFault handlers exit with 1).
    Code(i32),
    /// QEMU ended without an exit code (killed by a signal).
    Signal,
    /// The time limit passed; QEMU was killed.
    TimedOut,
}

impl Exit {
    /// The exit code in the convention of the old `timeout`-based scripts: the code, 124
    /// for a timeout, 137 for a signal.
    pub fn code(self) -> i32 {
        match self {
            Exit::Code(c) => c,
            Exit::TimedOut => 124,
            Exit::Signal => 137,
        }
    }
}

impl std::fmt::Display for Exit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Exit::Code(c) => write!(f, "exit code {c}"),
            Exit::Signal => write!(f, "killed by a signal"),
            Exit::TimedOut => write!(f, "no exit before the time limit (killed)"),
        }
    }
}

/// A QEMU command line for one firmware ELF (see the module documentation).
#[derive(Clone, Debug)]
pub struct Qemu {
    program: PathBuf,
    elf: PathBuf,
    serial: Serial,
    plugin: Option<OsString>,
    extra: Vec<OsString>,
    cpu: Option<usize>,
    stdout: PathBuf,
    stderr: PathBuf,
    pipe: bool,
}

impl Qemu {
    /// QEMU ([`qemu_program`]) for `elf`, USART1 not connected; the guest's output goes to
    /// `<log_stem>.raw` (defmt, binary) and QEMU's own messages to `<log_stem>.stderr.txt`.
    pub fn new(elf: impl Into<PathBuf>, log_stem: impl AsRef<Path>) -> Self {
        let stem = log_stem.as_ref();
        let with = |ext: &str| {
            let mut s = stem.as_os_str().to_owned();
            s.push(ext);
            PathBuf::from(s)
        };
        Self {
            program: PathBuf::from(qemu_program()),
            elf: elf.into(),
            serial: Serial::Null,
            plugin: None,
            extra: Vec::new(),
            cpu: None,
            stdout: with(".raw"),
            stderr: with(".stderr.txt"),
            pipe: false,
        }
    }

    /// Sends the guest's output to a pipe ([`QemuProcess::take_stdout`]) instead of the
    /// `.raw` file, for a live log. The reader must keep reading until QEMU exits (a guest
    /// writing to a closed semihosting stdout spins forever; the time limit ends it).
    pub fn pipe_stdout(mut self) -> Self {
        self.pipe = true;
        self
    }

    /// Other files for the guest's output and QEMU's messages (e.g. host-sim's
    /// `qemu-agent-<id>.log` and `qemu-agent-<id>.stderr.log`).
    pub fn log_files(mut self, stdout: impl Into<PathBuf>, stderr: impl Into<PathBuf>) -> Self {
        self.stdout = stdout.into();
        self.stderr = stderr.into();
        self
    }

    /// Another QEMU binary.
    pub fn program(mut self, program: impl Into<PathBuf>) -> Self {
        self.program = program.into();
        self
    }

    /// The backend of USART1.
    pub fn serial(mut self, serial: Serial) -> Self {
        self.serial = serial;
        self
    }

    /// Loads the TCG plugin `so` with `key=value` arguments.
    pub fn plugin(mut self, so: &Path, args: &[(&str, &str)]) -> Self {
        let mut s = so.as_os_str().to_owned();
        for (k, v) in args {
            s.push(format!(",{k}={v}"));
        }
        self.plugin = Some(s);
        self
    }

    /// Extra QEMU arguments (e.g. `-d in_asm`), placed before `-kernel`.
    pub fn args<I, S>(mut self, args: I) -> Self
    where
        I: IntoIterator<Item = S>,
        S: Into<OsString>,
    {
        self.extra.extend(args.into_iter().map(Into::into));
        self
    }

    /// On Linux, run QEMU on CPU `cpu` only (see [`allowed_cpus`]); `None`: anywhere.
    pub fn pin(mut self, cpu: Option<usize>) -> Self {
        self.cpu = cpu;
        self
    }

    /// The firmware ELF.
    pub fn elf(&self) -> &Path {
        &self.elf
    }

    /// Where the guest's raw semihosting output goes.
    pub fn stdout_path(&self) -> &Path {
        &self.stdout
    }

    /// Where QEMU's own messages go.
    pub fn stderr_path(&self) -> &Path {
        &self.stderr
    }

    /// The arguments after the program name.
    pub fn arguments(&self) -> Vec<OsString> {
        let mut a: Vec<OsString> = [
            "-machine",
            MACHINE,
            "-display",
            "none",
            "-monitor",
            "none",
            "-semihosting-config",
            "enable=on,target=native",
        ]
        .into_iter()
        .map(OsString::from)
        .collect();
        match &self.serial {
            Serial::Null => a.extend(["-serial".into(), "null".into()]),
            Serial::TcpClient { port } => {
                a.push("-chardev".into());
                a.push(
                    format!("socket,id=uart,host=127.0.0.1,port={port},server=off,nodelay=on")
                        .into(),
                );
                a.extend(["-serial".into(), "chardev:uart".into()]);
            }
            Serial::Spec(s) => a.extend(["-serial".into(), s.into()]),
        }
        if let Some(p) = &self.plugin {
            a.push("-plugin".into());
            a.push(p.clone());
        }
        a.extend(self.extra.iter().cloned());
        a.push("-kernel".into());
        a.push(self.elf.clone().into_os_string());
        a
    }

    /// The command line as one string, for messages.
    pub fn display(&self) -> String {
        let mut s = self.program.display().to_string();
        for a in self.arguments() {
            s.push(' ');
            s.push_str(&a.to_string_lossy());
        }
        s
    }

    /// Starts QEMU. Errors name the program (missing QEMU) or the ELF (missing firmware).
    pub fn spawn(&self) -> io::Result<QemuProcess> {
        if !self.elf.is_file() {
            return Err(io::Error::new(
                io::ErrorKind::NotFound,
                format!("no firmware ELF at {}", self.elf.display()),
            ));
        }
        let out = if self.pipe {
            Stdio::piped()
        } else {
            Stdio::from(create(&self.stdout)?)
        };
        let err = create(&self.stderr)?;
        let mut cmd = Command::new(&self.program);
        cmd.args(self.arguments())
            .stdin(Stdio::null())
            .stdout(out)
            .stderr(Stdio::from(err));
        before_exec(&mut cmd, self.cpu);
        let child = cmd.spawn().map_err(|e| {
            io::Error::new(
                e.kind(),
                format!(
                    "cannot start {}: {e}; {INSTALL_HINT}",
                    self.program.display()
                ),
            )
        })?;
        Ok(QemuProcess {
            child,
            log: self.stdout.clone(),
            stderr_log: self.stderr.clone(),
            exited: None,
        })
    }

    /// Runs the firmware to its end, at most `limit` (then QEMU is killed).
    pub fn run(&self, limit: Duration) -> io::Result<Exit> {
        let mut p = self.spawn()?;
        Ok(match p.wait_or_kill(limit) {
            Some(s) => s.code().map_or(Exit::Signal, Exit::Code),
            None => Exit::TimedOut,
        })
    }
}

/// Creates `path` (and its directory), naming it in the error.
fn create(path: &Path) -> io::Result<File> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| {
            io::Error::new(e.kind(), format!("cannot create {}: {e}", dir.display()))
        })?;
    }
    File::create(path)
        .map_err(|e| io::Error::new(e.kind(), format!("cannot create {}: {e}", path.display())))
}

/// A running QEMU; killed and reaped on drop.
#[derive(Debug)]
pub struct QemuProcess {
    child: Child,
    /// Where the guest's semihosting output goes (raw defmt frames; unused with
    /// [`Qemu::pipe_stdout`]).
    pub log: PathBuf,
    /// Where QEMU's own messages go.
    pub stderr_log: PathBuf,
    exited: Option<ExitStatus>,
}

impl QemuProcess {
    /// The guest's output, if QEMU was started with [`Qemu::pipe_stdout`] (once).
    pub fn take_stdout(&mut self) -> Option<std::process::ChildStdout> {
        self.child.stdout.take()
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

    /// Waits up to `limit` for QEMU to exit by itself (without polling); kills it
    /// otherwise. Returns the exit status if it exited by itself.
    pub fn wait_or_kill(&mut self, limit: Duration) -> Option<ExitStatus> {
        if let Some(s) = self.exited {
            return Some(s);
        }
        match self.child.wait_timeout(limit) {
            Ok(Some(s)) => {
                self.exited = Some(s);
                Some(s)
            }
            _ => {
                self.kill();
                None
            }
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
/// (an error from it aborts the wait). The polls are 2 ms apart: QEMU connects within
/// milliseconds of starting, and the deadline only guards against one that never does.
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

#[cfg(test)]
mod tests {
    use super::*;

    fn args(q: &Qemu) -> Vec<String> {
        q.arguments()
            .into_iter()
            .map(|a| a.to_string_lossy().into_owned())
            .collect()
    }

    #[test]
    fn command_line_of_a_plain_run() {
        let q = Qemu::new("/fw/measure", "/tmp/x/measure");
        let a = args(&q);
        assert_eq!(&a[..2], ["-machine", "netduinoplus2"]);
        assert!(a.windows(2).any(|w| w == ["-serial", "null"]));
        assert!(a
            .windows(2)
            .any(|w| w == ["-semihosting-config", "enable=on,target=native"]));
        assert_eq!(&a[a.len() - 2..], ["-kernel", "/fw/measure"]);
        assert_eq!(q.stdout_path(), Path::new("/tmp/x/measure.raw"));
        assert_eq!(q.stderr_path(), Path::new("/tmp/x/measure.stderr.txt"));
        let q = q.log_files("/l/a.log", "/l/a.stderr.log");
        assert_eq!(q.stdout_path(), Path::new("/l/a.log"));
        assert_eq!(q.stderr_path(), Path::new("/l/a.stderr.log"));
    }

    #[test]
    fn command_line_with_uart_plugin_and_extras() {
        let q = Qemu::new("fw", "log")
            .serial(Serial::TcpClient { port: 4321 })
            .plugin(
                Path::new("/p/libqemu-insn.so"),
                &[("marker", "0x20000000"), ("out", "o.txt")],
            )
            .args(["-d", "in_asm"]);
        let a = args(&q);
        let i = a.iter().position(|x| x == "-chardev").expect("chardev");
        assert_eq!(
            a[i + 1],
            "socket,id=uart,host=127.0.0.1,port=4321,server=off,nodelay=on"
        );
        assert!(a.windows(2).any(|w| w == ["-serial", "chardev:uart"]));
        assert!(a
            .windows(2)
            .any(|w| w == ["-plugin", "/p/libqemu-insn.so,marker=0x20000000,out=o.txt"]));
        let d = a.iter().position(|x| x == "-d").expect("-d");
        assert!(d < a.iter().position(|x| x == "-kernel").expect("-kernel"));
        assert!(q.display().contains("-kernel fw"));
    }

    #[test]
    fn missing_elf_is_reported_by_path() {
        let e = Qemu::new(
            "/nonexistent/fw.elf",
            std::env::temp_dir().join("qh-missing"),
        )
        .spawn()
        .expect_err("no ELF");
        assert!(e.to_string().contains("/nonexistent/fw.elf"), "{e}");
    }

    #[test]
    fn exit_codes_keep_the_timeout_convention() {
        assert_eq!(Exit::Code(1).code(), 1);
        assert_eq!(Exit::TimedOut.code(), 124);
        assert_eq!(Exit::Signal.code(), 137);
    }

    #[test]
    fn finds_programs_like_the_shell() {
        assert!(find_program("sh").is_some());
        assert!(find_program("no-such-program-here").is_none());
        assert!(find_program("/no/such/dir/prog").is_none());
    }
}
