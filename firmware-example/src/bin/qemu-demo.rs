//! `qemu-demo`: the paper's formation (SPEC §9, `paper` gains) simulated
//! inside the firmware in `f32`.
//!
//! Four robots, each its own `ph_formation_core::Agent<f32, 2, 4>` driven
//! through the generic control loop ([`ControlLoop`]) at 100 Hz by the demo
//! board ([`boards::demo`]): RK4 plant at 1 ms, exact bearings (rates by
//! finite differences in the controller), real encoded frames over an
//! in-memory broadcast radio with one tick of latency.
//!
//! Runs until converged, logging progress every 5 simulated seconds, then
//! prints (defmt `println!`, independent of `DEFMT_LOG`):
//!
//! ```text
//! DEMO final t=<s> rel=<x1>,<y1>;<x2>,<y2>;<x3>,<y3>;<x4>,<y4>
//! DEMO result converged=<true|false> ...
//! FWCHECK stack peak_bytes=<n> size_bytes=<n>
//! ```
//!
//! where `(x_i, y_i) = q_i − q_1` in metres. Exits 0 if converged, 1
//! otherwise.
//!
//! Converged: at one control tick all of
//! * every controlled angle within [`ANGLE_TOL`] rad of its target,
//! * `|(q1 − q2) − z*|` < [`LEADER_TOL`] m,
//! * every `|v_i − v*|` < [`VELOCITY_TOL`] m/s,
//!
//! and every control output after the first tick was nominal (the first is
//! the safe output: nothing has been heard yet), and no frame was lost or
//! rejected for any reason other than coming from a robot that is not a
//! neighbour. Not converged by [`MAX_TIME`] simulated seconds: exit 1.
//!
//! [`ControlLoop`]: firmware_example::app::ControlLoop
//! [`boards::demo`]: firmware_example::boards::demo
#![cfg_attr(target_os = "none", no_std, no_main)]

/// Angle error threshold (rad).
pub const ANGLE_TOL: f32 = 1.0e-4;
/// Leader displacement error threshold (m).
pub const LEADER_TOL: f32 = 1.0e-3;
/// Velocity error threshold (m/s).
pub const VELOCITY_TOL: f32 = 1.0e-3;
/// Give up after this many simulated seconds.
pub const MAX_TIME: f32 = 150.0;
/// Progress log period (simulated seconds).
pub const LOG_EVERY_S: u32 = 5;

#[cfg(target_os = "none")]
mod firmware {
    use super::{ANGLE_TOL, LEADER_TOL, LOG_EVERY_S, MAX_TIME, VELOCITY_TOL};
    use cortex_m_rt::entry;
    use firmware_example::app::ControlLoop;
    use firmware_example::boards::demo::{Metrics, World, CONTROL_HZ, N};
    use firmware_example::{paper, rt, stack};
    use ph_formation_core::Agent;

    /// The agents of the demo: 2 triangles, 4 neighbours at most.
    type DemoLoop = ControlLoop<2, 4>;

    #[entry]
    fn main() -> ! {
        defmt::info!(
            "qemu-demo: paper scenario, {=usize} agents, control {=u32} Hz, plant RK4 1 ms",
            N,
            CONTROL_HZ
        );
        let mut loops: [DemoLoop; N] =
            core::array::from_fn(|i| match Agent::new(paper::config::<2>(i)) {
                Ok(agent) => ControlLoop::new(agent),
                Err(e) => {
                    defmt::error!("agent {=usize}: configuration refused: {}", i + 1, e);
                    rt::exit(rt::EXIT_FAILURE)
                }
            });
        let mut world = World::paper();

        let max_ticks = (MAX_TIME as u32) * CONTROL_HZ;
        let log_every = LOG_EVERY_S * CONTROL_HZ;
        let mut late_safe = 0u32;
        let mut converged = false;
        let mut tick = 0u32;
        let mut metrics = Metrics::of(&world.plant);
        while tick < max_ticks {
            let reports = world.control_period(&mut loops);
            for (i, r) in reports.iter().enumerate() {
                if !r.nominal() && tick > 0 {
                    late_safe += 1;
                    if late_safe <= 8 {
                        defmt::warn!(
                            "t={=f32} agent {=usize}: safe output {}",
                            r.time,
                            i + 1,
                            r.output.status
                        );
                    }
                }
                if r.errors.any() {
                    defmt::warn!("t={=f32} agent {=usize}: {}", r.time, i + 1, r.errors);
                }
            }
            tick += 1;
            metrics = Metrics::of(&world.plant);
            if tick.is_multiple_of(log_every) {
                defmt::info!(
                    "t={=f32} s: angle error {=f32} rad, leader error {=f32} m, velocity error {=f32} m/s",
                    world.plant.time(),
                    metrics.angle_error,
                    metrics.leader_error,
                    metrics.velocity_error
                );
            }
            if metrics.within(ANGLE_TOL, LEADER_TOL, VELOCITY_TOL) {
                converged = true;
                break;
            }
        }

        let mut bad_frames = 0u32;
        for (i, l) in loops.iter().enumerate() {
            let s = l.agent().stats();
            // Broadcast: frames of robots that are not neighbours are
            // rejected as `unknown_sender`; nothing else may be rejected.
            bad_frames += s.rejected() - s.unknown_sender;
            defmt::info!("agent {=usize} frames: {}", i + 1, s);
        }
        defmt::info!(
            "radio: {=u32} frames sent, {=u32} lost; {=u32} late safe outputs",
            world.radio.sent,
            world.radio.lost,
            late_safe
        );

        let t = world.plant.time();
        let rel = |i: usize| world.plant.offset(0, i);
        let (r1, r2, r3, r4) = (rel(0), rel(1), rel(2), rel(3));
        defmt::println!(
            "DEMO final t={=f32} rel={=f32},{=f32};{=f32},{=f32};{=f32},{=f32};{=f32},{=f32}",
            t,
            r1[0],
            r1[1],
            r2[0],
            r2[1],
            r3[0],
            r3[1],
            r4[0],
            r4[1]
        );
        let ok = converged && late_safe == 0 && bad_frames == 0 && world.radio.lost == 0;
        defmt::println!(
            "DEMO result converged={=bool} t={=f32} angle_error={=f32} leader_error={=f32} velocity_error={=f32} late_safe={=u32} bad_frames={=u32} lost={=u32}",
            ok,
            t,
            metrics.angle_error,
            metrics.leader_error,
            metrics.velocity_error,
            late_safe,
            bad_frames,
            world.radio.lost
        );
        stack::report();
        if ok {
            rt::exit(rt::EXIT_SUCCESS)
        } else {
            defmt::error!("qemu-demo: did not converge (see the DEMO result line)");
            rt::exit(rt::EXIT_FAILURE)
        }
    }
}

/// On the host there is nothing to run; the firmware needs the MCU target.
#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "qemu-demo is firmware: run it with `cargo run -p firmware-example --target thumbv7em-none-eabihf --release --bin qemu-demo` (see docs/firmware.md)"
    );
    std::process::exit(2);
}
