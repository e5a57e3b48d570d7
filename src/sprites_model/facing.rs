//! In-cloud facing (paper §3.3): a sprite turns to face the camera until the
//! camera comes within half its radius; then its facing is locked (no
//! "parting of the Red Sea" as the camera pushes through) and it fades by
//! the angle between the locked orientation and the vector to the camera,
//! so it never shows edge-on.

use glam::Vec3;

/// The camera locks a sprite's facing within this fraction of its radius.
pub const LOCK_FRACTION: f32 = 0.5;

/// Facing state of one sprite.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Facing {
    /// Locked unit normal (sprite → camera at the moment of locking).
    pub locked: Option<Vec3>,
}

impl Facing {
    /// Updates for a camera at `camera_m`; returns the sprite normal to draw
    /// with and the alpha factor from facing.
    pub fn update(&mut self, center_m: Vec3, radius_m: f32, camera_m: Vec3) -> (Vec3, f32) {
        let to_cam = camera_m - center_m;
        let dir = to_cam.try_normalize();
        let inside = to_cam.length() < LOCK_FRACTION * radius_m;
        match (inside, self.locked) {
            (false, _) => {
                self.locked = None;
                (dir.unwrap_or(Vec3::Z), 1.0)
            }
            (true, Some(n)) => (n, dir.map_or(0.0, |d| n.dot(d).abs())),
            (true, None) => {
                let n = dir.unwrap_or(Vec3::Z);
                self.locked = Some(n);
                (n, 1.0)
            }
        }
    }
}
