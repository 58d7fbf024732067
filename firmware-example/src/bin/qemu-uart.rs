//! `qemu-uart`: one agent driven by a host over USART1 (host-in-the-loop).
//!
//! The host (e.g. the host simulator, or `tests/tests/qemu_uart.rs`) speaks
//! the lock-step protocol of `ph_formation_core::link` on the serial line; see
//! [`boards::uart`] for the messages. Each `Step` runs one tick of the
//! generic control loop on an `Agent<f32, 4, 8>` configured by the host.
//! On `Finish` the firmware replies `Finished`, reports its peak stack use
//! and exits 0. Logs (defmt) go through semihosting, separate from the
//! protocol.
//!
//! Under QEMU, connect USART1 to a TCP socket the host connects to:
//!
//! ```text
//! qemu-system-arm -machine netduinoplus2 -display none -monitor none \
//!     -semihosting-config enable=on,target=native \
//!     -serial tcp:127.0.0.1:PORT,server=on,wait=on -kernel qemu-uart | defmt-print -e qemu-uart
//! ```
//!
//! [`boards::uart`]: firmware_example::boards::uart
#![cfg_attr(target_os = "none", no_std, no_main)]

/// Log one line every this many ticks (at `info`).
pub const LOG_EVERY_TICKS: u32 = 1000;

#[cfg(target_os = "none")]
mod firmware {
    use super::LOG_EVERY_TICKS;
    use cortex_m_rt::entry;
    use firmware_example::boards::uart::{Event, Session, Usart1, BRR_115200_HSI};
    use firmware_example::{rt, stack};

    #[entry]
    fn main() -> ! {
        // SAFETY: the only user of USART1, PA9/PA10 and their clock bits.
        let port = unsafe { Usart1::init(BRR_115200_HSI) };
        let mut session = Session::new(port);
        session.announce();
        defmt::info!("qemu-uart: waiting for Configure on USART1");
        let (mut ticks, mut nominal) = (0u32, 0u32);
        loop {
            match session.poll() {
                Event::Configured(id) => {
                    defmt::info!("configured as agent {=u8}", id);
                    ticks = 0;
                    nominal = 0;
                }
                Event::Ticked(r) => {
                    ticks += 1;
                    nominal += u32::from(r.nominal());
                    defmt::debug!(
                        "t={=f32}: force ({=f32}, {=f32}) {}",
                        r.time,
                        r.output.force.x,
                        r.output.force.y,
                        r.output.status
                    );
                    if ticks.is_multiple_of(LOG_EVERY_TICKS) {
                        defmt::info!("{=u32} ticks, {=u32} nominal", ticks, nominal);
                    }
                }
                Event::Queued => {}
                Event::Refused(e) => defmt::warn!("refused a message: {}", e),
                Event::Finished { accepted, rejected } => {
                    defmt::info!(
                        "finished: {=u32} ticks ({=u32} nominal), frames accepted {=u32}, rejected {=u32}, dropped {=u32}",
                        ticks,
                        nominal,
                        accepted,
                        rejected,
                        session.radio_dropped
                    );
                    stack::report();
                    rt::exit(rt::EXIT_SUCCESS)
                }
            }
        }
    }
}

/// On the host there is nothing to run; the firmware needs the MCU target.
#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "qemu-uart is firmware: build it with --target thumbv7em-none-eabihf and connect a host to its USART1 (see docs/firmware.md)"
    );
    std::process::exit(2);
}
