//! Actuation through the virtual mass of SPEC S1 (`ph_formation_core::actuate`): the
//! force of `ph_step` turned into a velocity setpoint, for vehicles that track velocity
//! (the Crazyflie app, `crazyflie-app/src/agent_loop.c`).

use ph_formation_core::actuate::{VelocityCommand, VirtualMass};

use crate::api::{check, input, status, write};
use crate::status::ph_status;
use crate::storage::{self, ph_agent};

/// The virtual plant `m v̇ = −D^r v + U` (SPEC S1) and its velocity setpoint. Fill it
/// with `ph_actuator_init`; set `has_command = 0` to make the next `ph_actuate` start
/// again from the measured velocity (e.g. when the formation takes over the vehicle).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ph_actuator {
    /// Virtual mass `m` (kg, > 0).
    pub mass: f32,
    /// Friction `D^r` per axis (N s/m, ≥ 0): the agent's `ph_config.friction`.
    pub friction: [f32; 2],
    /// Largest setpoint speed (m/s, > 0; `INFINITY` for none): the vehicle's limit.
    pub max_speed: f32,
    /// Lead (s, ≥ 0): the time constant of the vehicle's own velocity loop, which the
    /// setpoints anticipate (SPEC S21); 0 for none.
    pub lead: f32,
    /// The virtual velocity (m/s, world frame: the setpoint without lead), valid when
    /// `has_command`.
    pub command: [f32; 2],
    /// 1 once `ph_actuate` has produced a setpoint.
    pub has_command: u8,
    /// Second-order lead (s², ≥ 0; SPEC S21b): `ph_actuator_set_second_lead`; 0 for
    /// none (`ph_actuator_init` sets 0).
    pub second_lead: f32,
    /// The virtual acceleration of the last step (m/s²), valid when `has_accel`.
    pub accel: [f32; 2],
    /// 1 once `ph_actuate` has kept a virtual acceleration (with a second-order lead).
    pub has_accel: u8,
    /// The gap bound (m/s, ≥ 0; 0 or `INFINITY` for none; SPEC S21c): the virtual
    /// velocity is kept within this of the measured one. `ph_actuator_init` sets
    /// `INFINITY`; `ph_actuator_set_max_gap` sets it.
    pub max_gap: f32,
    /// The stall limit (s, ≥ 0; 0 or `INFINITY` for none; SPEC S21c): a `ph_actuate`
    /// over a longer `dt` starts again from the measured velocity. `ph_actuator_init`
    /// sets the agent's `neighbour_timeout`.
    pub max_interval: f32,
    /// The time constant of the filter on the second-order lead's jerk (s, ≥ 0; 0 for
    /// none; SPEC S21d): `ph_actuator_set_jerk_filter`; `ph_actuator_init` sets 0. With
    /// it, `accel` holds the filtered acceleration.
    pub jerk_filter: f32,
}

/// Fills `*actuator` for `agent`: mass `mass`, the friction `D^r` of the agent's
/// configuration (so that the controller cancels the friction the plant has), speed
/// limit `max_speed`, lead `lead` (the vehicle's velocity-loop time constant, SPEC S21;
/// 0 for none), no gap bound, the agent's neighbour timeout as the stall limit (S21c),
/// no setpoint yet. `PH_ERR_ARGUMENT` for a mass that is not finite and
/// positive, a `max_speed` that is NaN or not positive, or a lead that is not finite and
/// non-negative.
///
/// # Safety
/// `actuator` is NULL or writable; `agent` as for `ph_stats`.
#[no_mangle]
pub unsafe extern "C" fn ph_actuator_init(
    actuator: *mut ph_actuator,
    agent: *const ph_agent,
    mass: f32,
    max_speed: f32,
    lead: f32,
) -> ph_status {
    // SAFETY: per this function's contract.
    let r = unsafe { storage::agent_ref(agent) }.and_then(|a| {
        let friction = a.config().friction;
        let plant = VirtualMass::new(mass, friction, max_speed)
            .and_then(|p| p.with_lead(lead))
            .and_then(|p| p.with_max_interval(a.config().limits.neighbour_timeout))
            .map_err(|_| ph_status::PH_ERR_ARGUMENT)?;
        let value = ph_actuator {
            mass: plant.mass(),
            friction: plant.friction(),
            max_speed: plant.max_speed(),
            lead: plant.lead(),
            command: [0.0; 2],
            has_command: 0,
            second_lead: 0.0,
            accel: [0.0; 2],
            has_accel: 0,
            max_gap: plant.max_gap(),
            max_interval: plant.max_interval(),
            jerk_filter: 0.0,
        };
        // SAFETY: per this function's contract.
        unsafe { write(actuator, value) }
    });
    status(r)
}

/// Sets the second-order lead of `*actuator` (s², finite, ≥ 0; SPEC S21b: `τ τ_a` of a
/// vehicle whose velocity loop `τ` acts through an attitude loop `τ_a`, 0.039 s² for the
/// Crazyflie's PID cascade, docs/world.md) and forgets the kept acceleration.
/// `PH_ERR_ARGUMENT` (nothing written) for a value that is not finite and non-negative.
///
/// # Safety
/// `actuator` is NULL or points to a `ph_actuator`.
#[no_mangle]
pub unsafe extern "C" fn ph_actuator_set_second_lead(
    actuator: *mut ph_actuator,
    second_lead: f32,
) -> ph_status {
    let r = (|| {
        if !(second_lead.is_finite() && second_lead >= 0.0) {
            return Err(ph_status::PH_ERR_ARGUMENT);
        }
        // SAFETY: per this function's contract.
        let a = unsafe { input(actuator.cast_const()) }?;
        let updated = ph_actuator {
            second_lead,
            has_accel: 0,
            ..*a
        };
        // SAFETY: per this function's contract.
        unsafe { write(actuator, updated) }
    })();
    status(r)
}

/// Sets the time constant of the filter on the second-order lead's jerk (s, finite,
/// ≥ 0; SPEC S21d: 0.03 s for the Crazyflie, docs/world.md) and forgets the kept
/// acceleration. `PH_ERR_ARGUMENT` (nothing written) for a value that is not finite and
/// non-negative.
///
/// # Safety
/// `actuator` is NULL or points to a `ph_actuator`.
#[no_mangle]
pub unsafe extern "C" fn ph_actuator_set_jerk_filter(
    actuator: *mut ph_actuator,
    jerk_filter: f32,
) -> ph_status {
    let r = (|| {
        if !(jerk_filter.is_finite() && jerk_filter >= 0.0) {
            return Err(ph_status::PH_ERR_ARGUMENT);
        }
        // SAFETY: per this function's contract.
        let a = unsafe { input(actuator.cast_const()) }?;
        let updated = ph_actuator {
            jerk_filter,
            has_accel: 0,
            ..*a
        };
        // SAFETY: per this function's contract.
        unsafe { write(actuator, updated) }
    })();
    status(r)
}

/// Sets the gap bound of `*actuator` (m/s, > 0; `INFINITY` for none; SPEC S21c): the
/// virtual velocity is kept within `max_gap` of the measured one, so that a blocked or
/// saturated vehicle does not let it run ahead. `PH_ERR_ARGUMENT` (nothing written) for
/// a NaN or non-positive value.
///
/// # Safety
/// `actuator` is NULL or points to a `ph_actuator`.
#[no_mangle]
pub unsafe extern "C" fn ph_actuator_set_max_gap(
    actuator: *mut ph_actuator,
    max_gap: f32,
) -> ph_status {
    let r = (|| {
        if max_gap.is_nan() || max_gap <= 0.0 {
            return Err(ph_status::PH_ERR_ARGUMENT);
        }
        // SAFETY: per this function's contract.
        let a = unsafe { input(actuator.cast_const()) }?;
        let updated = ph_actuator { max_gap, ..*a };
        // SAFETY: per this function's contract.
        unsafe { write(actuator, updated) }
    })();
    status(r)
}

/// One control period: integrates S1 from the previous virtual velocity (the first time
/// from `velocity[0..2]`, the vehicle's measured velocity) under `force[0..2]` (the
/// `ph_output.force` of this tick) for `dt` seconds (SPEC S20), keeps the new virtual
/// velocity in `actuator->command`, and writes the setpoint (S21: led by
/// `actuator->lead`) to `setpoint[0..2]`. S21c: the previous virtual velocity is kept
/// within `actuator->max_gap` of `velocity`, and a `dt` above `actuator->max_interval`
/// starts again from `velocity`; set `has_command = 0` once a safe output has lasted
/// `max_interval` (SPEC S21c). `PH_ERR_ARGUMENT` (nothing written) for an actuator
/// whose parameters `ph_actuator_init` would refuse.
///
/// # Safety
/// `actuator` is NULL or points to a `ph_actuator`; `force` and `velocity` are NULL or
/// point to 2 readable floats; `setpoint` is NULL or points to 2 writable floats.
#[no_mangle]
pub unsafe extern "C" fn ph_actuate(
    actuator: *mut ph_actuator,
    force: *const f32,
    velocity: *const f32,
    dt: f32,
    setpoint: *mut f32,
) -> ph_status {
    let r = (|| {
        // SAFETY: per this function's contract (2 floats each).
        let force = unsafe { input(force.cast::<[f32; 2]>()) }?;
        // SAFETY: as above.
        let velocity = unsafe { input(velocity.cast::<[f32; 2]>()) }?;
        check(setpoint.cast_const())?;
        // SAFETY: per this function's contract.
        let a = unsafe { input(actuator.cast_const()) }?;
        let plant = VirtualMass::new(a.mass, a.friction, a.max_speed)
            .and_then(|p| p.with_lead(a.lead))
            .and_then(|p| p.with_second_lead(a.second_lead))
            .and_then(|p| p.with_jerk_filter(a.jerk_filter))
            .and_then(|p| p.with_max_gap(none_if_zero(a.max_gap)))
            .and_then(|p| p.with_max_interval(none_if_zero(a.max_interval)))
            .map_err(|_| ph_status::PH_ERR_ARGUMENT)?;
        let mut command = VelocityCommand::resume_with_accel(
            plant,
            (a.has_command != 0).then_some(a.command),
            (a.has_accel != 0).then_some(a.accel),
        );
        let next = command.step(*force, *velocity, dt);
        let accel = command.accel();
        let updated = ph_actuator {
            command: command.command().unwrap_or(next),
            has_command: 1,
            accel: accel.unwrap_or([0.0; 2]),
            has_accel: u8::from(accel.is_some()),
            ..*a
        };
        // SAFETY: per this function's contract.
        unsafe { write(actuator, updated) }?;
        // SAFETY: per this function's contract (2 writable floats).
        unsafe { write(setpoint.cast::<[f32; 2]>(), next) }
    })();
    status(r)
}

/// 0 (a zero-filled `ph_actuator` of ABI 6) as "none": infinity.
fn none_if_zero(x: f32) -> f32 {
    if x == 0.0 {
        f32::INFINITY
    } else {
        x
    }
}
