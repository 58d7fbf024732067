//! `host-sim sweep`: run a sweep file (or a built-in sweep) on every core with a progress
//! bar, Ctrl-C keeping what finished; `host-sim sweep merge` combines shard outputs and
//! `host-sim sweep plot` redraws a sweep's figures.

use crate::exit_code;
use crate::sweep::{self, Control, Manifest, Plan, Shard, ShardArg, SweepError, BUILTIN_SWEEPS};
use clap::{Args, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Arguments of `host-sim sweep`.
#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct SweepArgs {
    /// `merge`: combine shard outputs.
    #[command(subcommand)]
    pub command: Option<SweepCommand>,
    /// Sweep file or built-in sweep name (`--list`); see docs/sweeps.md. With `--resume`
    /// it may be left out (read from DIR/sweep.json).
    pub sweep: Option<String>,
    /// Continue the sweep whose output is DIR (after Ctrl-C, SIGTERM, a time limit, a
    /// crash or `--max-runs`): its finished runs are kept, the others run; the files at the
    /// end are those of an uninterrupted run. A DIR without sweep.json starts afresh.
    #[arg(long, value_name = "DIR", conflicts_with = "out")]
    pub resume: Option<PathBuf>,
    /// Output directory (default `out/sweeps/<name>/`, a shard's in `shard-K-of-N/` below).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Runs per point (replaces the file's `runs`).
    #[arg(long, value_name = "N")]
    pub runs: Option<u64>,
    /// Run only shard K of N (jobs j with j mod N = K − 1); merge with `sweep merge`.
    /// `auto`: K and N from a Slurm job array (SLURM_ARRAY_TASK_ID, _MIN, _MAX, _COUNT)
    /// or a Kubernetes Indexed Job (JOB_COMPLETION_INDEX, with --shards).
    #[arg(long, value_name = "K/N|auto")]
    pub shard: Option<ShardArg>,
    /// With `--shard auto`: the number of shards N (Kubernetes: the Job's `completions`;
    /// Slurm: task ids are then 1 to N, so one task can be resubmitted alone).
    #[arg(long, value_name = "N", requires = "shard")]
    pub shards: Option<u64>,
    /// Start at most N runs in this session, then stop as Ctrl-C does (`--resume` goes on).
    #[arg(long, value_name = "N")]
    pub max_runs: Option<u64>,
    /// Run a sweep above the disk or time limit (20 GB of runs.csv, 24 h estimated).
    #[arg(long)]
    pub allow_large: bool,
    /// Override a base scenario field for every run, as for `run` (`--set duration=20`).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Worker threads (default: one per core).
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,
    /// Do not draw the figures.
    #[arg(long)]
    pub no_plots: bool,
    /// List the built-in sweeps.
    #[arg(long)]
    pub list: bool,
}

/// `host-sim sweep merge`.
#[derive(Debug, Subcommand)]
pub enum SweepCommand {
    /// Combine the outputs of every shard of one sweep into what one run writes.
    Merge {
        /// Output directory of the merged sweep.
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// The shards' output directories.
        #[arg(required = true)]
        shards: Vec<PathBuf>,
        /// Do not draw the figures.
        #[arg(long)]
        no_plots: bool,
    },
    /// (Re)draw the figures of a sweep's output directory from its sweep.json and runs.csv.
    Plot {
        /// The sweep's output directory.
        dir: PathBuf,
    },
}

/// Set by Ctrl-C: no new run starts.
static STOP: AtomicBool = AtomicBool::new(false);

fn fail(e: &SweepError) -> u8 {
    eprintln!("error: {e}");
    e.code
}

/// Runs `host-sim sweep …`; returns the exit code.
pub(super) fn command(args: &SweepArgs, quiet: bool) -> u8 {
    if let Some(SweepCommand::Merge {
        out,
        shards,
        no_plots,
    }) = &args.command
    {
        return match sweep::merge_into(shards, out, !no_plots) {
            Ok((m, stats, files)) => {
                if !quiet {
                    print!("{}", sweep::table::markdown(&m, &stats));
                    println!("wrote {} files to {}", files.len(), out.display());
                }
                if m.interrupted {
                    for p in sweep::merge::partial(shards) {
                        eprintln!("partial: {p}");
                    }
                    eprintln!(
                        "interrupted: {} of {} runs; resume the partial shard(s) with \
                         host-sim sweep --resume DIR, then merge again",
                        m.finished, m.jobs
                    );
                    exit_code::INTERRUPTED
                } else {
                    exit_code::CONVERGED
                }
            }
            Err(e) => fail(&e),
        };
    }
    if let Some(SweepCommand::Plot { dir }) = &args.command {
        return match sweep::redraw(dir) {
            Ok(files) => {
                if !quiet {
                    for f in files {
                        println!("{}", f.display());
                    }
                }
                exit_code::CONVERGED
            }
            Err(e) => fail(&e),
        };
    }
    if args.list {
        for b in BUILTIN_SWEEPS {
            println!("{:<12} {}", b.name, b.description);
        }
        return exit_code::CONVERGED;
    }
    match run(args, quiet) {
        Ok(code) => code,
        Err(e) => fail(&e),
    }
}

/// The plan and shard of `host-sim sweep [SWEEP] [--resume DIR]`, and whether DIR holds
/// a sweep already.
fn plan_of(args: &SweepArgs) -> Result<(Plan, Shard, bool), SweepError> {
    let usage = |reason: String| SweepError::new(exit_code::USAGE, "sweep", "", reason);
    let old = match &args.resume {
        Some(dir) if dir.join("sweep.json").is_file() => Some(Manifest::read(dir)?),
        _ => None,
    };
    // Resuming, what the command line leaves out is as first given (sweep.json).
    let runs = args.runs.or(old.as_ref().map(|m| m.runs));
    let set = match &old {
        Some(m) if args.set.is_empty() => &m.set,
        _ => &args.set,
    };
    let plan = match (&args.sweep, &old) {
        (Some(name), _) => Plan::load_with(name, runs, set)?,
        (None, Some(m)) => {
            let name = m.sweep.strip_prefix("builtin:").unwrap_or(&m.sweep);
            Plan::load_with(name, runs, set)?
        }
        (None, None) => {
            return Err(usage(match &args.resume {
                Some(d) => format!(
                    "{} has no sweep.json: give the sweep file or built-in name to start it",
                    d.display()
                ),
                None => "give a sweep file or built-in name (host-sim sweep --list)".into(),
            }))
        }
    };
    let shard = match args.shard {
        Some(ShardArg::Fixed(s)) => s,
        Some(ShardArg::Auto) => Shard::from_env(args.shards, |v| std::env::var(v).ok())
            .map_err(|e| usage(e.to_string()))?,
        None => match old.as_ref().and_then(|m| m.shard.as_deref()) {
            Some(s) => s
                .parse()
                .map_err(|e| usage(format!("sweep.json: shard: {e}")))?,
            None => Shard::ALL,
        },
    };
    if args.shards.is_some() && args.shard != Some(ShardArg::Auto) {
        return Err(usage("--shards goes with --shard auto".into()));
    }
    Ok((plan, shard, old.is_some()))
}

fn run(args: &SweepArgs, quiet: bool) -> Result<u8, SweepError> {
    let (plan, shard, resuming) = plan_of(args)?;
    let threads = args.jobs.unwrap_or_else(rayon::current_num_threads);
    // A sweep being resumed was accepted (or allowed) when it started.
    if !args.allow_large && !resuming {
        sweep::estimate(&plan, shard, threads).check(&plan.label)?;
    }
    let out = match (&args.resume, &args.out) {
        (Some(d), _) | (None, Some(d)) => d.clone(),
        (None, None) => {
            let d = Path::new("out").join("sweeps").join(&plan.name);
            if shard.is_all() {
                d
            } else {
                d.join(format!("shard-{}-of-{}", shard.k, shard.n))
            }
        }
    };
    // First Ctrl-C or SIGTERM: finish the running runs, write what finished; second: leave.
    let _ = ctrlc::set_handler(|| {
        if STOP.swap(true, Ordering::SeqCst) {
            std::process::exit(i32::from(exit_code::INTERRUPTED));
        }
        eprintln!("\nstopping: waiting for the running runs (Ctrl-C again to quit at once)");
    });
    let jobs = shard.count(plan.jobs());
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        let b = ProgressBar::with_draw_target(Some(jobs), ProgressDrawTarget::stderr());
        if let Ok(style) = ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} runs (eta {eta})",
        ) {
            b.set_style(style);
        }
        b
    };
    let started = Instant::now();
    let done = |_: &sweep::RunRow| bar.inc(1);
    let ctl = Control {
        stop: &STOP,
        max_runs: args.max_runs,
        done: &done,
    };
    let go = || {
        sweep::execute(
            &plan,
            shard,
            &out,
            args.resume.is_some(),
            !args.no_plots,
            &ctl,
        )
    };
    let report = match args.jobs {
        Some(n) => match rayon::ThreadPoolBuilder::new().num_threads(n).build() {
            Ok(pool) => pool.install(go)?,
            Err(e) => {
                eprintln!("error: --jobs {n}: {e}");
                return Ok(exit_code::USAGE);
            }
        },
        None => go()?,
    };
    bar.finish_and_clear();
    let wall = started.elapsed().as_secs_f64();
    let m = &report.manifest;
    if !quiet {
        print!("{}", sweep::table::markdown(m, &report.stats));
        println!("wrote {} files to {}", report.files.len(), out.display());
        println!(
            "{} of {} runs ({} resumed) in {wall:.1} s wall on {threads} threads",
            m.finished, m.jobs, report.resumed
        );
    }
    if m.interrupted {
        eprintln!(
            "interrupted: {} of {} runs written to {}; continue with: host-sim sweep --resume {}",
            m.finished,
            m.jobs,
            out.display(),
            out.display()
        );
        return Ok(exit_code::INTERRUPTED);
    }
    Ok(exit_code::CONVERGED)
}
