//! The formats of the renderer's targets and the bind-group layouts its
//! passes share ([`PassLayouts`]), with the layout-entry helpers the
//! methods' own layouts use too.

/// Format of the internal depth buffer (written by terrain, read by clouds).
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Format of the cloud-shadow map (sun transmittance 0..1).
pub const SHADOW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Unorm;

/// Stages that read the shared bindings: the passes' vertex and fragment
/// shaders and the compute march.
const STAGES: wgpu::ShaderStages =
    wgpu::ShaderStages::VERTEX_FRAGMENT.union(wgpu::ShaderStages::COMPUTE);
/// Format of the compute march's output (premultiplied linear radiance).
pub const CLOUD_TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Format of the compute march's cloud depth (the opacity-weighted mean
/// distance of the clouds along each pixel's ray; sprites sort against it).
pub const CLOUD_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
/// Format of the temporal path's cloud depth (quarter size) and sample
/// counts (full size): one unfilterable float each.
pub const TEMPORAL_SCALAR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
/// Format of the HDR scene target: every scene pass (sky, terrain, clouds,
/// composite) writes linear radiance into it; the tone-map pass alone
/// writes the output format. Half floats hold radiance up to 65504 (the
/// sun disc is ~12) with 11 bits of mantissa, finer than 8-bit output.
pub const SCENE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// A uniform buffer of `size` bytes the queue writes.
pub(crate) fn uniform_buffer(device: &wgpu::Device, label: &str, size: usize) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

pub(crate) fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
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

fn texture_entry(
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

fn sampler_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: STAGES,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    }
}

/// A write-only 2D storage texture of the compute passes.
fn storage_texture_entry(binding: u32, format: wgpu::TextureFormat) -> wgpu::BindGroupLayoutEntry {
    storage_texture_entry_of(binding, format, wgpu::TextureViewDimension::D2)
}

/// A write-only storage texture of the compute passes (also the bake's 3D
/// field and light volume, src/render/raymarch/baked.rs).
pub(crate) fn storage_texture_entry_of(
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

pub(crate) fn storage_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
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

/// The bind-group layouts every render pass shares (cheap to clone: wgpu
/// handles; the background builder holds a copy).
#[derive(Clone)]
pub struct PassLayouts {
    /// Group 0: frame, parcels, grid (exact), noise, samplers, baked field,
    /// occupancy and light volume (baked): the bindings of
    /// shaders/common.wgsl and shaders/raymarch/field_baked.wgsl (wgpu
    /// checks them against each pipeline's shader).
    pub common: wgpu::BindGroupLayout,
    /// Group 1 of the terrain: the cloud-shadow map.
    pub shadow_tex: wgpu::BindGroupLayout,
    /// Group 1 of the clouds: the terrain depth.
    pub depth: wgpu::BindGroupLayout,
    /// Group 2 of the compute march: its output texture and cloud depth.
    pub cloud_out: wgpu::BindGroupLayout,
    /// Group 1 of the sprites: the terrain depth and the march's cloud
    /// depth (shaders/sprites/sprites.wgsl).
    pub sprite_depth: wgpu::BindGroupLayout,
    /// Group 1 of the composite (the compute march's or the slices'
    /// texture) and of the tone map (the HDR scene target): one sampled
    /// float 2D texture.
    pub texture_in: wgpu::BindGroupLayout,
    /// Group 2 of the sprites: the atlas, its sampler and the sprite
    /// instances (shaders/sprites/sprites.wgsl).
    pub sprites: wgpu::BindGroupLayout,
    /// Group 2 of the slices pass: octave transforms and controls.
    pub slices: wgpu::BindGroupLayout,
    /// Group 2 of the temporal march (clouds.wgsl `cs_temporal`): quarter
    /// colour and depth outputs, the temporal uniform.
    pub temporal_out: wgpu::BindGroupLayout,
    /// Group 1 of the temporal resolve (shaders/raymarch/temporal.wgsl).
    pub temporal_in: wgpu::BindGroupLayout,
}

impl PassLayouts {
    pub fn new(device: &wgpu::Device) -> Self {
        let float3d = texture_entry(
            3,
            wgpu::TextureSampleType::Float { filterable: true },
            wgpu::TextureViewDimension::D3,
        );
        let common = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("common"),
            entries: &[
                uniform_entry(0),
                uniform_entry(1),
                uniform_entry(2),
                float3d,
                sampler_entry(4),
                sampler_entry(5),
                wgpu::BindGroupLayoutEntry {
                    binding: 6,
                    ..float3d
                },
                storage_entry(7),
                wgpu::BindGroupLayoutEntry {
                    binding: 8,
                    ..float3d
                },
            ],
        });
        let shadow_tex = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("terrain: shadow map"),
            entries: &[texture_entry(
                0,
                wgpu::TextureSampleType::Float { filterable: true },
                wgpu::TextureViewDimension::D2,
            )],
        });
        let depth = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("clouds: depth"),
            entries: &[texture_entry(
                0,
                wgpu::TextureSampleType::Depth,
                wgpu::TextureViewDimension::D2,
            )],
        });
        let cloud_out = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("clouds: compute output"),
            entries: &[
                storage_texture_entry(0, CLOUD_TARGET_FORMAT),
                storage_texture_entry(1, CLOUD_DEPTH_FORMAT),
            ],
        });
        let sprite_depth = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sprites: terrain and cloud depth"),
            entries: &[
                texture_entry(
                    0,
                    wgpu::TextureSampleType::Depth,
                    wgpu::TextureViewDimension::D2,
                ),
                texture_entry(
                    1,
                    wgpu::TextureSampleType::Float { filterable: false },
                    wgpu::TextureViewDimension::D2,
                ),
            ],
        });
        let float2d = |binding, filterable| {
            texture_entry(
                binding,
                wgpu::TextureSampleType::Float { filterable },
                wgpu::TextureViewDimension::D2,
            )
        };
        let temporal_out = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("clouds: temporal outputs"),
            entries: &[
                storage_texture_entry(0, CLOUD_TARGET_FORMAT),
                storage_texture_entry(1, TEMPORAL_SCALAR_FORMAT),
                uniform_entry(2),
            ],
        });
        let temporal_in = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("temporal resolve"),
            entries: &[
                float2d(0, false),
                float2d(1, false),
                float2d(2, true),
                float2d(3, false),
                storage_texture_entry(4, CLOUD_TARGET_FORMAT),
                storage_texture_entry(5, TEMPORAL_SCALAR_FORMAT),
                uniform_entry(6),
            ],
        });
        let texture_in = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("composite/tonemap: input texture"),
            entries: &[texture_entry(
                0,
                wgpu::TextureSampleType::Float { filterable: true },
                wgpu::TextureViewDimension::D2,
            )],
        });
        let sprites = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sprites: atlas and instances"),
            entries: &[
                texture_entry(
                    0,
                    wgpu::TextureSampleType::Float { filterable: true },
                    wgpu::TextureViewDimension::D2,
                ),
                sampler_entry(1),
                storage_entry(2),
            ],
        });
        Self {
            common,
            shadow_tex,
            depth,
            cloud_out,
            sprite_depth,
            texture_in,
            sprites,
            slices: crate::methods::slices::gpu::bind_group_layout(device),
            temporal_out,
            temporal_in,
        }
    }
}
