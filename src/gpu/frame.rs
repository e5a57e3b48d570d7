//! What one frame is given (the parcels, camera, sun and time) and the
//! passes it needs.

use crate::config::{Camera, RenderConfig, RenderMethod};
use crate::physics::CloudParcel;
use crate::sky::Sun;

/// Everything a frame needs from the outside world.
#[derive(Debug, Clone, Copy)]
pub struct FrameInput<'a> {
    pub camera: Camera,
    /// The condensed parcels to draw (from `ParcelWorld::cloud_parcels`).
    pub parcels: &'a [CloudParcel],
    pub sun: Sun,
    /// Simulation time, for slow noise drift. units: s
    pub time_s: f32,
}

/// Which passes and shader code a frame needs ("leave out what a scene does
/// not need"): derived from the configuration and whether there are clouds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Features {
    /// Ray-march clouds (configured on, a ray-marching method and at
    /// least one parcel).
    pub clouds: bool,
    /// Draw sprite clouds (the `sprites` method's parcels or the scene's
    /// `[[sprite_clouds]]`/`[[layers]]`; the renderer sets the latter).
    pub sprites: bool,
    /// Slicing planes (the `slices` method with at least one primitive).
    pub slices: bool,
    /// Terrain mesh pass.
    pub terrain: bool,
    /// Cloud shadows on the terrain (needs terrain and ray-marched clouds,
    /// sprites or slicing planes).
    pub shadows: bool,
    /// The cloud-shadow map pass: the ray-marched clouds' and the slicing
    /// planes' shadows (and the sprites', splatted in).
    pub shadow_map: bool,
    /// Finite-difference normals compiled into the cloud shader.
    pub normals: bool,
    /// Temporal amortisation: the quarter-rate march and the resolve pass
    /// (`[render] temporal` set to true, and clouds to march).
    pub temporal: bool,
}

impl Features {
    /// Features for `cfg` with or without any condensed parcel.
    pub fn new(cfg: &RenderConfig, any_clouds: bool) -> Self {
        let drawn = cfg.clouds && any_clouds;
        let clouds = drawn && cfg.method.ray_marches();
        let terrain = cfg.terrain.enabled;
        let slices = drawn && cfg.method == RenderMethod::Slices;
        Self {
            clouds,
            sprites: drawn && cfg.method == RenderMethod::Sprites,
            slices,
            terrain,
            shadows: cfg.shadows && (clouds || slices) && terrain,
            shadow_map: cfg.shadows && terrain && (clouds || slices),
            normals: cfg.normals && clouds,
            temporal: cfg.temporal == Some(true) && clouds,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::TerrainConfig;

    #[test]
    fn features_prune() {
        let cfg = RenderConfig::default();
        let all = Features::new(&cfg, true);
        assert!(all.clouds && all.terrain && all.shadows && !all.normals);
        let none = Features::new(&cfg, false);
        assert!(!none.clouds && !none.shadows && none.terrain);
        let no_terrain = RenderConfig {
            terrain: TerrainConfig {
                enabled: false,
                ..TerrainConfig::default()
            },
            ..cfg
        };
        assert!(!Features::new(&no_terrain, true).shadows);
    }
}
