//! The noise volume on the GPU: the RGBA8 3D texture with its mip chain
//! that every ray-march and slice pass samples as `noise_tex`, and its
//! repeating sampler. The volume itself is built on the CPU
//! ([`crate::noise`]).

use crate::noise::NoiseVolume;

/// Uploads every level of `volume` into an RGBA8 3D texture with a full mip chain
/// (the one the renderer binds as `noise_tex`).
pub fn texture(
    volume: &NoiseVolume,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
) -> wgpu::TextureView {
    let n = volume.side();
    let tex = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("noise 3d (4 octaves in RGBA, mipmapped)"),
        size: wgpu::Extent3d {
            width: n,
            height: n,
            depth_or_array_layers: n,
        },
        mip_level_count: volume.level_count(),
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    for (l, texels) in (0..volume.level_count())
        .map(|l| volume.level(l))
        .enumerate()
    {
        let side = n >> l;
        let extent = wgpu::Extent3d {
            width: side,
            height: side,
            depth_or_array_layers: side,
        };
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &tex,
                mip_level: l as u32,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            texels.as_flattened(),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * side),
                rows_per_image: Some(side),
            },
            extent,
        );
    }
    tex.create_view(&wgpu::TextureViewDescriptor::default())
}

/// The repeating sampler of `noise_tex` (and the other tiling lookups):
/// linear within a level and between mip levels.
pub fn repeat_sampler(device: &wgpu::Device) -> wgpu::Sampler {
    device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("repeat"),
        address_mode_u: wgpu::AddressMode::Repeat,
        address_mode_v: wgpu::AddressMode::Repeat,
        address_mode_w: wgpu::AddressMode::Repeat,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..Default::default()
    })
}
