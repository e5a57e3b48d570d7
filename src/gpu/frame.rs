//! What one frame is given: the parcels, the camera, the sun and the time.

use crate::config::Camera;
use crate::physics::CloudParcel;
use crate::sky::Sun;

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
