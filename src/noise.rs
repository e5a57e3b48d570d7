//! The tiling 3D noise texture of the hypertexture (paper §6.1), built on the
//! CPU at start-up, and its CPU twin. Pure CPU: the renderer uploads it
//! ([`crate::gpu::noise`]); the sprite atlas and the export read it too.
//!
//! One RGBA8 texture holds four octaves of fBm, one per channel: channel c
//! is periodic value noise (smooth-step interpolated lattice values from an
//! integer hash) with `BASE_PERIOD`·2^c lattice cells across the tile, so
//! one fetch returns octaves 1–4 at one coordinate and the sum needs no
//! further lookups; octaves 5 and 6 are a second fetch of the same texture
//! at 16× the frequency (2^4: the doubling continues). Every channel tiles,
//! so the shader samples it with a repeating sampler at any scale. Each
//! channel is stretched to fill 0..=255.
//!
//! The texture has a full mip chain (2×2×2 box averages, per channel, with
//! wrap-around), and the shader picks the level from the sample's
//! footprint, the width of the pixel's view cone at the sample
//! ([`lod`]): distant clouds see their fine octaves averaged out instead of
//! aliased. [`NoiseVolume`] holds exactly the texels the GPU gets (all
//! levels) and samples them the way the GPU does (repeat addressing,
//! trilinear within a level, linear between levels), so CPU evaluations of
//! eq. 18 (src/methods/raymarch/field.rs, the export) match the GPU: at level 0 (what
//! the export uses) and at any level. Deterministic: same size and seed,
//! same bytes.

/// Lattice cells across the tile of octave 1 (channel r); channel c has
/// `BASE_PERIOD`·2^c. The finest channel (32 cells) needs two texels per
/// cell, hence `MIN_TEXELS`.
const BASE_PERIOD: u32 = 4;
/// Octaves per fetch: the four channels.
pub const CHANNELS: u32 = 4;
/// Smallest texture side: two texels per lattice cell of the finest channel.
pub const MIN_TEXELS: u32 = (2 * BASE_PERIOD) << (CHANNELS - 1);
/// Lattice offset of channel c (in cells, times c): channels do not share
/// lattice points, so the octaves' grids do not line up.
const CHANNEL_OFFSET: f32 = 0.37;
/// Frequency of the second fetch (octaves 5, 6) relative to the first.
pub const SECOND_FETCH_SCALE: f32 = 16.0;
/// Mip levels the second fetch is coarser by (log2 of its scale).
const SECOND_FETCH_LOD: f32 = 4.0;
/// Offset of the second fetch (tile units), so it does not start on the
/// first fetch's lattice.
const SECOND_FETCH_OFFSET: [f32; 3] = [0.17, 0.31, 0.53];
/// Most octaves the two fetches hold (render.noise_octaves is 1 to 6).
pub const MAX_OCTAVES: u32 = 6;

// The lattice hash and fade of the terrain's hills, shared (written once in
// the CPU-only landscape module).
pub(crate) use crate::landscape::{fade, lattice_hash as hash};

/// Periodic value noise in [0, 1] at `p` (lattice units), period `period`.
fn value_noise(p: [f32; 3], period: u32, seed: u32) -> f32 {
    let i = p.map(|v| v.floor());
    let f = [p[0] - i[0], p[1] - i[1], p[2] - i[2]].map(fade);
    let i = i.map(|v| (v as i64).rem_euclid(period as i64) as u32);
    let n = |dx: u32, dy: u32, dz: u32| {
        hash(
            (i[0] + dx) % period,
            (i[1] + dy) % period,
            (i[2] + dz) % period,
            seed,
        )
    };
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let x00 = lerp(n(0, 0, 0), n(1, 0, 0), f[0]);
    let x10 = lerp(n(0, 1, 0), n(1, 1, 0), f[0]);
    let x01 = lerp(n(0, 0, 1), n(1, 0, 1), f[0]);
    let x11 = lerp(n(0, 1, 1), n(1, 1, 1), f[0]);
    lerp(lerp(x00, x10, f[1]), lerp(x01, x11, f[1]), f[2])
}

/// Level 0: an `n`³ RGBA texture (x fastest, then y, then z), channel c
/// holding octave c + 1, each stretched to 0..=255.
fn packed_octaves(n: u32, seed: u32) -> Vec<[u8; 4]> {
    let mut channels = Vec::with_capacity(CHANNELS as usize);
    for c in 0..CHANNELS {
        let period = BASE_PERIOD << c;
        let s = period as f32 / n as f32;
        let o = CHANNEL_OFFSET * c as f32;
        let mut v = Vec::with_capacity((n * n * n) as usize);
        for z in 0..n {
            for y in 0..n {
                for x in 0..n {
                    let p = [x as f32 * s + o, y as f32 * s + o, z as f32 * s + o];
                    v.push(value_noise(p, period, seed.wrapping_add(c)));
                }
            }
        }
        let (lo, hi) = v
            .iter()
            .fold((f32::MAX, f32::MIN), |(a, b), &x| (a.min(x), b.max(x)));
        let scale = 255.0 / (hi - lo).max(1e-6);
        channels.push(
            v.iter()
                .map(|&x| ((x - lo) * scale).round() as u8)
                .collect::<Vec<u8>>(),
        );
    }
    (0..(n * n * n) as usize)
        .map(|i| [0, 1, 2, 3].map(|c| channels[c][i]))
        .collect()
}

/// The next mip level of a side-`n` level: each texel the rounded mean of
/// its 2×2×2 block, per channel.
fn downsample(level: &[[u8; 4]], n: u32) -> Vec<[u8; 4]> {
    let h = n / 2;
    let at = |x: u32, y: u32, z: u32| level[(x + n * (y + n * z)) as usize];
    let mut out = Vec::with_capacity((h * h * h) as usize);
    for z in 0..h {
        for y in 0..h {
            for x in 0..h {
                let mut sum = [0u32; 4];
                for d in 0..8 {
                    let t = at(2 * x + (d & 1), 2 * y + (d >> 1 & 1), 2 * z + (d >> 2));
                    for c in 0..4 {
                        sum[c] += t[c] as u32;
                    }
                }
                out.push(sum.map(|s| ((s + 4) / 8) as u8));
            }
        }
    }
    out
}

/// Mip level of a noise fetch at `distance_m` from the eye, for a view cone
/// of `texels_per_m` texels of width per metre of distance (pixel angle ×
/// texels per metre of the first fetch): log2 of the footprint in texels,
/// 0 where a texel is wider than the footprint. The CPU twin of the `lod`
/// line of `noise3` in shaders/common.wgsl.
pub fn lod(distance_m: f32, texels_per_m: f32) -> f32 {
    (distance_m * texels_per_m).max(1.0).log2()
}

/// The noise texture, all mip levels, sampled on the CPU the way the shaders
/// sample `noise_tex` (repeat addressing, trilinear filtering, linear
/// between levels), for CPU evaluations of eq. 18 that must match the GPU.
#[derive(Debug, Clone)]
pub struct NoiseVolume {
    n: u32,
    /// Level l has side n >> l; the last is 1×1×1.
    levels: Vec<Vec<[u8; 4]>>,
}

impl NoiseVolume {
    /// The volume the renderer uploads for `render.noise_texels` = `n`
    /// (a power of two, at least [`MIN_TEXELS`]; seed 1, as `Renderer` uses).
    pub fn new(n: u32) -> Self {
        Self::with_seed(n, 1)
    }

    /// The volume of side `n` from hash seed `seed`.
    pub fn with_seed(n: u32, seed: u32) -> Self {
        assert!(n.is_power_of_two(), "noise side {n} is not a power of two");
        let mut levels = vec![packed_octaves(n, seed)];
        let mut side = n;
        while side > 1 {
            let next = downsample(levels.last().expect("level 0 exists"), side);
            levels.push(next);
            side /= 2;
        }
        Self { n, levels }
    }

    /// Texels per side of level 0.
    pub fn side(&self) -> u32 {
        self.n
    }

    /// Mip levels (log2 side + 1).
    pub fn level_count(&self) -> u32 {
        self.levels.len() as u32
    }

    /// Texels of level `l` (side `side() >> l`, x fastest), RGBA.
    pub fn level(&self, l: u32) -> &[[u8; 4]] {
        &self.levels[l as usize]
    }

    /// Trilinear RGBA sample in [0, 1] of level `l` at texture coordinate
    /// `uvw` (1 = one tile), wrapping like a repeat sampler: texel i's
    /// centre is at (i + 0.5) / side. GPUs quantise the filter weights
    /// (often to 8 bits), so the GPU value may differ by ~1/256 of a texel
    /// step.
    fn sample_level(&self, uvw: [f32; 3], l: usize) -> [f32; 4] {
        let side = self.n >> l;
        let n = side as i64;
        let texels = &self.levels[l];
        let mut i0 = [0i64; 3];
        let mut f = [0f32; 3];
        for a in 0..3 {
            let x = uvw[a] * side as f32 - 0.5;
            let fl = x.floor();
            i0[a] = fl as i64;
            f[a] = x - fl;
        }
        let at = |dx: i64, dy: i64, dz: i64| {
            let x = (i0[0] + dx).rem_euclid(n);
            let y = (i0[1] + dy).rem_euclid(n);
            let z = (i0[2] + dz).rem_euclid(n);
            texels[(x + n * (y + n * z)) as usize].map(|v| v as f32 / 255.0)
        };
        let lerp =
            |a: [f32; 4], b: [f32; 4], t: f32| [0, 1, 2, 3].map(|c| a[c] + (b[c] - a[c]) * t);
        let x00 = lerp(at(0, 0, 0), at(1, 0, 0), f[0]);
        let x10 = lerp(at(0, 1, 0), at(1, 1, 0), f[0]);
        let x01 = lerp(at(0, 0, 1), at(1, 0, 1), f[0]);
        let x11 = lerp(at(0, 1, 1), at(1, 1, 1), f[0]);
        lerp(lerp(x00, x10, f[1]), lerp(x01, x11, f[1]), f[2])
    }

    /// RGBA sample at `uvw` and mip level `lod` (clamped to the chain):
    /// trilinear within the two nearest levels, linear between them, as
    /// `textureSampleLevel` with a linear mipmap filter.
    pub fn sample(&self, uvw: [f32; 3], lod: f32) -> [f32; 4] {
        let last = (self.levels.len() - 1) as f32;
        let lod = lod.clamp(0.0, last);
        let l0 = lod.floor();
        let a = self.sample_level(uvw, l0 as usize);
        if lod == l0 {
            return a;
        }
        let b = self.sample_level(uvw, l0 as usize + 1);
        let t = lod - l0;
        [0, 1, 2, 3].map(|c| a[c] + (b[c] - a[c]) * t)
    }

    /// The noise of eq. 18 at world point `p_m` (m) and time `time_s` (s),
    /// in [−0.5, 0.5], at mip level 0 (no footprint: the export's voxels
    /// sample the field itself).
    pub fn noise3(&self, p_m: [f32; 3], time_s: f32, inv_scale_per_m: f32, octaves: u32) -> f32 {
        self.noise3_lod(p_m, time_s, inv_scale_per_m, octaves, 0.0)
    }

    /// [`Self::noise3`] at mip level `lod` of the first fetch (see [`lod`]):
    /// the CPU twin of `noise3` in shaders/common.wgsl (tests/cumulus/render/noise.rs
    /// compares the two through the mips; both have the drift,
    /// channel weights 2^−c, the second fetch's scale, offset and level, the
    /// doubling and clamp). `inv_scale_per_m` = 1 / `render.noise_scale_m`.
    pub fn noise3_lod(
        &self,
        p_m: [f32; 3],
        time_s: f32,
        inv_scale_per_m: f32,
        octaves: u32,
        lod: f32,
    ) -> f32 {
        let drift = [1.5 * time_s, 0.8 * time_s, 0.3 * time_s];
        let q: [f32; 3] = [0, 1, 2].map(|a| (p_m[a] + drift[a]) * inv_scale_per_m);
        let octaves = octaves.min(MAX_OCTAVES);
        let (mut sum, mut norm) = (0.0f32, 0.0f32);
        let first = self.sample(q, lod);
        for c in 0..octaves.min(CHANNELS) {
            let amp = 0.5f32.powi(c as i32);
            sum += amp * (first[c as usize] - 0.5);
            norm += amp;
        }
        if octaves > CHANNELS {
            let q2 = [0, 1, 2].map(|a| q[a] * SECOND_FETCH_SCALE + SECOND_FETCH_OFFSET[a]);
            let second = self.sample(q2, lod + SECOND_FETCH_LOD);
            for c in 0..octaves - CHANNELS {
                let amp = 0.5f32.powi((CHANNELS + c) as i32);
                sum += amp * (second[c as usize] - 0.5);
                norm += amp;
            }
        }
        (2.0 * sum / norm.max(1e-6)).clamp(-0.5, 0.5)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_texel_centres_exactly_wraps_and_filters_between_levels() {
        let n = MIN_TEXELS;
        let v = NoiseVolume::new(n);
        let l0 = v.level(0);
        let centre = |i: u32| (i as f32 + 0.5) / n as f32;
        for (x, y, z) in [(0, 0, 0), (3, 5, 7), (63, 1, 2)] {
            let want = l0[(x + n * (y + n * z)) as usize].map(|b| b as f32 / 255.0);
            let got = v.sample([centre(x), centre(y), centre(z)], 0.0);
            // Weights 0 and 1 exactly at texel centres: only f32 rounding.
            for c in 0..4 {
                assert!((got[c] - want[c]).abs() < 1e-5, "{got:?} vs {want:?}");
            }
            // One tile further is the same value (repeat addressing).
            let again = v.sample([centre(x) + 1.0, centre(y) - 2.0, centre(z) + 3.0], 0.0);
            for c in 0..4 {
                assert!((again[c] - got[c]).abs() < 1e-4, "{again:?} vs {got:?}");
            }
        }
        // Between two centres along x: their mean.
        let (a, b) = (l0[0][2] as f32 / 255.0, l0[1][2] as f32 / 255.0);
        let mid = v.sample([1.0 / n as f32, centre(0), centre(0)], 0.0)[2];
        assert!((mid - 0.5 * (a + b)).abs() < 1e-5);
        // Half-way between levels 1 and 2: the mean of the two levels.
        let p = [0.3, 0.7, 0.1];
        let (s1, s2, s15) = (v.sample(p, 1.0), v.sample(p, 2.0), v.sample(p, 1.5));
        for c in 0..4 {
            assert!((s15[c] - 0.5 * (s1[c] + s2[c])).abs() < 1e-5);
        }
        // The last level is one texel, the mean of everything; past it, clamped.
        assert_eq!(v.level_count(), 7);
        assert_eq!(v.level(6).len(), 1);
        assert_eq!(v.sample(p, 6.0), v.sample([0.9, 0.2, 0.5], 40.0));
        let s = v.noise3([100.0, -250.0, 1800.0], 12.0, 1.0 / 900.0, 6);
        assert!((-0.5..=0.5).contains(&s));
    }

    #[test]
    fn mips_average_blocks_and_keep_the_mean() {
        let n = MIN_TEXELS;
        let v = NoiseVolume::new(n);
        let (l0, l1) = (v.level(0), v.level(1));
        // Texel (1, 2, 3) of level 1 is the rounded mean of its 8 children.
        let (x, y, z) = (1u32, 2u32, 3u32);
        for c in 0..4 {
            let mut sum = 0u32;
            for d in 0..8u32 {
                let (cx, cy, cz) = (2 * x + (d & 1), 2 * y + (d >> 1 & 1), 2 * z + (d >> 2));
                sum += l0[(cx + n * (cy + n * cz)) as usize][c] as u32;
            }
            let want = ((sum + 4) / 8) as u8;
            assert_eq!(l1[(x + n / 2 * (y + n / 2 * z)) as usize][c], want);
        }
        // Each rounding moves the mean by < 1/2 step: the 1-texel level is
        // within 6 × 0.5 of level 0's mean, per channel.
        for c in 0..4 {
            let mean = l0.iter().map(|t| t[c] as f64).sum::<f64>() / l0.len() as f64;
            let top = v.level(v.level_count() - 1)[0][c] as f64;
            assert!((top - mean).abs() <= 3.0, "channel {c}: {top} vs {mean}");
        }
    }

    #[test]
    fn channels_tile_seamlessly_span_the_range_and_get_finer() {
        let n = MIN_TEXELS;
        let v = NoiseVolume::with_seed(n, 3);
        let t = v.level(0);
        let at = |x: u32, y: u32, z: u32, c: usize| t[(x + n * (y + n * z)) as usize][c] as i32;
        let mut mean_step = [0f64; 4];
        for c in 0..4 {
            assert_eq!(t.iter().map(|p| p[c]).min(), Some(0));
            assert_eq!(t.iter().map(|p| p[c]).max(), Some(255));
            // Wrapping: across the seam (x = n−1 to 0) neighbours differ no
            // more than neighbours inside the tile do.
            let (mut seam, mut inner) = (0, 0);
            for z in 0..n {
                for y in 0..n {
                    seam = seam.max((at(n - 1, y, z, c) - at(0, y, z, c)).abs());
                    inner = inner.max((at(n / 2, y, z, c) - at(n / 2 - 1, y, z, c)).abs());
                    for x in 1..n {
                        mean_step[c] += (at(x, y, z, c) - at(x - 1, y, z, c)).abs() as f64;
                    }
                }
            }
            // 1.5× + 8: the seam is an ordinary neighbour pair; allow the
            // spread of a maximum over one plane of pairs.
            assert!(
                seam as f32 <= inner as f32 * 1.5 + 8.0,
                "channel {c}: seam {seam} inner {inner}"
            );
        }
        // Channel c has 2^c times the lattice frequency: its neighbours
        // differ more (×1.3 at least, of the ideal ×2 for a ramp; the finest
        // channel, two texels per cell, saturates toward uncorrelated
        // neighbours).
        for c in 1..4 {
            assert!(mean_step[c] > 1.3 * mean_step[c - 1], "{mean_step:?}");
        }
    }

    #[test]
    fn octaves_past_four_come_from_the_second_fetch() {
        let v = NoiseVolume::new(MIN_TEXELS);
        let inv = 1.0 / 900.0;
        // 5 and 6 octaves differ from 4 somewhere (they add detail).
        let differs = (0..50).any(|i| {
            let p = [i as f32 * 37.0, i as f32 * -11.0, 1500.0 + i as f32 * 5.0];
            (v.noise3(p, 0.0, inv, 6) - v.noise3(p, 0.0, inv, 4)).abs() > 1e-3
        });
        assert!(differs);
        // Past the mip chain every octave is its tile mean: the noise is
        // the same everywhere (no detail left to alias).
        let (p, r) = ([123.0, 456.0, 789.0], [-4000.0, 77.0, 2.0]);
        assert_ne!(
            v.noise3_lod(p, 0.0, inv, 6, 0.0),
            v.noise3_lod(r, 0.0, inv, 6, 0.0)
        );
        assert_eq!(
            v.noise3_lod(p, 0.0, inv, 6, 40.0),
            v.noise3_lod(r, 0.0, inv, 6, 40.0)
        );
        assert_eq!(lod(10.0, 0.0), 0.0);
        assert!((lod(1000.0, 0.008) - 3.0).abs() < 1e-5);
    }

    #[test]
    fn deterministic() {
        let a = NoiseVolume::with_seed(MIN_TEXELS, 1);
        assert_eq!(a.level(0), NoiseVolume::with_seed(MIN_TEXELS, 1).level(0));
        assert_ne!(a.level(0), NoiseVolume::with_seed(MIN_TEXELS, 2).level(0));
    }
}
