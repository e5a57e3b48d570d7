//! The terrain heightfield, built on the CPU: procedural fBm hills (a broad
//! valley floor with rolling hills toward the edges) or a greyscale heightmap
//! PNG, as a triangle mesh with per-vertex normals for the terrain pass.
//! The height function itself lives in [`crate::landscape`], shared with the physics.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::error::Result;
use crate::landscape::{self, Heightfield};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Terrain settings (the `[render.terrain]` table).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TerrainConfig {
    /// Draw a terrain (and, with `shadows`, cloud shadows on it).
    pub enabled: bool,
    /// Optional 8/16-bit greyscale heightmap PNG (relative to the scene file);
    /// black = 0 m, white = `height_scale_m`. None = procedural fBm hills.
    pub heightmap: Option<PathBuf>,
    /// Height of the highest terrain point. units: m
    pub height_scale_m: f32,
    /// Side of the square terrain mesh, centred on the domain (larger than the
    /// domain so the landscape reaches the horizon). units: m
    pub extent_m: f32,
    /// Vertices per side of the terrain mesh.
    pub resolution: u32,
    /// Seed of the procedural terrain.
    pub seed: u32,
    /// Height of the water surface of lakes: the terrain below it lies
    /// under a flat, dark, sky-reflecting water plane (shaders/terrain.wgsl
    /// `water`). Unset: no water. Drawn only (the physics' ground is
    /// the terrain itself). units: m
    #[serde(skip_serializing_if = "Option::is_none")]
    pub water_level_m: Option<f32>,
}

impl Default for TerrainConfig {
    fn default() -> Self {
        Self {
            enabled: true,
            heightmap: None,
            height_scale_m: 1800.0,
            extent_m: 40_000.0,
            resolution: 160,
            seed: 7,
            water_level_m: None,
        }
    }
}

/// One mesh vertex. Matches `VertexIn` in shaders/terrain.wgsl.
/// The water plane's vertices have the normal [`WATER_NORMAL`], which no
/// ground vertex has (ground normals point up): the terrain shader tells
/// water from ground by it.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct TerrainVertex {
    /// units: m
    pub position: [f32; 3],
    pub normal: [f32; 3],
}

/// Normal of the water plane's vertices (see [`TerrainVertex`]).
pub const WATER_NORMAL: [f32; 3] = [0.0, 0.0, -1.0];

/// A heightfield mesh.
pub struct TerrainMesh {
    pub vertices: Vec<TerrainVertex>,
    pub indices: Vec<u32>,
}

/// Procedural height at (x, y) of `cfg`'s hills ([`landscape::procedural_height`]). units: m
pub fn procedural_height(x: f32, y: f32, cfg: &TerrainConfig) -> f32 {
    landscape::procedural_height(x, y, cfg.seed, cfg.height_scale_m)
}

/// The ground height of `cfg` (heightmap paths as given), the one the
/// physics also uses.
pub fn heightfield(cfg: &TerrainConfig) -> Result<Heightfield> {
    match &cfg.heightmap {
        None => Ok(Heightfield::procedural(cfg.seed, cfg.height_scale_m)),
        Some(path) => Heightfield::heightmap(path, cfg.extent_m, cfg.height_scale_m),
    }
}

/// Heights on an `n`×`n` grid (row-major, row 0 at y = −extent/2).
fn heights(cfg: &TerrainConfig) -> Result<Vec<f32>> {
    let n = cfg.resolution as usize;
    let half = cfg.extent_m * 0.5;
    let step = cfg.extent_m / (n - 1) as f32;
    let field = heightfield(cfg)?;
    Ok((0..n * n)
        .map(|i| field.height_m((i % n) as f32 * step - half, (i / n) as f32 * step - half))
        .collect())
}

/// Builds the terrain mesh for `cfg` (heightmap paths as given: resolve them
/// first with [`crate::config::RenderConfig::resolve_paths`]).
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
    if let Some(level) = cfg.water_level_m {
        // One quad over the whole terrain at the water level: the depth
        // test shows it where the ground lies lower (the lakes) and hides
        // it under the hills.
        let a = vertices.len() as u32;
        for (x, y) in [(-half, -half), (half, -half), (-half, half), (half, half)] {
            vertices.push(TerrainVertex {
                position: [x, y, level],
                normal: WATER_NORMAL,
            });
        }
        indices.extend_from_slice(&[a, a + 1, a + 3, a, a + 3, a + 2]);
    }
    Ok(TerrainMesh { vertices, indices })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn water_is_one_quad_at_its_level_told_apart_by_its_normal() {
        let dry = TerrainConfig {
            resolution: 9,
            ..TerrainConfig::default()
        };
        let wet = TerrainConfig {
            water_level_m: Some(50.0),
            ..dry.clone()
        };
        let (d, w) = (build_mesh(&dry).unwrap(), build_mesh(&wet).unwrap());
        assert_eq!(w.vertices.len(), d.vertices.len() + 4);
        assert_eq!(w.indices.len(), d.indices.len() + 6);
        assert_eq!(w.vertices[..d.vertices.len()], d.vertices[..]);
        for v in &w.vertices[d.vertices.len()..] {
            assert_eq!((v.position[2], v.normal), (50.0, WATER_NORMAL));
        }
        // No ground normal can be mistaken for the water's.
        assert!(d.vertices.iter().all(|v| v.normal[2] > 0.0));
    }

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
