//! Where a scenario's text comes from (a file, a built-in, a string) and how it is parsed:
//! TOML errors located by line, column and field, then the `--set key=value` overrides.

use super::builtin::{builtin, Builtin, BUILTINS};
use super::error::{ErrorKind, ScenarioError};
use super::schema::ScenarioFile;
use super::toml_text::{
    did_you_mean, field_at, line_col, one_line, parse_override_value, renamed_key, set_path,
};
use super::world::{self, PRESETS};
use std::path::Path;

/// A scenario's TOML text and where it came from.
#[derive(Clone, Debug)]
pub struct Source {
    /// A file path, or `builtin:<name>`.
    pub label: String,
    /// Default name (file stem or builtin name).
    pub default_name: String,
    /// The TOML text.
    pub text: String,
}

impl Source {
    /// Resolves `arg`: an existing file, else a built-in name.
    pub fn resolve(arg: &str) -> Result<Self, ScenarioError> {
        let path = Path::new(arg);
        if path.is_file() {
            return Self::from_file(path);
        }
        if let Some(b) = builtin(arg) {
            return Ok(Self::from_builtin(b));
        }
        let names: Vec<&str> = BUILTINS.iter().map(|b| b.name).collect();
        Err(ScenarioError::new(
            ErrorKind::Io,
            arg,
            "",
            format!(
                "no such file, and not a built-in scenario (built-ins: {})",
                names.join(", ")
            ),
        ))
    }

    /// Reads a scenario file.
    pub fn from_file(path: &Path) -> Result<Self, ScenarioError> {
        let label = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| {
            ScenarioError::new(ErrorKind::Io, &label, "", format!("cannot read: {e}"))
        })?;
        let default_name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scenario".to_owned());
        Ok(Self {
            label,
            default_name,
            text,
        })
    }

    /// A built-in scenario.
    pub fn from_builtin(b: &Builtin) -> Self {
        Self {
            label: format!("builtin:{}", b.name),
            default_name: b.name.to_owned(),
            text: b.text.to_owned(),
        }
    }

    /// TOML text given directly; `name` labels errors and is the default name.
    pub fn from_text(name: &str, text: &str) -> Self {
        Self {
            label: name.to_owned(),
            default_name: name.to_owned(),
            text: text.to_owned(),
        }
    }

    /// Parses the text, applies `overrides` (`key=value`, dotted keys, array indices as
    /// numbers: `agents.0.mass=2`) and deserializes the schema.
    pub fn parse(&self, overrides: &[String]) -> Result<ScenarioFile, ScenarioError> {
        // Deserialize the file itself first: errors carry its line and column.
        let file: ScenarioFile = toml::from_str(&self.text).map_err(|e| self.toml_error(&e))?;
        if overrides.is_empty() && file.world.is_none() {
            return Ok(file);
        }
        let mut value: toml::Value = toml::from_str(&self.text).map_err(|e| self.toml_error(&e))?;
        let mut parsed = file;
        for ov in overrides {
            let (key, raw) = ov.split_once('=').ok_or_else(|| {
                ScenarioError::new(
                    ErrorKind::Syntax,
                    &self.label,
                    ov,
                    "--set expects key=value (e.g. radio.loss=0.2)",
                )
            })?;
            let key = key.trim();
            let parsed_value = parse_override_value(raw.trim());
            set_path(&mut value, key, parsed_value).map_err(|reason| {
                ScenarioError::new(
                    ErrorKind::Syntax,
                    &self.label,
                    key,
                    format!("--set: {reason}"),
                )
            })?;
            parsed = value.clone().try_into().map_err(|e: toml::de::Error| {
                ScenarioError::new(
                    ErrorKind::Syntax,
                    &self.label,
                    key,
                    format!(
                        "--set {ov}: {}{}",
                        one_line(&e.to_string()),
                        suggestion(e.message())
                    ),
                )
            })?;
        }
        match parsed.world.clone() {
            Some(world) => self.with_world(value, &world),
            None => Ok(parsed),
        }
    }

    /// The scenario `value` (the file with its overrides) with the world preset `name`
    /// merged under it ([`super::world::merge_under`]).
    fn with_world(
        &self,
        mut value: toml::Value,
        name: &str,
    ) -> Result<ScenarioFile, ScenarioError> {
        let names: Vec<&str> = PRESETS.iter().map(|p| p.name).collect();
        let preset = world::preset(name).ok_or_else(|| {
            ScenarioError::new(
                ErrorKind::InvalidValue,
                &self.label,
                "world",
                format!(
                    "unknown world `{name}`; the presets are {}",
                    names.join(", ")
                ),
            )
        })?;
        let under: toml::Table = toml::from_str(preset.toml).map_err(|e| {
            ScenarioError::new(
                ErrorKind::Syntax,
                &self.label,
                "world",
                format!(
                    "the preset `{name}` does not parse: {}",
                    one_line(e.message())
                ),
            )
        })?;
        if let toml::Value::Table(t) = &mut value {
            world::merge_under(t, &under);
        }
        value.try_into().map_err(|e: toml::de::Error| {
            ScenarioError::new(
                ErrorKind::Syntax,
                &self.label,
                "world",
                format!(
                    "world = \"{name}\": {}{}",
                    one_line(&e.to_string()),
                    suggestion(e.message())
                ),
            )
        })
    }

    fn toml_error(&self, e: &toml::de::Error) -> ScenarioError {
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
        ScenarioError::new(
            ErrorKind::Syntax,
            &self.label,
            &field,
            format!(
                "{}{location}{}",
                one_line(e.message()),
                suggestion(e.message())
            ),
        )
    }
}

/// `"; did you mean `loss`?"` for an unknown field near a known one, or what became of a
/// renamed key, else empty.
fn suggestion(message: &str) -> String {
    if let Some(renamed) = renamed_key(message) {
        return format!("; {renamed}");
    }
    did_you_mean(message).map_or_else(String::new, |c| format!("; did you mean `{c}`?"))
}
