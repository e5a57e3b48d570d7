// The baked field's levels (src/methods/raymarch/clipmap.rs says how they
// are chosen): 1 to MAX_CLIP_LEVELS nested boxes of cubic voxels, finest
// first, each twice the voxel of the one before, stacked one above the
// other along z in the field texture, the light volume and the key buffer,
// their occupancy pyramids one after the other in one buffer. A sample
// reads the finest level whose texels surround it (`clip_level`). The
// frame's grid (grid_min, grid_cell, grid_dims) is the last level, the
// whole box, where the march starts and stops.

#import "../common.wgsl"

// Most levels: MAX_CLIP_LEVELS of src/methods/raymarch/clipmap.rs (a test
// compares them).
const MAX_CLIP_LEVELS: u32 = 5u;
// Voxels per coarse occupancy cell along each axis: BAKE_BLOCK of
// src/methods/raymarch/baked.rs (a test compares them).
const BAKE_BLOCK: u32 = 4u;

// `GpuClipLevel` of src/methods/raymarch/clipmap.rs (a test checks the
// layout against naga's).
struct ClipLevel {
    min_voxel: vec4<f32>, // xyz: lowest corner (m), w: voxel side (m)
    cells: vec4<u32>,     // xyz: coarse cells per axis, w: first cell along z in the stacked volumes
    offsets: vec4<u32>,   // x: first occupancy entry, y: first voxel key
}

// `ClipUniform` of src/methods/raymarch/clipmap.rs.
struct Clipmap {
    count: vec4<u32>, // x: levels in use
    levels: array<ClipLevel, MAX_CLIP_LEVELS>,
}

@group(3) @binding(3) var<uniform> clip: Clipmap;

fn clip_voxel_m(l: u32) -> f32 {
    return clip.levels[l].min_voxel.w;
}

fn clip_dims(l: u32) -> vec3<u32> {
    return clip.levels[l].cells.xyz * BAKE_BLOCK;
}

// p in voxels from level l's lowest corner.
fn clip_rel(l: u32, p: vec3<f32>) -> vec3<f32> {
    return (p - clip.levels[l].min_voxel.xyz) / clip_voxel_m(l);
}

// Whether a trilinear fetch at p reads only level l's texels (p at least
// half a voxel inside): ClipLevel::surrounds.
fn clip_inside(l: u32, p: vec3<f32>) -> bool {
    let rel = clip_rel(l, p);
    return all(rel >= vec3<f32>(0.5)) && all(rel <= vec3<f32>(clip_dims(l)) - 0.5);
}

// The finest level whose texels surround p; clip.count.x outside them all
// (no cloud there): Clipmap::level_at.
fn clip_level(p: vec3<f32>) -> u32 {
    let n = clip.count.x;
    for (var l = 0u; l < n; l++) {
        if clip_inside(l, p) {
            return l;
        }
    }
    return n;
}
