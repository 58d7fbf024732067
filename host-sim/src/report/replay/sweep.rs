//! `sweep.html`: the outcome map of a sweep's `points.csv` over its axes, one
//! self-contained page like `replay.html` (`host-sim view SWEEP_DIR`; docs/sweeps.md).
//! Each point is a stacked bar of its outcome fractions at its axis values; a table lists
//! every point.

use crate::analysis::Outcome;
use crate::report::PlotError;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// The page template; the data replaces [`DATA_MARKER`].
const TEMPLATE: &str = include_str!("sweep.html");
/// The placeholder of the data in [`TEMPLATE`].
const DATA_MARKER: &str = "/*PH_SWEEP_DATA*/null";

/// Reads `dir/points.csv` and writes `dir/sweep.html`; returns its path.
///
/// # Errors
///
/// A [`PlotError`] naming `points.csv` (unreadable, malformed, no `point` or `runs`
/// column) or `sweep.html` (not written).
pub fn write_sweep_page(dir: &Path) -> Result<PathBuf, PlotError> {
    let csv_path = dir.join("points.csv");
    let file = std::fs::File::open(&csv_path).map_err(|source| PlotError::Io {
        path: csv_path.clone(),
        source,
    })?;
    let mut reader = csv::Reader::from_reader(file);
    let csv_err = |source| PlotError::Csv {
        path: csv_path.clone(),
        source,
    };
    let columns: Vec<String> = reader
        .headers()
        .map_err(csv_err)?
        .iter()
        .map(str::to_owned)
        .collect();
    let missing = |column: &str| PlotError::MissingColumn {
        path: csv_path.clone(),
        column: column.to_owned(),
    };
    let runs = columns
        .iter()
        .position(|c| c == "runs")
        .ok_or_else(|| missing("runs"))?;
    if columns.first().map(String::as_str) != Some("point") {
        return Err(missing("point"));
    }
    let axes = &columns[1..runs];
    let outcomes: Vec<&str> = Outcome::ALL
        .iter()
        .map(|o| o.as_str())
        .filter(|o| columns.iter().any(|c| c == o))
        .collect();
    let mut rows = Vec::new();
    for rec in reader.records() {
        let rec = rec.map_err(csv_err)?;
        // A number where the text is one (JSON has no NaN: null), else the text.
        let row: Vec<Value> = rec
            .iter()
            .map(|v| match v.trim().parse::<f64>() {
                Ok(x) if x.is_finite() => json!(x),
                Ok(_) => Value::Null,
                Err(_) => json!(v),
            })
            .collect();
        rows.push(row);
    }
    let data = json!({
        "version": 1,
        "source": dir.display().to_string(),
        "columns": columns,
        "axes": axes,
        "outcomes": outcomes,
        "rows": rows,
    });
    let page = TEMPLATE.replacen(DATA_MARKER, &data.to_string().replace("</", "<\\/"), 1);
    let path = dir.join("sweep.html");
    std::fs::write(&path, page).map_err(|e| PlotError::Draw {
        path: path.clone(),
        reason: e.to_string(),
    })?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_template_has_one_data_marker_and_no_network_reference() {
        assert_eq!(TEMPLATE.matches(DATA_MARKER).count(), 1);
        for bad in ["http://", "https://", "src=", "href=", "fetch("] {
            assert!(!TEMPLATE.contains(bad), "template contains {bad}");
        }
    }
}
