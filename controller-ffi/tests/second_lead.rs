//! `ph_actuator_set_second_lead` (SPEC S21b) and `ph_actuator_set_jerk_filter` (S21d):
//! the C API's second-order lead and its jerk filter are the core's, kept across calls in
//! the `ph_actuator`, and refuse what they must.

mod fixture;

use ph_formation_core::actuate::{VelocityCommand, VirtualMass};
use ph_formation_ffi::actuate::{
    ph_actuate, ph_actuator_init, ph_actuator_set_jerk_filter, ph_actuator_set_second_lead,
};
use ph_formation_ffi::api::ph_agent_init;
use ph_formation_ffi::storage::ph_agent;
use ph_formation_ffi::{ph_actuator, ph_config, ph_status, PH_AGENT_SIZE};

use fixture::Memory;

const LEAD: f32 = 0.2337;
const SECOND: f32 = 0.039;

fn config() -> ph_config {
    let mut c = fixture::triangle_config(1);
    c.friction = [0.5, 0.25];
    c
}

/// An actuator of mass 1 and speed limit 1 for the triangle agent, with lead
/// [`LEAD`] (the agent's memory is only read by `ph_actuator_init`).
fn actuator() -> ph_actuator {
    let mut mem = Memory([0; PH_AGENT_SIZE]);
    let a = mem.0.as_mut_ptr().cast::<ph_agent>();
    // SAFETY: `mem` is PH_AGENT_SIZE bytes, 8-aligned, and outlives the agent's use.
    assert_eq!(
        unsafe { ph_agent_init(a, PH_AGENT_SIZE, &config()) },
        ph_status::PH_OK
    );
    let mut act = ph_actuator::default();
    // SAFETY: valid pointers.
    assert_eq!(
        unsafe { ph_actuator_init(&mut act, a, 1.0, 1.0, LEAD) },
        ph_status::PH_OK
    );
    act
}

/// [`actuator`] with the second lead and the jerk filter `filter` (s).
fn filtered_actuator(filter: f32) -> ph_actuator {
    let mut act = actuator();
    // SAFETY: valid pointer.
    unsafe {
        assert_eq!(
            ph_actuator_set_second_lead(&mut act, SECOND),
            ph_status::PH_OK
        );
        assert_eq!(
            ph_actuator_set_jerk_filter(&mut act, filter),
            ph_status::PH_OK
        );
    }
    act
}

/// One `ph_actuate` of `act` over 10 ms: its setpoint (the call must succeed).
fn actuate(act: &mut ph_actuator, force: [f32; 2], measured: [f32; 2]) -> [f32; 2] {
    let mut setpoint = [0.0_f32; 2];
    // SAFETY: valid pointers, 2 floats each.
    let s = unsafe {
        ph_actuate(
            act,
            force.as_ptr(),
            measured.as_ptr(),
            0.01,
            setpoint.as_mut_ptr(),
        )
    };
    assert_eq!(s, ph_status::PH_OK);
    setpoint
}

/// The core's plant of [`actuator`], with the second lead when `second`.
fn core_plant(second: bool) -> VirtualMass<f32> {
    let p = VirtualMass::new(1.0_f32, [0.5, 0.25], 1.0)
        .and_then(|p| p.with_lead(LEAD))
        .unwrap();
    if second {
        p.with_second_lead(SECOND).unwrap()
    } else {
        p
    }
}

/// Steps `act` through forces that change (so the jerk term acts): every setpoint must
/// be `same`'s, bit for bit; returns whether one differed from `other`'s.
fn steps_match(
    act: &mut ph_actuator,
    mut same: VelocityCommand<f32>,
    mut other: VelocityCommand<f32>,
) -> bool {
    let measured = [0.1_f32, -0.2];
    let mut differs = false;
    for force in [[0.2_f32, 0.1], [0.4, 0.1], [0.5, -0.3], [0.1, 0.0]] {
        let setpoint = actuate(act, force, measured);
        assert_eq!(setpoint, same.step(force, measured, 0.01));
        differs |= setpoint != other.step(force, measured, 0.01);
    }
    differs
}

/// The C API's setpoints with lead 0.2337 s and second lead 0.039 s² are the core's,
/// bit for bit, over steps whose force changes (so the jerk term acts); without the
/// second lead they differ (negative control).
#[test]
fn the_c_api_leads_like_the_core() {
    let mut act = actuator();
    // SAFETY: valid pointer.
    assert_eq!(
        unsafe { ph_actuator_set_second_lead(&mut act, SECOND) },
        ph_status::PH_OK
    );
    assert!(steps_match(
        &mut act,
        VelocityCommand::new(core_plant(true)),
        VelocityCommand::new(core_plant(false)),
    ));
    // SAFETY: valid pointer.
    assert_eq!(
        unsafe { ph_actuator_set_second_lead(&mut act, f32::NAN) },
        ph_status::PH_ERR_ARGUMENT
    );
    // SAFETY: NULL is allowed and refused.
    assert_ne!(
        unsafe { ph_actuator_set_second_lead(std::ptr::null_mut(), 0.0) },
        ph_status::PH_OK
    );
}

/// With the jerk filter (0.03 s) the C API's setpoints are the core's filtered ones, bit
/// for bit, and differ from S21b's plain difference (negative control); a negative or
/// NaN time constant is refused.
#[test]
fn the_c_api_filters_the_jerk_like_the_core() {
    let filter = 0.03_f32;
    let mut act = filtered_actuator(filter);
    let filtered = core_plant(true).with_jerk_filter(filter).unwrap();
    assert!(steps_match(
        &mut act,
        VelocityCommand::new(filtered),
        VelocityCommand::new(core_plant(true)),
    ));
    for bad in [f32::NAN, -0.01, f32::INFINITY] {
        // SAFETY: valid pointer.
        assert_eq!(
            unsafe { ph_actuator_set_jerk_filter(&mut act, bad) },
            ph_status::PH_ERR_ARGUMENT
        );
    }
}

/// `has_command = 0` (what the app does on the safe output) is the core's
/// `VelocityCommand::reseed`, bit for bit: the virtual velocity starts from the measured
/// one and the jerk filter goes on from the kept acceleration; the core's `restart`
/// (which drops it) differs (negative control).
#[test]
fn a_cleared_command_is_the_cores_reseed() {
    let mut act = filtered_actuator(0.03);
    let plant = core_plant(true).with_jerk_filter(0.03).unwrap();
    let (mut same, mut other) = (VelocityCommand::new(plant), VelocityCommand::new(plant));
    let measured = [0.1_f32, -0.2];
    let mut differs = false;
    for (k, force) in [[0.2_f32, 0.1], [0.4, 0.1], [0.5, -0.3], [0.1, 0.0]]
        .iter()
        .cycle()
        .take(12)
        .enumerate()
    {
        if k == 6 {
            act.has_command = 0;
            same.reseed();
            other.restart();
        }
        let setpoint = actuate(&mut act, *force, measured);
        assert_eq!(setpoint, same.step(*force, measured, 0.01), "step {k}");
        let o = other.step(*force, measured, 0.01);
        differs |= k >= 6 && setpoint != o;
    }
    assert!(differs, "the restart's setpoints equal the re-seed's");
}
