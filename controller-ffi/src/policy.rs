//! The safety policies of `ph_formation_core::policy` for C (`crazyflie-app/src/flight.c`):
//! lost neighbours or radio → hold, then land; flight volume; positioning; low battery;
//! and the minimum-separation guard on a setpoint. One implementation: the simulator
//! runs the same (host-sim's controller adapter).

use ph_formation_core::policy::{
    separation_guard, Policy, PolicyAction, PolicyConfig, PolicyCounts, PolicyInputs, PolicyReason,
};
use ph_formation_core::Vec2;

use crate::api::{check, input, status, write};
use crate::status::ph_status;

/// The policies' settings (`ph_formation_core::policy::PolicyConfig`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ph_policy_config {
    /// Lost neighbours or radio for this long (ms): land (holding until then).
    pub hold_timeout_ms: u32,
    /// Non-zero: the flight volume `fence_min`–`fence_max` is checked.
    pub fence: u8,
    /// The flight volume's lower corner (m, world frame).
    pub fence_min: [f32; 2],
    /// Its upper corner (m).
    pub fence_max: [f32; 2],
    /// Battery voltage to land below (V; 0: off).
    pub battery_land: f32,
    /// For this long (ms).
    pub battery_ms: u32,
    /// Minimum separation of `ph_separation_guard` (m; 0: off).
    pub min_separation: f32,
}

/// What the vehicle should do (`ph_policy_update`).
#[repr(u8)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ph_policy_action {
    /// Fly the formation.
    #[default]
    PH_POLICY_FLY = 0,
    /// Hold the position.
    PH_POLICY_HOLD = 1,
    /// Land.
    PH_POLICY_LAND = 2,
}

/// Why (`ph_policy_update`, `ph_policy.last_landing`).
#[repr(u8)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ph_policy_reason {
    /// Nothing wrong.
    #[default]
    PH_POLICY_NONE = 0,
    /// Neighbours or radio lost (holding).
    PH_POLICY_LOST = 1,
    /// Lost for `hold_timeout_ms` (landing).
    PH_POLICY_LOST_TIMEOUT = 2,
    /// Outside the flight volume (landing).
    PH_POLICY_FENCE = 3,
    /// Battery low (landing).
    PH_POLICY_BATTERY = 4,
    /// Positioning lost (landing).
    PH_POLICY_POSITIONING = 5,
}

/// The policies' state and counts, in caller memory: zero it (`ph_policy_init`) and
/// hand it to every `ph_policy_update`. The counts are for the log (the app's log group
/// `formation`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ph_policy {
    /// Lost for this long (ms).
    pub lost_ms: u32,
    /// Battery low for this long (ms).
    pub low_ms: u32,
    /// Lost at the last update.
    pub lost: u8,
    /// Low at the last update.
    pub low: u8,
    /// The landing decided (a `ph_policy_reason`; `PH_POLICY_NONE`: none).
    pub landing: u8,
    /// The reason of the last landing (a `ph_policy_reason`).
    pub last_landing: u8,
    /// Ticks answered with `PH_POLICY_HOLD`.
    pub hold_ticks: u32,
    /// Landings decided.
    pub landings: u32,
    /// Setpoints `ph_separation_guard` changed.
    pub guarded: u32,
}

/// One tick's inputs of `ph_policy_update`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ph_policy_input {
    /// Milliseconds since the previous update (0 on the first): integer time.
    pub dt_ms: u32,
    /// Non-zero: this tick's `ph_step` gave the safe output (neighbours or radio lost).
    pub lost: u8,
    /// Non-zero: the positioning system is locked.
    pub positioning: u8,
    /// Own position (m, world frame).
    pub position: [f32; 2],
    /// Battery voltage (V).
    pub battery: f32,
}

fn reason(r: PolicyReason) -> ph_policy_reason {
    use ph_policy_reason::*;
    match r {
        PolicyReason::None => PH_POLICY_NONE,
        PolicyReason::Lost => PH_POLICY_LOST,
        PolicyReason::LostTimeout => PH_POLICY_LOST_TIMEOUT,
        PolicyReason::Fence => PH_POLICY_FENCE,
        PolicyReason::Battery => PH_POLICY_BATTERY,
        PolicyReason::Positioning => PH_POLICY_POSITIONING,
    }
}

fn reason_of(code: u8) -> Result<PolicyReason, ph_status> {
    Ok(match code {
        0 => PolicyReason::None,
        1 => PolicyReason::Lost,
        2 => PolicyReason::LostTimeout,
        3 => PolicyReason::Fence,
        4 => PolicyReason::Battery,
        5 => PolicyReason::Positioning,
        _ => return Err(ph_status::PH_ERR_ARGUMENT),
    })
}

fn action(a: PolicyAction) -> ph_policy_action {
    match a {
        PolicyAction::Fly => ph_policy_action::PH_POLICY_FLY,
        PolicyAction::Hold => ph_policy_action::PH_POLICY_HOLD,
        PolicyAction::Land => ph_policy_action::PH_POLICY_LAND,
    }
}

fn to_core(p: &ph_policy) -> Result<Policy, ph_status> {
    let landing = reason_of(p.landing)?;
    Ok(Policy {
        lost_ms: p.lost_ms,
        low_ms: p.low_ms,
        lost: p.lost != 0,
        low: p.low != 0,
        landing: (landing != PolicyReason::None).then_some(landing),
        counts: PolicyCounts {
            hold_ticks: p.hold_ticks,
            landings: p.landings,
            last_landing: reason_of(p.last_landing)?,
            guarded: p.guarded,
        },
    })
}

fn from_core(p: &Policy) -> ph_policy {
    ph_policy {
        lost_ms: p.lost_ms,
        low_ms: p.low_ms,
        lost: u8::from(p.lost),
        low: u8::from(p.low),
        landing: reason(p.landing.unwrap_or(PolicyReason::None)) as u8,
        last_landing: reason(p.counts.last_landing) as u8,
        hold_ticks: p.counts.hold_ticks,
        landings: p.counts.landings,
        guarded: p.counts.guarded,
    }
}

fn config(c: &ph_policy_config) -> Result<PolicyConfig<f32>, ph_status> {
    let core = PolicyConfig {
        hold_timeout_ms: c.hold_timeout_ms,
        fence: c.fence != 0,
        fence_min: c.fence_min,
        fence_max: c.fence_max,
        battery_land: c.battery_land,
        battery_ms: c.battery_ms,
        min_separation: c.min_separation,
    };
    if core.is_valid() {
        Ok(core)
    } else {
        Err(ph_status::PH_ERR_ARGUMENT)
    }
}

/// Zeroes `*policy`: flying, nothing counted.
///
/// # Safety
/// `policy` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ph_policy_init(policy: *mut ph_policy) -> ph_status {
    // SAFETY: per this function's contract.
    status(unsafe { write(policy, ph_policy::default()) })
}

/// A new flight: the timers and the landing forgotten, the counts kept.
///
/// # Safety
/// `policy` is NULL or points to a `ph_policy`.
#[no_mangle]
pub unsafe extern "C" fn ph_policy_reset(policy: *mut ph_policy) -> ph_status {
    let r = (|| {
        // SAFETY: per this function's contract.
        let mut p = to_core(unsafe { input(policy.cast_const()) }?)?;
        p.reset();
        // SAFETY: as above.
        unsafe { write(policy, from_core(&p)) }
    })();
    status(r)
}

/// One tick of the policies (`ph_formation_core::policy::Policy::update`): writes what to
/// do to `*action` and why to `*why`. `PH_ERR_ARGUMENT` (nothing changed) for settings
/// that are not finite, a fence with `min > max`, a negative voltage or separation, or
/// a `*policy` with an unknown reason code.
///
/// # Safety
/// `policy` is NULL or points to a `ph_policy`; `config` and `in` are NULL or readable;
/// `action` and `why` are NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ph_policy_update(
    policy: *mut ph_policy,
    config: *const ph_policy_config,
    in_: *const ph_policy_input,
    action_out: *mut ph_policy_action,
    why: *mut ph_policy_reason,
) -> ph_status {
    let r = (|| {
        // SAFETY: per this function's contract.
        let c = self::config(unsafe { input(config) }?)?;
        // SAFETY: as above.
        let i = unsafe { input(in_) }?;
        check(action_out.cast_const())?;
        check(why.cast_const())?;
        // SAFETY: as above.
        let mut p = to_core(unsafe { input(policy.cast_const()) }?)?;
        let (a, w) = p.update(
            &c,
            &PolicyInputs {
                dt_ms: i.dt_ms,
                lost: i.lost != 0,
                position: i.position,
                positioning: i.positioning != 0,
                battery: i.battery,
            },
        );
        // SAFETY: as above.
        unsafe { write(policy, from_core(&p)) }?;
        // SAFETY: as above.
        unsafe { write(action_out, action(a)) }?;
        // SAFETY: as above.
        unsafe { write(why, reason(w)) }
    })();
    status(r)
}

/// The minimum-separation guard (`ph_formation_core::policy::separation_guard`):
/// removes from `setpoint[0..2]` (velocity or force, world frame) its component towards
/// every neighbour of `neighbours[0..2·count]` (x, y pairs) closer to `own[0..2]` than
/// `config->min_separation`; a neighbour closer than 1 mm stops it. Counts a change in
/// `policy->guarded`. `PH_ERR_ARGUMENT` as for `ph_policy_update`.
///
/// # Safety
/// `policy` and `config` as for `ph_policy_update`; `own` is NULL or 2 readable floats;
/// `neighbours` is NULL (only with `count` 0) or `2·count` readable floats, `count` at
/// most `PH_MAX_NEIGHBOURS` (more: `PH_ERR_ARGUMENT`); `setpoint`
/// is NULL or 2 readable and writable floats.
#[no_mangle]
pub unsafe extern "C" fn ph_separation_guard(
    policy: *mut ph_policy,
    config: *const ph_policy_config,
    own: *const f32,
    neighbours: *const f32,
    count: usize,
    setpoint: *mut f32,
) -> ph_status {
    let r = (|| {
        // SAFETY: per this function's contract.
        let c = self::config(unsafe { input(config) }?)?;
        // SAFETY: as above (2 floats).
        let [ox, oy] = *unsafe { input(own.cast::<[f32; 2]>()) }?;
        // SAFETY: as above.
        let [sx, sy] = *unsafe { input(setpoint.cast_const().cast::<[f32; 2]>()) }?;
        if count > crate::PH_MAX_NEIGHBOURS {
            return Err(ph_status::PH_ERR_ARGUMENT);
        }
        // SAFETY: as above (`count` pairs).
        let pairs: &[[f32; 2]] = unsafe { crate::api::slice(neighbours.cast(), count) }?;
        // SAFETY: as above.
        let mut p = to_core(unsafe { input(policy.cast_const()) }?)?;
        let (v, changed) = separation_guard(
            Vec2::new(sx, sy),
            Vec2::new(ox, oy),
            pairs.iter().map(|&[x, y]| Vec2::new(x, y)),
            c.min_separation,
        );
        if changed {
            p.count_guard();
        }
        // SAFETY: as above.
        unsafe { write(policy, from_core(&p)) }?;
        // SAFETY: as above.
        unsafe { write(setpoint.cast::<[f32; 2]>(), [v.x, v.y]) }
    })();
    status(r)
}

/// The safety policies a configuration blob carries (`blob[0..len]`, written by
/// `host-sim export` from the scenario's `[policy]`): fills `*config`, `start[0..2]`
/// (the agent's initial position in the scenario, m) and `*start_tolerance` (m, the
/// pre-flight check's radius). The blob gets the checks of `ph_agent_init_blob`
/// (`PH_ERR_BLOB_*`); `PH_ERR_BLOB_NO_POLICY` (nothing written) when it carries none.
///
/// # Safety
/// `blob` is NULL or points to `len` readable bytes; `config` is NULL or writable;
/// `start` is NULL or points to 2 writable floats; `start_tolerance` is NULL or
/// writable.
#[no_mangle]
pub unsafe extern "C" fn ph_blob_policy(
    blob: *const u8,
    len: usize,
    config: *mut ph_policy_config,
    start: *mut f32,
    start_tolerance: *mut f32,
) -> ph_status {
    let r = (|| {
        // SAFETY: per this function's contract.
        let bytes = unsafe { crate::api::slice(blob, len) }?;
        if bytes.is_empty() {
            return Err(ph_status::PH_ERR_NULL);
        }
        check(config.cast_const())?;
        check(start.cast_const())?;
        check(start_tolerance.cast_const())?;
        let p = crate::blob::decode_blob_policy(bytes)?.ok_or(ph_status::PH_ERR_BLOB_NO_POLICY)?;
        let (fence, (fence_min, fence_max)) = match p.fence {
            Some(corners) => (1, corners),
            None => (0, ([0.0; 2], [0.0; 2])),
        };
        let c = ph_policy_config {
            hold_timeout_ms: p.hold_timeout_ms,
            fence,
            fence_min,
            fence_max,
            battery_land: p.battery_land,
            battery_ms: p.battery_ms,
            min_separation: p.min_separation,
        };
        // SAFETY: per this function's contract (checked non-null and aligned above).
        unsafe { write(config, c) }?;
        // SAFETY: as above (2 writable floats).
        unsafe { write(start.cast::<[f32; 2]>(), p.start) }?;
        // SAFETY: as above.
        unsafe { write(start_tolerance, p.start_tolerance) }
    })();
    status(r)
}
