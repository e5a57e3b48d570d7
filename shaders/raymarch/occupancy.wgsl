// The baked field's occupancy pyramids, one per clipmap level
// (clipmap.wgsl): level 0 of clip level c is its coarse grid (one cell per
// BAKE_BLOCK³ voxels, clip.levels[c].cells), each pyramid level above it
// has one cell per OCCUPANCY_FACTOR³ cells of the level below (rounded
// up), up to OCCUPANCY_LEVELS levels, stored one after the other from
// clip.levels[c].offsets.x in one u32 buffer. A cell holds the largest v
// that trilinear filtering can return in it (bit pattern of v + 1; 0 =
// nothing), the max of the cells it covers, so an empty cell of level l is
// empty at every level under it and a ray crosses it in one step
// (bake.wgsl writes it, field_baked.wgsl `empty_skip` reads it).
// src/methods/raymarch/baked.rs sizes the buffer with the same rule (a
// test compares the constants).

#import "../common.wgsl"
#import "clipmap.wgsl"

const OCCUPANCY_LEVELS: u32 = 3u;
const OCCUPANCY_FACTOR: u32 = 4u;

// Cells per axis of pyramid level `l` of clip level `c`.
fn occupancy_dims(c: u32, l: u32) -> vec3<u32> {
    var d = clip.levels[c].cells.xyz;
    for (var i = 0u; i < l; i++) {
        d = (d + OCCUPANCY_FACTOR - 1u) / OCCUPANCY_FACTOR;
    }
    return d;
}

// Index in the buffer of clip level c's level-0 cell `c0`'s ancestor at
// pyramid level `l`.
fn occupancy_index(c: u32, c0: vec3<u32>, l: u32) -> u32 {
    var offset = clip.levels[c].offsets.x;
    var d = clip.levels[c].cells.xyz;
    var q = c0;
    for (var i = 0u; i < l; i++) {
        offset += d.x * d.y * d.z;
        d = (d + OCCUPANCY_FACTOR - 1u) / OCCUPANCY_FACTOR;
        q /= OCCUPANCY_FACTOR;
    }
    return offset + q.x + d.x * (q.y + d.y * q.z);
}

// Side of a pyramid level-`l` cell of clip level `c`. units: m
fn occupancy_cell_m(c: u32, l: u32) -> vec3<f32> {
    var side = clip_voxel_m(c) * f32(BAKE_BLOCK);
    for (var i = 0u; i < l; i++) {
        side *= f32(OCCUPANCY_FACTOR);
    }
    return vec3<f32>(side);
}
