//! The shared passes every render method draws with: the sky, the
//! terrain, the cloud-shadow map, the composite of a method's cloud image
//! and the tone map (their WGSL at the top of `shaders/`). The renderer
//! ([`crate::render::Renderer`]) encodes them around the method's own
//! passes; the terrain and the shadow map import the method's slots.

use crate::gpu::layouts::{COMMON, SHADOW_FORMAT, SHADOW_OUT, SHADOW_TEX, TEXTURE_IN};
use crate::gpu::pass::{PassKind, PassSpec, VertexLayout};
use crate::landscape::terrain::TerrainVertex;

/// A full-screen triangle into the key's format, without blending.
const FULLSCREEN: PassKind = PassKind::Render {
    vertex: None,
    target: None,
    blend: None,
    depth: false,
};

/// Sky gradient and sun disc (shaders/sky.wgsl).
pub static SKY: PassSpec = PassSpec {
    name: "sky",
    root: "sky.wgsl",
    files: &[],
    groups: &[Some(&COMMON)],
    slotted: false,
    kind: FULLSCREEN,
};

/// The terrain mesh with depth, shadowed by the map (shaders/terrain.wgsl).
pub static TERRAIN: PassSpec = PassSpec {
    name: "terrain",
    root: "terrain.wgsl",
    files: &[],
    groups: &[Some(&COMMON), Some(&SHADOW_TEX)],
    slotted: true,
    kind: PassKind::Render {
        vertex: Some(VertexLayout {
            stride: std::mem::size_of::<TerrainVertex>() as u64,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3],
        }),
        target: None,
        blend: None,
        depth: true,
    },
};

/// The cloud-shadow map: the method's `ground_sun_depth` per texel
/// (shaders/shadow.wgsl).
pub static SHADOW: PassSpec = PassSpec {
    name: "shadow",
    root: "shadow.wgsl",
    files: &[],
    groups: &[Some(&COMMON)],
    slotted: true,
    kind: PassKind::Render {
        vertex: None,
        target: Some(SHADOW_FORMAT),
        blend: None,
        depth: false,
    },
};

/// The cloud-shadow map marched in a compute shader (`cs_main`, the same
/// routine per texel as [`SHADOW`]) where the adapter runs compute: on
/// GPUs with few raster units (an H100 runs the same march 26× slower as
/// a fragment shader) it is most of the pass.
pub static SHADOW_COMPUTE: PassSpec = PassSpec {
    name: "shadow (compute)",
    root: "shadow.wgsl",
    files: &[],
    groups: &[Some(&COMMON), None, Some(&SHADOW_OUT)],
    slotted: true,
    kind: PassKind::Compute { entry: "cs_main" },
};

/// A method's cloud image blended over the scene, premultiplied
/// (shaders/composite.wgsl).
pub static COMPOSITE: PassSpec = PassSpec {
    name: "composite",
    root: "composite.wgsl",
    files: &[],
    groups: &[Some(&COMMON), Some(&TEXTURE_IN)],
    slotted: false,
    kind: PassKind::Render {
        vertex: None,
        target: None,
        blend: Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
        depth: false,
    },
};

/// The HDR scene target, tone-mapped once into the output
/// (shaders/tonemap.wgsl); group 2 is the method's cloud image, which it
/// blends first in the frames that have no composite pass (else the
/// scene target again, unread).
pub static TONEMAP: PassSpec = PassSpec {
    name: "tonemap",
    root: "tonemap.wgsl",
    files: &[],
    groups: &[Some(&COMMON), Some(&TEXTURE_IN), Some(&TEXTURE_IN)],
    slotted: false,
    kind: FULLSCREEN,
};

/// Every shared pass.
pub static ALL: [&PassSpec; 6] = [
    &SKY,
    &TERRAIN,
    &SHADOW,
    &SHADOW_COMPUTE,
    &COMPOSITE,
    &TONEMAP,
];
