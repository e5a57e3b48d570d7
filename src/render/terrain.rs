//! The terrain heightfield, built on the CPU: procedural fBm hills (a broad
//! valley floor with rolling hills toward the edges) or a greyscale heightmap
//! PNG, as a triangle mesh with per-vertex normals for the terrain pass.

use std::path::Path;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::error::{Error, Result};
use crate::render::{TerrainConfig, noise};

/// One mesh vertex. Matches `VertexIn` in shaders/terrain.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct TerrainVertex {
    /// units: m
    pub position: [f32; 3],
    pub normal: [f32; 3],
}

/// A heightfield mesh.
pub struct TerrainMesh {
    pub vertices: Vec<TerrainVertex>,
    pub indices: Vec<u32>,
}

/// The noise texture's lattice hash: with the seed in the z slot and a zero
/// seed it mixes exactly the words this 2D hash always mixed.
fn hash2(x: i32, y: i32, seed: u32) -> f32 {
    noise::hash(x as u32, y as u32, seed, 0)
}

fn value2(x: f32, y: f32, seed: u32) -> f32 {
    let (ix, iy) = (x.floor(), y.floor());
    let (fx, fy) = (x - ix, y - iy);
    let (sx, sy) = (noise::fade(fx), noise::fade(fy));
    let (ix, iy) = (ix as i32, iy as i32);
    let a = hash2(ix, iy, seed);
    let b = hash2(ix + 1, iy, seed);
    let c = hash2(ix, iy + 1, seed);
    let d = hash2(ix + 1, iy + 1, seed);
    let top = a + (b - a) * sx;
    let bot = c + (d - c) * sx;
    top + (bot - top) * sy
}

/// Procedural height at (x, y): fBm hills, low in the middle (the valley
/// floor under the simulated domain, at most a fifth of the scale) rising to
/// mountains toward the mesh edge, in [0, height_scale_m]. units: m
pub fn procedural_height(x: f32, y: f32, cfg: &TerrainConfig) -> f32 {
    let mut sum = 0.0;
    let mut amp = 1.0;
    let mut norm = 0.0;
    let mut freq = 1.0 / 6000.0;
    for o in 0..6 {
        sum += amp * value2(x * freq, y * freq, cfg.seed.wrapping_add(o));
        norm += amp;
        amp *= 0.5;
        freq *= 2.1;
    }
    let h = sum / norm;
    let r = (x * x + y * y).sqrt();
    let t = ((r - 7000.0) / 11000.0).clamp(0.0, 1.0);
    let envelope = 0.2 + 0.8 * t * t * (3.0 - 2.0 * t);
    (h * envelope).clamp(0.0, 1.0) * cfg.height_scale_m
}

/// Heights on an `n`×`n` grid (row-major, row 0 at y = −extent/2).
fn heights(cfg: &TerrainConfig) -> Result<Vec<f32>> {
    let n = cfg.resolution as usize;
    let half = cfg.extent_m * 0.5;
    let step = cfg.extent_m / (n - 1) as f32;
    match &cfg.heightmap {
        None => Ok((0..n * n)
            .map(|i| {
                let (x, y) = ((i % n) as f32 * step - half, (i / n) as f32 * step - half);
                procedural_height(x, y, cfg)
            })
            .collect()),
        Some(path) => {
            let img = load_heightmap(path)?;
            let (w, h) = img.dimensions();
            Ok((0..n * n)
                .map(|i| {
                    // Bilinear lookup; image row 0 is north (+y).
                    let u = (i % n) as f32 / (n - 1) as f32 * (w - 1) as f32;
                    let v = (1.0 - (i / n) as f32 / (n - 1) as f32) * (h - 1) as f32;
                    let (x0, y0) = (u.floor() as u32, v.floor() as u32);
                    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
                    let (fx, fy) = (u - x0 as f32, v - y0 as f32);
                    let p = |x, y| img.get_pixel(x, y).0[0] as f32 / 65535.0;
                    let top = p(x0, y0) * (1.0 - fx) + p(x1, y0) * fx;
                    let bot = p(x0, y1) * (1.0 - fx) + p(x1, y1) * fx;
                    (top * (1.0 - fy) + bot * fy) * cfg.height_scale_m
                })
                .collect())
        }
    }
}

fn load_heightmap(path: &Path) -> Result<image::ImageBuffer<image::Luma<u16>, Vec<u16>>> {
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

/// Builds the terrain mesh for `cfg` (heightmap paths as given: resolve them
/// first with [`crate::render::RenderConfig::resolve_paths`]).
pub fn build_mesh(cfg: &TerrainConfig) -> Result<TerrainMesh> {
    let n = cfg.resolution as usize;
    let hs = heights(cfg)?;
    let half = cfg.extent_m * 0.5;
    let step = cfg.extent_m / (n - 1) as f32;
    let at = |x: usize, y: usize| hs[y.min(n - 1) * n + x.min(n - 1)];
    let mut vertices = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let dx = at(i + 1, j) - at(i.saturating_sub(1), j);
            let dy = at(i, j + 1) - at(i, j.saturating_sub(1));
            let spanx = ((i + 1).min(n - 1) - i.saturating_sub(1)) as f32 * step;
            let spany = ((j + 1).min(n - 1) - j.saturating_sub(1)) as f32 * step;
            let normal = Vec3::new(-dx / spanx, -dy / spany, 1.0).normalize();
            vertices.push(TerrainVertex {
                position: [i as f32 * step - half, j as f32 * step - half, at(i, j)],
                normal: normal.to_array(),
            });
        }
    }
    let mut indices = Vec::with_capacity((n - 1) * (n - 1) * 6);
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = (j * n + i) as u32;
            let b = a + 1;
            let c = a + n as u32;
            let d = c + 1;
            // Counter-clockwise seen from above (+z).
            indices.extend_from_slice(&[a, b, d, a, d, c]);
        }
    }
    Ok(TerrainMesh { vertices, indices })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mesh_shape_and_heights() {
        let cfg = TerrainConfig {
            resolution: 17,
            ..TerrainConfig::default()
        };
        let m = build_mesh(&cfg).unwrap();
        assert_eq!(m.vertices.len(), 17 * 17);
        assert_eq!(m.indices.len(), 16 * 16 * 6);
        for v in &m.vertices {
            assert!((0.0..=cfg.height_scale_m).contains(&v.position[2]));
            assert!(v.normal[2] > 0.0);
        }
        let first = m.vertices[0].position;
        assert_eq!(first[0], -cfg.extent_m / 2.0);
    }

    #[test]
    fn missing_heightmap_names_the_file() {
        let cfg = TerrainConfig {
            heightmap: Some("/nonexistent/h.png".into()),
            ..TerrainConfig::default()
        };
        let e = build_mesh(&cfg).err().unwrap().to_string();
        assert!(e.contains("/nonexistent/h.png"), "{e}");
    }

    #[test]
    fn heightmap_png_is_read() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("h.png");
        // 2×2: west column black, east column white.
        let img = image::GrayImage::from_raw(2, 2, vec![0, 255, 0, 255]).unwrap();
        img.save(&path).unwrap();
        let cfg = TerrainConfig {
            heightmap: Some(path),
            resolution: 3,
            height_scale_m: 100.0,
            ..TerrainConfig::default()
        };
        let m = build_mesh(&cfg).unwrap();
        assert!((m.vertices[0].position[2] - 0.0).abs() < 1e-3);
        assert!((m.vertices[2].position[2] - 100.0).abs() < 1e-3);
        assert!((m.vertices[1].position[2] - 50.0).abs() < 1e-3);
    }
}
