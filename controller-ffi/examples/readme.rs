//! The usage example of README.md (kept equal to it by xtask's `package` tests).
use ph_formation_ffi::api::{ph_agent_init, ph_step};
use ph_formation_ffi::config::default_config;
use ph_formation_ffi::storage::ph_agent;
use ph_formation_ffi::tick::{ph_bearing, ph_fault, ph_measurements, ph_output, ph_output_status};
use ph_formation_ffi::{ph_status, PH_AGENT_SIZE};

/// The agent's memory, as a C caller provides it.
#[repr(C, align(8))]
struct Memory([u8; PH_AGENT_SIZE]);

fn main() {
    // Agent 1 of the triangle (1, 2, 3), holding 60° at vertices 1 and 2.
    let mut c = default_config(1);
    c.triangle_count = 1;
    c.triangles[0].vertices = [1, 2, 3];
    c.triangles[0].angles[0].apex = 1;
    c.triangles[0].angles[1].apex = 2;
    for a in &mut c.triangles[0].angles {
        a.cos_desired = 0.5;
        a.stiffness = 1.0;
        a.damping = 0.5;
        a.estimator_gain = 1.0;
    }
    let mut mem = Memory([0; PH_AGENT_SIZE]);
    let agent = mem.0.as_mut_ptr().cast::<ph_agent>();
    // SAFETY: `mem` is PH_AGENT_SIZE bytes, aligned, and used by nothing else.
    let status = unsafe { ph_agent_init(agent, PH_AGENT_SIZE, &c) };
    assert_eq!(status, ph_status::PH_OK);

    let bearings = [
        ph_bearing {
            neighbour: 2,
            direction: [1.0, 0.0],
            ..Default::default()
        },
        ph_bearing {
            neighbour: 3,
            direction: [0.6, 0.8],
            ..Default::default()
        },
    ];
    let m = ph_measurements {
        time: 0.0,
        dt: 0.01,
        velocity: [0.0, 0.0],
        bearings: bearings.as_ptr(),
        bearing_count: bearings.len(),
        has_partner_offset: 0,
        partner_offset: [0.0, 0.0],
    };
    let mut out = ph_output {
        force: [0.0; 2],
        status: ph_output_status::PH_OUTPUT_SAFE,
        fault: ph_fault::PH_FAULT_NONE,
        fault_neighbour: -1,
        saturated: false,
        degenerate: false,
    };
    // SAFETY: the agent was initialised above; `m` and `out` are valid.
    let status = unsafe { ph_step(agent, &m, &mut out) };
    assert_eq!(status, ph_status::PH_OK);
    // Nothing heard from the neighbours yet (`ph_receive` takes what they broadcast):
    // the safe output, and why.
    assert_eq!(out.status, ph_output_status::PH_OUTPUT_SAFE);
    assert_eq!(out.fault, ph_fault::PH_FAULT_STALE);
    println!("force {:?}", out.force);
}
