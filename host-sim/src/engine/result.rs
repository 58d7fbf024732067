//! Everything a run found, as the engine hands it to the reports.

use super::attack::AttackCounts;
use super::channel::ChannelStats;
use super::hil::LinkStats;
use super::stats::{ControlStats, FrameCounts};
use crate::analysis::{Event, Outcome};

/// Everything a run found (written to `summary.json` by the reports).
#[derive(Clone, Debug, PartialEq)]
pub struct RunResult {
    /// How it ended.
    pub outcome: Outcome,
    /// Why, in words.
    pub reason: String,
    /// Failures detected, in order.
    pub events: Vec<Event>,
    /// Time of the last evaluated instant (s).
    pub final_time: f64,
    /// When the formation settled ([`crate::analysis::Verdict::settle_time`]).
    pub settle_time: Option<f64>,
    /// The steady window's bands and figures of a run judged with bands (`None` for a
    /// noise-free run).
    pub steady: Option<crate::analysis::SteadyReport>,
    /// The pose over the steady window, reported apart from the shape.
    pub pose: crate::analysis::PoseReport,
    /// Share of the controllers' outputs in the steady window that were the safe output.
    pub safe_share: Option<f64>,
    /// Final `max |α − α*|` (rad).
    pub final_max_angle_error: f64,
    /// Final `|z − z*|` (m).
    pub final_displacement_error: f64,
    /// Final `max_n |v_n − v*|` (m/s).
    pub final_velocity_error: f64,
    /// Smallest estimate over the run.
    pub min_estimate: Option<f64>,
    /// Smallest inter-agent distance over the run, with time and agent indices.
    pub min_distance: (f64, f64, usize, usize),
    /// `V(0)`.
    pub v0: f64,
    /// Final `V`.
    pub v_final: f64,
    /// Largest rise of `V` above its running minimum, divided by `V(0)`.
    pub v_max_increase_rel: f64,
    /// When that rise peaked.
    pub v_max_increase_t: f64,
    /// Final positions, agent order.
    pub final_positions: Vec<[f64; 2]>,
    /// Final velocities, agent order.
    pub final_velocities: Vec<[f64; 2]>,
    /// Final estimates (layout order) and their true distances.
    pub final_estimates: Vec<(f64, f64)>,
    /// Per triangle: the sign of its signed area at the end equals the one at the start
    /// (the formation did not flip into its mirror image).
    pub orientation_kept: Vec<bool>,
    /// Frame counters.
    pub frames: FrameCounts,
    /// Controller counters.
    pub control: ControlStats,
    /// The shared channel's counters (`None` without `[radio.channel]`).
    pub channel: Option<ChannelStats>,
    /// Frames each attacker overheard and injected (`[[attacks]]` order).
    pub attacks: Vec<AttackCounts>,
    /// What the safety policies did, per agent in agent order: ticks holding, landings
    /// and the last one's reason, setpoints the separation guard changed (empty
    /// without `[policy]`; `crate::engine::policy`).
    pub policy: Vec<ph_formation_core::policy::PolicyCounts>,
    /// What the swarm did after each fault (`[[faults]]` order; empty without).
    pub faults: Vec<super::stats::FaultReport>,
    /// Things the user should know (ignored settings, …).
    pub warnings: Vec<String>,
    /// RK4 steps taken.
    pub steps: usize,
    /// Wall-clock seconds.
    pub wall_seconds: f64,
    /// Link figures of the host-in-the-loop agents (empty without).
    pub hil: Vec<LinkStats>,
}
