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

#[cfg(test)]
mod tests {
    use super::*;

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
