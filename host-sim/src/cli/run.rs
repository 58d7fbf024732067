//! `host-sim run`: load, check the `--hil` request, run through the library API with a
//! progress bar, print the summary table.

use super::{report, RunArgs};
use crate::api::{self, Simulation};
use crate::engine::hil::{self, HilOptions};
use crate::model::Model;
use crate::report::{summary_table, SeriesBudget};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::Path;
use std::time::{Duration, Instant};

/// A progress bar that appears only once a run has taken more than a second.
pub(super) struct Progress {
    quiet: bool,
    started: Instant,
    total: f64,
    bar: Option<ProgressBar>,
}

impl Progress {
    pub(super) fn new(quiet: bool, total: f64) -> Self {
        Self {
            quiet,
            started: Instant::now(),
            total,
            bar: None,
        }
    }
}

impl api::Progress for Progress {
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

pub(super) fn run_command(args: &RunArgs, quiet: bool) -> u8 {
    let model = match super::load(&args.scenario, &args.overrides()) {
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
    let mut progress = Progress::new(quiet, model.duration);
    let mut sim = Simulation::new(&model)
        .keep_series(false)
        .write_to(
            &out,
            crate::api::WriteOptions {
                plots: !args.no_plots,
            },
        )
        .csv(!args.summary_only)
        .mcap(args.mcap)
        .series_budget(if args.full_rate {
            SeriesBudget::FULL_RATE
        } else {
            SeriesBudget::DEFAULT
        })
        .progress(&mut progress);
    if let Some(n) = args.jobs {
        // One run per process: size rayon's global pool, so that the run stays on this
        // thread. (`Simulation::threads` runs it on a worker of a private pool, whose
        // allocator arena cannot reuse what loading the scenario freed on this one: a
        // 100,000-agent run then peaks ~0.6 GB higher.) The private pool only if the
        // global one already exists.
        let global = rayon::ThreadPoolBuilder::new()
            .num_threads(usize::from(n))
            .build_global();
        if global.is_err() {
            sim = sim.threads(usize::from(n));
        }
    }
    if let Some(h) = &hil_options {
        sim = sim.hil(h);
    }
    match sim.run() {
        Ok(run) => {
            if let Some(e) = &run.plot_error {
                eprintln!("warning: plots not drawn: {e}");
            }
            if let Some(e) = &run.replay_error {
                eprintln!("warning: replay.html not written: {e}");
            }
            let r = &run.result;
            for w in &r.warnings {
                eprintln!("warning: {w}");
            }
            if !quiet {
                print!("{}", summary_table(&model, r, &out, run.files.len()));
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
#[allow(irrefutable_let_patterns)] // QEMU is the only launcher without `fake-target`.
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
