//! In-cloud facing (paper §3.3): a sprite turns to face the camera until the
//! camera comes within half its radius; then its facing is locked (no
//! "parting of the Red Sea" as the camera pushes through) and it fades by
//! the angle between the locked orientation and the vector to the camera,
//! so it never shows edge-on.
//!
//! Leaving: the paper does not say how a locked sprite lets go. Snapping
//! back to the camera as soon as the camera is out of the half radius pops
//! (the locked quad may still reach in front of the camera, the turned one
//! not, or the other way round), so the release is a crossfade: from half
//! the radius to the whole radius the locked quad fades out and the
//! camera-facing one fades in, and the lock ends at the whole radius.

use glam::Vec3;

/// The camera locks a sprite's facing within this fraction of its radius.
pub const LOCK_FRACTION: f32 = 0.5;
/// The lock ends (the release crossfade is complete) at this fraction.
pub const RELEASE_FRACTION: f32 = 1.0;

/// Facing state of one sprite.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Facing {
    /// Locked unit normal (sprite → camera at the moment of locking).
    pub locked: Option<Vec3>,
}

/// The quads to draw a sprite with: (unit normal, alpha factor) each; the
/// second has alpha 0 except during the release crossfade.
pub type Views = [(Vec3, f32); 2];

impl Facing {
    /// Updates for a camera at `camera_m`; returns the sprite normal(s) to
    /// draw with and their alpha factors from facing.
    pub fn update(&mut self, center_m: Vec3, radius_m: f32, camera_m: Vec3) -> Views {
        let to_cam = camera_m - center_m;
        let d = to_cam.try_normalize().unwrap_or(Vec3::Z);
        let dist = to_cam.length();
        let (lock, release) = (LOCK_FRACTION * radius_m, RELEASE_FRACTION * radius_m);
        match self.locked {
            Some(n) if dist < lock => [(n, n.dot(d).abs()), (d, 0.0)],
            Some(n) if dist < release => {
                let t = (dist - lock) / (release - lock).max(1e-6);
                [(n, n.dot(d).abs() * (1.0 - t)), (d, t)]
            }
            None if dist < lock => {
                self.locked = Some(d);
                [(d, 1.0), (d, 0.0)]
            }
            _ => {
                self.locked = None;
                [(d, 1.0), (d, 0.0)]
            }
        }
    }
}
