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

fn config() -> ph_config {
    let mut c = fixture::triangle_config(1);
    c.friction = [0.5, 0.25];
    c
}

/// The C API's setpoints with lead 0.2337 s and second lead 0.039 s² are the core's,
/// bit for bit, over steps whose force changes (so the jerk term acts); without the
/// second lead they differ (negative control).
#[test]
fn the_c_api_leads_like_the_core() {
    let mut mem = Memory([0; PH_AGENT_SIZE]);
    let a = mem.0.as_mut_ptr().cast::<ph_agent>();
    // SAFETY: `mem` is PH_AGENT_SIZE bytes, 8-aligned, and outlives the agent's use.
    assert_eq!(
        unsafe { ph_agent_init(a, PH_AGENT_SIZE, &config()) },
        ph_status::PH_OK
    );
    let (lead, second) = (0.2337_f32, 0.039_f32);
    let mut act = ph_actuator::default();
    // SAFETY: valid pointers.
    assert_eq!(
        unsafe { ph_actuator_init(&mut act, a, 1.0, 1.0, lead) },
        ph_status::PH_OK
    );
    // SAFETY: valid pointer.
    assert_eq!(
        unsafe { ph_actuator_set_second_lead(&mut act, second) },
        ph_status::PH_OK
    );
    let plant = VirtualMass::new(1.0_f32, [0.5, 0.25], 1.0)
        .and_then(|p| p.with_lead(lead))
        .unwrap();
    let mut with = VelocityCommand::new(plant.with_second_lead(second).unwrap());
    let mut without = VelocityCommand::new(plant);
    let measured = [0.1_f32, -0.2];
    let mut differs = false;
    for force in [[0.2_f32, 0.1], [0.4, 0.1], [0.5, -0.3], [0.1, 0.0]] {
        let mut setpoint = [0.0_f32; 2];
        // SAFETY: valid pointers, 2 floats each.
        let s = unsafe {
            ph_actuate(
                &mut act,
                force.as_ptr(),
                measured.as_ptr(),
                0.01,
                setpoint.as_mut_ptr(),
            )
        };
        assert_eq!(s, ph_status::PH_OK);
        assert_eq!(setpoint, with.step(force, measured, 0.01));
        differs |= setpoint != without.step(force, measured, 0.01);
    }
    assert!(differs);
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
    let mut mem = Memory([0; PH_AGENT_SIZE]);
    let a = mem.0.as_mut_ptr().cast::<ph_agent>();
    // SAFETY: `mem` is PH_AGENT_SIZE bytes, 8-aligned, and outlives the agent's use.
    assert_eq!(
        unsafe { ph_agent_init(a, PH_AGENT_SIZE, &config()) },
        ph_status::PH_OK
    );
    let (lead, second, filter) = (0.2337_f32, 0.039_f32, 0.03_f32);
    let mut act = ph_actuator::default();
    // SAFETY: valid pointers.
    unsafe {
        assert_eq!(
            ph_actuator_init(&mut act, a, 1.0, 1.0, lead),
            ph_status::PH_OK
        );
        assert_eq!(
            ph_actuator_set_second_lead(&mut act, second),
            ph_status::PH_OK
        );
        assert_eq!(
            ph_actuator_set_jerk_filter(&mut act, filter),
            ph_status::PH_OK
        );
    }
    let plant = VirtualMass::new(1.0_f32, [0.5, 0.25], 1.0)
        .and_then(|p| p.with_lead(lead))
        .and_then(|p| p.with_second_lead(second))
        .unwrap();
    let mut filtered = VelocityCommand::new(plant.with_jerk_filter(filter).unwrap());
    let mut plain = VelocityCommand::new(plant);
    let measured = [0.1_f32, -0.2];
    let mut differs = false;
    for force in [[0.2_f32, 0.1], [0.4, 0.1], [0.5, -0.3], [0.1, 0.0]] {
        let mut setpoint = [0.0_f32; 2];
        // SAFETY: valid pointers, 2 floats each.
        let s = unsafe {
            ph_actuate(
                &mut act,
                force.as_ptr(),
                measured.as_ptr(),
                0.01,
                setpoint.as_mut_ptr(),
            )
        };
        assert_eq!(s, ph_status::PH_OK);
        assert_eq!(setpoint, filtered.step(force, measured, 0.01));
        differs |= setpoint != plain.step(force, measured, 0.01);
    }
    assert!(differs);
    for bad in [f32::NAN, -0.01, f32::INFINITY] {
        // SAFETY: valid pointer.
        assert_eq!(
            unsafe { ph_actuator_set_jerk_filter(&mut act, bad) },
            ph_status::PH_ERR_ARGUMENT
        );
    }
}
