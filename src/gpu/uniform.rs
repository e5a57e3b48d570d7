//! The per-frame uniform every pass reads (`struct Frame` of
//! shaders/common.wgsl) and the box of the method's clouds it carries
//! ([`GridInfo`]). Plain `#[repr(C)]` Pod data, member for member the
//! WGSL struct: a test (src/render/twins.rs) compares names, offsets
//! and sizes with naga's layout. Scalars come in fours and a `vec3` with a
//! scalar after it (`_pad` where none belongs), so every 16-byte WGSL
//! alignment falls where `#[repr(C)]` puts it.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::sky::{AIR_HEIGHTS, SKY_TEXELS};

/// Where the eye is, and when: `camera_pos` of [`FrameUniform`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct CameraPos {
    /// The eye. units: m
    pub eye_m: [f32; 3],
    /// Simulation time (the noise drifts with it). units: s
    pub time_s: f32,
}

/// The density noise (`noise3` in shaders/common.wgsl): `noise` of
/// [`FrameUniform`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct FrameNoise {
    /// 1 / `render.noise_scale_m`. units: 1/m
    pub inv_scale_per_m: f32,
    /// Octaves summed (1–6).
    pub octaves: f32,
    pub _pad: f32,
    /// Noise texels of a pixel's view-cone width per metre of eye distance,
    /// the mip level of the noise (0: level 0).
    pub texels_per_m: f32,
}

/// Per-frame constants: `struct Frame` of shaders/common.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct FrameUniform {
    pub clip_from_world: [[f32; 4]; 4],
    /// Clip → world offset from the eye (the inverse of
    /// [`crate::config::Camera::clip_from_eye`]): with no translation in
    /// it, view rays keep full f32 precision however far the camera is
    /// from the world's origin (an inverse of `clip_from_world` loses
    /// ~10⁻³ rad in a ray 18 km out, a tenth of a pixel).
    pub eye_from_clip: [[f32; 4]; 4],
    /// A [`CameraPos`] (`bytemuck::cast` one), as four floats for the
    /// callers that write it as `eye.extend(time)`.
    pub camera_pos: [f32; 4],
    /// Unit vector toward the sun.
    pub sun_dir: [f32; 3],
    /// Henyey–Greenstein g of the clouds' forward lobe (`render.phase_g`).
    pub phase_g: f32,
    /// Sun irradiance scale (linear RGB).
    pub sun_color: [f32; 3],
    /// Display exposure k, the scale of L before the filmic tone curve
    /// (`RenderConfig::tone_exposure`).
    pub exposure: f32,
    /// View-march step. units: m
    pub step_m: f32,
    /// View-march steps across the cloud box (the step stretches to it).
    pub max_steps: u32,
    /// Light-march samples toward the sun.
    pub light_steps: u32,
    /// The light march's first step. units: m
    pub light_step_m: f32,
    /// Noise amplitude k of eq. 18.
    pub noise_amplitude: f32,
    /// Hypertexture shell thickness. units: m
    pub shell_m: f32,
    /// Extinction of density 1. units: 1/m
    pub extinction_per_m: f32,
    /// The march stops below this transmittance (0: never).
    pub early_exit_transmittance: f32,
    /// A [`FrameNoise`] (`bytemuck::cast` one), as four floats for the
    /// callers that write it as an array.
    pub noise: [f32; 4],
    /// The frame grid's origin (the exact method's culling grid, the baked
    /// method's occupancy grid). units: m
    pub grid_min: [f32; 3],
    pub _pad0: f32,
    /// Its cell size. units: m
    pub grid_cell: [f32; 3],
    pub _pad1: f32,
    /// Its cells per axis.
    pub grid_dims: [u32; 3],
    /// Parcels packed ([`GridInfo::parcel_count`]).
    pub parcel_count: u32,
    /// Lowest corner (x, y) of the ground rectangle the cloud-shadow map
    /// covers. units: m
    pub shadow_min: [f32; 2],
    /// Its highest corner. units: m
    pub shadow_max: [f32; 2],
    /// Ambient light: the sky's irradiance on an up-facing surface over π
    /// (src/sky/view.rs `SkyLight`).
    pub sky_ambient: [f32; 3],
    /// Asymmetry g of the sky's Mie phase.
    pub sky_mie_g: f32,
    /// The sky's lower half on a down-facing surface over π
    /// (`SkyLight::below`).
    pub sky_below: [f32; 3],
    pub _pad2: f32,
    /// The sky-view table (src/sky/view.rs `SkyLight`), three vec4 per
    /// texel (texel k = elevation·SKY_AZIMUTHS + azimuth): `[3k]` Rayleigh
    /// radiance per unit phase, `[3k + 1]` Mie per unit phase, `[3k + 2]`
    /// multiple-scattered (rgb; w unused).
    pub sky_view: [[f32; 4]; 3 * SKY_TEXELS],
    /// The air table (src/sky/air.rs `AirTable`), four vec4 per height
    /// node k: `[4k]` Rayleigh scattered per metre per unit phase, `[4k + 1]`
    /// Mie per unit phase, `[4k + 2]` multiple, `[4k + 3]` extinction (1/m)
    /// (rgb; w unused).
    pub air: [[f32; 4]; 4 * AIR_HEIGHTS],
}

const _: () =
    assert!(std::mem::size_of::<FrameUniform>() == 320 + 48 * SKY_TEXELS + 64 * AIR_HEIGHTS);

/// Where the grid sits and how full it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridInfo {
    /// Grid origin (lowest corner). units: m
    pub min: Vec3,
    /// Cell size. units: m
    pub cell: Vec3,
    /// Cells per axis.
    pub dims: [u32; 3],
    /// Parcels packed (condensed ones with f > 0 and r > 0).
    pub parcel_count: u32,
    /// Parcel indices in all cell lists.
    pub entry_count: u32,
    /// How many times the grid was halved to fit the entries.
    pub coarsened: u32,
}

impl GridInfo {
    /// The grid of no parcels: one unit cell at the origin, nothing listed.
    pub const EMPTY: GridInfo = GridInfo {
        min: Vec3::ZERO,
        cell: Vec3::ONE,
        dims: [1, 1, 1],
        parcel_count: 0,
        entry_count: 0,
        coarsened: 0,
    };

    /// Grid's highest corner. units: m
    pub fn max(&self) -> Vec3 {
        self.min
            + self.cell
                * Vec3::new(
                    self.dims[0] as f32,
                    self.dims[1] as f32,
                    self.dims[2] as f32,
                )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_uniform_is_16_byte_sized_and_4_byte_aligned() {
        assert_eq!(std::mem::size_of::<FrameUniform>() % 16, 0);
        assert_eq!(std::mem::align_of::<FrameUniform>(), 4);
    }
}
