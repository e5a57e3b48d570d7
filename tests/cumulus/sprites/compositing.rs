//! Sprite clouds composited with the rest of a frame (issue 13, lavapipe):
//! their shadows on the terrain, depth order against ray-marched clouds,
//! physics clouds in the impostor ring, and a fly-through with no popping.
//! Fails without an adapter (see `common::gpu` for the opt-in skip).

use crate::common;

use crate::common::render::{camera, no_terrain, render};

use cumulus::config::{RenderConfig, RenderMethod, TerrainConfig};
use cumulus::methods::sprites::model::{CloudType, SpriteCloud};
use cumulus::physics::CloudParcel;
use cumulus::render::FrameInput;
use cumulus::render::headless::Headless;
use glam::Vec3;

/// Rec. 709 luma of an 8-bit RGBA pixel, 0–255.
fn luma(p: &[u8]) -> f32 {
    0.2126 * p[0] as f32 + 0.7152 * p[1] as f32 + 0.0722 * p[2] as f32
}

/// Mean of |a − b| over RGB of the pixels where `mask` holds. units: 8-bit levels
fn mean_diff(a: &[u8], b: &[u8], mask: &[bool]) -> f32 {
    let (sum, n) = a
        .chunks_exact(4)
        .zip(b.chunks_exact(4))
        .zip(mask)
        .filter(|(_, m)| **m)
        .fold((0.0, 0usize), |(s, n), ((p, q), _)| {
            let d: f32 = (0..3).map(|c| p[c].abs_diff(q[c]) as f32).sum();
            (s + d / 3.0, n + 1)
        });
    sum / n.max(1) as f32
}

/// Where two frames differ by more than `levels` in some channel.
fn differs(a: &[u8], b: &[u8], levels: u8) -> Vec<bool> {
    a.chunks_exact(4)
        .zip(b.chunks_exact(4))
        .map(|(p, q)| (0..3).any(|c| p[c].abs_diff(q[c]) > levels))
        .collect()
}

#[test]
fn sprite_clouds_shadow_the_terrain() {
    let Some(ctx) = common::context("sprite shadows") else {
        return;
    };
    // A flat ground, the sun 55° up in the south-east: a cumulus 1.2 km up
    // casts its shadow about 0.8 km north-west of its foot, in view of a
    // camera looking down from the south.
    let mut on = RenderConfig {
        method: RenderMethod::Sprites,
        sun_azimuth_deg: 135.0,
        sun_elevation_deg: 55.0,
        terrain: TerrainConfig {
            height_scale_m: 0.0,
            extent_m: 40_000.0,
            ..TerrainConfig::default()
        },
        ..RenderConfig::default()
    };
    on.shadows = true;
    let off = RenderConfig {
        shadows: false,
        ..on.clone()
    };
    let cloud = CloudType::CumulusCongestus
        .spec("", 0.0, 3000.0, 1200.0, 5)
        .build();
    let cam = camera(Vec3::new(0.0, -3000.0, 3500.0), Vec3::new(0.0, 3000.0, 0.0));
    let size = (96, 72);
    let lit = render(&ctx, &off, vec![cloud.clone()], cam, &[], size);
    let shaded = render(&ctx, &on, vec![cloud], cam, &[], size);
    let darker = lit
        .chunks_exact(4)
        .zip(shaded.chunks_exact(4))
        .filter(|(a, b)| luma(b) + 4.0 < luma(a))
        .count();
    let brighter = lit
        .chunks_exact(4)
        .zip(shaded.chunks_exact(4))
        .filter(|(a, b)| luma(b) > luma(a) + 1.0)
        .count();
    // The shadow of a 2 km cloud seen from 5 km covers a few hundred of
    // the 6912 pixels; shadows only take light away (1 level of rounding).
    assert!(darker > 150, "{darker} pixels darker under the shadow");
    assert_eq!(brighter, 0, "shadows made {brighter} pixels brighter");
    let mean = |img: &[u8]| img.chunks_exact(4).map(luma).sum::<f32>() / 6912.0;
    eprintln!(
        "sprite shadow: {darker} pixels darker, mean luma {:.2} → {:.2}",
        mean(&lit),
        mean(&shaded)
    );
}

/// A sprite cloud scaled about the camera by `k`: the same on screen
/// (positions, sizes and colour-level heights scaled alike), `k` times
/// as far.
fn scaled(cloud: &SpriteCloud, cam: Vec3, k: f32) -> SpriteCloud {
    let mut c = cloud.clone();
    c.center_m = cam + k * (c.center_m - cam);
    c.radius_m *= k;
    for s in &mut c.sprites {
        s.center_m = cam + k * (s.center_m - cam);
        s.width_m *= k;
        s.height_m *= k;
    }
    for l in &mut c.levels {
        l.height_m = cam.z + k * (l.height_m - cam.z);
    }
    c
}

#[test]
fn sprite_layers_above_and_below_a_ray_marched_cloud_sort_by_depth() {
    let Some(ctx) = common::context("sprites against the march") else {
        return;
    };
    // Looking up from the ground at a dense parcel 2.5 km up; a sprite
    // cloud 1.2 km up (below it: in front) and the same cloud scaled
    // about the camera to 4.8 km up (above it: behind), the same on screen.
    let cfg = no_terrain(RenderMethod::Exact);
    let cam = camera(Vec3::new(0.0, 0.0, 20.0), Vec3::new(0.0, 1200.0, 2500.0));
    let parcel = CloudParcel {
        id: 0,
        center_m: Vec3::new(0.0, 1200.0, 2500.0),
        radius_m: 700.0,
        fill: 1.0,
        cond_plane_z_m: 2000.0,
    };
    let below = CloudType::CumulusHumilis
        .spec("", 0.0, 600.0, 1200.0, 9)
        .build();
    let above = scaled(&below, cam.position, 4.0);
    assert!(above.sprites.iter().all(|s| s.center_m.z > 3300.0));
    let size = (96, 72);
    let sky = render(&ctx, &cfg, Vec::new(), cam, &[], size);
    let march = render(&ctx, &cfg, Vec::new(), cam, &[parcel], size);
    let sprites = render(&ctx, &cfg, vec![below.clone()], cam, &[], size);
    let front = render(&ctx, &cfg, vec![below], cam, &[parcel], size);
    let back = render(&ctx, &cfg, vec![above], cam, &[parcel], size);
    // Pixels covered by both: the march and the sprites each change them
    // by more than 24 levels from the bare sky.
    let cloud = differs(&march, &sky, 24);
    let sprite = differs(&sprites, &sky, 24);
    let both: Vec<bool> = cloud.iter().zip(&sprite).map(|(a, b)| *a && *b).collect();
    let n = both.iter().filter(|b| **b).count();
    assert!(
        n > 100,
        "{n} pixels where the cloud and the sprites overlap"
    );
    // Behind the cloud, the sprites are hidden by it: the frame there is
    // the march's, up to what shows through the cloud's thin parts; in
    // front, they cover it. (Drawing every sprite under the clouds, or
    // every sprite over them, makes the two alike.)
    let behind = mean_diff(&back, &march, &both);
    let in_front = mean_diff(&front, &march, &both);
    eprintln!(
        "overlap {n} px: behind differs from the march by {behind:.1}, in front by {in_front:.1} levels"
    );
    assert!(
        in_front > 3.0 * behind && in_front > 10.0,
        "in front {in_front:.1} vs behind {behind:.1}"
    );
    // And in front, the frame there is the sprites' more than the march's.
    let to_sprites = mean_diff(&front, &sprites, &both);
    assert!(to_sprites < in_front, "{to_sprites:.1} vs {in_front:.1}");
}

#[test]
fn physics_clouds_beyond_the_radius_go_into_the_impostor_ring() {
    let Some(ctx) = common::context("physics clouds in the ring") else {
        return;
    };
    // Three parcels 25 km north at the camera's height, as sprites.
    let parcels: Vec<CloudParcel> = [-3000.0, 0.0, 3000.0]
        .into_iter()
        .enumerate()
        .map(|(i, x)| CloudParcel {
            id: 100 + i as u64,
            center_m: Vec3::new(x, 25_000.0, 1500.0),
            radius_m: 900.0,
            fill: 1.0,
            cond_plane_z_m: 1000.0,
        })
        .collect();
    let mut cam = camera(
        Vec3::new(0.0, 0.0, 1500.0),
        Vec3::new(0.0, 25_000.0, 1500.0),
    );
    cam.vfov_rad = 20f32.to_radians();
    let direct_cfg = no_terrain(RenderMethod::Sprites);
    let mut ring_cfg = direct_cfg.clone();
    ring_cfg.sprites.impostor_radius_m = Some(10_000.0);
    let size = (192, 108);
    let frames = |cfg: &RenderConfig, n: usize| {
        let mut hl = Headless::new(&ctx, cfg, size.0, size.1).unwrap();
        let input = FrameInput {
            camera: cam,
            parcels: &parcels,
            sun: cfg.sun(),
            time_s: 0.0,
        };
        (0..n)
            .map(|_| {
                let img = hl.render(&ctx, &input).unwrap().0;
                (img, hl.renderer.sprite_stats())
            })
            .collect::<Vec<_>>()
    };
    let direct = frames(&direct_cfg, 1);
    let ring = frames(&ring_cfg, 9);
    assert_eq!(direct[0].1.parcel_clouds, 3);
    // Drawn directly until the set is complete (8 frames), then through it.
    assert!(ring[..7].iter().all(|(_, s)| s.parcel_clouds == 3));
    assert!(
        ring[7..]
            .iter()
            .all(|(_, s)| s.parcel_clouds == 0 && s.sprites == 0)
    );
    // Same look through the ring (the impostor test's tolerance:
    // sprites::gpu::RING_FLIP_TOLERANCE, one bilinear resampling).
    let flip = common::flip::mean_flip(&direct[0].0, &ring[8].0, size);
    eprintln!("physics clouds through the ring vs direct: mean FLIP {flip:.4}");
    assert!(flip < 0.015, "mean FLIP {flip:.4}");
}

/// Largest frame-to-frame change of mean luma allowed on the fly-through,
/// as a fraction of the largest change the cloud makes to the frame (its
/// frame against the empty sky) anywhere on the path. A pop (a sprite
/// appearing or vanishing, a quad turning at once, "parting the Red Sea",
/// or snapping back from its locked facing) moves the mean by a share of
/// the cloud's whole contribution whatever the step; a smooth flight moves
/// it in proportion to the step. The steepest smooth change is a locked
/// sprite filling the view while the camera passes a few metres from its
/// centre (its fade by angle, §3.3): 2.4 levels of 61 in a 1 m step on
/// lavapipe (3.9 %; 4.0 with a 5 m near plane), so 10 %. Before the
/// shading cache counted the distance to the cloud's nearest sprite,
/// re-shading every third frame made that 7.5 (12 %).
const FLY_JUMP_FRACTION: f32 = 0.1;

/// Step of the fly-through camera (60 m/s at 60 frames a second). units: m
const FLY_STEP_M: f32 = 1.0;

#[test]
fn flying_through_a_sprite_cloud_does_not_pop() {
    let Some(ctx) = common::context("sprite fly-through") else {
        return;
    };
    let cfg = no_terrain(RenderMethod::Sprites);
    let cloud = CloudType::CumulusHumilis
        .spec("", 0.0, 0.0, 1000.0, 21)
        .build();
    let centre = cloud.center_m;
    let mut hl = Headless::new(&ctx, &cfg, 64, 48).unwrap();
    hl.renderer.set_sprite_clouds(&ctx, vec![cloud]).unwrap();
    let mean = |v: &[u8]| v.chunks_exact(4).map(luma).sum::<f32>() / (64.0 * 48.0);
    // No terrain: the bare sky is the same from every point of the path.
    let sky = {
        let cam = camera(centre, centre + Vec3::Y);
        mean(&render(&ctx, &cfg, Vec::new(), cam, &[], (64, 48)))
    };
    // From 450 m south of the centre to 450 m north, through it (the
    // cloud is 800 m wide), on one renderer: its sprites keep their
    // facing state from frame to frame.
    let frames = (900.0 / FLY_STEP_M) as usize;
    let mut lumas = Vec::new();
    for i in 0..=frames {
        let y = -450.0 + FLY_STEP_M * i as f32;
        let cam = camera(
            centre + Vec3::new(0.0, y, 0.0),
            centre + Vec3::new(0.0, y + 1000.0, 0.0),
        );
        let input = FrameInput {
            camera: cam,
            parcels: &[],
            sun: cfg.sun(),
            time_s: FLY_STEP_M / 60.0 * i as f32,
        };
        let img = hl.render(&ctx, &input).unwrap().0;
        lumas.push(mean(&img));
    }
    let cloud_share = lumas.iter().map(|l| (l - sky).abs()).fold(0.0, f32::max);
    let (at, worst) = lumas
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .enumerate()
        .fold((0, 0.0f32), |a, (i, j)| if j > a.1 { (i, j) } else { a });
    eprintln!(
        "fly-through: the cloud changes the mean luma by up to {cloud_share:.1}; worst jump {worst:.2} ({:.1} %) at y = {} m",
        100.0 * worst / cloud_share,
        -450.0 + FLY_STEP_M * at as f32
    );
    // The flight does go through a visible cloud.
    assert!(cloud_share > 10.0, "cloud contributes {cloud_share:.1}");
    assert!(
        worst <= FLY_JUMP_FRACTION * cloud_share,
        "a jump of {worst:.2} levels against the cloud's {cloud_share:.1}"
    );
}
