//! The C structs of one control tick (bearings and measurements in; step output, frame
//! counters and estimates out) and their ONE mapping to and from the core's types.
//! Exhaustive matches and destructuring: a new core variant or field is a compile error
//! here.

use ph_formation_core::{
    BearingMeasurement, Fault, FrameStats, MeasurementError, OwnedEstimate, Status, StepOutput,
    Vec2,
};

use crate::status::ph_status;
use crate::PH_MAX_NEIGHBOURS;

/// `ph_bearing.flags`: `rate` holds a measured bearing rate (otherwise the agent takes
/// finite differences of successive bearings).
pub const PH_BEARING_HAS_RATE: u8 = 1;
/// `ph_bearing.flags`: `range` holds a measured distance (`PH_ESTIMATOR_MEASURED`).
pub const PH_BEARING_HAS_RANGE: u8 = 2;

/// One bearing this agent measured.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ph_bearing {
    /// The neighbour it points to.
    pub neighbour: u8,
    /// `PH_BEARING_HAS_RATE | PH_BEARING_HAS_RANGE` (other bits: `PH_ERR_ARGUMENT`).
    pub flags: u8,
    /// Unit bearing `s` in the shared world frame (S2).
    pub direction: [f32; 2],
    /// Measured bearing rate `ṡ` (with `PH_BEARING_HAS_RATE`).
    pub rate: [f32; 2],
    /// Measured distance, m (with `PH_BEARING_HAS_RANGE`).
    pub range: f32,
}

/// What the agent's own sensors give it at one control tick.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ph_measurements {
    /// Time, s (for the `v*`, `z*` schedules).
    pub time: f32,
    /// Seconds since the previous step (0 on the first; negative: the safe output with
    /// `PH_FAULT_NEGATIVE_DT`).
    pub dt: f32,
    /// Own velocity, m/s (world frame).
    pub velocity: [f32; 2],
    /// `bearing_count` bearings, one to every triangle neighbour (NULL if 0). Only
    /// bearings to neighbours (`ph_neighbours`): another one makes a safe output.
    pub bearings: *const ph_bearing,
    /// Number of bearings (at most `PH_MAX_NEIGHBOURS`).
    pub bearing_count: usize,
    /// Leaders: non-zero when `partner_offset` holds the partner's position minus this
    /// agent's (m).
    pub has_partner_offset: u8,
    /// The leader partner's relative position (with `has_partner_offset`).
    pub partner_offset: [f32; 2],
}

/// Kind of output of a step.
#[repr(u8)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ph_output_status {
    /// The control law S7–S12 (saturated to `max_force`).
    PH_OUTPUT_NOMINAL = 0,
    /// The safe output `U = −safe_damping · v` (no formation force); `fault` says why.
    PH_OUTPUT_SAFE = 1,
}

/// Why a step gave the safe output.
#[repr(u8)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ph_fault {
    /// No fault (nominal output).
    PH_FAULT_NONE = 0,
    /// Time, dt, velocity or partner offset not finite.
    PH_FAULT_NON_FINITE_MEASUREMENT = 1,
    /// The bearing to `fault_neighbour` is not a finite unit vector (or its rate is not
    /// finite).
    PH_FAULT_BAD_BEARING = 2,
    /// A bearing to `fault_neighbour`, which is not a neighbour.
    PH_FAULT_UNKNOWN_NEIGHBOUR = 3,
    /// Two bearings to `fault_neighbour`.
    PH_FAULT_DUPLICATE_BEARING = 4,
    /// The range to `fault_neighbour` is not finite and positive.
    PH_FAULT_BAD_RANGE = 5,
    /// No bearing to triangle neighbour `fault_neighbour` this tick.
    PH_FAULT_MISSING_BEARING = 6,
    /// `fault_neighbour` not heard within the timeout (or never).
    PH_FAULT_STALE = 7,
    /// `fault_neighbour`'s frames lack something the step needs.
    PH_FAULT_MISSING_DATA = 8,
    /// A leader without `partner_offset`.
    PH_FAULT_MISSING_PARTNER_OFFSET = 9,
    /// `PH_ESTIMATOR_MEASURED` without a range to `fault_neighbour`.
    PH_FAULT_MISSING_RANGE = 10,
    /// The computed force was not finite.
    PH_FAULT_NON_FINITE_FORCE = 11,
    /// An internal inconsistency the agent's construction rules out (a bug: report it).
    PH_FAULT_INTERNAL = 12,
    /// `dt` is negative (time ran backwards).
    PH_FAULT_NEGATIVE_DT = 13,
}

/// The result of `ph_step`. `force` is always finite and at most `max_force` long.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ph_output {
    /// The force command `U` (N, world frame).
    pub force: [f32; 2],
    /// A `ph_output_status`.
    pub status: ph_output_status,
    /// A `ph_fault` (`PH_FAULT_NONE` when nominal).
    pub fault: ph_fault,
    /// The neighbour the fault concerns, or −1.
    pub fault_neighbour: i16,
    /// The force was scaled down to `max_force`.
    pub saturated: bool,
    /// A current angle is within the margin of 0 or 180° (output still computed).
    pub degenerate: bool,
}

/// Counters of received frames by outcome, and the bearing trackers' reset counters
/// (`ph_stats`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ph_frame_stats {
    /// Accepted frames.
    pub accepted: u32,
    /// Too short or too long.
    pub bad_length: u32,
    /// CRC mismatch.
    pub bad_crc: u32,
    /// Unknown wire version.
    pub unknown_version: u32,
    /// Integrity or estimator mode different from this agent's.
    pub mode_mismatch: u32,
    /// Undecodable body.
    pub malformed: u32,
    /// Sender not a neighbour, or this agent itself.
    pub unknown_sender: u32,
    /// Stale or repeated sequence number.
    pub stale: u32,
    /// Non-finite or out-of-range values.
    pub invalid_value: u32,
    /// `auth`: the tag does not verify.
    pub bad_tag: u32,
    /// `auth`: counter not newer than the sender's last accepted one.
    pub replayed: u32,
    /// `auth`: no counter known for the sender and none in the frame.
    pub unsynced: u32,
    /// Restarts of each neighbour's bearing track after its first bearing (SPEC §11a,
    /// S15c–S15d: a long interval, or agreeing outliers), by neighbour slot (the order
    /// of `ph_neighbours`); 0 past the agent's neighbours and with the finite difference.
    pub track_resets: [u32; PH_MAX_NEIGHBOURS],
}

/// One distance estimate this agent owns (`ph_owned_estimates`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ph_estimate {
    /// Triangle index in the configuration.
    pub triangle: u8,
    /// Controlled angle (0 or 1) of the triangle.
    pub angle: u8,
    /// Edge: 0 is apex → first far vertex, 1 is apex → second far vertex.
    pub edge: u8,
    /// The angle's apex.
    pub apex: u8,
    /// The far vertex of the edge.
    pub far: u8,
    /// `r̂` (m).
    pub value: f32,
}

/// The core's form of one C bearing.
pub fn bearing_to_core(b: &ph_bearing) -> Result<BearingMeasurement<f32>, ph_status> {
    let ph_bearing {
        neighbour,
        flags,
        direction,
        rate,
        range,
    } = *b;
    if flags & !(PH_BEARING_HAS_RATE | PH_BEARING_HAS_RANGE) != 0 {
        return Err(ph_status::PH_ERR_ARGUMENT);
    }
    let v = |[x, y]: [f32; 2]| Vec2::new(x, y);
    Ok(BearingMeasurement {
        neighbour,
        bearing: v(direction),
        rate: (flags & PH_BEARING_HAS_RATE != 0).then(|| v(rate)),
        range: (flags & PH_BEARING_HAS_RANGE != 0).then_some(range),
    })
}

/// The fault kind and neighbour of a step status.
fn fault(status: &Status) -> (ph_output_status, ph_fault, i16) {
    use ph_fault::*;
    let (kind, who) = match *status {
        Status::Nominal => return (ph_output_status::PH_OUTPUT_NOMINAL, PH_FAULT_NONE, -1),
        Status::Safe(f) => match f {
            Fault::Measurement(m) => match m {
                MeasurementError::NonFinite => (PH_FAULT_NON_FINITE_MEASUREMENT, None),
                MeasurementError::NegativeDt => (PH_FAULT_NEGATIVE_DT, None),
                MeasurementError::BadBearing(id) => (PH_FAULT_BAD_BEARING, Some(id)),
                MeasurementError::UnknownNeighbour(id) => (PH_FAULT_UNKNOWN_NEIGHBOUR, Some(id)),
                MeasurementError::DuplicateBearing(id) => (PH_FAULT_DUPLICATE_BEARING, Some(id)),
                MeasurementError::BadRange(id) => (PH_FAULT_BAD_RANGE, Some(id)),
            },
            Fault::MissingBearing(id) => (PH_FAULT_MISSING_BEARING, Some(id)),
            Fault::Stale(id) => (PH_FAULT_STALE, Some(id)),
            Fault::MissingData(id) => (PH_FAULT_MISSING_DATA, Some(id)),
            Fault::MissingPartnerOffset => (PH_FAULT_MISSING_PARTNER_OFFSET, None),
            Fault::MissingRange(id) => (PH_FAULT_MISSING_RANGE, Some(id)),
            Fault::NonFinite => (PH_FAULT_NON_FINITE_FORCE, None),
            Fault::Internal => (PH_FAULT_INTERNAL, None),
        },
    };
    (
        ph_output_status::PH_OUTPUT_SAFE,
        kind,
        who.map_or(-1, i16::from),
    )
}

/// The C form of a step output.
pub fn output_from_core(o: &StepOutput<f32>) -> ph_output {
    let StepOutput {
        force,
        status,
        saturated,
        degenerate,
    } = o;
    let (status, fault, fault_neighbour) = fault(status);
    ph_output {
        force: [force.x, force.y],
        status,
        fault,
        fault_neighbour,
        saturated: *saturated,
        degenerate: *degenerate,
    }
}

/// What `ph_step` reports when it refuses its arguments (no step was taken).
pub const NO_OUTPUT: ph_output = ph_output {
    force: [0.0; 2],
    status: ph_output_status::PH_OUTPUT_SAFE,
    fault: ph_fault::PH_FAULT_NONE,
    fault_neighbour: -1,
    saturated: false,
    degenerate: false,
};

/// The C form of the frame counters and of the trackers' reset counters `resets` (by
/// neighbour slot; those past `PH_MAX_NEIGHBOURS` are dropped).
pub fn stats_from_core(s: &FrameStats, resets: impl Iterator<Item = u32>) -> ph_frame_stats {
    let mut track_resets = [0; PH_MAX_NEIGHBOURS];
    for (slot, r) in track_resets.iter_mut().zip(resets) {
        *slot = r;
    }
    let FrameStats {
        accepted,
        bad_length,
        bad_crc,
        unknown_version,
        mode_mismatch,
        malformed,
        unknown_sender,
        stale,
        invalid_value,
        bad_tag,
        replayed,
        unsynced,
    } = *s;
    ph_frame_stats {
        accepted,
        bad_length,
        bad_crc,
        unknown_version,
        mode_mismatch,
        malformed,
        unknown_sender,
        stale,
        invalid_value,
        bad_tag,
        replayed,
        unsynced,
        track_resets,
    }
}

/// The C form of an owned estimate (indices are below `PH_MAX_TRIANGLES` and 2).
pub fn estimate_from_core(e: &OwnedEstimate<f32>) -> ph_estimate {
    let OwnedEstimate {
        triangle,
        angle,
        edge,
        apex,
        far,
        value,
    } = *e;
    let small = |i: usize| u8::try_from(i).unwrap_or(u8::MAX);
    ph_estimate {
        triangle: small(triangle),
        angle: small(angle),
        edge: small(edge),
        apex,
        far,
        value,
    }
}
