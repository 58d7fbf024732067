//! `host-sim vehicle step`: the response of a scenario's vehicle to a horizontal
//! velocity-setpoint step from hover (`docs/world.md`), for a user to hold against a
//! logged flight. One agent of the scenario's `[plant]`, at rest, no wind; its setpoint
//! held at `speed` along `direction_deg` from `t = 0`; sampled every millisecond.

use crate::engine::plant::{new_plant, Held};
use crate::exit_code;
use crate::model::VehicleModel;
use crate::report::plot::{plot_xy, XyChart, XyLine, XyPanel, XyPoint};
use clap::{Args, Subcommand};
use ph_formation_core::Vec2;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Standard gravity (m/s²).
const G: f64 = 9.806_65;
/// The sampling step (s).
const H: f64 = 1e-3;

/// `host-sim vehicle …`.
#[derive(Debug, Subcommand)]
pub enum VehicleCommand {
    /// The response to a velocity-setpoint step from hover: DIR/step.csv (t, v_along,
    /// v_across, a, tilt_deg every ms), a plot, and the 63 % rise time, overshoot, peak
    /// acceleration and tilt.
    Step(StepArgs),
}

/// Arguments of `host-sim vehicle step`.
#[derive(Debug, Args)]
pub struct StepArgs {
    /// Scenario file or built-in name whose `[plant]` is stepped (with `--set`).
    #[arg(default_value = "formation-only")]
    pub scenario: String,
    /// Override a field, e.g. `--set world=crazyflie`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// The step's speed (m/s, > 0).
    #[arg(long)]
    pub speed: f64,
    /// The step's direction from the x axis (degrees; 45: a diagonal).
    #[arg(long, default_value_t = 0.0)]
    pub direction_deg: f64,
    /// How long to follow it (s, > 0, at most 600).
    #[arg(long, default_value_t = 5.0)]
    pub duration: f64,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
}

/// One sample of the response.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Time from the step (s).
    pub t: f64,
    /// Velocity along the step (m/s).
    pub along: f64,
    /// Velocity across it (m/s, to the left).
    pub across: f64,
    /// Horizontal acceleration (m/s²).
    pub a: f64,
    /// Tilt from vertical (degrees).
    pub tilt_deg: f64,
}

/// What the response shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Figures {
    /// First time the velocity along reaches 63.2 % of the step (s), if it does.
    pub rise_63: Option<f64>,
    /// `(max v_along − speed) / speed` (%, ≥ 0).
    pub overshoot_pct: f64,
    /// Largest horizontal acceleration (m/s²).
    pub peak_a: f64,
    /// Largest tilt (degrees).
    pub peak_tilt_deg: f64,
}

/// Checks the flags: each finite and in range, naming the flag.
pub fn check(args: &StepArgs) -> Result<(), String> {
    if !(args.speed.is_finite() && args.speed > 0.0) {
        return Err(format!(
            "--speed: must be a finite speed > 0 m/s, got {}",
            args.speed
        ));
    }
    if !args.direction_deg.is_finite() {
        return Err(format!(
            "--direction-deg: must be finite, got {}",
            args.direction_deg
        ));
    }
    if !(args.duration.is_finite() && args.duration > 0.0 && args.duration <= 600.0) {
        return Err(format!(
            "--duration: must be above 0 and at most 600 s, got {}",
            args.duration
        ));
    }
    Ok(())
}

/// The step response of `args.scenario`'s vehicle.
pub fn respond(args: &StepArgs) -> Result<Vec<Sample>, String> {
    check(args)?;
    let mut model = super::load(&args.scenario, &args.set).map_err(|e| e.to_string())?;
    if model.world.vehicle == VehicleModel::PointMass {
        return Err(format!(
            "{}: [plant] is the point mass (SPEC S1), which has no velocity loop to step; \
             give a vehicle, e.g. --set world=crazyflie or --set plant.model=crazyflie_pid",
            model.source
        ));
    }
    model.agents.truncate(1);
    if let Some(a) = model.agents.first_mut() {
        a.position = [0.0; 2];
        a.velocity = [0.0; 2];
    }
    let mut plant = new_plant(&model).map_err(|e| e.to_string())?;
    let (s, c) = args.direction_deg.to_radians().sin_cos();
    let dir = Vec2::new(c, s);
    if !plant.set_velocity_setpoint(0, dir * args.speed) {
        return Err("the vehicle takes no velocity setpoint".to_owned());
    }
    let held = Held {
        forces: &[Vec2::zeros()],
        wind: &[],
    };
    let n = (args.duration / H).round() as usize;
    let mut v = Vec::with_capacity(n + 1);
    let mut tilt = Vec::with_capacity(n + 1);
    for k in 0..=n {
        if k > 0 {
            plant.step(&held, H, 1, None);
        }
        v.push(plant.v().first().copied().unwrap_or_else(Vec2::zeros));
        tilt.push(plant.tilt(0));
    }
    let accel = |k: usize| -> f64 {
        let (lo, hi) = (k.saturating_sub(1), (k + 1).min(n));
        match (v.get(lo), v.get(hi)) {
            (Some(a), Some(b)) if hi > lo => ((b - a) / ((hi - lo) as f64 * H)).norm(),
            _ => 0.0,
        }
    };
    Ok((0..=n)
        .map(|k| {
            let vk = v.get(k).copied().unwrap_or_else(Vec2::zeros);
            let a = accel(k);
            let t = tilt
                .get(k)
                .copied()
                .flatten()
                .unwrap_or_else(|| (a / G).atan());
            Sample {
                t: k as f64 * H,
                along: vk.dot(&dir),
                across: dir.x * vk.y - dir.y * vk.x,
                a,
                tilt_deg: t.to_degrees(),
            }
        })
        .collect())
}

/// The figures of a response to a step of `speed`.
pub fn figures(samples: &[Sample], speed: f64) -> Figures {
    let target = (1.0 - (-1.0f64).exp()) * speed;
    let rise_63 = samples.windows(2).find_map(|w| match w {
        [p, q] if p.along < target && q.along >= target => {
            Some(p.t + (target - p.along) / (q.along - p.along) * (q.t - p.t))
        }
        _ => None,
    });
    let max_along = samples.iter().map(|s| s.along).fold(f64::MIN, f64::max);
    Figures {
        rise_63,
        overshoot_pct: ((max_along - speed) / speed * 100.0).max(0.0),
        peak_a: samples.iter().map(|s| s.a).fold(0.0, f64::max),
        peak_tilt_deg: samples.iter().map(|s| s.tilt_deg).fold(0.0, f64::max),
    }
}

/// `host-sim vehicle step`: writes DIR/step.csv and the plot, prints the figures.
pub(super) fn command(cmd: &VehicleCommand, quiet: bool) -> u8 {
    let VehicleCommand::Step(args) = cmd;
    let samples = match respond(args) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: vehicle step: {e}");
            return exit_code::USAGE;
        }
    };
    let mut csv = String::from("t,v_along,v_across,a,tilt_deg\n");
    for s in &samples {
        let _ = writeln!(
            csv,
            "{:.3},{},{},{},{}",
            s.t, s.along, s.across, s.a, s.tilt_deg
        );
    }
    let path = args.out.join("step.csv");
    if let Err(e) = std::fs::create_dir_all(&args.out).and_then(|()| std::fs::write(&path, csv)) {
        eprintln!("error: vehicle step: cannot write {}: {e}", path.display());
        return exit_code::IO;
    }
    let f = figures(&samples, args.speed);
    let line = |label: &str, y: fn(&Sample) -> f64| XyLine {
        label: label.to_owned(),
        points: samples
            .iter()
            .step_by(5)
            .map(|s| XyPoint {
                x: s.t,
                y: y(s),
                lo: y(s),
                hi: y(s),
            })
            .collect(),
        join: true,
    };
    let chart = XyChart {
        title: format!(
            "velocity step {} m/s at {}°",
            args.speed, args.direction_deg
        ),
        subtitle: format!("{} {}", args.scenario, args.set.join(" ")),
        x_label: "t from the step (s)".to_owned(),
        categories: None,
        panels: vec![
            XyPanel {
                y_label: "velocity (m/s)".to_owned(),
                y_range: None,
                lines: vec![line("v_along", |s| s.along), line("v_across", |s| s.across)],
            },
            XyPanel {
                y_label: "a (m/s²), tilt (°)".to_owned(),
                y_range: None,
                lines: vec![line("a", |s| s.a), line("tilt_deg", |s| s.tilt_deg)],
            },
        ],
    };
    if let Err(e) = plot_xy(&args.out, "step", &chart) {
        eprintln!("error: vehicle step: cannot draw the plot: {e}");
        return exit_code::IO;
    }
    if !quiet {
        println!("wrote {}", path.display());
    }
    let rise = f
        .rise_63
        .map_or_else(|| "not reached".to_owned(), |t| format!("{t:.3} s"));
    println!(
        "63 % rise time {rise}, overshoot {:.1} %, peak acceleration {:.2} m/s², peak tilt {:.1}°",
        f.overshoot_pct, f.peak_a, f.peak_tilt_deg
    );
    exit_code::CONVERGED
}
