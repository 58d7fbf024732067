//! `firmware-example`: one robot's firmware, the template for a real board.
//!
//! It builds agent 1 of the paper scenario ([`paper::config`]) with `auth`
//! integrity (the placeholder key and boot epoch of [`keys`]) and runs it
//! with [`run_agent`] at [`CONTROL_HZ`] on a [`Board`] of drivers. Here the
//! drivers are the stand-ins of [`stand_in`] (fixed bearings, a loopback
//! radio, a recording actuator, a polled clock), so the agent never hears
//! its neighbours and answers with its safe output; on a robot, replace them
//! by drivers implementing the [`hal`] traits (see `docs/firmware.md`).
//!
//! Under QEMU it runs [`RUN_TICKS`] control ticks, logs the last output,
//! reports peak stack use and exits 0.
//!
//! [`paper::config`]: firmware_example::paper::config
//! [`run_agent`]: firmware_example::app::run_agent
//! [`Board`]: firmware_example::app::Board
//! [`stand_in`]: firmware_example::stand_in
//! [`hal`]: firmware_example::hal
//! [`keys`]: firmware_example::keys
#![cfg_attr(target_os = "none", no_std, no_main)]

/// Control rate (Hz).
pub const CONTROL_HZ: u32 = 100;
/// Ticks of the clock per second (a 1 kHz timer).
pub const CLOCK_HZ: u32 = 1000;
/// Control ticks before exiting (under QEMU).
pub const RUN_TICKS: u32 = 20;

#[cfg(target_os = "none")]
mod firmware {
    use super::{CLOCK_HZ, CONTROL_HZ, RUN_TICKS};
    use core::ops::ControlFlow;

    use cortex_m_rt::entry;
    use firmware_example::app::{run_agent, Board};
    use firmware_example::paper;
    use firmware_example::stand_in::{
        FixedBearings, FixedVelocity, LoopbackRadio, PollClock, RecordingActuator,
    };
    use firmware_example::{keys, rt, stack};
    use ph_formation_core::{Agent, Integrity};

    #[entry]
    fn main() -> ! {
        // This robot: agent 1 of the paper (2 triangles at most, 4 neighbours).
        // Authenticated frames. A real board reads its swarm key from protected
        // storage and persists its boot epoch: see `firmware_example::keys`.
        let mut config = paper::config(0);
        config.integrity = Integrity::Auth(keys::PLACEHOLDER_SWARM_KEY);
        let mut agent = match Agent::<f32, 2, 4>::new(config) {
            Ok(a) => a,
            Err(e) => {
                defmt::error!("configuration refused: {}", e);
                rt::exit(rt::EXIT_FAILURE)
            }
        };
        // Before the first frame: larger than at any earlier boot.
        agent.set_boot_epoch(keys::placeholder_boot_epoch());
        defmt::info!(
            "firmware-example: agent {=u8}, control at {=u32} Hz over stand-in drivers",
            agent.id(),
            CONTROL_HZ
        );

        // The drivers. Replace these with the robot's own.
        let mut board = Board {
            // Bearings to agents 2 and 3 from agent 1's initial position.
            bearings: FixedBearings {
                first_id: 2,
                directions: [[0.908, 0.419], [0.6, -0.8], [0.0, 1.0]],
            },
            velocity: FixedVelocity::default(),
            radio: LoopbackRadio::new(),
            actuator: RecordingActuator::default(),
            clock: PollClock::new(CLOCK_HZ),
        };

        let mut ticks = 0;
        let control = run_agent(agent, &mut board, CONTROL_HZ, |report| {
            ticks += 1;
            defmt::debug!(
                "t={=f32}: force ({=f32}, {=f32}) {}",
                report.time,
                report.output.force.x,
                report.output.force.y,
                report.output.status
            );
            if report.errors.any() {
                defmt::warn!("driver errors: {}", report.errors);
            }
            if ticks >= RUN_TICKS {
                defmt::info!(
                    "after {=u32} ticks (t={=f32} s): force ({=f32}, {=f32}) N, {}",
                    ticks,
                    report.time,
                    report.output.force.x,
                    report.output.force.y,
                    report.output.status
                );
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        });
        defmt::info!("frames: {}", control.agent().stats());

        stack::report();
        rt::exit(rt::EXIT_SUCCESS)
    }
}

/// On the host there is nothing to run; the firmware needs the MCU target.
#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "firmware-example is firmware: run it with `cargo run -p firmware-example --target thumbv7em-none-eabihf --release` (see docs/firmware.md)"
    );
    std::process::exit(2);
}
