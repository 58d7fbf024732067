//! `cargo xtask`: the workspace's automation, in Rust (the `xtask` pattern; the alias is
//! in `.cargo/config.toml`).
//!
//! * `cargo xtask firmware-check`: the on-target checks under QEMU against
//!   `firmware-example/budgets.toml` (sizes, instructions per step, stack, no f64,
//!   handler self-tests, the demo and UART QEMU tests).
//! * `cargo xtask test`: everything `scripts/test.sh` runs after installing: rustfmt,
//!   clippy (host and thumbv7em), rustdoc, builds, `cargo test`, firmware-check, host-sim's
//!   host-in-the-loop tests; then the duration of each phase.
//! * `cargo xtask firmware-profile [REGION] [TOP]`: where the instructions of one
//!   measured step go (by file and function).
//! * `cargo xtask cluster-test`: a sweep as a Slurm job array on a one-node cluster
//!   started here (installs slurm-wlm and munge if missing).
//! * `cargo xtask bench-counts [--profile dev|release]`: host-sim's instructions and
//!   last-level misses per agent-step (callgrind) against `host-sim/bench-counts.toml`.
//! * `cargo xtask stack-frames <elf> [N]`: the largest stack frames of an ELF.
//! * `cargo xtask qemu-run <elf> [qemu args…]`: the cargo runner of the firmware (QEMU +
//!   live defmt log).

mod bench_counts;
mod bench_outputs;
mod budgets;
mod check;
mod cluster;
mod firmware_check;
mod fwlog;
mod package;
mod profile;
mod qemu_run;
mod stack_frames;
mod test_cmd;
mod tools;

use clap::{Args, Parser, Subcommand};
use qemu_harness::firmware::{target_dir, workspace_root};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

/// Workspace automation for ph-formation.
#[derive(Parser, Debug)]
#[command(name = "cargo xtask", bin_name = "cargo xtask", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Task,
}

#[derive(Subcommand, Debug)]
enum Task {
    /// Build the release firmware and check its on-target resource use (QEMU) against
    /// the budgets; exits 1 on any regression.
    FirmwareCheck(CheckArgs),
    /// Run every check of the project (what scripts/test.sh runs after installing).
    Test(CheckArgs),
    /// Run a sweep as a Slurm job array on a one-node cluster started for the test
    /// (installs slurm-wlm and munge if missing; as root), merge it, cancel and resubmit a
    /// task; compare with an unsharded run byte for byte.
    ClusterTest,
    /// Where the instructions of one measured region of `measure` go: by source file, by
    /// innermost function and by outermost function of the inlining chain (needs binutils'
    /// addr2line). Report also in target/firmware-check/profile-REGION.txt.
    FirmwareProfile {
        /// Region name printed by `measure`: tri2 (whole step), tri2-rx, tri2-step,
        /// tri2-tx, tri2-crc, tri8, …
        #[arg(default_value = "tri2")]
        region: String,
        /// Rows per table.
        #[arg(default_value_t = 25)]
        top: usize,
    },
    /// host-sim's instructions and last-level cache misses per agent-step, counted by
    /// valgrind's callgrind (1,000- and 100,000-agent strips, the paper run), checked
    /// against host-sim/bench-counts.toml with a 5 % guard; exits 1 on any regression.
    BenchCounts {
        /// Build profile of the measured binary: dev (what `cargo test` built; CI) or
        /// release (the figures of docs/performance.md).
        #[arg(long, default_value = "dev")]
        profile: String,
        /// Budget file.
        #[arg(long)]
        budgets: Option<PathBuf>,
        /// Only measure and print.
        #[arg(long)]
        no_check: bool,
        /// Every case, also the 100,000-agent strip (about 160 s in the dev build).
        #[arg(long)]
        all: bool,
    },
    /// The largest stack frames of a thumbv7em ELF (from the `sub sp, #N` of the
    /// function prologues; push/vpush not counted).
    StackFrames {
        /// The ELF, e.g. target/thumbv7em-none-eabihf/release/measure.
        elf: PathBuf,
        /// How many frames to list.
        #[arg(default_value_t = 20)]
        count: usize,
    },
    /// Run a firmware ELF under QEMU (netduinoplus2) and print its defmt log: the cargo
    /// runner for thumbv7em-none-eabihf. Exits with the firmware's exit code (124: timed
    /// out). Environment: QEMU_TIMEOUT, QEMU_SERIAL, QEMU_RAW_OUT, QEMU_SYSTEM_ARM,
    /// DEFMT_PRINT.
    QemuRun {
        /// The firmware ELF.
        elf: PathBuf,
        /// Extra QEMU arguments (e.g. -d in_asm).
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        qemu_args: Vec<String>,
    },
}

/// Options of the firmware checks (also taken from the environment, as the old script
/// did: FIRMWARE_BUDGETS, FIRMWARE_CHECK_OUT, QEMU_TIMEOUT).
#[derive(Args, Debug, Default)]
struct CheckArgs {
    /// Budget file [env FIRMWARE_BUDGETS; default firmware-example/budgets.toml].
    #[arg(long)]
    budgets: Option<PathBuf>,
    /// Directory for logs and plugin output [env FIRMWARE_CHECK_OUT; default
    /// target/firmware-check].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Time limit of each QEMU run of the checks, in seconds [env QEMU_TIMEOUT; default 60].
    #[arg(long)]
    qemu_timeout: Option<u64>,
}

impl CheckArgs {
    fn options(self) -> Result<firmware_check::Options, String> {
        let env = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
        let budgets = self
            .budgets
            .or_else(|| env("FIRMWARE_BUDGETS").map(PathBuf::from))
            .unwrap_or_else(|| workspace_root().join("firmware-example/budgets.toml"));
        let out = self
            .out
            .or_else(|| env("FIRMWARE_CHECK_OUT").map(PathBuf::from))
            .unwrap_or_else(|| target_dir().join("firmware-check"));
        let timeout = match self.qemu_timeout {
            Some(t) => t,
            None => match env("QEMU_TIMEOUT") {
                Some(v) => v.to_string_lossy().trim().parse().map_err(|_| {
                    format!("QEMU_TIMEOUT={v:?}: expected a whole number of seconds")
                })?,
                None => 60,
            },
        };
        Ok(firmware_check::Options {
            budgets,
            out,
            timeout: Duration::from_secs(timeout),
        })
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Task::QemuRun { elf, qemu_args } => return qemu_run::run(&elf, &qemu_args),
        Task::StackFrames { elf, count } => {
            stack_frames::run(&elf, count).map(|()| ExitCode::SUCCESS)
        }
        Task::FirmwareProfile { region, top } => CheckArgs::default().options().and_then(|o| {
            profile::run(&region, top, &o.out, o.timeout).map(|()| ExitCode::SUCCESS)
        }),
        Task::FirmwareCheck(a) => a.options().and_then(|o| {
            firmware_check::run(&o).map(|ok| {
                if ok {
                    ExitCode::SUCCESS
                } else {
                    ExitCode::FAILURE
                }
            })
        }),
        Task::ClusterTest => cluster::run().map(|()| ExitCode::SUCCESS),
        Task::BenchCounts {
            profile,
            budgets,
            no_check,
            all,
        } => bench_counts::run(&bench_counts::Options {
            profile,
            budgets: budgets.unwrap_or_else(bench_counts::default_budgets),
            no_check,
            all,
        })
        .map(|ok| {
            if ok {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            }
        }),
        Task::Test(a) => a
            .options()
            .and_then(|o| test_cmd::run(&o))
            .map(|()| ExitCode::SUCCESS),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("xtask: {e}");
            ExitCode::FAILURE
        }
    }
}
