//! The simulator's speed tricks in one place: what each is, where it acts, and why it
//! stays. None changes a value: each is either a shortcut taken only when it gives the
//! same bits as the general path, or a hint. `docs/performance.md` has the counts
//! (`cargo xtask bench-counts`) and wall-clock figures behind each.
//!
//! | trick | where | why it stays (and what keeps it exact) |
//! |---|---|---|
//! | direct delivery: with an ideal radio each receiver reads its neighbours' outboxes of the last tick in place | [`super::direct_radio`], `controller::Inbox` | no radio queue (a heap operation per copy); the same frames in the same order and the same counters (`tests/scaling.rs`, `tests/one_of_each.rs`) |
//! | quiet sensors: no random stream when no noise applies | `Sensors::draws`, `quiet_bearing` | no generator seeded per agent and tick; the drawing path with zero noise gives the same bits (`engine/sensors.rs` tests) |
//! | one CRC per broadcast, checked once for all receivers | `RadioFrame::checked`, `Agent::receive_checked` | the CRC was a third of an agent-step when every receiver computed it |
//! | the smallest capacity class per agent | [`super::LOCAL_CAPACITIES`] | a strip agent is 2.6 KB instead of 6 KB: the memory a large run walks per tick |
//! | bearings handed over in the core's slot order | `slot_order.rs` | the core takes them in one pass instead of searching |
//! | estimates copied in the tick that computed them | `SampledSim`'s `viewed` | no second walk over every controller for the diagnostics |
//! | parallel ticks and plant from [`PARALLEL_MIN_AGENTS`] agents, in [`CHUNK`]s | `sampled/parallel.rs`, `Plant::step_parallel` | every core; each agent draws from its own stream and sums are taken in agent order, so the bits do not depend on the threads (`tests/scaling.rs`) |
//! | software prefetch of the agent [`prefetch::AHEAD`] ahead | [`prefetch`] | 0.9 → 2.0 M agent-steps/s at 100,000 agents; a hint (callgrind does not model it: it shows in wall time and hardware counters only) |
//!
//! Removed (issue 29): backing the controllers with huge pages (`madvise`), whose gain
//! was not reproducible on the development VM and shows in no deterministic count.

pub mod prefetch;

/// Runs of at least this many agents compute ticks and plant steps on every thread of the
/// current rayon pool (below it the fork-join costs more than it saves).
pub const PARALLEL_MIN_AGENTS: usize = 2048;

/// Agents per parallel work item of a tick and of the plant's steps.
pub const CHUNK: usize = 256;
