//! One emulated agent's link figures (`summary.json` → `hil`).

/// One emulated agent's link figures (`summary.json` → `hil`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LinkStats {
    /// The agent's id as the scenario writes it.
    pub agent: String,
    /// QEMU's pid (none for the test stand-in).
    pub pid: Option<u32>,
    /// Link messages (COBS frames) sent to the target.
    pub frames_to_target: u64,
    /// Link messages received from the target.
    pub frames_from_target: u64,
    /// Bytes sent on the serial line.
    pub bytes_to_target: u64,
    /// Bytes received from the serial line.
    pub bytes_from_target: u64,
    /// Radio frames delivered to the target (`HostMsg::Radio`).
    pub radio_to_target: u64,
    /// Radio frames the target broadcast (`TargetMsg::Radio`).
    pub radio_from_target: u64,
    /// Control ticks completed.
    pub ticks: u64,
    /// Wall-clock seconds between sending a tick and receiving its `Output`, summed.
    pub wall_s: f64,
    /// Wall-clock seconds from starting QEMU to `Ready`.
    pub startup_s: f64,
    /// Whether the estimates came from `TargetMsg::Estimates` (else from the agent's own
    /// broadcast frames).
    pub estimates_from_target: bool,
    /// Estimates the agent owns.
    pub estimates: usize,
    /// Frames the target's agent accepted over the run (`Finished`).
    pub target_accepted: Option<u32>,
    /// Frames the target's agent rejected over the run (`Finished`).
    pub target_rejected: Option<u32>,
    /// QEMU's exit code after `Finish` (0: the firmware exited cleanly; none: killed).
    pub exit_code: Option<i32>,
}

impl LinkStats {
    /// Where the agent's estimates in the outputs come from: `"estimates_message"`
    /// (`TargetMsg::Estimates`), `"radio_frames"` (the angle items of its own broadcast
    /// frames) or `"none"` (it owns no estimate).
    pub fn estimates_source(&self) -> &'static str {
        match (self.estimates, self.estimates_from_target) {
            (0, _) => "none",
            (_, true) => "estimates_message",
            (_, false) => "radio_frames",
        }
    }
}
