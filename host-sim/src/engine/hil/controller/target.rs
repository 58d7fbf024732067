//! What runs an emulated target: a QEMU process, or (tests) a thread; how it ended.

use crate::engine::hil::qemu::QemuProcess;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// What runs the target: a QEMU process, or (tests) a thread.
#[derive(Debug)]
pub enum TargetHandle {
    /// `qemu-system-arm` with the firmware (killed on drop).
    Qemu(QemuProcess),
    /// The host-side stand-in of `engine::hil::fake` (tests).
    Fake(Option<JoinHandle<std::io::Result<()>>>),
}

impl TargetHandle {
    /// QEMU's pid, for a QEMU target.
    pub fn pid(&self) -> Option<u32> {
        match self {
            Self::Qemu(p) => Some(p.pid()),
            Self::Fake(_) => None,
        }
    }

    /// A description of how the target ended, if it did (QEMU's exit status and stderr).
    pub(super) fn ended(&mut self, wait: Duration) -> Option<String> {
        match self {
            Self::Qemu(p) => {
                let end = Instant::now() + wait;
                loop {
                    if let Some(s) = p.try_exit() {
                        let tail = p.stderr_tail();
                        return Some(if tail.is_empty() {
                            format!("QEMU exited ({s})")
                        } else {
                            format!("QEMU exited ({s}): {tail}")
                        });
                    }
                    if Instant::now() >= end {
                        return None;
                    }
                    std::thread::sleep(Duration::from_millis(5));
                }
            }
            Self::Fake(h) => h
                .as_ref()
                .is_some_and(|h| h.is_finished())
                .then(|| "the fake target ended".to_owned()),
        }
    }

    pub(super) fn log_hint(&self) -> String {
        match self {
            Self::Qemu(p) => format!(
                "; firmware log (raw defmt): {}, QEMU messages: {}",
                p.log.display(),
                p.stderr_log.display()
            ),
            Self::Fake(_) => String::new(),
        }
    }
}
