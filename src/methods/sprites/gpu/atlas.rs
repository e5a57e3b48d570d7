//! The sprite atlas on the GPU: the 16-tile sheet of
//! [`crate::methods::sprites::model::atlas`] uploaded once, with a mip chain built on
//! the CPU so distant sprites do not shimmer. Each level halves the sheet by
//! 2×2 boxes that never straddle two tiles (tile sides are powers of two
//! down to the last level); colour is averaged weighted by alpha, so the
//! transparent surround does not darken a tile's edge.

use crate::gpu::GpuContext;
use crate::methods::sprites::model::Atlas;

pub use crate::methods::sprites::model::atlas::{ATLAS_SEED, TILE_TEXELS};
/// Smallest tile side in the mip chain (a tile keeps its shape). units: texels
const MIN_MIP_TILE: u32 = 8;

/// The sheet the renderer draws with.
pub fn sheet() -> Atlas {
    Atlas::generate(TILE_TEXELS, ATLAS_SEED)
}

/// One mip level down: 2×2 boxes, colour weighted by alpha.
pub fn half(size: u32, rgba: &[u8]) -> Vec<u8> {
    let n = size / 2;
    let mut out = vec![0u8; (n * n * 4) as usize];
    for y in 0..n {
        for x in 0..n {
            let (mut rgb, mut a) = ([0.0f32; 3], 0.0f32);
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let i = (((2 * y + dy) * size + 2 * x + dx) * 4) as usize;
                let w = rgba[i + 3] as f32;
                for c in 0..3 {
                    rgb[c] += rgba[i + c] as f32 * w;
                }
                a += w;
            }
            let o = ((y * n + x) * 4) as usize;
            for c in 0..3 {
                // A fully transparent box keeps the plain mean of nothing: 0.
                out[o + c] = if a > 0.0 {
                    (rgb[c] / a).round() as u8
                } else {
                    0
                };
            }
            out[o + 3] = (a / 4.0).round() as u8;
        }
    }
    out
}

/// Every mip level of `atlas`: (side, RGBA8 texels), level 0 first.
pub fn mip_chain(atlas: &Atlas) -> Vec<(u32, Vec<u8>)> {
    let mut levels = vec![(atlas.size, atlas.rgba.clone())];
    while levels.last().map_or(0, |l| l.0) / crate::methods::sprites::model::atlas::GRID
        > MIN_MIP_TILE
    {
        let (size, rgba) = levels.last().expect("level 0 exists");
        let next = (size / 2, half(*size, rgba));
        levels.push(next);
    }
    levels
}

/// Uploads the sheet with its mips; returns the view.
pub fn upload(ctx: &GpuContext, atlas: &Atlas) -> wgpu::TextureView {
    let levels = mip_chain(atlas);
    let tex = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("sprite atlas"),
        size: wgpu::Extent3d {
            width: atlas.size,
            height: atlas.size,
            depth_or_array_layers: 1,
        },
        mip_level_count: levels.len() as u32,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    for (level, (size, rgba)) in levels.iter().enumerate() {
        ctx.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &tex,
                mip_level: level as u32,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            rgba,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * size),
                rows_per_image: None,
            },
            wgpu::Extent3d {
                width: *size,
                height: *size,
                depth_or_array_layers: 1,
            },
        );
    }
    tex.create_view(&Default::default())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mips_stop_at_eight_texel_tiles_and_keep_coverage() {
        let a = sheet();
        let chain = mip_chain(&a);
        let sizes: Vec<u32> = chain.iter().map(|l| l.0).collect();
        assert_eq!(sizes, vec![512, 256, 128, 64, 32]);
        // Mean alpha is preserved by 2×2 averaging up to rounding (±0.5 of
        // 255 per texel, so the means agree within 1 level).
        let mean = |v: &[u8]| v.chunks(4).map(|p| p[3] as f64).sum::<f64>() / (v.len() / 4) as f64;
        for w in chain.windows(2) {
            assert!((mean(&w[0].1) - mean(&w[1].1)).abs() < 1.0);
        }
    }

    #[test]
    fn transparent_texels_do_not_darken_the_average() {
        // One white opaque texel, three transparent black ones.
        let rgba = [255, 255, 255, 255, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0];
        assert_eq!(half(2, &rgba), vec![255, 255, 255, 64]);
    }
}
