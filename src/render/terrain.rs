//! The terrain heightfield, built on the CPU: procedural fBm hills (a broad
//! valley floor with rolling hills toward the edges) or a greyscale heightmap
//! PNG, as a triangle mesh with per-vertex normals for the terrain pass.
//! The height function itself lives in [`crate::landscape`], shared with the physics.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::error::Result;
use crate::landscape::{self, Heightfield};
use crate::render::TerrainConfig;

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
