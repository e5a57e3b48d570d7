//! The bake's bind-group layouts, module and buffers (the pipelines and
//! the encoding are in [`super::baked`]).

use crate::gpu::layouts::{compute_storage_entry, compute_uniform_entry, storage_texture_entry_of};
use crate::methods::raymarch::baked::{
    FIELD_FORMAT, LIGHT_FORMAT, OCCUPANCY_FACTOR, PARCEL_BYTES, SPLAT_ROW,
};
use crate::methods::raymarch::clipmap::Clipmap;

/// A 3D texture the bake writes and the march samples.
pub(super) fn volume_texture(
    device: &wgpu::Device,
    label: &str,
    format: wgpu::TextureFormat,
    dims: [u32; 3],
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: dims[0],
            height: dims[1],
            depth_or_array_layers: dims[2],
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

/// Group 0 of the bake: the frame uniform.
pub(super) const FRAME_ENTRIES: &[wgpu::BindGroupLayoutEntry] = &[compute_uniform_entry(0)];

/// Group 1 of the bake: the parcels, the accumulators, and the field and
/// light volumes it writes.
pub(super) const JOB_ENTRIES: &[wgpu::BindGroupLayoutEntry] = &[
    wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: wgpu::BufferSize::new(PARCEL_BYTES),
        },
        count: None,
    },
    compute_storage_entry(1),
    compute_storage_entry(2),
    storage_texture_entry_of(3, FIELD_FORMAT, wgpu::TextureViewDimension::D3),
    storage_texture_entry_of(4, LIGHT_FORMAT, wgpu::TextureViewDimension::D3),
    compute_storage_entry(5),
];

/// Group 3 of the bake: the clipmap's levels (binding 3, as in the march's
/// group 3; shaders/raymarch/clipmap.wgsl).
pub(super) const CLIP_ENTRIES: &[wgpu::BindGroupLayoutEntry] = &[compute_uniform_entry(3)];

/// The bake's module.
pub(super) fn source() -> std::result::Result<String, crate::gpu::shaders::ImportError> {
    crate::gpu::shaders::assemble_with("raymarch/bake.wgsl", &[], &super::passes::BAKED)
        .map(|a| a.source)
}

/// What the bake needs from the device (checked before it is built).
pub fn requirement() -> crate::gpu::requires::Requirement {
    crate::gpu::requires::Requirement::of(
        "bake",
        true,
        None,
        &[
            Some(FRAME_ENTRIES),
            Some(JOB_ENTRIES),
            None,
            Some(CLIP_ENTRIES),
        ],
        &source().unwrap_or_default(),
    )
}

/// Workgroups (4³ threads) of pyramid level `p` over every clip level:
/// the widest level's cells across, each clip level's slices one after the
/// other along z, as many as the deepest level's rounded up to a
/// workgroup (bake.wgsl `pyramid_slices`).
pub(super) fn pyramid_dispatch(map: &Clipmap, p: u32) -> [u32; 3] {
    let dims = |cells: [u32; 3]| {
        let mut d = cells;
        for _ in 0..p {
            d = d.map(|n| n.div_ceil(OCCUPANCY_FACTOR));
        }
        d
    };
    let widest = |a: usize| {
        map.levels
            .iter()
            .map(|l| dims(l.cells)[a])
            .max()
            .unwrap_or(1)
    };
    let slices = widest(2).div_ceil(4) * 4;
    [
        widest(0).div_ceil(4),
        widest(1).div_ceil(4),
        slices * map.levels.len() as u32 / 4,
    ]
}

/// The splat's dispatch for `n` parcels: rows of [`SPLAT_ROW`] workgroups
/// (the shader skips those past the count).
pub(super) fn splat_workgroups(n: u32) -> [u32; 2] {
    [n.clamp(1, SPLAT_ROW), n.div_ceil(SPLAT_ROW).max(1)]
}

pub(super) fn parcel_buffer(device: &wgpu::Device, parcels: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("bake: parcels"),
        size: parcels.max(1) * PARCEL_BYTES,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

pub(super) fn occupancy_buffer(device: &wgpu::Device, cells: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("bake: occupancy"),
        size: 4 * cells.max(1),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}
