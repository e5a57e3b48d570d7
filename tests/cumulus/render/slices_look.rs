//! What the `slices` method shows a user of the shipped authored scene:
//! the cumulonimbus with its anvil at the scene's start, and the early
//! discard on the implicit field leaving the image exactly as it was.

use std::path::Path;

use cumulus::config::RenderConfig;
use cumulus::scene::{SceneProfile, load_scene_with};

use crate::common;

/// The paper's frame is 730×545; a quarter of it keeps lavapipe quick.
const SIZE: (u32, u32) = (240, 180);

fn authored(sets: &[&str]) -> SceneProfile {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/authored.toml");
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    load_scene_with(Some(&path), &sets).unwrap().0
}

/// The scene at its start time from its camera under `cfg`: the 8-bit
/// frame and the linear HDR scene.
fn frame(
    ctx: &cumulus::render::GpuContext,
    scene: &SceneProfile,
    cfg: &RenderConfig,
) -> (Vec<u8>, Vec<f32>) {
    let (hl, img) = super::slices::render_at(ctx, scene, cfg, SIZE);
    (img, hl.read_hdr(ctx).unwrap())
}

/// Skipping the noise where the implicit field alone cannot pass the
/// cut-off (the media filters are at most 1) draws the same image, to the
/// bit, with the terrain and sky of the shipped scene.
#[test]
fn the_early_discard_leaves_the_image_unchanged() {
    let Some(ctx) = common::context("slices early discard") else {
        return;
    };
    let scene = authored(&[]);
    let on = frame(&ctx, &scene, &scene.render).0;
    let mut cfg = scene.render.clone();
    cfg.slices.early_discard = false;
    let off = frame(&ctx, &scene, &cfg).0;
    assert!(on == off, "the images differ");
}

/// Alpha of the clouds per pixel: the linear scene over a black and over
/// a white background (no sky, no terrain; the background is flat
/// radiance), α = 1 − (white − black) in luminance.
fn cloud_alpha(ctx: &cumulus::render::GpuContext) -> Vec<f32> {
    let over = |bg: &str| {
        let scene = authored(&[
            "render.terrain.enabled=false",
            "render.slices.sky=false",
            "render.aerial_perspective=false",
            &format!("render.slices.background_colour=[{bg}, {bg}, {bg}]"),
        ]);
        common::hdr::luminance(&frame(ctx, &scene, &scene.render).1)
    };
    let (black, white) = (over("0.0"), over("1.0"));
    black
        .iter()
        .zip(&white)
        .map(|(b, w)| (1.0 - (w - b)).clamp(0.0, 1.0))
        .collect()
}

/// The shipped cumulonimbus reads as one at the scene's start time from
/// its camera: on the mask where the clouds' alpha > 0.5, the cloud
/// holding the fullest column (the tower) covers at least 10 % of the
/// frame, and the widest row in the top 20 % of its height is at least
/// twice its width at mid-height (the measures).
#[test]
fn the_shipped_cumulonimbus_has_its_anvil_at_the_start() {
    let Some(ctx) = common::context("slices cumulonimbus") else {
        return;
    };
    let alpha = cloud_alpha(&ctx);
    let (w, h) = (SIZE.0 as usize, SIZE.1 as usize);
    let mask: Vec<bool> = alpha.iter().map(|a| *a > 0.5).collect();
    let column = |x: usize| (0..h).filter(|&y| mask[y * w + x]).count();
    let tower_x = (0..w).max_by_key(|&x| column(x)).unwrap();
    let tower_y = (0..h)
        .filter(|&y| mask[y * w + tower_x])
        .nth(column(tower_x) / 2)
        .unwrap();
    let cb = common::hdr::component(&mask, w, tower_y * w + tower_x);
    let area = cb.iter().filter(|c| **c).count();
    let width = |y: usize| (0..w).filter(|&x| cb[y * w + x]).count();
    let rows: Vec<usize> = (0..h).filter(|&y| width(y) > 0).collect();
    let (top, bottom) = (rows[0], *rows.last().unwrap());
    let height = bottom - top;
    let anvil = (top..=top + height / 5).map(width).max().unwrap();
    let mid = width(top + height / 2);
    eprintln!(
        "cumulonimbus: {area} px of {} ({:.1} %), rows {top}..{bottom}, anvil {anvil} px, mid-height {mid} px",
        w * h,
        100.0 * area as f64 / (w * h) as f64
    );
    assert!(area * 10 >= w * h, "{area} px of {}", w * h);
    assert!(anvil >= 2 * mid, "anvil {anvil} px, mid-height {mid} px");
}

/// No tint a user did not ask for: the slices' colours are lit by the
/// frame's sun and sky as the sprites' are (shaders/artist.wgsl), so over
/// the fair-weather parcels the mean chroma (max − min of the 8-bit sRGB
/// channels) of cloud pixels is within 1.5× of the ray-march's on the same
/// field (the bound; measured 1.1× at 480×270, and 2.3× with the
/// sun-only, sky-less colours before).
#[test]
fn slices_add_no_tint_to_the_parcels() {
    if common::context("slices chroma").is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let render = |name: &str, extra: &[&str]| {
        let png = dir.path().join(name);
        common::cli::run_command(
            common::cli::command()
                .args([
                    "render",
                    "profiles/fair_weather.toml",
                    "--width",
                    "240",
                    "--height",
                    "135",
                ])
                .args(extra)
                .arg("--out")
                .arg(&png),
        )
        .expect_success();
        image::open(&png).unwrap().into_rgb8()
    };
    let none = render("none.png", &["--set", "render.clouds=false"]);
    let chroma = |img: &image::RgbImage| {
        let (mut sum, mut n) = (0.0f64, 0usize);
        for (p, q) in img.pixels().zip(none.pixels()) {
            let diff: i32 = (0..3).map(|c| (p[c] as i32 - q[c] as i32).abs()).sum();
            // A summed change of 30 of 765 is cloud, not dithering.
            if diff > 30 {
                let (hi, lo) = (p.0.iter().max().unwrap(), p.0.iter().min().unwrap());
                sum += (hi - lo) as f64 / 255.0;
                n += 1;
            }
        }
        assert!(n > 100, "{n} cloud pixels");
        sum / n as f64
    };
    let marched = chroma(&render("baked.png", &[]));
    let sliced = chroma(&render("slices.png", &["--method", "slices"]));
    assert!(
        sliced <= 1.5 * marched,
        "slices {sliced:.4}, ray-march {marched:.4}"
    );
}
