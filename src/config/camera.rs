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

    /// World offset from the eye → clip: `clip_from_world` without the
    /// eye's translation, whose inverse gives view rays at full precision
    /// far from the world's origin.
    pub fn clip_from_eye(&self, aspect: f32) -> Mat4 {
        self.clip_from_view(aspect)
            * Mat4::look_at_rh(Vec3::ZERO, self.target - self.position, Vec3::Z)
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

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DVec3, Vec4};

    /// The view ray through a pixel, in f64 from the camera's basis: the
    /// truth the shaders' `view_dir` approximates in f32.
    fn exact_dir(c: &Camera, aspect: f64, ndc: (f64, f64)) -> DVec3 {
        let f = (c.target - c.position).as_dvec3().normalize();
        let r = f.cross(DVec3::Z).normalize();
        let u = r.cross(f);
        let t = (0.5 * c.vfov_rad as f64).tan();
        (f + r * (ndc.0 * t * aspect) + u * (ndc.1 * t)).normalize()
    }

    /// View rays 18 km from the world's origin (the landscape's camera):
    /// through `clip_from_eye` they are exact to f32 (under 10⁻⁶ rad,
    /// tolerance: a few ulps of a unit vector), while through the inverse
    /// of `clip_from_world`, a point 2 m out minus an eye 18 km out, they
    /// are off by ~10⁻³ rad, a tenth of a pixel at 108 rows: the
    /// temporal history resampled at that offset every frame drifted from
    /// the full march. The second assertion shows the test can tell.
    #[test]
    fn view_rays_keep_their_precision_far_from_the_origin() {
        let cam = Camera {
            position: Vec3::new(-2000.0, -18000.0, 900.0),
            target: Vec3::new(3000.0, 10000.0, 2500.0),
            vfov_rad: 50f32.to_radians(),
            near_m: 1.0,
            far_m: 150_000.0,
        };
        let aspect = 16.0 / 9.0;
        let eye_from_clip = cam.clip_from_eye(aspect).inverse();
        let world_from_clip = cam.clip_from_world(aspect).inverse();
        let (mut relative, mut absolute) = (0.0f64, 0.0f64);
        for i in 0..=20 {
            for j in 0..=20 {
                let ndc = (i as f32 / 10.0 - 1.0, j as f32 / 10.0 - 1.0);
                let truth = exact_dir(&cam, aspect as f64, (ndc.0 as f64, ndc.1 as f64));
                let h = eye_from_clip * Vec4::new(ndc.0, ndc.1, 0.5, 1.0);
                let d = (h.truncate() / h.w).normalize().as_dvec3();
                relative = relative.max(d.angle_between(truth));
                let h = world_from_clip * Vec4::new(ndc.0, ndc.1, 0.5, 1.0);
                let d = (h.truncate() / h.w - cam.position).normalize().as_dvec3();
                absolute = absolute.max(d.angle_between(truth));
            }
        }
        assert!(
            relative < 1e-6,
            "camera-relative rays off by {relative:e} rad"
        );
        assert!(absolute > 1e-4, "world rays off by only {absolute:e} rad");
    }
}
