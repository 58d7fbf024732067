//! Adversaries on the radio channel (`[[attacks]]`, `docs/attacks.md`), in SI units and
//! agent indices.

/// What an attacker does during its window.
#[derive(Clone, Debug, PartialEq)]
pub enum AttackKind {
    /// Re-broadcasts, unchanged, every frame it overheard `delay` seconds earlier, to the
    /// same receivers.
    Replay {
        /// Age of the replayed frames (s).
        delay: f64,
    },
    /// Forges frames of agent `victim`: each time the victim broadcasts, it sends a copy
    /// with the next sequence number (so the victim's own next frame looks like a
    /// replay), every angle item's `γ` replaced by `gamma` and the velocity by
    /// `velocity`; the integrity trailer recomputed where it is public (`crc16`), the
    /// overheard one kept where it needs a key (`auth`).
    Forge {
        /// The agent (index) whose frames are forged.
        victim: usize,
        /// The port effort `γ` written into every angle item.
        gamma: f64,
        /// The velocity written into the header, if given.
        velocity: Option<[f64; 2]>,
    },
    /// Transmits random bytes at `rate_hz` frames per second, `bytes` each: with a shared
    /// channel they occupy the medium (collisions, air time); without one every agent
    /// in reach receives them (and rejects them).
    Flood {
        /// Frames per second.
        rate_hz: f64,
        /// Bytes per frame (1–60).
        bytes: usize,
    },
}

impl AttackKind {
    /// The name used in files and `summary.json`.
    pub fn as_str(&self) -> &'static str {
        match self {
            AttackKind::Replay { .. } => "replay",
            AttackKind::Forge { .. } => "forge",
            AttackKind::Flood { .. } => "flood",
        }
    }
}

/// One attacker.
#[derive(Clone, Debug, PartialEq)]
pub struct AttackModel {
    /// What it does.
    pub kind: AttackKind,
    /// Active from (s).
    pub start: f64,
    /// Active until (s).
    pub end: f64,
    /// Where it is (m); `None`: every agent hears it and it hears every agent. With a
    /// position it reaches (and overhears) the agents within the channel's radio range
    /// (everyone without a range).
    pub position: Option<[f64; 2]>,
}

impl AttackModel {
    /// Whether it is active at `t`.
    pub fn active(&self, t: f64) -> bool {
        t >= self.start && t < self.end
    }
}
