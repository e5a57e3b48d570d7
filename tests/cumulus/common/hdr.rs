//! Linear HDR frames of the lighting and tower tests: one renderer for a
//! few parcel sets, cloud masks against the empty sky, luminance, and the
//! two measurements on a tower (base against top, one side against the
//! other).

use cumulus::config::{Camera, RenderConfig};
use cumulus::physics::CloudParcel;
use cumulus::render::headless::Headless;
use cumulus::render::{FrameInput, GpuContext};
use cumulus::sky::Sun;

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
    hl.renderer.set_scene_whole(true);
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

/// Mean luminance of the bottom and top eighths of the rows in which the
/// 2·`half_width` central columns are all cloud (image rows grow downward:
/// the first such rows are the top): (base, top, rows).
pub fn base_and_top(lum: &[f32], mask: &[bool], w: u32, half_width: u32) -> (f32, f32, usize) {
    let h = lum.len() as u32 / w;
    let (x0, x1) = (w / 2 - half_width, w / 2 + half_width);
    let rows: Vec<u32> = (0..h)
        .filter(|&y| (x0..x1).all(|x| mask[(y * w + x) as usize]))
        .collect();
    let n = (rows.len() / 8).max(1);
    let band = |ys: &[u32]| {
        let sum: f32 = ys
            .iter()
            .flat_map(|y| (x0..x1).map(move |x| lum[(y * w + x) as usize]))
            .sum();
        sum / (ys.len() as u32 * (x1 - x0)).max(1) as f32
    };
    let top = band(&rows[..n.min(rows.len())]);
    let base = band(&rows[rows.len().saturating_sub(n)..]);
    (base, top, rows.len())
}

/// Mean luminance of the cloud pixels left and right of the image's
/// centre column: (left, right, [pixels left, pixels right]).
pub fn half_means(lum: &[f32], mask: &[bool], w: u32) -> (f32, f32, [u32; 2]) {
    let (mut sum, mut n) = ([0.0f32; 2], [0u32; 2]);
    for (i, (&l, &m)) in lum.iter().zip(mask).enumerate() {
        if m {
            let side = usize::from(i as u32 % w >= w / 2);
            sum[side] += l;
            n[side] += 1;
        }
    }
    (sum[0] / n[0].max(1) as f32, sum[1] / n[1].max(1) as f32, n)
}

/// The display transform of shaders/common.wgsl `tone_map` (exposure `k`,
/// the filmic curve, then the sRGB encoding), to compare an EXR with the PNG of
/// one frame (the GPU's curve: `exr_is_the_linear_scene_the_png_tone_maps`).
pub fn tone_map(c: f32, k: f32) -> f32 {
    // Narkowicz's ACES fit, clamped to [0, 1].
    let x = c.max(0.0) * k;
    let t = (x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0);
    if t <= 0.003_130_8 {
        12.92 * t
    } else {
        1.055 * t.powf(1.0 / 2.4) - 0.055
    }
}

/// The pixels of `mask` (row-major, `w` wide) 4-connected to `start`.
pub fn component(mask: &[bool], w: usize, start: usize) -> Vec<bool> {
    let mut seen = vec![false; mask.len()];
    let mut stack = vec![start];
    while let Some(i) = stack.pop() {
        if seen[i] || !mask[i] {
            continue;
        }
        seen[i] = true;
        let (x, y) = (i % w, i / w);
        if x > 0 {
            stack.push(i - 1);
        }
        if x + 1 < w {
            stack.push(i + 1);
        }
        if y > 0 {
            stack.push(i - w);
        }
        if i + w < mask.len() {
            stack.push(i + w);
        }
    }
    seen
}
