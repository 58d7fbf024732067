//! A simulated Crazyflie for the tests that fly the app's C code (feature `sim-vehicle`,
//! off in the flight build): the firmware's PID cascade of `ph-formation-vehicle`, the
//! same implementation host-sim's `[plant] model = "crazyflie_pid"` flies
//! (docs/world.md, "The Crazyflie's cascade").

use ph_formation_vehicle::crazyflie::{Crazyflie, WORDS};

use crate::api::{input, status, write};
use crate::status::ph_status;

/// Words of a `ph_vehicle`'s cascade state.
pub const PH_VEHICLE_STATE_LEN: usize = 16;
const _: [(); PH_VEHICLE_STATE_LEN] = [(); WORDS];

/// One simulated Crazyflie (plain data: copy it freely). Fill it with
/// `ph_vehicle_init`; read `q`, `v` and `tilt` after each `ph_vehicle_step`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ph_vehicle {
    /// Position (m, world frame).
    pub q: [f32; 2],
    /// Velocity (m/s, world frame).
    pub v: [f32; 2],
    /// Total tilt from vertical (rad).
    pub tilt: f32,
    /// The cascade's state (opaque; any content steps without fault).
    pub state: [f64; PH_VEHICLE_STATE_LEN],
}

impl ph_vehicle {
    fn of(drone: &Crazyflie) -> Self {
        // f64 → f32: the C side's view; the state keeps f64.
        let f = |x: [f64; 2]| x.map(|a| a as f32);
        Self {
            q: f(drone.q),
            v: f(drone.v),
            tilt: drone.tilt() as f32,
            state: drone.to_words(),
        }
    }
}

/// Fills `*vehicle` with a level Crazyflie at `q[0..2]` (m) moving with `v[0..2]`
/// (m/s), its controllers' integrals empty. `PH_ERR_ARGUMENT` for a value that is not
/// finite.
///
/// # Safety
/// `vehicle` is NULL or writable; `q` and `v` are NULL or point to 2 readable floats.
#[no_mangle]
pub unsafe extern "C" fn ph_vehicle_init(
    vehicle: *mut ph_vehicle,
    q: *const f32,
    v: *const f32,
) -> ph_status {
    let r = (|| {
        // SAFETY: per this function's contract (2 floats each).
        let q = unsafe { input(q.cast::<[f32; 2]>()) }?;
        // SAFETY: as above.
        let v = unsafe { input(v.cast::<[f32; 2]>()) }?;
        if !q.iter().chain(v).all(|x| x.is_finite()) {
            return Err(ph_status::PH_ERR_ARGUMENT);
        }
        let drone = Crazyflie::new(q.map(f64::from), v.map(f64::from));
        // SAFETY: per this function's contract.
        unsafe { write(vehicle, ph_vehicle::of(&drone)) }
    })();
    status(r)
}

/// Flies `*vehicle` for `dt` seconds (> 0, finite; split at the firmware's 500 Hz
/// attitude ticks) toward the velocity setpoint `setpoint[0..2]` (m/s, world frame), as
/// the commander's velocity-mode setpoint. `PH_ERR_ARGUMENT` (nothing written) for a bad
/// `dt` or a setpoint that is not finite.
///
/// # Safety
/// `vehicle` is NULL or points to a `ph_vehicle`; `setpoint` is NULL or points to 2
/// readable floats.
#[no_mangle]
pub unsafe extern "C" fn ph_vehicle_step(
    vehicle: *mut ph_vehicle,
    setpoint: *const f32,
    dt: f32,
) -> ph_status {
    let r = (|| {
        // SAFETY: per this function's contract.
        let sp = unsafe { input(setpoint.cast::<[f32; 2]>()) }?;
        // SAFETY: per this function's contract.
        let current = unsafe { input(vehicle.cast_const()) }?;
        if !(dt.is_finite() && dt > 0.0 && sp.iter().all(|x| x.is_finite())) {
            return Err(ph_status::PH_ERR_ARGUMENT);
        }
        let mut drone = Crazyflie::from_words(current.state);
        drone.step(sp.map(f64::from), [0.0; 2], f64::from(dt));
        // SAFETY: per this function's contract.
        unsafe { write(vehicle, ph_vehicle::of(&drone)) }
    })();
    status(r)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The C entry points fly the vehicle crate's Crazyflie: 300 steps of 1 ms through
    /// the API land where the crate's own drone does; bad arguments are refused.
    #[test]
    fn steps_as_the_vehicle_crate() {
        let mut veh = core::mem::MaybeUninit::<ph_vehicle>::uninit();
        let p = veh.as_mut_ptr();
        // SAFETY: valid pointers to 2 floats; `p` is writable.
        let s = unsafe { ph_vehicle_init(p, [1.0f32, 2.0].as_ptr(), [0.0f32; 2].as_ptr()) };
        assert_eq!(s, ph_status::PH_OK);
        let mut drone = Crazyflie::new([1.0, 2.0], [0.0; 2]);
        for _ in 0..300 {
            // SAFETY: `p` was initialised above.
            let s = unsafe { ph_vehicle_step(p, [0.5f32, -0.25].as_ptr(), 1e-3) };
            assert_eq!(s, ph_status::PH_OK);
            drone.step([0.5, -0.25], [0.0; 2], f64::from(1e-3f32));
        }
        // SAFETY: initialised.
        let veh = unsafe { veh.assume_init() };
        assert_eq!(veh.state, drone.to_words());
        assert!(veh.v[0] > 0.3 && veh.tilt > 0.0, "{veh:?}");
        let mut copy = veh;
        for bad in [0.0f32, -1e-3, f32::NAN, f32::INFINITY] {
            // SAFETY: valid pointers.
            let s = unsafe { ph_vehicle_step(&mut copy, [0.0f32; 2].as_ptr(), bad) };
            assert_eq!(s, ph_status::PH_ERR_ARGUMENT);
        }
        assert_eq!(copy, veh, "nothing written on a refusal");
        // SAFETY: NULL is allowed.
        let s = unsafe { ph_vehicle_step(core::ptr::null_mut(), [0.0f32; 2].as_ptr(), 1e-3) };
        assert_eq!(s, ph_status::PH_ERR_NULL);
    }
}
