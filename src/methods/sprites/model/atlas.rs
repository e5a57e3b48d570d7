//! The 16-texture sprite atlas (paper §3.2, Figure 6), generated from our
//! own noise since we have no artist's textures: one RGBA8 sheet of 4 × 4
//! tiles. Top row: three foggy stratus tiles (a lumpy-edged patch of
//! low-frequency density, 0.3–0.9, with a subtle bluish-grey tinge) and,
//! upper right, the flat-bottomed tile for cumulus bases; then six wispy
//! tiles (used by every type: fibrous strands with hooked heads and fraying
//! tails) and six puffy cumulus tiles (a cauliflower of overlapping billows
//! with a solid core, an eroded, wispy fringe and each billow lit on its
//! upper side, darker in the creases and toward the bottom). RGB is the
//! tile's tint and self-shading, alpha its density; every tile's outer two
//! texels are clear; deterministic. The unit tests state the measured
//! structure (correlation between tiles, residual after a blur, core cover,
//! internal shading).

use std::path::Path;

use rayon::prelude::*;

use crate::error::Result;
use crate::noise::{fade, hash};

/// Tiles per row and column of the sheet.
pub const GRID: u32 = 4;
/// Smallest tile: the paper's 512² sheet of 128² tiles.
pub const MIN_TILE: u32 = 128;
/// Tile side of the sheet the renderer uses: the paper's 512² sheet of 128²
/// tiles. units: texels
pub const TILE_TEXELS: u32 = 128;
/// Seed of the atlas noise (`cumulus atlas` writes the same sheet).
pub const ATLAS_SEED: u32 = 1;
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

/// `octaves`-octave fBm in [0, 1].
fn fbm(x: f32, y: f32, seed: u32, octaves: u32) -> f32 {
    let (mut sum, mut amp, mut freq, mut norm) = (0.0, 0.5, 1.0, 0.0);
    for o in 0..octaves {
        sum += amp * value2(x * freq, y * freq, seed.wrapping_add(o * 101));
        norm += amp;
        amp *= 0.5;
        freq *= 2.0;
    }
    sum / norm
}

/// Smooth step from 0 at `e0` to 1 at `e1` (either order).
fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    fade(((x - e0) / (e1 - e0)).clamp(0.0, 1.0))
}

/// Per-tile random number `k` in [0, 1] of tile `i`.
fn rnd(i: u8, k: u32, s: u32) -> f32 {
    hash(i as u32, k, 0x51, s)
}

/// A second per-tile number in [0, 1): the tile's draw `k` plus a
/// golden-ratio step by index (`s` is the tile's own seed, so this is as
/// random as [`rnd`]; the shapes' variety comes from the ranges it feeds).
fn spread(i: u8, k: u32, s: u32) -> f32 {
    (rnd(0, k, s) + 0.618 * i as f32).fract()
}

/// Tile-space sun for the self-shading: up (−v), a little left, toward
/// the viewer.
const SUN: [f32; 3] = [-0.3, -0.8, 0.5];
/// Softness of the choice of visible billow for the normal (tile units of
/// sphere height): the creases between billows blend over a few texels.
const CREASE_SOFTNESS: f32 = 0.02;
/// Softness of the billows' union (fractions of a radius).
const UNION_SOFTNESS: f32 = 0.1;
/// Darkest shade of a puffy tile's creases (1: the lit top). 0.93 rather
/// than the 0.55 of a tile seen alone: measured against the path tracer
/// (issue 32), with the sprites' sunlit shares carrying a cloud's shade and
/// the sprites overlapping by the dozen, 0.82 cost 0.003 FLIP on the
/// towering cumulus and on the deck field and 0.0007 on fair weather
/// (0.96: within 0.0007 of 0.93 on every frame).
const PUFFY_SHADE_FLOOR: f32 = 0.93;
/// Room kept between any billow and the tile's edge, for the eroded fringe
/// and the fade. units: tile sides
const BILLOW_MARGIN: f32 = 0.1;

/// One billow: a sphere seen from the front, centre (x, y) and radius r in
/// tile units.
#[derive(Debug, Clone, Copy)]
struct Billow {
    x: f32,
    y: f32,
    r: f32,
}

/// One cirrus strand along the tile's streak axis: centre line
/// `off + bend·t² + hook·h(t)²` (h rising from 0 to 1 over the head),
/// half-length `len`, shifted `shift` along the axis.
#[derive(Debug, Clone, Copy)]
struct Strand {
    off: f32,
    bend: f32,
    len: f32,
    shift: f32,
    hook: f32,
}

/// A tile's seeded layout, drawn once per tile.
enum Layout {
    Billows { billows: Vec<Billow>, flat: bool },
    Fog { ax: f32, ay: f32, ox: f32, oy: f32 },
    Streaks { axis: (f32, f32), strands: Vec<Strand> },
}

/// A cauliflower of billows: one core sphere and 8–11 around its top
/// (and a little below its sides) on an ellipse of half-axes (a, b) whose
/// aspect and offset step through the six puffy tiles; the flat-bottomed
/// tile is a wide, low one.
fn billows(i: u8, s: u32, flat: bool) -> Vec<Billow> {
    let n = 8 + (rnd(i, 0, s) * 4.0) as u32;
    let q = spread(i, 5, s);
    let (a, b) = if flat {
        (0.4, 0.22)
    } else {
        let a = 0.23 + 0.19 * q;
        (a, 0.1 / a)
    };
    let lean = 0.3 * (rnd(i, 6, s) - 0.5);
    let phi = std::f32::consts::TAU * (rnd(0, 8, s) + i as f32 / 6.0);
    let cx = 0.5 + 0.11 * phi.cos();
    let cy = if flat { 0.44 } else { 0.5 + 0.09 * phi.sin() };
    let m = a.min(b);
    let mut out = vec![Billow {
        x: cx,
        y: cy,
        r: 0.75 * m,
    }];
    for k in 0..n {
        let t = (k as f32 + rnd(i, 10 + k, s)) / n as f32;
        let ang = -std::f32::consts::PI * (t * 1.5 - 0.25);
        let r = m * (0.4 + 0.3 * rnd(i, 30 + k, s));
        let e = 0.95 - 0.5 * r / m;
        out.push(Billow {
            x: cx + a * e * ang.cos() - lean * ang.sin() * b,
            y: cy + b * e * ang.sin(),
            r,
        });
    }
    for bl in &mut out {
        bl.r = bl.r.min(0.5 - BILLOW_MARGIN);
        let (lo, hi) = (BILLOW_MARGIN + bl.r, 1.0 - BILLOW_MARGIN - bl.r);
        bl.x = bl.x.clamp(lo, hi);
        bl.y = bl.y.clamp(lo, hi);
    }
    out
}

/// Two to four strands, about parallel, each bent and hooked its own way.
fn strands(i: u8, s: u32) -> Vec<Strand> {
    let n = 2 + (rnd(i, 2, s) * 3.0) as u32;
    (0..n)
        .map(|k| {
            let sign = if rnd(i, 60 + k, s) > 0.5 { 1.0 } else { -1.0 };
            Strand {
                off: (k as f32 - (n - 1) as f32 / 2.0) * 0.16 + 0.06 * (rnd(i, 10 + k, s) - 0.5),
                bend: (rnd(i, 20 + k, s) - 0.5) * 0.6,
                len: 0.28 + 0.12 * rnd(i, 30 + k, s),
                shift: 0.12 * (rnd(i, 40 + k, s) - 0.5),
                hook: sign * (0.06 + 0.08 * rnd(i, 50 + k, s)),
            }
        })
        .collect()
}

impl Layout {
    fn new(i: u8, s: u32) -> Layout {
        match tile_kind(i) {
            TileKind::Puffy | TileKind::FlatBottom => {
                let flat = tile_kind(i) == TileKind::FlatBottom;
                Layout::Billows {
                    billows: billows(i, s, flat),
                    flat,
                }
            }
            TileKind::Foggy => {
                // Ellipses of different aspect (equal area) and offsets.
                let ax = 0.3 + 0.18 * spread(i, 5, s);
                let phi = std::f32::consts::TAU * (rnd(0, 8, s) + i as f32 / 3.0);
                Layout::Fog {
                    ax,
                    ay: 0.12 / ax,
                    ox: 0.1 * phi.cos(),
                    oy: 0.1 * phi.sin(),
                }
            }
            TileKind::Wispy => {
                let ang = rnd(i, 1, s) * std::f32::consts::TAU;
                Layout::Streaks {
                    axis: (ang.cos(), ang.sin()),
                    strands: strands(i, s),
                }
            }
        }
    }
}

/// (shade, alpha) of a puffy or flat-bottomed tile at (u, v).
fn puffy(billows: &[Billow], flat: bool, u: f32, v: f32, s: u32) -> (f32, f32) {
    // A warp of the lookup pulls the fringe into wisps.
    let pu = u + 0.07 * (fbm(u * 4.0 + 11.3, v * 4.0 + 7.1, s ^ 0x1234, 4) - 0.5);
    let pv = v + 0.07 * (fbm(u * 4.0 + 3.7, v * 4.0 + 1.9, s ^ 0x4321, 4) - 0.5);
    // Each billow's height above the tile (a sphere; outside it, minus the
    // distance), the smooth union of their insides, and the normal of the
    // visible one, blended across the creases.
    let mut best = f32::MIN;
    let mut parts = [(0.0f32, 0.0f32, 0.0f32); 16];
    let mut union = 0.0;
    for (p, b) in parts.iter_mut().zip(billows) {
        let (dx, dy) = ((pu - b.x) / b.r, (pv - b.y) / b.r);
        let d2 = dx * dx + dy * dy;
        let d = d2.sqrt();
        let h = if d < 1.0 {
            b.r * (1.0 - d2).sqrt()
        } else {
            b.r * (1.0 - d)
        };
        best = best.max(h);
        union += ((1.0 - d) / UNION_SOFTNESS).exp();
        *p = (h, dx, dy);
    }
    let (mut w_sum, mut nx, mut ny) = (0.0, 0.0, 0.0);
    for &(h, dx, dy) in &parts[..billows.len()] {
        let w = ((h - best) / CREASE_SOFTNESS).exp();
        w_sum += w;
        nx += w * dx;
        ny += w * dy;
    }
    let (nx, ny) = (nx / w_sum, ny / w_sum);
    // Eroded edge: higher-frequency noise eats into the union.
    let inside = UNION_SOFTNESS * union.ln();
    let eroded = inside - 0.5 * (fbm(u * 12.0, v * 12.0, s ^ 0x77, 5) - 0.3);
    let mut a = smoothstep(0.0, 0.2, eroded);
    // Lit on the upper side of each billow, darker toward its rim (the
    // creases) and toward the bottom, with a little mottling.
    let nz = (1.0 - nx * nx - ny * ny).max(0.0).sqrt();
    let len = (SUN[0] * SUN[0] + SUN[1] * SUN[1] + SUN[2] * SUN[2]).sqrt();
    let lit = ((nx * SUN[0] + ny * SUN[1] + nz * SUN[2]) / len).clamp(0.0, 1.0);
    let mut shade = (0.6 + 0.4 * lit) * (0.82 + 0.18 * nz);
    shade *= 1.0 - 0.15 * ((v - 0.35) / 0.5).clamp(0.0, 1.0);
    shade += 0.16 * (fbm(u * 9.0 + 5.0, v * 9.0 + 5.0, s ^ 0x99, 5) - 0.5);
    if flat {
        // Cut flat (softly) at 60–68 % of the height, the base darker.
        shade *= 1.0 - 0.2 * smoothstep(0.45, 0.66, v);
        a *= smoothstep(0.68, 0.6, v);
    }
    // The billows' shading is kept shallow: the sprites' own corners
    // carry a parcel's light and shade (model::shading), and overlapping
    // tiles of deep shading read as a speckle finer than the billows.
    let depth = (1.0 - shade.clamp(0.55, 1.0)) / 0.45;
    (1.0 - (1.0 - PUFFY_SHADE_FLOOR) * depth, a)
}

/// Alpha of a wispy tile at (u, v): fibrous strands, each with a dense
/// hooked head and a tail that widens, frays and fades.
fn wispy(axis: (f32, f32), strands: &[Strand], u: f32, v: f32, s: u32) -> f32 {
    let (x, y) = (u - 0.5, v - 0.5);
    let (c, sn) = axis;
    let (along, across) = (x * c + y * sn, -x * sn + y * c);
    let mut a: f32 = 0.0;
    for (k, st) in strands.iter().enumerate() {
        let kf = k as f32;
        let t = along - st.shift;
        let l = st.len;
        let h0 = smoothstep(0.3 * l, l, t);
        let h1 = smoothstep(0.3 * l, l, t + 1e-3);
        let centre = st.off + st.bend * t * t + st.hook * h0 * h0;
        let slope = 2.0 * st.bend * t + st.hook * (h1 * h1 - h0 * h0) / 1e-3;
        // Distance across the strand, corrected for its slope.
        let dist = (across - centre) / (1.0 + slope * slope).sqrt();
        let tail = ((l - t) / (2.0 * l)).clamp(0.0, 1.0);
        let width = 0.018 + 0.1 * tail * fbm(t * 3.0 + kf * 7.0, kf * 3.0, s ^ 0x55, 3);
        if dist.abs() > 3.0 * width {
            continue; // exp(−9): nothing there
        }
        let profile = (-(dist / width).powi(2)).exp();
        let fibres = smoothstep(
            0.25,
            0.7,
            fbm(t * 3.0 + kf * 13.0, dist * 70.0 + kf * 5.0, s ^ 0x66, 3),
        );
        let along_density = 0.4 + 1.4 * fbm(t * 7.0 + kf * 3.3, kf * 1.7, s ^ 0x88, 3);
        let ends = smoothstep(l, 0.75 * l, t) * smoothstep(-l, -0.2 * l, t);
        a = a.max(profile * fibres * ends * (1.1 - 0.5 * tail) * along_density);
    }
    a.clamp(0.0, 1.0) * smoothstep(0.5, 0.42, (x * x + y * y).sqrt())
}

/// RGBA in [0, 1] of tile `i` (layout `layout`) at (u, v) ∈ [0, 1]² (v
/// down), from the tile's seed `s`.
fn texel(i: u8, layout: &Layout, u: f32, v: f32, s: u32) -> [f32; 4] {
    let (rgb, a) = match layout {
        Layout::Billows { billows, flat } => {
            let (shade, a) = puffy(billows, *flat, u, v, s);
            ([shade; 3], a)
        }
        &Layout::Fog { ax, ay, ox, oy } => {
            // A patch with a lumpy edge and low-frequency density (0.3–0.9).
            let (x, y) = ((u - 0.5 - ox) / ax, (v - 0.5 - oy) / ay);
            let r = (x * x + y * y).sqrt();
            let edge = 1.0 + (fbm(u * 2.5 + 7.0 * i as f32, v * 2.5, s ^ 0xabc, 4) - 0.5);
            let n = fbm(u * 4.0, v * 4.0, s, 5);
            // Rolls and lumps a few times smaller than the patch: a deck
            // seen from below keeps a texture where one sprite fills the view.
            let m = 0.7 * fbm(u * 11.0 + 3.1, v * 11.0, s ^ 0x77, 3)
                + 0.3 * fbm(u * 37.0, v * 37.0 + 5.3, s ^ 0x99, 2);
            let a = smoothstep(edge, 0.4 * edge, r)
                * (0.3 + 0.6 * smoothstep(0.25, 0.75, n))
                * (0.7 + 0.3 * m);
            // §3.2: a subtle bluish-grey tinge; darker in the lumps' creases.
            let k = 0.62 + 0.38 * m;
            ([(0.84 + 0.06 * n) * k, (0.86 + 0.06 * n) * k, (0.92 + 0.05 * n) * k], a)
        }
        Layout::Streaks { axis, strands } => ([0.95; 3], wispy(*axis, strands, u, v, s)),
    };
    [rgb[0], rgb[1], rgb[2], a.clamp(0.0, 1.0)]
}

/// Fade toward the tile's edge, by texel: 0 on the outermost two texels,
/// 1 from 8 % of the side inward, so no square edge can show.
fn border_fade(p: u32, tile: u32) -> f32 {
    let d = (p as f32 + 0.5).min(tile as f32 - p as f32 - 0.5);
    smoothstep(2.0, 2.0 + 0.08 * tile as f32, d)
}

impl Atlas {
    /// The sheet with tiles of `tile` texels (≥ 128), from `seed`.
    pub fn generate(tile: u32, seed: u32) -> Atlas {
        let tile = tile.max(MIN_TILE);
        let size = tile * GRID;
        let seeds: Vec<u32> = (0..16u32)
            .map(|i| seed.wrapping_mul(16).wrapping_add(i + 1))
            .collect();
        let layouts: Vec<Layout> = (0..16u8).map(|i| Layout::new(i, seeds[i as usize])).collect();
        let mut rgba = vec![0u8; (size * size * 4) as usize];
        rgba.par_chunks_exact_mut((size * 4) as usize)
            .enumerate()
            .for_each(|(row, line)| {
                let (ty, py) = (row as u32 / tile, row as u32 % tile);
                for (col, px) in line.chunks_exact_mut(4).enumerate() {
                    let (tx, pxx) = (col as u32 / tile, col as u32 % tile);
                    let i = (ty * GRID + tx) as u8;
                    let mut t = texel(
                        i,
                        &layouts[i as usize],
                        (pxx as f32 + 0.5) / tile as f32,
                        (py as f32 + 0.5) / tile as f32,
                        seeds[i as usize],
                    );
                    t[3] *= border_fade(pxx, tile) * border_fade(py, tile);
                    for (o, c) in px.iter_mut().zip(t) {
                        *o = (c * 255.0).round() as u8;
                    }
                }
            });
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The renderer's sheet, tile by tile: alpha and luminance in [0, 1].
    fn tiles() -> (usize, Vec<Vec<f32>>, Vec<Vec<f32>>) {
        let a = Atlas::generate(TILE_TEXELS, ATLAS_SEED);
        let t = a.tile_size() as usize;
        let (mut alpha, mut lum) = (Vec::new(), Vec::new());
        for i in 0..16 {
            let px = a.tile(i);
            alpha.push(px.chunks(4).map(|p| p[3] as f32 / 255.0).collect());
            lum.push(
                px.chunks(4)
                    .map(|p| (0.2126 * p[0] as f32 + 0.7152 * p[1] as f32 + 0.0722 * p[2] as f32) / 255.0)
                    .collect(),
            );
        }
        (t, alpha, lum)
    }

    fn mean_std(x: impl Iterator<Item = f32> + Clone) -> (f32, f32) {
        let n = x.clone().count() as f32;
        let m = x.clone().sum::<f32>() / n;
        (m, (x.map(|v| (v - m) * (v - m)).sum::<f32>() / n).sqrt())
    }

    fn puffy_like() -> impl Iterator<Item = usize> {
        PUFFY_TILES.iter().chain([&FLAT_BOTTOM_TILE]).map(|&i| i as usize)
    }

    #[test]
    fn same_seed_same_bytes() {
        let a = Atlas::generate(MIN_TILE, 5);
        assert_eq!(a, Atlas::generate(MIN_TILE, 5));
        assert_ne!(a.rgba, Atlas::generate(MIN_TILE, 6).rgba);
    }

    #[test]
    fn no_two_tiles_correlate_above_0_8() {
        let (_, alpha, _) = tiles();
        let mut worst = (0.0f32, 0, 0);
        for i in 0..16 {
            for j in 0..i {
                let (mi, si) = mean_std(alpha[i].iter().copied());
                let (mj, sj) = mean_std(alpha[j].iter().copied());
                let cov = alpha[i].iter().zip(&alpha[j]).map(|(a, b)| (a - mi) * (b - mj)).sum::<f32>()
                    / alpha[i].len() as f32;
                let r = cov / (si * sj);
                if r > worst.0 {
                    worst = (r, i, j);
                }
            }
        }
        // The bound; the sheet measures 0.78 (tiles 12 and 14, two
        // puffs of similar aspect). The old smooth sheet: 0.99 (fog 0, 1).
        assert!(worst.0 < 0.8, "tiles {} and {}: r = {}", worst.1, worst.2, worst.0);
    }

    #[test]
    fn cumulus_alpha_has_structure_beyond_an_8_texel_blur() {
        let (t, alpha, _) = tiles();
        for i in puffy_like() {
            let a = &alpha[i];
            // 8 × 8 box (texels x−4..x+3), clipped to the tile.
            let blur = |x: usize, y: usize| {
                let (x0, x1) = (x.saturating_sub(4), (x + 4).min(t));
                let (y0, y1) = (y.saturating_sub(4), (y + 4).min(t));
                let sum: f32 = (y0..y1).flat_map(|yy| (x0..x1).map(move |xx| (xx, yy))).map(|(xx, yy)| a[yy * t + xx]).sum();
                sum / ((x1 - x0) * (y1 - y0)) as f32
            };
            let residual: Vec<f32> = (0..t * t)
                .filter_map(|k| {
                    let b = blur(k % t, k / t);
                    (b > 0.05).then_some(a[k] - b)
                })
                .collect();
            let (_, std) = mean_std(residual.iter().copied());
            // New tiles measure 0.11–0.12, the flat-bottomed 0.14 (billowed,
            // eroded, wispy edges and the cut);
            // the old noisy blobs 0.047–0.055 (0.051 the flat-bottomed).
            // 0.07 sits between them.
            assert!(std >= 0.07, "tile {i}: residual std {std}");
        }
    }

    #[test]
    fn puffs_have_a_solid_core_and_every_tile_a_clear_border() {
        let (t, alpha, _) = tiles();
        for i in PUFFY_TILES {
            let core = alpha[i as usize].iter().filter(|&&a| a > 0.9).count() as f32 / (t * t) as f32;
            // Neighbouring sprites must read as one body: measured 0.26–0.29;
            // the old blobs never passed 0.9 (≤ 0.01).
            assert!(core >= 0.25, "tile {i}: alpha > 0.9 over {core}");
        }
        for (i, a) in alpha.iter().enumerate() {
            for (k, &texel) in a.iter().enumerate().take(t * t) {
                let (x, y) = (k % t, k / t);
                if x.min(y) < 2 || x.max(y) >= t - 2 {
                    // Exactly 0: no square edge, however the sprite is tinted.
                    assert_eq!(texel, 0.0, "tile {i} texel ({x}, {y})");
                }
            }
        }
    }

    #[test]
    fn puffs_are_shaded_inside_and_lit_from_above() {
        let (t, alpha, lum) = tiles();
        for i in PUFFY_TILES.iter().map(|&i| i as usize) {
            let (a, l) = (&alpha[i], &lum[i]);
            let body = (0..t * t).filter(|&k| a[k] > 0.5).map(|k| l[k]);
            // Over the shade's range (1 − PUFFY_SHADE_FLOOR), so the
            // structure is tested whatever its depth: billows lit on top,
            // darker creases measure 0.25–0.28 (0.11–0.12 over the 0.45 range
            // the tiles had before, 0.045 over today's 0.18); the old
            // vertical ramp gave 0.04–0.07 (0.02–0.03 over 0.45).
            let (_, std) = mean_std(body);
            let relative = std / (1.0 - PUFFY_SHADE_FLOOR);
            assert!(relative >= 0.13, "tile {i}: luminance std {std}, {relative} of the range");
            let half = |rows: std::ops::Range<usize>| {
                let (mut s, mut w) = (0.0, 0.0);
                for k in rows.start * t..rows.end * t {
                    s += l[k] * a[k];
                    w += a[k];
                }
                s / w
            };
            let (top, bottom) = (half(0..t / 2), half(t / 2..t));
            assert!(top > bottom, "tile {i}: top {top} bottom {bottom}");
        }
    }
}
