//! Where a real board keeps the `auth` swarm key and its boot epoch
//! ([`ph_formation_core::Integrity::Auth`], [`ph_formation_core::wire::auth`]).
//!
//! * **The key** is a per-deployment secret shared by every robot of the
//!   swarm. Never compile it into firmware that leaves the lab and never log
//!   it (its `Debug`, `Display` and `defmt` forms print `<redacted>`). On an
//!   STM32F405 a real board writes it once at provisioning into a dedicated
//!   flash sector (or the 512-byte OTP area, 0x1FFF_7800) over SWD, sets
//!   read-out protection (RDP level 1 or 2) so that a debugger cannot read
//!   it back, and reads it at boot with [`SwarmKey::new`]. A board with a
//!   secure element (ATECC608, SE050) keeps it there instead.
//! * **The boot epoch** must be larger at every boot than at any earlier one
//!   (receivers reject every counter not above the last one they accepted
//!   from a robot, see [`ph_formation_core::Agent::set_boot_epoch`]). A real
//!   board keeps a `u32` in flash (an append-only log of words in one sector:
//!   the epoch is the number of programmed words, one word programmed per
//!   boot, the sector erased when full after writing the next value into a
//!   second sector) or in battery-backed RAM (BKPSRAM with VBAT), reads it,
//!   stores `epoch + 1` **before** the first frame and uses `epoch + 1`.
//!
//! The QEMU binaries have no persistent storage: they use the placeholders
//! below.

use ph_formation_core::SwarmKey;

/// PLACEHOLDER swarm key for the QEMU binaries and the measurements ONLY.
///
/// It is public (it is in this source file): frames signed with it are not
/// authenticated against anybody. A real board reads its key from protected
/// storage at boot (see the module documentation) and never uses this one.
pub const PLACEHOLDER_SWARM_KEY: SwarmKey = SwarmKey::new(*b"NOT-A-SECRET-KEY");

/// PLACEHOLDER boot epoch for the QEMU binaries (no persistent storage: every
/// run is "the first boot"). A real board returns the epoch it persisted,
/// incremented, as described in the module documentation.
pub const fn placeholder_boot_epoch() -> u32 {
    1
}
