//! Counters of the shared channel (`summary.json` `channel`, `docs/outputs.md`).

/// What the shared channel did over a run.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ChannelStats {
    /// Frames put on the air (one per broadcast frame).
    pub transmissions: u64,
    /// Total time on the air of those frames (s), overhead included, turnaround not.
    pub air_time: f64,
    /// Transmissions from outside the swarm (a `flood` attacker's frames).
    pub external_transmissions: u64,
    /// Their total time on the air (s), overhead included.
    pub external_air_time: f64,
    /// Link copies lost to collisions (an overlapping transmission the receiver hears,
    /// or its own).
    pub collided: u64,
    /// Transmissions lost at one receiver or more.
    pub collided_transmissions: u64,
    /// Link copies not heard: the receiver was out of radio range.
    pub out_of_range: u64,
    /// Frames never put on the air: they would have waited longer than
    /// `radio.queue_limit` for the medium.
    pub access_dropped: u64,
    /// Longest wait of a frame for the medium (tick to start of its turnaround) (s).
    pub max_access_wait: f64,
    /// Mean age of neighbour data at the control ticks (s): tick time minus the tick
    /// at which the newest frame received on that link was produced.
    pub mean_age: f64,
    /// Worst such age (s).
    pub max_age: f64,
    /// Number of (tick, link) age samples.
    pub age_samples: u64,
    /// Other transmissions the collision check inspected, over all copies: the
    /// resolver's work (deterministic; stays proportional to the copies when the
    /// cost is linear).
    pub inspected: u64,
}

impl ChannelStats {
    /// The swarm's air time over `elapsed` seconds: the offered load (can exceed 1 when
    /// transmissions overlap).
    pub fn utilisation(&self, elapsed: f64) -> f64 {
        per(self.air_time, elapsed)
    }

    /// The swarm's and the outside transmitters' air time over `elapsed` seconds.
    pub fn total_utilisation(&self, elapsed: f64) -> f64 {
        per(self.air_time + self.external_air_time, elapsed)
    }
}

/// `x / elapsed`, 0 for an empty interval.
fn per(x: f64, elapsed: f64) -> f64 {
    if elapsed > 0.0 {
        x / elapsed
    } else {
        0.0
    }
}
