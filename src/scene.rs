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
    /// Sprite clouds authored from boxes (Wang 2003, `sprites` method).
    pub sprite_clouds: Vec<crate::sprites_model::SpriteCloudSpec>,
    /// Layers of preset cloud types expanded into sprite clouds (Wang 2003).
    pub layers: Vec<crate::sprites_model::LayerSpec>,
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

    /// Reads, parses and validates a profile file. Errors name the file and,
    /// for a bad value, the line and column of its key.
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
        let profile = Self::from_toml(&text, path)?;
        profile.validate().map_err(|e| locate(e, &text, path))?;
        Ok(profile)
    }

    /// Checks every table against what the model accepts: the atmosphere
    /// points, physics, ground, emission, wind, render and camera.
    pub fn validate(&self) -> Result<()> {
        self.atmosphere.validate()?;
        crate::physics::WorldConfig::from_scene(self).validate()?;
        self.render.validate()?;
        crate::sprites_model::validate_scene(&self.sprite_clouds, &self.layers)?;
        self.camera.validate()
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

/// Turns a parameter error into one that names the profile file and the
/// line and column where the parameter is set (or just the file when the
/// value comes from a default).
fn locate(e: Error, text: &str, path: &Path) -> Error {
    match e {
        Error::InvalidParameter {
            name,
            value,
            allowed,
        } => {
            let (line, column) = locate_key(text, &name).unwrap_or((0, 0));
            Error::parse(
                path,
                line,
                column,
                format!("invalid {name} = {value}: {allowed}"),
            )
        }
        other => other,
    }
}

/// 1-based (line, column) of the key a dotted parameter name
/// ("physics.stiffness", "wind.aloft_m_s[0]", "atmosphere.points[1].t_c")
/// sets in a profile's TOML text, when it is written there as `key = value`
/// under its `[table]` or `[[array.of.tables]]` header.
pub fn locate_key(text: &str, name: &str) -> Option<(usize, usize)> {
    let (table, key) = name.rsplit_once('.')?;
    let key = key.split('[').next()?;
    // "atmosphere.points[1]" → the second [[atmosphere.points]] table.
    let (table, index) = match table.split_once('[') {
        Some((t, rest)) => (t, Some(rest.trim_end_matches(']').parse::<usize>().ok()?)),
        None => (table, None),
    };
    let mut inside = false;
    let mut seen = 0;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if let Some(h) = t.strip_prefix("[[") {
            let h = h.split("]]").next().unwrap_or("").trim();
            inside = h == table && index == Some(seen);
            if h == table {
                seen += 1;
            }
        } else if let Some(h) = t.strip_prefix('[') {
            inside = index.is_none() && h.split(']').next().unwrap_or("").trim() == table;
        } else if inside
            && let Some((k, _)) = t.split_once('=')
            && k.trim() == key
        {
            return Some((i + 1, line.len() - line.trim_start().len() + 1));
        }
    }
    None
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
    fn bad_values_name_the_line_and_column_of_their_key() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.toml");
        std::fs::write(
            &path,
            "name = \"x\"\n\n[physics]\nmixing = true\n  stiffness = -3.0\n",
        )
        .unwrap();
        let msg = SceneProfile::load(&path).unwrap_err().to_string();
        assert!(
            msg.starts_with(&format!(
                "{}:5:3: invalid physics.stiffness",
                path.display()
            )),
            "{msg}"
        );
    }

    #[test]
    fn every_shipped_profile_validates() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles");
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "toml") {
                SceneProfile::load(&p).unwrap_or_else(|e| panic!("{e}"));
            }
        }
        SceneProfile::embedded_default().validate().unwrap();
    }

    #[test]
    fn toml_errors_name_line_and_column() {
        let err =
            SceneProfile::from_toml("name = \"x\"\nbogus = 3\n", Path::new("p.toml")).unwrap_err();
        let msg = err.to_string();
        assert!(msg.starts_with("p.toml:2:1:"), "{msg}");
    }
}
