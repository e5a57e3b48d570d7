//! The 16-texture sprite atlas (paper §3.2, Figure 6), generated from our
//! own noise since we have no artist's textures: one RGBA8 sheet of 4 × 4
//! tiles. Top row: three foggy stratus tiles with a subtle bluish-grey tinge
//! and, upper right, the flat-bottomed tile for cumulus bases; then six
//! wispy tiles (used by every type) and six puffy cumulus tiles. RGB is the
//! tile's tint and self-shading, alpha its density; deterministic.

use std::path::Path;

use crate::error::Result;
use crate::noise::{fade, hash};

/// Tiles per row and column of the sheet.
pub const GRID: u32 = 4;
/// Smallest tile: the paper's 512² sheet of 128² tiles.
pub const MIN_TILE: u32 = 128;
/// Foggy stratus tiles.
pub const FOGGY_TILES: [u8; 3] = [0, 1, 2];
/// The flat-bottomed tile, upper right.
pub const FLAT_BOTTOM_TILE: u8 = 3;
/// Wispy tiles.
pub const WISPY_TILES: [u8; 6] = [4, 5, 6, 7, 8, 9];
/// Puffy cumulus tiles (the bottom rows).
pub const PUFFY_TILES: [u8; 6] = [10, 11, 12, 13, 14, 15];

/// What a tile looks like.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TileKind {
    Foggy,
    FlatBottom,
    Wispy,
    Puffy,
}

/// The kind of tile `i` (0–15).
pub fn tile_kind(i: u8) -> TileKind {
    match i {
        0..=2 => TileKind::Foggy,
        3 => TileKind::FlatBottom,
        4..=9 => TileKind::Wispy,
        _ => TileKind::Puffy,
    }
}

/// The sheet: `size` × `size` RGBA8 texels, row-major, ready for upload.
#[derive(Debug, Clone, PartialEq)]
pub struct Atlas {
    /// units: texels
    pub size: u32,
    pub rgba: Vec<u8>,
}

/// Value noise in [0, 1] at `(x, y)` (lattice units), 2-D slice of the
/// noise volume's lattice hash (`landscape::lattice_hash`).
fn value2(x: f32, y: f32, seed: u32) -> f32 {
    let (ix, iy) = (x.floor(), y.floor());
    let (fx, fy) = (fade(x - ix), fade(y - iy));
    let (ix, iy) = (ix as i32 as u32, iy as i32 as u32);
    let n = |dx: u32, dy: u32| hash(ix.wrapping_add(dx), iy.wrapping_add(dy), 0, seed);
    let a = n(0, 0) + (n(1, 0) - n(0, 0)) * fx;
    let b = n(0, 1) + (n(1, 1) - n(0, 1)) * fx;
    a + (b - a) * fy
}

/// Five-octave fBm in about [0, 1].
fn fbm(x: f32, y: f32, seed: u32) -> f32 {
    let (mut sum, mut amp, mut freq) = (0.0, 0.5, 1.0);
    for o in 0..5 {
        sum += amp * value2(x * freq, y * freq, seed.wrapping_add(o * 101));
        amp *= 0.5;
        freq *= 2.0;
    }
    sum / 0.96875
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    fade(((x - e0) / (e1 - e0)).clamp(0.0, 1.0))
}

/// RGBA in [0, 1] of tile `i` at (u, v) ∈ [0, 1]² (v down), from `seed`.
fn texel(i: u8, u: f32, v: f32, seed: u32) -> [f32; 4] {
    let s = seed.wrapping_mul(16).wrapping_add(i as u32 + 1);
    let (x, y) = (u - 0.5, v - 0.5);
    let r = (x * x + y * y).sqrt() * 2.0;
    let n = fbm(u * 6.0, v * 6.0, s);
    let (rgb, a) = match tile_kind(i) {
        TileKind::Puffy | TileKind::FlatBottom => {
            // A lumpy disc: its edge pushed in and out by the noise.
            let edge = 0.62 + 0.35 * (n - 0.5) * 2.0;
            let mut a = smoothstep(edge, edge - 0.35, r) * (0.55 + 0.45 * n);
            if tile_kind(i) == TileKind::FlatBottom {
                a *= smoothstep(0.68, 0.6, v);
            }
            // Lighter on top, a little darker underneath (self-shading).
            let light = 0.78 + 0.22 * (1.0 - v) + 0.1 * (n - 0.5);
            ([light; 3], a)
        }
        TileKind::Foggy => {
            let a = smoothstep(1.0, 0.3, r) * (0.35 + 0.5 * n);
            // §3.2: a subtle bluish-grey tinge.
            ([0.84 + 0.06 * n, 0.86 + 0.06 * n, 0.92 + 0.05 * n], a)
        }
        TileKind::Wispy => {
            // Streaks: noise stretched along a seeded direction.
            let ang = hash(i as u32, 7, 0, s) * std::f32::consts::PI;
            let (c, sn) = (ang.cos(), ang.sin());
            let (along, across) = (x * c + y * sn, -x * sn + y * c);
            let w = fbm(along * 2.0 + 3.0, across * 14.0 + 3.0, s ^ 0x5bd1);
            let a = smoothstep(0.5, 0.8, w) * smoothstep(1.0, 0.5, r);
            ([0.95; 3], a)
        }
    };
    [rgb[0], rgb[1], rgb[2], a.clamp(0.0, 1.0)]
}

impl Atlas {
    /// The sheet with tiles of `tile` texels (≥ 128), from `seed`.
    pub fn generate(tile: u32, seed: u32) -> Atlas {
        let tile = tile.max(MIN_TILE);
        let size = tile * GRID;
        let mut rgba = vec![0u8; (size * size * 4) as usize];
        for (row, line) in rgba.chunks_exact_mut((size * 4) as usize).enumerate() {
            let (ty, py) = (row as u32 / tile, row as u32 % tile);
            for (col, px) in line.chunks_exact_mut(4).enumerate() {
                let (tx, pxx) = (col as u32 / tile, col as u32 % tile);
                let i = (ty * GRID + tx) as u8;
                let t = texel(
                    i,
                    (pxx as f32 + 0.5) / tile as f32,
                    (py as f32 + 0.5) / tile as f32,
                    seed,
                );
                for (o, c) in px.iter_mut().zip(t) {
                    *o = (c * 255.0).round() as u8;
                }
            }
        }
        Atlas { size, rgba }
    }

    /// Side of one tile. units: texels
    pub fn tile_size(&self) -> u32 {
        self.size / GRID
    }

    /// The RGBA8 texels of tile `i`, row by row.
    pub fn tile(&self, i: u8) -> Vec<u8> {
        let t = self.tile_size() as usize;
        let (tx, ty) = (i as usize % GRID as usize, i as usize / GRID as usize);
        (0..t)
            .flat_map(|y| {
                let start = ((ty * t + y) * self.size as usize + tx * t) * 4;
                self.rgba[start..start + t * 4].iter().copied()
            })
            .collect()
    }

    /// UV rectangle (u0, v0, u1, v1) of tile `i` on the sheet.
    pub fn uv_rect(i: u8) -> [f32; 4] {
        let g = GRID as f32;
        let (x, y) = ((i as u32 % GRID) as f32, (i as u32 / GRID) as f32);
        [x / g, y / g, (x + 1.0) / g, (y + 1.0) / g]
    }

    /// Writes the sheet as a PNG, whole or not at all.
    pub fn write_png(&self, path: &Path) -> Result<()> {
        crate::output::write_png_atomic(path, self.size, self.size, &self.rgba)
    }
}
