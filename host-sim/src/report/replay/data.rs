//! What `replay.html` shows, read from a run directory and thinned: the drawn agents'
//! positions and velocities and the drawn edges' angle errors at the kept frames, and
//! V(t) and the largest angle error for the charts.

use super::{MAX_AGENTS, MAX_CELLS, MAX_CHART_POINTS, MAX_FRAMES};
use crate::report::plot::spread;
use crate::report::rows::{Field, Rows};
use crate::report::{PlotError, TimeSeries};
use serde_json::{json, Value};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::fs::File;
use std::io::BufReader;
use std::path::Path;

/// A number of the camera's configuration in `summary.json` (`world.sensors.camera.KEY`,
/// or `world.camera.KEY`), if the run recorded one.
fn camera(summary: &Value, key: &str) -> Option<f64> {
    let w = &summary["world"];
    w["sensors"]["camera"][key]
        .as_f64()
        .or_else(|| w["camera"][key].as_f64())
}

/// Every `stride`-th of `valid` rows and the last one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Stride {
    valid: usize,
    stride: usize,
}

impl Stride {
    /// At most `max` (≥ 2) of `valid` rows.
    pub(super) fn new(valid: usize, max: usize) -> Self {
        let stride = if valid <= max {
            1
        } else {
            valid.div_ceil(max.max(2) - 1)
        };
        Self { valid, stride }
    }

    fn keeps(&self, v: usize) -> bool {
        v.is_multiple_of(self.stride) || v + 1 == self.valid
    }
}

/// The frame budget: at most [`MAX_FRAMES`] and at most [`MAX_CELLS`] numbers in all, at
/// least the first and the last row.
pub(super) fn max_frames(agents: usize, edges: usize) -> usize {
    let cells = (4 * agents + edges).max(1);
    (MAX_CELLS / cells).clamp(2, MAX_FRAMES)
}

/// The data of the page (`docs/outputs.md`, "replay.html").
#[derive(Debug)]
pub struct ReplayData {
    summary: Value,
    ids: Vec<String>,
    agent_index: Vec<usize>,
    n_agents: usize,
    edges: Vec<(usize, usize)>,
    n_edges: usize,
    leaders: Option<(usize, usize)>,
    rows: usize,
    t: Vec<f64>,
    x: Vec<f64>,
    y: Vec<f64>,
    vx: Vec<f64>,
    vy: Vec<f64>,
    edge_err: Vec<f64>,
    chart_t: Vec<f64>,
    chart_v: Vec<f64>,
    chart_err: Vec<f64>,
}

/// An agent id of `summary.json` as the column names write it.
fn id_text(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// Splits `s` into `n` ids of `known`, joined by `_` (ids may contain `_` themselves).
fn split_ids(s: &str, n: usize, known: &HashMap<String, usize>) -> Option<Vec<usize>> {
    if n == 1 {
        return known.get(s).map(|&i| vec![i]);
    }
    for (k, _) in s.match_indices('_') {
        if let Some(&first) = known.get(&s[..k]) {
            if let Some(mut rest) = split_ids(&s[k + 1..], n - 1, known) {
                rest.insert(0, first);
                return Some(rest);
            }
        }
    }
    None
}

fn io_err(path: &Path) -> impl Fn(std::io::Error) -> PlotError + '_ {
    move |source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// A field as a number (NaN when empty or not a number).
fn number(rows: &Rows<'_>, col: usize) -> f64 {
    match rows.get(col) {
        Field::Value(x) => x,
        Field::Text(raw, _) => std::str::from_utf8(raw)
            .ok()
            .and_then(|s| s.trim().parse().ok())
            .unwrap_or(f64::NAN),
    }
}

impl ReplayData {
    /// Reads `dir/summary.json` and `dir/timeseries.csv` (twice: to count the rows, then
    /// to keep the thinned ones).
    pub fn load(dir: &Path) -> Result<Self, PlotError> {
        Self::load_from(dir, None)
    }

    /// [`Self::load`] with the rows of `dir/timeseries.csv` given in memory (`series`,
    /// the rows the run wrote there).
    pub fn load_from(dir: &Path, series: Option<&TimeSeries>) -> Result<Self, PlotError> {
        let summary_path = dir.join("summary.json");
        let file = File::open(&summary_path).map_err(io_err(&summary_path))?;
        let summary: Value =
            serde_json::from_reader(BufReader::new(file)).map_err(|source| PlotError::Json {
                path: summary_path.clone(),
                source,
            })?;
        let csv_path = dir.join("timeseries.csv");
        let missing = |column: &str| PlotError::MissingColumn {
            path: csv_path.clone(),
            column: column.to_owned(),
        };
        let mut reader = match series {
            Some(s) => Rows::memory(s, &csv_path),
            None => Rows::csv(&csv_path)?,
        };
        let names: Vec<String> = reader.names()?;
        let col: HashMap<&str, usize> = names
            .iter()
            .enumerate()
            .map(|(i, n)| (n.as_str(), i))
            .collect();
        let need = |c: &str| col.get(c).copied().ok_or_else(|| missing(c));
        let (c_t, c_v, c_err) = (need("t")?, need("V")?, need("max_angle_err")?);

        // Agents: the summary's ids, in agent order; an evenly spaced subset, leaders kept.
        let all_ids: Vec<String> = summary["agents"]
            .as_array()
            .map(|a| a.iter().map(id_text).collect())
            .unwrap_or_default();
        let known: HashMap<String, usize> = all_ids
            .iter()
            .enumerate()
            .map(|(i, s)| (s.clone(), i))
            .collect();
        let pair = |v: &Value| -> Option<(usize, usize)> {
            let a = known.get(&id_text(v.get(0)?))?;
            let b = known.get(&id_text(v.get(1)?))?;
            Some((*a, *b))
        };
        let leaders_all = pair(&summary["leaders"]);
        let mut agent_index = if all_ids.len() <= MAX_AGENTS {
            (0..all_ids.len()).collect()
        } else {
            spread(all_ids.len(), MAX_AGENTS - 2)
        };
        if let Some((a, b)) = leaders_all {
            agent_index.extend([a, b]);
        }
        agent_index.sort_unstable();
        agent_index.dedup();
        let kept: HashMap<usize, usize> = agent_index
            .iter()
            .enumerate()
            .map(|(k, &i)| (i, k))
            .collect();
        let mut state_cols = Vec::with_capacity(4 * agent_index.len());
        for &i in &agent_index {
            for c in ["x", "y", "vx", "vy"] {
                state_cols.push(need(&format!("{c}_{}", all_ids[i]))?);
            }
        }
        let ids: Vec<String> = agent_index.iter().map(|&i| all_ids[i].clone()).collect();
        let leaders = leaders_all.and_then(|(a, b)| Some((*kept.get(&a)?, *kept.get(&b)?)));

        // Edges between drawn agents, and the angle columns that colour each.
        let all_edges: Vec<(usize, usize)> = summary["edges"]
            .as_array()
            .map(|a| a.iter().filter_map(pair).collect())
            .unwrap_or_default();
        let mut edges = Vec::new();
        let mut edge_slot: HashMap<(usize, usize), usize> = HashMap::new();
        for &(a, b) in &all_edges {
            if let (Some(&ka), Some(&kb)) = (kept.get(&a), kept.get(&b)) {
                let key = (ka.min(kb), ka.max(kb));
                edge_slot.entry(key).or_insert_with(|| {
                    edges.push(key);
                    edges.len() - 1
                });
            }
        }
        // (column, edge slot): the angle with apex u and far vertices v, w colours edges
        // u–v and u–w.
        let mut angle_edges: Vec<(usize, usize)> = Vec::new();
        for (c, name) in names.iter().enumerate() {
            let Some(rest) = name.strip_prefix("angle_err_") else {
                continue;
            };
            let Some(uvw) = split_ids(rest, 3, &known) else {
                continue;
            };
            for far in [uvw[1], uvw[2]] {
                if let (Some(&ku), Some(&kf)) = (kept.get(&uvw[0]), kept.get(&far)) {
                    if let Some(&s) = edge_slot.get(&(ku.min(kf), ku.max(kf))) {
                        angle_edges.push((c, s));
                    }
                }
            }
        }

        // Pass 1: count the rows with a finite t.
        let mut valid = 0usize;
        while reader.next()? {
            if number(&reader, c_t).is_finite() {
                valid += 1;
            }
        }
        if valid == 0 {
            return Err(PlotError::Empty {
                path: csv_path,
                reason: "no row with a finite t",
            });
        }
        let frames = Stride::new(valid, max_frames(ids.len(), edges.len()));
        let chart = Stride::new(valid, MAX_CHART_POINTS);

        // Pass 2: keep the thinned rows.
        let mut d = Self {
            summary,
            n_agents: all_ids.len(),
            ids,
            agent_index,
            n_edges: all_edges.len(),
            edges,
            leaders,
            rows: valid,
            t: Vec::new(),
            x: Vec::new(),
            y: Vec::new(),
            vx: Vec::new(),
            vy: Vec::new(),
            edge_err: Vec::new(),
            chart_t: Vec::new(),
            chart_v: Vec::new(),
            chart_err: Vec::new(),
        };
        reader.restart()?;
        let mut v = 0usize;
        let mut errs = vec![0.0f64; d.edges.len()];
        while reader.next()? {
            let t = number(&reader, c_t);
            if !t.is_finite() {
                continue;
            }
            if chart.keeps(v) {
                d.chart_t.push(t);
                d.chart_v.push(number(&reader, c_v));
                d.chart_err.push(number(&reader, c_err));
            }
            if frames.keeps(v) {
                d.t.push(t);
                for q in state_cols.chunks_exact(4) {
                    d.x.push(number(&reader, q[0]));
                    d.y.push(number(&reader, q[1]));
                    d.vx.push(number(&reader, q[2]));
                    d.vy.push(number(&reader, q[3]));
                }
                errs.fill(0.0);
                for &(c, s) in &angle_edges {
                    errs[s] = errs[s].max(number(&reader, c).abs());
                }
                d.edge_err.extend_from_slice(&errs);
            }
            v += 1;
        }
        Ok(d)
    }

    /// Number of kept frames.
    pub fn frames(&self) -> usize {
        self.t.len()
    }

    /// The drawn agents' ids.
    pub fn ids(&self) -> &[String] {
        &self.ids
    }

    /// The drawn agents (indices into [`Self::ids`]) that `summary.json`'s verdict names
    /// as giving the safe output in the steady window.
    fn safe_agents(&self) -> Vec<usize> {
        let named = self.summary["verdict"]["safe_agents"].as_array();
        let ids: Vec<String> = named
            .into_iter()
            .flatten()
            .map(|a| match &a["agent"] {
                serde_json::Value::String(s) => s.clone(),
                other => other.to_string(),
            })
            .collect();
        (0..self.ids.len())
            .filter(|&k| ids.contains(&self.ids[k]))
            .collect()
    }

    /// The page's data as JSON text.
    pub fn to_json(&self) -> String {
        let s = &self.summary;
        let head = json!({
            "version": 1,
            "scenario": s["scenario"],
            "outcome": s["outcome"],
            "outcome_reason": s["outcome_reason"],
            "mode": s["mode"],
            "estimator": s["estimator"],
            "settle_time_s": s["settle_time_s"],
            "angle_tolerance": s["criteria"]["angle_tolerance_rad"],
            "angle_band": s["verdict"]["bands"]["angle_rad"],
            "steady_from": s["verdict"]["steady_window_s"][0],
            "safe_agents": self.safe_agents(),
            "ids": self.ids,
            "agent_index": self.agent_index,
            "n_agents": self.n_agents,
            "edges": self.edges.iter().map(|&(a, b)| [a, b]).collect::<Vec<_>>(),
            "n_edges": self.n_edges,
            "leaders": self.leaders.map(|(a, b)| [a, b]),
            "rows": self.rows,
            "fov": camera(s, "fov_deg").map(|d| d.to_radians() / 2.0),
            "camera_range": camera(s, "range_m"),
            "heading_nominal": s["world"]["heading"]["initial_deg"].as_f64().map(f64::to_radians),
        });
        let mut out = head.to_string();
        out.pop(); // the closing brace: the arrays follow
        let mut arr = |name: &str, values: &[f64], digits: usize| {
            let _ = write!(out, ",\"{name}\":[");
            for (k, &x) in values.iter().enumerate() {
                if k > 0 {
                    out.push(',');
                }
                if x.is_finite() {
                    let _ = write!(out, "{x:.digits$e}");
                } else {
                    out.push_str("null");
                }
            }
            out.push(']');
        };
        // Times with 10 significant digits: the hook's frame times are these, and the
        // browser test finds the row of timeseries.csv by them.
        arr("t", &self.t, 9);
        arr("x", &self.x, 9);
        arr("y", &self.y, 9);
        arr("vx", &self.vx, 4);
        arr("vy", &self.vy, 4);
        arr("edge_err", &self.edge_err, 2);
        arr("chart_t", &self.chart_t, 6);
        arr("chart_V", &self.chart_v, 4);
        arr("chart_max_angle_err", &self.chart_err, 4);
        out.push('}');
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stride_keeps_at_most_max_rows_with_first_and_last() {
        for (valid, max) in [
            (1, 2),
            (2, 2),
            (3, 2),
            (6001, 2000),
            (100_000, 13),
            (10, 10),
        ] {
            let s = Stride::new(valid, max);
            let kept: Vec<usize> = (0..valid).filter(|&v| s.keeps(v)).collect();
            assert!(kept.len() <= max, "{valid} {max}: {}", kept.len());
            assert_eq!(kept[0], 0);
            assert_eq!(*kept.last().unwrap(), valid - 1);
        }
    }

    #[test]
    fn the_budget_bounds_the_numbers_at_ten_thousand_agents() {
        let agents = MAX_AGENTS; // 10,000 agents are thinned to these
        let edges = 2 * agents;
        let f = max_frames(agents, edges);
        assert!(f >= 2);
        assert!(f * (4 * agents + edges) <= MAX_CELLS);
        assert_eq!(max_frames(4, 5), MAX_FRAMES);
    }

    #[test]
    fn ids_with_underscores_are_split_by_the_known_ids() {
        let known: HashMap<String, usize> = [("a_1", 0), ("b", 1), ("c_2_x", 2)]
            .into_iter()
            .map(|(s, i)| (s.to_owned(), i))
            .collect();
        assert_eq!(split_ids("a_1_b_c_2_x", 3, &known), Some(vec![0, 1, 2]));
        assert_eq!(split_ids("a_1_b_d", 3, &known), None);
    }

    #[test]
    fn the_camera_is_read_where_summary_json_records_it() {
        let with = json!({"world": {"sensors": {"camera": {"fov_deg": 87.0, "range_m": 4.0}}}});
        assert_eq!(camera(&with, "fov_deg"), Some(87.0));
        assert_eq!(camera(&with, "range_m"), Some(4.0));
        let flat = json!({"world": {"camera": {"fov_deg": 60.0}}});
        assert_eq!(camera(&flat, "fov_deg"), Some(60.0));
        // Today's summary.json (world without sensors): no camera, no wedges.
        let without = json!({"world": {"heading": {"initial_deg": 0.0}}});
        assert_eq!(camera(&without, "fov_deg"), None);
    }
}
