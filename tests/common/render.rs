//! Camera and configuration helpers of the sprite render tests.

use cumulus::render::{Camera, RenderConfig, RenderMethod, TerrainConfig};
use glam::Vec3;

/// A 50° camera at `position` looking at `target`, near plane 10 m.
pub fn camera(position: Vec3, target: Vec3) -> Camera {
    Camera {
        position,
        target,
        vfov_rad: 50f32.to_radians(),
        near_m: 10.0,
        far_m: 100_000.0,
    }
}

/// The default configuration under `method`, without terrain.
pub fn no_terrain(method: RenderMethod) -> RenderConfig {
    RenderConfig {
        method,
        terrain: TerrainConfig {
            enabled: false,
            ..TerrainConfig::default()
        },
        ..RenderConfig::default()
    }
}
