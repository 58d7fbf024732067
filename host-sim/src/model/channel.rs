//! The shared radio channel and the swarm's communication settings, in SI units
//! (`docs/radio.md`).

use serde::{Deserialize, Serialize};

/// 2 Mbit/s on the air (nRF24L01+ / nRF51 Enhanced ShockBurst at the Crazyflie's rate).
pub const CRAZYFLIE_BIT_RATE: f64 = 2e6;
/// Per-frame overhead of a Crazyflie P2P packet, in bytes: preamble 1 B + address 5 B +
/// packet control field 9 bit + CRC 2 B (nRF24L01+ §7.3) + P2P/CRTP header 2 B
/// (bitcraze/crazyflie2-nrf-firmware#29) = 89 bit.
pub const CRAZYFLIE_OVERHEAD_BYTES: f64 = 89.0 / 8.0;
/// TX settling before each packet (nRF24L01+ `Tstby2a` = 130 µs).
pub const CRAZYFLIE_TURNAROUND: f64 = 130e-6;

/// `controller.comm_rate_hz = "auto"` (docs/radio.md): requested by the file, then
/// resolved by the API (`engine::load::resolve_auto`) into `Model::comm_every` and the
/// timeouts, with what it measured for the run's report.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AutoRate {
    /// The offered load broadcasting at every control tick (share of the air time;
    /// `None` before resolution, or without a shared channel).
    pub load_every_tick: Option<f64>,
    /// The offered load at the chosen rate.
    pub load: Option<f64>,
    /// The share of frames the access dropped at the chosen rate (they would have
    /// waited longer than `radio.queue_limit`).
    pub dropped: Option<f64>,
    /// The chosen rate (Hz).
    pub rate_hz: f64,
    /// Timeouts raised to span the broadcasts they need: `(key, from s, to s)`.
    pub raised: Vec<(&'static str, f64, f64)>,
}

/// How agents share the medium.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Access {
    /// Unslotted ALOHA, no carrier sense: a frame starts at a random instant of its tick;
    /// two overlapping transmissions are lost at every receiver that hears both.
    #[default]
    Aloha,
    /// Each agent owns one slot of a repeating superframe: no collisions, the wait for
    /// the own slot is latency.
    Tdma,
}

impl Access {
    /// The name used in files and `summary.json`.
    pub fn as_str(self) -> &'static str {
        match self {
            Access::Aloha => "aloha",
            Access::Tdma => "tdma",
        }
    }
}

/// How frames are protected, the same for the whole swarm (the core's
/// `ph_formation_core::Integrity`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum IntegrityMode {
    /// A CRC-16 trailer in every frame (2 bytes).
    #[default]
    Crc16,
    /// The link checks its own CRC: no trailer.
    Link,
    /// A 64-bit SipHash-2-4 tag under the swarm key and replay protection
    /// (`docs/core.md`, "auth"); the key is `controller.auth_key`.
    Auth,
}

impl IntegrityMode {
    /// The name used in files and `summary.json`.
    pub fn as_str(self) -> &'static str {
        match self {
            IntegrityMode::Crc16 => "crc16",
            IntegrityMode::Link => "link",
            IntegrityMode::Auth => "auth",
        }
    }

    /// The core's value (`key`: the swarm key of `auth`).
    pub fn core(self, key: &[u8; 16]) -> ph_formation_core::Integrity {
        match self {
            IntegrityMode::Crc16 => ph_formation_core::Integrity::Crc16,
            IntegrityMode::Link => ph_formation_core::Integrity::Link,
            IntegrityMode::Auth => ph_formation_core::Integrity::Auth(
                ph_formation_core::wire::auth::SwarmKey::new(*key),
            ),
        }
    }
}

/// One shared medium (`docs/radio.md`).
#[derive(Clone, Debug, PartialEq)]
pub struct ChannelModel {
    /// Preset it came from (`crazyflie`), or `custom`.
    pub preset: String,
    /// Access scheme.
    pub access: Access,
    /// Bit rate on the air in bits per second (scenario key `radio.channel.bit_rate_bps`).
    pub bit_rate: f64,
    /// Bytes each frame carries besides the controller's payload (preamble, address,
    /// packet control, link CRC, link header); may be fractional (bits / 8).
    pub overhead_bytes: f64,
    /// Transmitter settling before each frame (s); the medium is free meanwhile.
    pub turnaround: f64,
    /// Radio range (m): agents farther apart neither hear nor disturb each other.
    /// `None`: everyone hears everyone.
    pub range: Option<f64>,
    /// ALOHA: a frame's start is uniform in `[t, t + aloha_window)` after its tick `t`.
    pub aloha_window: f64,
    /// TDMA: slot length (s); the superframe is one slot per agent.
    pub slot: f64,
}

/// Seconds on the air of a packet of `len` payload bytes with `overhead` bytes besides
/// (preamble, address, control, CRC, header) at `bit_rate` bits per second.
pub fn air_time(len: usize, overhead: f64, bit_rate: f64) -> f64 {
    (len as f64 + overhead) * 8.0 / bit_rate
}

impl ChannelModel {
    /// Seconds on the air of a frame of `len` payload bytes.
    pub fn air_time(&self, len: usize) -> f64 {
        air_time(len, self.overhead_bytes, self.bit_rate)
    }

    /// TDMA superframe length (s) for `n` agents.
    pub fn superframe(&self, n: usize) -> f64 {
        self.slot * n as f64
    }
}
