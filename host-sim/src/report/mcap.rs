//! `run.mcap` (`host-sim run --mcap`): the logged rows of `timeseries.csv` as MCAP
//! messages that Foxglove and PlotJuggler open (`docs/outputs.md`, "run.mcap"). Every value
//! comes from [`for_each_cell`] under the column names of [`header`], the one
//! implementation of the time series; the run's events are added when it is over.
//!
//! Messages are JSON (`message_encoding = "json"`) with `jsonschema` schemas, in
//! zstd-compressed chunks. The
//! visual channels carry Foxglove's schema names (`foxglove.PosesInFrame`,
//! `foxglove.SceneUpdate`, `foxglove.Log`) and their field layout; each embedded schema
//! describes the fields written. No ROS 2 message schemas are written.

use super::columns::{for_each_cell, header, BASE_COLUMNS};
use crate::analysis::Event;
use crate::engine::{Recorder, Row};
use crate::model::{EstimateInfo, Model};
use mcap::records::MessageHeader;
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::fs::File;
use std::io::{self, BufWriter};
use std::path::Path;

/// The fixed frame every position is in (the simulator's world frame, metres).
pub const FRAME: &str = "world";

/// Topics of `run.mcap`.
pub mod topic {
    /// Every agent's position (`foxglove.PosesInFrame`, one pose per agent in model order).
    pub const POSES: &str = "/agents/poses";
    /// The formation drawn: agents, labels, triangle edges, leader edge
    /// (`foxglove.SceneUpdate`), at most every [`super::SCENE_PERIOD`] of simulated time.
    pub const SCENE: &str = "/formation/scene";
    /// Prefix of each agent's state channel (`/agents/<id>`: `x`, `y`, `vx`, `vy`).
    pub const AGENT: &str = "/agents/";
    /// V and its parts, errors, distances, frame counters (the first columns of the CSV).
    pub const DIAGNOSTICS: &str = "/diagnostics";
    /// Every controlled angle's error (columns `angle_err_*`).
    pub const ANGLE_ERRORS: &str = "/angle_errors";
    /// Every owned estimate and its true value (columns `rhat_*`, `r_*`).
    pub const ESTIMATES: &str = "/estimates";
    /// The run's events (collisions, divergence, …), `foxglove.Log`.
    pub const EVENTS: &str = "/events";
}

/// Simulated seconds between two scene updates (10 Hz: what a 3-D view needs; the
/// entities stay until replaced). Every other channel has every logged row.
pub const SCENE_PERIOD: f64 = 0.1;

/// Writes `run.mcap`; [`McapRecorder::close`] adds the events and the summary section.
pub struct McapRecorder {
    writer: mcap::Writer<BufWriter<File>>,
    columns: Vec<String>,
    /// Agent ids (as in the scenario), triangle edges and the leader edge (indices).
    names: Vec<String>,
    edges: Vec<(usize, usize)>,
    leader: Option<(usize, usize)>,
    n_angles: usize,
    channels: Channels,
    values: Vec<f64>,
    sequence: u32,
    /// Time of the last scene update.
    last_scene: Option<f64>,
    /// Each column's JSON key, `"name":`.
    keys: Vec<String>,
    /// The message being written (reused).
    text: String,
}

struct Channels {
    poses: u16,
    scene: u16,
    agents: Vec<u16>,
    diagnostics: u16,
    angles: u16,
    estimates: u16,
    events: u16,
}

/// An MCAP error as an I/O error (the [`Recorder`] interface).
fn io_err(e: mcap::McapError) -> io::Error {
    io::Error::other(e)
}

impl McapRecorder {
    /// Creates the file and writes its header, schemas and channels.
    pub fn create(path: &Path, model: &Model, estimates: &[EstimateInfo]) -> io::Result<Self> {
        let file = BufWriter::new(File::create(path)?);
        // zstd chunks (MCAP's default compression, which Foxglove, PlotJuggler and the
        // PyPI reader read): the JSON messages shrink about 4× (`paper`: 26.6 → 6.6 MB). One
        // thread: the same bytes and counts on any machine.
        let options = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Zstd))
            .compression_threads(0)
            .profile("")
            .library(concat!("ph-formation-sim ", env!("CARGO_PKG_VERSION")));
        let mut w = options.create(file).map_err(io_err)?;
        let mut channel = |topic: &str, schema_name: &str, schema: Value| -> io::Result<u16> {
            let data = serde_json::to_vec(&schema).map_err(io::Error::other)?;
            let s = w
                .add_schema(schema_name, "jsonschema", &data)
                .map_err(io_err)?;
            w.add_channel(s, topic, "json", &BTreeMap::new())
                .map_err(io_err)
        };
        let columns = header(model, estimates);
        let n = model.agents.len();
        let n_angles = model.triangles.len() * 2;
        let base = BASE_COLUMNS.len();
        let names_of = |range: std::ops::Range<usize>| columns[range].to_vec();
        let poses = channel(
            topic::POSES,
            "foxglove.PosesInFrame",
            schemas::poses_in_frame(),
        )?;
        let scene = channel(
            topic::SCENE,
            "foxglove.SceneUpdate",
            schemas::scene_update(),
        )?;
        let mut agents = Vec::with_capacity(n);
        for a in &model.agents {
            let keys = ["x", "y", "vx", "vy"].map(String::from);
            let t = format!("{}{}", topic::AGENT, a.name);
            agents.push(channel(
                &t,
                "ph_formation.AgentState",
                schemas::numbers(&keys),
            )?);
        }
        let diagnostics = channel(
            topic::DIAGNOSTICS,
            "ph_formation.Diagnostics",
            schemas::numbers(&names_of(1..base)),
        )?;
        let angles = channel(
            topic::ANGLE_ERRORS,
            "ph_formation.AngleErrors",
            schemas::numbers(&names_of(base + 4 * n..base + 4 * n + n_angles)),
        )?;
        let estimates_ch = channel(
            topic::ESTIMATES,
            "ph_formation.Estimates",
            schemas::numbers(&names_of(base + 4 * n + n_angles..columns.len())),
        )?;
        let events = channel(topic::EVENTS, "foxglove.Log", schemas::log())?;
        let mut edges: Vec<(usize, usize)> = model
            .triangles
            .iter()
            .flat_map(|t| {
                let [a, b, c] = t.vertices;
                [(a, b), (b, c), (a, c)]
            })
            .map(|(a, b)| (a.min(b), a.max(b)))
            .collect();
        edges.sort_unstable();
        edges.dedup();
        Ok(Self {
            writer: w,
            columns: columns.clone(),
            names: model.agents.iter().map(|a| a.name.clone()).collect(),
            edges,
            leader: model.leader.as_ref().map(|l| (l.a, l.b)),
            n_angles,
            channels: Channels {
                poses,
                scene,
                agents,
                diagnostics,
                angles,
                estimates: estimates_ch,
                events,
            },
            values: Vec::new(),
            sequence: 0,
            last_scene: None,
            keys: columns
                .iter()
                .map(|c| format!("{}:", Value::String(c.clone())))
                .collect(),
            text: String::new(),
        })
    }

    fn write_value(&mut self, channel_id: u16, t: f64, message: &Value) -> io::Result<()> {
        let data = serde_json::to_vec(message).map_err(io::Error::other)?;
        self.write(channel_id, t, &data)
    }

    fn write(&mut self, channel_id: u16, t: f64, data: &[u8]) -> io::Result<()> {
        let time = nanos(t);
        self.sequence = self.sequence.wrapping_add(1);
        let header = MessageHeader {
            channel_id,
            sequence: self.sequence,
            log_time: time,
            publish_time: time,
        };
        self.writer
            .write_to_known_channel(&header, data)
            .map_err(io_err)
    }

    /// Writes the values `range` of a row as a JSON object keyed by column name into
    /// `out` (cleared first).
    fn object(&self, out: &mut String, values: &[f64], range: std::ops::Range<usize>) {
        out.clear();
        out.push('{');
        for k in range {
            out.push_str(&self.keys[k]);
            number(out, values[k]);
            out.push(',');
        }
        if out.ends_with(',') {
            out.pop();
        }
        out.push('}');
    }

    /// Writes the run's events (`foxglove.Log`, level ERROR) and finishes the file (its
    /// summary and index records).
    pub fn close(mut self, events: &[Event]) -> io::Result<()> {
        for e in events {
            let msg = json!({
                "timestamp": stamp(e.t),
                "level": 4,
                "message": e.message,
                "name": e.kind.to_string(),
                "file": "",
                "line": 0,
            });
            self.write_value(self.channels.events, e.t, &msg)?;
        }
        self.writer.finish().map_err(io_err)?;
        Ok(())
    }
}

impl Recorder for McapRecorder {
    fn record(&mut self, r: &Row<'_>) -> io::Result<()> {
        // The row's values, taken out of `self` while the messages are written.
        let mut values = std::mem::take(&mut self.values);
        values.clear();
        for_each_cell(r, |c| values.push(c.as_f64()));
        let result = self.write_row(&values);
        self.values = values;
        result
    }

    fn finish(&mut self) -> io::Result<()> {
        self.writer.flush().map_err(io_err)
    }
}

impl McapRecorder {
    /// The messages of one row (`values` in column order).
    fn write_row(&mut self, values: &[f64]) -> io::Result<()> {
        let t = values[0];
        let base = BASE_COLUMNS.len();
        let n = self.names.len();
        let q = |k: usize| -> (f64, f64) {
            let i = base + 4 * k;
            (values[i], values[i + 1])
        };
        let mut out = std::mem::take(&mut self.text);
        // foxglove.PosesInFrame. Every message is written as text (serde_json's `Value`s
        // cost 3 times the simulation of paper in instructions, callgrind).
        out.clear();
        let ns = nanos(t);
        let _ = write!(
            out,
            r#"{{"timestamp":{{"sec":{},"nsec":{}}},"frame_id":"{FRAME}","poses":["#,
            ns / 1_000_000_000,
            ns % 1_000_000_000
        );
        for k in 0..n {
            pose(&mut out, q(k));
            out.push(',');
        }
        if n > 0 {
            out.pop();
        }
        out.push_str("]}");
        let mut result = self.write(self.channels.poses, t, out.as_bytes());
        // A tolerance of a microsecond: log instants are multiples of the step.
        if result.is_ok()
            && self
                .last_scene
                .is_none_or(|t0| t - t0 >= SCENE_PERIOD - 1e-6)
        {
            self.last_scene = Some(t);
            self.scene(&mut out, t, &q);
            result = self.write(self.channels.scene, t, out.as_bytes());
        }
        for k in 0..n {
            if result.is_err() {
                break;
            }
            // The agent's own channel: its columns without the `_<id>` suffix.
            let i = base + 4 * k;
            out.clear();
            for (key, x) in [r#"{"x":"#, r#","y":"#, r#","vx":"#, r#","vy":"#]
                .iter()
                .zip(&values[i..i + 4])
            {
                out.push_str(key);
                number(&mut out, *x);
            }
            out.push('}');
            result = self.write(self.channels.agents[k], t, out.as_bytes());
        }
        let a0 = base + 4 * n;
        for (channel, range) in [
            (self.channels.diagnostics, 1..base),
            (self.channels.angles, a0..a0 + self.n_angles),
            (
                self.channels.estimates,
                a0 + self.n_angles..self.columns.len(),
            ),
        ] {
            if result.is_err() {
                break;
            }
            self.object(&mut out, values, range);
            result = self.write(channel, t, out.as_bytes());
        }
        self.text = out;
        result
    }

    /// One `SceneUpdate` into `out` (cleared first): a sphere and a label per agent, the
    /// triangle edges (grey line list) and the leader edge (orange), replacing the
    /// previous ones (same ids). Written as text, as the rows' messages.
    fn scene(&self, out: &mut String, t: f64, q: &dyn Fn(usize) -> (f64, f64)) {
        const BLUE: &str = r#"{"r":0.12,"g":0.47,"b":0.71,"a":1.0}"#;
        const BLACK: &str = r#"{"r":0.0,"g":0.0,"b":0.0,"a":1.0}"#;
        const GREY: &str = r#"{"r":0.5,"g":0.5,"b":0.5,"a":1.0}"#;
        const ORANGE: &str = r#"{"r":1.0,"g":0.5,"b":0.0,"a":1.0}"#;
        let ns = nanos(t);
        let entity = |out: &mut String, id: &str| {
            let _ = write!(
                out,
                r#"{{"timestamp":{{"sec":{},"nsec":{}}},"frame_id":"{FRAME}","id":"{id}","lifetime":{{"sec":0,"nsec":0}},"frame_locked":false,"metadata":[],"arrows":[],"cubes":[],"cylinders":[],"triangles":[],"models":[]"#,
                ns / 1_000_000_000,
                ns % 1_000_000_000
            );
        };
        let line = |out: &mut String, pairs: &[(usize, usize)], colour: &str, thickness: f64| {
            let _ = write!(
                out,
                r#"{{"type":2,"thickness":{thickness:?},"scale_invariant":true,"color":{colour},"colors":[],"indices":[],"pose":"#
            );
            pose(out, (0.0, 0.0));
            out.push_str(r#","points":["#);
            for &(a, b) in pairs {
                for p in [q(a), q(b)] {
                    out.push_str(r#"{"x":"#);
                    number(out, p.0);
                    out.push_str(r#","y":"#);
                    number(out, p.1);
                    out.push_str(r#","z":0.0},"#);
                }
            }
            if !pairs.is_empty() {
                out.pop();
            }
            out.push_str("]}");
        };
        out.clear();
        out.push_str(r#"{"deletions":[],"entities":["#);
        entity(out, "agents");
        out.push_str(r#","lines":[],"spheres":["#);
        for k in 0..self.names.len() {
            out.push_str(if k == 0 {
                r#"{"pose":"#
            } else {
                r#",{"pose":"#
            });
            pose(out, q(k));
            let _ = write!(
                out,
                r#","size":{{"x":0.1,"y":0.1,"z":0.1}},"color":{BLUE}}}"#
            );
        }
        out.push_str(r#"],"texts":["#);
        for (k, name) in self.names.iter().enumerate() {
            out.push_str(if k == 0 {
                r#"{"pose":"#
            } else {
                r#",{"pose":"#
            });
            pose(out, q(k));
            let _ = write!(
                out,
                r#","billboard":true,"font_size":14.0,"scale_invariant":true,"color":{BLACK},"text":{}}}"#,
                Value::String(name.clone())
            );
        }
        out.push_str("]},");
        entity(out, "edges");
        out.push_str(r#","spheres":[],"texts":[],"lines":["#);
        line(out, &self.edges, GREY, 2.0);
        out.push_str("]}");
        if let Some(l) = self.leader {
            out.push(',');
            entity(out, "leader_edge");
            out.push_str(r#","spheres":[],"texts":[],"lines":["#);
            line(out, &[l], ORANGE, 4.0);
            out.push_str("]}");
        }
        out.push_str("]}");
    }
}

/// A pose at `(x, y, 0)`, identity orientation (the agents are points in the plane).
fn pose(out: &mut String, (x, y): (f64, f64)) {
    out.push_str(r#"{"position":{"x":"#);
    number(out, x);
    out.push_str(r#","y":"#);
    number(out, y);
    out.push_str(r#","z":0.0},"orientation":{"x":0.0,"y":0.0,"z":0.0,"w":1.0}}"#);
}

/// `x` as JSON: Rust's shortest round-trip form, as in `timeseries.csv` (`0.35`, `1e-7`),
/// `null` for NaN and infinities (which JSON lacks).
fn number(out: &mut String, x: f64) {
    if x.is_finite() {
        super::number::push_f64(out, x);
    } else {
        out.push_str("null");
    }
}

/// Simulated time (s, from 0) in nanoseconds, the MCAP log time.
fn nanos(t: f64) -> u64 {
    (t.max(0.0) * 1e9).round() as u64
}

/// Simulated time as Foxglove's `{sec, nsec}`.
fn stamp(t: f64) -> Value {
    let ns = nanos(t);
    json!({"sec": ns / 1_000_000_000, "nsec": ns % 1_000_000_000})
}

/// The embedded JSON schemas (`mcap/schemas.rs`).
mod schemas;
