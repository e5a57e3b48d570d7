//! Plain GPU resources every pass and method makes: single-mip 2D
//! textures, bind groups whose resources take bindings in order, and the
//! frame-size check.

use crate::gpu::GpuContext;

/// A single-sample, single-mip 2D texture (also the headless target and the
/// window's 3D view and screenshot).
pub fn texture_2d(
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

/// A bind group whose `resources` take bindings 0, 1, 2, … in order.
pub fn bind_in_order(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    resources: Vec<wgpu::BindingResource>,
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = resources
        .into_iter()
        .enumerate()
        .map(|(i, resource)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource,
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// A frame size the device can hold, or a clear error.
pub fn check_size(ctx: &GpuContext, width: u32, height: u32) -> crate::error::Result<()> {
    let max = ctx.device.limits().max_texture_dimension_2d;
    if width == 0 || height == 0 || width > max || height > max {
        return Err(crate::error::Error::invalid(
            "frame size",
            format!("{width}×{height}"),
            format!("1 to {max} pixels per side on this device"),
        ));
    }
    Ok(())
}
