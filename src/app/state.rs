//! Everything the window shows and edits, without any window or GPU type:
//! the scene, the profile editor, the running simulation, playback, the
//! camera and the panel's settings. The panel mutates it; the window reads it
//! to draw. Tests can drive it headless.

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::Vec3;

use super::camera::OrbitCamera;
use super::profile_edit::ProfileEditor;
use super::standin as sim;
use crate::error::{Error, Result};
use crate::physics::CloudParcel;
use crate::scene::{SceneProfile, SceneSource};

/// Seed of the simulation; fixed so that a reset replays the same run.
pub const SIM_SEED: u64 = 1;
/// Simulated seconds per frame at speed 1 when frames are counted (screenshot
/// runs), so a capture does not depend on how fast the machine is. units: s
pub const FIXED_FRAME_DT_S: f64 = 1.0 / 30.0;
/// Largest simulated step of one frame at speed 1: a stall (window dragged,
/// slow frame) must not turn into one huge physics step. units: s
pub const MAX_FRAME_DT_S: f64 = 0.1;

/// Playback of the simulation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Playback {
    pub playing: bool,
    /// Simulated seconds per real second.
    pub speed: f64,
    /// Set by "step": advance one frame while paused.
    pub step_once: bool,
}

/// Controls that go to the simulation (paper §7.2 plus emission and wind).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimControls {
    /// Multiplies the ground's emission probability. units: 1
    pub emission_scale: f64,
    /// Wind speed at all heights. units: m/s
    pub wind_speed_m_s: f64,
    /// Direction the wind blows from, clockwise from north (+y). units: deg
    pub wind_from_deg: f64,
    /// Local solar time; emission follows the sun's heating. units: h
    pub time_of_day_h: f64,
}

impl Default for SimControls {
    fn default() -> Self {
        Self {
            emission_scale: 1.0,
            wind_speed_m_s: 0.0,
            wind_from_deg: 270.0,
            time_of_day_h: 13.0,
        }
    }
}

/// Render settings the panel toggles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderControls {
    /// Ray-march step. units: m
    pub step_m: f32,
    /// Octaves of the noise (detail).
    pub noise_octaves: u32,
    pub normals: bool,
    pub shadows: bool,
    pub terrain: bool,
}

impl Default for RenderControls {
    fn default() -> Self {
        Self {
            step_m: 50.0,
            noise_octaves: 4,
            normals: false,
            shadows: true,
            terrain: true,
        }
    }
}

/// Last frame's timings for the panel. units: ms
#[derive(Debug, Clone, Default)]
pub struct FrameStats {
    pub frame_ms: f64,
    pub physics_ms: f64,
    pub upload_ms: f64,
    /// GPU (or CPU-synchronised) time of each render pass.
    pub passes: Vec<(String, f64)>,
    pub gpu_timestamps: bool,
}

/// The window's model.
pub struct Model {
    pub profile: SceneProfile,
    pub source: SceneSource,
    pub editor: ProfileEditor,
    pub world: sim::World,
    /// Editor revision last handed to the world.
    pushed_revision: u64,
    pub playback: Playback,
    pub sim: SimControls,
    pub render: RenderControls,
    pub camera: OrbitCamera,
    pub default_camera: OrbitCamera,
    pub stats: FrameStats,
    /// Condensed parcels of the current frame, reused between frames.
    pub parcels: Vec<CloudParcel>,
    /// The save/load path text field.
    pub path_text: String,
    /// Last message for the status line (saved, load error…).
    pub status: String,
    /// The surface parcel: condensation level the panel's handle shows. units: m
    pub cond_level_m: f64,
    /// Surface mixing ratio the panel's handle shows. units: g/kg
    pub surface_qv_g_per_kg: f64,
}

impl Model {
    /// A model on a loaded scene.
    pub fn new(profile: SceneProfile, source: SceneSource) -> Result<Self> {
        let env = profile.atmosphere.build(&source.base_dir())?;
        let editor = ProfileEditor::from_environment(&env)?;
        let world = sim::World::new(editor.environment().clone(), SIM_SEED)?;
        let camera = default_camera(&profile);
        let path_text = match &source {
            SceneSource::File(p) => p.display().to_string(),
            SceneSource::Embedded => format!("{}.toml", profile.name),
        };
        let mut m = Self {
            profile,
            source,
            editor,
            world,
            pushed_revision: 0,
            playback: Playback {
                playing: true,
                speed: 10.0,
                step_once: false,
            },
            sim: SimControls::default(),
            render: RenderControls::default(),
            camera,
            default_camera: camera,
            stats: FrameStats::default(),
            parcels: Vec::new(),
            path_text,
            status: String::new(),
            cond_level_m: 0.0,
            surface_qv_g_per_kg: 0.0,
        };
        m.sync_handles();
        Ok(m)
    }

    /// Title for the window.
    pub fn title(&self) -> String {
        format!("cumulus — {}", self.profile.name)
    }

    /// Refreshes the condensation-level and mixing-ratio handles from the
    /// editor (after an edit elsewhere moved them).
    pub fn sync_handles(&mut self) {
        self.cond_level_m = self.editor.curve().lcl_m.unwrap_or(0.0);
        self.surface_qv_g_per_kg = self.editor.surface_mixing_ratio() * 1000.0;
    }

    /// Hands an edited environment to the running world at once.
    pub fn push_edits(&mut self) {
        if self.editor.revision() != self.pushed_revision {
            self.world
                .set_environment(self.editor.environment().clone());
            self.pushed_revision = self.editor.revision();
        }
    }

    /// Advances the simulation by one frame that took `real_dt_s` of wall
    /// time, and collects the condensed parcels for drawing.
    pub fn advance(&mut self, real_dt_s: f64) {
        self.push_edits();
        let t0 = Instant::now();
        if self.playback.playing || self.playback.step_once {
            let dt = real_dt_s.min(MAX_FRAME_DT_S) * self.playback.speed;
            if dt > 0.0 {
                self.world.step(dt);
            }
            self.playback.step_once = false;
        }
        self.world.cloud_parcels(&mut self.parcels);
        self.stats.physics_ms = t0.elapsed().as_secs_f64() * 1000.0;
    }

    /// Simulates `seconds` at once (start-up warm-up), in frame-sized steps.
    pub fn warm_up(&mut self, seconds: f64) {
        self.push_edits();
        let mut left = seconds;
        let dt = MAX_FRAME_DT_S * self.playback.speed.max(1.0);
        while left > 0.0 {
            let d = left.min(dt);
            self.world.step(d);
            left -= d;
        }
    }

    /// Restarts the simulation on the current (edited) profile.
    pub fn reset(&mut self) -> Result<()> {
        self.world = sim::World::new(self.editor.environment().clone(), SIM_SEED)?;
        self.pushed_revision = self.editor.revision();
        Ok(())
    }

    /// The scene as edited: what "save" writes.
    pub fn edited_profile(&self) -> SceneProfile {
        // The atmosphere points go back into the profile once the
        // AtmosphereSpec with inline points is on main.
        self.profile.clone()
    }

    /// Saves the edited scene as a profile TOML, atomically.
    pub fn save(&self, path: &Path) -> Result<()> {
        let text = self.edited_profile().to_toml()?;
        crate::output::write_atomic(path, text.as_bytes())
    }

    /// Loads a profile and restarts on it; on error nothing changes.
    pub fn load(&mut self, path: &Path) -> Result<()> {
        let (profile, source) = crate::scene::load_scene(Some(path))?;
        let fresh = Model::new(profile, source)?;
        let keep_path = std::mem::take(&mut self.path_text);
        *self = Self {
            path_text: keep_path,
            stats: std::mem::take(&mut self.stats),
            ..fresh
        };
        Ok(())
    }

    /// Path from the panel's text field.
    pub fn path(&self) -> Result<PathBuf> {
        let t = self.path_text.trim();
        if t.is_empty() {
            return Err(Error::invalid(
                "profile path",
                "(empty)",
                "a file name such as my_scene.toml",
            ));
        }
        Ok(PathBuf::from(t))
    }
}

/// The scene's camera framing: the eye south-west of the domain centre,
/// looking across the landscape at the cloud layer.
pub fn default_camera(_profile: &SceneProfile) -> OrbitCamera {
    OrbitCamera::look_at(
        Vec3::new(-9000.0, -9000.0, 1200.0),
        Vec3::new(0.0, 0.0, 1500.0),
        55.0,
    )
}
