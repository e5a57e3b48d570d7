//! The sun as the renderer's light: its direction and colour, and the sky
//! it makes, cached per step of elevation and per visibility (the window
//! asks every frame; a new sky costs ~1 ms, new tables 25 ms).

use glam::Vec3;

use super::{Atmosphere, SkyLight, SkyLuts};

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
