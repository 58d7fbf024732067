//! Demo firmware: runs the application loop over the [`hal`] traits with the
//! stand-in drivers for a few steps, logs with defmt, reports peak stack use
//! and exits 0 (under QEMU through semihosting).
//!
//! Run under QEMU with
//! `cargo run -p firmware-example --target thumbv7em-none-eabihf --release`.
//!
//! [`hal`]: firmware_example::hal
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod firmware {
    use cortex_m_rt::entry;
    use firmware_example::hal::{
        Actuator, Bearing, BearingSensor, Clock, Radio, Vec2, VelocitySource, MAX_FRAME_LEN,
    };
    use firmware_example::stand_in::{
        FixedBearings, IntegratedVelocity, LoopbackRadio, RecordingActuator, StepClock,
    };
    use firmware_example::workload::{control_step, Scenario, STEP_CONFIGS};
    use firmware_example::{rt, stack};

    /// Control steps the demo runs.
    const STEPS: u32 = 10;
    /// Control rate of the demo, Hz.
    const CONTROL_HZ: u32 = 100;

    /// The application's step, generic over the hardware traits: read the
    /// sensors, exchange a frame, compute and apply a force.
    ///
    /// The formation application will have this shape; the computation in
    /// the middle is [`control_step`] (stand-in for the controller).
    fn app_step<S, V, R, A, C>(
        sensor: &mut S,
        velocity: &mut V,
        radio: &mut R,
        actuator: &mut A,
        clock: &C,
        scenario: &mut Scenario,
    ) -> Result<Vec2, &'static str>
    where
        S: BearingSensor,
        V: VelocitySource,
        R: Radio,
        A: Actuator,
        C: Clock,
    {
        let mut bearings = [Bearing {
            neighbour: 0,
            direction: [0.0; 2],
        }; 4];
        let seen = sensor
            .read_bearings(&mut bearings)
            .map_err(|_| "bearing sensor")?;
        let v = velocity.velocity().map_err(|_| "velocity source")?;

        // Broadcast our tick and velocity; read what arrived.
        let mut frame = [0u8; 12];
        frame[..4].copy_from_slice(&(clock.now_ticks() as u32).to_le_bytes());
        frame[4..8].copy_from_slice(&v[0].to_le_bytes());
        frame[8..].copy_from_slice(&v[1].to_le_bytes());
        radio.send(&frame).map_err(|_| "radio send")?;
        let mut rx = [0u8; MAX_FRAME_LEN];
        let received = radio
            .receive(&mut rx)
            .map_err(|_| "radio receive")?
            .unwrap_or(0);

        let force = control_step(scenario);
        actuator.apply_force(force).map_err(|_| "actuator")?;

        // Stand-in dynamics: move our own position a little along the force.
        let dt = 1.0 / clock.tick_hz() as f32;
        scenario.own[0] += force[0] * dt;
        scenario.own[1] += force[1] * dt;

        defmt::debug!(
            "tick {=u64}: {=usize} bearings, rx {=usize} B",
            clock.now_ticks(),
            seen,
            received
        );
        Ok(force)
    }

    #[entry]
    fn main() -> ! {
        defmt::info!(
            "firmware-example: {=usize} step configurations, {=u32} demo steps",
            STEP_CONFIGS.len(),
            STEPS
        );

        let mut sensor = FixedBearings {
            directions: [[1.0, 0.0], [0.0, 1.0], [-0.6, -0.8]],
        };
        let mut velocity = IntegratedVelocity::default();
        let mut radio = LoopbackRadio::new();
        let mut actuator = RecordingActuator::default();
        let mut clock = StepClock::new(CONTROL_HZ);
        let mut scenario = Scenario::new(&STEP_CONFIGS[STEP_CONFIGS.len() - 1]);

        for _ in 0..STEPS {
            match app_step(
                &mut sensor,
                &mut velocity,
                &mut radio,
                &mut actuator,
                &clock,
                &mut scenario,
            ) {
                Ok(force) => {
                    // Unit mass: integrate the force into the velocity.
                    let dt = 1.0 / CONTROL_HZ as f32;
                    velocity.velocity[0] += force[0] * dt;
                    velocity.velocity[1] += force[1] * dt;
                }
                Err(what) => {
                    defmt::error!("step failed: {=str}", what);
                    rt::exit(rt::EXIT_FAILURE);
                }
            }
            clock.advance();
        }

        let f = actuator.last;
        defmt::info!(
            "after {=u64} steps ({=f32} s): force = ({=f32}, {=f32}) N",
            clock.now_ticks(),
            clock.seconds_since(0),
            f[0],
            f[1]
        );
        let s = stack::report();
        defmt::info!("stack: peak {=u32} of {=u32} bytes", s.peak, s.size);
        rt::exit(rt::EXIT_SUCCESS)
    }
}

/// On the host there is nothing to run; the firmware needs the MCU target.
#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("firmware-example is firmware: build it with --target thumbv7em-none-eabihf (see docs/firmware.md)");
    std::process::exit(2);
}
