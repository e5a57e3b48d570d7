//! Aerial perspective: the light the air between the eye and a cloud or
//! a hill scatters toward the eye, and how much of the object's own light
//! that air lets through. The same air and the same source term as the sky
//! ([`super::Medium::source`]), so a far hill fades toward the horizon
//! sky's own colour: blue where Rayleigh scattering dominates, whiter with
//! the aerosols near the ground, red-grey at a low sun.
//!
//! The renderer gets one small table per sun position (Hillaire 2020 keeps
//! a camera-frustum volume instead): for heights h_k = [`AIR_TOP_M`] ·
//! (k/(N−1))², dense near the ground where the aerosols are, the air's
//! extinction and what it scatters per metre, in three parts like the sky
//! view (Rayleigh and Mie per unit phase, multiple isotropic). In the flat
//! approximation of the sun's direction (its zenith angle changes by 0.9°
//! over 100 km) this depends on height alone. A ray then marches
//! [`AIR_STEPS`] steps from the eye to the object through that table
//! (shaders/air.wgsl `aerial_perspective`, CPU twin [`SkyLight::aerial`]),
//! each step's medium constant and integrated exactly (the in-scattering of
//! a homogeneous slab), the ray's height following the Earth's curve.
//! The clouds' shadow reaches the air where a pass has the cloud-shadow
//! map (the terrain): shadowed air scatters no sunlight, only its share of
//! the multiply scattered light. tests/cumulus/sky/aerial.rs holds it against direct
//! integration of the sky model.

use glam::{DVec3, Vec3};

use super::{SkyLight, SkyLuts, mie_phase, rayleigh_phase};

/// Heights of the air table (the WGSL prelude, src/gpu/shaders/mod.rs,
/// writes it into the shaders).
pub const AIR_HEIGHTS: usize = 24;
/// Height of the table's top node; the air above reads as the top's (the
/// clouds stay below 16 km, so rays to them never leave the table). units: m
pub const AIR_TOP_M: f32 = 20_000.0;
/// Steps of the march from the eye to the object (shaders/air.wgsl).
pub const AIR_STEPS: u32 = 8;

/// Radius of the Earth for the ray's height (the sky model's). units: m
const EARTH_RADIUS_M: f32 = 6_360_000.0;

/// The air over height for one sun position, in the renderer's units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AirTable {
    /// Node k sits at [`AirTable::height_m`]`(k)`: [Rayleigh scattered
    /// per metre per unit phase, Mie per unit phase, multiple scattered
    /// (isotropic), extinction (1/m)].
    pub nodes: [[Vec3; 4]; AIR_HEIGHTS],
}

/// What the air along a view ray does to what lies at its end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Air {
    /// Radiance the air adds (linear RGB).
    pub light: Vec3,
    /// Fraction of the object's radiance that arrives.
    pub transmittance: Vec3,
}

impl AirTable {
    /// Height of node `k`. units: m
    pub fn height_m(k: usize) -> f32 {
        let x = k as f32 / (AIR_HEIGHTS - 1) as f32;
        AIR_TOP_M * x * x
    }

    /// The four parts at height `h_m`, linear between the nodes (clamped
    /// to the table).
    fn at(&self, h_m: f32) -> [Vec3; 4] {
        let x = (h_m / AIR_TOP_M).clamp(0.0, 1.0).sqrt() * (AIR_HEIGHTS - 1) as f32;
        let k = (x as usize).min(AIR_HEIGHTS - 2);
        let f = x - k as f32;
        std::array::from_fn(|i| self.nodes[k][i].lerp(self.nodes[k + 1][i], f))
    }
}

/// Height above the ground at distance `t` along a ray from height `eye_m`
/// whose cosine to the vertical is `mu`: the exact √(r² + 2rμt + t²) − R
/// to second order in t/R (off by < 10 m at 200 km), which f32 keeps.
pub fn ray_height_m(eye_m: f32, mu: f32, t: f32) -> f32 {
    eye_m + mu * t + t * t * (1.0 - mu * mu) / (2.0 * (EARTH_RADIUS_M + eye_m))
}

impl SkyLuts {
    /// The air table for a sun with cosine `sun_z` to the vertical, its
    /// irradiance `scale` times the unit of [`SkyLuts::scattered`].
    pub(super) fn air_table(&self, sun_z: f64, scale: f64) -> AirTable {
        let a = &self.atmosphere;
        let mut nodes = [[Vec3::ZERO; 4]; AIR_HEIGHTS];
        for (k, node) in nodes.iter_mut().enumerate() {
            let h = AirTable::height_m(k) as f64;
            let r = a.ground_radius_m + h;
            let medium = a.medium(h);
            let source = medium.source(
                r,
                sun_z,
                |r, mu| self.transmittance.at(r, mu),
                |r, mu| self.multiple.at(r, mu),
            );
            for (n, s) in node.iter_mut().zip(source) {
                *n = (s * scale).as_vec3();
            }
            node[3] = medium.extinction.as_vec3();
        }
        AirTable { nodes }
    }

    /// The air's light and transmittance over `dist_m` along unit `dir`
    /// from an eye at height `eye_m`, by direct integration of the sky
    /// model (`steps` samples, the Earth round, the sun's transmittance
    /// from the table at every sample): the reference of
    /// [`SkyLight::aerial`]. The sun (unit `sun`) at unit irradiance.
    pub fn aerial_reference(
        &self,
        eye_m: f64,
        dir: DVec3,
        dist_m: f64,
        sun: DVec3,
        steps: u32,
    ) -> (Vec3, Vec3) {
        let a = &self.atmosphere;
        let ([rayleigh, mie, multiple], transmittance) = a.scattered_segment(
            eye_m,
            dir,
            dist_m,
            steps,
            sun,
            |r, mu| self.transmittance.at(r, mu),
            |r, mu| self.multiple.at(r, mu),
        );
        let mu = dir.dot(sun) as f32;
        let light = rayleigh.as_vec3() * rayleigh_phase(mu)
            + mie.as_vec3() * mie_phase(mu, a.mie_g as f32)
            + multiple.as_vec3();
        (light, transmittance.as_vec3())
    }
}

impl SkyLight {
    /// What the air does over `dist_m` along unit `dir` from an eye at
    /// height `eye_m`, the sun toward unit `sun`: the CPU twin of
    /// `aerial_perspective` in shaders/air.wgsl (tests/cumulus/sky/aerial.rs
    /// compares the terrain pass against it).
    pub fn aerial(&self, eye_m: f32, dir: Vec3, dist_m: f32, sun: Vec3) -> Air {
        self.aerial_shadowed(eye_m, dir, dist_m, sun, |_| 1.0)
    }

    /// [`SkyLight::aerial`] with the clouds' shadow in the air:
    /// `sunlit(t)` is the share of the sun's light reaching the air `t`
    /// metres from the eye (`sunlit` of `air_step` in shaders/air.wgsl); it scales
    /// the single-scattered parts.
    pub fn aerial_shadowed(
        &self,
        eye_m: f32,
        dir: Vec3,
        dist_m: f32,
        sun: Vec3,
        sunlit: impl Fn(f32) -> f32,
    ) -> Air {
        let mu = dir.dot(sun);
        let (pr, pm) = (rayleigh_phase(mu), mie_phase(mu, self.mie_g));
        let dt = dist_m / AIR_STEPS as f32;
        let eye = eye_m.max(0.0);
        let mut air = Air {
            light: Vec3::ZERO,
            transmittance: Vec3::ONE,
        };
        for i in 0..AIR_STEPS {
            let t = (i as f32 + 0.5) * dt;
            let [r, m, ms, ext] = self.air.at(ray_height_m(eye, dir.z, t));
            let source = (r * pr + m * pm) * sunlit(t) + ms;
            let step = (-ext * dt).exp();
            // A homogeneous slab: ∫₀^dt σ_s e^{−σ_t s} ds = σ_s (1 − e^{−σ_t dt}) / σ_t.
            air.light +=
                air.transmittance * source * (Vec3::ONE - step) / ext.max(Vec3::splat(1e-12));
            air.transmittance *= step;
        }
        air
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nodes_run_from_the_ground_to_the_top() {
        assert_eq!(AirTable::height_m(0), 0.0);
        assert_eq!(AirTable::height_m(AIR_HEIGHTS - 1), AIR_TOP_M);
    }

    #[test]
    fn the_ray_height_follows_the_earth_curve() {
        // Horizontal from the ground: the ground falls away as t²/2R
        // (7.9 m at 10 km, 3.1 km at 200 km).
        let h = ray_height_m(0.0, 0.0, 200_000.0);
        assert!((h - 200_000.0f32.powi(2) / (2.0 * EARTH_RADIUS_M)).abs() < 1.0);
        // Straight up: the distance itself.
        assert_eq!(ray_height_m(100.0, 1.0, 5000.0), 5100.0);
    }
}
