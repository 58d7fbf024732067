//! The command line: `host-sim [run|validate|list|plot|design|export|sweep|vehicle|compare|flight]` (exit codes
//! in [`crate::exit_code`] and `docs/outputs.md`): a thin client of the library API
//! ([`crate::Simulation`]).

mod compare;
mod design;
mod export;
mod run;
mod serve;
mod step;
mod sweep;
mod vehicle;
mod view;

pub use compare::{CompareArgs, FlightArgs};
pub use design::{DesignArgs, Shape};
pub use serve::ServeArgs;

use crate::engine::hil;
use crate::exit_code;
use crate::scenario::{ScenarioErrors, BUILTINS};
use clap::{Args, Parser, Subcommand};
use design::design_command;
use run::run_command;
use std::path::PathBuf;

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
        /// Scenario file, built-in name, or `-` (stdin).
        scenario: String,
        /// Override a field before validation, e.g. `--set radio.loss=0.2`.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Also draw the formation (labelled agents, triangles, desired angles, leader
        /// edge, initial and target positions) into FILE (.png or .svg).
        #[arg(long, value_name = "FILE")]
        plot: Option<PathBuf>,
    },
    /// List the built-in scenarios.
    List,
    /// (Re)draw the plots of a run directory from its timeseries.csv and summary.json.
    Plot {
        /// The run's output directory.
        dir: PathBuf,
    },
    /// Design a formation from a shape: a points file or a built-in generator → a
    /// complete scenario (stdout or -o), quality figures on stderr.
    Design(DesignArgs),
    /// Run a Monte Carlo sweep (docs/sweeps.md) on every core, or merge its shards.
    Sweep(sweep::SweepArgs),
    /// Write agents' configurations as the C API's checked blobs (docs/c-api.md).
    Export(ExportArgs),
    /// The scenario's drones as simulated Crazyflies that cflib flies over
    /// `udp://127.0.0.1:PORT+k`, paced at real time (docs/crazyflie.md).
    Serve(ServeArgs),
    /// A vehicle on its own: `vehicle step` (docs/world.md).
    #[command(subcommand)]
    Vehicle(step::VehicleCommand),
    /// Print the path of a run's replay.html (writing it if missing), or of a sweep's
    /// sweep.html, and open it in a browser when there is one ($BROWSER, else xdg-open
    /// with a display).
    View {
        /// The run's (or the sweep's) output directory.
        dir: PathBuf,
        /// Only print the path.
        #[arg(long)]
        no_open: bool,
    },
    /// Hold a run against a flight of the swarm tool (positions, angle errors, faults on
    /// one time axis), or a step-test log against `host-sim vehicle step`; prints the
    /// differences, writes compare.json and figures (docs/crazyflie.md).
    Compare(CompareArgs),
    /// A flight log of the swarm tool as a run directory: timeseries.csv, summary.json,
    /// replay.html (`host-sim view DIR`) and, with --mcap, run.mcap.
    Flight(FlightArgs),
}

/// Arguments of `host-sim export`.
#[derive(Debug, Args)]
pub struct ExportArgs {
    /// Scenario file or built-in name.
    pub scenario: String,
    /// The agent's id in the scenario.
    #[arg(
        long,
        value_name = "ID",
        required_unless_present = "all",
        conflicts_with = "all"
    )]
    pub agent: Option<String>,
    /// Every agent: `-o DIR` gets `agent<ID>.blob` each and `ph_blobs.c`/`.h` (all blobs
    /// in one C table indexed by wire id, docs/crazyflie.md).
    #[arg(long, requires = "out")]
    pub all: bool,
    /// Refuse limits beyond what this vehicle can do (force over mass, `v*`).
    #[arg(long, value_name = "NAME")]
    pub vehicle: Option<vehicle::Vehicle>,
    /// Override a field first, e.g. `--set integrity=link`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Output file (default: standard output); with `--all` the directory.
    #[arg(short, long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Write C source (`const uint8_t ph_blob[]`) instead of the raw bytes.
    #[arg(long, conflicts_with = "all")]
    pub c_array: bool,
}

/// Arguments of `host-sim run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// Scenario file, built-in name (`host-sim list`), or `-` to read it from stdin.
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
    /// Write only summary.json: no timeseries.csv and no plots (for huge runs; to keep a
    /// thinner series instead, `--set integration.log_interval=S`).
    #[arg(long)]
    pub summary_only: bool,
    /// Also write run.mcap: the logged rows and the run's events as MCAP, for Foxglove
    /// and PlotJuggler (docs/outputs.md). Changes no other output.
    #[arg(long)]
    pub mcap: bool,
    /// Write every logged row into timeseries.csv (and run.mcap) whatever the size. By
    /// default a series over 8 M cells (rows × columns, ~160 MB) keeps every 2nd, 5th,
    /// 10th, 20th, … row, to at most 1 M cells, and says so (docs/outputs.md).
    #[arg(long)]
    pub full_rate: bool,
    /// Worker threads of a large run (at least 2,048 agents; default one per core). The
    /// results are the same for any number.
    #[arg(short = 'j', long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub jobs: Option<u16>,
    /// Run agent ID's controller as firmware on an emulated STM32F405 (QEMU), over an
    /// emulated UART; ID is the agent's id as written in the scenario (an integer or a
    /// short name); repeat for more agents (see docs/hil.md).
    #[arg(long = "hil", value_name = "ID")]
    pub hil: Vec<String>,
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
                summary_only: false,
                mcap: false,
                full_rate: false,
                jobs: None,
                hil: Vec::new(),
                firmware: None,
                hil_timeout: hil::DEFAULT_TIMEOUT_S,
                hil_no_pin: false,
            },
            quiet,
        ),
        Some(Command::Run(args)) => run_command(&args, quiet),
        Some(Command::Export(args)) => export::export_command(&args, quiet),
        Some(Command::Serve(args)) => serve::serve_command(&args),
        Some(Command::Vehicle(cmd)) => step::command(&cmd, quiet),
        Some(Command::Validate {
            scenario,
            set,
            plot,
        }) => validate_command(&scenario, &set, plot.as_deref(), quiet),
        Some(Command::Design(args)) => design_command(&args, quiet),
        Some(Command::List) => {
            for b in BUILTINS {
                println!("{:<16} {}", b.name, b.description);
            }
            exit_code::CONVERGED
        }
        Some(Command::Sweep(args)) => sweep::command(&args, quiet),
        Some(Command::View { dir, no_open }) => view::view_command(&dir, no_open),
        Some(Command::Compare(args)) => compare::compare_command(&args, quiet),
        Some(Command::Flight(args)) => compare::flight_command(&args, quiet),
        Some(Command::Plot { dir }) => match crate::report::plot_run(&dir) {
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

/// Loads a scenario: `-` reads it from stdin, anything else is a file or a built-in.
pub(crate) fn load(scenario: &str, set: &[String]) -> Result<crate::model::Model, ScenarioErrors> {
    if scenario != "-" {
        return crate::api::load(scenario, set);
    }
    let mut text = String::new();
    use std::io::Read;
    if let Err(e) = std::io::stdin().read_to_string(&mut text) {
        return Err(ScenarioErrors(vec![crate::scenario::ScenarioError::new(
            crate::scenario::ErrorKind::Io,
            "<stdin>",
            "",
            format!("cannot read: {e}"),
        )]));
    }
    crate::api::load_toml(&text, "<stdin>", set)
}

/// Draws the formation of the scenario `text` into `file`.
fn plot_formation_of(
    text: &str,
    name: &str,
    file: &std::path::Path,
) -> Result<(), design::WriteError> {
    let m = crate::api::load_toml(text, name, &[])?;
    Ok(crate::report::plot::plot_formation(&m, file)?)
}

fn validate_command(
    scenario: &str,
    set: &[String],
    plot: Option<&std::path::Path>,
    quiet: bool,
) -> u8 {
    match load(scenario, set) {
        Ok(m) => {
            if let Some(file) = plot {
                if let Err(e) = crate::report::plot::plot_formation(&m, file) {
                    eprintln!("error: {e}");
                    return exit_code::IO;
                }
            }
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
                if let Some(auto) = &m.comm_auto {
                    println!("note: {}", crate::engine::load::auto_note(auto));
                }
            }
            // Printed even with --quiet, as warnings are.
            for w in crate::engine::model_notes(&m) {
                eprintln!("warning: {w}");
            }
            if let Some(w) = crate::engine::load::overload_warning(&m) {
                eprintln!("warning: {w}");
            }
            for w in view_warnings(&m) {
                eprintln!("warning: {w}");
            }
            exit_code::CONVERGED
        }
        Err(e) => report(&e),
    }
}

/// `validate`'s warnings when a camera (`[sensors.camera]`) leaves an agent without one of
/// its triangles' neighbours: at the initial positions, and in the target shape as it
/// starts (its first triangle's base edge where it is; the leader edge may turn it).
fn view_warnings(m: &crate::model::Model) -> Vec<String> {
    let start: Vec<[f64; 2]> = m.agents.iter().map(|a| a.position).collect();
    [
        ("at the initial positions", start.as_slice()),
        ("in the target shape", m.target.positions.as_slice()),
    ]
    .into_iter()
    .filter_map(|(when, q)| crate::engine::view_note(m, q).map(|w| format!("{when}, {w}")))
    .collect()
}
