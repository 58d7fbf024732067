//! `replay.html`: one self-contained page that replays a run in a browser, offline from
//! `file://` (`docs/outputs.md`). The data is read from the run directory's
//! `timeseries.csv` and `summary.json` ([`ReplayData`]), thinned in time and space to a bounded
//! size, and written as JSON into the page template (`replay.html`, next to this file:
//! canvas drawing, controls and the test hook `window.phReplay`). A sweep's `points.csv`
//! gets the same treatment: `sweep.html` ([`write_sweep_page`]).
//!
//! Bounds: at most [`MAX_AGENTS`] agents are drawn (an evenly spaced subset, leaders
//! included), at most [`MAX_FRAMES`] frames and at most [`MAX_CELLS`] per-frame numbers
//! (4 per drawn agent, 1 per drawn edge) are kept, and the charts keep at most
//! [`MAX_CHART_POINTS`] points. Every number is written in at most 17 characters, so the
//! page stays below [`MAX_BYTES`].

mod data;
mod sweep;

use super::{PlotError, TimeSeries};
use std::path::{Path, PathBuf};

pub use data::ReplayData;
pub use sweep::write_sweep_page;

/// At most this many agents are drawn (an evenly spaced subset, leaders included).
pub const MAX_AGENTS: usize = 1_000;
/// At most this many frames (logged rows) are kept, evenly spaced, first and last
/// included.
pub const MAX_FRAMES: usize = 2_000;
/// At most this many per-frame numbers (x, y, vx, vy per drawn agent and the angle error
/// of each drawn edge, per frame) are kept: fewer frames for more agents.
pub const MAX_CELLS: usize = 500_000;
/// At most this many points of V(t) and of the largest angle error are kept.
pub const MAX_CHART_POINTS: usize = 2_000;
/// An upper bound of the size of `replay.html` in bytes: 18 bytes per kept number (at
/// most 17 characters, `-1.234567890e-100`, and a comma: the per-frame numbers, the frame
/// times and the three chart series) plus the ids, edges, summary texts and page (taken
/// as at most 1 MB).
pub const MAX_BYTES: usize = 18 * (MAX_CELLS + MAX_FRAMES + 3 * MAX_CHART_POINTS) + 1_000_000;

/// The page template; the data replaces [`DATA_MARKER`].
const TEMPLATE: &str = include_str!("replay.html");
/// The placeholder of the data in [`TEMPLATE`].
const DATA_MARKER: &str = "/*PH_REPLAY_DATA*/null";

/// Reads `dir/timeseries.csv` and `dir/summary.json` and writes `dir/replay.html`;
/// returns its path.
///
/// # Errors
///
/// A [`PlotError`] naming the file and the reason, as for the figures.
pub fn write_replay(dir: &Path) -> Result<PathBuf, PlotError> {
    write_replay_from(dir, None)
}

/// [`write_replay`] with the rows of `dir/timeseries.csv` given in memory (`series`, the
/// rows the run wrote there): the same page without reading the file back.
pub fn write_replay_from(dir: &Path, series: Option<&TimeSeries>) -> Result<PathBuf, PlotError> {
    let data = ReplayData::load_from(dir, series)?;
    let path = dir.join("replay.html");
    std::fs::write(&path, page(&data.to_json())).map_err(|e| PlotError::Draw {
        path: path.clone(),
        reason: e.to_string(),
    })?;
    Ok(path)
}

/// The page with `json` as its data. `</` is escaped (`<\/`, the same JSON string), so
/// that no text of the run can close the script element.
pub fn page(json: &str) -> String {
    let safe = json.replace("</", "<\\/");
    TEMPLATE.replacen(DATA_MARKER, &safe, 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_template_has_one_data_marker_and_no_network_reference() {
        assert_eq!(TEMPLATE.matches(DATA_MARKER).count(), 1);
        for bad in ["http://", "https://", "//cdn", "import(", "XMLHttpRequest"] {
            assert!(!TEMPLATE.contains(bad), "template contains {bad}");
        }
    }

    #[test]
    fn run_text_cannot_close_the_script() {
        let p = page(r#"{"scenario":"</script><script>alert(1)</script>"}"#);
        assert_eq!(
            p.matches("</script>").count(),
            TEMPLATE.matches("</script>").count()
        );
        assert!(p.contains(r#"<\/script>"#));
    }
}
