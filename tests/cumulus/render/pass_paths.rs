//! Passes with two paths draw the same frame by either: the cloud image
//! reaches the output through the composite pass or, where nothing is
//! drawn after it, through the tone map; the cloud-shadow map is marched
//! in a compute shader (where the adapter runs one) or in a full-screen
//! fragment shader, the sprites' shadows splatted over it either way.

use crate::common;

use cumulus::config::{Camera, CameraConfig, RenderConfig, TerrainConfig};
use cumulus::methods::standin;
use cumulus::physics::CloudParcel;
use cumulus::render::FrameInput;
use cumulus::render::headless::Headless;
use cumulus::scene::SceneProfile;
use glam::Vec3;

/// The tone map blends the compute march's cloud image as the composite
/// pass would have (one full-screen pass less), and a frame left to it has
/// no HDR read-back: keeping the scene whole brings the composite back.
#[test]
fn the_tone_map_blends_the_clouds_as_the_composite_pass_does() {
    let Some(ctx) = common::context("GPU pass-path test") else {
        return;
    };
    let cfg = RenderConfig {
        march: cumulus::config::MarchPath::Compute,
        ..RenderConfig::default()
    };
    let (w, h) = (96, 72);
    let parcels = standin::default_field(300.0);
    let input = common::render::default_view(&cfg, &parcels);
    let mut hl = Headless::new(&ctx, &cfg, w, h).unwrap();
    let (folded, t) = hl.render(&ctx, &input).unwrap();
    assert!(t.pass_ms("composite").is_none(), "{:?}", t.passes);
    assert!(hl.renderer.scene_folded());
    assert!(
        hl.read_hdr(&ctx).is_err(),
        "the scene target lacks the clouds"
    );
    hl.renderer.set_scene_whole(true);
    let (whole, t) = hl.render(&ctx, &input).unwrap();
    assert!(t.pass_ms("composite").is_some(), "{:?}", t.passes);
    assert!(hl.read_hdr(&ctx).is_ok());
    // The composite rounds the blend to the scene target's half floats
    // (relative 5·10⁻⁴) before the tone map; the tone map blends in f32:
    // at most one 8-bit step apart.
    let worst = largest_difference(&folded, &whole);
    assert!(worst <= 1, "largest difference {worst}");
    // And the clouds are there: the frame differs from the empty sky.
    let empty = FrameInput {
        parcels: &[],
        ..input
    };
    hl.renderer.set_scene_whole(false);
    let (sky, _) = hl.render(&ctx, &empty).unwrap();
    let changed = folded
        .chunks_exact(4)
        .zip(sky.chunks_exact(4))
        .filter(|(a, b)| a.iter().zip(*b).any(|(x, y)| x.abs_diff(*y) > 8))
        .count();
    assert!(changed > (w * h / 50) as usize, "{changed} cloud pixels");
}

/// The largest difference of two 8-bit frames, channel by channel.
fn largest_difference(a: &[u8], b: &[u8]) -> u8 {
    a.iter().zip(b).map(|(x, y)| x.abs_diff(*y)).max().unwrap()
}

/// A sprite cloud beside the parcel, so that the map holds a marched
/// shadow and a splatted one.
const PUFF: &str = r#"
[[sprite_clouds]]
name = "puff"
type = "cumulus_humilis"
center_m = [-2500.0, 0.0, 1500.0]
seed = 9
boxes = [
  { min_m = [-400.0, -400.0, -200.0], max_m = [400.0, 400.0, 200.0], count = 60, width_m = [250.0, 300.0], height_m = [250.0, 300.0], textures = [10, 11], group = 0 },
]
"#;

/// The compute shadow march gives the fragment march's map: the frame
/// over a flat ground under a parcel and a sprite cloud is the same to
/// within one 8-bit step either way, and it has the shadows (darker than
/// without them).
#[test]
fn the_compute_shadow_march_draws_the_fragment_marchs_map() {
    let Some(ctx) = common::context("GPU pass-path test") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("puff.toml");
    std::fs::write(&path, format!("{PUFF}\n{}", common::ATMOSPHERE_TOML)).unwrap();
    let clouds = SceneProfile::load(&path).unwrap().build_sprite_clouds();
    let on = RenderConfig {
        terrain: TerrainConfig {
            height_scale_m: 0.0,
            ..TerrainConfig::default()
        },
        radius_scale: 1.0,
        ..RenderConfig::default()
    };
    let parcel = CloudParcel {
        id: 0,
        center_m: Vec3::new(0.0, 0.0, 1800.0),
        radius_m: 700.0,
        fill: 1.0,
        cond_plane_z_m: 1400.0,
    };
    let input = FrameInput {
        camera: Camera::from(&CameraConfig {
            position_m: [-1500.0, -9000.0, 4000.0],
            target_m: [-2000.0, 0.0, 0.0],
            vfov_deg: 45.0,
            ..CameraConfig::default()
        }),
        parcels: &[parcel],
        sun: on.sun(),
        time_s: 0.0,
    };
    let (w, h) = (96, 72);
    let frame = |cfg: &RenderConfig, compute: bool| {
        let mut hl = Headless::new(&ctx, cfg, w, h).unwrap();
        hl.renderer.set_sprite_clouds(&ctx, clouds.clone()).unwrap();
        hl.renderer.set_compute_shadow(&ctx, compute).unwrap();
        let (img, t) = hl.render(&ctx, &input).unwrap();
        assert_eq!(
            hl.renderer.compute_shadow(),
            compute,
            "lavapipe runs compute"
        );
        (img, t)
    };
    let (compute, t) = frame(&on, true);
    assert!(t.pass_ms("shadow").is_some(), "{:?}", t.passes);
    let (fragment, _) = frame(&on, false);
    let worst = largest_difference(&compute, &fragment);
    // The same WGSL routine at the same texel centres (the compute path
    // computes them, the rasteriser interpolates them): float rounding.
    assert!(worst <= 1, "largest difference {worst}");
    let off = RenderConfig {
        shadows: false,
        ..on.clone()
    };
    let (unshadowed, _) = frame(&off, true);
    // Ground pixels in the shadows: darker by more than a few 8-bit steps.
    let shaded = compute
        .chunks_exact(4)
        .zip(unshadowed.chunks_exact(4))
        .filter(|(a, b)| {
            let sum = |p: &[u8]| p[..3].iter().map(|v| *v as i32).sum::<i32>();
            sum(b) - sum(a) > 12
        })
        .count();
    assert!(shaded > (w * h / 100) as usize, "{shaded} shaded pixels");
}
