//! GPU resources the renderer creates: plain textures, the noise volume,
//! the shared bind group (group 0) and the compute march's target.

use crate::render::gpu::GpuContext;
use crate::render::noise;
use crate::render::pipelines::{CLOUD_TARGET_FORMAT, PassLayouts};
use crate::render::raymarch::baked::BakedField;
use crate::render::raymarch::exact::ExactField;

use super::Renderer;

/// A single-sample, single-mip 2D texture (also the headless target and the
/// window's 3D view and screenshot).
pub(crate) fn texture_2d(
    device: &wgpu::Device,
    label: &str,
    w: u32,
    h: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

pub(super) fn noise_texture(ctx: &GpuContext, n: u32) -> wgpu::TextureView {
    let tex = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("noise 3d"),
        size: wgpu::Extent3d {
            width: n,
            height: n,
            depth_or_array_layers: n,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: wgpu::TextureFormat::R8Unorm,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    ctx.queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture: &tex,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        &noise::tiling_fbm(n, 1),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(n),
            rows_per_image: Some(n),
        },
        wgpu::Extent3d {
            width: n,
            height: n,
            depth_or_array_layers: n,
        },
    );
    tex.create_view(&wgpu::TextureViewDescriptor::default())
}

#[allow(clippy::too_many_arguments)]
pub(super) fn make_bind_common(
    device: &wgpu::Device,
    layouts: &PassLayouts,
    frame: &wgpu::Buffer,
    exact: &ExactField,
    baked: &BakedField,
    noise: &wgpu::TextureView,
    repeat: &wgpu::Sampler,
    clamp: &wgpu::Sampler,
) -> wgpu::BindGroup {
    let (field, occupancy) = baked.field();
    let entries = [
        frame.as_entire_binding(),
        exact.parcels_buf.as_entire_binding(),
        exact.grid_buf.as_entire_binding(),
        wgpu::BindingResource::TextureView(noise),
        wgpu::BindingResource::Sampler(repeat),
        wgpu::BindingResource::Sampler(clamp),
        wgpu::BindingResource::TextureView(field),
        occupancy.as_entire_binding(),
    ];
    let entries: Vec<wgpu::BindGroupEntry> = entries
        .into_iter()
        .enumerate()
        .map(|(i, resource)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource,
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("common"),
        layout: &layouts.common,
        entries: &entries,
    })
}

impl Renderer {
    pub(super) fn rebind_common(&mut self, ctx: &GpuContext) {
        self.bind_common = make_bind_common(
            &ctx.device,
            &self.layouts,
            &self.frame_buf,
            &self.exact,
            &self.baked,
            &self.noise_view,
            &self.repeat_sampler,
            &self.clamp_sampler,
        );
        self.bound_generation = self.baked.generation;
    }

    pub(super) fn make_cloud_target(
        &self,
        device: &wgpu::Device,
    ) -> (wgpu::TextureView, wgpu::BindGroup, wgpu::BindGroup) {
        let view = texture_2d(
            device,
            "clouds (compute)",
            self.width,
            self.height,
            CLOUD_TARGET_FORMAT,
            // Storage: the compute march writes it; render attachment: the
            // slices pass blends its planes into it.
            wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .create_view(&Default::default());
        let bind = |label, layout| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view),
                }],
            })
        };
        let out = bind("clouds: compute output", &self.layouts.cloud_out);
        let input = bind("composite: clouds", &self.layouts.cloud_in);
        (view, out, input)
    }
}
