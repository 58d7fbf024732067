//! Where models come from: the scenario file's TOML schema and defaults
//! (`docs/scenarios.md`), the built-in scenarios, loading with `--set key=value`
//! overrides, validation into a [`Model`], and the generated strip formation.
//!
//! Above [`crate::model`] only: the engine never sees a scenario file, only the model
//! made from it (`docs/architecture.md`).

mod builtin;
pub mod error;
pub mod faults;
pub mod policy;
mod schema;
mod settings;
mod source;
pub mod strip;
pub mod toml_text;
mod validate;
pub mod world;

pub use builtin::{builtin, Builtin, BUILTINS};
pub use error::{ErrorKind, ScenarioError, ScenarioErrors};
pub use schema::{
    AgentDefaults, AgentId, AgentSpec, AngleSpec, Diagonal, GainsSpec, LeaderSpec, ScenarioFile,
    ScheduleSpec, StepSpec, TargetSpec, TriangleSpec,
};
pub use settings::{BearingSource, PositionsSpec};
pub use settings::{CameraSpec, ChannelSpec, ControllerSpec, Integration, RadioSpec, SensorSpec};
pub use source::Source;
pub use strip::strip_model;
pub use validate::{check_model, validate, validate_text};
pub use world::{plant_spec, ClockSpec, HeadingSpec, PlantSpec, PlantTable, WindSpec, PRESETS};

use crate::model::Model;

/// Loads, parses and validates a scenario (a file path or a built-in name) with
/// `key=value` overrides.
pub fn load(arg: &str, overrides: &[String]) -> Result<Model, ScenarioErrors> {
    let source = Source::resolve(arg)?;
    let file = source.parse(overrides)?;
    validate_text(&file, &source.label, &source.default_name, &source.text)
}
