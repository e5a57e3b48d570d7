//! The tiling 3D noise texture of the hypertexture (paper §6.1), built on the
//! CPU at start-up: fBm of periodic value noise (smooth-step interpolated
//! lattice values from an integer hash), so the texture wraps seamlessly and
//! the shader can sample it with a repeating sampler at any scale. Values are
//! stretched to fill 0..=255. Deterministic: same size and seed, same bytes.

/// Lattice periods of the octaves: the texture tile holds whole periods.
const BASE_PERIOD: u32 = 4;
/// Octaves baked into the texture (the shader sums a few more at run time).
const OCTAVES: u32 = 4;

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

/// An `n`³ R8 texture of tiling fBm (x fastest, then y, then z).
pub fn tiling_fbm(n: u32, seed: u32) -> Vec<u8> {
    let mut v = Vec::with_capacity((n * n * n) as usize);
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let mut sum = 0.0;
                let mut amp = 1.0;
                let mut period = BASE_PERIOD;
                for o in 0..OCTAVES {
                    let s = period as f32 / n as f32;
                    let p = [x as f32 * s, y as f32 * s, z as f32 * s];
                    sum += amp * value_noise(p, period, seed.wrapping_add(o));
                    amp *= 0.5;
                    period *= 2;
                }
                v.push(sum);
            }
        }
    }
    let (lo, hi) = v
        .iter()
        .fold((f32::MAX, f32::MIN), |(a, b), &x| (a.min(x), b.max(x)));
    let scale = 255.0 / (hi - lo).max(1e-6);
    v.iter()
        .map(|&x| ((x - lo) * scale).round() as u8)
        .collect()
}

/// A texture of [`tiling_fbm`] with its side, sampled on the CPU the way
/// the shaders sample `noise_tex` (repeat addressing, trilinear filtering,
/// mip 0), for CPU evaluations of eq. 18 that must match the GPU.
#[derive(Debug, Clone)]
pub struct NoiseVolume {
    n: u32,
    texels: Vec<u8>,
}

impl NoiseVolume {
    /// The volume the renderer uploads for `render.noise_texels` = `n`
    /// (seed 1, as `Renderer` uses).
    pub fn new(n: u32) -> Self {
        Self {
            n,
            texels: tiling_fbm(n, 1),
        }
    }

    /// Trilinear sample in [0, 1] at texture coordinate `uvw` (1 = one
    /// tile), wrapping like a repeat sampler: texel i's centre is at
    /// (i + 0.5) / n. GPUs quantise the filter weights (often to 8 bits),
    /// so the GPU value may differ by ~1/256 of a texel step.
    pub fn sample(&self, uvw: [f32; 3]) -> f32 {
        let n = self.n as i64;
        let mut i0 = [0i64; 3];
        let mut f = [0f32; 3];
        for a in 0..3 {
            let x = uvw[a] * self.n as f32 - 0.5;
            let fl = x.floor();
            i0[a] = fl as i64;
            f[a] = x - fl;
        }
        let at = |dx: i64, dy: i64, dz: i64| {
            let x = (i0[0] + dx).rem_euclid(n);
            let y = (i0[1] + dy).rem_euclid(n);
            let z = (i0[2] + dz).rem_euclid(n);
            self.texels[(x + n * (y + n * z)) as usize] as f32 / 255.0
        };
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let x00 = lerp(at(0, 0, 0), at(1, 0, 0), f[0]);
        let x10 = lerp(at(0, 1, 0), at(1, 1, 0), f[0]);
        let x01 = lerp(at(0, 0, 1), at(1, 0, 1), f[0]);
        let x11 = lerp(at(0, 1, 1), at(1, 1, 1), f[0]);
        lerp(lerp(x00, x10, f[1]), lerp(x01, x11, f[1]), f[2])
    }

    /// The noise of eq. 18 at world point `p_m` (m) and time `time_s` (s),
    /// in [−0.5, 0.5]: the CPU twin of `noise3` in shaders/common.wgsl
    /// (keep in sync: drift, octave factor 2.03 and offset, weights, the
    /// doubling and clamp). `inv_scale_per_m` = 1 / `render.noise_scale_m`.
    pub fn noise3(&self, p_m: [f32; 3], time_s: f32, inv_scale_per_m: f32, octaves: u32) -> f32 {
        let drift = [1.5 * time_s, 0.8 * time_s, 0.3 * time_s];
        let mut q = [0f32; 3];
        for a in 0..3 {
            q[a] = (p_m[a] + drift[a]) * inv_scale_per_m;
        }
        let (mut sum, mut amp, mut norm) = (0.0f32, 1.0f32, 0.0f32);
        for _ in 0..octaves {
            sum += amp * (self.sample(q) - 0.5);
            norm += amp;
            amp *= 0.5;
            q = [q[0] * 2.03 + 0.17, q[1] * 2.03 + 0.31, q[2] * 2.03 + 0.53];
        }
        (2.0 * sum / norm.max(1e-6)).clamp(-0.5, 0.5)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn volume_samples_texel_centres_exactly_and_wraps() {
        let n = 8;
        let v = NoiseVolume::new(n);
        let t = tiling_fbm(n, 1);
        let centre = |i: u32| (i as f32 + 0.5) / n as f32;
        for (x, y, z) in [(0, 0, 0), (3, 5, 7), (7, 1, 2)] {
            let want = t[(x + n * (y + n * z)) as usize] as f32 / 255.0;
            let got = v.sample([centre(x), centre(y), centre(z)]);
            // Weights 0 and 1 exactly at texel centres: only f32 rounding.
            assert!((got - want).abs() < 1e-5, "{got} vs {want}");
            // One tile further is the same value (repeat addressing).
            let again = v.sample([centre(x) + 1.0, centre(y) - 2.0, centre(z) + 3.0]);
            assert!((again - got).abs() < 1e-4, "{again} vs {got}");
        }
        // Between two centres along x: their mean.
        let a = t[0] as f32 / 255.0;
        let b = t[1] as f32 / 255.0;
        let mid = v.sample([1.0 / n as f32, centre(0), centre(0)]);
        assert!((mid - 0.5 * (a + b)).abs() < 1e-5);
        let s = v.noise3([100.0, -250.0, 1800.0], 12.0, 1.0 / 900.0, 4);
        assert!((-0.5..=0.5).contains(&s));
    }

    #[test]
    fn tiles_seamlessly_and_spans_the_range() {
        let n = 16;
        let t = tiling_fbm(n, 3);
        assert_eq!(t.len(), 16 * 16 * 16);
        assert_eq!(*t.iter().min().unwrap(), 0);
        assert_eq!(*t.iter().max().unwrap(), 255);
        // Wrapping: the texel after the last (x = n) equals x = 0 when
        // evaluated directly, so neighbours across the seam differ no more
        // than typical neighbours do.
        let at = |x: u32, y: u32, z: u32| t[(x + n * (y + n * z)) as usize] as i32;
        let mut seam = 0;
        let mut inner = 0;
        for z in 0..n {
            for y in 0..n {
                seam = seam.max((at(n - 1, y, z) - at(0, y, z)).abs());
                inner = inner.max((at(n / 2, y, z) - at(n / 2 - 1, y, z)).abs());
            }
        }
        // 1.5×: the seam is an ordinary neighbour pair; allow sampling spread.
        assert!(
            seam as f32 <= inner as f32 * 1.5 + 8.0,
            "seam {seam} inner {inner}"
        );
    }

    #[test]
    fn deterministic() {
        assert_eq!(tiling_fbm(8, 1), tiling_fbm(8, 1));
        assert_ne!(tiling_fbm(8, 1), tiling_fbm(8, 2));
    }
}
