//! A flight as a run directory (`host-sim flight`): `timeseries.csv` and `run.mcap` by
//! the run's own writers ([`CsvRecorder`], [`McapRecorder`]) fed the flight's rows
//! ([`FlightSeries::for_each_row`]), a `summary.json` with what the replay page reads
//! (scenario, agents, edges, leaders, criteria) and the flight's state changes, and
//! `replay.html` from them ([`write_replay`]): `host-sim view DIR` opens it.

use super::log::{FlightError, FlightLog};
use super::series::FlightSeries;
use crate::engine::Recorder;
use crate::model::Model;
use crate::report::{write_replay, CsvRecorder, McapRecorder};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// An agent id as `summary.json` writes it (a number when it is one).
pub(super) fn user_id(name: &str) -> Value {
    name.parse::<u64>()
        .map_or_else(|_| Value::String(name.to_owned()), Value::from)
}

/// Every change of a drone's state or fault, on the flight's clock: `(t, agent, state,
/// fault)`, the first row of each drone included.
pub fn changes(log: &FlightLog) -> Vec<(f64, String, Option<u8>, Option<u8>)> {
    let mut out = Vec::new();
    for k in &log.tracks {
        let mut last = None;
        for s in &k.samples {
            let now = (s.state, s.fault);
            if last != Some(now) {
                out.push((s.t, k.agent.clone(), s.state, s.fault));
                last = Some(now);
            }
        }
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

/// A state's name (docs/crazyflie.md, `formation.state`).
pub fn state_name(state: Option<u8>) -> &'static str {
    match state {
        Some(0) => "idle",
        Some(1) => "formation",
        Some(2) => "hold",
        Some(3) => "landing",
        Some(_) => "unknown",
        None => "not logged",
    }
}

/// `summary.json` of a flight: what the replay page reads, and the flight's own facts.
fn summary(log: &FlightLog, series: &FlightSeries, model: &Model) -> Value {
    let id = |i: usize| user_id(&model.agents[i].name);
    let last = |agent: &str, f: fn(&super::log::Sample) -> Option<u64>| {
        log.track(agent)
            .and_then(|k| k.samples.iter().rev().find_map(f))
    };
    json!({
        "kind": "flight",
        "flight_log": log.path.display().to_string(),
        "scenario": format!("{} (flight)", model.name),
        "source": model.source,
        "outcome": "flight",
        "outcome_reason": format!(
            "the flight log {} on the scenario's formation; t on the flight's clock, \
             the formation started at {:.3} s",
            log.path.display(), series.start
        ),
        "mode": model.mode.as_str(),
        "estimator": model.estimator.as_str(),
        "agents": model.agents.iter().map(|a| user_id(&a.name)).collect::<Vec<_>>(),
        "edges": model.graph.edges.iter().map(|e| [id(e[0]), id(e[1])]).collect::<Vec<_>>(),
        "leaders": model.leader.as_ref().map(|l| [id(l.a), id(l.b)]),
        "criteria": {"angle_tolerance_rad": model.criteria.angle_tolerance},
        "formation_start_s": series.start,
        "grid_step_s": series.step,
        "changes": changes(log).into_iter().map(|(t, agent, state, fault)| json!({
            "t": t, "agent": user_id(&agent), "state": state_name(state), "fault": fault,
        })).collect::<Vec<_>>(),
        "policy": model.agents.iter().map(|a| json!({
            "agent": user_id(&a.name),
            "hold_ticks": last(&a.name, |s| s.hold_ticks),
            "landings": last(&a.name, |s| s.landings),
        })).collect::<Vec<_>>(),
    })
}

/// Writes `dir/timeseries.csv`, `dir/summary.json`, `dir/replay.html` and, with `mcap`,
/// `dir/run.mcap`; returns their paths.
///
/// # Errors
///
/// [`FlightError::Write`] naming the file that cannot be written.
pub fn write_flight_dir(
    log: &FlightLog,
    series: &FlightSeries,
    model: &Model,
    dir: &Path,
    mcap: bool,
) -> Result<Vec<PathBuf>, FlightError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| FlightError::Write { path, source }
    };
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let csv_path = dir.join("timeseries.csv");
    let mut csv = CsvRecorder::create(&csv_path, model, &[]).map_err(io(&csv_path))?;
    series
        .for_each_row(model, |r| csv.record(r))
        .and_then(|()| csv.finish())
        .map_err(io(&csv_path))?;
    drop(csv);
    let mut files = vec![csv_path];
    if mcap {
        let path = dir.join("run.mcap");
        let mut m = McapRecorder::create(&path, model, &[]).map_err(io(&path))?;
        series
            .for_each_row(model, |r| m.record(r))
            .and_then(|()| m.finish())
            .and_then(|()| m.close(&[]))
            .map_err(io(&path))?;
        files.push(path);
    }
    let path = dir.join("summary.json");
    let text = serde_json::to_string_pretty(&summary(log, series, model))
        .map_err(|e| io(&path)(std::io::Error::other(e)))?;
    std::fs::write(&path, text + "\n").map_err(io(&path))?;
    files.push(path);
    let page = write_replay(dir).map_err(|e| FlightError::Content {
        path: dir.join("replay.html"),
        reason: format!("cannot write: {e}"),
    })?;
    files.push(page);
    Ok(files)
}
