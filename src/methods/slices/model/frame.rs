//! One frame of an authored scene on the CPU alone (Table 1's CPU row):
//! the ellipsoids at a time, every cloud's slicing stack for the current
//! light and eye, and the noise-octave uniform, pivoting on the cloud's centre.
//! The renderer builds its frames with `methods::slices::gpu::slices_frame`,
//! which adds the physics' parcels and the first noise octave in the
//! shadow; this is the same frame for the ellipsoids alone, without the
//! renderer's noise volume.

use glam::Vec3;

use super::animation::{ParticleConfig, states_at};
use super::ellipsoid::{Ellipsoid, EllipsoidState, bounds_m};
use super::octaves::{OctaveUniform, octave_uniform};
use super::clouds::CloudSlices;
use crate::config::slices::SlicesConfig;
use crate::error::Result;

/// What the slice renderer draws in one frame.
#[derive(Debug, Clone)]
pub struct AuthoredFrame {
    /// The ellipsoids at this frame's time.
    pub states: Vec<EllipsoidState>,
    /// Every cloud's slicing planes with per-vertex density and shadow,
    /// back to front.
    pub slices: CloudSlices,
    /// Every tier's octave transforms at this frame's time.
    pub octaves: OctaveUniform,
}

/// Builds the frame at `time_s` (units: s) for the light toward `to_light`
/// and a viewer at `eye_m` looking along `view_dir`. Noise rotates about the centre of
/// the clouds' bounds at time 0, so the pivot does not drift with them.
pub fn authored_frame(
    ellipsoids: &[Ellipsoid],
    particles: &ParticleConfig,
    slices: &SlicesConfig,
    time_s: f32,
    to_light: Vec3,
    eye_m: Vec3,
    view_dir: Vec3,
) -> Result<AuthoredFrame> {
    let states = states_at(ellipsoids, particles, time_s);
    let pivot_m = bounds_m(&states_at(ellipsoids, particles, 0.0))
        .map_or(Vec3::ZERO, |(lo, hi)| (lo + hi) * 0.5);
    let mut clouds = CloudSlices::grid(&states, slices, to_light, eye_m, view_dir)?;
    clouds.evaluate(slices, to_light, None)?;
    let octaves = octave_uniform(
        &slices.tiers,
        &slices.base,
        slices.lacunarity(),
        slices.octaves as usize,
        pivot_m,
        time_s,
    );
    Ok(AuthoredFrame {
        states,
        slices: clouds,
        octaves,
    })
}
