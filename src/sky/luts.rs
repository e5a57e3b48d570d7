//! The tables of the sky that depend only on the atmosphere (Hillaire
//! 2020, §5.1 and §5.5): transmittance to space and multiple scattering
//! Ψ_ms. Built once per atmosphere on the CPU (rayon over rows) and read
//! by the sky-view table each time the sun moves (src/sky/view.rs).

use glam::DVec3;
use rayon::prelude::*;

use super::{Atmosphere, SUN_STEPS};

/// Transmittance table size: view zenith cosine × height (Hillaire uses
/// 256 × 64 on the GPU; the CPU's bilinear lookups need fewer, see
/// tests/cumulus/sky/model.rs for the error against direct integration).
pub const TRANSMITTANCE_SIZE: [usize; 2] = [128, 32];
/// Multiple-scattering table size: sun zenith cosine × height (Hillaire:
/// 32 × 32).
pub const MULTIPLE_SCATTERING_SIZE: [usize; 2] = [32, 32];
/// Directions per texel of Ψ_ms (Hillaire: 64), as a square grid over
/// (cos θ, φ): uniform in solid angle (half of them integrated, by symmetry).
const MS_DIRECTIONS_SQRT: u32 = 8;
/// Samples along one ray of Ψ_ms.
const MS_STEPS: u32 = 20;

/// Bilinear lookup in a row-major table of `size[0]` × `size[1]` nodes at
/// unit coordinates (x, y), nodes on the edges, clamped.
fn bilinear(table: &[DVec3], size: [usize; 2], x: f64, y: f64) -> DVec3 {
    let fx = x.clamp(0.0, 1.0) * (size[0] - 1) as f64;
    let fy = y.clamp(0.0, 1.0) * (size[1] - 1) as f64;
    let (i, j) = (
        (fx as usize).min(size[0] - 2),
        (fy as usize).min(size[1] - 2),
    );
    let (u, v) = (fx - i as f64, fy - j as f64);
    let at = |i: usize, j: usize| table[j * size[0] + i];
    (at(i, j) * (1.0 - u) + at(i + 1, j) * u) * (1.0 - v)
        + (at(i, j + 1) * (1.0 - u) + at(i + 1, j + 1) * u) * v
}

/// Transmittance to the top of the atmosphere from radius r along a ray
/// with cosine μ to the vertical, for rays that miss the ground, in
/// Bruneton's (2017) parameterisation: x_r = ρ/H and x_μ = (d − d_min)/
/// (d_max − d_min), with ρ = √(r² − R_g²), H = √(R_t² − R_g²), d the
/// distance to the top and d_min = R_t − r, d_max = ρ + H; dense where
/// the transmittance changes fast (near the horizon, near the ground).
#[derive(Debug, Clone)]
pub struct TransmittanceLut {
    atmosphere: Atmosphere,
    table: Vec<DVec3>,
}

impl TransmittanceLut {
    pub fn new(atmosphere: &Atmosphere) -> Self {
        let a = *atmosphere;
        let [nx, ny] = TRANSMITTANCE_SIZE;
        let h = (a.top_radius_m.powi(2) - a.ground_radius_m.powi(2)).sqrt();
        let table = (0..ny)
            .into_par_iter()
            .flat_map_iter(|j| {
                let rho = h * j as f64 / (ny - 1) as f64;
                let r = (rho * rho + a.ground_radius_m.powi(2)).sqrt();
                (0..nx).map(move |i| {
                    let (d_min, d_max) = (a.top_radius_m - r, rho + h);
                    let d = d_min + (d_max - d_min) * i as f64 / (nx - 1) as f64;
                    let mu = if d <= 0.0 {
                        1.0
                    } else {
                        ((h * h - rho * rho - d * d) / (2.0 * r * d)).clamp(-1.0, 1.0)
                    };
                    (-a.column(r, mu, d, SUN_STEPS)).exp()
                })
            })
            .collect();
        Self {
            atmosphere: a,
            table,
        }
    }

    /// Transmittance to space from radius `r_m` at cosine `mu` to the
    /// vertical; 0 when the ground is in the way (the Earth's shadow).
    pub fn at(&self, r_m: f64, mu: f64) -> DVec3 {
        let a = &self.atmosphere;
        let r = r_m.clamp(a.ground_radius_m, a.top_radius_m);
        let Some(d) = a.distance_to_top(r, mu) else {
            return DVec3::ZERO;
        };
        let h = (a.top_radius_m.powi(2) - a.ground_radius_m.powi(2)).sqrt();
        let rho = (r * r - a.ground_radius_m.powi(2)).max(0.0).sqrt();
        let (d_min, d_max) = (a.top_radius_m - r, rho + h);
        let x_mu = (d - d_min) / (d_max - d_min).max(1e-9);
        bilinear(&self.table, TRANSMITTANCE_SIZE, x_mu, rho / h)
    }
}

/// Ψ_ms of Hillaire 2020 (§5.5, eq. 5–10): the light scattered twice or
/// more into a point, per unit sun irradiance, with an isotropic phase,
/// over (sun zenith cosine μ_s, linear in [−1, 1]) × (height, linear).
/// Second order L_2 = ∫ L′(ω) p_u dω, where L′ is the single-scattered
/// light (isotropic phase) plus the lit ground's reflection reaching the
/// point from ω; the higher orders follow as the geometric series of the
/// fraction f_ms = ∫∫ σ_s T dt p_u dω that the air around scatters back:
/// Ψ_ms = L_2 / (1 − f_ms).
#[derive(Debug, Clone)]
pub struct MultipleScatteringLut {
    atmosphere: Atmosphere,
    table: Vec<DVec3>,
}

impl MultipleScatteringLut {
    pub fn new(atmosphere: &Atmosphere, transmittance: &TransmittanceLut) -> Self {
        let a = *atmosphere;
        let [nx, ny] = MULTIPLE_SCATTERING_SIZE;
        let table = (0..ny)
            .into_par_iter()
            .flat_map_iter(|j| {
                // Just under the top, so that upward rays have some length.
                let height =
                    (a.top_radius_m - a.ground_radius_m - 1.0) * j as f64 / (ny - 1) as f64;
                (0..nx).map(move |i| {
                    let mu_s = -1.0 + 2.0 * i as f64 / (nx - 1) as f64;
                    a.psi_ms(height, mu_s, transmittance)
                })
            })
            .collect();
        Self {
            atmosphere: a,
            table,
        }
    }

    /// Ψ_ms at radius `r_m` with the sun at cosine `mu_s` to the vertical.
    pub fn at(&self, r_m: f64, mu_s: f64) -> DVec3 {
        let a = &self.atmosphere;
        let y = (r_m - a.ground_radius_m) / (a.top_radius_m - a.ground_radius_m);
        bilinear(&self.table, MULTIPLE_SCATTERING_SIZE, 0.5 * (mu_s + 1.0), y)
    }
}

impl Atmosphere {
    /// One texel of [`MultipleScatteringLut`] (see there).
    fn psi_ms(&self, height_m: f64, mu_s: f64, transmittance: &TransmittanceLut) -> DVec3 {
        let isotropic = 1.0 / (4.0 * std::f64::consts::PI);
        let origin = DVec3::new(0.0, 0.0, self.ground_radius_m + height_m);
        let sun = DVec3::new((1.0 - mu_s * mu_s).max(0.0).sqrt(), 0.0, mu_s);
        let n = MS_DIRECTIONS_SQRT;
        let (mut second, mut f_ms) = (DVec3::ZERO, DVec3::ZERO);
        for i in 0..n {
            let cos_t = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
            // The half φ ∈ (0, π): the other half mirrors it in the sun's
            // vertical plane (y → −y) and gives the same light; the means
            // below count each direction twice.
            for j in 0..n / 2 {
                let phi = std::f64::consts::TAU * (j as f64 + 0.5) / n as f64;
                let dir = DVec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t);
                let (length, ground) = self.distance_to_end(origin.z, cos_t);
                let mut last_seen = DVec3::ONE;
                self.march(origin, dir, length, MS_STEPS, |p, medium, dt, seen| {
                    let scattered = (medium.rayleigh + medium.mie) * seen * dt;
                    let r = p.length();
                    second += scattered * transmittance.at(r, p.dot(sun) / r) * isotropic;
                    f_ms += scattered;
                    last_seen = seen;
                });
                if ground {
                    // The lit ground's Lambertian reflection, seen through
                    // the air up to the last sample.
                    let normal = (origin + dir * length).normalize();
                    let cos_sun = normal.dot(sun);
                    if cos_sun > 0.0 {
                        second += last_seen
                            * transmittance.at(self.ground_radius_m, cos_sun)
                            * cos_sun
                            * self.ground_albedo
                            / std::f64::consts::PI;
                    }
                }
            }
        }
        // Means over the sphere: ∫ … p_u dω with p_u = 1/(4π).
        let count = (n * (n / 2)) as f64;
        let (second, f_ms) = (second / count, f_ms / count);
        second / (DVec3::ONE - f_ms)
    }
}

/// The atmosphere's sun-independent tables, built once (the renderer's
/// sun keeps the Earth's for the last few visibilities asked for,
/// src/sky/sun_light.rs).
#[derive(Debug, Clone)]
pub struct SkyLuts {
    pub atmosphere: Atmosphere,
    pub transmittance: TransmittanceLut,
    pub multiple: MultipleScatteringLut,
}

impl SkyLuts {
    pub fn new(atmosphere: &Atmosphere) -> Self {
        let transmittance = TransmittanceLut::new(atmosphere);
        let multiple = MultipleScatteringLut::new(atmosphere, &transmittance);
        Self {
            atmosphere: *atmosphere,
            transmittance,
            multiple,
        }
    }
}
