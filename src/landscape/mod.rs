//! The height of the ground, shared by the physics (parcels leave the ground
//! and sink back into it) and the renderer (the terrain mesh): procedural fBm
//! hills or a greyscale heightmap PNG. Pure CPU; imports neither the physics
//! nor the GPU, so both can use it.

pub mod terrain;

use std::path::Path;

use crate::error::{Error, Result};

/// Integer lattice hash to [0, 1]: the terrain's 2D hills (z = seed, seed =
/// 0) and the 3D noise texture of the hypertexture (`noise`).
pub fn lattice_hash(x: u32, y: u32, z: u32, seed: u32) -> f32 {
    let mut h = x.wrapping_mul(0x8da6_b343)
        ^ y.wrapping_mul(0xd816_3841)
        ^ z.wrapping_mul(0xcb1a_b31f)
        ^ seed.wrapping_mul(0x1656_67b1);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2c1b_3c6d);
    h ^= h >> 12;
    h = h.wrapping_mul(0x297a_2d39);
    h ^= h >> 15;
    (h & 0xff_ffff) as f32 / 0xff_ffff as f32
}

/// Smooth-step interpolation weight of value noise.
pub fn fade(t: f32) -> f32 {
    t * t * (3.0 - 2.0 * t)
}

/// 2D value noise in [0, 1] at (x, y) in lattice units.
fn value2(x: f32, y: f32, seed: u32) -> f32 {
    let (ix, iy) = (x.floor(), y.floor());
    let (sx, sy) = (fade(x - ix), fade(y - iy));
    let (ix, iy) = (ix as i32, iy as i32);
    let h = |x: i32, y: i32| lattice_hash(x as u32, y as u32, seed, 0);
    let top = h(ix, iy) + (h(ix + 1, iy) - h(ix, iy)) * sx;
    let bot = h(ix, iy + 1) + (h(ix + 1, iy + 1) - h(ix, iy + 1)) * sx;
    top + (bot - top) * sy
}

/// Procedural height at (x, y): fBm hills, low in the middle (a valley floor
/// at most a fifth of the scale within 7 km of the origin) rising to full
/// relief 18 km out, in [0, height_scale_m]. The sum of six value-noise
/// octaves stays within about ±0.2 of its mean, so it is stretched 2.5×
/// about 0.5 and clipped: the relief fills the scale, valley floors and
/// hilltops flatten where it clips. On the landscape scene the hills span
/// 0–700 m at slopes of 5.8° (median) and 13.7° (p90), 33° at most.
/// units: m
pub fn procedural_height(x: f32, y: f32, seed: u32, height_scale_m: f32) -> f32 {
    let mut sum = 0.0;
    let mut amp = 1.0;
    let mut norm = 0.0;
    let mut freq = 1.0 / 6000.0;
    for o in 0..6 {
        sum += amp * value2(x * freq, y * freq, seed.wrapping_add(o));
        norm += amp;
        amp *= 0.5;
        freq *= 2.1;
    }
    let h = (0.5 + 2.5 * (sum / norm - 0.5)).clamp(0.0, 1.0);
    let r = (x * x + y * y).sqrt();
    let t = ((r - 7000.0) / 11000.0).clamp(0.0, 1.0);
    let envelope = 0.2 + 0.8 * t * t * (3.0 - 2.0 * t);
    (h * envelope).clamp(0.0, 1.0) * height_scale_m
}

/// Reads an 8- or 16-bit greyscale PNG heightmap (at least 2×2 pixels).
pub fn load_heightmap(path: &Path) -> Result<image::ImageBuffer<image::Luma<u16>, Vec<u16>>> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let img = image::load_from_memory(&bytes).map_err(|e| {
        Error::parse(
            path,
            0,
            0,
            format!("not a readable PNG heightmap ({e}); use an 8- or 16-bit greyscale PNG"),
        )
    })?;
    let img = img.to_luma16();
    if img.width() < 2 || img.height() < 2 {
        return Err(Error::parse(
            path,
            0,
            0,
            format!(
                "heightmap is {}×{} pixels; at least 2×2 is needed",
                img.width(),
                img.height()
            ),
        ));
    }
    Ok(img)
}

#[derive(Debug, Clone, PartialEq)]
enum Source {
    Flat,
    Procedural {
        seed: u32,
    },
    /// Heights in [0, 1], row 0 north (+y), spread over a square `extent_m` wide.
    Map {
        width: u32,
        height: u32,
        values: Vec<f32>,
        extent_m: f32,
    },
}

/// The ground's height everywhere: flat (z = 0), procedural or a heightmap.
#[derive(Debug, Clone, PartialEq)]
pub struct Heightfield {
    source: Source,
    /// Height of the highest possible point. units: m
    height_scale_m: f32,
}

impl Default for Heightfield {
    fn default() -> Self {
        Self::flat()
    }
}

impl Heightfield {
    /// Flat ground at z = 0.
    pub fn flat() -> Self {
        Self {
            source: Source::Flat,
            height_scale_m: 0.0,
        }
    }

    /// The procedural hills of [`procedural_height`].
    pub fn procedural(seed: u32, height_scale_m: f32) -> Self {
        Self {
            source: Source::Procedural { seed },
            height_scale_m,
        }
    }

    /// A heightmap PNG (black 0 m, white `height_scale_m`) covering a square
    /// `extent_m` wide centred on the origin; outside it the edge continues.
    pub fn heightmap(path: &Path, extent_m: f32, height_scale_m: f32) -> Result<Self> {
        let img = load_heightmap(path)?;
        Ok(Self {
            source: Source::Map {
                width: img.width(),
                height: img.height(),
                values: img.pixels().map(|p| p.0[0] as f32 / 65535.0).collect(),
                extent_m,
            },
            height_scale_m,
        })
    }

    /// Whether this is the flat ground at z = 0.
    pub fn is_flat(&self) -> bool {
        self.source == Source::Flat
    }

    /// Height of the highest possible point. units: m
    pub fn height_scale_m(&self) -> f32 {
        self.height_scale_m
    }

    /// Ground height at (x, y). units: m → m
    pub fn height_m(&self, x_m: f32, y_m: f32) -> f32 {
        match &self.source {
            Source::Flat => 0.0,
            Source::Procedural { seed } => procedural_height(x_m, y_m, *seed, self.height_scale_m),
            Source::Map {
                width,
                height,
                values,
                extent_m,
            } => {
                // Bilinear lookup; image row 0 is north (+y).
                let (w, h) = (*width, *height);
                let u = ((x_m / extent_m + 0.5) * (w - 1) as f32).clamp(0.0, (w - 1) as f32);
                let v = ((0.5 - y_m / extent_m) * (h - 1) as f32).clamp(0.0, (h - 1) as f32);
                let (x0, y0) = (u.floor() as u32, v.floor() as u32);
                let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
                let (fx, fy) = (u - x0 as f32, v - y0 as f32);
                let p = |x: u32, y: u32| values[(y * w + x) as usize];
                let top = p(x0, y0) * (1.0 - fx) + p(x1, y0) * fx;
                let bot = p(x0, y1) * (1.0 - fx) + p(x1, y1) * fx;
                (top * (1.0 - fy) + bot * fy) * self.height_scale_m
            }
        }
    }

    /// Upward unit normal of the ground at (x, y), from central differences
    /// `step_m` apart. units: m → 1
    pub fn normal(&self, x_m: f32, y_m: f32, step_m: f32) -> glam::Vec3 {
        let dx = self.height_m(x_m + step_m, y_m) - self.height_m(x_m - step_m, y_m);
        let dy = self.height_m(x_m, y_m + step_m) - self.height_m(x_m, y_m - step_m);
        glam::Vec3::new(-dx / (2.0 * step_m), -dy / (2.0 * step_m), 1.0).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_is_zero_and_procedural_stays_in_range() {
        assert_eq!(Heightfield::flat().height_m(123.0, -4.0), 0.0);
        let h = Heightfield::procedural(7, 600.0);
        for i in 0..200 {
            let (x, y) = (i as f32 * 311.0 - 30_000.0, i as f32 * -173.0 + 9_000.0);
            let z = h.height_m(x, y);
            assert!((0.0..=600.0).contains(&z), "{z}");
            assert!(h.normal(x, y, 50.0).z > 0.0);
        }
    }
}
