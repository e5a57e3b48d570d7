//! The baked field's camera-centred clipmap on the 100 km landscape
//! (profiles/landscape_100km.toml): its clouds at the profile's start time
//! bake into several levels, the voxel the march samples stays ≤ 50 m
//! within 20 km of the camera (checked on the layout the bake itself uses,
//! `Clipmap::voxel_at`, and on what the bake reports), and a small frame
//! renders with them. Without any adapter the render part fails (see
//! `common::gpu` for the opt-in skip).

use crate::common;

use cumulus::config::Camera;
use cumulus::methods::raymarch::clipmap::clipmap;
use cumulus::methods::raymarch::pack::gpu_parcels;
use cumulus::render::FrameInput;
use cumulus::render::headless::Headless;
use glam::Vec3;

/// The bound: within NEAR_M of the camera (horizontally), voxels
/// of at most FINE_VOXEL_M.
const NEAR_M: f32 = 20_000.0;
const FINE_VOXEL_M: f32 = 50.0;

#[test]
fn landscape_100km_renders_with_50_m_voxels_within_20_km_of_the_camera() {
    let (scene, base, parcels) = common::physics::scene_at_start("landscape_100km.toml");
    let start = scene.simulation.start_s;
    assert!(parcels.len() > 500, "only {} cloud parcels", parcels.len());

    let mut cfg = scene.render.clone();
    cfg.resolve_paths(&base);
    let camera = Camera::from(&scene.camera);
    let live = gpu_parcels(&parcels, cfg.shell_m, cfg.radius_scale).unwrap();
    let map = clipmap(&live, cfg.shell_m, camera.position);
    assert!(
        map.levels.len() > 1,
        "the 100 km field fits one volume: it does not exercise the clipmap"
    );
    // Every point of the cloud layer (lowest condensation plane to highest
    // centre) within 20 km of the camera that the field covers, every
    // 500 m across and at five heights.
    let z0 = parcels
        .iter()
        .map(|p| p.cond_plane_z_m)
        .fold(f32::MAX, f32::min);
    let z1 = parcels
        .iter()
        .map(|p| p.center_m.z)
        .fold(f32::MIN, f32::max);
    let (top_min, top_max) = (map.top().min, map.top().max());
    let mut checked = 0;
    for i in -40..=40 {
        for j in -40..=40 {
            let d = Vec3::new(i as f32, j as f32, 0.0) * 500.0;
            if d.length() > NEAR_M {
                continue;
            }
            for k in 0..5 {
                let z = z0 + (z1 - z0) * k as f32 / 4.0;
                let p = Vec3::new(camera.position.x + d.x, camera.position.y + d.y, z);
                if p.cmplt(top_min).any() || p.cmpgt(top_max).any() {
                    continue;
                }
                let v = map.voxel_at(p).unwrap_or(f32::INFINITY);
                assert!(
                    v <= FINE_VOXEL_M,
                    "{v} m voxels at {p}, {:.0} m from the camera ({} levels)",
                    d.length(),
                    map.levels.len()
                );
                checked += 1;
            }
        }
    }
    // Most of the 20 km disc lies over the 100 km domain.
    assert!(checked > 20_000, "only {checked} points checked");

    let Some(ctx) = common::context("GPU clipmap test") else {
        return;
    };
    let (w, h) = (96, 54);
    let mut hl = Headless::new(&ctx, &cfg, w, h).unwrap();
    let frame = |parcels| FrameInput {
        camera,
        parcels,
        sun: cfg.sun(),
        time_s: start as f32,
    };
    let (clear, _) = hl.render(&ctx, &frame(&[])).unwrap();
    let (cloudy, t) = hl.render(&ctx, &frame(&parcels)).unwrap();
    assert!(t.pass_ms("bake").is_some(), "{t:?}");
    // The bake used the same levels.
    let info = hl.renderer.bake_info();
    assert_eq!(info.levels as usize, map.levels.len());
    assert_eq!(info.voxel_m, map.levels[0].voxel_m);
    // Clouds show: more than 5 % of the pixels differ from the clear sky
    // by over 8 of 255 (the profile's view is a sky full of cumulus; an
    // empty or misplaced field leaves the frame nearly clear).
    let changed = clear
        .chunks(4)
        .zip(cloudy.chunks(4))
        .filter(|(a, b)| {
            a.iter()
                .zip(b.iter())
                .take(3)
                .any(|(x, y)| x.abs_diff(*y) > 8)
        })
        .count();
    assert!(
        changed * 20 > (w * h) as usize,
        "only {changed} of {} pixels show clouds",
        w * h
    );
}

#[test]
fn the_clipmap_follows_the_camera_past_its_grid_and_not_before() {
    let Some(ctx) = common::context("GPU clipmap test") else {
        return;
    };
    // 41 × 41 parcels over 100 km × 100 km in a layer 1.4–2.3 km high;
    // a 150 m shell asks for 45 m voxels, far more than one volume holds.
    let mut parcels = Vec::new();
    for i in 0..41 {
        for j in 0..41 {
            let c = Vec3::new(
                i as f32 * 2500.0 - 50_000.0,
                j as f32 * 2500.0 - 50_000.0,
                1800.0,
            );
            parcels.push(cumulus::physics::CloudParcel {
                id: (i * 41 + j) as u64,
                center_m: c + Vec3::new(0.0, 0.0, ((i * j) % 3) as f32 * 150.0),
                radius_m: 180.0,
                fill: 1.0,
                cond_plane_z_m: 1600.0,
            });
        }
    }
    let cfg = cumulus::config::RenderConfig {
        shell_m: 150.0,
        terrain: cumulus::config::TerrainConfig {
            enabled: false,
            ..Default::default()
        },
        ..Default::default()
    };
    let mut hl = Headless::new(&ctx, &cfg, 32, 24).unwrap();
    let at = |x: f32| Camera {
        position: Vec3::new(x, -30_000.0, 900.0),
        target: Vec3::new(x, 0.0, 1800.0),
        vfov_rad: 50f32.to_radians(),
        near_m: 10.0,
        far_m: 150_000.0,
    };
    let mut bakes_at = |x: f32| {
        let input = FrameInput {
            camera: at(x),
            parcels: &parcels,
            sun: cfg.sun(),
            time_s: 0.0,
        };
        hl.render(&ctx, &input).unwrap();
        hl.renderer.bake_info()
    };
    let first = bakes_at(0.0);
    assert!(first.levels > 1, "{first:?}");
    // 100 m: inside the camera's grid cell (8 level-0 cells, 1.4 km), the
    // same levels, no bake.
    assert_eq!(bakes_at(100.0).bakes, first.bakes);
    // 5 km: past the grid line, the levels move and the field re-bakes.
    assert_eq!(bakes_at(5000.0).bakes, first.bakes + 1);
}
