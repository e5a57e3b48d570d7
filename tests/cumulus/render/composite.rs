//! The cloud image reaches the output through the composite pass, or,
//! where nothing is drawn after it, through the tone map (one full-screen
//! pass less): the same frame either way.

use crate::common;

use cumulus::config::RenderConfig;
use cumulus::methods::standin;
use cumulus::render::FrameInput;
use cumulus::render::headless::Headless;

/// The tone map blends the compute march's cloud image as the composite
/// pass would have (one full-screen pass less), and a frame left to it has
/// no HDR read-back: keeping the scene whole brings the composite back.
#[test]
fn the_tone_map_blends_the_clouds_as_the_composite_pass_does() {
    let Some(ctx) = common::context("GPU composite test") else {
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
    let worst = folded
        .iter()
        .zip(&whole)
        .map(|(a, b)| a.abs_diff(*b))
        .max()
        .unwrap();
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
