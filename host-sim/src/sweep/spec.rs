//! The sweep file's TOML schema (`docs/sweeps.md`) and its parsing, with errors located
//! by line, column and field as for scenario files.

use super::error::{SweepError, SCHEMA, UNREADABLE};
use crate::scenario::toml_text::{field_at, line_col, one_line};
use serde::Deserialize;
use std::path::Path;

/// A whole sweep file.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepFile {
    /// Name (default: the file stem).
    #[serde(default)]
    pub name: Option<String>,
    /// Free text.
    #[serde(default)]
    pub description: Option<String>,
    /// The sweep seed: every run's seed derives from it (`docs/sweeps.md`).
    #[serde(default = "one")]
    pub seed: u64,
    /// Runs per point.
    #[serde(default = "one")]
    pub runs: u64,
    /// Common random numbers: run `r` has the same seed at every point.
    #[serde(default)]
    pub common_seeds: bool,
    /// How points are chosen.
    #[serde(default)]
    pub sampling: Sampling,
    /// Number of points for `sampling = "random"`.
    #[serde(default)]
    pub points: Option<u64>,
    /// The scenario every run starts from.
    pub base: BaseSpec,
    /// Perturbation of the initial shape (enables the `perturbation` axis).
    #[serde(default)]
    pub perturbation: Option<PerturbationSpec>,
    /// The axes (none: one point).
    #[serde(default)]
    pub axes: Vec<AxisSpec>,
}

fn one() -> u64 {
    1
}

/// Grid (every combination) or random points.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sampling {
    /// Every combination of the axes' values, the first axis slowest.
    #[default]
    Grid,
    /// `points` points, each axis drawn independently (a value from `values`, or uniform
    /// in `[from, to]`).
    Random,
}

impl Sampling {
    /// The name in the file.
    pub fn as_str(self) -> &'static str {
        match self {
            Sampling::Grid => "grid",
            Sampling::Random => "random",
        }
    }
}

/// `[base]`: the scenario every run starts from.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaseSpec {
    /// A scenario file (relative to the sweep file's folder) or a built-in name.
    #[serde(default)]
    pub scenario: Option<String>,
    /// Reserved: a `host-sim design` generator as the base (not available yet).
    #[serde(default)]
    pub design: Option<toml::Value>,
    /// Overrides applied to every run, as `--set` (`["duration=60"]`).
    #[serde(default)]
    pub set: Vec<String>,
}

/// `[perturbation]`: random initial shapes around a reference.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PerturbationSpec {
    /// Largest displacement as a fraction of the reference's size (RMS distance from its
    /// centroid); the `perturbation` axis overrides it.
    #[serde(default)]
    pub fraction: f64,
    /// Rotate the whole reference by a random angle about its centroid first.
    #[serde(default = "yes")]
    pub rotate: bool,
    /// Reference positions in agent order (default: the scenario's initial positions).
    #[serde(default)]
    pub shape: Option<Vec<[f64; 2]>>,
}

fn yes() -> bool {
    true
}

/// One `[[axes]]` entry: a scenario field (dotted key as `--set`) or `perturbation`, and
/// its values: a list, or a range.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisSpec {
    /// Dotted key (`radio.loss`, `agents.0.mass`) or `perturbation`.
    pub key: String,
    /// The values (any TOML value the field takes).
    #[serde(default)]
    pub values: Option<Vec<toml::Value>>,
    /// Range start (with `to`).
    #[serde(default)]
    pub from: Option<f64>,
    /// Range end (inclusive).
    #[serde(default)]
    pub to: Option<f64>,
    /// Grid: number of evenly spaced values from `from` to `to` (≥ 2).
    #[serde(default)]
    pub steps: Option<u64>,
}

/// A sweep's text and where it came from.
#[derive(Clone, Debug)]
pub struct SweepSource {
    /// The file path or `builtin:<name>`.
    pub label: String,
    /// Default name (file stem or built-in name).
    pub default_name: String,
    /// The folder relative scenario paths are resolved in (none for a built-in).
    pub dir: Option<std::path::PathBuf>,
    /// The TOML text.
    pub text: String,
}

impl SweepSource {
    /// An existing file, else a built-in sweep name (`host-sim sweep --list`).
    pub fn resolve(arg: &str) -> Result<Self, SweepError> {
        let path = Path::new(arg);
        if path.is_file() {
            let text = std::fs::read_to_string(path)
                .map_err(|e| SweepError::new(UNREADABLE, arg, "", format!("cannot read: {e}")))?;
            return Ok(Self {
                label: arg.to_owned(),
                default_name: path
                    .file_stem()
                    .map_or("sweep".to_owned(), |s| s.to_string_lossy().into_owned()),
                dir: path.parent().map(Path::to_path_buf),
                text,
            });
        }
        if let Some(b) = super::builtin::builtin_sweep(arg) {
            return Ok(Self {
                label: format!("builtin:{}", b.name),
                default_name: b.name.to_owned(),
                dir: None,
                text: b.text.to_owned(),
            });
        }
        let names: Vec<&str> = super::builtin::BUILTIN_SWEEPS
            .iter()
            .map(|b| b.name)
            .collect();
        Err(SweepError::new(
            UNREADABLE,
            arg,
            "",
            format!(
                "no such file, and not a built-in sweep (built-ins: {})",
                names.join(", ")
            ),
        ))
    }

    /// TOML text given directly (`label` names it in errors).
    pub fn from_text(label: &str, text: &str) -> Self {
        Self {
            label: label.to_owned(),
            default_name: label.to_owned(),
            dir: None,
            text: text.to_owned(),
        }
    }

    /// Deserializes the schema; a TOML or schema error names its line, column and field.
    pub fn parse(&self) -> Result<SweepFile, SweepError> {
        toml::from_str(&self.text).map_err(|e: toml::de::Error| {
            let (field, location) = match e.span() {
                Some(span) => {
                    let (line, col) = line_col(&self.text, span.start);
                    (
                        field_at(&self.text, span.start),
                        format!(" (line {line}, column {col})"),
                    )
                }
                None => (String::new(), String::new()),
            };
            SweepError::new(
                SCHEMA,
                &self.label,
                &field,
                format!("{}{location}", one_line(e.message())),
            )
        })
    }
}
