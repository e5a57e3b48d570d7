//! The JSON sidecar of an exported grid: everything another renderer needs
//! to reproduce our frame from the `.vol` (world box, camera, sun, sky,
//! medium, tone curve), with units. Field names carry their units.
//!
//! The lighting constants below are those of the cloud pass
//! (shaders/raymarch/lighting.wgsl `HG_BACK_G`, `HG_BACK_WEIGHT`,
//! `LIGHT_DENSITY`; a test compares them); what the sidecar says of the
//! phase, the sky and the tone curve describes `sun_phase_weights` there
//! and `sky_color` and `tone_map` of shaders/common.wgsl (benches/
//! pathtraced.py reads it; the test
//! `render::pathtraced::the_path_tracer_s_tone_curve_and_sky_are_the_renderer_s`
//! checks that what it computes from it is the renderer's);
//! the sky itself is the frame's sky-view table from the atmosphere model
//! (src/sky).

use serde::{Deserialize, Serialize};

use crate::config::{Camera, RenderConfig};
use crate::sky::Sun;
use crate::sky::{SKY_AZIMUTHS, SKY_ELEVATIONS};

use super::GridSpec;

/// Henyey–Greenstein g of the weak back lobe (lighting.wgsl `HG_BACK_G`).
pub const BACK_LOBE_G: f32 = -0.3;
/// Weight of the back lobe in the mix (lighting.wgsl `HG_BACK_WEIGHT`).
pub const BACK_LOBE_WEIGHT: f32 = 0.25;
/// Extra density factor of the light march toward the sun (lighting.wgsl `LIGHT_DENSITY`;
/// 1: the same medium as the view rays and the path tracer).
pub const LIGHT_DENSITY: f32 = 1.0;

/// The grid file and what its values mean.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VolumeInfo {
    /// The grid file (`.vol` or `.vdb`), relative to the sidecar.
    pub file: String,
    /// Cells along x, y, z.
    pub dims: [u32; 3],
    /// units: m
    pub voxel_m: f32,
    /// Lowest corner of the grid (cell (0,0,0)'s corner). units: m
    pub bounds_min_m: [f32; 3],
    /// Highest corner. units: m
    pub bounds_max_m: [f32; 3],
    /// Size of the values (float32). units: bytes
    pub memory_bytes: u64,
    pub values: String,
}

/// The participating medium the renderer assumes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MediumInfo {
    /// σ_t = extinction_scale_per_m · value. units: 1/m
    pub extinction_scale_per_m: f32,
    /// Single-scattering albedo (the march scatters all it extinguishes).
    pub albedo: f32,
    /// Forward lobe g.
    pub phase_g_forward: f32,
    pub phase_g_back: f32,
    /// p = (1 − w)·HG(g_forward) + w·HG(g_back).
    pub phase_back_weight: f32,
    /// The real-time light march toward the sun sees σ_t times this.
    pub light_march_density_factor: f32,
    pub notes: String,
}

/// The camera (z up).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CameraInfo {
    pub position_m: [f32; 3],
    pub target_m: [f32; 3],
    pub up: [f32; 3],
    pub vfov_deg: f32,
    pub near_m: f32,
    pub far_m: f32,
}

/// The sun and sky.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LightInfo {
    /// Unit vector toward the sun (light travels along its negative).
    pub sun_direction: [f32; 3],
    /// The renderer's sun colour (`Sun::color`). units: linear RGB
    pub sun_color_rgb: [f32; 3],
    /// Physical irradiance equivalent: 4π·sun_color (the march's source term
    /// is sun_color·4π·p(θ)). units: linear RGB per unit area
    pub sun_irradiance_rgb: [f32; 3],
    /// Skylight the march adds (×0.8, shaded): the sky's irradiance on an
    /// up-facing surface over π. units: linear RGB radiance
    pub sky_ambient_rgb: [f32; 3],
    /// The sky's radiance (common.wgsl `sky_color`).
    pub sky: SkyInfo,
    /// Display value = filmic(exposure·L) (shaders/common.wgsl `tone_map`:
    /// Narkowicz's ACES fit, clamped to [0, 1]), then sRGB-encoded.
    pub tone_exposure: f32,
}

/// The sky's radiance as the sky-view table of src/sky/view.rs, texel
/// k = e·azimuths + a at azimuth π·a/(azimuths − 1) from the sun and
/// elevation π/2·(e/(elevations − 1))²: toward unit direction d (z up)
/// with mu = d·sun, bilinear in (acos of the horizontal cosine between d
/// and the sun, √(elevation/(π/2))),
/// L = P_R(mu)·rayleigh + P_M(mu; g)·mie + multiple, with P_R the
/// Rayleigh and P_M the Cornette–Shanks phase; below the horizon the
/// horizon's value times 1 − 0.4·clamp(−3·d.z, 0, 1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SkyInfo {
    pub azimuths: usize,
    pub elevations: usize,
    /// units: linear RGB radiance per unit phase (1/sr)
    pub rayleigh_rgb: Vec<[f32; 3]>,
    /// units: linear RGB radiance per unit phase (1/sr)
    pub mie_rgb: Vec<[f32; 3]>,
    /// Multiple-scattered part (isotropic). units: linear RGB radiance
    pub multiple_rgb: Vec<[f32; 3]>,
    /// Asymmetry of the Mie phase.
    pub mie_g: f32,
    pub model: String,
}

/// The whole sidecar.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sidecar {
    pub format: String,
    pub scene: String,
    /// Simulated time of the frame. units: s
    pub time_s: f64,
    pub units: String,
    pub volume: VolumeInfo,
    pub medium: MediumInfo,
    pub camera: CameraInfo,
    pub light: LightInfo,
}

impl Sidecar {
    /// The sidecar of grid `spec` written to `vol_file`.
    pub fn new(
        scene: &str,
        time_s: f64,
        vol_file: &str,
        spec: &GridSpec,
        cfg: &RenderConfig,
        camera: &Camera,
        sun: &Sun,
    ) -> Self {
        let irr = sun.color * 4.0 * std::f32::consts::PI;
        Self {
            format: "cumulus cloud export, version 1".into(),
            scene: scene.into(),
            time_s,
            units: "lengths in metres, colours linear RGB, z up".into(),
            volume: VolumeInfo {
                file: vol_file.into(),
                dims: spec.dims,
                voxel_m: spec.voxel_m,
                bounds_min_m: spec.min.to_array(),
                bounds_max_m: spec.max().to_array(),
                memory_bytes: spec.bytes(),
                values: super::GridFormat::of_name(vol_file).describe().into(),
            },
            medium: MediumInfo {
                extinction_scale_per_m: cfg.extinction_per_m,
                albedo: 1.0,
                phase_g_forward: cfg.phase_g,
                phase_g_back: BACK_LOBE_G,
                phase_back_weight: BACK_LOBE_WEIGHT,
                light_march_density_factor: LIGHT_DENSITY,
                notes: "The real-time renderer approximates multiple scattering with a \
                        two-stream (diffusion-like) falloff and adds sky ambient; a path tracer \
                        with this medium computes it exactly."
                    .into(),
            },
            camera: CameraInfo {
                position_m: camera.position.to_array(),
                target_m: camera.target.to_array(),
                up: [0.0, 0.0, 1.0],
                vfov_deg: camera.vfov_rad.to_degrees(),
                near_m: camera.near_m,
                far_m: camera.far_m,
            },
            light: LightInfo {
                sun_direction: sun.direction.normalize().to_array(),
                sun_color_rgb: sun.color.to_array(),
                sun_irradiance_rgb: irr.to_array(),
                sky_ambient_rgb: sun.sky.ambient.to_array(),
                sky: SkyInfo {
                    azimuths: SKY_AZIMUTHS,
                    elevations: SKY_ELEVATIONS,
                    rayleigh_rgb: sun.sky.rayleigh.iter().map(|c| c.to_array()).collect(),
                    mie_rgb: sun.sky.mie.iter().map(|c| c.to_array()).collect(),
                    multiple_rgb: sun.sky.multiple.iter().map(|c| c.to_array()).collect(),
                    mie_g: sun.sky.mie_g,
                    model: "Hillaire 2020 sky-view table: single scattering (transmittance \
                            table) + multiple scattering Psi_ms, Rayleigh + Mie + ozone, Earth \
                            parameters of Bruneton 2017 (src/sky)"
                        .into(),
                },
                tone_exposure: cfg.tone_exposure(),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::render::twins::{module, wgsl_const};

    #[test]
    fn the_lighting_constants_match_the_cloud_shader() {
        let clouds = module(
            &crate::methods::raymarch::passes::CLOUDS,
            &crate::methods::raymarch::passes::BAKED,
        );
        assert_eq!(wgsl_const(&clouds, "HG_BACK_G"), super::BACK_LOBE_G as f64);
        assert_eq!(
            wgsl_const(&clouds, "HG_BACK_WEIGHT"),
            super::BACK_LOBE_WEIGHT as f64
        );
        assert_eq!(
            wgsl_const(&clouds, "LIGHT_DENSITY"),
            super::LIGHT_DENSITY as f64
        );
    }
}
