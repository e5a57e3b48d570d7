//! The sky-view table (Hillaire 2020, §5.3): the sky's radiance over
//! (azimuth from the sun, elevation) for one sun position, from the
//! transmittance and Ψ_ms tables (src/sky/luts.rs), and what the renderer
//! reads of it (`SkyLight`; WGSL twin `sky_color` in shaders/common.wgsl).
//!
//! Each texel keeps three parts: single-scattered Rayleigh and Mie light
//! per unit phase, times their phase functions of the angle to the sun
//! per pixel (so the Mie glow around the sun stays sharp in a small
//! table; Hillaire bakes the phase into a 192 × 108 table instead), and
//! the multiple-scattered light, isotropic. Azimuth runs from toward the
//! sun (0) to away from it (π), the sky being symmetric about the sun's
//! vertical plane; elevation is non-linear, el = π/2 · x², dense near the
//! horizon where the sky changes fastest (Hillaire's mapping, upper half).

use glam::{DVec3, Vec3};

use super::{AirTable, Atmosphere, SUN_ABOVE_AIR, SkyLuts};

/// Azimuths of the sky-view table, 0 to π from the sun (12° apart).
/// The WGSL prelude (src/gpu/shaders/mod.rs) writes it into the shaders.
pub const SKY_AZIMUTHS: usize = 16;
/// Elevations of the sky-view table, at el = π/2 · (k/(N−1))².
pub const SKY_ELEVATIONS: usize = 16;
/// Texels of the sky-view table, elevation-major: texel e·SKY_AZIMUTHS + a.
pub const SKY_TEXELS: usize = SKY_AZIMUTHS * SKY_ELEVATIONS;

/// What the renderer needs of the sky for one sun position, in its units
/// (linear RGB radiance; the sun colour as `Sun::color`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkyLight {
    /// The sun's colour after the air between it and the ground.
    pub sun: Vec3,
    /// Single-scattered Rayleigh radiance per unit Rayleigh phase, per
    /// sky-view texel ([`SKY_TEXELS`]).
    pub rayleigh: [Vec3; SKY_TEXELS],
    /// Single-scattered Mie radiance per unit Mie phase, same texels.
    pub mie: [Vec3; SKY_TEXELS],
    /// Multiple-scattered radiance (Ψ_ms, isotropic), same texels.
    pub multiple: [Vec3; SKY_TEXELS],
    /// Irradiance of the sky on an up-facing surface over π (its
    /// cosine-weighted mean radiance): the ambient light.
    pub ambient: Vec3,
    /// The same for a down-facing surface, from the sky's lower half as
    /// the sky pass draws it (the horizon's radiance darkening toward the
    /// ground haze): the light under clouds with no terrain below them.
    pub below: Vec3,
    /// Asymmetry of the Mie phase.
    pub mie_g: f32,
    /// The air over height, for the aerial perspective (src/sky/air.rs).
    pub air: AirTable,
}

/// Direction of texel (azimuth `a`, elevation `e`), azimuth from +y.
fn texel_direction(a: usize, e: usize) -> DVec3 {
    let x = e as f64 / (SKY_ELEVATIONS - 1) as f64;
    let el = std::f64::consts::FRAC_PI_2 * x * x;
    let az = std::f64::consts::PI * a as f64 / (SKY_AZIMUTHS - 1) as f64;
    DVec3::new(az.sin() * el.cos(), az.cos() * el.cos(), el.sin())
}

impl SkyLuts {
    /// The sky for a sun at `elevation_rad`, its light scaled by
    /// `strength` (the renderer's fade at dusk; 1 in daylight).
    pub fn sky_light(&self, elevation_rad: f64, strength: f64) -> SkyLight {
        let a = &self.atmosphere;
        let sun = DVec3::new(0.0, elevation_rad.cos(), elevation_rad.sin());
        // The renderer's sun irradiance is 4π times its colour.
        let scale = SUN_ABOVE_AIR * 4.0 * std::f64::consts::PI * strength;
        let sun_color = self.transmittance.at(a.ground_radius_m, sun.z) * SUN_ABOVE_AIR * strength;
        let mut light = SkyLight {
            sun: sun_color.as_vec3(),
            rayleigh: [Vec3::ZERO; SKY_TEXELS],
            mie: [Vec3::ZERO; SKY_TEXELS],
            multiple: [Vec3::ZERO; SKY_TEXELS],
            ambient: Vec3::ZERO,
            below: Vec3::ZERO,
            mie_g: a.mie_g as f32,
            air: self.air_table(sun.z, scale),
        };
        for e in 0..SKY_ELEVATIONS {
            for az in 0..SKY_AZIMUTHS {
                let [r, m, ms] = self.scattered(texel_direction(az, e), sun);
                let k = e * SKY_AZIMUTHS + az;
                light.rayleigh[k] = (r * scale).as_vec3();
                light.mie[k] = (m * scale).as_vec3();
                light.multiple[k] = (ms * scale).as_vec3();
            }
        }
        light.ambient = light.mean_cosine_radiance(sun.as_vec3(), true);
        light.below = light.mean_cosine_radiance(sun.as_vec3(), false);
        light
    }

    /// Light scattered toward the eye along unit `view` per unit sun
    /// irradiance, from the tables: [Rayleigh, Mie (both per unit phase),
    /// multiple].
    pub fn scattered(&self, view: DVec3, sun: DVec3) -> [DVec3; 3] {
        self.atmosphere.scattered_along(
            view,
            sun,
            |r, mu| self.transmittance.at(r, mu),
            |r, mu| self.multiple.at(r, mu),
        )
    }
}

impl Atmosphere {
    /// The sky for a sun at `elevation_rad` (builds this atmosphere's
    /// tables first; the renderer's sun keeps its tables instead,
    /// src/sky/sun_light.rs).
    pub fn sky_light(&self, elevation_rad: f64, strength: f64) -> SkyLight {
        SkyLuts::new(self).sky_light(elevation_rad, strength)
    }
}

impl SkyLight {
    /// Sky radiance toward unit `dir` for the sun toward unit `sun`; the
    /// CPU twin of `sky_color` in shaders/common.wgsl and of benches/
    /// pathtraced.py's (tests `sky::aerial::sky_pass_draws_the_cpu_twin_of_sky_color`
    /// and `render::pathtraced::the_path_tracer_s_tone_curve_and_sky_are_the_renderer_s`
    /// compare them): the table bilinear in (azimuth from the
    /// sun, √(elevation)), the single-scattered parts times their phase,
    /// plus the multiple-scattered part; below the horizon the horizon's
    /// radiance, darkening by up to 40% toward the ground haze.
    pub fn radiance(&self, dir: Vec3, sun: Vec3) -> Vec3 {
        use std::f32::consts::{FRAC_PI_2, PI};
        let el = dir.z.clamp(0.0, 1.0).asin();
        let y = (el / FRAC_PI_2).sqrt() * (SKY_ELEVATIONS - 1) as f32;
        let e = (y as usize).min(SKY_ELEVATIONS - 2);
        let fe = y - e as f32;
        let lens = dir.truncate().length() * sun.truncate().length();
        let cos_az = if lens > 1e-6 {
            dir.truncate().dot(sun.truncate()) / lens
        } else {
            1.0
        };
        let x = cos_az.clamp(-1.0, 1.0).acos() / PI * (SKY_AZIMUTHS - 1) as f32;
        let a = (x as usize).min(SKY_AZIMUTHS - 2);
        let fa = x - a as f32;
        let at = |t: &[Vec3; SKY_TEXELS]| {
            let k = e * SKY_AZIMUTHS + a;
            let lo = t[k].lerp(t[k + 1], fa);
            let hi = t[k + SKY_AZIMUTHS].lerp(t[k + SKY_AZIMUTHS + 1], fa);
            lo.lerp(hi, fe)
        };
        let mu = dir.dot(sun);
        let c = at(&self.rayleigh) * super::rayleigh_phase(mu)
            + at(&self.mie) * super::mie_phase(mu, self.mie_g)
            + at(&self.multiple);
        c * (1.0 - 0.4 * (-3.0 * dir.z).clamp(0.0, 1.0))
    }

    /// (1/π)∫ L |cosθ| dω over the upper hemisphere (`up`) or the lower
    /// one, by quadrature.
    pub fn mean_cosine_radiance(&self, sun: Vec3, up: bool) -> Vec3 {
        const N_EL: u32 = 24;
        const N_AZ: u32 = 48;
        let mut sum = Vec3::ZERO;
        for i in 0..N_EL {
            // Uniform in sin²(elevation): cosθ dω = ½ d(sin²) dφ.
            let u = (i as f32 + 0.5) / N_EL as f32;
            let (sin_el, cos_el) = (u.sqrt(), (1.0 - u).sqrt());
            for j in 0..N_AZ {
                let az = std::f32::consts::TAU * (j as f32 + 0.5) / N_AZ as f32;
                let z = if up { sin_el } else { -sin_el };
                let dir = Vec3::new(az.sin() * cos_el, az.cos() * cos_el, z);
                sum += self.radiance(dir, sun);
            }
        }
        // ∫ L cosθ dω = π · mean over the (u, φ) grid.
        sum / (N_EL * N_AZ) as f32
    }
}
