//! The one CPU evaluation of the cloud density ρ(P) of paper eq. 18, mirroring
//! shaders/density.wgsl (`parcel_value`, `cell_list`, `macro_value`,
//! `cloud_density`) and the noise of shaders/common.wgsl (`noise3`), so the
//! exporter (`crate::export`) writes the field the GPU ray-marches. Keep in
//! sync with those WGSL routines.
//!
//! The parcels and the culling grid come from [`pack`], exactly as uploaded
//! to the GPU; the noise is the same tiling texture ([`noise::tiling_fbm`])
//! sampled as the GPU samples it (repeat addressing, trilinear filtering,
//! texel centres at (i + ½)/n). The only GPU detail not mirrored is the
//! hardware's 8-bit fixed-point filter weights (about 1/256 of a texel step).
//! No wgpu here: unit-testable without a GPU; tests/export_gpu.rs checks it
//! against the real cloud pass.

use glam::Vec3;

use crate::error::Result;
use crate::physics::CloudParcel;
use crate::render::RenderConfig;
use crate::render::noise;
use crate::render::pack::{GpuParcel, GridInfo, Packed, pack};

/// Plane shell thickness relative to the sphere's shell. Keep in sync with
/// `PLANE_SHELL` in shaders/density.wgsl.
pub const PLANE_SHELL: f32 = 0.3;

/// Seed of the noise texture. Keep in sync with the `tiling_fbm(n, 1)` call
/// in src/render/renderer.rs.
pub const NOISE_SEED: u32 = 1;

/// The renderer's tiling noise texture, sampled on the CPU like the GPU does.
#[derive(Debug, Clone)]
pub struct NoiseTexture {
    /// Side in texels.
    n: u32,
    /// R8 texels, x fastest.
    texels: Vec<u8>,
}

impl NoiseTexture {
    /// The texture the renderer uploads for `texels`³.
    pub fn new(texels: u32) -> Self {
        Self {
            n: texels,
            texels: noise::tiling_fbm(texels, NOISE_SEED),
        }
    }

    fn texel(&self, x: i64, y: i64, z: i64) -> f32 {
        let n = self.n as i64;
        let (x, y, z) = (x.rem_euclid(n), y.rem_euclid(n), z.rem_euclid(n));
        self.texels[(x + n * (y + n * z)) as usize] as f32 / 255.0
    }

    /// `textureSampleLevel(noise_tex, repeat_sampler, q, 0)` of an R8Unorm
    /// texture: trilinear between texel centres, wrapping. `q` in texture
    /// coordinates (1 = one tile). units: value in [0, 1]
    pub fn sample(&self, q: Vec3) -> f32 {
        let u = q * self.n as f32 - Vec3::splat(0.5);
        let i = u.floor();
        let f = u - i;
        let (x, y, z) = (i.x as i64, i.y as i64, i.z as i64);
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let row = |dy: i64, dz: i64| {
            lerp(
                self.texel(x, y + dy, z + dz),
                self.texel(x + 1, y + dy, z + dz),
                f.x,
            )
        };
        lerp(
            lerp(row(0, 0), row(1, 0), f.y),
            lerp(row(0, 1), row(1, 1), f.y),
            f.z,
        )
    }
}

/// The noise the hypertexture adds: `noise3` of shaders/common.wgsl, in
/// [−0.5, 0.5]. This is the one function to swap when the noise changes.
fn noise3(tex: &NoiseTexture, p: Vec3, time_s: f32, inv_scale_per_m: f32, octaves: u32) -> f32 {
    let drift = Vec3::new(1.5, 0.8, 0.3) * time_s;
    let mut q = (p + drift) * inv_scale_per_m;
    let (mut sum, mut amp, mut norm) = (0.0f32, 1.0f32, 0.0f32);
    for _ in 0..octaves {
        sum += amp * (tex.sample(q) - 0.5);
        norm += amp;
        amp *= 0.5;
        q = q * 2.03 + Vec3::new(0.17, 0.31, 0.53);
    }
    (2.0 * sum / norm.max(1e-6)).clamp(-0.5, 0.5)
}

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
    /// Parcel indices per grid cell (x fastest), from the packed grid.
    cells: Vec<Vec<u32>>,
    info: GridInfo,
    noise: NoiseTexture,
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
    /// The field `cfg` renders for `parcels` at simulated time `time_s`.
    pub fn new(parcels: &[CloudParcel], cfg: &RenderConfig, time_s: f32) -> Result<Self> {
        let packed = pack(parcels, cfg.shell_m, cfg.radius_scale)?;
        Ok(Self::from_packed(&packed, cfg, time_s))
    }

    /// The field of an already packed frame.
    pub fn from_packed(packed: &Packed, cfg: &RenderConfig, time_s: f32) -> Self {
        let info = packed.info;
        let [nx, ny, nz] = info.dims;
        let mut cells = Vec::with_capacity((nx * ny * nz) as usize);
        for iz in 0..nz {
            for iy in 0..ny {
                for ix in 0..nx {
                    cells.push(packed.cell_list(ix, iy, iz));
                }
            }
        }
        Self {
            parcels: packed.parcels.parcels[..info.parcel_count as usize].to_vec(),
            cells,
            info,
            noise: NoiseTexture::new(cfg.noise_texels),
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
        (self.info.min, self.info.max())
    }

    /// Packed parcels (rendered radius, fill ≤ 1, plane).
    pub fn parcels(&self) -> &[GpuParcel] {
        &self.parcels
    }

    /// `parcel_value` of density.wgsl: f·(d + 1) − 1.
    fn parcel_value(&self, q: &GpuParcel, p: Vec3) -> f32 {
        let c = Vec3::new(q.center_radius[0], q.center_radius[1], q.center_radius[2]);
        let d_sphere = (q.center_radius[3] - p.distance(c)) / self.shell_m;
        let d_plane = (p.z - q.fill_plane[1]) / (PLANE_SHELL * self.shell_m);
        let d = d_sphere.min(d_plane).clamp(-1.0, 1.0);
        q.fill_plane[0] * (d + 1.0) - 1.0
    }

    /// `cell_list` of density.wgsl: the parcels listed in p's cell (none
    /// outside the grid).
    fn cell_list(&self, p: Vec3) -> &[u32] {
        let rel = (p - self.info.min) / self.info.cell;
        let [nx, ny, nz] = self.info.dims;
        let dims = Vec3::new(nx as f32, ny as f32, nz as f32);
        if rel.cmplt(Vec3::ZERO).any() || rel.cmpge(dims).any() {
            return &[];
        }
        let (x, y, z) = (rel.x as u32, rel.y as u32, rel.z as u32);
        &self.cells[(x + nx * (y + ny * z)) as usize]
    }

    /// `macro_value` of density.wgsl: union over parcels of f·(d + 1) − 1,
    /// in [−1, 1].
    pub fn macro_value(&self, p: Vec3) -> f32 {
        let mut v = -1.0f32;
        for &i in self.cell_list(p) {
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
        let n = noise3(
            &self.noise,
            p,
            self.time_s,
            self.inv_noise_scale_per_m,
            self.octaves,
        );
        smoothstep01(v + self.k * n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_sample_hits_texel_centres_and_wraps() {
        let t = NoiseTexture::new(8);
        let c = |i: u32| (i as f32 + 0.5) / 8.0;
        for (x, y, z) in [(0, 0, 0), (3, 5, 7), (7, 7, 7)] {
            let want = t.texels[(x + 8 * (y + 8 * z)) as usize] as f32 / 255.0;
            let got = t.sample(Vec3::new(c(x), c(y), c(z)));
            // Texel centres interpolate nothing: only float rounding differs.
            assert!((got - want).abs() < 1e-5, "{got} {want}");
            // One tile further is the same texel (repeat addressing).
            let again = t.sample(Vec3::new(c(x) + 1.0, c(y) - 2.0, c(z) + 3.0));
            assert!((again - want).abs() < 1e-5);
        }
        // Half-way between texels 7 and 0 (across the seam) is their mean.
        let mid = t.sample(Vec3::new(1.0, c(0), c(0)));
        let want = 0.5 * (t.texel(7, 0, 0) + t.texel(0, 0, 0));
        assert!((mid - want).abs() < 1e-5, "{mid} {want}");
    }

    #[test]
    fn noise_stays_in_range() {
        let t = NoiseTexture::new(16);
        for i in 0..500 {
            let p = Vec3::new(i as f32 * 37.1, i as f32 * -11.3, i as f32 * 5.7);
            let n = noise3(&t, p, 12.0, 1.0 / 900.0, 4);
            assert!((-0.5..=0.5).contains(&n), "{n}");
        }
    }
}
