//! `host-sim sweep`: Monte Carlo sweeps over a base scenario (`docs/sweeps.md`), a client
//! of the library API ([`crate::load_toml`], [`crate::Simulation`]).
//!
//! * [`spec`]: the sweep file's schema, parsed with located errors;
//! * [`plan`]: checked against the base scenario (the axes and points in `axes.rs`: grid
//!   or random), each run's seed derived from (sweep seed, point, run);
//! * [`perturb`]: random initial shapes (as `host-sim design` makes them);
//! * [`run`]: one run, and all of a small sweep's in memory (rows in job order);
//! * [`mod@execute`]: the command's runs: interleaved over the points (`order`), streamed
//!   to `runs.csv` and sorted at the end (`journal`), stopped by a signal or a run limit,
//!   resumed (`done`); [`mod@estimate`]: disk and time, refused above a limit;
//! * [`shard`] and [`mod@merge`]: a deterministic share of the runs (`K/N` or from Slurm's
//!   or Kubernetes' variables), and shares combined;
//! * [`mod@aggregate`] and [`stats`]: outcome fractions with 95 % Wilson intervals and
//!   settle-time quantiles per point;
//! * [`output`], `runs_csv` and `figures`: `sweep.json`, `runs.csv`, `points.csv`,
//!   `points.json` and the figures.
//!
//! The modules without a link here (`order`, `journal`, `done`, `runs_csv`, `figures`,
//! `table`) are the command's internals, not API.
//!
//! The same sweep file and seed give the same files whatever the number of threads or
//! shards.

pub mod aggregate;
mod axes;
pub mod builtin;
pub(crate) mod done;
pub mod error;
pub mod estimate;
pub mod execute;
pub(crate) mod figures;
// `tests/sweep/resume.rs` reads `journal::FAN_IN`: public for it, not API.
#[doc(hidden)]
pub mod journal;
pub mod merge;
pub(crate) mod order;
pub mod output;
pub mod perturb;
pub mod plan;
pub mod run;
pub(crate) mod runs_csv;
pub mod shard;
pub mod spec;
pub mod stats;
pub(crate) mod table;

pub use aggregate::{aggregate, PointStats};
pub use builtin::{builtin_sweep, BuiltinSweep, BUILTIN_SWEEPS};
pub use error::SweepError;
pub use estimate::{estimate, Estimate};
pub use execute::{execute, Control, Report};
pub use merge::{merge, merge_into};
pub use output::{redraw, write_all, Manifest};
pub use plan::{run_seed, Plan};
pub use run::{run_all, run_job, Finished, RunRow};
pub use shard::{Shard, ShardArg, ShardError};
pub use spec::SweepSource;
pub use stats::{quantile, wilson};
