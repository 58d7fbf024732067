//! The workload of `cargo xtask bench-counts` (docs/performance.md): one case, run under
//! valgrind's callgrind, which counts only inside [`counted`]
//! (`--collect-atstart=no --toggle-collect=*counted*`), so building the model and the
//! simulator and the warm-up ticks are not counted. Prints the agent-steps counted.
//!
//! ```sh
//! counts strip N WARM TICKS   # the N-agent strip: WARM ticks, then TICKS counted (engine only)
//! counts paper DURATION       # the paper run, DURATION s, whole (diagnostics included)
//! counts crazyflie DURATION   # strip20 under world = "crazyflie", DURATION s, whole
//! counts engine SCENARIO D     # a run through the library writing nothing
//! counts rows SCENARIO D S     # the same writing timeseries.csv (every S-th row) and summary.json
//! counts write SCENARIO D DIR  # (not counted) the run's row files into DIR; prints its stride
//! counts draw DIR              # the figures and replay.html of DIR
//! counts cli ARGS…             # (not counted) host-sim ARGS…, e.g. `design … -o FILE`
//! ```
//!
//! Everything runs on one thread (a one-thread rayon pool): the counts do not depend on
//! the machine or on scheduling.

use ph_formation_sim::engine::{run, NullRecorder, SampledSim};
use ph_formation_sim::model::Model;
use ph_formation_sim::scenario::strip_model;
use ph_formation_sim::TimeSeries;
use std::process::ExitCode;

/// The counted part: `ticks` control periods of `sim` from `start` (or, with no
/// simulator, the whole run of `model`). Not inlined, so that callgrind can find it.
#[inline(never)]
fn counted(model: &Model, sim: Option<&mut SampledSim<'_>>, start: f64, ticks: usize) {
    match sim {
        Some(sim) => sim.advance_ticks(start, ticks),
        None => {
            let r = run(model, &mut NullRecorder, &mut |_| {});
            std::hint::black_box(r.ok());
        }
    }
}

/// The counted part of an outputs case: a run of `model` through the library, writing
/// nothing (`dir` = None: the engine and its verdict) or its row files and summary
/// into `dir` at `stride`.
#[inline(never)]
fn counted_outputs(model: &Model, dir: Option<&std::path::Path>, stride: Option<u64>) {
    // With rows, every row is also kept in memory: at least the cost of the rows a run
    // keeps for its figures (those it writes).
    let mut sim = ph_formation_sim::Simulation::new(model).keep_series(dir.is_some());
    if let Some(dir) = dir {
        sim = sim.write_to(dir, ph_formation_sim::WriteOptions::without_plots());
    }
    if let Some(s) = stride {
        sim = sim.row_stride(s);
    }
    std::hint::black_box(sim.run().ok());
}

/// The counted part of `draw`: the figures and the replay page of a run directory,
/// drawn from its rows in memory, as the run draws them.
#[inline(never)]
fn counted_draw(dir: &std::path::Path, rows: &TimeSeries) -> Result<(), String> {
    let plots =
        ph_formation_sim::report::plot_run_from(dir, Some(rows)).map_err(|e| e.to_string())?;
    let replay =
        ph_formation_sim::report::write_replay_from(dir, Some(rows)).map_err(|e| e.to_string())?;
    std::hint::black_box((plots, replay));
    Ok(())
}

/// `args[i]` (a scenario) with `duration=args[i + 1]`.
fn load(args: &[String], i: usize) -> Result<Model, String> {
    let scenario = args.get(i).ok_or("missing SCENARIO")?;
    let duration = args.get(i + 1).ok_or("missing DURATION")?;
    ph_formation_sim::load(scenario, &[format!("duration={duration}")]).map_err(|e| e.to_string())
}

/// Agent-steps of a whole run of `model`.
fn agent_steps(model: &Model) -> u64 {
    let ticks = (model.duration / model.control_period()).round() as u64;
    model.n() as u64 * ticks
}

fn case(args: &[String]) -> Result<u64, String> {
    let number = |i: usize, what: &str| -> Result<f64, String> {
        let text = args.get(i).ok_or(format!("missing {what}"))?;
        text.parse()
            .map_err(|_| format!("{what}: '{text}' is not a number"))
    };
    match args.first().map(String::as_str) {
        Some("strip") => {
            let (n, warm, ticks) = (number(1, "N")?, number(2, "WARM")?, number(3, "TICKS")?);
            let (n, warm, ticks) = (n as usize, warm as usize, ticks as usize);
            let model = strip_model(n, 1000.0).expect("the strip is a valid model");
            let mut sim = SampledSim::new(&model).map_err(|e| e.to_string())?;
            sim.advance_ticks(0.0, warm);
            let start = warm as f64 * model.control_period();
            counted(&model, Some(&mut sim), start, ticks);
            Ok((n * ticks) as u64)
        }
        Some("paper") => {
            let duration = number(1, "DURATION")?;
            let model = ph_formation_sim::load("paper", &[format!("duration={duration}")])
                .map_err(|e| e.to_string())?;
            counted(&model, None, 0.0, 0);
            // Per agent-step of the run: its instructions over N · (duration / period).
            let ticks = (duration / model.control_period()).round() as u64;
            Ok(model.n() as u64 * ticks)
        }
        Some("crazyflie") => {
            // docs/world.md: the 20-agent strip in world = "crazyflie" (vehicles, wind,
            // headings, own clocks, noisy bearings, the shared channel), whole.
            let duration = number(1, "DURATION")?;
            let strip20 = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/strip20.toml");
            let model = ph_formation_sim::load(
                strip20,
                &["world=crazyflie".to_owned(), format!("duration={duration}")],
            )
            .map_err(|e| e.to_string())?;
            counted(&model, None, 0.0, 0);
            let ticks = (duration / model.control_period()).round() as u64;
            Ok(model.n() as u64 * ticks)
        }
        // The outputs against the engine (docs/performance.md, "What the outputs cost").
        Some("engine") => {
            let model = load(args, 1)?;
            counted_outputs(&model, None, None);
            Ok(agent_steps(&model))
        }
        Some("rows") => {
            let model = load(args, 1)?;
            let stride = number(3, "STRIDE")? as u64;
            let dir = std::env::temp_dir().join(format!("ph-counts-rows-{}", std::process::id()));
            counted_outputs(&model, Some(&dir), Some(stride));
            let _ = std::fs::remove_dir_all(&dir);
            Ok(agent_steps(&model))
        }
        Some("write") => {
            // Not counted: the whole run's row files and summary (default budget), for `draw`.
            let model = load(args, 1)?;
            let dir = std::path::PathBuf::from(args.get(3).ok_or("missing DIR")?);
            let run = ph_formation_sim::Simulation::new(&model)
                .keep_series(false)
                .write_to(&dir, ph_formation_sim::WriteOptions::without_plots())
                .run()
                .map_err(|e| e.to_string())?;
            println!("stride {}", run.thinning.map_or(1, |t| t.stride));
            Ok(agent_steps(&model))
        }
        Some("cli") => {
            // host-sim's own command line (e.g. `design … -o FILE`), not counted.
            use clap::Parser as _;
            let cli = ph_formation_sim::cli::Cli::try_parse_from(
                std::iter::once("host-sim").chain(args[1..].iter().map(String::as_str)),
            )
            .map_err(|e| e.to_string())?;
            match ph_formation_sim::cli::execute(cli) {
                0 => Ok(0),
                code => Err(format!(
                    "host-sim {} exited with {code}",
                    args[1..].join(" ")
                )),
            }
        }
        Some("draw") => {
            let dir = std::path::PathBuf::from(args.get(1).ok_or("missing DIR")?);
            // The rows the run kept in memory: read back, not counted.
            let rows =
                TimeSeries::read_csv(&dir.join("timeseries.csv")).map_err(|e| e.to_string())?;
            counted_draw(&dir, &rows)?;
            Ok(0)
        }
        _ => Err(
            "usage: counts strip N WARM TICKS | counts paper DURATION | counts crazyflie DURATION \
             | counts engine|rows|write SCENARIO DURATION [STRIDE|DIR] | counts draw DIR"
                .into(),
        ),
    }
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build();
    let result = match pool {
        Ok(pool) => pool.install(|| case(&args)),
        Err(e) => Err(e.to_string()),
    };
    match result {
        Ok(steps) => {
            println!("agent-steps {steps}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("counts: {e}");
            ExitCode::FAILURE
        }
    }
}
