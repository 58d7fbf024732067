//! Reports of a run: the time series (`timeseries.csv`, or in memory), `summary.json`,
//! the summary table, the figures (one file per figure under [`plot`]) and the replay page
//! ([`replay`]). They read
//! what the engine produced and never drive a run (`docs/architecture.md`).

mod attack;
mod channel;
mod columns;
mod csv;
mod faults;
pub mod flight;
mod mcap;
mod number;
pub mod plot;
pub mod replay;
mod rows;
mod series;
mod summary;
mod table;
mod thin;
mod verdict;
mod world;

pub use columns::{for_each_cell, header, Cell, BASE_COLUMNS};
pub use csv::CsvRecorder;
pub use mcap::McapRecorder;
pub use plot::{plot_run, plot_run_from, PlotError};
pub use replay::{write_replay, write_replay_from};
pub use series::TimeSeries;
pub use summary::{summary_json, write_summary};
pub use table::summary_table;
pub use thin::{expected_rows, SeriesBudget, Thinned};
