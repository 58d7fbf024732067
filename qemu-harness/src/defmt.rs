//! Decoding the firmware's defmt output with `defmt-print` (installed by
//! `scripts/firmware-deps.sh`).

use std::fs::File;
use std::path::Path;
use std::process::{Command, Stdio};

/// Environment variable naming the `defmt-print` binary.
pub const DEFMT_PRINT_ENV: &str = "DEFMT_PRINT";

/// The `defmt-print` binary: `$DEFMT_PRINT` or `defmt-print`.
pub fn program() -> String {
    std::env::var(DEFMT_PRINT_ENV)
        .ok()
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "defmt-print".to_owned())
}

/// Decodes the raw defmt stream in file `raw` with the symbols of `elf`; returns the log
/// text. Errors say what failed (a missing `defmt-print`, a stream it cannot decode).
pub fn decode(elf: &Path, raw: &Path) -> Result<String, String> {
    let input = File::open(raw).map_err(|e| format!("cannot read {}: {e}", raw.display()))?;
    let print = program();
    let out = Command::new(&print)
        .arg("-e")
        .arg(elf)
        .stdin(Stdio::from(input))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .output()
        .map_err(|e| {
            format!("cannot run {print}: {e}; run `bash scripts/firmware-deps.sh` to install it")
        })?;
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    if out.status.success() {
        Ok(text)
    } else {
        Err(format!(
            "{print} -e {} failed ({}) on {}: {}{}",
            elf.display(),
            out.status,
            raw.display(),
            String::from_utf8_lossy(&out.stderr).trim(),
            if text.is_empty() {
                String::new()
            } else {
                format!("\n(decoded so far:)\n{text}")
            }
        ))
    }
}

/// [`decode`], or on failure a placeholder line naming the error (for logs that are only
/// shown to a human).
pub fn decode_or_note(elf: &Path, raw: &Path) -> String {
    decode(elf, raw).unwrap_or_else(|e| format!("(defmt log not decoded: {e})\n"))
}
