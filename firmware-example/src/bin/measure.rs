//! Measurement firmware for `scripts/firmware-check.sh`.
//!
//! For every configuration in [`STEP_CONFIGS`] it prepares the inputs, then
//! runs [`control_step`] a few times, each as a measured region (instruction
//! counts come from the QEMU plugin in `tools/qemu-insn/`). It prints one
//! `FWCHECK region …` line per region id so the script can name the plugin's
//! counts, reports peak stack use, and exits 0.
//!
//! Output lines (defmt `println!`, independent of `DEFMT_LOG`):
//!
//! ```text
//! FWCHECK region id=<id> name=<name> triangles=<n> repeats=<r>
//! FWCHECK stack peak_bytes=<n> size_bytes=<n>
//! FWCHECK done
//! ```
//!
//! [`STEP_CONFIGS`]: firmware_example::workload::STEP_CONFIGS
//! [`control_step`]: firmware_example::workload::control_step
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod firmware {
    use cortex_m_rt::entry;
    use firmware_example::hal::Vec2;
    use firmware_example::measure::{self, MAX_REGIONS};
    use firmware_example::workload::{control_step, Scenario, STEP_CONFIGS};
    use firmware_example::{rt, stack};

    /// Region id of the empty calibration region (marker overhead only).
    const OVERHEAD_ID: u8 = 0;
    /// Times each configuration is measured (the script reports min and max;
    /// the first run may differ from later ones on a real cache, never on
    /// QEMU).
    const REPEATS: u32 = 3;

    const _: () = assert!(
        STEP_CONFIGS.len() < MAX_REGIONS,
        "too many step configurations for the marker table"
    );

    /// The single call site of a measured step (keeps the marker overhead
    /// identical for every configuration and repetition).
    #[inline(never)]
    fn measured_step(id: u8, scenario: &Scenario) -> Vec2 {
        measure::measured(id, scenario, control_step)
    }

    /// An empty measured region: the marker overhead alone.
    #[inline(never)]
    fn measured_nothing(id: u8, scenario: &Scenario) -> &Scenario {
        measure::measured(id, scenario, |s| s)
    }

    #[entry]
    fn main() -> ! {
        defmt::println!(
            "FWCHECK region id={=u8} name={=str} triangles={=usize} repeats={=u32}",
            OVERHEAD_ID,
            "overhead",
            0,
            REPEATS
        );
        let idle = Scenario::new(&STEP_CONFIGS[0]);
        for _ in 0..REPEATS {
            measured_nothing(OVERHEAD_ID, &idle);
        }

        let mut checksum = 0.0f32;
        for (i, cfg) in STEP_CONFIGS.iter().enumerate() {
            let id = (i + 1) as u8;
            defmt::println!(
                "FWCHECK region id={=u8} name={=str} triangles={=usize} repeats={=u32}",
                id,
                cfg.name,
                cfg.triangles,
                REPEATS
            );
            let scenario = Scenario::new(cfg);
            for _ in 0..REPEATS {
                let force = measured_step(id, &scenario);
                checksum += force[0] + force[1];
            }
        }
        defmt::info!("checksum {=f32}", checksum);

        stack::report();
        defmt::println!("FWCHECK done");
        rt::exit(rt::EXIT_SUCCESS)
    }
}

/// On the host there is nothing to run; the firmware needs the MCU target.
#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "measure is firmware: build it with --target thumbv7em-none-eabihf (see docs/firmware.md)"
    );
    std::process::exit(2);
}
