//! The ray-march's passes and slots: the march (a fragment pass, a compute
//! pass writing the cloud image and depth, and the one-pixel-per-block temporal
//! march), the temporal resolve, and the files `exact` and `baked` bind
//! to the shared shaders' slots, with the layout of their field (group
//! [`SLOT_GROUP`](crate::gpu::pass::SLOT_GROUP)). The bake's own
//! pipelines are in [`super::baked`].

use crate::gpu::layouts::{
    CLOUD_OUT, CLOUD_TARGET_FORMAT, COMMON, DEPTH, TEMPORAL_SCALAR_FORMAT, float2d_entry,
    storage_entry, storage_texture_entry, texture_entry, uniform_entry,
};
use crate::gpu::pass::{LayoutSpec, PassKind, PassSpec, Slots};

/// The ray-march's files under `shaders/raymarch/`.
pub const FILES: &[(&str, &str)] = crate::gpu::shaders::shader_files![
    "raymarch/clouds.wgsl",
    "raymarch/parcel.wgsl",
    "raymarch/field_exact.wgsl",
    "raymarch/far_light_exact.wgsl",
    "raymarch/field_baked.wgsl",
    "raymarch/occupancy.wgsl",
    "raymarch/clipmap.wgsl",
    "raymarch/density.wgsl",
    "raymarch/lighting.wgsl",
    "raymarch/bake.wgsl",
    "raymarch/temporal.wgsl",
    "raymarch/temporal_uniform.wgsl",
];

/// Group 3 under `exact`: the parcels and the grid's cell lists
/// (shaders/raymarch/field_exact.wgsl).
pub static EXACT_FIELD: LayoutSpec = LayoutSpec {
    label: "exact: parcels and grid",
    entries: &[uniform_entry(0), uniform_entry(1)],
};

/// A filterable float 3D texture readable by every stage.
const fn volume_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    texture_entry(
        binding,
        wgpu::TextureSampleType::Float { filterable: true },
        wgpu::TextureViewDimension::D3,
    )
}

/// Group 3 under `baked`: the baked field, its occupancy, the light
/// volume (shaders/raymarch/field_baked.wgsl) and the clipmap's levels
/// (shaders/raymarch/clipmap.wgsl).
pub static BAKED_FIELD: LayoutSpec = LayoutSpec {
    label: "baked: field, occupancy, light, clipmap",
    entries: &[volume_entry(0), storage_entry(1), volume_entry(2), uniform_entry(3)],
};

/// Group 2 of the temporal march (clouds.wgsl `cs_temporal`): one-texel-per-block
/// colour and depth outputs, the temporal uniform.
pub static TEMPORAL_OUT: LayoutSpec = LayoutSpec {
    label: "clouds: temporal outputs",
    entries: &[
        storage_texture_entry(0, CLOUD_TARGET_FORMAT),
        storage_texture_entry(1, TEMPORAL_SCALAR_FORMAT),
        uniform_entry(2),
    ],
};

/// Group 1 of the temporal resolve (shaders/raymarch/temporal.wgsl).
pub static TEMPORAL_IN: LayoutSpec = LayoutSpec {
    label: "temporal resolve",
    entries: &[
        float2d_entry(0, false),
        float2d_entry(1, false),
        float2d_entry(2, true),
        float2d_entry(3, false),
        storage_texture_entry(4, CLOUD_TARGET_FORMAT),
        storage_texture_entry(5, TEMPORAL_SCALAR_FORMAT),
        uniform_entry(6),
    ],
};

/// The march as a fragment pass over the scene target.
pub static CLOUDS: PassSpec = PassSpec {
    name: "clouds",
    root: "raymarch/clouds.wgsl",
    files: FILES,
    groups: &[Some(&COMMON), Some(&DEPTH)],
    slotted: true,
    kind: PassKind::Render {
        vertex: None,
        target: None,
        blend: Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
        depth: false,
    },
};

/// The march in compute, into the cloud image and depth (`cs_main`).
pub static CLOUDS_COMPUTE: PassSpec = PassSpec {
    name: "clouds (compute)",
    root: "raymarch/clouds.wgsl",
    files: FILES,
    groups: &[Some(&COMMON), Some(&DEPTH), Some(&CLOUD_OUT)],
    slotted: true,
    kind: PassKind::Compute { entry: "cs_main" },
};

/// The one-pixel-per-block march of the temporal path (`cs_temporal`).
pub static CLOUDS_TEMPORAL: PassSpec = PassSpec {
    name: "clouds (temporal)",
    root: "raymarch/clouds.wgsl",
    files: FILES,
    groups: &[Some(&COMMON), Some(&DEPTH), Some(&TEMPORAL_OUT)],
    slotted: true,
    kind: PassKind::Compute {
        entry: "cs_temporal",
    },
};

/// The temporal resolve: reprojection and accumulation (`cs_resolve`).
pub static TEMPORAL: PassSpec = PassSpec {
    name: "temporal resolve",
    root: "raymarch/temporal.wgsl",
    files: FILES,
    groups: &[Some(&COMMON), Some(&TEMPORAL_IN)],
    slotted: false,
    kind: PassKind::Compute {
        entry: "cs_resolve",
    },
};

/// Every pass of this folder the pipeline cache builds.
pub static ALL: [&PassSpec; 4] = [&CLOUDS, &CLOUDS_COMPUTE, &CLOUDS_TEMPORAL, &TEMPORAL];

/// `exact`: the per-sample union from the grid lists, its own far light.
pub static EXACT: Slots = Slots {
    name: "exact",
    bind: &[
        ("field", "raymarch/field_exact.wgsl"),
        ("far_light", "raymarch/far_light_exact.wgsl"),
        ("ground_shadow", "raymarch/density.wgsl"),
    ],
    files: FILES,
    group: Some(&EXACT_FIELD),
};

/// `baked`: the baked field and light volume.
pub static BAKED: Slots = Slots {
    name: "baked",
    bind: &[
        ("field", "raymarch/field_baked.wgsl"),
        ("far_light", "raymarch/field_baked.wgsl"),
        ("ground_shadow", "raymarch/density.wgsl"),
    ],
    files: FILES,
    group: Some(&BAKED_FIELD),
};
