//! The sprites' passes and slots: the instanced sprite quads over the
//! scene (also a ring face and the ring's quads), and the same quads
//! splatting their shadows into the cloud-shadow map.

use crate::gpu::layouts::{
    COMMON, SHADOW_FORMAT, float2d_entry, sampler_entry, storage_entry,
};
use crate::gpu::pass::{LayoutSpec, PassKind, PassSpec, Slots};

/// The sprites' files under `shaders/sprites/`.
pub const FILES: &[(&str, &str)] = crate::gpu::shaders::shader_files!["sprites/sprites.wgsl"];

/// Group 1 of the sprites: the terrain depth and the march's cloud depth
/// (shaders/sprites/sprites.wgsl).
pub static SPRITE_DEPTH: LayoutSpec = LayoutSpec {
    label: "sprites: terrain and cloud depth",
    entries: &[
        // The depth as an unfilterable float (see gpu::layouts::DEPTH).
        float2d_entry(0, false),
        float2d_entry(1, false),
    ],
};

/// Group 2 of the sprites: the atlas, its sampler and the instances.
pub static SPRITES_GROUP: LayoutSpec = LayoutSpec {
    label: "sprites: atlas and instances",
    entries: &[float2d_entry(0, true), sampler_entry(1), storage_entry(2)],
};

/// The groups of both sprite passes: the shared uniforms, the depths, the
/// atlas and instances.
const SPRITE_GROUPS: &[Option<&LayoutSpec>] =
    &[Some(&COMMON), Some(&SPRITE_DEPTH), Some(&SPRITES_GROUP)];

/// Sprites over the scene target (or a ring face), premultiplied "over".
pub static SPRITES: PassSpec = PassSpec {
    name: "sprites",
    root: "sprites/sprites.wgsl",
    files: FILES,
    groups: SPRITE_GROUPS,
    slotted: false,
    kind: PassKind::Render {
        vertex: None,
        target: None,
        blend: Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
        depth: false,
    },
};

/// Sprite shadows splatted into the shadow map: each multiplies the sun's
/// transmittance there by its own (1 − its opacity).
pub static SPRITES_SHADOW: PassSpec = PassSpec {
    name: "sprites (shadow)",
    root: "sprites/sprites.wgsl",
    files: FILES,
    groups: SPRITE_GROUPS,
    slotted: false,
    kind: PassKind::Render {
        vertex: None,
        target: Some(SHADOW_FORMAT),
        blend: Some(wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::Zero,
                dst_factor: wgpu::BlendFactor::Src,
                operation: wgpu::BlendOperation::Add,
            },
            alpha: wgpu::BlendComponent::REPLACE,
        }),
        depth: false,
    },
};

/// Every pass of this folder the pipeline cache builds.
pub static ALL: [&PassSpec; 2] = [&SPRITES, &SPRITES_SHADOW];

/// The `sprites` method marches no field: its shadows are splatted.
pub static SLOTS: Slots = Slots {
    name: "sprites",
    bind: &[("ground_shadow", "ground_none.wgsl")],
    files: FILES,
    group: None,
};
