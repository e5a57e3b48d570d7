//! Linear HDR frames of the lighting and tower tests: one renderer for a
//! few parcel sets, cloud masks against the empty sky, luminance.

use cumulus::physics::CloudParcel;
use cumulus::render::headless::Headless;
use cumulus::render::{Camera, FrameInput, GpuContext, RenderConfig, Sun};

/// Rec. 709 luminance of each pixel of an RGB float image.
pub fn luminance(rgb: &[f32]) -> Vec<f32> {
    rgb.chunks_exact(3)
        .map(|c| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2])
        .collect()
}

/// Linear HDR RGB frames of each parcel set under `cfg` and `sun` from
/// `camera`, one renderer for all of them (w × h pixels).
pub fn hdr_frames(
    ctx: &GpuContext,
    cfg: &RenderConfig,
    camera: Camera,
    sun: Sun,
    (w, h): (u32, u32),
    scenes: &[&[CloudParcel]],
) -> Vec<Vec<f32>> {
    let mut hl = Headless::new(ctx, cfg, w, h).unwrap();
    scenes
        .iter()
        .map(|parcels| {
            let input = FrameInput {
                camera,
                parcels,
                sun,
                time_s: 0.0,
            };
            hl.render(ctx, &input).unwrap();
            hl.read_hdr(ctx).unwrap()
        })
        .collect()
}

/// Cloud pixels: the frame differs from the empty sky in some channel by
/// more than 0.05 (grey cloud against blue sky differs in colour even where
/// its luminance matches the sky's).
pub fn cloud_mask(cloud_rgb: &[f32], sky_rgb: &[f32]) -> Vec<bool> {
    cloud_rgb
        .chunks_exact(3)
        .zip(sky_rgb.chunks_exact(3))
        .map(|(c, s)| (0..3).any(|i| (c[i] - s[i]).abs() > 0.05))
        .collect()
}
