//! The formats of the renderer's targets, the bind-group layouts the
//! shared passes declare, the `const` layout-entry helpers every layout
//! (the methods' too) is written with, and [`Layouts`], which creates each
//! declared layout once per device.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use crate::gpu::pass::LayoutSpec;

/// Format of the internal depth buffer (written by terrain, read by clouds).
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Format of the cloud-shadow map (sun transmittance 0..1 in red): four
/// 8-bit channels, since the compute march writes it as a storage texture
/// (which R8Unorm cannot be without an optional feature) and the sprites
/// blend their shadows into it.
pub const SHADOW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// Stages that read the shared bindings: the passes' vertex and fragment
/// shaders and the compute march.
pub const STAGES: wgpu::ShaderStages =
    wgpu::ShaderStages::VERTEX_FRAGMENT.union(wgpu::ShaderStages::COMPUTE);
/// Format of the compute march's output (premultiplied linear radiance).
pub const CLOUD_TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Format of the compute march's cloud depth (the opacity-weighted mean
/// distance of the clouds along each pixel's ray; sprites sort against it).
pub const CLOUD_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
/// Format of the temporal path's cloud depth (one texel per block) and sample
/// counts (full size): one unfilterable float each.
pub const TEMPORAL_SCALAR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
/// Format of the HDR scene target: every scene pass (sky, terrain, clouds,
/// composite) writes linear radiance into it; the tone-map pass alone
/// writes the output format. Half floats hold radiance up to 65504 (the
/// sun disc is ~12) with 11 bits of mantissa, finer than 8-bit output.
pub const SCENE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// A uniform buffer of `size` bytes the queue writes.
pub fn uniform_buffer(device: &wgpu::Device, label: &str, size: usize) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

pub const fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: STAGES,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

pub const fn texture_entry(
    binding: u32,
    sample_type: wgpu::TextureSampleType,
    dim: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: STAGES,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: dim,
            multisampled: false,
        },
        count: None,
    }
}

pub const fn sampler_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: STAGES,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    }
}

/// A write-only 2D storage texture of the compute passes.
pub const fn storage_texture_entry(
    binding: u32,
    format: wgpu::TextureFormat,
) -> wgpu::BindGroupLayoutEntry {
    storage_texture_entry_of(binding, format, wgpu::TextureViewDimension::D2)
}

/// A write-only storage texture of the compute passes (also the bake's 3D
/// field and light volume, src/methods/raymarch/baked.rs).
pub const fn storage_texture_entry_of(
    binding: u32,
    format: wgpu::TextureFormat,
    view_dimension: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension,
        },
        count: None,
    }
}

pub const fn storage_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: STAGES,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A uniform buffer of the compute passes (the bake's frame and clipmap
/// levels).
pub const fn compute_uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        visibility: wgpu::ShaderStages::COMPUTE,
        ..uniform_entry(binding)
    }
}

/// A read-write storage buffer of the compute passes (the bake's
/// accumulators, the slices' vertices).
pub const fn compute_storage_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: false },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A filterable float 2D texture (binding `binding`).
pub const fn float2d_entry(binding: u32, filterable: bool) -> wgpu::BindGroupLayoutEntry {
    texture_entry(
        binding,
        wgpu::TextureSampleType::Float { filterable },
        wgpu::TextureViewDimension::D2,
    )
}

/// Group 0 of every pass: the frame uniform, the noise volume and the
/// samplers (the bindings of shaders/common.wgsl; wgpu checks them against
/// each pipeline's shader).
pub static COMMON: LayoutSpec = LayoutSpec {
    label: "common",
    entries: &[
        uniform_entry(0),
        texture_entry(
            3,
            wgpu::TextureSampleType::Float { filterable: true },
            wgpu::TextureViewDimension::D3,
        ),
        sampler_entry(4),
        sampler_entry(5),
    ],
};

/// Group 1 of the terrain: the cloud-shadow map.
pub static SHADOW_TEX: LayoutSpec = LayoutSpec {
    label: "terrain: shadow map",
    entries: &[float2d_entry(0, true)],
};

/// Group 1 of the passes that test the terrain's depth (the clouds, the
/// slices): the depth as an unfilterable float texture, which every
/// backend can load from (OpenGL's GLSL cannot load from a depth binding).
pub static DEPTH: LayoutSpec = LayoutSpec {
    label: "clouds: depth",
    entries: &[float2d_entry(0, false)],
};

/// Group 1 of the composite (a method's cloud image) and of the tone map
/// (the HDR scene target): one sampled float 2D texture.
pub static TEXTURE_IN: LayoutSpec = LayoutSpec {
    label: "composite/tonemap: input texture",
    entries: &[float2d_entry(0, true)],
};

/// Group 2 of the compute shadow march: the cloud-shadow map it writes.
pub static SHADOW_OUT: LayoutSpec = LayoutSpec {
    label: "shadow: compute output",
    entries: &[storage_texture_entry(0, SHADOW_FORMAT)],
};

/// Group 2 of a compute pass writing the shared float cloud image: the
/// image and its cloud depth.
pub static CLOUD_OUT: LayoutSpec = LayoutSpec {
    label: "clouds: compute output",
    entries: &[
        storage_texture_entry(0, CLOUD_TARGET_FORMAT),
        storage_texture_entry(1, CLOUD_DEPTH_FORMAT),
    ],
};

/// Every declared layout this device has needed, created once each (cheap
/// to clone: the background builder holds a copy).
#[derive(Clone)]
pub struct Layouts {
    device: wgpu::Device,
    made: Arc<Mutex<HashMap<&'static str, wgpu::BindGroupLayout>>>,
}

impl Layouts {
    pub fn new(device: &wgpu::Device) -> Self {
        Self {
            device: device.clone(),
            made: Arc::default(),
        }
    }

    /// The layout of `spec` on this device.
    pub fn get(&self, spec: &'static LayoutSpec) -> wgpu::BindGroupLayout {
        let mut made = self.made.lock().unwrap_or_else(|e| e.into_inner());
        made.entry(spec.label)
            .or_insert_with(|| {
                self.device
                    .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                        label: Some(spec.label),
                        entries: spec.entries,
                    })
            })
            .clone()
    }
}
