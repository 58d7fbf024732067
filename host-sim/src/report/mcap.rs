//! `run.mcap` (`host-sim run --mcap`): the logged rows of `timeseries.csv` as MCAP
//! messages that Foxglove and PlotJuggler open (`docs/outputs.md`, "run.mcap"). Every value
//! comes from [`for_each_cell`] under the column names of [`header`], the one
//! implementation of the time series; the run's events are added when it is over.
//!
//! Messages are JSON (`message_encoding = "json"`) with `jsonschema` schemas. The
//! visual channels carry Foxglove's schema names (`foxglove.PosesInFrame`,
//! `foxglove.SceneUpdate`, `foxglove.Log`) and their field layout; each embedded schema
//! describes the fields written. No ROS 2 message schemas are written.

use super::columns::{for_each_cell, header, BASE_COLUMNS};
use crate::analysis::Event;
use crate::engine::{Recorder, Row};
use crate::model::{EstimateInfo, Model};
use mcap::records::MessageHeader;
use serde_json::{json, Map, Value};
use std::collections::BTreeMap;
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
        let options = mcap::WriteOptions::new()
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
            columns,
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
        })
    }

    fn write(&mut self, channel_id: u16, t: f64, message: &Value) -> io::Result<()> {
        let data = serde_json::to_vec(message).map_err(io::Error::other)?;
        let time = nanos(t);
        self.sequence = self.sequence.wrapping_add(1);
        let header = MessageHeader {
            channel_id,
            sequence: self.sequence,
            log_time: time,
            publish_time: time,
        };
        self.writer
            .write_to_known_channel(&header, &data)
            .map_err(io_err)
    }

    /// The values `range` of a row as a JSON object keyed by column name.
    fn object(&self, values: &[f64], range: std::ops::Range<usize>) -> Value {
        let m: Map<String, Value> = range
            .map(|k| (self.columns[k].clone(), json!(values[k])))
            .collect();
        Value::Object(m)
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
            self.write(self.channels.events, e.t, &msg)?;
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
        let poses: Vec<Value> = (0..n).map(|k| pose(q(k))).collect();
        let msg = json!({"timestamp": stamp(t), "frame_id": FRAME, "poses": poses});
        self.write(self.channels.poses, t, &msg)?;
        // A tolerance of a microsecond: log instants are multiples of the step.
        if self
            .last_scene
            .is_none_or(|t0| t - t0 >= SCENE_PERIOD - 1e-6)
        {
            self.last_scene = Some(t);
            let scene = self.scene(t, &q);
            self.write(self.channels.scene, t, &scene)?;
        }
        for k in 0..n {
            let i = base + 4 * k;
            let v = &values[i..i + 4];
            let msg = json!({"x": v[0], "y": v[1], "vx": v[2], "vy": v[3]});
            self.write(self.channels.agents[k], t, &msg)?;
        }
        let diag = self.object(values, 1..base);
        self.write(self.channels.diagnostics, t, &diag)?;
        let a0 = base + 4 * n;
        let angles = self.object(values, a0..a0 + self.n_angles);
        self.write(self.channels.angles, t, &angles)?;
        let est = self.object(values, a0 + self.n_angles..self.columns.len());
        self.write(self.channels.estimates, t, &est)
    }

    /// One `SceneUpdate`: a sphere and a label per agent, the triangle edges (grey line
    /// list) and the leader edge (orange), replacing the previous ones (same ids).
    fn scene(&self, t: f64, q: &dyn Fn(usize) -> (f64, f64)) -> Value {
        let point = |(x, y): (f64, f64)| json!({"x": x, "y": y, "z": 0.0});
        let colour = |r: f64, g: f64, b: f64| json!({"r": r, "g": g, "b": b, "a": 1.0});
        let line = |pairs: &[(usize, usize)], c: Value, thickness: f64| {
            let points: Vec<Value> = pairs
                .iter()
                .flat_map(|&(a, b)| [point(q(a)), point(q(b))])
                .collect();
            json!({"type": 2, "pose": pose((0.0, 0.0)), "thickness": thickness,
                   "scale_invariant": true, "points": points, "color": c,
                   "colors": [], "indices": []})
        };
        let entity = |id: &str, extra: Value| {
            let mut e = json!({"timestamp": stamp(t), "frame_id": FRAME, "id": id,
                "lifetime": {"sec": 0, "nsec": 0}, "frame_locked": false, "metadata": [],
                "arrows": [], "cubes": [], "spheres": [], "cylinders": [], "lines": [],
                "triangles": [], "texts": [], "models": []});
            if let (Some(e), Value::Object(x)) = (e.as_object_mut(), extra) {
                e.extend(x);
            }
            e
        };
        let spheres: Vec<Value> = (0..self.names.len())
            .map(|k| {
                json!({"pose": pose(q(k)), "size": {"x": 0.1, "y": 0.1, "z": 0.1},
                       "color": colour(0.12, 0.47, 0.71)})
            })
            .collect();
        let texts: Vec<Value> = self
            .names
            .iter()
            .enumerate()
            .map(|(k, name)| {
                json!({"pose": pose(q(k)), "billboard": true, "font_size": 14.0,
                       "scale_invariant": true, "color": colour(0.0, 0.0, 0.0), "text": name})
            })
            .collect();
        let mut entities = vec![
            entity("agents", json!({"spheres": spheres, "texts": texts})),
            entity(
                "edges",
                json!({"lines": [line(&self.edges, colour(0.5, 0.5, 0.5), 2.0)]}),
            ),
        ];
        if let Some(l) = self.leader {
            let lines = [line(&[l], colour(1.0, 0.5, 0.0), 4.0)];
            entities.push(entity("leader_edge", json!({ "lines": lines })));
        }
        json!({"deletions": [], "entities": entities})
    }
}

/// A pose at `(x, y, 0)`, identity orientation (the agents are points in the plane).
fn pose((x, y): (f64, f64)) -> Value {
    json!({"position": {"x": x, "y": y, "z": 0.0},
           "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}})
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

/// The embedded JSON schemas: Foxglove's field layout for its well-known schemas (the
/// fields written), plain objects of numbers for the rest.
mod schemas {
    use serde_json::{json, Map, Value};

    fn object(title: &str, props: Value) -> Value {
        json!({"title": title, "type": "object", "properties": props})
    }

    fn time() -> Value {
        object(
            "time",
            json!({"sec": {"type": "integer"}, "nsec": {"type": "integer"}}),
        )
    }

    fn xyz(title: &str) -> Value {
        object(
            title,
            json!({"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}}),
        )
    }

    fn pose() -> Value {
        let q = json!({"x": {"type": "number"}, "y": {"type": "number"},
                       "z": {"type": "number"}, "w": {"type": "number"}});
        object(
            "foxglove.Pose",
            json!({"position": xyz("foxglove.Vector3"),
                   "orientation": object("foxglove.Quaternion", q)}),
        )
    }

    fn color() -> Value {
        object(
            "foxglove.Color",
            json!({"r": {"type": "number"}, "g": {"type": "number"},
                   "b": {"type": "number"}, "a": {"type": "number"}}),
        )
    }

    fn array(items: Value) -> Value {
        json!({"type": "array", "items": items})
    }

    pub fn poses_in_frame() -> Value {
        object(
            "foxglove.PosesInFrame",
            json!({"timestamp": time(), "frame_id": {"type": "string"},
                   "poses": array(pose())}),
        )
    }

    pub fn scene_update() -> Value {
        let sphere = object(
            "foxglove.SpherePrimitive",
            json!({"pose": pose(), "size": xyz("foxglove.Vector3"), "color": color()}),
        );
        let line = object(
            "foxglove.LinePrimitive",
            json!({"type": {"type": "integer"}, "pose": pose(), "thickness": {"type": "number"},
                   "scale_invariant": {"type": "boolean"}, "points": array(xyz("foxglove.Point3")),
                   "color": color(), "colors": array(color()),
                   "indices": array(json!({"type": "integer"}))}),
        );
        let text = object(
            "foxglove.TextPrimitive",
            json!({"pose": pose(), "billboard": {"type": "boolean"},
                   "font_size": {"type": "number"}, "scale_invariant": {"type": "boolean"},
                   "color": color(), "text": {"type": "string"}}),
        );
        let any = array(json!({"type": "object"}));
        let entity = object(
            "foxglove.SceneEntity",
            json!({"timestamp": time(), "frame_id": {"type": "string"}, "id": {"type": "string"},
                   "lifetime": object("duration", json!({"sec": {"type": "integer"},
                                                        "nsec": {"type": "integer"}})),
                   "frame_locked": {"type": "boolean"}, "metadata": any,
                   "arrows": any, "cubes": any, "spheres": array(sphere),
                   "cylinders": any, "lines": array(line), "triangles": any,
                   "texts": array(text), "models": any}),
        );
        object(
            "foxglove.SceneUpdate",
            json!({"deletions": any, "entities": array(entity)}),
        )
    }

    pub fn log() -> Value {
        object(
            "foxglove.Log",
            json!({"timestamp": time(), "level": {"type": "integer"},
                   "message": {"type": "string"}, "name": {"type": "string"},
                   "file": {"type": "string"}, "line": {"type": "integer"}}),
        )
    }

    /// An object of numbers with these keys (non-finite values are written as `null`).
    pub fn numbers(keys: &[String]) -> Value {
        let props: Map<String, Value> = keys
            .iter()
            .map(|k| (k.clone(), json!({"type": ["number", "null"]})))
            .collect();
        json!({"type": "object", "properties": props})
    }
}
