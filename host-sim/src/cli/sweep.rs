//! `host-sim sweep`: run a sweep file (or a built-in sweep) on every core with a progress
//! bar, Ctrl-C keeping what finished; `host-sim sweep merge` combines shard outputs and
//! `host-sim sweep plot` redraws a sweep's figures.

use crate::exit_code;
use crate::sweep::{self, Manifest, Plan, Shard, SweepError, BUILTIN_SWEEPS};
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
    /// Sweep file or built-in sweep name (`--list`); see docs/sweeps.md.
    pub sweep: Option<String>,
    /// Output directory (default `out/sweeps/<name>/`, a shard's in `shard-K-of-N/` below).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Runs per point (replaces the file's `runs`).
    #[arg(long, value_name = "N")]
    pub runs: Option<u64>,
    /// Run only shard K of N (jobs j with j mod N = K − 1); merge with `sweep merge`.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<Shard>,
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
        return match sweep::merge(shards)
            .and_then(|(m, rows)| finish(out, &m, &rows, !no_plots, quiet))
        {
            Ok(()) => exit_code::CONVERGED,
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
    let Some(name) = &args.sweep else {
        eprintln!("error: give a sweep file or built-in name (host-sim sweep --list)");
        return exit_code::USAGE;
    };
    let plan = match Plan::load_with(name, args.runs, &args.set) {
        Ok(p) => p,
        Err(e) => return fail(&e),
    };
    let shard = args.shard.unwrap_or(Shard::ALL);
    let out = args.out.clone().unwrap_or_else(|| {
        let d = Path::new("out").join("sweeps").join(&plan.name);
        if shard.is_all() {
            d
        } else {
            d.join(format!("shard-{}-of-{}", shard.k, shard.n))
        }
    });
    // First Ctrl-C: finish the running runs, write what finished; second: leave now.
    let _ = ctrlc::set_handler(|| {
        if STOP.swap(true, Ordering::SeqCst) {
            std::process::exit(i32::from(exit_code::INTERRUPTED));
        }
        eprintln!("\nstopping: waiting for the running runs (Ctrl-C again to quit at once)");
    });
    let jobs = shard.jobs(plan.jobs()).count() as u64;
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
    let finished = match args.jobs {
        Some(n) => match rayon::ThreadPoolBuilder::new().num_threads(n).build() {
            Ok(pool) => pool.install(|| sweep::run_all(&plan, shard, &STOP, &done)),
            Err(e) => {
                eprintln!("error: --jobs {n}: {e}");
                return exit_code::USAGE;
            }
        },
        None => sweep::run_all(&plan, shard, &STOP, &done),
    };
    bar.finish_and_clear();
    let wall = started.elapsed().as_secs_f64();
    let manifest = Manifest::new(&plan, shard, &finished);
    if let Err(e) = finish(&out, &manifest, &finished.rows, !args.no_plots, quiet) {
        return fail(&e);
    }
    if !quiet {
        println!(
            "{} of {} runs in {wall:.1} s wall on {} threads",
            finished.rows.len(),
            finished.jobs,
            args.jobs.unwrap_or_else(rayon::current_num_threads)
        );
    }
    if finished.interrupted {
        eprintln!(
            "interrupted: {} of {} runs written to {}",
            finished.rows.len(),
            finished.jobs,
            out.display()
        );
        return exit_code::INTERRUPTED;
    }
    exit_code::CONVERGED
}

/// Writes the outputs and prints the table and the files.
fn finish(
    out: &Path,
    m: &Manifest,
    rows: &[sweep::RunRow],
    plots: bool,
    quiet: bool,
) -> Result<(), SweepError> {
    let (files, stats) = sweep::write_all(out, m, rows, plots)?;
    if !quiet {
        print!("{}", sweep::table::markdown(m, &stats));
        println!("wrote {} files to {}", files.len(), out.display());
    }
    Ok(())
}
