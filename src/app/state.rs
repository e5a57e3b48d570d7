//! Everything the window shows and edits, without any window or GPU type:
//! the scene, the profile editor, the running simulation, playback, the
//! camera and the panel's settings. The panel mutates it; the window reads it
//! to draw. Tests can drive it headless.

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::Vec3;

use super::camera::OrbitCamera;
use super::profile_edit::ProfileEditor;
use crate::config::{Camera, RenderConfig, TemporalMode};
use crate::error::{Error, Result};
use crate::physics::{CloudParcel, ParcelWorld, WorldConfig};
use crate::scene::{SceneProfile, SceneSource};
use crate::sky::Sun;
use crate::sun::SolarClock;

/// Seed of the simulation; fixed so that a reset replays the same run.
pub const SIM_SEED: u64 = 1;
/// Simulated seconds per frame at speed 1 when frames are counted (screenshot
/// runs), so a capture does not depend on how fast the machine is. units: s
pub const FIXED_FRAME_DT_S: f64 = 1.0 / 30.0;
/// Largest simulated step of one frame at speed 1: a stall (window dragged,
/// slow frame) must not turn into one huge physics step. units: s
pub const MAX_FRAME_DT_S: f64 = 0.1;
/// Physics frame of the pre-simulation to the start time: the default
/// `--dt` of `cumulus render` and `simulate`, so the window opens on the same
/// world as `cumulus render --time START`. units: s
pub const WARM_UP_DT_S: f64 = 2.0;
/// Wall time one window frame spends pre-simulating, so the progress
/// display stays live. units: s
pub const WARM_UP_SLICE_S: f64 = 0.05;

/// Playback of the simulation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Playback {
    pub playing: bool,
    /// Simulated seconds per real second.
    pub speed: f64,
    /// Set by "step": advance one frame while paused.
    pub step_once: bool,
}

/// The wind as the panel shows it: speed and the direction it blows from.
/// The scene's wind is linear from the surface to `aloft_z_m`; the panel
/// edits the wind aloft and scales the surface wind with it, keeping the
/// scene's shear (surface/aloft ratio).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindHandle {
    /// units: m/s
    pub speed_m_s: f64,
    /// Direction the wind blows from, clockwise from north (+y). units: deg
    pub from_deg: f64,
    /// |surface wind| / |wind aloft| of the scene (0.5 when it has no wind).
    pub surface_ratio: f64,
}

impl WindHandle {
    /// The handle for a wind table.
    pub fn of(w: &crate::physics::WindConfig) -> Self {
        let [ax, ay] = w.aloft_m_s;
        let [sx, sy] = w.surface_m_s;
        let aloft = ax.hypot(ay);
        let surface = sx.hypot(sy);
        // Meteorological convention: the direction the wind comes *from*.
        let from_deg = if aloft > 0.0 {
            (-ax).atan2(-ay).to_degrees().rem_euclid(360.0)
        } else {
            270.0
        };
        Self {
            speed_m_s: aloft,
            from_deg,
            surface_ratio: if aloft > 0.0 { surface / aloft } else { 0.5 },
        }
    }

    /// Writes the handle into a wind table.
    pub fn apply(&self, w: &mut crate::physics::WindConfig) {
        let (s, c) = self.from_deg.to_radians().sin_cos();
        let to = [-s * self.speed_m_s, -c * self.speed_m_s];
        w.aloft_m_s = to;
        w.surface_m_s = to.map(|v| v * self.surface_ratio);
    }
}

/// Last frame's timings for the panel. units: ms
#[derive(Debug, Clone, Default)]
pub struct FrameStats {
    /// The GPU adapter, for the panel.
    pub adapter: String,
    pub frame_ms: f64,
    pub physics_ms: f64,
    /// Physics stages of the last step (from `physics::Counters`).
    pub physics_stages: Vec<(&'static str, f64)>,
    /// Sub-steps the last frame's physics took.
    pub substeps: u32,
    pub upload_ms: f64,
    /// GPU (or CPU-synchronised) time of each render pass.
    pub passes: Vec<(String, f64)>,
    pub gpu_timestamps: bool,
    /// Set when the baked field's voxels had to be coarsened to fit memory
    /// (`BakeInfo::coarsening_note`).
    pub bake_note: Option<String>,
}

/// The window's model.
pub struct Model {
    pub profile: SceneProfile,
    pub source: SceneSource,
    pub editor: ProfileEditor,
    pub world: ParcelWorld,
    /// Editor revision last handed to the world.
    pushed_revision: u64,
    pub playback: Playback,
    /// Physics, ground, emission and wind, as edited by the panel.
    pub world_cfg: WorldConfig,
    /// Render settings as in the profile (paths unresolved), as edited.
    pub render_cfg: RenderConfig,
    pub wind: WindHandle,
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
    /// The sun's clock (the scene's `[sun]`, as moved by the time slider);
    /// None = the sun pinned by the render settings.
    pub clock: Option<SolarClock>,
    /// Simulated time a run opens at and Reset returns to. units: s
    pub start_s: f64,
    /// Pre-simulating toward this time (frames show progress, not playback). units: s
    pub warming_to: Option<f64>,
}

impl Model {
    /// A model on a loaded scene.
    pub fn new(profile: SceneProfile, source: SceneSource) -> Result<Self> {
        let env = profile.build_atmosphere(&source)?;
        let mut editor = ProfileEditor::from_environment(&profile.atmosphere, env)?;
        let world_cfg = profile.world_config(&source.base_dir())?;
        let clock = profile.clock()?;
        editor.set_lift_options(crate::atmosphere::lifting::LiftOptions {
            alpha: world_cfg.physics.latent_heat_alpha,
            condensate_loading: world_cfg.physics.condensate_loading,
            ..Default::default()
        })?;
        let world = ParcelWorld::new(editor.environment().clone(), world_cfg.clone(), SIM_SEED)?;
        let render_cfg = profile.render.clone();
        let profile_start_s = profile.simulation.start_s;
        render_cfg.validate()?;
        profile.camera.validate()?;
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
            wind: WindHandle::of(&world_cfg.wind.clone().unwrap_or_default()),
            world_cfg,
            render_cfg,
            camera,
            default_camera: camera,
            stats: FrameStats::default(),
            parcels: Vec::new(),
            path_text,
            status: String::new(),
            cond_level_m: 0.0,
            surface_qv_g_per_kg: 0.0,
            clock,
            start_s: profile_start_s,
            warming_to: None,
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
        self.cond_level_m = self.editor.lcl_m().unwrap_or(0.0);
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
        if let Some(target) = self.warming_to {
            while t0.elapsed().as_secs_f64() < WARM_UP_SLICE_S {
                if !self.warm_step(target) {
                    self.warming_to = None;
                    break;
                }
            }
            // Clouds appear once the start time is reached: the first frame
            // that shows any is the scene's start state, not a cloud still
            // forming in the pre-simulation.
            if self.warming_to.is_some() {
                self.parcels.clear();
            } else {
                self.world.cloud_parcels(&mut self.parcels);
            }
            self.stats.physics_ms = t0.elapsed().as_secs_f64() * 1000.0;
            return;
        }
        if self.playback.playing || self.playback.step_once {
            let dt = real_dt_s.min(MAX_FRAME_DT_S) * self.playback.speed;
            if dt > 0.0 {
                let before = *self.world.counters();
                let report = self.world.step(dt);
                let after = self.world.counters();
                let ms = |a: std::time::Duration, b: std::time::Duration| {
                    (a.saturating_sub(b)).as_secs_f64() * 1000.0
                };
                self.stats.substeps = report.substeps;
                self.stats.physics_stages = vec![
                    ("neighbours", ms(after.neighbours, before.neighbours)),
                    ("sph", ms(after.sph, before.sph)),
                    ("exposed area", ms(after.exposed_area, before.exposed_area)),
                    ("mixing", ms(after.mixing, before.mixing)),
                    ("thermo", ms(after.thermo, before.thermo)),
                    ("integrate", ms(after.integrate, before.integrate)),
                ];
            }
            self.playback.step_once = false;
        }
        self.world.cloud_parcels(&mut self.parcels);
        self.stats.physics_ms = t0.elapsed().as_secs_f64() * 1000.0;
    }

    /// One pre-simulation frame toward `target_s` (the last one shortened
    /// to land on it); false once there.
    fn warm_step(&mut self, target_s: f64) -> bool {
        let d = (target_s - self.world.time_s()).min(WARM_UP_DT_S);
        if d <= 1e-9 {
            return false;
        }
        self.world.step(d);
        true
    }

    /// Starts pre-simulating to the start time: the next frames advance
    /// toward it as fast as they can and show progress (see [`Self::warm_up_progress`]).
    pub fn begin_warm_up(&mut self) {
        self.warming_to = (self.start_s > self.world.time_s()).then_some(self.start_s);
    }

    /// Fraction of the pre-simulation done, while there is one.
    pub fn warm_up_progress(&self) -> Option<f64> {
        self.warming_to
            .map(|t| (self.world.time_s() / t).clamp(0.0, 1.0))
    }

    /// Simulates to `target_s` at once, calling `on_step` with the simulated
    /// time after each frame (a progress bar). Same frames as [`Self::advance`]'s
    /// pre-simulation, so both give the same world.
    pub fn warm_up_to(&mut self, target_s: f64, mut on_step: impl FnMut(f64)) {
        self.push_edits();
        self.warming_to = None;
        while self.warm_step(target_s) {
            on_step(self.world.time_s());
        }
        self.world.cloud_parcels(&mut self.parcels);
    }

    /// Restarts the simulation on the current (edited) profile and
    /// pre-simulates back to the start time.
    pub fn reset(&mut self) -> Result<()> {
        self.world = ParcelWorld::new(
            self.editor.environment().clone(),
            self.world_cfg.clone(),
            SIM_SEED,
        )?;
        self.pushed_revision = self.editor.revision();
        self.begin_warm_up();
        Ok(())
    }

    /// The scene as edited: what "save" writes.
    pub fn edited_profile(&self) -> SceneProfile {
        let mut p = self.profile.clone();
        p.atmosphere = self.editor.spec().clone();
        p.physics = self.world_cfg.physics.clone();
        p.ground = self.world_cfg.ground.clone();
        p.emission = self.world_cfg.emission.clone();
        p.wind = self.world_cfg.wind.clone();
        p.render = self.render_cfg.clone();
        p.sun = self.clock.map(|c| c.to_config());
        let eye = self.camera.eye_m();
        p.camera.position_m = eye.to_array();
        p.camera.target_m = self.camera.target_m.to_array();
        p.camera.vfov_deg = self.camera.fov_y_rad.to_degrees();
        p
    }

    /// Applies the panel's simulation settings (emission, wind, time of
    /// day) to the running world; on a refused value nothing changes.
    pub fn apply_world_config(&mut self, mut cfg: WorldConfig) -> Result<()> {
        // The handle writes the scene's [wind] table; with none, a calm
        // handle leaves the sounding's wind in charge, a moved one overrides it.
        match cfg.wind.as_mut() {
            Some(w) => self.wind.apply(w),
            None if self.wind.speed_m_s > 0.0 => {
                let mut w = crate::physics::WindConfig::default();
                self.wind.apply(&mut w);
                cfg.wind = Some(w);
            }
            None => {}
        }
        self.world.set_config(cfg.clone())?;
        self.world_cfg = cfg;
        Ok(())
    }

    /// Time of day now: the `[sun]` clock's local time, or (sun pinned) the
    /// ground's solar time. units: h
    pub fn time_of_day_h(&self) -> f64 {
        match &self.clock {
            Some(c) => c.local_time_h(self.world.time_s()),
            None => {
                (self.world_cfg.emission.start_hour + self.world.time_s() / 3600.0).rem_euclid(24.0)
            }
        }
    }

    /// Sets the time of day now: moves the `[sun]` clock (the sun, sky,
    /// shadows and the ground's heating follow), or with a pinned sun only
    /// the ground's solar start hour. units: h
    pub fn set_time_of_day_h(&mut self, hour: f64) -> Result<()> {
        let t = self.world.time_s();
        let mut cfg = self.world_cfg.clone();
        match &self.clock {
            Some(c) => {
                let moved = c.with_local_time_at(hour, t);
                cfg.emission.start_hour = moved.solar_time_h(0.0);
                self.apply_world_config(cfg)?;
                self.clock = Some(moved);
                Ok(())
            }
            None => {
                cfg.emission.start_hour = (hour - t / 3600.0).rem_euclid(24.0);
                self.apply_world_config(cfg)
            }
        }
    }

    /// The render settings with file paths resolved against the scene's
    /// directory: what the renderer gets.
    /// Temporal amortisation is on in the window unless the scene (or
    /// the panel) turned it off.
    pub fn resolved_render_config(&self) -> RenderConfig {
        let mut c = self.render_cfg.clone();
        c.resolve_paths(&self.source.base_dir());
        c.temporal.get_or_insert(TemporalMode::default());
        c
    }

    /// The renderer's camera now.
    pub fn render_camera(&self) -> Camera {
        Camera {
            position: self.camera.eye_m(),
            target: self.camera.target_m,
            vfov_rad: self.camera.fov_y_rad,
            near_m: self.profile.camera.near_m,
            far_m: self.profile.camera.far_m,
        }
    }

    /// The sun now: from the clock, or pinned by the render settings.
    pub fn sun(&self) -> Sun {
        crate::scene::render_sun(self.clock.as_ref(), &self.render_cfg, self.world.time_s()).0
    }

    /// Saves the edited scene as a profile TOML, atomically.
    pub fn save(&self, path: &Path) -> Result<()> {
        let text = self.edited_profile().to_toml()?;
        crate::output::write_atomic(path, text.as_bytes())
    }

    /// Loads a profile and restarts on it; on error nothing changes.
    pub fn load(&mut self, path: &Path) -> Result<()> {
        let (profile, source) = crate::scene::load_scene(Some(path))?;
        let mut fresh = Model::new(profile, source)?;
        fresh.begin_warm_up();
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

/// The scene's `[camera]` framing as an orbit camera.
pub fn default_camera(profile: &SceneProfile) -> OrbitCamera {
    let c = &profile.camera;
    OrbitCamera::look_at(Vec3::from(c.position_m), Vec3::from(c.target_m), c.vfov_deg)
}
