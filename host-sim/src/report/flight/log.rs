//! Reading the swarm tool's flight log (`crazyflie-app/tools/swarm.py fly|step --log`,
//! docs/crazyflie.md "The flight log"): one row per log packet of each drone, grouped
//! here per agent in file order.

use std::path::{Path, PathBuf};

/// Which column gives a row's time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Clock {
    /// `t_s`: the host's clock from the tool's start (the drones' timestamps aligned to
    /// it). Right for real drones and for `host-sim serve --speed 1`.
    #[default]
    #[value(name = "t_s")]
    Host,
    /// `drone_ms / 1000`, less its smallest value in the log: the drones' own clock.
    /// Right for served drones at any `--speed` (they share serve's one clock); real
    /// drones' clocks start at their own boot.
    #[value(name = "drone_ms")]
    Drone,
}

/// One logged packet of one drone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Time on the chosen [`Clock`] (s).
    pub t: f64,
    /// Position and velocity (m, m/s, world frame).
    pub x: f64,
    /// See [`Self::x`].
    pub y: f64,
    /// Height (m; NaN when the column is absent).
    pub z: f64,
    /// See [`Self::x`].
    pub vx: f64,
    /// See [`Self::x`].
    pub vy: f64,
    /// The velocity setpoint along x (m/s; NaN before its first packet).
    pub setpoint_vx: f64,
    /// `formation.state` (0 idle, 1 formation, 2 hold, 3 landing), if logged.
    pub state: Option<u8>,
    /// `formation.fault`, if logged.
    pub fault: Option<u8>,
    /// `formation.holdTicks`, if logged.
    pub hold_ticks: Option<u64>,
    /// `formation.landings`, if logged.
    pub landings: Option<u64>,
}

/// One drone's rows, in time order.
#[derive(Clone, Debug, PartialEq)]
pub struct Track {
    /// The scenario's agent id, as logged.
    pub agent: String,
    /// Its samples.
    pub samples: Vec<Sample>,
}

/// A flight log.
#[derive(Clone, Debug, PartialEq)]
pub struct FlightLog {
    /// Where it was read from.
    pub path: PathBuf,
    /// The drones, in order of first appearance.
    pub tracks: Vec<Track>,
}

/// Why a flight log (or a file held against it) cannot be used: file, line or column,
/// and reason.
#[derive(Debug, thiserror::Error)]
pub enum FlightError {
    /// The file cannot be read.
    #[error("{}: cannot read: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// An output cannot be written.
    #[error("{}: cannot write: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A required column is missing.
    #[error("{}: no column `{column}` ({what})", path.display())]
    MissingColumn {
        /// The file.
        path: PathBuf,
        /// The column.
        column: String,
        /// What the file should be.
        what: &'static str,
    },
    /// A value cannot be read.
    #[error("{}: line {line}, column `{column}`: {value:?}: {reason}", path.display())]
    Value {
        /// The file.
        path: PathBuf,
        /// Line number (1 = the header).
        line: u64,
        /// The column.
        column: String,
        /// The text found.
        value: String,
        /// Why it is refused.
        reason: String,
    },
    /// The content does not fit (no rows, an agent missing, no formation start, …).
    #[error("{}: {reason}", path.display())]
    Content {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
}

/// What the flight log's header must hold.
pub(super) const FLIGHT_LOG: &str =
    "a flight log of crazyflie-app/tools/swarm.py, docs/crazyflie.md \"The flight log\"";

/// A CSV reader of `path`, its header (trimmed) and a column finder.
pub(super) fn open_csv(
    path: &Path,
) -> Result<(csv::Reader<std::fs::File>, Vec<String>), FlightError> {
    let io = |source| FlightError::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .from_reader(file);
    let header = reader
        .headers()
        .map_err(|e| FlightError::Content {
            path: path.to_path_buf(),
            reason: format!("malformed CSV header: {e}"),
        })?
        .iter()
        .map(|s| s.trim().to_owned())
        .collect();
    Ok((reader, header))
}

/// The index of `column` in `header`, or the error naming it.
pub(super) fn column(
    path: &Path,
    header: &[String],
    column: &str,
    what: &'static str,
) -> Result<usize, FlightError> {
    header
        .iter()
        .position(|h| h == column)
        .ok_or_else(|| FlightError::MissingColumn {
            path: path.to_path_buf(),
            column: column.to_owned(),
            what,
        })
}

/// Every record of `reader` (opened by [`open_csv`] on `path`, with `header`) as
/// [`Cells`] numbered by its line, in order, to `each`; the first error ends it (a
/// malformed record is one, naming its line).
pub(super) fn for_each_row(
    path: &Path,
    reader: &mut csv::Reader<std::fs::File>,
    header: &[String],
    mut each: impl FnMut(&Cells<'_>) -> Result<(), FlightError>,
) -> Result<(), FlightError> {
    let mut record = csv::StringRecord::new();
    let mut line = 1u64;
    loop {
        line += 1;
        match reader.read_record(&mut record) {
            Ok(false) => return Ok(()),
            Ok(true) => {}
            Err(e) => {
                return Err(FlightError::Content {
                    path: path.to_path_buf(),
                    reason: format!("line {line}: malformed CSV: {e}"),
                })
            }
        }
        each(&Cells {
            path,
            header,
            record: &record,
            line,
        })?;
    }
}

/// Reads the cells of one CSV record by column, naming line and column on error.
pub(super) struct Cells<'a> {
    pub(super) path: &'a Path,
    pub(super) header: &'a [String],
    pub(super) record: &'a csv::StringRecord,
    pub(super) line: u64,
}

impl Cells<'_> {
    fn text(&self, col: usize) -> &str {
        self.record.get(col).unwrap_or("").trim()
    }

    fn bad(&self, col: usize, reason: &str) -> FlightError {
        FlightError::Value {
            path: self.path.to_path_buf(),
            line: self.line,
            column: self.header.get(col).cloned().unwrap_or_default(),
            value: self.text(col).to_owned(),
            reason: reason.to_owned(),
        }
    }

    /// A finite number (required).
    pub(super) fn number(&self, col: usize) -> Result<f64, FlightError> {
        match self.text(col).parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(self.bad(col, "not a finite number")),
        }
    }

    /// A finite number, or NaN when empty or the column is absent.
    pub(super) fn optional(&self, col: Option<usize>) -> Result<f64, FlightError> {
        match col {
            Some(c) if !self.text(c).is_empty() => self.number(c),
            _ => Ok(f64::NAN),
        }
    }

    /// A whole number, `None` when empty or the column is absent.
    fn count(&self, col: Option<usize>) -> Result<Option<u64>, FlightError> {
        match col {
            Some(c) if !self.text(c).is_empty() => self
                .text(c)
                .parse::<u64>()
                .map(Some)
                .map_err(|_| self.bad(c, "not a whole number ≥ 0")),
            _ => Ok(None),
        }
    }

    fn byte(&self, col: Option<usize>) -> Result<Option<u8>, FlightError> {
        match self.count(col)? {
            None => Ok(None),
            Some(n) => u8::try_from(n)
                .map(Some)
                .map_err(|_| self.bad(col.unwrap_or(0), "above 255")),
        }
    }
}

impl FlightLog {
    /// Reads `path` with times on `clock`.
    ///
    /// # Errors
    ///
    /// A [`FlightError`] naming the file, and the line and column of a bad value.
    pub fn read(path: &Path, clock: Clock) -> Result<Self, FlightError> {
        let (mut reader, header) = open_csv(path)?;
        let need = |c: &str| column(path, &header, c, FLIGHT_LOG);
        let opt = |c: &str| header.iter().position(|h| h == c);
        let time = need(match clock {
            Clock::Host => "t_s",
            Clock::Drone => "drone_ms",
        })?;
        let agent = need("agent")?;
        let [x, y, vx, vy] = ["x", "y", "vx", "vy"].map(need);
        let (x, y, vx, vy) = (x?, y?, vx?, vy?);
        let (z, spx) = (opt("z"), opt("setpoint_vx"));
        let (state, fault) = (opt("state"), opt("fault"));
        let (hold, landings) = (opt("hold_ticks"), opt("landings"));
        let mut tracks: Vec<Track> = Vec::new();
        for_each_row(path, &mut reader, &header, |c| {
            let id = c.text(agent).to_owned();
            if id.is_empty() {
                return Err(c.bad(agent, "no agent id"));
            }
            let mut t = c.number(time)?;
            if clock == Clock::Drone {
                t /= 1000.0;
            }
            let s = Sample {
                t,
                x: c.number(x)?,
                y: c.number(y)?,
                z: c.optional(z)?,
                vx: c.number(vx)?,
                vy: c.number(vy)?,
                setpoint_vx: c.optional(spx)?,
                state: c.byte(state)?,
                fault: c.byte(fault)?,
                hold_ticks: c.count(hold)?,
                landings: c.count(landings)?,
            };
            match tracks.iter_mut().find(|k| k.agent == id) {
                Some(k) => k.samples.push(s),
                None => tracks.push(Track {
                    agent: id,
                    samples: vec![s],
                }),
            }
            Ok(())
        })?;
        if tracks.is_empty() {
            return Err(FlightError::Content {
                path: path.to_path_buf(),
                reason: "no rows".to_owned(),
            });
        }
        if clock == Clock::Drone {
            let t0 = tracks
                .iter()
                .flat_map(|k| k.samples.iter().map(|s| s.t))
                .fold(f64::INFINITY, f64::min);
            for s in tracks.iter_mut().flat_map(|k| k.samples.iter_mut()) {
                s.t -= t0;
            }
        }
        for k in &mut tracks {
            k.samples.sort_by(|a, b| a.t.total_cmp(&b.t));
        }
        Ok(Self {
            path: path.to_path_buf(),
            tracks,
        })
    }

    /// The track of `agent`.
    pub fn track(&self, agent: &str) -> Option<&Track> {
        self.tracks.iter().find(|k| k.agent == agent)
    }

    /// The first time any drone logged state 1 (formation): the run's `t = 0`.
    pub fn formation_start(&self) -> Option<f64> {
        self.tracks
            .iter()
            .filter_map(|k| k.samples.iter().find(|s| s.state == Some(1)).map(|s| s.t))
            .reduce(f64::min)
    }

    pub(super) fn content(&self, reason: String) -> FlightError {
        FlightError::Content {
            path: self.path.clone(),
            reason,
        }
    }
}
