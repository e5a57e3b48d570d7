// Macro field of the `baked` method: the union of parcel_value over all
// parcels, baked by bake.wgsl into a 3D texture over the cloud region
// (R: v, G: condensation plane (m)), read with one trilinear fetch, so a
// sample costs the same whatever the parcel count. The light volume
// (`light_tex`, R, G and B: optical depths toward the sun, straight up and
// away from the sun) is a second 3D texture over the same region, one
// texel per coarse cell, so the same coordinates address both and the
// sampler interpolates between the cells' centres. The frame's grid
// (grid_min, grid_cell, grid_dims) is the bake's coarse occupancy grid
// (BAKE_BLOCK³ voxels a cell) over the same region; `occupancy` holds, per
// coarse cell and per cell of the levels above (occupancy.wgsl), the
// largest v that trilinear filtering can return in it (bit pattern of
// v + 1; 0 = nothing), so rays cross the largest empty cell around them in
// one step: kilometres of clear air in a few. Bound to both the `<field>` slot (field_value, field_sample,
// empty_skip: as field_exact.wgsl, see there) and the `<far_light>` slot
// (far_light_depth, far_behind_depth: as far_light_exact.wgsl) of the
// method (src/methods/raymarch/passes.rs).

#import "../common.wgsl"
#import "occupancy.wgsl"

// The `baked` method's field (group 3 of the passes that import it).
@group(3) @binding(0) var field_tex: texture_3d<f32>;
@group(3) @binding(1) var<storage, read> occupancy: array<u32>;
@group(3) @binding(2) var light_tex: texture_3d<f32>;

fn field_uvw(p: vec3<f32>) -> vec3<f32> {
    let size = frame.grid_cell * vec3<f32>(frame.grid_dims);
    return (p - frame.grid_min) / size;
}

fn field_value(p: vec3<f32>) -> f32 {
    // The region is padded with empty voxels: clamping returns v = −1
    // outside it, as the exact union does far from every parcel.
    return textureSampleLevel(field_tex, clamp_sampler, field_uvw(p), 0.0).r;
}

fn field_sample(p: vec3<f32>) -> vec2<f32> {
    return textureSampleLevel(field_tex, clamp_sampler, field_uvw(p), 0.0).rg;
}

fn far_light_depth(p: vec3<f32>) -> vec2<f32> {
    // Clamped at the region's edge to the outermost cells.
    return textureSampleLevel(light_tex, clamp_sampler, field_uvw(p), 0.0).rg;
}

fn far_behind_depth(p: vec3<f32>) -> f32 {
    return textureSampleLevel(light_tex, clamp_sampler, field_uvw(p), 0.0).b;
}

// Whether occupancy cell `bits` may show cloud: the noise adds at most k/2
// (density.wgsl), so a cell whose v stays under −k/2 shows nothing.
fn occupied(bits: u32) -> bool {
    let v_max = select(-1.0, bitcast<f32>(bits) - 1.0, bits != 0u);
    return v_max + 0.5 * frame.noise_amplitude > 0.0;
}

fn empty_skip(p: vec3<f32>, rd: vec3<f32>) -> f32 {
    let dims = frame.grid_dims;
    let rel = (p - frame.grid_min) / frame.grid_cell;
    if any(rel < vec3<f32>(0.0)) || any(rel >= vec3<f32>(dims)) {
        return 0.0;
    }
    let ci = vec3<u32>(rel);
    // In cloud: one read, as with a single level.
    if occupied(occupancy[occupancy_index(ci, 0u)]) {
        return 0.0;
    }
    // Empty: the largest empty cell holding p, from the top level down.
    var level = 0u;
    for (var l = OCCUPANCY_LEVELS - 1u; l > 0u; l--) {
        if !occupied(occupancy[occupancy_index(ci, l)]) {
            level = l;
            break;
        }
    }
    var step = 1u;
    for (var i = 0u; i < level; i++) {
        step *= OCCUPANCY_FACTOR;
    }
    let lo = frame.grid_min + vec3<f32>((ci / step) * step) * frame.grid_cell;
    return max(ray_box(p, rd, lo, lo + occupancy_cell_m(level)).y, 1e-3);
}
