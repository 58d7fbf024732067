//! The library on its own: load the built-in `paper` scenario, run it in memory (no file
//! written), and read the outcome, the summary and the time series.
//!
//! ```sh
//! cargo run -p ph-formation-sim --release --example paper
//! ```
//!
//! Exits with an error unless the formation converges (`tests/api.rs` runs it).

use ph_formation_sim::{Outcome, Simulation};

/// Runs `paper` for 60 s and prints what it found.
pub fn main() -> Result<(), Box<dyn std::error::Error>> {
    // A file path, a built-in name or (`ph_formation_sim::load_toml`) TOML text; overrides as
    // with `--set`.
    let model = ph_formation_sim::load("paper", &["duration=60".to_owned()])?;
    let run = Simulation::new(&model).run()?;

    let r = &run.result;
    println!("{}: {} ({})", model.name, r.outcome, r.reason);
    if let Some(t) = r.settle_time {
        println!("every angle within tolerance from t = {t:.2} s");
    }
    let summary = run.summary_json(&model);
    println!("summary.json would say V0 = {}", summary["V0"]);

    let series = run.series.as_ref().ok_or("no time series kept")?;
    let (t, v) = (
        series.column("t").ok_or("no column t")?,
        series.column("V").ok_or("no column V")?,
    );
    println!(
        "{} rows of {} columns",
        series.len(),
        series.columns().len()
    );
    for k in (0..series.len()).step_by(series.len().div_ceil(6).max(1)) {
        println!("  t = {:6.2} s   V = {:10.4}", t[k], v[k]);
    }
    if r.outcome != Outcome::Converged {
        return Err(format!("expected convergence, got {}", r.outcome).into());
    }
    Ok(())
}
