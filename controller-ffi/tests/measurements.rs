//! `ph_step`'s measurement faults through the C API: a negative `dt` is
//! `PH_FAULT_NEGATIVE_DT` (issue 29), a NaN or infinite one
//! `PH_FAULT_NON_FINITE_MEASUREMENT`; and `ph_limits.bearing_hold` reaches the agent
//! (SPEC §12): a bearing missing for a tick is held with a hold, missing without.

mod fixture;

use ph_formation_ffi::api::{ph_agent_init, ph_receive, ph_step};
use ph_formation_ffi::storage::ph_agent;
use ph_formation_ffi::tick::{ph_bearing, ph_fault, ph_measurements, ph_output, ph_output_status};
use ph_formation_ffi::{ph_config, ph_status, PH_AGENT_SIZE};

use fixture::Memory;

/// Agent `id` of the triangle (1, 2, 3) with angles at 1 and 2, finite differences.
fn config(id: u8, hold: f32) -> ph_config {
    let mut c = fixture::triangle_config(id);
    c.bearing_filter = ph_formation_ffi::config::ph_bearing_filter {
        kind: ph_formation_ffi::config::ph_filter_kind::PH_FILTER_FINITE_DIFFERENCE as u8,
        ..Default::default()
    };
    c.limits.bearing_hold = hold;
    c
}

fn bearing(neighbour: u8, x: f32, y: f32) -> ph_bearing {
    ph_bearing {
        neighbour,
        flags: 0,
        direction: [x, y],
        rate: [0.0; 2],
        range: 0.0,
    }
}

/// The equilateral triangle 1 (0, 0), 2 (1, 0), 3 (½, √3/2) at rest: agent `id`'s bearings.
fn bearings(id: u8) -> Vec<ph_bearing> {
    let h = 0.866_025_4;
    match id {
        1 => vec![bearing(2, 1.0, 0.0), bearing(3, 0.5, h)],
        2 => vec![bearing(1, -1.0, 0.0), bearing(3, -0.5, h)],
        _ => vec![bearing(1, -0.5, -h), bearing(2, 0.5, -h)],
    }
}

/// Three agents; steps agent 1 with `dt` and the bearings `b1` after a first tick with
/// all bearings and frames exchanged. Returns its output.
fn second_step(hold: f32, dt: f32, b1: &[ph_bearing]) -> ph_output {
    let mut mem: Vec<Box<Memory>> = (0..3)
        .map(|_| Box::new(Memory([0; PH_AGENT_SIZE])))
        .collect();
    let agents: Vec<*mut ph_agent> = mem.iter_mut().map(|m| m.0.as_mut_ptr().cast()).collect();
    let mut out = ph_output {
        force: [0.0; 2],
        status: ph_output_status::PH_OUTPUT_NOMINAL,
        fault: ph_fault::PH_FAULT_NONE,
        fault_neighbour: -1,
        saturated: false,
        degenerate: false,
    };
    let meas = |b: &[ph_bearing], dt: f32| ph_measurements {
        time: 0.0,
        dt,
        velocity: [0.1, 0.0],
        bearings: b.as_ptr(),
        bearing_count: b.len(),
        has_partner_offset: 0,
        partner_offset: [0.0; 2],
    };
    // SAFETY: valid memory, measurements and out-pointers; frames are copied out.
    unsafe {
        for (i, &a) in agents.iter().enumerate() {
            let c = config(i as u8 + 1, hold);
            assert_eq!(ph_agent_init(a, PH_AGENT_SIZE, &c), ph_status::PH_OK);
        }
        for (i, &a) in agents.iter().enumerate() {
            let b = bearings(i as u8 + 1);
            assert_eq!(ph_step(a, &meas(&b, 0.0), &mut out), ph_status::PH_OK);
        }
        let mut frames = Vec::new();
        for &a in &agents {
            let mut buf = [[0u8; ph_formation_ffi::PH_MAX_FRAME_LEN]; 3];
            let mut lens = [0u8; 3];
            let mut n = 0;
            ph_formation_ffi::api::ph_frames(a, buf.as_mut_ptr(), lens.as_mut_ptr(), 3, &mut n);
            for k in 0..n {
                frames.push(buf[k][..usize::from(lens[k])].to_vec());
            }
        }
        for f in &frames {
            // Its own frames are refused: fine.
            let _ = ph_receive(agents[0], f.as_ptr(), f.len());
        }
        assert_eq!(
            ph_step(agents[0], &meas(b1, dt), &mut out),
            ph_status::PH_OK
        );
    }
    out
}

#[test]
fn a_negative_dt_has_its_own_fault() {
    let b = bearings(1);
    let ok = second_step(0.0, 0.01, &b);
    assert_eq!(ok.fault, ph_fault::PH_FAULT_NONE, "{ok:?}");
    let neg = second_step(0.0, -0.01, &b);
    assert_eq!(neg.status, ph_output_status::PH_OUTPUT_SAFE);
    assert_eq!(neg.fault, ph_fault::PH_FAULT_NEGATIVE_DT);
    assert_eq!(neg.fault_neighbour, -1);
    for dt in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let out = second_step(0.0, dt, &b);
        assert_eq!(
            out.fault,
            ph_fault::PH_FAULT_NON_FINITE_MEASUREMENT,
            "dt {dt}"
        );
    }
}

#[test]
fn the_bearing_hold_reaches_the_agent() {
    let b = &bearings(1)[..1]; // no bearing to agent 3
    let without = second_step(0.0, 0.01, b);
    assert_eq!(without.fault, ph_fault::PH_FAULT_MISSING_BEARING);
    assert_eq!(without.fault_neighbour, 3);
    let with = second_step(0.05, 0.01, b);
    assert_eq!(with.status, ph_output_status::PH_OUTPUT_NOMINAL, "{with:?}");
}
