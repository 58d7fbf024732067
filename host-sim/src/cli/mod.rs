//! The command line: `host-sim [run|validate|list|plot]` (exit codes in
//! [`crate::scenario::error::exit_code`] and `docs/outputs.md`).

use crate::engine::hil::{self, HilOptions};
use crate::engine::sampled::{self as sim, RunResult};
use crate::model::Model;
use crate::report::csv::{summary_json, write_summary, CsvRecorder};
use crate::scenario::error::{exit_code, RunError, ScenarioErrors};
use crate::scenario::validate;
use crate::scenario::BUILTINS;
use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// ph-formation simulator: N controller-core agents over simulated dynamics and radio.
///
/// Without a command it runs the built-in `paper` scenario into `out/paper/`.
#[derive(Debug, Parser)]
#[command(name = "host-sim", version, about, long_about = None)]
pub struct Cli {
    /// No progress bar and no summary table (errors and warnings are still printed).
    #[arg(short, long, global = true)]
    pub quiet: bool,
    /// What to do (default: `run paper`).
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a scenario (a TOML file or a built-in name) and write its outputs.
    Run(RunArgs),
    /// Check a scenario and report every problem (exit code per kind of problem).
    Validate {
        /// Scenario file or built-in name.
        scenario: String,
        /// Override a field before validation, e.g. `--set radio.loss=0.2`.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// List the built-in scenarios.
    List,
    /// (Re)draw the plots of a run directory from its timeseries.csv and summary.json.
    Plot {
        /// The run's output directory.
        dir: PathBuf,
    },
}

/// Arguments of `host-sim run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// Scenario file or built-in name (`host-sim list`).
    #[arg(default_value = "paper")]
    pub scenario: String,
    /// Output directory (default `out/<scenario name>/`).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Simulated duration in seconds (overrides the file's `duration`).
    #[arg(long, value_name = "S")]
    pub duration: Option<f64>,
    /// Random seed (overrides the file's `seed`).
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
    /// Override any field, e.g. `--set radio.loss=0.2 --set mode=continuous`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Do not draw the plots.
    #[arg(long)]
    pub no_plots: bool,
    /// Run agent ID's controller as firmware on an emulated STM32F405 (QEMU), over an
    /// emulated UART; repeat for more agents (see docs/hil.md).
    #[arg(long = "hil", value_name = "ID")]
    pub hil: Vec<u8>,
    /// Firmware ELF for --hil [default: $HOST_SIM_FIRMWARE, else
    /// WORKSPACE/target/thumbv7em-none-eabihf/release/qemu-uart].
    #[arg(long, value_name = "PATH")]
    pub firmware: Option<PathBuf>,
    /// Seconds an emulated agent may take to answer one control tick (--hil).
    #[arg(long, value_name = "S", default_value_t = hil::DEFAULT_TIMEOUT_S)]
    pub hil_timeout: f64,
    /// Do not pin each QEMU to one CPU (--hil; pinned round robin by default, Linux).
    #[arg(long)]
    pub hil_no_pin: bool,
}

impl RunArgs {
    /// The overrides, with `--duration` and `--seed` folded in.
    pub fn overrides(&self) -> Vec<String> {
        let mut v = self.set.clone();
        if let Some(d) = self.duration {
            v.push(format!("duration={d:?}"));
        }
        if let Some(s) = self.seed {
            v.push(format!("seed={s}"));
        }
        v
    }
}

/// Parses the process arguments and runs; returns the exit code.
pub fn main() -> u8 {
    let cli = Cli::parse();
    execute(cli)
}

/// Runs a parsed command line; returns the exit code.
pub fn execute(cli: Cli) -> u8 {
    let quiet = cli.quiet;
    match cli.command {
        None => run_command(
            &RunArgs {
                scenario: "paper".to_owned(),
                out: None,
                duration: None,
                seed: None,
                set: Vec::new(),
                no_plots: false,
                hil: Vec::new(),
                firmware: None,
                hil_timeout: hil::DEFAULT_TIMEOUT_S,
                hil_no_pin: false,
            },
            quiet,
        ),
        Some(Command::Run(args)) => run_command(&args, quiet),
        Some(Command::Validate { scenario, set }) => validate_command(&scenario, &set, quiet),
        Some(Command::List) => {
            for b in BUILTINS {
                println!("{:<16} {}", b.name, b.description);
            }
            exit_code::CONVERGED
        }
        Some(Command::Plot { dir }) => match crate::report::plot::plot_run(&dir) {
            Ok(files) => {
                if !quiet {
                    for f in files {
                        println!("{}", f.display());
                    }
                }
                exit_code::CONVERGED
            }
            Err(e) => {
                eprintln!("error: cannot plot {}: {e}", dir.display());
                exit_code::IO
            }
        },
    }
}

fn report(errors: &ScenarioErrors) -> u8 {
    eprintln!("{errors}");
    errors.exit_code()
}

fn validate_command(scenario: &str, set: &[String], quiet: bool) -> u8 {
    match validate::load(scenario, set) {
        Ok(m) => {
            if !quiet {
                println!(
                    "ok: {} ({}): {} agents, {} triangles, {} edges, mode {}, estimator {}, {} s",
                    m.name,
                    m.source,
                    m.n(),
                    m.triangles.len(),
                    m.graph.edges.len(),
                    m.mode.as_str(),
                    m.estimator.as_str(),
                    m.duration
                );
            }
            exit_code::CONVERGED
        }
        Err(e) => report(&e),
    }
}

/// A progress bar that appears only once a run has taken more than a second.
struct Progress {
    quiet: bool,
    started: Instant,
    total: f64,
    bar: Option<ProgressBar>,
}

impl Progress {
    fn update(&mut self, t: f64) {
        if self.quiet {
            return;
        }
        if self.bar.is_none() && self.started.elapsed() > Duration::from_secs(1) {
            let bar = ProgressBar::with_draw_target(
                Some((self.total * 1000.0) as u64),
                ProgressDrawTarget::stderr(),
            );
            if let Ok(style) = ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:40} {msg} (eta {eta})",
            ) {
                bar.set_style(style);
            }
            self.bar = Some(bar);
        }
        if let Some(bar) = &self.bar {
            bar.set_position((t * 1000.0) as u64);
            bar.set_message(format!("t = {t:.2} / {:.2} s", self.total));
        }
    }

    fn finish(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
    }
}

/// Loads, runs and writes one scenario; returns the result and the exit code.
pub fn run_to_dir(
    model: &Model,
    out: &Path,
    plots: bool,
    quiet: bool,
) -> Result<(RunResult, Vec<PathBuf>), String> {
    run_to_dir_with(model, out, plots, quiet, None).map_err(|e| e.to_string())
}

/// [`run_to_dir`], with some agents on emulated targets when `hil` is given.
pub fn run_to_dir_with(
    model: &Model,
    out: &Path,
    plots: bool,
    quiet: bool,
    hil: Option<&HilOptions>,
) -> Result<(RunResult, Vec<PathBuf>), RunError> {
    std::fs::create_dir_all(out)
        .map_err(|e| format!("cannot create output directory {}: {e}", out.display()))?;
    // The estimate layout (for the CSV header) comes from the agents' own configurations.
    let mut layout = Vec::new();
    for i in 0..model.n() {
        let a = model.core_agent(i)?;
        let owned: Vec<_> = a.owned_estimates().collect();
        layout.extend(crate::analysis::diagnostics::resolve_estimates(
            model, i, &owned,
        )?);
    }
    let csv_path = out.join("timeseries.csv");
    let mut recorder = CsvRecorder::create(&csv_path, model, &layout)
        .map_err(|e| format!("cannot create {}: {e}", csv_path.display()))?;
    let mut progress = Progress {
        quiet,
        started: Instant::now(),
        total: model.duration,
        bar: None,
    };
    let result = match hil {
        Some(h) => hil::run(model, h, &mut recorder, &mut |t| progress.update(t)),
        None => sim::run(model, &mut recorder, &mut |t| progress.update(t)).map_err(RunError::from),
    };
    progress.finish();
    let result = result?;
    let summary = summary_json(model, &result, &layout);
    let summary_path = out.join("summary.json");
    write_summary(&summary_path, &summary)
        .map_err(|e| format!("cannot write {}: {e}", summary_path.display()))?;
    let mut files = vec![csv_path, summary_path];
    if plots {
        match crate::report::plot::plot_run(out) {
            Ok(p) => files.extend(p),
            Err(e) => eprintln!("warning: plots not drawn: {e}"),
        }
    }
    Ok((result, files))
}

fn run_command(args: &RunArgs, quiet: bool) -> u8 {
    let model = match validate::load(&args.scenario, &args.overrides()) {
        Ok(m) => m,
        Err(e) => return report(&e),
    };
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| Path::new("out").join(&model.name));
    let hil_options = if args.hil.is_empty() {
        None
    } else {
        match hil_options(args, &model, &out) {
            Ok(h) => Some(h),
            Err(e) => {
                eprintln!("error: {e}");
                return e.exit_code();
            }
        }
    };
    match run_to_dir_with(&model, &out, !args.no_plots, quiet, hil_options.as_ref()) {
        Ok((r, files)) => {
            for w in &r.warnings {
                eprintln!("warning: {w}");
            }
            if !quiet {
                print_table(&model, &r, &out, files.len());
            }
            r.outcome.exit_code()
        }
        Err(e) => {
            eprintln!("error: {e}");
            e.exit_code()
        }
    }
}

/// Checks the `--hil` arguments (agent ids, timeout, firmware ELF, QEMU) before anything
/// is written.
fn hil_options(args: &RunArgs, model: &Model, out: &Path) -> Result<HilOptions, hil::HilError> {
    hil::agent_indices(model, &args.hil)?;
    let opts = HilOptions::qemu(
        args.hil.clone(),
        args.firmware.clone(),
        out,
        args.hil_timeout,
    )?;
    if let hil::Launcher::Qemu {
        program, firmware, ..
    } = &opts.launcher
    {
        hil::preflight(program, firmware)?;
    }
    Ok(opts)
}

fn g(x: f64) -> String {
    if x == 0.0 || (1e-3..1e4).contains(&x.abs()) {
        format!("{x:.4}")
    } else {
        format!("{x:.3e}")
    }
}

fn print_table(m: &Model, r: &RunResult, out: &Path, n_files: usize) {
    let id = |i: usize| m.agents.get(i).map_or(0, |a| a.id);
    let mut rows: Vec<(&str, String)> = vec![
        ("scenario", format!("{} ({})", m.name, m.source)),
        (
            "mode / estimator",
            format!("{} / {}", m.mode.as_str(), m.estimator.as_str()),
        ),
        (
            "outcome",
            format!("{} (exit code {})", r.outcome, r.outcome.exit_code()),
        ),
        ("reason", r.reason.clone()),
        (
            "simulated",
            format!(
                "{} s of {} s in {:.2} s wall",
                g(r.final_time),
                g(m.duration),
                r.wall_seconds
            ),
        ),
        (
            "settle time",
            r.settle_time.map_or(
                "never (angle errors ≥ tolerance at the end)".to_owned(),
                |t| format!("{} s", g(t)),
            ),
        ),
        (
            "final max angle error",
            format!("{} rad", g(r.final_max_angle_error)),
        ),
        (
            "final displacement error",
            format!("{} m", g(r.final_displacement_error)),
        ),
        (
            "final velocity error",
            format!("{} m/s", g(r.final_velocity_error)),
        ),
        (
            "min estimate",
            r.min_estimate
                .map_or("none".to_owned(), |x| format!("{} m", g(x))),
        ),
        (
            "min distance",
            format!(
                "{} m (agents {}–{} at t = {} s)",
                g(r.min_distance.0),
                id(r.min_distance.2),
                id(r.min_distance.3),
                g(r.min_distance.1)
            ),
        ),
        ("V(0) → V(end)", format!("{} → {}", g(r.v0), g(r.v_final))),
        ("V max increase / V(0)", g(r.v_max_increase_rel)),
        (
            "frames sent / dropped / rejected",
            format!(
                "{} / {} / {}",
                r.frames.sent, r.frames.dropped, r.frames.rejected
            ),
        ),
        (
            "safe outputs after t = 0",
            format!(
                "{} of {} agent ticks",
                r.control.safe_after_start, r.control.ticks
            ),
        ),
        ("saturated outputs", r.control.saturated.to_string()),
    ];
    for h in &r.hil {
        rows.push((
            "emulated agent",
            format!(
                "{}: {} ticks, {} / {} frames and {} / {} bytes to / from the target, {:.1} s in round trips",
                h.agent,
                h.ticks,
                h.frames_to_target,
                h.frames_from_target,
                h.bytes_to_target,
                h.bytes_from_target,
                h.wall_s
            ),
        ));
    }
    if !r.hil.is_empty() && r.final_time > 0.0 {
        rows.push((
            "wall-clock per simulated s",
            format!("{:.3} s", r.wall_seconds / r.final_time),
        ));
    }
    rows.extend([("output", format!("{} ({n_files} files)", out.display()))]);
    if !r.orientation_kept.iter().all(|&k| k) {
        rows.push((
            "mirror flips",
            "a triangle's orientation flipped (mirror image)".to_owned(),
        ));
    }
    let w = rows
        .iter()
        .map(|(k, _)| k.chars().count())
        .max()
        .unwrap_or(0);
    let line = "-".repeat(w + 2 + 60);
    println!("{line}");
    for (k, v) in rows {
        println!("{k:<w$}  {v}");
    }
    println!("{line}");
}
