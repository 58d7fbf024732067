//! Reading a run directory: the fields of `summary.json` the figures use and the
//! columns of `timeseries.csv` they draw, thinned while reading (two passes: count the
//! rows, then keep an evenly spaced subset).

use super::thinning::{spread, Thinning};
use super::{PlotError, MAX_AGENT_PATHS, MAX_ANGLES, MAX_ESTIMATES, REQUIRED, WORST_NAMED};
use crate::report::rows::{Field, Rows};
use crate::report::TimeSeries;
use serde::Deserialize;
use std::collections::HashMap;
use std::fs::File;
use std::io::BufReader;
use std::path::Path;

// ---------------------------------------------------------------------------
// Input

/// An agent id in `summary.json`: an integer or a name.
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
pub(super) enum Id {
    /// `7`.
    Number(i64),
    /// `"north-3"`.
    Name(String),
}

impl std::fmt::Display for Id {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Number(i) => write!(f, "{i}"),
            Self::Name(s) => f.write_str(s),
        }
    }
}

/// `summary.json`'s `shape`.
#[derive(Debug, Deserialize)]
pub(super) struct ShapeSummary {
    pub(super) target: String,
    pub(super) max_error_rel: Option<f64>,
    pub(super) reflected: bool,
    pub(super) folded_triangles: Vec<[Id; 3]>,
    pub(super) target_positions: Vec<[Option<f64>; 2]>,
}

/// The fields of `summary.json` the plots use.
#[derive(Debug, Deserialize)]
pub(super) struct Summary {
    pub(super) scenario: String,
    pub(super) outcome: String,
    #[serde(default)]
    pub(super) outcome_reason: Option<String>,
    pub(super) agents: Vec<Id>,
    pub(super) edges: Vec<[Id; 2]>,
    #[serde(default)]
    pub(super) leaders: Option<[Id; 2]>,
    /// The final formation against its target (absent in runs made before it existed).
    #[serde(default)]
    pub(super) shape: Option<ShapeSummary>,
    #[serde(default)]
    pub(super) mode: Option<serde_json::Value>,
    #[serde(default)]
    pub(super) estimator: Option<serde_json::Value>,
    /// How the run was judged (absent in runs made before it existed).
    #[serde(default)]
    pub(super) verdict: Option<VerdictSummary>,
    #[serde(default)]
    pub(super) criteria: Option<CriteriaSummary>,
}

/// `summary.json`'s `verdict`: the bands and window a noisy run was judged on.
#[derive(Debug, Deserialize)]
pub(super) struct VerdictSummary {
    #[serde(default)]
    pub(super) bands: Option<BandsSummary>,
    #[serde(default)]
    pub(super) steady_window_s: Option<[f64; 2]>,
}

/// `summary.json`'s `verdict.bands`.
#[derive(Debug, Deserialize)]
pub(super) struct BandsSummary {
    pub(super) angle_rad: f64,
}

/// `summary.json`'s `criteria`.
#[derive(Debug, Deserialize)]
pub(super) struct CriteriaSummary {
    pub(super) angle_tolerance_rad: f64,
}

impl Summary {
    /// The angle line the verdict used: the calibrated band with the steady window's
    /// start, else the noise-free tolerance (else 1e-3 rad).
    pub(super) fn angle_line(&self) -> (f64, Option<f64>) {
        if let Some(v) = &self.verdict {
            if let Some(b) = &v.bands {
                return (b.angle_rad, v.steady_window_s.map(|w| w[0]));
            }
        }
        let tol = self
            .criteria
            .as_ref()
            .map_or(super::ANGLE_THRESHOLD, |c| c.angle_tolerance_rad);
        (tol, None)
    }
}

/// A labelled series aligned with [`Run::t`].
pub(super) struct Named {
    pub(super) label: String,
    pub(super) values: Vec<f64>,
}

/// The kept path of one agent, aligned with [`Run::t`].
pub(super) struct AgentPath {
    pub(super) agent: usize,
    pub(super) x: Vec<f64>,
    pub(super) y: Vec<f64>,
}

/// All agent positions at one time.
pub(super) struct Snapshot {
    pub(super) t: f64,
    pub(super) pos: Vec<(f64, f64)>,
}

/// One estimate and its true value, aligned with [`Run::t`].
pub(super) struct Estimate {
    pub(super) label: String,
    pub(super) rhat: Vec<f64>,
    pub(super) r: Vec<f64>,
}

/// Everything the figures draw, downsampled.
pub(super) struct Run {
    pub(super) summary: Summary,
    /// Time of each kept row.
    pub(super) t: Vec<f64>,
    /// `V`, `V_kin`, `V_ang`, `V_lead`, `V_est`.
    pub(super) energy: Vec<Named>,
    pub(super) max_angle_err: Vec<f64>,
    pub(super) disp_err: Vec<f64>,
    pub(super) vel_err: Vec<f64>,
    pub(super) min_dist: Vec<f64>,
    /// Agent ids (as in the column names) in agent order.
    pub(super) agent_ids: Vec<String>,
    /// Indices into `agent_ids`.
    pub(super) leaders: Vec<usize>,
    /// Graph edges as index pairs into `agent_ids` (unknown ids dropped).
    pub(super) edges: Vec<(usize, usize)>,
    pub(super) paths: Vec<AgentPath>,
    pub(super) snapshots: Vec<Snapshot>,
    pub(super) angles: Vec<Named>,
    pub(super) n_angles: usize,
    /// Indices into `angles` of the [`WORST_NAMED`] largest |angle errors| at the end,
    /// largest first.
    pub(super) worst_angles: Vec<usize>,
    pub(super) estimates: Vec<Estimate>,
    pub(super) n_estimates: usize,
}

/// Column indices of the CSV header, by name.
pub(super) struct Header<'a> {
    pub(super) path: &'a Path,
    pub(super) names: Vec<String>,
    pub(super) index: HashMap<String, usize>,
}

impl Header<'_> {
    pub(super) fn require(&self, column: &str) -> Result<usize, PlotError> {
        self.index
            .get(column)
            .copied()
            .ok_or_else(|| PlotError::MissingColumn {
                path: self.path.to_path_buf(),
                column: column.to_string(),
            })
    }

    /// `(column index, suffix)` of every column whose name starts with
    /// `prefix`, in column order.
    pub(super) fn with_prefix(&self, prefix: &str) -> Vec<(usize, String)> {
        self.names
            .iter()
            .enumerate()
            .filter_map(|(i, n)| n.strip_prefix(prefix).map(|s| (i, s.to_string())))
            .collect()
    }
}

/// Downsampled columns being collected: `data[k]` holds the kept values of
/// CSV column `src[k]`.
#[derive(Default)]
pub(super) struct Columns {
    pub(super) src: Vec<usize>,
    pub(super) data: Vec<Vec<f64>>,
}

impl Columns {
    pub(super) fn add(&mut self, column: usize) -> usize {
        self.src.push(column);
        self.data.push(Vec::new());
        self.src.len() - 1
    }

    pub(super) fn take(&mut self, slot: usize) -> Vec<f64> {
        std::mem::take(&mut self.data[slot])
    }
}

/// Parses one field: empty → NaN; a number (including `NaN`/`inf`) → it;
/// anything else → [`PlotError::BadValue`]. A value kept in memory is itself.
pub(super) fn field(f: Field<'_>, col: usize, header: &Header<'_>) -> Result<f64, PlotError> {
    let (raw, line) = match f {
        Field::Value(x) => return Ok(x),
        Field::Text(raw, line) => (raw, line),
    };
    let text = String::from_utf8_lossy(raw);
    let text = text.trim();
    if text.is_empty() {
        return Ok(f64::NAN);
    }
    text.parse::<f64>().map_err(|_| PlotError::BadValue {
        path: header.path.to_path_buf(),
        line,
        column: header.names.get(col).cloned().unwrap_or_default(),
        value: text.chars().take(40).collect(),
    })
}

pub(super) fn load_summary(path: &Path) -> Result<Summary, PlotError> {
    let file = File::open(path).map_err(|source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    serde_json::from_reader(BufReader::new(file)).map_err(|source| PlotError::Json {
        path: path.to_path_buf(),
        source,
    })
}

/// Reads `dir/summary.json` and the rows of `dir/timeseries.csv`, or `series` (the same
/// rows, kept in memory by the run) when given.
pub(super) fn load_run(dir: &Path, series: Option<&TimeSeries>) -> Result<Run, PlotError> {
    let summary = load_summary(&dir.join("summary.json"))?;
    let csv_path = dir.join("timeseries.csv");
    let mut reader = match series {
        Some(s) => Rows::memory(s, &csv_path),
        None => Rows::csv(&csv_path)?,
    };

    // Header.
    let names: Vec<String> = reader.names()?;
    if names.iter().all(String::is_empty) {
        return Err(PlotError::Empty {
            path: csv_path,
            reason: "no header row",
        });
    }
    let mut index = HashMap::new();
    for (i, n) in names.iter().enumerate() {
        index.entry(n.clone()).or_insert(i);
    }
    let header = Header {
        path: &csv_path,
        names,
        index,
    };

    // Columns.
    let mut cols = Columns::default();
    let fixed: Vec<usize> = REQUIRED
        .iter()
        .map(|name| header.require(name).map(|c| cols.add(c)))
        .collect::<Result<_, _>>()?;
    let t_col = header.require("t")?;

    let agent_ids: Vec<String> = if summary.agents.is_empty() {
        header
            .with_prefix("x_")
            .into_iter()
            .map(|(_, s)| s)
            .collect()
    } else {
        summary.agents.iter().map(Id::to_string).collect()
    };
    let mut agent_xy = Vec::with_capacity(agent_ids.len());
    for id in &agent_ids {
        agent_xy.push((
            header.require(&format!("x_{id}"))?,
            header.require(&format!("y_{id}"))?,
        ));
    }
    let agent_index: HashMap<&str, usize> = agent_ids
        .iter()
        .enumerate()
        .rev()
        .map(|(i, id)| (id.as_str(), i))
        .collect();
    let lookup = |id: &Id| agent_index.get(id.to_string().as_str()).copied();
    let leaders: Vec<usize> = summary
        .leaders
        .as_ref()
        .map(|[a, b]| [lookup(a), lookup(b)].into_iter().flatten().collect())
        .unwrap_or_default();
    let edges: Vec<(usize, usize)> = summary
        .edges
        .iter()
        .filter_map(|[a, b]| Some((lookup(a)?, lookup(b)?)))
        .collect();

    let mut path_agents = spread(agent_ids.len(), MAX_AGENT_PATHS);
    path_agents.extend(&leaders);
    path_agents.sort_unstable();
    path_agents.dedup();
    let path_slots: Vec<(usize, usize, usize)> = path_agents
        .iter()
        .map(|&a| (a, cols.add(agent_xy[a].0), cols.add(agent_xy[a].1)))
        .collect();

    // Pass 1: count the rows with a finite t, and keep the last one (swapped, not copied).
    let mut valid = 0usize;
    while reader.next()? {
        if field(reader.get(t_col), t_col, &header)?.is_finite() {
            valid += 1;
            reader.keep_as_last();
        }
    }
    let reader = reader;
    // |value| at the end, for ranking (non-finite ranks first: the worst).
    let at_end = |c: usize| field(reader.last(c), c, &header).map_or(f64::INFINITY, |x| x.abs());

    // Angles: an evenly spaced subset and the WORST_NAMED largest at the end (named in
    // the legend).
    let angle_cols = header.with_prefix("angle_err_");
    let n_angles = angle_cols.len();
    let mut by_end: Vec<usize> = (0..n_angles).collect();
    by_end.sort_by(|&a, &b| {
        let (ea, eb) = (at_end(angle_cols[a].0), at_end(angle_cols[b].0));
        eb.total_cmp(&ea).then(a.cmp(&b))
    });
    let worst: Vec<usize> = by_end.iter().copied().take(WORST_NAMED).collect();
    let mut shown = spread(n_angles, MAX_ANGLES);
    shown.extend(&worst);
    shown.sort_unstable();
    shown.dedup();
    let worst_angles: Vec<usize> = worst
        .iter()
        .filter_map(|w| shown.iter().position(|k| k == w))
        .collect();
    let angle_slots: Vec<(String, usize)> = shown
        .into_iter()
        .map(|k| {
            let (c, suffix) = &angle_cols[k];
            (angle_label(suffix), cols.add(*c))
        })
        .collect();

    // Estimates: the MAX_ESTIMATES farthest from their true distance at the end, worst
    // first (all of them, in column order, when there are no more).
    let est_cols = header.with_prefix("rhat_");
    let n_estimates = est_cols.len();
    let mut pairs = Vec::with_capacity(n_estimates);
    for (c, suffix) in &est_cols {
        let r = header.require(&format!("r_{suffix}"))?;
        let gap = field(reader.last(*c), *c, &header)
            .and_then(|h| Ok((h - field(reader.last(r), r, &header)?).abs()));
        let gap = gap.ok().filter(|g| !g.is_nan()).unwrap_or(f64::INFINITY);
        pairs.push((gap, *c, r, suffix.as_str()));
    }
    if n_estimates > MAX_ESTIMATES {
        pairs.sort_by(|a, b| b.0.total_cmp(&a.0));
    }
    let est_slots: Vec<(String, usize, usize)> = pairs
        .iter()
        .take(MAX_ESTIMATES)
        .map(|&(_, c, r, suffix)| (estimate_label(suffix), cols.add(c), cols.add(r)))
        .collect();
    if valid == 0 {
        return Err(PlotError::Empty {
            path: csv_path.clone(),
            reason: "no data row with a finite `t`",
        });
    }
    let thin = Thinning::new(valid);
    let snapshot_at = thin.snapshots();

    // Pass 2: keep the thinned rows.
    let mut reader = reader;
    reader.restart()?;
    let mut snapshots = Vec::with_capacity(snapshot_at.len());
    let (mut v, mut kept) = (0usize, 0usize);
    while reader.next()? {
        let t = field(reader.get(t_col), t_col, &header)?;
        if !t.is_finite() {
            continue;
        }
        if thin.keeps(v) {
            for (slot, &c) in cols.src.iter().enumerate() {
                let x = field(reader.get(c), c, &header)?;
                cols.data[slot].push(x);
            }
            if snapshot_at.contains(&kept) {
                let pos = agent_xy
                    .iter()
                    .map(|&(cx, cy)| {
                        Ok((
                            field(reader.get(cx), cx, &header)?,
                            field(reader.get(cy), cy, &header)?,
                        ))
                    })
                    .collect::<Result<_, PlotError>>()?;
                snapshots.push(Snapshot { t, pos });
            }
            kept += 1;
        }
        v += 1;
        if v == valid {
            break; // the file changed between the passes; ignore the rest
        }
    }

    let t = cols.take(fixed[0]);
    let energy = ["V", "V_kin", "V_ang", "V_lead", "V_est"]
        .iter()
        .zip(&fixed[1..6])
        .map(|(name, &slot)| Named {
            label: (*name).to_string(),
            values: cols.take(slot),
        })
        .collect();
    let max_angle_err = cols.take(fixed[6]);
    let disp_err = cols.take(fixed[7]);
    let vel_err = cols.take(fixed[8]);
    let min_dist = cols.take(fixed[9]);
    let paths = path_slots
        .into_iter()
        .map(|(agent, sx, sy)| AgentPath {
            agent,
            x: cols.take(sx),
            y: cols.take(sy),
        })
        .collect();
    let angles = angle_slots
        .into_iter()
        .map(|(label, slot)| Named {
            label,
            values: cols.take(slot),
        })
        .collect();
    let estimates = est_slots
        .into_iter()
        .map(|(label, sh, sr)| Estimate {
            label,
            rhat: cols.take(sh),
            r: cols.take(sr),
        })
        .collect();

    Ok(Run {
        summary,
        t,
        energy,
        max_angle_err,
        disp_err,
        vel_err,
        min_dist,
        agent_ids,
        leaders,
        edges,
        paths,
        snapshots,
        angles,
        n_angles,
        worst_angles,
        estimates,
        n_estimates,
    })
}

/// `u_v_w` (apex u) → `∠v-u-w`.
pub(super) fn angle_label(suffix: &str) -> String {
    match suffix.split('_').collect::<Vec<_>>()[..] {
        [u, v, w] => format!("∠{v}-{u}-{w}"),
        _ => suffix.to_string(),
    }
}

/// `o_u_f_w` → `o: u→f (w)`.
pub(super) fn estimate_label(suffix: &str) -> String {
    match suffix.split('_').collect::<Vec<_>>()[..] {
        [o, u, f, w] => format!("{o}: {u}→{f} ({w})"),
        _ => suffix.to_string(),
    }
}
