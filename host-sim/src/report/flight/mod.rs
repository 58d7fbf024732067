//! Flights beside simulations (docs/crazyflie.md "Flights beside simulations"): the
//! swarm tool's flight log read ([`FlightLog`]), resampled for the scenario it flew
//! ([`FlightSeries`]) and handed to the run's own writers (`timeseries.csv`,
//! `run.mcap`, `replay.html`: [`write_flight_dir`]); a run held against a flight
//! ([`compare()`]) with its figures and both in one replay page ([`write_overlay`]), and
//! a step-test log against `host-sim vehicle step` ([`compare_step`]).

mod compare;
mod log;
mod overlay;
mod plot;
mod series;
mod step;
mod write;

pub use compare::{compare, Comparison, Options, Overlay, RunSeries};
pub use log::{Clock, FlightError, FlightLog, Sample, Track};
pub use overlay::write_overlay;
pub use plot::{plot_overlay, plot_step};
pub use series::FlightSeries;
pub use step::{compare_step, step_csv, StepComparison};
pub use write::{changes, state_name, write_flight_dir};
