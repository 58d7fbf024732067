//! `ph_actuator_init` / `ph_actuate`: the C API's virtual-mass actuation is the core's
//! (`ph_formation_core::actuate`), takes the agent's friction, starts from the measured
//! velocity, and refuses what it must.

mod fixture;

use ph_formation_core::actuate::{VelocityCommand, VirtualMass};
use ph_formation_ffi::actuate::{ph_actuate, ph_actuator_init};
use ph_formation_ffi::api::ph_agent_init;
use ph_formation_ffi::storage::ph_agent;
use ph_formation_ffi::{ph_actuator, ph_config, ph_status, PH_AGENT_SIZE};

use fixture::Memory;

/// Agent 1 of triangle (1, 2, 3), friction (0.5, 0.25).
fn config() -> ph_config {
    let mut c = fixture::triangle_config(1);
    c.friction = [0.5, 0.25];
    c
}

fn agent(mem: &mut Memory) -> *mut ph_agent {
    let a = mem.0.as_mut_ptr().cast::<ph_agent>();
    // SAFETY: `mem` is PH_AGENT_SIZE bytes, 8-aligned, and outlives the agent's use.
    assert_eq!(
        unsafe { ph_agent_init(a, PH_AGENT_SIZE, &config()) },
        ph_status::PH_OK
    );
    a
}

#[test]
fn the_c_api_steps_the_cores_velocity_command() {
    let mut mem = Memory([0; PH_AGENT_SIZE]);
    let a = agent(&mut mem);
    let mut act = ph_actuator::default();
    // SAFETY: valid pointers.
    assert_eq!(
        unsafe { ph_actuator_init(&mut act, a, 2.0, 1.0, 0.0) },
        ph_status::PH_OK
    );
    assert_eq!(act.friction, [0.5, 0.25], "the agent's D^r");
    assert_eq!(act.has_command, 0);
    let plant = VirtualMass::new(2.0_f32, [0.5, 0.25], 1.0).unwrap();
    let mut reference = VelocityCommand::new(plant);
    let measured = [0.1_f32, -0.2];
    let mut setpoint = [0.0_f32; 2];
    for (k, force) in [[1.0_f32, 0.5], [-0.5, 2.0], [30.0, 0.0]]
        .iter()
        .enumerate()
    {
        // SAFETY: valid pointers to 2 floats.
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
        let want = reference.step(*force, measured, 0.01);
        assert_eq!(setpoint, want, "step {k}");
        assert_eq!(act.command, want);
        assert_eq!(act.has_command, 1);
    }
    // Restart: from the measured velocity again.
    act.has_command = 0;
    // SAFETY: as above.
    unsafe {
        ph_actuate(
            &mut act,
            [0.0; 2].as_ptr(),
            measured.as_ptr(),
            0.0,
            setpoint.as_mut_ptr(),
        )
    };
    assert_eq!(setpoint, measured);
}

/// With a lead, the setpoint is the core's led setpoint (S21) and the actuator keeps the
/// virtual velocity; a negative lead is refused.
#[test]
fn the_lead_is_the_cores() {
    let mut mem = Memory([0; PH_AGENT_SIZE]);
    let a = agent(&mut mem);
    let mut act = ph_actuator::default();
    // SAFETY: valid pointers.
    unsafe {
        assert_eq!(
            ph_actuator_init(&mut act, a, 1.0, 2.0, -0.1),
            ph_status::PH_ERR_ARGUMENT
        );
        assert_eq!(
            ph_actuator_init(&mut act, a, 1.0, 2.0, 0.23),
            ph_status::PH_OK
        );
    }
    assert_eq!(act.lead, 0.23);
    let plant = VirtualMass::new(1.0_f32, [0.5, 0.25], 2.0)
        .and_then(|p| p.with_lead(0.23))
        .unwrap();
    let mut reference = VelocityCommand::new(plant);
    let (measured, force) = ([0.1_f32, 0.0], [1.0_f32, -1.0]);
    let mut setpoint = [0.0_f32; 2];
    for _ in 0..3 {
        // SAFETY: valid pointers to 2 floats.
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
        assert_eq!(setpoint, reference.step(force, measured, 0.01));
        assert_eq!(Some(act.command), reference.command());
        assert_ne!(setpoint, act.command, "the lead moves the setpoint ahead");
    }
}

#[test]
fn bad_arguments_are_refused() {
    let mut mem = Memory([0; PH_AGENT_SIZE]);
    let a = agent(&mut mem);
    let mut act = ph_actuator::default();
    // SAFETY: valid pointers (or NULL).
    unsafe {
        assert_eq!(
            ph_actuator_init(&mut act, a, 0.0, 1.0, 0.0),
            ph_status::PH_ERR_ARGUMENT
        );
        assert_eq!(
            ph_actuator_init(&mut act, a, 1.0, f32::NAN, 0.0),
            ph_status::PH_ERR_ARGUMENT
        );
        assert_eq!(
            ph_actuator_init(core::ptr::null_mut(), a, 1.0, 1.0, 0.0),
            ph_status::PH_ERR_NULL
        );
        let zero = Memory([0; PH_AGENT_SIZE]);
        assert_eq!(
            ph_actuator_init(&mut act, zero.0.as_ptr().cast(), 1.0, 1.0, 0.0),
            ph_status::PH_ERR_NOT_INITIALIZED
        );
        // A never-initialised actuator (mass 0) is refused and left alone.
        let mut out = [7.0_f32; 2];
        let f = [1.0_f32; 2];
        assert_eq!(
            ph_actuate(&mut act, f.as_ptr(), f.as_ptr(), 0.01, out.as_mut_ptr()),
            ph_status::PH_ERR_ARGUMENT
        );
        assert_eq!(out, [7.0, 7.0]);
        assert_eq!(
            ph_actuate(
                &mut act,
                core::ptr::null(),
                f.as_ptr(),
                0.01,
                out.as_mut_ptr()
            ),
            ph_status::PH_ERR_NULL
        );
    }
}
