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

    /// With collisions (ALOHA access), when the offered load `G` (the utilisation over
    /// `elapsed`) is above `ALOHA_LOAD_TARGET` (0.1): the share of the `copies` link copies
    /// lost to collisions and the communication rate that brings `G` to the target,
    /// `1 / (period · every · ⌈G / target⌉)` (the frames and the position packets go at
    /// that rate, so the load scales with it), with the timeouts that span
    /// `TIMEOUT_BROADCASTS` (3.5) of its broadcasts. `period` is the control period (s),
    /// `every` the control ticks per broadcast now.
    pub fn collision_note(
        &self,
        elapsed: f64,
        copies: u64,
        period: f64,
        every: usize,
    ) -> Option<String> {
        let load = self.utilisation(elapsed);
        if self.collided == 0 || load <= ALOHA_LOAD_TARGET || period.is_nan() || period <= 0.0 {
            return None;
        }
        let slower = (load / ALOHA_LOAD_TARGET).ceil();
        let rate = 1.0 / (period * every.max(1) as f64 * slower);
        let timeout = TIMEOUT_BROADCASTS / rate;
        Some(format!(
            "the shared channel is overloaded for ALOHA: an offered load of {:.0} % of its \
             air time lost {:.0} % of the link copies to collisions; \
             controller.comm_rate_hz = {rate} keeps the load at {:.0} % or less, with \
             controller.neighbour_timeout (and, as used, sensors.positions.max_age_s and \
             controller.bearing_hold_s) of {timeout:.3} s or more (docs/radio.md)",
            100.0 * load,
            100.0 * self.collided as f64 / copies.max(1) as f64,
            100.0 * ALOHA_LOAD_TARGET
        ))
    }
}

/// The offered load (share of the air time) up to which ALOHA access is taken as
/// working: an unslotted transmission survives with probability `e^{−2G}`, 82 % at
/// `G` = 0.1, so a neighbour whose timeout spans `TIMEOUT_BROADCASTS` (3.5) broadcasts (three
/// lost in a row) goes silent with probability about 0.18³ = 0.6 %, well under the
/// verdict's 5 % of safe outputs (docs/radio.md).
pub const ALOHA_LOAD_TARGET: f64 = 0.1;

/// Broadcast periods a neighbour timeout should span under ALOHA: three losses in a row
/// plus the half period of the clocks' phases.
pub const TIMEOUT_BROADCASTS: f64 = 3.5;

/// The share of an agent's link copies lost above which the run names it: with a
/// timeout of [`TIMEOUT_BROADCASTS`] broadcasts its neighbours go silent on three losses
/// in a row, `0.37³` = 5 % of the time, the verdict's share of safe outputs
/// (docs/radio.md).
pub const LOSSY_SHARE: f64 = 0.37;

/// The agents (by their scenario ids `names`) whose copies were lost more than
/// [`LOSSY_SHARE`] of the time, from `loss` (sent, lost per agent), with their shares;
/// `None` when there is none.
pub fn lossy_note(loss: &[(u64, u64)], names: &[&str]) -> Option<String> {
    let lossy: Vec<String> = loss
        .iter()
        .zip(names)
        .filter(|((sent, lost), _)| *sent > 0 && *lost as f64 > LOSSY_SHARE * *sent as f64)
        .map(|((sent, lost), name)| {
            format!("{name} ({:.0} %)", 100.0 * *lost as f64 / *sent as f64)
        })
        .collect();
    (!lossy.is_empty()).then(|| {
        format!(
            "agents whose link copies were lost more than {:.0} % of the time (their \
             neighbours time out on three losses in a row): {}",
            100.0 * LOSSY_SHARE,
            lossy.join(", ")
        )
    })
}

/// `x / elapsed`, 0 for an empty interval.
fn per(x: f64, elapsed: f64) -> f64 {
    if elapsed > 0.0 {
        x / elapsed
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Named above 37 % of the copies sent (not at it, not without copies), with the
    /// share rounded.
    #[test]
    fn lossy_agents_are_named_above_the_share() {
        let loss = [(100, 38), (100, 37), (0, 0), (10, 10)];
        let note = lossy_note(&loss, &["a", "b", "c", "d"]).expect("two lossy");
        assert!(note.ends_with(": a (38 %), d (100 %)"), "{note}");
        assert_eq!(lossy_note(&loss[1..3], &["b", "c"]), None);
    }
}
