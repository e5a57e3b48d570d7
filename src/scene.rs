//! Scene profiles (`profiles/*.toml`): atmosphere, ground, emission, wind,
//! physics switches, camera and render settings in one file. Loading parses
//! the TOML (errors name the file, line and column), validates every part and
//! builds the environment.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::atmosphere::AtmosphereSpec;
use crate::error::{Error, Result};
use crate::physics::{EmissionConfig, GroundConfig, PhysicsConfig, WindConfig};
use crate::render::{CameraConfig, RenderConfig};

/// Name of the scene embedded in the binary and used when none is given.
pub const DEFAULT_SCENE_NAME: &str = "fair_weather";
/// The embedded default scene: fair-weather cumulus under an inversion.
pub const DEFAULT_SCENE_TOML: &str = include_str!("../profiles/fair_weather.toml");

/// A scene profile as written in TOML.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SceneProfile {
    /// Short name shown in the window title and reports.
    pub name: String,
    /// One paragraph on the weather situation this scene shows.
    pub description: String,
    /// Environment profile: inline points or a sounding file.
    pub atmosphere: AtmosphereSpec,
    /// Domain size and the heat/humidity map of the ground.
    pub ground: GroundConfig,
    /// How the ground emits parcels.
    pub emission: EmissionConfig,
    /// Wind profile.
    pub wind: WindConfig,
    /// Physics switches, constants and time stepping.
    pub physics: PhysicsConfig,
    /// Camera placement.
    pub camera: CameraConfig,
    /// Render settings and feature switches.
    pub render: RenderConfig,
}

/// Byte offset → 1-based (line, column).
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before
        .rsplit('\n')
        .next()
        .map(|s| s.chars().count())
        .unwrap_or(0)
        + 1;
    (line, col)
}

impl SceneProfile {
    /// Parses a profile from TOML text; `path` is used in error messages.
    pub fn from_toml(text: &str, path: &Path) -> Result<Self> {
        toml::from_str(text).map_err(|e| {
            let (line, column) = e.span().map(|s| line_col(text, s.start)).unwrap_or((0, 0));
            Error::parse(path, line, column, e.message().to_string())
        })
    }

    /// Reads and parses a profile file.
    pub fn load(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        let text = String::from_utf8(bytes).map_err(|e| {
            Error::parse(
                path,
                0,
                0,
                format!(
                    "not UTF-8 text (byte {}): a profile is a TOML file",
                    e.utf8_error().valid_up_to()
                ),
            )
        })?;
        Self::from_toml(&text, path)
    }

    /// The embedded default scene.
    pub fn embedded_default() -> Self {
        Self::from_toml(
            DEFAULT_SCENE_TOML,
            Path::new("<embedded fair_weather.toml>"),
        )
        .expect("the embedded default profile is tested to parse")
    }

    /// Serialises the profile back to TOML (used by the window's "save").
    pub fn to_toml(&self) -> Result<String> {
        toml::to_string_pretty(self).map_err(|e| Error::invalid("scene", &self.name, e.to_string()))
    }
}

/// Where a scene came from, for resolving relative paths (sounding files).
#[derive(Debug, Clone, PartialEq)]
pub enum SceneSource {
    Embedded,
    File(PathBuf),
}

impl SceneSource {
    /// Directory against which relative paths in the profile are resolved.
    pub fn base_dir(&self) -> PathBuf {
        match self {
            SceneSource::Embedded => PathBuf::from("."),
            SceneSource::File(p) => p.parent().map(Path::to_path_buf).unwrap_or_default(),
        }
    }
}

/// Loads `path`, or the embedded default when `None`.
pub fn load_scene(path: Option<&Path>) -> Result<(SceneProfile, SceneSource)> {
    match path {
        None => Ok((SceneProfile::embedded_default(), SceneSource::Embedded)),
        Some(p) => Ok((SceneProfile::load(p)?, SceneSource::File(p.to_path_buf()))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_default_parses() {
        let s = SceneProfile::embedded_default();
        assert!(!s.name.is_empty());
    }

    #[test]
    fn toml_errors_name_line_and_column() {
        let err =
            SceneProfile::from_toml("name = \"x\"\nbogus = 3\n", Path::new("p.toml")).unwrap_err();
        let msg = err.to_string();
        assert!(msg.starts_with("p.toml:2:1:"), "{msg}");
    }
}
