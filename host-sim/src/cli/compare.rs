//! `host-sim compare` and `host-sim flight` (docs/crazyflie.md "Flights beside
//! simulations"): a run against a flight of the same scenario, a step-test log against
//! `host-sim vehicle step`, and a flight log as a run directory (replay page, MCAP).

use crate::exit_code;
use crate::model::Model;
use crate::report::flight::{
    compare, compare_step, plot_overlay, plot_step, step_csv, write_flight_dir, write_overlay,
    Clock, FlightError, FlightLog, FlightSeries, Options, RunSeries,
};
use clap::Args;
use serde_json::Value;
use std::path::{Path, PathBuf};

/// Arguments of `host-sim compare`.
#[derive(Debug, Args)]
pub struct CompareArgs {
    /// `host-sim run`'s output directory (a flight comparison), or `host-sim vehicle
    /// step`'s output directory or its step.csv (a step comparison).
    pub reference: PathBuf,
    /// The swarm tool's log: `swarm.py fly --log` (against a run) or `swarm.py step
    /// --log` (against a vehicle step).
    pub log: PathBuf,
    /// Flight: the scenario flown (default: the run's summary.json `source`).
    #[arg(long, value_name = "SCENARIO")]
    pub scenario: Option<String>,
    /// Flight: override a field of the scenario, e.g. `--set world=crazyflie`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Flight: the log's clock (`t_s`: real drones, serve --speed 1; `drone_ms`: served
    /// drones at any --speed).
    #[arg(long, value_enum, default_value_t)]
    pub clock: Clock,
    /// Flight: the time on the log's clock that is the run's t = 0 (default: the first
    /// row in state formation).
    #[arg(long, value_name = "S")]
    pub start: Option<f64>,
    /// Flight: converged once the largest angle error stays at most this (degrees).
    #[arg(long, value_name = "DEG", default_value_t = 2.0)]
    pub settle_deg: f64,
    /// Flight: exit 1 unless every agent's RMS position difference (common start) is at
    /// most this (m).
    #[arg(long, value_name = "M")]
    pub tolerance_m: Option<f64>,
    /// Step: the step's speed (m/s), as given to swarm.py step and host-sim vehicle step.
    #[arg(long, value_name = "M/S")]
    pub speed: Option<f64>,
    /// Step: exit 1 unless the RMS velocity difference is at most this (m/s).
    #[arg(long, value_name = "M/S", default_value_t = 0.03)]
    pub tolerance: f64,
    /// Step: the agent's rows of the log (default: every row).
    #[arg(long, value_name = "ID")]
    pub agent: Option<String>,
    /// Where compare.json and the figures go (default: REFERENCE/compare, or the step
    /// file's directory's compare/).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Do not draw the figures nor write the overlay's replay page (OUT/overlay/).
    #[arg(long)]
    pub no_plots: bool,
}

/// Arguments of `host-sim flight`.
#[derive(Debug, Args)]
pub struct FlightArgs {
    /// The swarm tool's flight log (`swarm.py fly --log`).
    pub log: PathBuf,
    /// The scenario flown (agent ids, edges, angle targets).
    #[arg(long, value_name = "SCENARIO")]
    pub scenario: String,
    /// Override a field of the scenario.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// The log's clock (see `host-sim compare --clock`).
    #[arg(long, value_enum, default_value_t)]
    pub clock: Clock,
    /// The time on the log's clock of the formation's start (default: the first row in
    /// state formation).
    #[arg(long, value_name = "S")]
    pub start: Option<f64>,
    /// Output directory: timeseries.csv, summary.json, replay.html (host-sim view DIR).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Also write run.mcap.
    #[arg(long)]
    pub mcap: bool,
}

/// The reference's kind: a run directory, or a vehicle step's file.
enum Kind {
    Run,
    Step(PathBuf),
}

fn kind(reference: &Path) -> Result<Kind, String> {
    if reference.is_dir() && reference.join("timeseries.csv").is_file() {
        return Ok(Kind::Run);
    }
    let step = step_csv(reference);
    let header = std::fs::read_to_string(&step)
        .ok()
        .and_then(|t| t.lines().next().map(str::to_owned))
        .unwrap_or_default();
    if header.split(',').any(|c| c.trim() == "v_along") {
        return Ok(Kind::Step(step));
    }
    Err(format!(
        "{}: neither host-sim run's output directory (no timeseries.csv) nor host-sim \
         vehicle step's output (step.csv with a v_along column)",
        reference.display()
    ))
}

fn load_model(scenario: &str, set: &[String]) -> Result<Model, u8> {
    super::load(scenario, set).map_err(|e| super::report(&e))
}

fn fail(e: &FlightError) -> u8 {
    eprintln!("error: {e}");
    match e {
        FlightError::Write { .. } => exit_code::IO,
        _ => exit_code::USAGE,
    }
}

fn write_json(dir: &Path, json: &Value) -> Result<PathBuf, u8> {
    let path = dir.join("compare.json");
    let text = serde_json::to_string_pretty(json).unwrap_or_default() + "\n";
    std::fs::create_dir_all(dir)
        .and_then(|()| std::fs::write(&path, text))
        .map_err(|e| {
            eprintln!("error: cannot write {}: {e}", path.display());
            exit_code::IO
        })?;
    Ok(path)
}

/// `host-sim compare`.
pub(super) fn compare_command(args: &CompareArgs, quiet: bool) -> u8 {
    let step = match kind(&args.reference) {
        Ok(Kind::Run) => None,
        Ok(Kind::Step(p)) => Some(p),
        Err(e) => {
            eprintln!("error: {e}");
            return exit_code::USAGE;
        }
    };
    let result = match step {
        Some(p) => step_command(args, &p, quiet),
        None => flight_compare(args, quiet),
    };
    result.unwrap_or_else(|code| code)
}

fn step_command(args: &CompareArgs, step: &Path, quiet: bool) -> Result<u8, u8> {
    let Some(speed) = args.speed.filter(|s| s.is_finite() && *s > 0.0) else {
        eprintln!(
            "error: --speed: a step comparison needs the step's speed (m/s, > 0), as given \
             to swarm.py step and host-sim vehicle step"
        );
        return Err(exit_code::USAGE);
    };
    if !(args.tolerance.is_finite() && args.tolerance >= 0.0) {
        eprintln!("error: --tolerance: must be finite and ≥ 0 m/s");
        return Err(exit_code::USAGE);
    }
    let c = compare_step(&args.log, step, speed, args.agent.as_deref()).map_err(|e| fail(&e))?;
    let within = c.rms <= args.tolerance;
    println!(
        "compare: step vs host-sim vehicle step: rms {:.4} m/s, max {:.4} m/s (shift {} ms, \
         {} samples): {} {} m/s",
        c.rms,
        c.max,
        c.shift_ms,
        c.samples,
        if within { "within" } else { "beyond" },
        args.tolerance
    );
    let out = args.out.clone().unwrap_or_else(|| {
        step.parent()
            .unwrap_or_else(|| Path::new("."))
            .join("compare")
    });
    let json = c.json(&args.log, step, speed, args.tolerance);
    let path = write_json(&out, &json)?;
    let mut files = vec![path];
    if !args.no_plots {
        let sub = format!("{} against {}", args.log.display(), step.display());
        files.extend(plot_step(&out, &c, &sub).map_err(|e| {
            eprintln!("error: {e}");
            exit_code::IO
        })?);
    }
    if !quiet {
        for f in files {
            println!("wrote {}", f.display());
        }
    }
    Ok(if within {
        exit_code::CONVERGED
    } else {
        exit_code::IO
    })
}

/// The scenario of a run: `--scenario`, else its summary.json's `source`.
fn run_scenario(args: &CompareArgs) -> Result<String, u8> {
    if let Some(s) = &args.scenario {
        return Ok(s.clone());
    }
    let path = args.reference.join("summary.json");
    let source = std::fs::read_to_string(&path)
        .ok()
        .and_then(|t| serde_json::from_str::<Value>(&t).ok())
        .and_then(|v| v["source"].as_str().map(str::to_owned))
        .filter(|s| s != "<stdin>");
    source.ok_or_else(|| {
        eprintln!(
            "error: {}: no scenario source to read: give --scenario (the file or built-in \
             the run and the flight used)",
            path.display()
        );
        exit_code::USAGE
    })
}

fn flight_compare(args: &CompareArgs, quiet: bool) -> Result<u8, u8> {
    if args.speed.is_some() {
        eprintln!("error: --speed: only for a step comparison (REFERENCE is a run directory)");
        return Err(exit_code::USAGE);
    }
    if !(args.settle_deg.is_finite() && args.settle_deg > 0.0) {
        eprintln!("error: --settle-deg: must be a finite angle > 0");
        return Err(exit_code::USAGE);
    }
    if args
        .tolerance_m
        .is_some_and(|t| !(t.is_finite() && t >= 0.0))
    {
        eprintln!("error: --tolerance-m: must be finite and ≥ 0 m");
        return Err(exit_code::USAGE);
    }
    let scenario = run_scenario(args)?;
    let model = load_model(&scenario, &args.set)?;
    let log = FlightLog::read(&args.log, args.clock).map_err(|e| fail(&e))?;
    let series = FlightSeries::new(&log, &model, args.start).map_err(|e| fail(&e))?;
    let run = RunSeries::read(&args.reference, &model).map_err(|e| fail(&e))?;
    let options = Options {
        settle_deg: args.settle_deg,
        tolerance_m: args.tolerance_m,
    };
    let c = compare(&run, &log, &series, &model, options).map_err(|e| fail(&e))?;
    print!("{}", report(&c.json));
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| args.reference.join("compare"));
    let mut files = vec![write_json(&out, &c.json)?];
    if !args.no_plots {
        let sub = format!(
            "{} ({}) against {}",
            args.reference.display(),
            model.name,
            args.log.display()
        );
        files.extend(plot_overlay(&out, &c.overlay, &model, &sub).map_err(|e| {
            eprintln!("error: {e}");
            exit_code::IO
        })?);
        let overlay = out.join("overlay");
        files.push(
            write_overlay(&overlay, &c.overlay, &model, &args.reference, &args.log)
                .map_err(|e| fail(&e))?,
        );
    }
    if !quiet {
        for f in files {
            println!("wrote {}", f.display());
        }
    }
    Ok(match c.within {
        Some(false) => exit_code::IO,
        _ => exit_code::CONVERGED,
    })
}

/// A number of `compare.json` with `digits` decimals, `-` when null.
fn num(v: &Value, digits: usize) -> String {
    v.as_f64()
        .map_or_else(|| "-".to_owned(), |x| format!("{x:.digits$}"))
}

/// The printed differences.
fn report(j: &Value) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let a = &j["alignment"];
    let _ = writeln!(
        s,
        "compare: {} against {}: {} instants, t = 0 to {} s from the formation's start \
         (the flight's {} s on its clock; common-start offset ({}, {}) m)",
        j["run"].as_str().unwrap_or(""),
        j["flight"].as_str().unwrap_or(""),
        a["instants"],
        num(&a["window_s"][1], 2),
        num(&a["flight_start_s"], 3),
        num(&a["common_start_offset_m"][0], 3),
        num(&a["common_start_offset_m"][1], 3),
    );
    let _ = writeln!(
        s,
        "  agent  rms (m)  rms common start (m)  max (m)  start offset (m)"
    );
    for g in j["agents"].as_array().into_iter().flatten() {
        let id = match &g["agent"] {
            Value::String(x) => x.clone(),
            other => other.to_string(),
        };
        let _ = writeln!(
            s,
            "  {id:<6} {:>7}  {:>20}  {:>7}  {:>16}",
            num(&g["rms_m"], 3),
            num(&g["rms_common_start_m"], 3),
            num(&g["max_m"], 3),
            num(&g["start_offset_m"], 3),
        );
    }
    let e = &j["angle_error_deg"];
    let _ = writeln!(
        s,
        "largest angle error: run {}°, flight {}° (at the end: {}°, {}°)",
        num(&e["run_worst"], 2),
        num(&e["flight_worst"], 2),
        num(&e["run_final"], 2),
        num(&e["flight_final"], 2),
    );
    let c = &j["convergence_s"];
    let _ = writeln!(
        s,
        "converged (largest angle error within {}° to the end): run {} s, flight {} s",
        num(&c["threshold_deg"], 1),
        num(&c["run"], 2),
        num(&c["flight"], 2),
    );
    let f = &j["faults"];
    let events = f["run"]["events"].as_array().map_or(0, Vec::len);
    let holds = |p: &Value| {
        p.as_array()
            .into_iter()
            .flatten()
            .map(|a| format!("{}:{}/{}", a["agent"], a["hold_ticks"], a["landings"]))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let changes: Vec<String> = f["flight"]["changes"]
        .as_array()
        .into_iter()
        .flatten()
        .filter(|c| c["state"] != "formation" && c["state"] != "idle" || c["fault"] != 0)
        .map(|c| {
            format!(
                "{} {} fault {} at {} s",
                c["agent"],
                c["state"].as_str().unwrap_or(""),
                c["fault"],
                num(&c["t"], 2)
            )
        })
        .collect();
    let _ = writeln!(
        s,
        "faults: run {events} events, hold ticks/landings {}; flight hold ticks/landings {}; \
         flight holds, landings, faults: {}",
        holds(&f["run"]["policy"]),
        holds(&f["flight"]["policy"]),
        if changes.is_empty() {
            "none".to_owned()
        } else {
            changes.join(", ")
        }
    );
    if let Some(w) = j["within_tolerance"].as_bool() {
        let _ = writeln!(
            s,
            "every agent's rms (common start) {} {} m",
            if w { "within" } else { "beyond" },
            num(&j["tolerance_m"], 3)
        );
    }
    s
}

/// `host-sim flight`.
pub(super) fn flight_command(args: &FlightArgs, quiet: bool) -> u8 {
    let run = || -> Result<Vec<PathBuf>, u8> {
        let model = load_model(&args.scenario, &args.set)?;
        let log = FlightLog::read(&args.log, args.clock).map_err(|e| fail(&e))?;
        let series = FlightSeries::new(&log, &model, args.start).map_err(|e| fail(&e))?;
        write_flight_dir(&log, &series, &model, &args.out, args.mcap).map_err(|e| fail(&e))
    };
    match run() {
        Ok(files) => {
            if !quiet {
                for f in files {
                    println!("wrote {}", f.display());
                }
            }
            exit_code::CONVERGED
        }
        Err(code) => code,
    }
}
