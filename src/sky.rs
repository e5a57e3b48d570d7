//! The sky from an atmosphere model: the colour of the sun after the air it
//! crosses, the sky's radiance in every direction and the light the whole
//! sky sheds on an up-facing surface, for a sun at a given elevation. Pure
//! CPU arithmetic (no GPU, no physics): the renderer computes it once per
//! sun position and uploads it in the frame uniform (`SkyLight`, read by
//! `sky_color` and `sky_ambient` in shaders/common.wgsl).
//!
//! Model: single scattering in a spherical, layered atmosphere (Nishita et
//! al. 1993, "Display of the Earth taking into account atmospheric
//! scattering"), with the Earth parameters of Bruneton's 2017 reference
//! implementation that Hillaire (2020, "A scalable and production ready sky
//! and atmosphere rendering technique") also uses: Rayleigh scattering
//! (scale height 8 km), Mie scattering and absorption (1.2 km, Cornette–
//! Shanks phase with g = 0.8) and an ozone layer (a tent 25 ± 15 km) that
//! only absorbs. The RGB channels stand for 680, 550 and 440 nm.
//! Not modelled: multiple scattering in the air (it would brighten the sky,
//! most at low sun, by some tens of percent), ground reflection, the sun's
//! spectrum (the sun above the air is white).
//!
//! The sky's radiance splits into a phase-free in-scattered part per
//! species, which depends on the view's elevation (and, through the Earth's
//! curvature, a little on its azimuth, averaged out here), times the phase
//! of the angle to the sun, which the shader evaluates per pixel:
//! L(v) = P_R(v·s)·R(elev v) + P_M(v·s)·M(elev v). R and M are tabulated at
//! [`SKY_KNOTS`] view elevations, denser near the horizon.

use glam::{DVec3, Vec3};

/// View elevations of the sky table: knot k at sin(elevation) = (k/(N−1))².
/// Keep in sync with `SKY_KNOTS` in the WGSL prelude (src/render/shaders.rs).
pub const SKY_KNOTS: usize = 16;

/// The sun's colour above the atmosphere, in the renderer's units (linear
/// RGB; the cloud march's irradiance is 4π times it, see
/// src/export/sidecar.rs). White, and chosen so that the sun at 60°
/// elevation, (2.3, 2.1, 1.8), matches the fixed sun the renderer had before
/// the sky model (2.2, 2.1, 2.0).
pub const SUN_ABOVE_AIR: f64 = 2.5;

/// A layered atmosphere over a spherical ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Atmosphere {
    /// units: m
    pub ground_radius_m: f64,
    /// Radius of the top of the atmosphere. units: m
    pub top_radius_m: f64,
    /// Rayleigh scattering at sea level (R, G, B = 680, 550, 440 nm). units: 1/m
    pub rayleigh_scattering_per_m: DVec3,
    /// units: m
    pub rayleigh_scale_height_m: f64,
    /// Mie scattering at sea level (grey). units: 1/m
    pub mie_scattering_per_m: f64,
    /// Mie extinction (scattering + absorption) at sea level. units: 1/m
    pub mie_extinction_per_m: f64,
    /// units: m
    pub mie_scale_height_m: f64,
    /// Asymmetry g of the Cornette–Shanks phase of the aerosols.
    pub mie_g: f64,
    /// Ozone absorption at the layer's peak. units: 1/m
    pub ozone_absorption_per_m: DVec3,
    /// Height of the ozone peak. units: m
    pub ozone_centre_m: f64,
    /// Half width of the ozone tent (density 0 this far from the peak). units: m
    pub ozone_half_width_m: f64,
}

impl Atmosphere {
    /// The Earth (Bruneton 2017, `demo.cc`; Hillaire 2020, table 1).
    pub const EARTH: Self = Self {
        ground_radius_m: 6_360_000.0,
        top_radius_m: 6_460_000.0,
        rayleigh_scattering_per_m: DVec3::new(5.802e-6, 13.558e-6, 33.1e-6),
        rayleigh_scale_height_m: 8_000.0,
        mie_scattering_per_m: 3.996e-6,
        mie_extinction_per_m: 4.440e-6,
        mie_scale_height_m: 1_200.0,
        mie_g: 0.8,
        ozone_absorption_per_m: DVec3::new(0.650e-6, 1.881e-6, 0.085e-6),
        ozone_centre_m: 25_000.0,
        ozone_half_width_m: 15_000.0,
    };

    /// Relative densities (Rayleigh, Mie, ozone) at height `h_m`.
    fn densities(&self, h_m: f64) -> (f64, f64, f64) {
        let ozone = (1.0 - (h_m - self.ozone_centre_m).abs() / self.ozone_half_width_m).max(0.0);
        (
            (-h_m / self.rayleigh_scale_height_m).exp(),
            (-h_m / self.mie_scale_height_m).exp(),
            ozone,
        )
    }

    /// Extinction at height `h_m`. units: 1/m
    fn extinction(&self, h_m: f64) -> DVec3 {
        let (r, m, o) = self.densities(h_m);
        self.rayleigh_scattering_per_m * r
            + DVec3::splat(self.mie_extinction_per_m * m)
            + self.ozone_absorption_per_m * o
    }

    /// Distance from radius `r_m` along a ray with cosine `mu` to the
    /// vertical to the top of the atmosphere, or None when the ray meets
    /// the ground first. units: m
    fn distance_to_top(&self, r_m: f64, mu: f64) -> Option<f64> {
        let disc_ground = r_m * r_m * (mu * mu - 1.0) + self.ground_radius_m * self.ground_radius_m;
        if mu < 0.0 && disc_ground >= 0.0 {
            return None;
        }
        let disc_top = r_m * r_m * (mu * mu - 1.0) + self.top_radius_m * self.top_radius_m;
        Some((-r_m * mu + disc_top.max(0.0).sqrt()).max(0.0))
    }

    /// Optical depth from height `h_m` to space along a ray whose cosine
    /// to the vertical is `mu`; None when the ground is in the way.
    /// Midpoint rule in s with t = T·s² (steps short near the start, where
    /// the air is densest), `steps` samples.
    pub fn optical_depth(&self, h_m: f64, mu: f64, steps: u32) -> Option<DVec3> {
        let r = self.ground_radius_m + h_m;
        let length = self.distance_to_top(r, mu)?;
        let mut sum = DVec3::ZERO;
        for i in 0..steps {
            let s = (i as f64 + 0.5) / steps as f64;
            let t = length * s * s;
            let dt = 2.0 * length * s / steps as f64;
            let height = (r * r + t * t + 2.0 * r * mu * t).sqrt() - self.ground_radius_m;
            sum += self.extinction(height) * dt;
        }
        Some(sum)
    }

    /// Transmittance of the air from the ground to the sun at
    /// `elevation_rad` (0 when the sun is below the horizon).
    pub fn sun_transmittance(&self, elevation_rad: f64) -> DVec3 {
        self.optical_depth(0.0, elevation_rad.sin(), SUN_STEPS)
            .map_or(DVec3::ZERO, |od| (-od).exp())
    }

    /// Phase-free single-scattered sky radiance toward unit `view` from
    /// the ground (x, y horizontal, z up), per unit irradiance of a sun
    /// toward unit `sun`: (Rayleigh, Mie) parts, each to be multiplied by
    /// its phase function of view·sun. units: 1/sr per 1/sr of phase.
    pub fn inscattering(&self, view: DVec3, sun: DVec3) -> (DVec3, DVec3) {
        let origin = DVec3::new(0.0, 0.0, self.ground_radius_m + 1.0);
        let Some(length) = self.distance_to_top(origin.z, view.z) else {
            return (DVec3::ZERO, DVec3::ZERO);
        };
        let (mut rayleigh, mut mie) = (DVec3::ZERO, DVec3::ZERO);
        let mut depth = DVec3::ZERO;
        let mut t_prev = 0.0;
        for i in 0..VIEW_STEPS {
            let s = (i as f64 + 0.5) / VIEW_STEPS as f64;
            let t = length * s * s;
            let dt = 2.0 * length * s / VIEW_STEPS as f64;
            let p = origin + view * t;
            let r = p.length();
            let h = r - self.ground_radius_m;
            // Optical depth from the eye to this sample (midpoint sums).
            depth += self.extinction(h) * (t - t_prev);
            t_prev = t;
            let Some(to_sun) = self.optical_depth(h, p.dot(sun) / r, SUN_STEPS) else {
                continue;
            };
            let (dr, dm, _) = self.densities(h);
            let w = (-(depth + to_sun)).exp() * dt;
            rayleigh += self.rayleigh_scattering_per_m * dr * w;
            mie += DVec3::splat(self.mie_scattering_per_m * dm) * w;
        }
        (rayleigh, mie)
    }

    /// The sky for a sun at `elevation_rad`, its light scaled by `strength`
    /// (the renderer's fade at dusk; 1 in daylight).
    pub fn sky_light(&self, elevation_rad: f64, strength: f64) -> SkyLight {
        let sun = DVec3::new(0.0, elevation_rad.cos(), elevation_rad.sin());
        let scale = SUN_ABOVE_AIR * 4.0 * std::f64::consts::PI * strength;
        let mut light = SkyLight {
            sun: (self.sun_transmittance(elevation_rad) * SUN_ABOVE_AIR * strength).as_vec3(),
            rayleigh: [Vec3::ZERO; SKY_KNOTS],
            mie: [Vec3::ZERO; SKY_KNOTS],
            ambient: Vec3::ZERO,
            mie_g: self.mie_g as f32,
        };
        for k in 0..SKY_KNOTS {
            let x = k as f64 / (SKY_KNOTS - 1) as f64;
            let (sin_el, cos_el) = (x * x, (1.0 - x * x * x * x).max(0.0).sqrt());
            let (mut r, mut m) = (DVec3::ZERO, DVec3::ZERO);
            // Averaged over the view's azimuth relative to the sun.
            for a in 0..AZIMUTHS {
                let az = std::f64::consts::TAU * (a as f64 + 0.5) / AZIMUTHS as f64;
                let view = DVec3::new(az.sin() * cos_el, az.cos() * cos_el, sin_el);
                let (ra, ma) = self.inscattering(view, sun);
                r += ra;
                m += ma;
            }
            light.rayleigh[k] = (r * scale / AZIMUTHS as f64).as_vec3();
            light.mie[k] = (m * scale / AZIMUTHS as f64).as_vec3();
        }
        light.ambient = light.mean_cosine_radiance(sun.as_vec3());
        light
    }
}

/// Samples of one optical depth toward the sun.
const SUN_STEPS: u32 = 32;
/// Samples along one view ray of the sky table.
const VIEW_STEPS: u32 = 32;
/// View azimuths averaged per knot of the sky table.
const AZIMUTHS: u32 = 4;

/// Rayleigh phase function. units: 1/sr
pub fn rayleigh_phase(mu: f32) -> f32 {
    3.0 / (16.0 * std::f32::consts::PI) * (1.0 + mu * mu)
}

/// Cornette–Shanks phase function (Mie). units: 1/sr
pub fn mie_phase(mu: f32, g: f32) -> f32 {
    let g2 = g * g;
    3.0 / (8.0 * std::f32::consts::PI) * (1.0 - g2) * (1.0 + mu * mu)
        / ((2.0 + g2) * (1.0 + g2 - 2.0 * g * mu).max(1e-6).powf(1.5))
}

/// What the renderer needs of the sky for one sun position, in its units
/// (linear RGB radiance; the sun colour as `Sun::color`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkyLight {
    /// The sun's colour after the air between it and the ground.
    pub sun: Vec3,
    /// Rayleigh part of the sky radiance per unit Rayleigh phase, at the
    /// view elevations of [`SKY_KNOTS`].
    pub rayleigh: [Vec3; SKY_KNOTS],
    /// Mie part per unit Mie phase, same knots.
    pub mie: [Vec3; SKY_KNOTS],
    /// Irradiance of the sky on an up-facing surface over π (its
    /// cosine-weighted mean radiance): the ambient light.
    pub ambient: Vec3,
    /// Asymmetry of the Mie phase.
    pub mie_g: f32,
}

impl SkyLight {
    /// Sky radiance toward unit `dir` for the sun toward unit `sun`; the
    /// CPU twin of `sky_color` in shaders/common.wgsl (keep in sync):
    /// the table at the view's elevation (linear between knots), each part
    /// times its phase; below the horizon the horizon's radiance, darkening
    /// by up to 40% toward the ground haze.
    pub fn radiance(&self, dir: Vec3, sun: Vec3) -> Vec3 {
        let x = dir.z.clamp(0.0, 1.0).sqrt() * (SKY_KNOTS - 1) as f32;
        let k = (x.floor() as usize).min(SKY_KNOTS - 2);
        let f = x - k as f32;
        let r = self.rayleigh[k].lerp(self.rayleigh[k + 1], f);
        let m = self.mie[k].lerp(self.mie[k + 1], f);
        let mu = dir.dot(sun);
        let c = r * rayleigh_phase(mu) + m * mie_phase(mu, self.mie_g);
        c * (1.0 - 0.4 * (-3.0 * dir.z).clamp(0.0, 1.0))
    }

    /// (1/π)∫ L cosθ dω over the upper hemisphere, by quadrature.
    fn mean_cosine_radiance(&self, sun: Vec3) -> Vec3 {
        const N_EL: u32 = 24;
        const N_AZ: u32 = 48;
        let mut sum = Vec3::ZERO;
        for i in 0..N_EL {
            // Uniform in sin²(elevation): cosθ dω = ½ d(sin²) dφ.
            let u = (i as f32 + 0.5) / N_EL as f32;
            let (sin_el, cos_el) = (u.sqrt(), (1.0 - u).sqrt());
            for j in 0..N_AZ {
                let az = std::f32::consts::TAU * (j as f32 + 0.5) / N_AZ as f32;
                let dir = Vec3::new(az.sin() * cos_el, az.cos() * cos_el, sin_el);
                sum += self.radiance(dir, sun);
            }
        }
        // ∫ L cosθ dω = π · mean over the (u, φ) grid.
        sum / (N_EL * N_AZ) as f32
    }
}
