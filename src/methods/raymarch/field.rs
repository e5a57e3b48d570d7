//! The one CPU evaluation of the cloud density ρ(P) of paper eq. 18, mirroring
//! shaders/raymarch/parcel.wgsl (`parcel_value`), the exact method's
//! shaders/raymarch/field_exact.wgsl (`cell_list`, `field_value`), shaders/raymarch/density.wgsl
//! (`cloud_density`) and the noise of shaders/common.wgsl (`noise3`, through
//! [`noise::NoiseVolume`]), so the
//! exporter (`crate::export`) writes the field the GPU ray-marches. Keep in
//! sync with those WGSL routines.
//!
//! The parcels are [`pack::gpu_parcels`], exactly as uploaded to the GPU,
//! with no limit on their number (the exact method's uniform array holds
//! [`pack::MAX_PARCELS`]; the CPU has no such array); the culling grid is
//! [`ParcelGrid`], which lists at every point every parcel the GPU's grid
//! lists, so the union is the same bit for bit. The noise is
//! [`noise::NoiseVolume`], the same tiling texture sampled as the GPU
//! samples it. The only GPU detail not mirrored is the
//! hardware's 8-bit fixed-point filter weights (about 1/256 of a texel step).
//! No wgpu here: unit-testable without a GPU; tests/cumulus/export/gpu.rs checks it
//! against the real cloud pass.

use glam::Vec3;

use crate::config::RenderConfig;
use crate::error::Result;
use crate::methods::raymarch::pack::{self, GpuParcel, Packed};
use crate::methods::raymarch::parcel_grid::ParcelGrid;
use crate::noise;
use crate::physics::CloudParcel;

/// Plane shell thickness relative to the sphere's shell: `PLANE_SHELL` of
/// shaders/raymarch/parcel.wgsl (a test compares them).
pub const PLANE_SHELL: f32 = 0.3;

/// GLSL/WGSL `smoothstep(0, 1, x)`.
fn smoothstep01(x: f32) -> f32 {
    let t = x.clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The density field of one frame: packed parcels, their culling grid and
/// the noise, as the GPU sees them.
#[derive(Debug, Clone)]
pub struct CloudField {
    parcels: Vec<GpuParcel>,
    /// Which parcels can reach each cell.
    grid: ParcelGrid,
    noise: noise::NoiseVolume,
    /// Noise amplitude k of eq. 18.
    k: f32,
    /// units: m
    shell_m: f32,
    /// units: 1/m
    inv_noise_scale_per_m: f32,
    octaves: u32,
    /// Simulation time (noise drift). units: s
    time_s: f32,
}

impl CloudField {
    /// The field `cfg` renders for `parcels` at simulated time `time_s`;
    /// any number of parcels.
    pub fn new(parcels: &[CloudParcel], cfg: &RenderConfig, time_s: f32) -> Result<Self> {
        let live = pack::gpu_parcels(parcels, cfg.shell_m, cfg.radius_scale)?;
        let grid = ParcelGrid::new(&live, cfg.shell_m);
        Ok(Self::with_grid(live, grid, cfg, time_s))
    }

    /// The field of an already packed frame, culled by the GPU's own
    /// (capped) grid.
    pub fn from_packed(packed: &Packed, cfg: &RenderConfig, time_s: f32) -> Self {
        let live = packed.parcels.parcels[..packed.info.parcel_count as usize].to_vec();
        Self::with_grid(live, ParcelGrid::from_packed(packed), cfg, time_s)
    }

    fn with_grid(parcels: Vec<GpuParcel>, grid: ParcelGrid, cfg: &RenderConfig, time_s: f32) -> Self {
        Self {
            parcels,
            grid,
            noise: noise::NoiseVolume::new(cfg.noise_texels),
            k: cfg.noise_amplitude,
            shell_m: cfg.shell_m,
            inv_noise_scale_per_m: 1.0 / cfg.noise_scale_m,
            octaves: cfg.noise_octaves,
            time_s,
        }
    }

    /// Where density can be non-zero: the culling grid's box (lowest and
    /// highest corner; no parcel's density reaches past it). units: m
    pub fn bounds(&self) -> (Vec3, Vec3) {
        (self.grid.info.min, self.grid.info.max())
    }

    /// Packed parcels (rendered radius, fill ≤ 1, plane).
    pub fn parcels(&self) -> &[GpuParcel] {
        &self.parcels
    }

    /// `parcel_value` of parcel.wgsl: f·(d + 1) − 1.
    fn parcel_value(&self, q: &GpuParcel, p: Vec3) -> f32 {
        let c = Vec3::from(q.center_m);
        let d_sphere = (q.radius_m - p.distance(c)) / self.shell_m;
        let d_plane = (p.z - q.plane_z_m) / (PLANE_SHELL * self.shell_m);
        let d = d_sphere.min(d_plane).clamp(-1.0, 1.0);
        q.fill * (d + 1.0) - 1.0
    }

    /// `field_value` of field_exact.wgsl: union over parcels of f·(d + 1) − 1,
    /// in [−1, 1].
    pub fn macro_value(&self, p: Vec3) -> f32 {
        let mut v = -1.0f32;
        for &i in self.grid.list(p) {
            v = v.max(self.parcel_value(&self.parcels[i as usize], p));
            if v >= 1.0 {
                break;
            }
        }
        v
    }

    /// `cloud_density` of density.wgsl: ρ(P) ∈ [0, 1] (eq. 18).
    pub fn density(&self, p: Vec3) -> f32 {
        let v = self.macro_value(p);
        if v + 0.5 * self.k <= 0.0 {
            return 0.0;
        }
        let n = self.noise.noise3(
            p.to_array(),
            self.time_s,
            self.inv_noise_scale_per_m,
            self.octaves,
        );
        smoothstep01(v + self.k * n)
    }
}
