//! `host-sim view OUT_DIR`: the path of the run's `replay.html` (written first when the
//! directory has a time series but no page yet), or of a sweep's `sweep.html`, opened in a
//! browser when one is there.

use crate::exit_code;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The browser command to open a page with: `$BROWSER`, else `xdg-open` when a display is
/// there; `None` without either (the path is printed only).
fn browser() -> Option<String> {
    if let Some(b) = std::env::var_os("BROWSER").filter(|b| !b.is_empty()) {
        return Some(b.to_string_lossy().into_owned());
    }
    let display = ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|d| !d.is_empty()));
    let xdg = std::env::var_os("PATH")
        .is_some_and(|p| std::env::split_paths(&p).any(|d| d.join("xdg-open").is_file()));
    (display && xdg).then(|| "xdg-open".to_owned())
}

/// The page of `dir`, written from its `timeseries.csv` and `summary.json` if missing; for
/// a sweep's directory (`points.csv`, no `timeseries.csv`), `sweep.html`, written afresh.
fn page(dir: &Path) -> Result<PathBuf, PageError> {
    if dir.join("points.csv").is_file() && !dir.join("timeseries.csv").is_file() {
        return crate::report::replay::write_sweep_page(dir).map_err(|source| PageError {
            path: dir.join("sweep.html"),
            source,
        });
    }
    let path = dir.join("replay.html");
    if path.is_file() {
        return Ok(path);
    }
    crate::report::write_replay(dir).map_err(|source| PageError { path, source })
}

/// A page that cannot be written.
#[derive(Debug, thiserror::Error)]
#[error("cannot write {}: {source}", path.display())]
struct PageError {
    /// The page.
    path: PathBuf,
    /// Why.
    source: crate::report::plot::PlotError,
}

pub(super) fn view_command(dir: &Path, no_open: bool) -> u8 {
    let path = match page(dir) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: {e}");
            return exit_code::IO;
        }
    };
    println!("{}", path.display());
    if no_open {
        return exit_code::CONVERGED;
    }
    if let Some(b) = browser() {
        // `$BROWSER` may hold arguments (`firefox --new-window`).
        let mut words = b.split_whitespace();
        if let Some(program) = words.next() {
            let spawned = Command::new(program)
                .args(words)
                .arg(&path)
                .stdin(Stdio::null())
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn();
            if let Err(e) = spawned {
                eprintln!("warning: cannot start {program}: {e}");
            }
        }
    }
    exit_code::CONVERGED
}
