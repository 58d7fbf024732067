//! Self-test of the HardFault handler: executes a permanently undefined
//! instruction (a UsageFault, escalated to HardFault). Under QEMU it must end
//! with exit code 1 (not hang); `scripts/firmware-check.sh` checks that.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod firmware {
    use cortex_m_rt::entry;
    use firmware_example::rt;

    #[entry]
    fn main() -> ! {
        defmt::info!("selftest-hardfault: executing UDF on purpose");
        if core::hint::black_box(true) {
            cortex_m::asm::udf();
        }
        rt::exit(rt::EXIT_SUCCESS)
    }
}

/// On the host there is nothing to run; the firmware needs the MCU target.
#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("selftest-hardfault is firmware: build it with --target thumbv7em-none-eabihf");
    std::process::exit(2);
}
