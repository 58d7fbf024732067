//! The panic handler of the bare-metal staticlib.
//!
//! Nothing reachable from the C API should panic: like the core, this crate denies
//! `unwrap`, `expect`, `panic!`, indexing and unchecked arithmetic. Should one happen
//! anyway, the handler calls the C function `ph_panic_hook(void)` (log, cut the motors,
//! …) and then executes a permanently undefined instruction (`udf`), which raises a
//! HardFault: the firmware's fault handler decides (reset, halt). The library defines
//! `ph_panic_hook` as a weak symbol that does nothing, so a firmware that does not
//! define it still links. (`docs/c-api.md`: whether a panic path is linked at all.)

use core::panic::PanicInfo;

#[cfg(target_arch = "arm")]
core::arch::global_asm!(
    ".section .text.ph_panic_hook,\"ax\",%progbits",
    ".weak ph_panic_hook",
    ".type ph_panic_hook,%function",
    ".thumb_func",
    "ph_panic_hook:",
    "    bx lr",
    ".size ph_panic_hook, . - ph_panic_hook",
);

extern "C" {
    /// Bare-metal builds: called if the library ever panics, before it traps (`udf`,
    /// i.e. a HardFault). Define it to log or cut the motors; the library's weak
    /// default does nothing. Must not return into Rust code by other means
    /// (`longjmp`). See docs/c-api.md.
    fn ph_panic_hook();
}

#[panic_handler]
fn panic(_info: &PanicInfo) -> ! {
    // SAFETY: a C function without arguments; the firmware's (or the weak default).
    unsafe { ph_panic_hook() };
    trap()
}

#[cfg(target_arch = "arm")]
fn trap() -> ! {
    // SAFETY: `udf` only raises the undefined-instruction fault (HardFault).
    unsafe { core::arch::asm!("udf #0", options(noreturn, nomem, nostack)) }
}

#[cfg(not(target_arch = "arm"))]
fn trap() -> ! {
    loop {
        core::hint::spin_loop();
    }
}
