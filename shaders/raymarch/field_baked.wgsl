// Macro field of the `baked` method: the union of parcel_value over all
// parcels, baked by bake.wgsl into a 3D texture over the clipmap's levels
// (clipmap.wgsl; R: v, G: condensation plane (m)), read with one trilinear
// fetch in the finest level around the sample, so a sample costs the same
// whatever the parcel count. The light volume
// (`light_tex`, R, G and B: optical depths toward the sun, straight up and
// away from the sun) is a second 3D texture with the same levels, one
// texel per coarse cell, and the sampler interpolates between the cells'
// centres. `occupancy` holds, per level's coarse cell (BAKE_BLOCK³ voxels)
// and per cell of the pyramid levels above (occupancy.wgsl), the
// largest v that trilinear filtering can return in it (bit pattern of
// v + 1; 0 = nothing), so rays cross the largest empty cell around them in
// one step: kilometres of clear air in a few. Bound to both the `<field>` slot (field_value, field_sample,
// empty_skip: as field_exact.wgsl, see there) and the `<far_light>` slot
// (far_light_depth, far_behind_depth: as far_light_exact.wgsl) of the
// method (src/methods/raymarch/passes.rs).

#import "../common.wgsl"
#import "clipmap.wgsl"
#import "occupancy.wgsl"

// The `baked` method's field (group 3 of the passes that import it; the
// clipmap's uniform is binding 3, clipmap.wgsl).
@group(3) @binding(0) var field_tex: texture_3d<f32>;
@group(3) @binding(1) var<storage, read> occupancy: array<u32>;
@group(3) @binding(2) var light_tex: texture_3d<f32>;

// The field texel (v, plane) at p: level l's texels lie from cell
// clip.levels[l].cells.w up along z.
fn field_fetch(l: u32, p: vec3<f32>) -> vec2<f32> {
    let z0 = f32(clip.levels[l].cells.w * BAKE_BLOCK);
    let texel = clip_rel(l, p) + vec3<f32>(0.0, 0.0, z0);
    let uvw = texel / vec3<f32>(textureDimensions(field_tex));
    return textureSampleLevel(field_tex, clamp_sampler, uvw, 0.0).rg;
}

fn field_sample(p: vec3<f32>) -> vec2<f32> {
    let l = clip_level(p);
    // Outside every level (each padded with empty voxels): v = −1 and the
    // sample's own height as the plane, as the exact union gives far from
    // every parcel.
    if l >= clip.count.x {
        return vec2<f32>(-1.0, p.z);
    }
    return field_fetch(l, p);
}

fn field_value(p: vec3<f32>) -> f32 {
    return field_sample(p).x;
}

// The light volume's texel at p: in the finest level around p (the last
// outside them all), clamped to that level's outermost cells.
fn light_fetch(p: vec3<f32>) -> vec3<f32> {
    if clip.count.x == 0u {
        return vec3<f32>(0.0);
    }
    let l = min(clip_level(p), clip.count.x - 1u);
    let cells = clip.levels[l].cells;
    let rel = clamp(clip_rel(l, p) / f32(BAKE_BLOCK), vec3<f32>(0.5), vec3<f32>(cells.xyz) - 0.5);
    let uvw = (rel + vec3<f32>(0.0, 0.0, f32(cells.w))) / vec3<f32>(textureDimensions(light_tex));
    return textureSampleLevel(light_tex, clamp_sampler, uvw, 0.0).rgb;
}

fn far_light_depth(p: vec3<f32>) -> vec2<f32> {
    return light_fetch(p).rg;
}

fn far_behind_depth(p: vec3<f32>) -> f32 {
    return light_fetch(p).b;
}

// Whether occupancy cell `bits` may show cloud: the noise adds at most k/2
// (density.wgsl), so a cell whose v stays under −k/2 shows nothing.
fn occupied(bits: u32) -> bool {
    let v_max = select(-1.0, bitcast<f32>(bits) - 1.0, bits != 0u);
    return v_max + 0.5 * frame.noise_amplitude > 0.0;
}

fn empty_skip(p: vec3<f32>, rd: vec3<f32>) -> f32 {
    // The level the field reads at p: its occupancy bounds what it returns.
    let c = clip_level(p);
    if c >= clip.count.x {
        return 0.0;
    }
    let ci = vec3<u32>(clip_rel(c, p) / f32(BAKE_BLOCK));
    // In cloud: one read, as with a single level.
    if occupied(occupancy[occupancy_index(c, ci, 0u)]) {
        return 0.0;
    }
    // Empty: the largest empty cell holding p, from the top level down.
    var level = 0u;
    for (var l = OCCUPANCY_LEVELS - 1u; l > 0u; l--) {
        if !occupied(occupancy[occupancy_index(c, ci, l)]) {
            level = l;
            break;
        }
    }
    var step = 1u;
    for (var i = 0u; i < level; i++) {
        step *= OCCUPANCY_FACTOR;
    }
    let cell = f32(BAKE_BLOCK) * clip_voxel_m(c);
    let lo = clip.levels[c].min_voxel.xyz + vec3<f32>((ci / step) * step) * cell;
    var t = ray_box(p, rd, lo, lo + occupancy_cell_m(c, level)).y;
    // Not past where the finer level begins (its field has detail this
    // level's occupancy does not bound).
    if c > 0u {
        let f = c - 1u;
        let h = clip_voxel_m(f);
        let fmin = clip.levels[f].min_voxel.xyz + 0.5 * h;
        let fmax = clip.levels[f].min_voxel.xyz + (vec3<f32>(clip_dims(f)) - 0.5) * h;
        let span = ray_box(p, rd, fmin, fmax);
        if span.x <= span.y && span.y > 0.0 {
            t = min(t, span.x);
        }
    }
    return max(t, 1e-3);
}
