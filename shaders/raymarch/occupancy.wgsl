// The baked field's occupancy pyramid: level 0 is the coarse grid of the
// frame (one cell per BAKE_BLOCK³ voxels, frame.grid_dims cells), each
// level above it has one cell per OCCUPANCY_FACTOR³ cells of the level
// below (rounded up), up to OCCUPANCY_LEVELS levels, stored one after the
// other in one u32 buffer. A cell holds the largest v that trilinear
// filtering can return in it (bit pattern of v + 1; 0 = nothing), the max
// of the cells it covers, so an empty cell of level l is empty at every
// level under it and a ray crosses it in one step (bake.wgsl writes it,
// field_baked.wgsl `empty_skip` reads it). src/methods/raymarch/baked.rs
// sizes the buffer with the same rule (a test compares the constants).

#import "../common.wgsl"

const OCCUPANCY_LEVELS: u32 = 3u;
const OCCUPANCY_FACTOR: u32 = 4u;

// Cells per axis of level `l`.
fn occupancy_dims(l: u32) -> vec3<u32> {
    var d = frame.grid_dims;
    for (var i = 0u; i < l; i++) {
        d = (d + OCCUPANCY_FACTOR - 1u) / OCCUPANCY_FACTOR;
    }
    return d;
}

// Index in the buffer of level-0 cell `c0`'s ancestor at level `l`.
fn occupancy_index(c0: vec3<u32>, l: u32) -> u32 {
    var offset = 0u;
    var d = frame.grid_dims;
    var c = c0;
    for (var i = 0u; i < l; i++) {
        offset += d.x * d.y * d.z;
        d = (d + OCCUPANCY_FACTOR - 1u) / OCCUPANCY_FACTOR;
        c /= OCCUPANCY_FACTOR;
    }
    return offset + c.x + d.x * (c.y + d.y * c.z);
}

// Side of a level-`l` cell. units: m
fn occupancy_cell_m(l: u32) -> vec3<f32> {
    var side = frame.grid_cell;
    for (var i = 0u; i < l; i++) {
        side *= f32(OCCUPANCY_FACTOR);
    }
    return side;
}
