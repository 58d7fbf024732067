//! The run and the flight in one replay page (`OUT/overlay/replay.html`, written by
//! [`write_replay`], the run's page): the run's agents under their ids and the flight's
//! as `flight-<id>`, each with its formation's edges coloured by its own angle errors, on
//! the common time axis of [`Overlay`] (from the formation's start). The page's charts
//! show the run's V and largest angle error. The directory's `timeseries.csv` holds the
//! columns the page reads (`t`, `V`, `max_angle_err`, positions, velocities, angle
//! errors) for both; its `summary.json` the ids, edges and the text shown.

use super::compare::Overlay;
use super::log::FlightError;
use super::write::user_id;
use crate::model::Model;
use crate::report::write_replay;
use serde_json::json;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The flight's id of agent `name` in the overlay.
fn flight_id(name: &str) -> String {
    format!("flight-{name}")
}

/// The angle columns of agents named by `id`, model order (as `timeseries.csv`'s).
fn angle_columns(model: &Model, id: &dyn Fn(usize) -> String) -> Vec<String> {
    let mut out = Vec::new();
    for t in &model.triangles {
        for a in &t.angles {
            let (v, w) = (id(a.far[0]), id(a.far[1]));
            let (v, w) = if v <= w { (v, w) } else { (w, v) };
            out.push(format!("angle_err_{}_{v}_{w}", id(a.apex)));
        }
    }
    out
}

/// Writes `dir/timeseries.csv`, `dir/summary.json` and `dir/replay.html`; returns the
/// page's path.
///
/// # Errors
///
/// [`FlightError::Write`] naming the file.
pub fn write_overlay(
    dir: &Path,
    o: &Overlay,
    model: &Model,
    run: &Path,
    flight: &Path,
) -> Result<PathBuf, FlightError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| FlightError::Write { path, source }
    };
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let n = model.n();
    let run_id = |i: usize| model.agents[i].name.clone();
    let fl_id = |i: usize| flight_id(&model.agents[i].name);
    let mut text = String::from("t,V,max_angle_err");
    for id in [&run_id as &dyn Fn(usize) -> String, &fl_id] {
        for i in 0..n {
            for c in ["x", "y", "vx", "vy"] {
                let _ = write!(text, ",{c}_{}", id(i));
            }
        }
    }
    for c in angle_columns(model, &run_id)
        .into_iter()
        .chain(angle_columns(model, &fl_id))
    {
        let _ = write!(text, ",{c}");
    }
    text.push('\n');
    let na = 2 * model.triangles.len();
    for (k, t) in o.t.iter().enumerate() {
        let _ = write!(text, "{t:?},{:?},{:?}", o.run_big_v[k], o.run_err[k]);
        for (q, v) in [(&o.run_q, &o.run_v), (&o.flight_q, &o.flight_v)] {
            for i in 0..n {
                let (p, u) = (q[k * n + i], v[k * n + i]);
                let _ = write!(text, ",{:?},{:?},{:?},{:?}", p.x, p.y, u.x, u.y);
            }
        }
        for a in [&o.run_angles, &o.flight_angles] {
            for x in &a[k * na..(k + 1) * na] {
                let _ = write!(text, ",{x:?}");
            }
        }
        text.push('\n');
    }
    let path = dir.join("timeseries.csv");
    std::fs::write(&path, text).map_err(io(&path))?;
    let both = |f: &dyn Fn(&str) -> serde_json::Value| {
        model
            .agents
            .iter()
            .map(|a| f(&a.name))
            .chain(model.agents.iter().map(|a| f(&flight_id(&a.name))))
            .collect::<Vec<_>>()
    };
    let mut edges = Vec::new();
    for id in [&run_id as &dyn Fn(usize) -> String, &fl_id] {
        for e in &model.graph.edges {
            edges.push([user_id(&id(e[0])), user_id(&id(e[1]))]);
        }
    }
    let summary = json!({
        "kind": "overlay",
        "scenario": format!("{}: run and flight", model.name),
        "outcome": "overlay",
        "outcome_reason": format!(
            "agents {}: the run {}; flight-…: the flight {}; t from the formation's start; \
             the charts are the run's",
            model.agents.iter().map(|a| a.name.as_str()).collect::<Vec<_>>().join(", "),
            run.display(),
            flight.display()
        ),
        "mode": model.mode.as_str(),
        "estimator": model.estimator.as_str(),
        "agents": both(&user_id),
        "edges": edges,
        "leaders": model.leader.as_ref().map(|l| [user_id(&run_id(l.a)), user_id(&run_id(l.b))]),
        "criteria": {"angle_tolerance_rad": model.criteria.angle_tolerance},
    });
    let path = dir.join("summary.json");
    let body = serde_json::to_string_pretty(&summary).unwrap_or_default() + "\n";
    std::fs::write(&path, body).map_err(io(&path))?;
    write_replay(dir).map_err(|e| FlightError::Content {
        path: dir.join("replay.html"),
        reason: format!("cannot write: {e}"),
    })
}
