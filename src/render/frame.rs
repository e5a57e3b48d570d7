//! What one frame is given: the sun and the sky it makes (cached per step of
//! elevation), the parcels and camera, and the passes it needs.

use glam::Vec3;

use super::{Camera, RenderConfig, RenderMethod};
use crate::physics::CloudParcel;
use crate::sky::{Atmosphere, SkyLight, SkyLuts};

/// The sun as a directional light, and the sky it makes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sun {
    /// Unit vector toward the sun.
    pub direction: Vec3,
    /// Linear RGB irradiance scale (1 = nominal daylight exposure): the
    /// sun's colour after the air (`sky.sun`), unless a caller sets it.
    pub color: Vec3,
    /// Sky-view table and ambient light for this sun (src/sky).
    pub sky: SkyLight,
}

impl Sun {
    /// The sun toward `direction`, its light scaled by `strength` (1 in
    /// daylight, fading to 0 at dusk), coloured by the atmosphere model
    /// at the direction's elevation (held at 0 below the horizon), in the
    /// Earth's air with the aerosol of `visibility_km` (`[render]
    /// visibility_km`, checked by the scene; see
    /// [`Atmosphere::with_visibility_km`]).
    pub fn from_sky(direction: Vec3, strength: f32, visibility_km: f32) -> Self {
        let sky = sky_light_cached(direction.z.clamp(0.0, 1.0).asin(), strength, visibility_km);
        Self {
            direction,
            color: sky.sun,
            sky,
        }
    }
}

/// Steps the sky is computed at: elevation 0.05° (the sun moves that far in
/// about 12 s of clock time; its colour changes by well under 1 %), the
/// dusk fade 1/256.
const SKY_ELEVATION_STEP_DEG: f32 = 0.05;
const SKY_STRENGTH_STEPS: f32 = 256.0;

/// Sky tables kept: the scene's and a few a panel slider passes through.
const KEPT_LUTS: usize = 4;

/// The sun-independent sky tables (transmittance, Ψ_ms) of the Earth's air
/// at `visibility_km`, built on first use (25 ms on two cores); the last
/// [`KEPT_LUTS`] visibilities asked for are kept.
fn luts(visibility_km: f32) -> std::sync::Arc<SkyLuts> {
    use std::sync::{Arc, Mutex};
    static KEPT: Mutex<Vec<(u32, Arc<SkyLuts>)>> = Mutex::new(Vec::new());
    let key = visibility_km.to_bits();
    let mut kept = KEPT.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(i) = kept.iter().position(|(k, _)| *k == key) {
        let hit = kept.remove(i);
        kept.push(hit);
    } else {
        let air = Atmosphere::EARTH.with_visibility_km(visibility_km as f64);
        kept.push((key, Arc::new(SkyLuts::new(&air))));
        if kept.len() > KEPT_LUTS {
            kept.remove(0);
        }
    }
    kept.last().expect("just pushed").1.clone()
}

/// [`SkyLuts::sky_light`] at the nearest step of elevation and strength,
/// remembered for the last step asked for: the window asks every frame,
/// and a new step costs 0.7 ms of CPU (the sky-view table).
fn sky_light_cached(elevation_rad: f32, strength: f32, visibility_km: f32) -> SkyLight {
    use std::sync::Mutex;
    type Key = (i32, i32, u32);
    static LAST: Mutex<Option<(Key, SkyLight)>> = Mutex::new(None);
    let key = (
        (elevation_rad.to_degrees() / SKY_ELEVATION_STEP_DEG).round() as i32,
        (strength.clamp(0.0, 1.0) * SKY_STRENGTH_STEPS).round() as i32,
        visibility_km.to_bits(),
    );
    let mut last = LAST.lock().unwrap_or_else(|e| e.into_inner());
    match *last {
        Some((k, sky)) if k == key => sky,
        _ => {
            let elevation = (key.0 as f64 * SKY_ELEVATION_STEP_DEG as f64).to_radians();
            let strength = key.1 as f64 / SKY_STRENGTH_STEPS as f64;
            let sky = luts(visibility_km).sky_light(elevation, strength);
            *last = Some((key, sky));
            sky
        }
    }
}

impl Default for Sun {
    fn default() -> Self {
        RenderConfig::default().sun()
    }
}

/// Everything a frame needs from the outside world.
#[derive(Debug, Clone, Copy)]
pub struct FrameInput<'a> {
    pub camera: Camera,
    /// The condensed parcels to draw (from `ParcelWorld::cloud_parcels`).
    pub parcels: &'a [CloudParcel],
    pub sun: Sun,
    /// Simulation time, for slow noise drift. units: s
    pub time_s: f32,
}

/// Which passes and shader code a frame needs ("leave out what a scene does
/// not need"): derived from the configuration and whether there are clouds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Features {
    /// Ray-march clouds (configured on, a ray-marching method and at
    /// least one parcel).
    pub clouds: bool,
    /// Draw sprite clouds (the `sprites` method's parcels or the scene's
    /// `[[sprite_clouds]]`/`[[layers]]`; the renderer sets the latter).
    pub sprites: bool,
    /// Slicing planes (the `slices` method with at least one primitive).
    pub slices: bool,
    /// Terrain mesh pass.
    pub terrain: bool,
    /// Cloud shadows on the terrain (needs terrain and ray-marched clouds,
    /// sprites or slicing planes).
    pub shadows: bool,
    /// The cloud-shadow map pass: the ray-marched clouds' and the slicing
    /// planes' shadows (and the sprites', splatted in).
    pub shadow_map: bool,
    /// Finite-difference normals compiled into the cloud shader.
    pub normals: bool,
    /// Temporal amortisation: the quarter-rate march and the resolve pass
    /// (`[render] temporal` set to true, and clouds to march).
    pub temporal: bool,
}

impl Features {
    /// Features for `cfg` with or without any condensed parcel.
    pub fn new(cfg: &RenderConfig, any_clouds: bool) -> Self {
        let drawn = cfg.clouds && any_clouds;
        let clouds = drawn && cfg.method.ray_marches();
        let terrain = cfg.terrain.enabled;
        let slices = drawn && cfg.method == RenderMethod::Slices;
        Self {
            clouds,
            sprites: drawn && cfg.method == RenderMethod::Sprites,
            slices,
            terrain,
            shadows: cfg.shadows && (clouds || slices) && terrain,
            shadow_map: cfg.shadows && terrain && (clouds || slices),
            normals: cfg.normals && clouds,
            temporal: cfg.temporal == Some(true) && clouds,
        }
    }
}
