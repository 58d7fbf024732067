//! The workload of `cargo xtask bench-counts` (docs/performance.md): one case, run under
//! valgrind's callgrind, which counts only inside [`counted`]
//! (`--collect-atstart=no --toggle-collect=*counted*`), so building the model and the
//! simulator and the warm-up ticks are not counted. Prints the agent-steps counted.
//!
//! ```sh
//! counts strip N WARM TICKS   # the N-agent strip: WARM ticks, then TICKS counted (engine only)
//! counts paper DURATION       # the paper run, DURATION s, whole (diagnostics included)
//! counts crazyflie DURATION   # strip20 under world = "crazyflie", DURATION s, whole
//! ```
//!
//! Everything runs on one thread (a one-thread rayon pool): the counts do not depend on
//! the machine or on scheduling.

use ph_formation_sim::engine::{run, NullRecorder, SampledSim};
use ph_formation_sim::model::Model;
use ph_formation_sim::scenario::strip_model;
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
        _ => Err(
            "usage: counts strip N WARM TICKS | counts paper DURATION | counts crazyflie DURATION"
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
