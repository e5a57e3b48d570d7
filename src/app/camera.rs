//! The window's camera: orbit around a target (drag), fly (WASD + mouse
//! look), wheel zoom, and a reset to the scene's framing. Pure glam, no
//! window types, so its maths is tested without a display.
//!
//! Angles: yaw about +z from +x, pitch up from the horizontal, both radians.
//! The eye sits `distance_m` behind the target along the view direction.

use glam::{Mat4, Vec3};

/// Pitch is kept off ±90° so the view never flips over the pole.
const MAX_PITCH_RAD: f32 = 1.54;
/// The eye never goes below this height, so the camera stays out of the ground. units: m
const MIN_EYE_Z_M: f32 = 2.0;

/// An orbit/fly camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrbitCamera {
    /// Point the camera looks at and orbits around. units: m
    pub target_m: Vec3,
    /// Distance from the eye to the target. units: m
    pub distance_m: f32,
    /// Heading of the view direction, about +z from +x. units: rad
    pub yaw_rad: f32,
    /// Elevation of the view direction (negative looks down). units: rad
    pub pitch_rad: f32,
    /// Vertical field of view. units: rad
    pub fov_y_rad: f32,
}

impl OrbitCamera {
    /// A camera at `eye_m` looking at `target_m`.
    pub fn look_at(eye_m: Vec3, target_m: Vec3, fov_y_deg: f32) -> Self {
        let d = target_m - eye_m;
        let distance = d.length().max(1.0);
        let dir = if d.length_squared() > 0.0 {
            d / d.length()
        } else {
            Vec3::X
        };
        Self {
            target_m,
            distance_m: distance,
            yaw_rad: dir.y.atan2(dir.x),
            pitch_rad: dir
                .z
                .clamp(-1.0, 1.0)
                .asin()
                .clamp(-MAX_PITCH_RAD, MAX_PITCH_RAD),
            fov_y_rad: fov_y_deg.clamp(5.0, 150.0).to_radians(),
        }
    }

    /// Unit view direction.
    pub fn forward(&self) -> Vec3 {
        let (sp, cp) = self.pitch_rad.sin_cos();
        let (sy, cy) = self.yaw_rad.sin_cos();
        Vec3::new(cp * cy, cp * sy, sp)
    }

    /// Unit vector to the right of the view, horizontal.
    pub fn right(&self) -> Vec3 {
        let (sy, cy) = self.yaw_rad.sin_cos();
        Vec3::new(sy, -cy, 0.0)
    }

    /// Eye position. units: m
    pub fn eye_m(&self) -> Vec3 {
        self.target_m - self.forward() * self.distance_m
    }

    /// Orbit about the target by a drag of (dx, dy) pixels.
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        const RAD_PER_PX: f32 = 0.005;
        self.yaw_rad -= dx * RAD_PER_PX;
        self.pitch_rad = (self.pitch_rad + dy * RAD_PER_PX).clamp(-MAX_PITCH_RAD, MAX_PITCH_RAD);
        self.keep_above_ground();
    }

    /// Turn the view about the eye (fly mode mouse look) by (dx, dy) pixels.
    pub fn look(&mut self, dx: f32, dy: f32) {
        const RAD_PER_PX: f32 = 0.003;
        let eye = self.eye_m();
        self.yaw_rad -= dx * RAD_PER_PX;
        self.pitch_rad = (self.pitch_rad - dy * RAD_PER_PX).clamp(-MAX_PITCH_RAD, MAX_PITCH_RAD);
        self.target_m = eye + self.forward() * self.distance_m;
    }

    /// Fly: move eye and target together by (forward, right, up) metres;
    /// forward follows the view heading but stays horizontal, like walking.
    pub fn fly(&mut self, forward_m: f32, right_m: f32, up_m: f32) {
        let (sy, cy) = self.yaw_rad.sin_cos();
        let ahead = Vec3::new(cy, sy, 0.0);
        self.target_m += ahead * forward_m + self.right() * right_m + Vec3::Z * up_m;
        self.keep_above_ground();
    }

    /// Zoom: scale the eye–target distance (wheel steps; positive = closer).
    pub fn zoom(&mut self, steps: f32) {
        self.distance_m = (self.distance_m * 0.9f32.powf(steps)).clamp(10.0, 200_000.0);
        self.keep_above_ground();
    }

    fn keep_above_ground(&mut self) {
        let eye = self.eye_m();
        if eye.z < MIN_EYE_Z_M {
            self.target_m.z += MIN_EYE_Z_M - eye.z;
        }
    }

    /// World → view transform (right-handed, z up in the world).
    pub fn view_from_world(&self) -> Mat4 {
        Mat4::look_at_rh(self.eye_m(), self.target_m, Vec3::Z)
    }

    /// View → clip transform for an aspect ratio (width / height).
    pub fn clip_from_view(&self, aspect: f32) -> Mat4 {
        Mat4::perspective_rh(self.fov_y_rad, aspect.max(1e-3), 1.0, 500_000.0)
    }

    /// Projects a world point to pixel coordinates in a `w`×`h` image
    /// (origin top left), or None behind the eye.
    pub fn project_px(&self, p_m: Vec3, w: f32, h: f32) -> Option<glam::Vec2> {
        let clip = self.clip_from_view(w / h) * self.view_from_world() * p_m.extend(1.0);
        if clip.w <= 1e-3 {
            return None;
        }
        let ndc = clip.truncate() / clip.w;
        Some(glam::Vec2::new(
            (ndc.x * 0.5 + 0.5) * w,
            (0.5 - ndc.y * 0.5) * h,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_round_trips_eye_and_target() {
        let eye = Vec3::new(-8000.0, -3000.0, 600.0);
        let target = Vec3::new(0.0, 0.0, 1500.0);
        let c = OrbitCamera::look_at(eye, target, 50.0);
        // f32 trigonometry over ~8.6 km: a centimetre is well within rounding.
        assert!((c.eye_m() - eye).length() < 0.05, "{:?}", c.eye_m());
        let px = c.project_px(target, 800.0, 600.0).unwrap();
        assert!((px - glam::Vec2::new(400.0, 300.0)).length() < 0.01);
    }

    #[test]
    fn orbit_keeps_distance_and_look_keeps_eye() {
        let mut c = OrbitCamera::look_at(Vec3::new(-5000.0, 0.0, 1000.0), Vec3::ZERO, 50.0);
        let d = c.distance_m;
        c.orbit(100.0, 20.0);
        assert!((c.eye_m() - c.target_m).length() - d < 0.05);
        let eye = c.eye_m();
        c.look(50.0, -30.0);
        assert!((c.eye_m() - eye).length() < 0.05);
    }
}
