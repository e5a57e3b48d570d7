//! Scene profiles (`profiles/*.toml`): atmosphere, ground, emission, wind,
//! physics switches, the sun's clock, the start time, camera and render
//! settings and the authored clouds (ellipsoids, sprite clouds, layers) in
//! one file. Loading parses the TOML (errors name the file, line and
//! column) and validates every part; the profile then gives the models
//! their inputs ([`SceneProfile::world_config`],
//! [`SceneProfile::build_sprite_clouds`]), and its atmosphere builds the
//! environment. [`set`] applies `--set` overrides before validation.

pub mod set;

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::atmosphere::{AtmosphereSpec, Environment};
use crate::config::{CameraConfig, RenderConfig};
use crate::error::{Error, Result, line_col};
use crate::methods::slices::model::{Ellipsoid, ParticleConfig};
use crate::physics::{EmissionConfig, GroundConfig, PhysicsConfig, WindConfig, WorldConfig};
use crate::sky::Sun;
use crate::sun::{SolarClock, SunConfig};

/// Name of the scene embedded in the binary and used when none is given.
pub const DEFAULT_SCENE_NAME: &str = "fair_weather";
/// The embedded default scene: fair-weather cumulus under an inversion.
pub const DEFAULT_SCENE_TOML: &str = include_str!("../../profiles/fair_weather.toml");

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
    /// Wind profile (`[wind]`). Present, it drives the drag even when calm;
    /// absent, the sounding's own wind does (DRCT/SKNT), else the air is calm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wind: Option<WindConfig>,
    /// Physics switches, constants and time stepping.
    pub physics: PhysicsConfig,
    /// Camera placement.
    pub camera: CameraConfig,
    /// Render settings and feature switches.
    pub render: RenderConfig,
    /// Authored implicit ellipsoids (Schpok 2003), with their keyframes.
    pub ellipsoids: Vec<Ellipsoid>,
    /// Particle dynamics of the ellipsoids (the uniform wind).
    pub particles: ParticleConfig,
    /// Place and clock of the sun; absent = the sun pinned by `[render]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sun: Option<SunConfig>,
    /// Where a run starts.
    pub simulation: SimulationConfig,
    /// Sprite clouds authored from boxes (Wang 2003, `sprites` method).
    pub sprite_clouds: Vec<crate::methods::sprites::model::SpriteCloudSpec>,
    /// Layers of preset cloud types expanded into sprite clouds (Wang 2003).
    pub layers: Vec<crate::methods::sprites::model::LayerSpec>,
}

/// Simulated time a scene opens at when nothing else says. The shipped
/// scenes' first cloud forms after 220–530 s and by 1800 s each shows a
/// developed field (fair_weather 131 condensed parcels, towering_cumulus
/// 829, high_based 184; `cumulus simulate`, seed 1, 2-s frames). units: s
pub const DEFAULT_START_S: f64 = 1800.0;

/// The `[simulation]` table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimulationConfig {
    /// Simulated time the window opens at (pre-simulated before its first
    /// frame) and `cumulus render`'s default `--time`: late enough that the
    /// clouds have formed. units: s
    pub start_s: f64,
}

impl Default for SimulationConfig {
    fn default() -> Self {
        Self {
            start_s: DEFAULT_START_S,
        }
    }
}

impl SimulationConfig {
    /// Checks `start_s`; the error names the key and the allowed range.
    pub fn validate(&self) -> Result<()> {
        if self.start_s.is_finite() && (0.0..=MAX_START_S).contains(&self.start_s) {
            Ok(())
        } else {
            Err(Error::invalid(
                "simulation.start_s",
                self.start_s,
                format!("a number of seconds from 0 to {MAX_START_S} (one day)"),
            ))
        }
    }
}

/// Latest start time: a day of simulated time. units: s
pub const MAX_START_S: f64 = 86_400.0;

/// The sun the renderer draws at simulated time `t_s`: from `clock` when the
/// scene has a `[sun]` table, else pinned by `render`. The second value says
/// whether the sun was below [`crate::sun::MIN_LIGHT_ELEVATION_DEG`], so the
/// light's direction was held there (front ends show it).
pub fn render_sun(clock: Option<&SolarClock>, render: &RenderConfig, t_s: f64) -> (Sun, bool) {
    match clock {
        None => (render.sun(), false),
        Some(c) => {
            let (direction, strength, held) = crate::sun::light(c.position(t_s));
            let sun = Sun::from_sky(direction, strength, render.visibility_km);
            (sun, held)
        }
    }
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
        let text = read_text(path)?;
        let profile = Self::from_toml(&text, path)?;
        profile.validate().map_err(|e| locate(e, &text, path))?;
        require_atmosphere(&text, path)?;
        Ok(profile)
    }

    /// Checks every table against what the model accepts: the atmosphere
    /// points, physics, ground, emission, wind, render and camera.
    pub fn validate(&self) -> Result<()> {
        self.atmosphere.validate()?;
        self.world_tables().validate()?;
        self.render.validate()?;
        self.render.slices.validate()?;
        crate::methods::slices::model::ellipsoid::validate_all(&self.ellipsoids)?;
        self.particles.validate()?;
        if let Some(sun) = &self.sun {
            sun.validate()?;
        }
        self.simulation.validate()?;
        if self.ground.follow_terrain && !self.render.terrain.enabled {
            return Err(Error::invalid(
                "ground.follow_terrain",
                true,
                "false unless [render.terrain] has enabled = true (the parcels leave the drawn terrain)",
            ));
        }
        crate::methods::sprites::model::validate_scene(&self.sprite_clouds, &self.layers)?;
        self.camera.validate()
    }

    /// Builds the scene's atmosphere ([`AtmosphereSpec::build`], a relative
    /// sounding against `source`'s directory), for every command and the
    /// window alike. Its errors name the profile: a sounding file that
    /// cannot be read or parsed at the line of the profile's `sounding`
    /// key, before the sounding's own message (its path, line, cause).
    pub fn build_atmosphere(&self, source: &SceneSource) -> Result<Environment> {
        self.atmosphere.build(&source.base_dir()).map_err(|e| {
            let text = match source {
                SceneSource::File(p) => std::fs::read_to_string(p).unwrap_or_default(),
                SceneSource::Embedded => DEFAULT_SCENE_TOML.to_string(),
            };
            let profile = PathBuf::from(source.name());
            match &self.atmosphere.sounding {
                Some(sounding) if !matches!(e, Error::InvalidParameter { .. }) => {
                    let (line, column) = locate_key(&text, "atmosphere.sounding").unwrap_or((0, 0));
                    Error::parse(
                        profile,
                        line,
                        column,
                        format!("sounding = \"{}\": {}", sounding.display(), with_causes(&e)),
                    )
                }
                _ => locate(e, &text, &profile),
            }
        })
    }

    /// The sun's clock, when the scene has a `[sun]` table.
    pub fn clock(&self) -> Result<Option<SolarClock>> {
        self.sun.as_ref().map(SunConfig::clock).transpose()
    }

    /// The physics tables of this scene (physics, ground, emission, wind),
    /// the emission clocked by the `[sun]` table when there is one; the
    /// ground's terrain is read by [`SceneProfile::world_config`].
    pub fn world_tables(&self) -> WorldConfig {
        let mut emission = self.emission.clone();
        // One clock: with a [sun] table the ground heats by its solar time.
        if let Some(Ok(clock)) = self.sun.as_ref().map(|s| s.clock()) {
            emission.start_hour = clock.solar_time_h(0.0);
        }
        WorldConfig {
            physics: self.physics.clone(),
            ground: self.ground.clone(),
            emission,
            wind: self.wind.clone(),
        }
    }

    /// Every sprite cloud of this scene: its `[[sprite_clouds]]`, then its
    /// `[[layers]]` expanded, in file order (deterministic).
    pub fn build_sprite_clouds(&self) -> Vec<crate::methods::sprites::model::SpriteCloud> {
        crate::methods::sprites::model::build_clouds(&self.sprite_clouds, &self.layers)
    }

    /// Everything the physics needs, with the ground's terrain read (a
    /// heightmap relative to `base_dir`) when `[ground] follow_terrain`.
    pub fn world_config(&self, base_dir: &Path) -> Result<WorldConfig> {
        let mut cfg = self.world_tables();
        if self.ground.follow_terrain {
            let mut render = self.render.clone();
            render.resolve_paths(base_dir);
            cfg.ground.terrain = crate::landscape::terrain::heightfield(&render.terrain)?;
            if let Some(clock) = self.clock()? {
                // Solar noon of the first day; a sun held 5° up in polar night.
                let noon_s = (12.0 - clock.solar_time_h(0.0)) * 3600.0;
                let p = clock.position(noon_s);
                let d = crate::sun::direction(p.azimuth_deg, p.elevation_deg.max(5.0));
                cfg.ground.midday_sun = d.as_dvec3().to_array();
            }
        }
        Ok(cfg)
    }

    /// The embedded default scene.
    pub fn embedded_default() -> Self {
        Self::from_toml(DEFAULT_SCENE_TOML, Path::new(EMBEDDED_SCENE_LABEL))
            .expect("the embedded default profile is tested to parse")
    }

    /// Serialises the profile back to TOML (used by the window's "save").
    pub fn to_toml(&self) -> Result<String> {
        toml::to_string_pretty(self).map_err(|e| Error::invalid("scene", &self.name, e.to_string()))
    }
}

/// `e` and its causes, as `{:#}` prints them: "path: No such file …".
fn with_causes(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        text.push_str(&format!(": {c}"));
        cause = c.source();
    }
    text
}

/// Reads a profile file as UTF-8 text.
pub(crate) fn read_text(path: &Path) -> Result<String> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    String::from_utf8(bytes).map_err(|e| {
        Error::parse(
            path,
            0,
            0,
            format!(
                "not UTF-8 text (byte {}): a profile is a TOML file",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

/// A profile file must say what its atmosphere is: one without an
/// `[atmosphere]` table (an empty file, say) would otherwise run on the
/// built-in default without a word. (Parsed TOML text is given.)
fn require_atmosphere(text: &str, path: &Path) -> Result<()> {
    let table: toml::Table = toml::from_str(text).unwrap_or_default();
    if table.contains_key("atmosphere") {
        return Ok(());
    }
    Err(Error::parse(
        path,
        0,
        0,
        "the profile has no [atmosphere] table: say what the atmosphere is, either \
         `[atmosphere]` with `sounding = \"soundings/FILE.txt\"` or with \
         `[[atmosphere.points]]` (z_m, t_c, td_c)"
            .to_string(),
    ))
}

/// Turns a parameter error into one that names the profile file and the
/// line and column where the parameter is set (or just the file when the
/// value comes from a default).
pub(crate) fn locate(e: Error, text: &str, path: &Path) -> Error {
    match e {
        Error::InvalidParameter {
            name,
            value,
            allowed,
        } => {
            let (line, column) = locate_nearest(text, &name).unwrap_or((0, 0));
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
/// (`"physics.stiffness"`, `"wind.aloft_m_s[0]"`, `"atmosphere.points[1].t_c"`)
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

/// Like [`locate_key`], but when the key itself cannot be found (a value
/// inside an inline table or array, "ellipsoids[0].keyframes[2].time_s"),
/// the place of the nearest enclosing key that can ("ellipsoids[0].keyframes").
fn locate_nearest(text: &str, name: &str) -> Option<(usize, usize)> {
    let mut name = name;
    loop {
        if let Some(at) = locate_key(text, name) {
            return Some(at);
        }
        name = name.rsplit_once('.')?.0;
        name = name
            .strip_suffix(']')
            .and_then(|n| n.rsplit_once('['))
            .map_or(name, |(n, _)| n);
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

    /// The name errors and reports give the scene: its file, or
    /// [`EMBEDDED_SCENE_LABEL`].
    pub fn name(&self) -> String {
        match self {
            SceneSource::Embedded => EMBEDDED_SCENE_LABEL.to_string(),
            SceneSource::File(p) => p.display().to_string(),
        }
    }
}

/// How messages name the embedded default scene.
pub const EMBEDDED_SCENE_LABEL: &str = "<embedded fair_weather.toml>";

/// Loads `path`, or the embedded default when `None`.
pub fn load_scene(path: Option<&Path>) -> Result<(SceneProfile, SceneSource)> {
    match path {
        None => Ok((SceneProfile::embedded_default(), SceneSource::Embedded)),
        Some(p) => Ok((SceneProfile::load(p)?, SceneSource::File(p.to_path_buf()))),
    }
}

/// [`load_scene`] with `--set TABLE.KEY=VALUE` overrides applied to the
/// TOML before validation (see [`set`]).
pub fn load_scene_with(
    path: Option<&Path>,
    overrides: &[String],
) -> Result<(SceneProfile, SceneSource)> {
    match path {
        None => Ok((
            set::load_with_overrides(
                DEFAULT_SCENE_TOML,
                Path::new(EMBEDDED_SCENE_LABEL),
                overrides,
            )?,
            SceneSource::Embedded,
        )),
        Some(p) => {
            let text = read_text(p)?;
            let profile = set::load_with_overrides(&text, p, overrides)?;
            require_atmosphere(&text, p)?;
            Ok((profile, SceneSource::File(p.to_path_buf())))
        }
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
