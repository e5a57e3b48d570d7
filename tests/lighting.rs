//! The light volume and lighting model on a tall cloud (lavapipe, small
//! frames): a tower lit from above is dark at its base and bright at its
//! top, measured on the linear HDR scene before the tone map.

mod common;

use cumulus::physics::CloudParcel;
use cumulus::render::headless::Headless;
use cumulus::render::{Camera, CameraConfig, FrameInput, RenderConfig, TerrainConfig};
use glam::Vec3;

/// A 4 km tower: parcels of radius 500 m stacked every 400 m from 1.5 to
/// 5.1 km, all on one condensation plane at 1.1 km.
fn tower() -> Vec<CloudParcel> {
    (0..10)
        .map(|i| CloudParcel {
            id: i as u64,
            center_m: Vec3::new(0.0, 0.0, 1500.0 + 400.0 * i as f32),
            radius_m: 500.0,
            fill: 1.0,
            cond_plane_z_m: 1100.0,
        })
        .collect()
}

/// Rec. 709 luminance of each pixel of an RGB float image.
fn luminance(rgb: &[f32]) -> Vec<f32> {
    rgb.chunks_exact(3)
        .map(|c| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2])
        .collect()
}

#[test]
fn a_tall_cloud_lit_from_above_has_a_dark_base() {
    let Some(ctx) = common::context("GPU lighting test") else {
        return;
    };
    // Sun overhead, no terrain (no ground bounce off a lit plane in view).
    let cfg = RenderConfig {
        sun_elevation_deg: 90.0,
        radius_scale: 1.0,
        terrain: TerrainConfig {
            enabled: false,
            ..TerrainConfig::default()
        },
        ..RenderConfig::default()
    };
    let camera = Camera::from(&CameraConfig {
        position_m: [0.0, -14000.0, 3200.0],
        target_m: [0.0, 0.0, 3200.0],
        vfov_deg: 24.0,
        ..CameraConfig::default()
    });
    let (w, h) = (128, 192);
    let mut hl = Headless::new(&ctx, &cfg, w, h).unwrap();
    let mut frame = |parcels: &[CloudParcel]| {
        let input = FrameInput {
            camera,
            parcels,
            sun: cfg.sun(),
            time_s: 0.0,
        };
        hl.render(&ctx, &input).unwrap();
        hl.read_hdr(&ctx).unwrap()
    };
    let sky = frame(&[]);
    let cloud_rgb = frame(&tower());
    let cloud = luminance(&cloud_rgb);
    // Cloud pixels of the central columns: not sky in some channel by more
    // than 0.05 (grey cloud against blue sky differs in colour even where
    // a dark base matches the sky's luminance).
    let (x0, x1) = (w / 2 - 6, w / 2 + 6);
    let rows: Vec<u32> = (0..h)
        .filter(|&y| {
            (x0..x1).all(|x| {
                let i = 3 * (y * w + x) as usize;
                (0..3).any(|c| (cloud_rgb[i + c] - sky[i + c]).abs() > 0.05)
            })
        })
        .collect();
    assert!(
        rows.len() > h as usize / 3,
        "the tower covers {} rows",
        rows.len()
    );
    let band = |ys: &[u32]| {
        let mut s = 0.0;
        for &y in ys {
            for x in x0..x1 {
                s += cloud[(y * w + x) as usize];
            }
        }
        s / (ys.len() as u32 * (x1 - x0)) as f32
    };
    // Image rows grow downward: the first cloud rows are the top.
    let n = rows.len() / 8;
    let top = band(&rows[..n]);
    let base = band(&rows[rows.len() - n..]);
    let ratio = base / top;
    eprintln!("tower luminance: top {top:.3}, base {base:.3}, base/top {ratio:.3}");
    // Overhead, the sun reaches the base only through the whole 4 km tower
    // (optical depth in the hundreds: no direct light, the diffuse part
    // down to ~1 %) and the sky only sideways, while the top gets the full
    // sun. Real cumulus bases are grey under white tops, several times
    // darker (a factor of about 3 to 20 in luminance), so base/top must lie
    // between 0.05 and 0.35: above, the tower does not shadow its own base
    // (a light march that stops short of the top); below, the base gets
    // neither sky nor multiply scattered light. Measured 0.112 (llvmpipe).
    assert!(
        (0.05..=0.35).contains(&ratio),
        "base/top luminance {ratio:.3} outside 0.05–0.35"
    );
}
