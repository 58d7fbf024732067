//! `host-sim sweep`: Monte Carlo sweeps over a base scenario (`docs/sweeps.md`), a client
//! of the library API ([`crate::load_toml`], [`crate::Simulation`]).
//!
//! * [`spec`]: the sweep file's schema, parsed with located errors;
//! * [`plan`]: checked against the base scenario (the axes and points in `axes.rs`: grid
//!   or random), each run's seed derived from (sweep seed, point, run);
//! * [`perturb`]: random initial shapes (as `host-sim design` makes them);
//! * [`run`]: the runs, in parallel on rayon's pool, rows in job order;
//! * [`shard`] and [`mod@merge`]: a deterministic share of the runs, and shares combined;
//! * [`mod@aggregate`] and [`stats`]: outcome fractions with 95 % Wilson intervals and
//!   settle-time quantiles per point;
//! * [`output`], [`runs_csv`] and [`figures`]: `sweep.json`, `runs.csv`, `points.csv`,
//!   `points.json` and the figures.
//!
//! The same sweep file and seed give the same files whatever the number of threads or
//! shards.

pub mod aggregate;
mod axes;
pub mod builtin;
pub mod error;
pub mod figures;
pub mod merge;
pub mod output;
pub mod perturb;
pub mod plan;
pub mod run;
pub mod runs_csv;
pub mod shard;
pub mod spec;
pub mod stats;
pub mod table;

pub use aggregate::{aggregate, PointStats};
pub use builtin::{builtin_sweep, BuiltinSweep, BUILTIN_SWEEPS};
pub use error::SweepError;
pub use merge::merge;
pub use output::{redraw, write_all, Manifest};
pub use plan::{run_seed, Plan};
pub use run::{run_all, run_job, Finished, RunRow};
pub use shard::Shard;
pub use spec::SweepSource;
pub use stats::{quantile, wilson};
