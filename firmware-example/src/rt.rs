//! Runtime glue: log transport, exit codes, panic and fault handlers.
//!
//! * Feature `qemu` (default): defmt frames go out through semihosting;
//!   [`exit`] ends QEMU with the given code (`SYS_EXIT_EXTENDED`), and a
//!   panic, a HardFault or an unexpected interrupt logs and exits with
//!   [`EXIT_FAILURE`] instead of hanging.
//! * Feature `rtt`: defmt frames go out through RTT (probe-rs). While a
//!   debugger is attached, [`exit`] uses semihosting too (`probe-rs run`
//!   ends with that code); without a debugger a successful exit sleeps
//!   forever and a failure resets the MCU.

#[cfg(all(feature = "qemu", feature = "rtt"))]
compile_error!(
    "features `qemu` and `rtt` are exclusive: use `--no-default-features --features rtt` for RTT"
);
#[cfg(not(any(feature = "qemu", feature = "rtt")))]
compile_error!("select a log transport: feature `qemu` (default) or `rtt`");

#[cfg(feature = "rtt")]
use defmt_rtt as _;
#[cfg(feature = "qemu")]
use defmt_semihosting as _;

use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m_rt::{exception, ExceptionFrame};

/// Exit code of a successful run.
pub const EXIT_SUCCESS: i32 = 0;
/// Exit code of a failed run (panic, fault, failed self-check).
pub const EXIT_FAILURE: i32 = 1;

/// Ends the program with `code` (see the module docs for each transport).
pub fn exit(code: i32) -> ! {
    #[cfg(feature = "qemu")]
    {
        semihosting::process::exit(code)
    }
    #[cfg(feature = "rtt")]
    {
        if cortex_m::peripheral::DCB::is_debugger_attached() {
            semihosting::process::exit(code)
        } else if code == EXIT_SUCCESS {
            loop {
                cortex_m::asm::wfi();
            }
        } else {
            cortex_m::peripheral::SCB::sys_reset()
        }
    }
}

/// Set on the first panic; a nested panic (e.g. inside the logger) exits at
/// once without logging.
static PANICKING: AtomicBool = AtomicBool::new(false);

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    cortex_m::interrupt::disable();
    if !PANICKING.swap(true, Ordering::Relaxed) {
        defmt::error!("panic: {}", defmt::Display2Format(info));
    }
    exit(EXIT_FAILURE)
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    if !PANICKING.swap(true, Ordering::Relaxed) {
        defmt::error!(
            "HardFault: pc={=u32:#010x} lr={=u32:#010x} xpsr={=u32:#010x}",
            frame.pc(),
            frame.lr(),
            frame.xpsr()
        );
    }
    exit(EXIT_FAILURE)
}

#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    if !PANICKING.swap(true, Ordering::Relaxed) {
        defmt::error!("unexpected exception or interrupt: IRQn={=i16}", irqn);
    }
    exit(EXIT_FAILURE)
}
