//! Loading a scene: read or parse the TOML, then validate it into a [`Scenario`] (every error
//! names the file and the field).

use super::file::ScenarioFile;
use super::{parse, validate, Scenario};
use crate::error::Result;
use std::path::Path;

impl Scenario {
    /// Loads and validates a scenario file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let (raw, _) = parse::read_file(path)?;
        validate::validate(raw, path)
    }

    /// Parses and validates scenario TOML; `label` names it in errors and gives the default name.
    pub fn from_toml_str(text: &str, label: impl AsRef<Path>) -> Result<Self> {
        let label = label.as_ref();
        validate::validate(parse::parse_toml(text, label)?, label)
    }

    /// Validates an in-memory [`ScenarioFile`] (a scene built in code).
    pub fn from_spec(raw: ScenarioFile) -> Result<Self> {
        validate::validate(raw, Path::new("<memory>"))
    }
}
