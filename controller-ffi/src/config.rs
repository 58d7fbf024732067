//! The C form of an agent's configuration ([`ph_config`]) and the ONE place that maps it
//! to and from the core's [`AgentConfig`] ([`to_core`], [`from_core`]).
//!
//! Both directions destructure or build every field by name (no `..`), so a field added
//! to a core configuration type is a compile error here until it is mapped.

use ph_formation_core::{
    AgentConfig, AngleConfig, BearingFilter, EstimatorMode, Integrity, LeaderConfig, LeaderRole,
    Limits, Schedule, ScheduleStep, SwarmKey, TrackerConfig, TriangleConfig,
};

use crate::status::ph_status;
use crate::{FfiConfig, PH_MAX_SCHEDULE_STEPS, PH_MAX_TRIANGLES};

/// How the agent gets the distances of S8 (values of `ph_config.estimator`).
#[repr(u8)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ph_estimator {
    /// One passive estimate per angle and edge, owned by the apex (S9, S10). Default.
    PH_ESTIMATOR_SHARED = 0,
    /// Every agent of an angle keeps its own copies (the paper's structure).
    PH_ESTIMATOR_PER_AGENT = 1,
    /// A range sensor measures the distances (`ph_bearing.range`); no estimator.
    PH_ESTIMATOR_MEASURED = 2,
}

/// How frames are protected (values of `ph_config.integrity`); the same for every agent
/// of a swarm (see `docs/core.md`, wire format).
#[repr(u8)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ph_integrity {
    /// A CRC-16 trailer: raw UART or any link without its own check. Default.
    PH_INTEGRITY_CRC16 = 0,
    /// No trailer: the link checks its own CRC (the Crazyflie radio does).
    PH_INTEGRITY_LINK = 1,
    /// A 64-bit SipHash-2-4 tag under the swarm key `ph_config.auth_key` and replay
    /// protection (see `docs/core.md`, "auth"); call `ph_agent_set_boot_epoch` after
    /// `ph_agent_init*`.
    PH_INTEGRITY_AUTH = 2,
}

/// How the agent filters its bearings (values of `ph_bearing_filter.kind`; SPEC §11).
#[repr(u8)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ph_filter_kind {
    /// The bearing tracker (S15–S17) with the settings of `ph_bearing_filter`. Default.
    PH_FILTER_TRACKER = 0,
    /// The finite difference of successive bearings (SPEC §2); the settings are unused
    /// and must be zero.
    PH_FILTER_FINITE_DIFFERENCE = 1,
}

/// The bearing filter (SPEC §11): `kind` is a `ph_filter_kind`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ph_bearing_filter {
    /// A `ph_filter_kind`.
    pub kind: u8,
    /// `σ_b > 0`: the bearing noise (rad), at most 0.5.
    pub bearing_noise: f32,
    /// `σ_ω ≥ 0`: unmodelled bearing rate (rad/√s).
    pub rate_noise: f32,
    /// `σ_ρ ≥ 0`: random walk of the inverse distance (1/(m √s)).
    pub inverse_range_noise: f32,
    /// Innovation gate in standard deviations, in `[1, 1000]`.
    pub gate: f32,
}

/// Which end of the leader edge an agent is (values of `ph_leader.role`; S11 with
/// `z = q_a − q_b`).
#[repr(u8)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ph_leader_role {
    /// Agent `a`.
    PH_LEADER_A = 0,
    /// Agent `b`.
    PH_LEADER_B = 1,
    /// Either end of an edge whose orientation no one controls: the distance part of S11
    /// alone (S11b), for agents whose heading estimates disagree.
    PH_LEADER_DISTANCE = 2,
}

/// One controlled angle `α = (apex; v, w)` of a triangle.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ph_angle {
    /// The apex (a vertex of the triangle); the far vertices are the two others.
    pub apex: u8,
    /// `cos α*` (S4): the desired angle enters as its cosine.
    pub cos_desired: f32,
    /// `c_α > 0` (S7).
    pub stiffness: f32,
    /// `d_α ≥ 0` (S7).
    pub damping: f32,
    /// `c_e > 0` (S9).
    pub estimator_gain: f32,
}

/// A triangle of the Laman graph with its two controlled angles (distinct apexes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ph_triangle {
    /// The three vertices (agent ids); one of them is this agent.
    pub vertices: [u8; 3],
    /// The two controlled angles.
    pub angles: [ph_angle; 2],
}

/// One step of a schedule: `value` holds from time `from` (s) on.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ph_schedule_step {
    /// Start time (s).
    pub from: f32,
    /// The value `[x, y]`.
    pub value: [f32; 2],
}

/// A piecewise-constant 2-D schedule: `steps[0..count]`, sorted by `from`. Before the
/// first step the first value holds; `count == 0` is zero.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ph_schedule {
    /// Steps used (at most `PH_MAX_SCHEDULE_STEPS`).
    pub count: u32,
    /// The steps.
    pub steps: [ph_schedule_step; PH_MAX_SCHEDULE_STEPS],
}

/// The leader-edge maneuver (S11); read only when `ph_config.has_leader` is non-zero.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ph_leader {
    /// A `ph_leader_role`.
    pub role: u8,
    /// The other leader's id.
    pub partner: u8,
    /// `k_z > 0`.
    pub stiffness: f32,
    /// `D_z` (diagonal), ≥ 0.
    pub damping: [f32; 2],
    /// `z*(t)`: desired `q_a − q_b` (m).
    pub displacement: ph_schedule,
}

/// Safety limits and input tolerances.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ph_limits {
    /// The force is scaled down to this norm (N).
    pub max_force: f32,
    /// A neighbour not heard from for longer than this (s) is stale: safe output.
    pub neighbour_timeout: f32,
    /// Safe output `U = −safe_damping · v`.
    pub safe_damping: f32,
    /// A bearing `s` is accepted when `| |s|² − 1 | ≤ bearing_tolerance`.
    pub bearing_tolerance: f32,
    /// `cos` of the angle margin: a current angle with `|cos α|` above it is reported as
    /// degenerate.
    pub margin_cos: f32,
    /// `T_h ≥ 0` (s): a missing bearing is held (finite differences) or predicted (the
    /// tracker) while the last one measured is younger than this; past it, the safe
    /// output (SPEC §12). 0: no hold.
    pub bearing_hold: f32,
}

/// One agent's configuration. Start from `ph_config_default` (the SPEC defaults), then
/// set the triangles, gains and maneuvers.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ph_config {
    /// This agent's id (unique within two hops).
    pub id: u8,
    /// A `ph_estimator`.
    pub estimator: u8,
    /// Non-zero: this agent is one of the two leaders (`leader` is read).
    pub has_leader: u8,
    /// Triangles used (at most `PH_MAX_TRIANGLES`).
    pub triangle_count: u32,
    /// The triangles this agent belongs to.
    pub triangles: [ph_triangle; PH_MAX_TRIANGLES],
    /// `r̂(0)` (m), ≥ `min_estimate`.
    pub initial_estimate: f32,
    /// `r_min > 0` of S10 (m).
    pub min_estimate: f32,
    /// `D^r` (diagonal) of S12: the plant's friction, cancelled at `v*`.
    pub friction: [f32; 2],
    /// `D^v` (diagonal) of S12.
    pub velocity_damping: [f32; 2],
    /// `v*(t)` of S12 (m/s).
    pub velocity_reference: ph_schedule,
    /// The leader-edge maneuver (when `has_leader`).
    pub leader: ph_leader,
    /// Safety limits.
    pub limits: ph_limits,
    /// The bearing filter (SPEC §11).
    pub bearing_filter: ph_bearing_filter,
    /// A `ph_integrity`.
    pub integrity: u8,
    /// Broadcast every `comm_every`-th step (≥ 1).
    pub comm_every: u16,
    /// Which step of each `comm_every` broadcasts (< `comm_every`).
    pub comm_phase: u16,
    /// The 128-bit swarm key when `integrity` is `PH_INTEGRITY_AUTH` (all zero
    /// otherwise). A secret: keep it in protected storage and never log it.
    pub auth_key: [u8; 16],
}

fn schedule_to_core(s: &ph_schedule) -> Result<Schedule<f32>, ph_status> {
    let ph_schedule { count, steps } = s;
    let n = usize::try_from(*count).unwrap_or(usize::MAX);
    let used = steps
        .get(..n)
        .ok_or(ph_status::PH_ERR_CONFIG_SCHEDULE_TOO_LONG)?;
    let mut out = Schedule::default();
    for st in used {
        let ph_schedule_step { from, value } = *st;
        out.steps
            .push(ScheduleStep { from, value })
            .map_err(|_| ph_status::PH_ERR_CONFIG_SCHEDULE_TOO_LONG)?;
    }
    Ok(out)
}

fn schedule_from_core(s: &Schedule<f32>) -> ph_schedule {
    let Schedule { steps } = s;
    let mut out = ph_schedule::default();
    for (dst, st) in out.steps.iter_mut().zip(steps) {
        let ScheduleStep { from, value } = *st;
        *dst = ph_schedule_step { from, value };
    }
    // At most PH_MAX_SCHEDULE_STEPS (= the core's capacity, asserted in lib.rs).
    out.count = u32::try_from(steps.len()).unwrap_or(0);
    out
}

fn angle_to_core(a: &ph_angle) -> AngleConfig<f32> {
    let ph_angle {
        apex,
        cos_desired,
        stiffness,
        damping,
        estimator_gain,
    } = *a;
    AngleConfig {
        apex,
        cos_desired,
        stiffness,
        damping,
        estimator_gain,
    }
}

fn angle_from_core(a: &AngleConfig<f32>) -> ph_angle {
    let AngleConfig {
        apex,
        cos_desired,
        stiffness,
        damping,
        estimator_gain,
    } = *a;
    ph_angle {
        apex,
        cos_desired,
        stiffness,
        damping,
        estimator_gain,
    }
}

fn estimator_to_core(e: u8) -> Result<EstimatorMode, ph_status> {
    match e {
        x if x == ph_estimator::PH_ESTIMATOR_SHARED as u8 => Ok(EstimatorMode::Shared),
        x if x == ph_estimator::PH_ESTIMATOR_PER_AGENT as u8 => Ok(EstimatorMode::PerAgent),
        x if x == ph_estimator::PH_ESTIMATOR_MEASURED as u8 => Ok(EstimatorMode::Measured),
        _ => Err(ph_status::PH_ERR_CONFIG_BAD_ENUM),
    }
}

fn estimator_from_core(e: EstimatorMode) -> ph_estimator {
    match e {
        EstimatorMode::Shared => ph_estimator::PH_ESTIMATOR_SHARED,
        EstimatorMode::PerAgent => ph_estimator::PH_ESTIMATOR_PER_AGENT,
        EstimatorMode::Measured => ph_estimator::PH_ESTIMATOR_MEASURED,
    }
}

/// The integrity of code `e` (with the key `key` for `auth`; the key must be all zero
/// otherwise, so that the C form stays exact).
fn integrity_to_core(e: u8, key: &[u8; 16]) -> Result<Integrity, ph_status> {
    let no_key = *key == [0; 16];
    match e {
        x if x == ph_integrity::PH_INTEGRITY_CRC16 as u8 && no_key => Ok(Integrity::Crc16),
        x if x == ph_integrity::PH_INTEGRITY_LINK as u8 && no_key => Ok(Integrity::Link),
        x if x == ph_integrity::PH_INTEGRITY_AUTH as u8 => Ok(Integrity::Auth(SwarmKey::new(*key))),
        _ => Err(ph_status::PH_ERR_CONFIG_BAD_ENUM),
    }
}

/// The code and key (zero unless `auth`) of an integrity.
fn integrity_from_core(e: &Integrity) -> (ph_integrity, [u8; 16]) {
    match e {
        Integrity::Crc16 => (ph_integrity::PH_INTEGRITY_CRC16, [0; 16]),
        Integrity::Link => (ph_integrity::PH_INTEGRITY_LINK, [0; 16]),
        Integrity::Auth(key) => (ph_integrity::PH_INTEGRITY_AUTH, *key.expose_secret()),
    }
}

fn role_to_core(r: u8) -> Result<LeaderRole, ph_status> {
    match r {
        x if x == ph_leader_role::PH_LEADER_A as u8 => Ok(LeaderRole::A),
        x if x == ph_leader_role::PH_LEADER_B as u8 => Ok(LeaderRole::B),
        x if x == ph_leader_role::PH_LEADER_DISTANCE as u8 => Ok(LeaderRole::Distance),
        _ => Err(ph_status::PH_ERR_CONFIG_BAD_ENUM),
    }
}

fn role_from_core(r: LeaderRole) -> ph_leader_role {
    match r {
        LeaderRole::A => ph_leader_role::PH_LEADER_A,
        LeaderRole::B => ph_leader_role::PH_LEADER_B,
        LeaderRole::Distance => ph_leader_role::PH_LEADER_DISTANCE,
    }
}

fn limits_to_core(l: &ph_limits) -> Limits<f32> {
    let ph_limits {
        max_force,
        neighbour_timeout,
        safe_damping,
        bearing_tolerance,
        margin_cos,
        bearing_hold,
    } = *l;
    Limits {
        max_force,
        neighbour_timeout,
        safe_damping,
        bearing_tolerance,
        margin_cos,
        bearing_hold,
    }
}

fn limits_from_core(l: &Limits<f32>) -> ph_limits {
    let Limits {
        max_force,
        neighbour_timeout,
        safe_damping,
        bearing_tolerance,
        margin_cos,
        bearing_hold,
    } = *l;
    ph_limits {
        max_force,
        neighbour_timeout,
        safe_damping,
        bearing_tolerance,
        margin_cos,
        bearing_hold,
    }
}

fn filter_to_core(f: &ph_bearing_filter) -> Result<BearingFilter<f32>, ph_status> {
    let ph_bearing_filter {
        kind,
        bearing_noise,
        rate_noise,
        inverse_range_noise,
        gate,
    } = *f;
    match kind {
        x if x == ph_filter_kind::PH_FILTER_TRACKER as u8 => {
            Ok(BearingFilter::Tracker(TrackerConfig {
                bearing_noise,
                rate_noise,
                inverse_range_noise,
                gate,
            }))
        }
        x if x == ph_filter_kind::PH_FILTER_FINITE_DIFFERENCE as u8
            && [bearing_noise, rate_noise, inverse_range_noise, gate] == [0.0; 4] =>
        {
            Ok(BearingFilter::FiniteDifference)
        }
        _ => Err(ph_status::PH_ERR_CONFIG_BAD_ENUM),
    }
}

fn filter_from_core(f: &BearingFilter<f32>) -> ph_bearing_filter {
    match *f {
        BearingFilter::FiniteDifference => ph_bearing_filter {
            kind: ph_filter_kind::PH_FILTER_FINITE_DIFFERENCE as u8,
            ..ph_bearing_filter::default()
        },
        BearingFilter::Tracker(TrackerConfig {
            bearing_noise,
            rate_noise,
            inverse_range_noise,
            gate,
        }) => ph_bearing_filter {
            kind: ph_filter_kind::PH_FILTER_TRACKER as u8,
            bearing_noise,
            rate_noise,
            inverse_range_noise,
            gate,
        },
    }
}

/// The core's configuration of a C configuration. Checks only what the C form can get
/// wrong (counts, enum values); the core's [`ph_formation_core::Agent::new`] checks the
/// rest.
pub fn to_core(c: &ph_config) -> Result<FfiConfig, ph_status> {
    let ph_config {
        id,
        estimator,
        has_leader,
        triangle_count,
        triangles,
        initial_estimate,
        min_estimate,
        friction,
        velocity_damping,
        velocity_reference,
        leader,
        limits,
        bearing_filter,
        integrity,
        comm_every,
        comm_phase,
        auth_key,
    } = c;
    let n = usize::try_from(*triangle_count).unwrap_or(usize::MAX);
    let used = triangles
        .get(..n)
        .ok_or(ph_status::PH_ERR_CONFIG_TOO_MANY_TRIANGLES)?;
    let mut tris = heapless::Vec::new();
    for t in used {
        let ph_triangle { vertices, angles } = t;
        tris.push(TriangleConfig {
            vertices: *vertices,
            angles: angles.each_ref().map(angle_to_core),
        })
        .map_err(|_| ph_status::PH_ERR_CONFIG_TOO_MANY_TRIANGLES)?;
    }
    let leader = if *has_leader != 0 {
        let ph_leader {
            role,
            partner,
            stiffness,
            damping,
            displacement,
        } = leader;
        Some(LeaderConfig {
            role: role_to_core(*role)?,
            partner: *partner,
            stiffness: *stiffness,
            damping: *damping,
            displacement: schedule_to_core(displacement)?,
        })
    } else {
        None
    };
    Ok(AgentConfig {
        id: *id,
        triangles: tris,
        estimator: estimator_to_core(*estimator)?,
        initial_estimate: *initial_estimate,
        min_estimate: *min_estimate,
        friction: *friction,
        velocity_damping: *velocity_damping,
        velocity_reference: schedule_to_core(velocity_reference)?,
        leader,
        limits: limits_to_core(limits),
        bearing_filter: filter_to_core(bearing_filter)?,
        integrity: integrity_to_core(*integrity, auth_key)?,
        comm_every: *comm_every,
        comm_phase: *comm_phase,
    })
}

/// The C form of a core configuration (exact: `to_core(&from_core(c)) == c`).
pub fn from_core(c: &FfiConfig) -> ph_config {
    let AgentConfig {
        id,
        triangles,
        estimator,
        initial_estimate,
        min_estimate,
        friction,
        velocity_damping,
        velocity_reference,
        leader,
        limits,
        bearing_filter,
        integrity,
        comm_every,
        comm_phase,
    } = c;
    let (integrity, auth_key) = integrity_from_core(integrity);
    let mut out = ph_config {
        integrity: integrity as u8,
        auth_key,
        comm_every: *comm_every,
        comm_phase: *comm_phase,
        id: *id,
        estimator: estimator_from_core(*estimator) as u8,
        // At most PH_MAX_TRIANGLES (the core's capacity).
        triangle_count: u32::try_from(triangles.len()).unwrap_or(0),
        initial_estimate: *initial_estimate,
        min_estimate: *min_estimate,
        friction: *friction,
        velocity_damping: *velocity_damping,
        velocity_reference: schedule_from_core(velocity_reference),
        limits: limits_from_core(limits),
        bearing_filter: filter_from_core(bearing_filter),
        ..ph_config::default()
    };
    for (dst, t) in out.triangles.iter_mut().zip(triangles) {
        let TriangleConfig { vertices, angles } = t;
        *dst = ph_triangle {
            vertices: *vertices,
            angles: angles.each_ref().map(angle_from_core),
        };
    }
    if let Some(l) = leader {
        let LeaderConfig {
            role,
            partner,
            stiffness,
            damping,
            displacement,
        } = l;
        out.has_leader = 1;
        out.leader = ph_leader {
            role: role_from_core(*role) as u8,
            partner: *partner,
            stiffness: *stiffness,
            damping: *damping,
            displacement: schedule_from_core(displacement),
        };
    }
    out
}

/// The SPEC defaults of agent `id` (the core's [`AgentConfig::new`]): no triangles, no
/// leader, shared estimators.
pub fn default_config(id: u8) -> ph_config {
    from_core(&AgentConfig::new(id))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_core_then_to_core_is_the_identity() {
        let mut c: FfiConfig = AgentConfig::new(3);
        c.estimator = EstimatorMode::PerAgent;
        c.friction = [0.5, 0.25];
        c.velocity_reference = Schedule::constant([3.0, -1.0]);
        c.triangles
            .push(TriangleConfig {
                vertices: [1, 2, 3],
                angles: [
                    AngleConfig {
                        apex: 1,
                        cos_desired: 0.0,
                        stiffness: 10.0,
                        damping: 1.0,
                        estimator_gain: 5.0,
                    },
                    AngleConfig {
                        apex: 3,
                        cos_desired: 0.7,
                        stiffness: 11.0,
                        damping: 2.0,
                        estimator_gain: 6.0,
                    },
                ],
            })
            .unwrap();
        c.leader = Some(LeaderConfig {
            role: LeaderRole::B,
            partner: 1,
            stiffness: 1.0,
            damping: [0.8, 0.9],
            displacement: Schedule::constant([10.0, -10.0]),
        });
        assert_eq!(to_core(&from_core(&c)), Ok(c));
    }

    #[test]
    fn counts_and_enums_out_of_range_are_refused() {
        let good = default_config(1);
        assert_eq!(to_core(&good), Ok(AgentConfig::new(1)));
        let mut c = good;
        c.triangle_count = 9;
        assert_eq!(
            to_core(&c),
            Err(ph_status::PH_ERR_CONFIG_TOO_MANY_TRIANGLES)
        );
        let mut c = good;
        c.velocity_reference.count = 9;
        assert_eq!(to_core(&c), Err(ph_status::PH_ERR_CONFIG_SCHEDULE_TOO_LONG));
        let mut c = good;
        c.estimator = 3;
        assert_eq!(to_core(&c), Err(ph_status::PH_ERR_CONFIG_BAD_ENUM));
        let mut c = good;
        c.has_leader = 1;
        c.leader.role = 3;
        assert_eq!(to_core(&c), Err(ph_status::PH_ERR_CONFIG_BAD_ENUM));
        // Without has_leader the leader block is not read.
        let mut c = good;
        c.leader.role = 3;
        c.leader.displacement.count = 100;
        assert!(to_core(&c).is_ok());
    }
}
