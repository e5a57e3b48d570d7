//! The camera: its scene table (`[camera]`) and the placement a frame uses.

use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};

use super::check;
use crate::error::{Error, Result};

/// Camera placement (the `[camera]` table).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CameraConfig {
    /// Eye position. units: m
    pub position_m: [f32; 3],
    /// Point looked at. units: m
    pub target_m: [f32; 3],
    /// Vertical field of view. units: degrees
    pub vfov_deg: f32,
    /// Near clip distance. units: m
    pub near_m: f32,
    /// Far clip distance. units: m
    pub far_m: f32,
}

impl Default for CameraConfig {
    /// Stands 6.5 km south of a 10 km domain, 1 km up (just under the usual
    /// cloud base), looking north across the landscape at the cloud layer
    /// (1–3 km); with the default sun from the east the bases are in shade
    /// and the shadows fall sideways onto the ground in front of the clouds.
    fn default() -> Self {
        Self {
            position_m: [-2000.0, -11500.0, 1000.0],
            target_m: [0.0, -1000.0, 900.0],
            vfov_deg: 45.0,
            near_m: 10.0,
            far_m: 60_000.0,
        }
    }
}

impl CameraConfig {
    /// Checks every field; the error names the field and its allowed range.
    pub fn validate(&self) -> Result<()> {
        for (i, v) in self.position_m.iter().chain(&self.target_m).enumerate() {
            if !v.is_finite() {
                let name = if i < 3 {
                    "camera.position_m"
                } else {
                    "camera.target_m"
                };
                return Err(Error::invalid(name, v, "finite numbers (metres)"));
            }
        }
        let d = Vec3::from(self.target_m) - Vec3::from(self.position_m);
        if d.length() < 1.0 {
            return Err(Error::invalid(
                "camera.target_m",
                format!("{:?}", self.target_m),
                "at least 1 m from camera.position_m",
            ));
        }
        if d.normalize().z.abs() > 0.999 {
            return Err(Error::invalid(
                "camera.target_m",
                format!("{:?}", self.target_m),
                "not straight above or below the camera (z is up)",
            ));
        }
        check(
            "camera.vfov_deg",
            self.vfov_deg,
            self.vfov_deg >= 5.0 && self.vfov_deg <= 150.0,
            "5 to 150 degrees",
        )?;
        check(
            "camera.near_m",
            self.near_m,
            self.near_m > 0.0,
            "more than 0 m",
        )?;
        check(
            "camera.far_m",
            self.far_m,
            self.far_m > self.near_m * 2.0,
            "more than twice camera.near_m",
        )?;
        Ok(())
    }
}

/// A perspective camera, z up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// units: m
    pub position: Vec3,
    /// units: m
    pub target: Vec3,
    /// units: radians
    pub vfov_rad: f32,
    /// units: m
    pub near_m: f32,
    /// units: m
    pub far_m: f32,
}

impl From<&CameraConfig> for Camera {
    fn from(c: &CameraConfig) -> Self {
        Self {
            position: Vec3::from(c.position_m),
            target: Vec3::from(c.target_m),
            vfov_rad: c.vfov_deg.to_radians(),
            near_m: c.near_m,
            far_m: c.far_m,
        }
    }
}

impl Camera {
    /// World → view transform (right-handed, z up in the world).
    pub fn view_from_world(&self) -> Mat4 {
        Mat4::look_at_rh(self.position, self.target, Vec3::Z)
    }

    /// View → clip (wgpu depth range 0..1).
    pub fn clip_from_view(&self, aspect: f32) -> Mat4 {
        Mat4::perspective_rh(self.vfov_rad, aspect, self.near_m, self.far_m)
    }

    /// World → clip.
    pub fn clip_from_world(&self, aspect: f32) -> Mat4 {
        self.clip_from_view(aspect) * self.view_from_world()
    }

    /// Pixel (column, row from the top) where a world point lands, or None
    /// behind the camera.
    pub fn project_to_pixel(&self, p: Vec3, width: u32, height: u32) -> Option<(f32, f32)> {
        let c = self.clip_from_world(width as f32 / height as f32) * p.extend(1.0);
        if c.w <= 0.0 {
            return None;
        }
        let ndc = c.truncate() / c.w;
        Some((
            (ndc.x * 0.5 + 0.5) * width as f32,
            (0.5 - ndc.y * 0.5) * height as f32,
        ))
    }
}
