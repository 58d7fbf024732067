//! Measurement firmware for `scripts/firmware-check.sh`.
//!
//! For every configuration in [`STEP_CONFIGS`] (an agent in 1, 2, 4 and 8
//! triangles) it builds the [`Bench`] (real agents, warm-up ticks, the
//! neighbours' frames of the measured tick), then measures, as regions of the
//! QEMU instruction-count plugin (`tools/qemu-insn/`):
//!
//! * `<name>`: the whole control step ([`StepCtx::control_step`]: decode and
//!   receive the neighbours' frames, `Agent::step`, encode the own frames),
//!   [`REPEATS`] times, each on a freshly built bench (same state);
//! * `<name>-rx`, `<name>-step`, `<name>-tx`: the three parts separately, on
//!   one more fresh bench (their sum is the whole step plus twice the marker
//!   overhead);
//! * `<name>-crc`: the CRC-16 of all those frames alone (part of rx and tx).
//!
//! Every measured step must be nominal (`Status::Nominal`) with every
//! neighbour frame accepted; otherwise it prints `FWCHECK error …` and exits
//! 1 (a safe-output step is not a valid measurement).
//!
//! Output lines (defmt `println!`, independent of `DEFMT_LOG`):
//!
//! ```text
//! FWCHECK region id=<id> name=<name> triangles=<n> repeats=<r>
//! FWCHECK bench name=<name> triangles=<n> neighbours=<n> rx_frames=<n> rx_bytes=<n> tx_frames=<n> tx_bytes=<n> force=<x>,<y>
//! FWCHECK error <reason>
//! FWCHECK stack peak_bytes=<n> size_bytes=<n>
//! FWCHECK done
//! ```
//!
//! [`STEP_CONFIGS`]: firmware_example::workload::STEP_CONFIGS
//! [`Bench`]: firmware_example::workload::Bench
//! [`StepCtx::control_step`]: firmware_example::workload::StepCtx::control_step
#![cfg_attr(target_os = "none", no_std, no_main)]

/// Times the whole step of each configuration is measured (the script
/// reports min and max; QEMU is deterministic, so they are equal).
pub const REPEATS: u32 = 3;

#[cfg(target_os = "none")]
mod firmware {
    use super::REPEATS;
    use cortex_m_rt::entry;
    use firmware_example::measure::{self, MAX_REGIONS};
    use firmware_example::workload::{Bench, StepConfig, StepCtx, StepResult, STEP_CONFIGS};
    use firmware_example::{rt, stack};
    use ph_formation_core::StepOutput;

    /// Region id of the empty calibration region (marker overhead only).
    const OVERHEAD_ID: u8 = 0;
    /// Regions per configuration: whole step, rx, step, tx, crc.
    const REGIONS_PER_CONFIG: usize = 5;

    const _: () = assert!(
        REGIONS_PER_CONFIG * STEP_CONFIGS.len() < MAX_REGIONS,
        "too many regions for the marker table"
    );

    /// The single call site of a measured whole step.
    #[inline(never)]
    fn measured_step(id: u8, ctx: &mut StepCtx<'_>) -> StepResult {
        measure::measured(id, ctx, |b| b.control_step())
    }

    #[inline(never)]
    fn measured_rx(id: u8, ctx: &mut StepCtx<'_>) -> (u8, u8) {
        measure::measured(id, ctx, |b| b.receive_all())
    }

    #[inline(never)]
    fn measured_step_only(id: u8, ctx: &mut StepCtx<'_>) -> StepOutput<f32> {
        measure::measured(id, ctx, |b| b.step_only())
    }

    #[inline(never)]
    fn measured_tx(id: u8, ctx: &mut StepCtx<'_>) -> u8 {
        measure::measured(id, ctx, |b| b.encode())
    }

    #[inline(never)]
    fn measured_crc(id: u8, ctx: &mut StepCtx<'_>) -> u16 {
        measure::measured(id, ctx, |b| b.crc_all())
    }

    /// An empty measured region: the marker overhead alone.
    #[inline(never)]
    fn measured_nothing(id: u8, x: u32) -> u32 {
        measure::measured(id, x, |x| x)
    }

    fn announce(id: u8, name: &str, suffix: &str, triangles: usize, repeats: u32) {
        defmt::println!(
            "FWCHECK region id={=u8} name={=str}{=str} triangles={=usize} repeats={=u32}",
            id,
            name,
            suffix,
            triangles,
            repeats
        );
    }

    fn fail(what: &str, cfg: &StepConfig) -> ! {
        defmt::println!("FWCHECK error {=str}: {=str}", cfg.name, what);
        rt::exit(rt::EXIT_FAILURE)
    }

    /// Rebuilds `bench` for `cfg` and returns what the measured step uses.
    fn reset<'a>(bench: &'a mut Bench, cfg: &StepConfig) -> StepCtx<'a> {
        match bench.reset(cfg) {
            Ok(()) if bench.rx.overflow == 0 => {}
            Ok(()) => fail("bench frame buffer overflow", cfg),
            Err(e) => {
                defmt::error!("bench {=str}: {}", cfg.name, e);
                fail("bench could not be built", cfg)
            }
        }
        match bench.ctx() {
            Some(ctx) => ctx,
            None => fail("bench without agent", cfg),
        }
    }

    fn check(r: &StepResult, cfg: &StepConfig) {
        if !r.valid() {
            defmt::error!(
                "{=str}: status {}, {=u8} frames rejected",
                cfg.name,
                r.output.status,
                r.rejected
            );
            fail("the measured step is not nominal with all frames accepted (not a valid measurement)", cfg);
        }
    }

    #[entry]
    fn main() -> ! {
        announce(OVERHEAD_ID, "overhead", "", 0, REPEATS);
        for i in 0..REPEATS {
            measured_nothing(OVERHEAD_ID, i);
        }

        // One bench, rebuilt in place before every measured step.
        let mut bench = Bench::empty();
        for (i, cfg) in STEP_CONFIGS.iter().enumerate() {
            let base = (1 + REGIONS_PER_CONFIG * i) as u8;
            let (id_all, id_rx, id_step, id_tx, id_crc) =
                (base, base + 1, base + 2, base + 3, base + 4);

            announce(id_all, cfg.name, "", cfg.triangles, REPEATS);
            let mut last = None;
            for rep in 0..REPEATS {
                let mut ctx = reset(&mut bench, cfg);
                let r = measured_step(id_all, &mut ctx);
                check(&r, cfg);
                if last.is_some_and(|l| l != r) {
                    fail("repeated steps differ", cfg);
                }
                last = Some(r);
                if rep == 0 {
                    defmt::println!(
                        "FWCHECK bench name={=str} triangles={=usize} neighbours={=usize} rx_frames={=usize} rx_bytes={=usize} tx_frames={=usize} tx_bytes={=usize} force={=f32},{=f32}",
                        cfg.name,
                        cfg.triangles,
                        bench.inputs.bearings.len(),
                        bench.rx.len(),
                        bench.rx.bytes(),
                        bench.tx.len(),
                        bench.tx.bytes(),
                        r.output.force.x,
                        r.output.force.y
                    );
                }
            }

            // The breakdown, on one more fresh bench.
            announce(id_rx, cfg.name, "-rx", cfg.triangles, 1);
            announce(id_step, cfg.name, "-step", cfg.triangles, 1);
            announce(id_tx, cfg.name, "-tx", cfg.triangles, 1);
            announce(id_crc, cfg.name, "-crc", cfg.triangles, 1);
            let mut ctx = reset(&mut bench, cfg);
            let (accepted, rejected) = measured_rx(id_rx, &mut ctx);
            let output = measured_step_only(id_step, &mut ctx);
            let sent = measured_tx(id_tx, &mut ctx);
            defmt::println!(
                "FWCHECK crc name={=str} xor={=u16}",
                cfg.name,
                measured_crc(id_crc, &mut ctx)
            );
            let r = StepResult {
                output,
                accepted,
                rejected,
                sent,
            };
            check(&r, cfg);
            if last != Some(r) {
                fail("the breakdown's step differs from the whole step", cfg);
            }
        }

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
