//! The slices' passes and slots: the slicing planes into the float cloud
//! image, the compute pass of the vertex field and shadows
//! (`vertex_field = "gpu"`), and the field the shared shadow map marches
//! (`ground_shadow`), with the layout of the primitives' group
//! [`SLOT_GROUP`](crate::gpu::pass::SLOT_GROUP).

use crate::gpu::layouts::{
    CLOUD_TARGET_FORMAT, COMMON, DEPTH, compute_storage_entry, storage_entry, uniform_entry,
};
use crate::gpu::pass::{LayoutSpec, PassKind, PassSpec, Slots, VertexLayout};

/// The slices' files under `shaders/slices/`.
pub const FILES: &[(&str, &str)] = crate::gpu::shaders::shader_files![
    "slices/slices.wgsl",
    "slices/implicit.wgsl",
    "slices/vertex_field.wgsl",
    "slices/shadow_field.wgsl",
];

/// Group 3 of the slices passes: the octave transforms, the controls, the
/// primitives and their grid index (shaders/slices/implicit.wgsl).
pub static PRIMITIVES: LayoutSpec = LayoutSpec {
    label: "slices: octaves, controls, primitives",
    entries: &[
        uniform_entry(0),
        uniform_entry(1),
        storage_entry(2),
        storage_entry(3),
    ],
};

/// Group 1 of the vertex-field pass: its job and the vertices it writes.
pub static FIELD_JOB: LayoutSpec = LayoutSpec {
    label: "slice field: job and vertices",
    entries: &[uniform_entry(0), compute_storage_entry(1)],
};

/// Vertex layout of [`crate::methods::slices::model::SliceVertex`]:
/// position, field, shadow, plane opacity.
pub const VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 4] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32, 2 => Float32, 3 => Float32];

/// The planes, back to front into the float cloud image, premultiplied
/// "over" (shaders/slices/slices.wgsl).
pub static SLICES: PassSpec = PassSpec {
    name: "slices",
    root: "slices/slices.wgsl",
    files: FILES,
    groups: &[Some(&COMMON), Some(&DEPTH)],
    slotted: true,
    kind: PassKind::Render {
        vertex: Some(VertexLayout {
            stride: std::mem::size_of::<crate::methods::slices::model::SliceVertex>() as u64,
            attributes: &VERTEX_ATTRIBUTES,
        }),
        target: Some(CLOUD_TARGET_FORMAT),
        blend: Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
        depth: false,
    },
};

/// The vertex field (`cs_field`) of `vertex_field = "gpu"`.
pub static SLICE_FIELD: PassSpec = PassSpec {
    name: "slice_field",
    root: "slices/vertex_field.wgsl",
    files: FILES,
    groups: &[Some(&COMMON), Some(&FIELD_JOB)],
    slotted: true,
    kind: PassKind::Compute { entry: "cs_field" },
};

/// The vertex shadows along the light rays (`cs_shadow`).
pub static SLICE_SHADOW: PassSpec = PassSpec {
    name: "slice_field (shadow)",
    root: "slices/vertex_field.wgsl",
    files: FILES,
    groups: &[Some(&COMMON), Some(&FIELD_JOB)],
    slotted: true,
    kind: PassKind::Compute { entry: "cs_shadow" },
};

/// Every pass of this folder the pipeline cache builds.
pub static ALL: [&PassSpec; 3] = [&SLICES, &SLICE_FIELD, &SLICE_SHADOW];

/// The shadow map marches the slices' own field.
pub static SLOTS: Slots = Slots {
    name: "slices",
    bind: &[("ground_shadow", "slices/shadow_field.wgsl")],
    files: FILES,
    group: Some(&PRIMITIVES),
};
