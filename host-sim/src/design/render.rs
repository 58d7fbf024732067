//! A construction as a complete scenario file (schema: `docs/scenarios.md`), with a
//! commented header and the target shape in a `[target]` section.
//!
//! The gains and settings come from a template scenario: its `[integration]`,
//! `[controller]`, `[gains]`, `[agent_defaults]`, `[sensors]`, `[radio]` and `[criteria]`
//! are copied, its `mode` and `duration` are kept, and its `[leader]` gives `stiffness`
//! and `damping`. Without a template, `host-sim/scenarios/paper.toml` is the template.

use super::error::DesignError;
use super::initial::{formation_size, initial_positions, Initial, Perturbation, Scale};
use super::laman::{Construction, DesignOptions};
use super::points::Point;
use std::fmt::Write;

/// The sections copied from the template, in the order they are written.
const COPIED: [&str; 7] = [
    "integration",
    "controller",
    "gains",
    "agent_defaults",
    "sensors",
    "radio",
    "criteria",
];

/// A parsed template scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct Template {
    label: String,
    table: toml::Table,
}

/// `D^v` per kg of virtual mass that `host-sim design --vehicle crazyflie` writes (N s/m
/// per kg, SPEC S12): the smallest of the measured 1, 2, 3, 4, 6 and 8 with which the
/// designed formations of 16 and 20 agents converged in 10 of 10 runs and the 30-agent
/// lattice on the unslotted channel in 9 under `world = "crazyflie"` (docs/design.md,
/// "Designing for the Crazyflie").
pub const CRAZYFLIE_VELOCITY_DAMPING: f64 = 6.0;

impl Template {
    /// Parses a template's TOML text; `label` names it in errors and in the header.
    pub fn parse(text: &str, label: &str) -> Result<Self, DesignError> {
        let err = |reason: String| DesignError::Template {
            file: label.to_owned(),
            reason,
        };
        let table: toml::Table =
            toml::from_str(text).map_err(|e| err(format!("not TOML: {}", e.message())))?;
        for s in COPIED.iter().chain(&["leader"]) {
            if table.get(*s).is_some_and(|v| !v.is_table()) {
                return Err(err(format!("`{s}` must be a table")));
            }
        }
        Ok(Self {
            label: label.to_owned(),
            table,
        })
    }

    /// The template for a Crazyflie team of `n` (`host-sim design --vehicle crazyflie`,
    /// docs/design.md "Designing for the Crazyflie"): `world = "crazyflie"` (the
    /// firmware's cascade, shared positions, the radio channel with the broadcast rate
    /// it carries), the force limited to 2 N per kg of virtual mass (2 m/s², under the
    /// 3.57 m/s² of the firmware's 20° tilt limit, as the app's square), and a velocity
    /// damping `D^v` = [`CRAZYFLIE_VELOCITY_DAMPING`] N s/m per kg (SPEC S12) that damps
    /// the modes the estimator's velocity noise excites (docs/design.md measures 1 to 8
    /// on formations of 4 to 50). With `slotted` the team shares the channel in slots
    /// ([`Template::slotted`]). The rest is the template's.
    pub fn crazyflie(mut self, n: usize, slotted: bool) -> Self {
        let mass = self
            .table
            .get("agent_defaults")
            .and_then(|a| a.get("mass"))
            .and_then(|m| m.as_float().or_else(|| m.as_integer().map(|i| i as f64)))
            .unwrap_or(1.0);
        self.set("controller", "max_force", toml::Value::Float(2.0 * mass));
        self.set(
            "agent_defaults",
            "velocity_damping",
            toml::Value::Float(CRAZYFLIE_VELOCITY_DAMPING * mass),
        );
        self.table.insert(
            "world".to_owned(),
            toml::Value::String("crazyflie".to_owned()),
        );
        self.label = format!("{} for the Crazyflie (--vehicle crazyflie)", self.label);
        if slotted {
            self.slotted(n)
        } else {
            self
        }
    }

    /// The Crazyflie channel shared in slots (TDMA, docs/radio.md) by a team of `n`:
    /// each agent owns one slot per superframe, long enough for what it sends at one
    /// broadcast (a frame of at most `MAX_FRAME_LEN` bytes and its position packet of at
    /// most `MAX_POSITION_LEN`, each after the radio's turnaround), and a frame may wait
    /// one superframe for its slot (`radio.queue_limit`, at least the default 0.05 s).
    /// The simulator's slots are perfectly synchronised; the Crazyflie app broadcasts
    /// unslotted today (docs/design.md).
    pub fn slotted(mut self, n: usize) -> Self {
        use crate::model::channel::{
            air_time, CRAZYFLIE_BIT_RATE as RATE, CRAZYFLIE_OVERHEAD_BYTES as OVERHEAD,
            CRAZYFLIE_TURNAROUND,
        };
        use ph_formation_core::{wire::position::MAX_POSITION_LEN, MAX_FRAME_LEN};
        let packet = |len| CRAZYFLIE_TURNAROUND + air_time(len, OVERHEAD, RATE);
        // To the nanosecond, so that the file reads 0.000697.
        let slot = ((packet(MAX_FRAME_LEN) + packet(MAX_POSITION_LEN)) * 1e9).round() / 1e9;
        let mut channel = toml::Table::new();
        channel.insert("access".to_owned(), toml::Value::String("tdma".to_owned()));
        channel.insert("slot".to_owned(), toml::Value::Float(slot));
        self.set("radio", "channel", toml::Value::Table(channel));
        let wait = ((slot * n as f64).max(0.05) * 1e9).round() / 1e9;
        self.set("radio", "queue_limit", toml::Value::Float(wait));
        self.label = format!("{}, slotted channel", self.label);
        self
    }

    /// Sets `[section] key = value`, making the section if needed.
    fn set(&mut self, section: &str, key: &str, value: toml::Value) {
        let t = self
            .table
            .entry(section.to_owned())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        if let Some(t) = t.as_table_mut() {
            t.insert(key.to_owned(), value);
        }
    }

    /// The built-in `paper` scenario (SPEC §9) as template: the default.
    pub fn paper() -> Self {
        // The file is the repository's own and parses (tested).
        Self::parse(include_str!("../../scenarios/paper.toml"), "builtin:paper").unwrap_or_else(
            |_| Self {
                label: "builtin:paper".to_owned(),
                table: toml::Table::new(),
            },
        )
    }

    /// Where it came from.
    pub fn label(&self) -> &str {
        &self.label
    }

    fn number(&self, section: &str, key: &str) -> Option<f64> {
        let v = self.table.get(section)?.get(key)?;
        v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
    }

    /// `controller.angle_margin_deg` (default 5°): construct with at least this margin.
    pub fn angle_margin_deg(&self) -> f64 {
        self.number("controller", "angle_margin_deg").unwrap_or(5.0)
    }

    /// The template's `duration` (s), if it has one.
    pub fn duration(&self) -> Option<f64> {
        self.number_top("duration")
    }

    /// `criteria.collision_distance` (default 0.05 m).
    pub fn collision_distance(&self) -> f64 {
        self.number("criteria", "collision_distance")
            .unwrap_or(0.05)
    }
}

/// What the scenario says besides the construction.
#[derive(Clone, Debug, PartialEq)]
pub struct ScenarioOptions {
    /// `name` (output directory `out/<name>/`).
    pub name: String,
    /// `description`; default: the source and the counts.
    pub description: Option<String>,
    /// The command line that asked for it (echoed in the header).
    pub command: String,
    /// Where the points came from (a file, or a generator's description).
    pub source: String,
    /// v* (m/s), constant.
    pub velocity_reference: [f64; 2],
    /// `duration` (s); default: the template's, else 100.
    pub duration: Option<f64>,
    /// `seed` of the run (noise, radio faults).
    pub seed: u64,
    /// Write a `[leader]` on the construction's leader edge, `z*` = its target offset.
    pub leader: bool,
    /// Initial positions.
    pub perturbation: Perturbation,
    /// Template; `None`: [`Template::paper`].
    pub template: Option<Template>,
    /// The camera the construction was designed for (`--fov-deg`); `None`: no camera
    /// written, no headings.
    pub camera: Option<CameraView>,
}

/// A camera a construction was designed for ([`super::fov`]): written as `[sensors.camera]
/// fov_deg` and one `heading_deg` per agent, after checking at the target and at the
/// initial positions that every triangle neighbour is at least the heading margin inside
/// the view.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraView {
    /// Field of view (degrees).
    pub fov_deg: f64,
    /// Heading margin (degrees).
    pub heading_margin_deg: f64,
    /// Every agent's heading (rad), in point order.
    pub headings: Vec<f64>,
}

impl Default for ScenarioOptions {
    fn default() -> Self {
        Self {
            name: "design".to_owned(),
            description: None,
            command: "host-sim design".to_owned(),
            source: "points".to_owned(),
            velocity_reference: [0.0, 0.0],
            duration: None,
            seed: 1,
            leader: true,
            perturbation: Perturbation::default(),
            template: None,
            camera: None,
        }
    }
}

/// An angle in degrees with 10 decimals, trailing zeros dropped (`60.0`, not
/// `60.00000000000001`); 1e-10° is far below any tolerance of the controller.
fn deg(rad: f64) -> String {
    let s = format!("{:.10}", rad.to_degrees());
    let s = s.trim_end_matches('0');
    if s.ends_with('.') {
        format!("{s}0")
    } else {
        s.to_owned()
    }
}

/// A TOML string literal.
fn quoted(s: &str) -> String {
    toml::Value::String(s.to_owned()).to_string()
}

/// Renders the scenario. Fails when the initial positions cannot be made valid for the
/// template's angle margin and collision distance ([`initial_positions`]).
pub fn render_scenario(
    points: &[Point],
    c: &Construction,
    design: &DesignOptions,
    o: &ScenarioOptions,
) -> Result<String, DesignError> {
    let paper = Template::paper();
    let tpl = o.template.as_ref().unwrap_or(&paper);
    let init: Initial = initial_positions(
        points,
        c,
        &o.perturbation,
        tpl.angle_margin_deg(),
        tpl.collision_distance(),
    )?;
    let with_camera;
    let tpl = match &o.camera {
        Some(cam) => {
            check_camera(points, &init.positions, c, cam)?;
            with_camera = tpl.with_fov(cam.fov_deg);
            &with_camera
        }
        None => tpl,
    };
    let f = &c.figures;
    let n = points.len();
    let mut s = String::new();
    let w = &mut s;
    // A String never fails to take a write.
    let _ = writeln!(
        w,
        "# Generated by `host-sim design`; regenerate rather than edit."
    );
    let _ = writeln!(w, "# Command: {}", o.command.replace('\n', " "));
    let _ = writeln!(
        w,
        "# Target: {} ({n} agents, size {:.4} m RMS from the centroid)",
        o.source,
        formation_size(points)
    );
    let _ = writeln!(
        w,
        "# Triangulated Laman graph (SPEC §3): {} triangles, angle margin {}°{}; gains from {}",
        f.triangles,
        c.margin_deg,
        if c.margin_deg > design.margin_deg {
            format!(
                " (raised from {}°, which gave a controlled angle below {}°)",
                design.margin_deg,
                super::laman::RAISE_BELOW_DEG
            )
        } else {
            String::new()
        },
        tpl.label()
    );
    let _ = writeln!(
        w,
        "#   smallest controlled angle margin {:.3}°, smallest interior angle {:.3}°",
        f.min_controlled_deg, f.min_angle_deg
    );
    let _ = writeln!(
        w,
        "#   at most {} triangles (capacity {}) and {} neighbours (capacity {}) per agent",
        f.max_triangles_per_agent,
        design.max_triangles,
        f.max_neighbours_per_agent,
        design.max_neighbours
    );
    let _ = writeln!(
        w,
        "#   longest edge {:.4} m, mean edge {:.4} m, {} overlapping triangles",
        f.longest_edge, f.mean_edge, f.overlapping
    );
    let _ = writeln!(
        w,
        "# Initial positions: the target rotated by {:.3}° about its centroid, plus random",
        init.rotation.to_degrees()
    );
    let _ = writeln!(
        w,
        "#   displacements of at most {:.4} m ({} % of {}, seed {}); {} of them shortened",
        init.max_displacement,
        100.0 * o.perturbation.fraction,
        match o.perturbation.scale {
            Scale::Size => "its size",
            Scale::Spacing => "the spacing (median nearest-neighbour distance)",
        },
        o.perturbation.seed,
        init.shortened
    );
    let _ = writeln!(w, "#   so that every triangle starts valid and unfolded");
    if let Some(cam) = &o.camera {
        let _ = writeln!(
            w,
            "# Camera: field of view {}°, every agent's heading_deg chosen so that each triangle",
            cam.fov_deg
        );
        let _ = writeln!(
            w,
            "#   neighbour stays at least {}° (the heading margin) inside its view, at the target",
            cam.heading_margin_deg
        );
        let _ = writeln!(
            w,
            "#   and at the initial positions (docs/design.md, \"Designing for a camera\")"
        );
    }
    let _ = writeln!(
        w,
        "# Schema: docs/scenarios.md. Agent i is point i − 1 of the target."
    );
    let description = o.description.clone().unwrap_or_else(|| {
        format!(
            "{}: {n} agents, {} triangles (host-sim design)",
            o.source, f.triangles
        )
    });
    let _ = writeln!(w, "name = {}", quoted(&o.name));
    let _ = writeln!(w, "description = {}", quoted(&description));
    let duration = o
        .duration
        .or_else(|| tpl.number_top("duration"))
        .unwrap_or(100.0);
    let _ = writeln!(w, "duration = {duration:?}");
    let _ = writeln!(w, "seed = {}", o.seed);
    let mode = tpl
        .table
        .get("mode")
        .and_then(|m| m.as_str())
        .unwrap_or("sampled");
    let _ = writeln!(w, "mode = {}", quoted(mode));
    if let Some(world) = tpl.table.get("world").and_then(|x| x.as_str()) {
        let _ = writeln!(w, "world = {}   # docs/world.md", quoted(world));
    }
    let [vx, vy] = o.velocity_reference;
    let _ = writeln!(w, "velocity_reference = [{vx:?}, {vy:?}]   # v* (m/s)");
    for section in &COPIED[..4] {
        copy_section(w, tpl, section);
    }
    for (i, q) in init.positions.iter().enumerate() {
        let _ = write!(
            w,
            "\n[[agents]]\nid = {}\nposition = [{:?}, {:?}]\n",
            i + 1,
            q[0],
            q[1]
        );
        if let Some(h) = o.camera.as_ref().and_then(|cam| cam.headings.get(i)) {
            let _ = writeln!(w, "heading_deg = {}", deg(*h));
        }
    }
    for t in &c.triangles {
        let [a, b, v] = t.vertices.map(|x| x + 1);
        let _ = write!(
            w,
            "\n[[triangles]]\nvertices = [{a}, {b}, {v}]\nangles = [\n"
        );
        for ca in t.angles {
            let _ = writeln!(
                w,
                "  {{ apex = {}, desired_deg = {} }},",
                ca.apex + 1,
                deg(ca.desired)
            );
        }
        let _ = writeln!(w, "]");
    }
    if o.leader {
        let [a, b] = c.leader;
        let z = [points[a][0] - points[b][0], points[a][1] - points[b][1]];
        let leader = tpl.table.get("leader").and_then(|l| l.as_table());
        let stiffness = leader
            .and_then(|l| l.get("stiffness"))
            .cloned()
            .unwrap_or(toml::Value::Float(1.0));
        let damping = leader
            .and_then(|l| l.get("damping"))
            .cloned()
            .unwrap_or(toml::Value::Float(0.8));
        let _ = write!(w, "\n[leader]\nagents = [{}, {}]   # z = q{} − q{}\nstiffness = {stiffness}\ndamping = {damping}\ndisplacement = [{:?}, {:?}]   # z* = the target's offset\n", a + 1, b + 1, a + 1, b + 1, z[0], z[1]);
    }
    for section in &COPIED[4..] {
        copy_section(w, tpl, section);
    }
    let _ = write!(w, "\n[target]\n# The shape the angles encode, in agent order (agent i at entry i − 1).\npositions = [\n");
    for p in points {
        let _ = writeln!(w, "  [{:?}, {:?}],", p[0], p[1]);
    }
    let _ = writeln!(w, "]");
    Ok(s)
}

/// Checks at the target and at the initial positions that every triangle neighbour is at
/// least the heading margin inside its agent's view ([`super::fov::view_check`]).
fn check_camera(
    points: &[Point],
    initial: &[Point],
    c: &Construction,
    cam: &CameraView,
) -> Result<(), DesignError> {
    let tris: Vec<[usize; 3]> = c.triangles.iter().map(|t| t.vertices).collect();
    for (when, q) in [("target", points), ("initial positions", initial)] {
        super::fov::view_check(
            q,
            &tris,
            &cam.headings,
            cam.fov_deg.to_radians(),
            cam.heading_margin_deg.to_radians(),
        )
        .map_err(|(i, j, off)| {
            DesignError::Camera(format!(
                "at the {when}, agent {}'s neighbour {} is {:.2}° off its heading, beyond \
                 F/2 − margin = {}°/2 − {}°",
                i + 1,
                j + 1,
                off.to_degrees(),
                cam.fov_deg,
                cam.heading_margin_deg
            ))
        })?;
    }
    Ok(())
}

impl Template {
    /// This template with `[sensors.camera] fov_deg` set to `fov_deg`.
    fn with_fov(&self, fov_deg: f64) -> Self {
        let mut t = self.clone();
        let sensors = t
            .table
            .entry("sensors".to_owned())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        if let Some(s) = sensors.as_table_mut() {
            let camera = s
                .entry("camera".to_owned())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            if let Some(cam) = camera.as_table_mut() {
                cam.insert("fov_deg".to_owned(), toml::Value::Float(fov_deg));
            }
        }
        t
    }

    fn number_top(&self, key: &str) -> Option<f64> {
        let v = self.table.get(key)?;
        v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
    }
}

/// Writes `[section]` of the template, if it has one.
fn copy_section(w: &mut String, tpl: &Template, section: &str) {
    if let Some(t) = tpl.table.get(section).and_then(|v| v.as_table()) {
        let _ = writeln!(w, "\n[{section}]   # from {}", tpl.label());
        for (k, v) in t {
            let _ = writeln!(w, "{k} = {v}");
        }
    }
}
