//! Camera, configuration and one-frame helpers of the sprite render tests,
//! and the parcel columns of the lighting and render-method tests.

use cumulus::config::{Camera, RenderConfig, RenderMethod, TerrainConfig};
use cumulus::methods::sprites::model::SpriteCloud;
use cumulus::physics::CloudParcel;
use cumulus::render::headless::Headless;
use cumulus::render::{FrameInput, GpuContext};
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

/// One frame (RGBA8) of a fresh renderer with the scene's sprite `clouds`
/// and the physics `parcels`, at t = 0.
pub fn render(
    ctx: &GpuContext,
    cfg: &RenderConfig,
    clouds: Vec<SpriteCloud>,
    camera: Camera,
    parcels: &[CloudParcel],
    (w, h): (u32, u32),
) -> Vec<u8> {
    let mut hl = Headless::new(ctx, cfg, w, h).unwrap();
    hl.renderer.set_sprite_clouds(ctx, clouds).unwrap();
    let input = FrameInput {
        camera,
        parcels,
        sun: cfg.sun(),
        time_s: 0.0,
    };
    hl.render(ctx, &input).unwrap().0
}

/// `parcels` from the default camera under `cfg`'s sun, at t = 0.
pub fn default_view<'a>(cfg: &RenderConfig, parcels: &'a [CloudParcel]) -> FrameInput<'a> {
    FrameInput {
        camera: Camera::from(&cumulus::config::CameraConfig::default()),
        parcels,
        sun: cfg.sun(),
        time_s: 0.0,
    }
}

/// `n` full parcels of `radius_m` stacked on the z axis every `spacing_m`
/// from `base_m` up, each cut at the condensation plane `plane(centre z)`.
pub fn column(
    n: usize,
    (base_m, spacing_m): (f32, f32),
    radius_m: f32,
    plane: impl Fn(f32) -> f32,
) -> Vec<CloudParcel> {
    (0..n)
        .map(|i| {
            let z = base_m + spacing_m * i as f32;
            CloudParcel {
                id: i as u64,
                center_m: Vec3::new(0.0, 0.0, z),
                radius_m,
                fill: 1.0,
                cond_plane_z_m: plane(z),
            }
        })
        .collect()
}
