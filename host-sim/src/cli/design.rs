//! `host-sim design`: from a shape (a points file or a built-in generator) to a complete
//! scenario TOML ([`crate::design`]); the quality figures go to stderr, the scenario to
//! stdout or `-o FILE`.

use crate::design::{
    construct, construct_for_camera, read_points, render_scenario, CameraOptions, CameraView,
    DesignError, DesignOptions, Generator, Perturbation, Scale, ScenarioOptions, Template,
};
use crate::exit_code;
use crate::scenario::Source;
use clap::{Args, ValueEnum};
use std::path::PathBuf;

/// A built-in shape of `host-sim design --shape`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Shape {
    /// Regular polygon, `n` corners.
    Polygon,
    /// Regular polygon of `n − 1` corners and its centre.
    PolygonCentre,
    /// Square lattice, `⌈√n⌉` points wide.
    RectLattice,
    /// Triangular lattice, `⌈√n⌉` points wide.
    TriLattice,
    /// Zig-zag strip of equilateral triangles.
    Strip,
    /// Random points in a disc, no two closer than the spacing.
    Disc,
}

/// Arguments of `host-sim design`.
#[derive(Debug, Args)]
pub struct DesignArgs {
    /// Target points: a `.csv` (columns x, y) or a `.toml` (`points = [[x, y], …]`, or a
    /// scenario's `[target]`). Give this or `--shape`.
    #[arg(
        value_name = "POINTS",
        required_unless_present = "shape",
        conflicts_with = "shape"
    )]
    pub points: Option<PathBuf>,
    /// A built-in shape instead of a points file.
    #[arg(long, value_enum, requires = "n")]
    pub shape: Option<Shape>,
    /// Number of agents of the built-in shape.
    #[arg(short, long, value_name = "N")]
    pub n: Option<usize>,
    /// Side / lattice step / smallest distance of the built-in shape (m).
    #[arg(long, value_name = "M", default_value_t = 1.0)]
    pub spacing: f64,
    /// Largest initial displacement of each agent, as a fraction of the formation's
    /// spacing (the median nearest-neighbour distance), in [0, 1] (local, so it means the
    /// same at any N and any shape).
    #[arg(long, value_name = "F", default_value_t = 0.1)]
    pub perturbation: f64,
    /// Also rotate the initial formation by a random angle about its centroid.
    #[arg(long)]
    pub rotate: bool,
    /// Seed of the random disc, of the initial displacements and of the run.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub seed: u64,
    /// Leader edge as two agent ids `A,B` (agent i is point i − 1); default: the shortest
    /// edge of the best triangle near the centroid.
    #[arg(long, value_name = "A,B", value_parser = pair::<usize>)]
    pub leader: Option<[usize; 2]>,
    /// Write no `[leader]` section (no leader edge maneuver).
    #[arg(long, conflicts_with = "leader")]
    pub no_leader: bool,
    /// Reference velocity v* (m/s) as `VX,VY`.
    #[arg(long = "v-star", value_name = "VX,VY", value_parser = pair::<f64>, allow_hyphen_values = true)]
    pub v_star: Option<[f64; 2]>,
    /// Scenario (file or built-in name) whose gains and settings are copied. The default,
    /// `formation-only` (c = 10, d = 1, c_e = 10), converges for lattices, strips and discs
    /// of 200 agents (docs/design.md); the paper's gains (c = 1000) do not beyond a few
    /// agents.
    #[arg(long, value_name = "SCENARIO", default_value = "formation-only")]
    pub template: String,
    /// Every angle of every triangle stays this far from 0 and 180° (degrees) [default: the
    /// template's `controller.angle_margin_deg`]. A construction whose smallest controlled
    /// angle is below 15° is grown again with the margin raised in 5° steps up to 30°
    /// (points on a circle need it; docs/design.md).
    #[arg(long, value_name = "DEG")]
    pub margin: Option<f64>,
    /// Triangles per agent at most [default: the controller's capacity].
    #[arg(long, value_name = "K", default_value_t = ph_formation_core::MAX_TRIANGLES)]
    pub max_triangles: usize,
    /// Neighbours per agent at most [default: the controller's capacity].
    #[arg(long, value_name = "K", default_value_t = ph_formation_core::MAX_NEIGHBOURS)]
    pub max_neighbours: usize,
    /// Scenario name (output directory `out/<name>/`) [default: the shape or file stem].
    #[arg(long)]
    pub name: Option<String>,
    /// Simulated duration (s) [default: the template's].
    #[arg(long, value_name = "S")]
    pub duration: Option<f64>,
    /// The vehicle the formation is designed for: `crazyflie` writes `world =
    /// "crazyflie"`, a 2 N/kg force limit and a velocity damping of 6 N s/m per kg over
    /// the template's, and for more than 20 agents a slotted channel (docs/design.md).
    #[arg(long, value_enum)]
    pub vehicle: Option<Vehicle>,
    /// With `--vehicle crazyflie`: how the team shares the radio channel [default:
    /// `aloha` up to 20 agents, `tdma` above] (docs/design.md).
    #[arg(long, value_enum, requires = "vehicle")]
    pub channel: Option<Channel>,
    /// Design for a camera of this field of view (degrees, in (0, 360]): choose the
    /// triangles and every agent's heading so that each triangle neighbour stays at least
    /// the heading margin inside its view at the target and at the initial positions, and
    /// no line of sight passes another agent (`--clearance`), within the camera's range; write
    /// `heading_deg` per agent and `[sensors.camera] fov_deg` (docs/design.md, "Designing
    /// for a camera"). 360: the plain design, byte for byte. Not with `--rotate`.
    #[arg(long = "fov-deg", value_name = "F", conflicts_with = "rotate")]
    pub fov_deg: Option<f64>,
    /// Find the smallest field of view at which the design still finds a formation
    /// (bisection to 0.5°), print it, and write that design.
    #[arg(long, conflicts_with_all = ["fov_deg", "rotate"])]
    pub smallest_fov: bool,
    /// How far inside the view every neighbour stays for the heading's errors (degrees)
    /// [default: the `crazyflie-camera` world's heading error + spread + drift × duration,
    /// 2° + 5° + 0.02°/s × duration].
    #[arg(long, value_name = "DEG")]
    pub heading_margin_deg: Option<f64>,
    /// With `--fov-deg`: no other agent may be this close to a line of sight at the
    /// target (m) [default: the `crazyflie-camera` world's occlusion radius, 0.05 m, plus
    /// twice the largest initial displacement]; 0 lets lines of sight pass other agents.
    #[arg(long, value_name = "M")]
    pub clearance: Option<f64>,
    /// Write the scenario here instead of stdout.
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Also draw the designed formation (labelled agents, triangles, desired angles,
    /// leader edge, initial and target positions) into FILE (.png or .svg).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
}

/// `--vehicle`: what the formation is designed to fly on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Vehicle {
    /// The template's settings as they are (the default).
    Template,
    /// A Crazyflie team (`world = "crazyflie"`, docs/design.md).
    Crazyflie,
}

/// `--channel`: how a Crazyflie team shares its radio channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Channel {
    /// Unslotted broadcasts, as the Crazyflie app sends them (the preset's).
    Aloha,
    /// One slot per agent (docs/radio.md), sized for a frame and a position packet.
    Tdma,
}

/// Above this many agents `--vehicle crazyflie` slots the channel: one unslotted
/// Crazyflie channel carries 20 agents at 16.7 Hz, and the designed formations of 30 and
/// more hold on slots, not on it (docs/design.md).
pub const ALOHA_TEAM: usize = 20;

/// Parses `A,B`.
fn pair<T: std::str::FromStr>(s: &str) -> Result<[T; 2], PairError> {
    let parse = |x: &str| {
        x.trim()
            .parse::<T>()
            .map_err(|_| PairError::NotANumber(x.trim().to_owned()))
    };
    match s.split_once(',') {
        Some((a, b)) => Ok([parse(a)?, parse(b)?]),
        None => Err(PairError::NotAPair(s.to_owned())),
    }
}

/// Why a `A,B` flag value is refused (clap prints it after the flag's name).
#[derive(Debug, thiserror::Error)]
enum PairError {
    /// One of the two is not a number.
    #[error("`{0}` is not a number")]
    NotANumber(String),
    /// No comma.
    #[error("expected two numbers separated by a comma, got `{0}`")]
    NotAPair(String),
}

impl DesignArgs {
    fn generator(&self, shape: Shape, n: usize) -> Generator {
        let spacing = self.spacing;
        match shape {
            Shape::Polygon | Shape::PolygonCentre => Generator::Polygon {
                n,
                spacing,
                centre: shape == Shape::PolygonCentre,
            },
            Shape::RectLattice => Generator::RectangularLattice { n, spacing },
            Shape::TriLattice => Generator::TriangularLattice { n, spacing },
            Shape::Strip => Generator::Strip { n, spacing },
            Shape::Disc => Generator::RandomDisc {
                n,
                spacing,
                seed: self.seed,
            },
        }
    }
}

/// Why a designed scenario or its figure could not be written.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// The scenario file or standard output.
    #[error("cannot write {to}: {source}")]
    Io {
        /// Where.
        to: String,
        /// Why.
        source: std::io::Error,
    },
    /// The written scenario does not load (a bug: `design` checked it).
    #[error("{0}")]
    Scenario(#[from] crate::scenario::ScenarioErrors),
    /// The formation figure.
    #[error("{0}")]
    Plot(#[from] crate::report::plot::PlotError),
}

/// Runs `host-sim design`; returns the exit code.
pub fn design_command(args: &DesignArgs, quiet: bool) -> u8 {
    match design(args) {
        Ok((text, figures)) => {
            if !quiet {
                eprint!("{figures}");
            }
            let written = match &args.output {
                Some(path) => std::fs::write(path, &text).map_err(|source| WriteError::Io {
                    to: path.display().to_string(),
                    source,
                }),
                None => {
                    use std::io::Write;
                    std::io::stdout()
                        .write_all(text.as_bytes())
                        .map_err(|source| WriteError::Io {
                            to: "stdout".to_owned(),
                            source,
                        })
                }
            };
            let written = written.and_then(|()| match &args.plot {
                Some(file) => super::plot_formation_of(&text, "design", file),
                None => Ok(()),
            });
            match written {
                Ok(()) => exit_code::CONVERGED,
                Err(e) => {
                    eprintln!("error: {e}");
                    exit_code::IO
                }
            }
        }
        Err(e) => {
            eprintln!("error: design refused: {e}");
            exit_code::DESIGN_REFUSED
        }
    }
}

/// The scenario text and the figures to print.
fn design(args: &DesignArgs) -> Result<(String, String), DesignError> {
    let option = |name: &str, reason: String| DesignError::Option {
        option: name.to_owned(),
        reason,
    };
    let (points, source, default_name) = match (&args.points, args.shape) {
        (Some(path), _) => {
            let stem = path
                .file_stem()
                .map_or_else(|| "design".to_owned(), |s| s.to_string_lossy().into_owned());
            (read_points(path)?, path.display().to_string(), stem)
        }
        (None, Some(shape)) => {
            let n = args
                .n
                .ok_or_else(|| option("n", "a built-in shape needs --n".to_owned()))?;
            let g = args.generator(shape, n);
            let name = format!(
                "{}-{n}",
                shape
                    .to_possible_value()
                    .map_or_else(|| "shape".to_owned(), |v| v.get_name().to_owned())
            );
            (g.points()?, g.describe(), name)
        }
        (None, None) => return Err(option("points", "give a points file or --shape".to_owned())),
    };
    if !(0.0..=1.0).contains(&args.perturbation) {
        return Err(option(
            "perturbation",
            format!(
                "must be a fraction of the spacing in [0, 1], got {}",
                args.perturbation
            ),
        ));
    }
    let src = Source::resolve(&args.template).map_err(|e| DesignError::Template {
        file: args.template.clone(),
        reason: e.to_string(),
    })?;
    let template = Template::parse(&src.text, &src.label)?;
    let n = points.len();
    if args.channel.is_some() && args.vehicle != Some(Vehicle::Crazyflie) {
        return Err(option(
            "channel",
            "only with --vehicle crazyflie (the channel of a Crazyflie team)".to_owned(),
        ));
    }
    let slotted = match args.channel {
        Some(c) => c == Channel::Tdma,
        None => n > ALOHA_TEAM,
    };
    let template = Some(match args.vehicle {
        Some(Vehicle::Crazyflie) => template.crazyflie(n, slotted),
        Some(Vehicle::Template) | None => template,
    });
    let margin_deg = args.margin.unwrap_or_else(|| {
        template
            .as_ref()
            .map_or(crate::design::laman::DEFAULT_MARGIN_DEG, |t| {
                t.angle_margin_deg()
            })
    });
    let leader = match args.leader {
        Some(ids) => {
            let id = |k: usize| -> Result<usize, DesignError> {
                let v = ids[k];
                if (1..=n).contains(&v) {
                    Ok(v - 1)
                } else {
                    Err(option(
                        "leader",
                        format!("agent id {v} is not in 1..={n} (agent i is point i − 1)"),
                    ))
                }
            };
            Some([id(0)?, id(1)?])
        }
        None => None,
    };
    let opts = DesignOptions {
        margin_deg,
        max_triangles: args.max_triangles,
        max_neighbours: args.max_neighbours,
        leader,
    };
    if let Some(d) = args.duration {
        if !(d.is_finite() && d > 0.0) {
            return Err(option("duration", format!("must be > 0 s, got {d}")));
        }
    }
    let duration = args
        .duration
        .or_else(|| template.as_ref().and_then(Template::duration))
        .unwrap_or(100.0);
    let camera_options = |fov_deg: f64| -> Result<CameraOptions, DesignError> {
        let displacement = crate::design::initial::displacements(
            &points,
            &Perturbation {
                fraction: args.perturbation,
                scale: Scale::Spacing,
                rotate: false,
                seed: args.seed,
            },
        );
        let world = CameraWorld::preset()?;
        let largest = displacement
            .iter()
            .map(|d| d[0].hypot(d[1]))
            .fold(0.0, f64::max);
        Ok(CameraOptions {
            fov_deg,
            heading_margin_deg: match args.heading_margin_deg {
                Some(m) => m,
                None => world.heading_margin(duration),
            },
            displacement,
            range: world.range,
            clearance: match args.clearance {
                Some(c) if c.is_finite() && c >= 0.0 => c,
                Some(c) => return Err(option("clearance", format!("must be ≥ 0 m, got {c}"))),
                None => world.occlusion_radius + 2.0 * largest,
            },
            seed: args.seed,
        })
    };
    if args.fov_deg.is_none() && !args.smallest_fov {
        for (given, name) in [
            (args.heading_margin_deg.is_some(), "heading-margin-deg"),
            (args.clearance.is_some(), "clearance"),
        ] {
            if given {
                return Err(option(
                    name,
                    "applies to a camera design: give --fov-deg or --smallest-fov".to_owned(),
                ));
            }
        }
    }
    let mut smallest = None;
    let fov = if args.smallest_fov {
        let f = smallest_fov(&points, &opts, &camera_options(360.0)?)?;
        smallest = Some(f);
        Some(f)
    } else {
        args.fov_deg
    };
    let (c, camera, camera_line) = match fov {
        Some(f) if !(f.is_finite() && f > 0.0 && f <= 360.0) => {
            return Err(option(
                "fov-deg",
                format!("must be in (0, 360] degrees, got {f}"),
            ))
        }
        Some(f) if f < 360.0 => {
            let cam = camera_options(f)?;
            let d = construct_for_camera(&points, &opts, &cam)?;
            let line = format!(
                "  camera: field of view {f}°{}, heading margin {}°; widest neighbour arc {:.2}° (agent {}) of {}° allowed; attempt {}\n",
                if smallest.is_some() { " (the smallest found, bisection to 0.5°)" } else { "" },
                cam.heading_margin_deg,
                d.widest.0,
                d.widest.1 + 1,
                f - 2.0 * cam.heading_margin_deg,
                d.attempt
            );
            let view = CameraView {
                fov_deg: f,
                heading_margin_deg: cam.heading_margin_deg,
                headings: d.headings,
            };
            (d.construction, Some(view), line)
        }
        _ => (construct(&points, &opts)?, None, String::new()),
    };
    let v = args.v_star.unwrap_or([0.0, 0.0]);
    if v.iter().any(|x| !x.is_finite()) {
        return Err(option("v-star", format!("must be finite, got {v:?}")));
    }
    let command: Vec<String> = std::env::args().collect();
    let so = ScenarioOptions {
        name: args.name.clone().unwrap_or(default_name),
        description: None,
        command: command.join(" "),
        source,
        velocity_reference: v,
        duration: args.duration,
        seed: args.seed,
        leader: !args.no_leader,
        perturbation: Perturbation {
            fraction: args.perturbation,
            scale: Scale::Spacing,
            rotate: args.rotate,
            seed: args.seed,
        },
        template,
        camera,
    };
    let text = render_scenario(&points, &c, &opts, &so)?;
    let f = &c.figures;
    let figures = format!(
        "design: {} agents, {} triangles, leader edge ({}, {}), angle margin {}°\n  smallest controlled angle {:.3}° (margin from 0 and 180°), smallest interior angle {:.3}°\n  largest triangles per agent {} (capacity {}), largest neighbours per agent {} (capacity {})\n  longest edge {:.4} m, mean edge {:.4} m, overlapping triangles {}\n",
        f.agents,
        f.triangles,
        c.leader[0] + 1,
        c.leader[1] + 1,
        c.margin_deg,
        f.min_controlled_deg,
        f.min_angle_deg,
        f.max_triangles_per_agent,
        opts.max_triangles,
        f.max_neighbours_per_agent,
        opts.max_neighbours,
        f.longest_edge,
        f.mean_edge,
        f.overlapping
    ) + &camera_line;
    Ok((text, figures))
}

/// What `--fov-deg` takes from the `crazyflie-camera` world (docs/design.md argues each).
struct CameraWorld {
    /// `heading.error_deg`, `heading.spread_deg`, `heading.drift_deg_per_s`.
    error_deg: f64,
    spread_deg: f64,
    drift_deg_per_s: f64,
    /// `sensors.camera.range_m` (m).
    range: f64,
    /// `sensors.camera.occlusion_radius_m` (m).
    occlusion_radius: f64,
}

impl CameraWorld {
    fn preset() -> Result<Self, DesignError> {
        let bad = |reason: &str| DesignError::Template {
            file: "world crazyflie-camera".to_owned(),
            reason: reason.to_owned(),
        };
        let preset = crate::scenario::world::preset("crazyflie-camera")
            .ok_or_else(|| bad("no such preset"))?;
        let table: toml::Table = toml::from_str(preset.toml).map_err(|_| bad("not TOML"))?;
        let key = |path: &[&str], default: f64| {
            let mut v = table.get(path[0]);
            for k in &path[1..] {
                v = v.and_then(|x| x.get(*k));
            }
            v.and_then(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)))
                .unwrap_or(default)
        };
        Ok(Self {
            error_deg: key(&["heading", "error_deg"], 0.0),
            spread_deg: key(&["heading", "spread_deg"], 0.0),
            drift_deg_per_s: key(&["heading", "drift_deg_per_s"], 0.0),
            range: key(&["sensors", "camera", "range_m"], f64::INFINITY),
            occlusion_radius: key(&["sensors", "camera", "occlusion_radius_m"], 0.0),
        })
    }

    /// The default heading margin (degrees) for a run of `duration` seconds: error +
    /// spread + drift × duration.
    fn heading_margin(&self, duration: f64) -> f64 {
        self.error_deg + self.spread_deg + self.drift_deg_per_s * duration
    }
}

/// The smallest field of view (degrees) at which [`construct_for_camera`] finds a design:
/// bisection to 0.5° between `60° + 2·margin` (no triangle fits) and 359.5°.
fn smallest_fov(
    points: &[crate::design::Point],
    opts: &DesignOptions,
    cam: &CameraOptions,
) -> Result<f64, DesignError> {
    let works = |f: f64| {
        construct_for_camera(
            points,
            opts,
            &CameraOptions {
                fov_deg: f,
                ..cam.clone()
            },
        )
        .is_ok()
    };
    let mut hi = 359.5;
    if !works(hi) {
        // The refusal at the widest field of view says why.
        construct_for_camera(
            points,
            opts,
            &CameraOptions {
                fov_deg: hi,
                ..cam.clone()
            },
        )?;
    }
    let mut lo = 60.0 + 2.0 * cam.heading_margin_deg;
    while hi - lo > 0.5 {
        let mid = (0.5 * (lo + hi) * 2.0).round() / 2.0;
        let mid = if mid <= lo || mid >= hi {
            0.5 * (lo + hi)
        } else {
            mid
        };
        if works(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Ok(hi)
}
