// Bake of the `baked` method's macro field (compute): M(P) = max over
// parcels of f·(d(P)+1) − 1 (parcel.wgsl) on the voxel grids of the
// clipmap's levels (clipmap.wgsl: one level over the condensed parcels'
// box, or nested camera-centred levels at 2× voxel steps, stacked along
// z), then per level a coarse occupancy pyramid for empty-space skipping.
// src/methods/raymarch/baked.rs drives it; field_baked.wgsl reads the
// result.
//
// 1. `splat`, one dispatch for all the parcels (a read-only storage
//    buffer of frame.parcel_count parcels; workgroups in rows of
//    SPLAT_ROW along x, rows along y, so any count fits the per-dimension
//    dispatch limit, one layer of rows per level along z): workgroup
//    (w, level) takes parcel w (every thread reads the same parcel) and
//    its threads walk the voxels of the parcel's bounding box in that
//    level, folding (v, height above the parcel's
//    condensation plane) into the voxel with one atomic max on a key
//    (`voxel_key`): the largest v wins, and among equal v (saturated
//    parcels) the lowest plane, so the voxel keeps the plane of the parcel
//    that gives its value, as field_exact.wgsl's field_sample does. The
//    max does not depend on the order the parcels are folded in, so the
//    field is the same whatever the scheduling. A thread reads the key
//    first and folds only a larger one: inside overlapping parcels most
//    voxels already hold the saturated value, and the read spares them the
//    atomic's contention.
//    Cost ∝ parcels × voxels each, not pixels × parcels.
// 2. `light`, one thread per coarse cell of every level: the light
//    volume. From the cell's centre it marches toward the sun, straight up
//    and away from the sun, through the splatted macro field (parcels only,
//    no noise; the finest level holding each step, whose voxel sets the
//    step) to the whole box's edge and stores the three optical depths (density × m; ×
//    extinction gives the exponent) in the R, G and B of its texel of
//    `light_out`, a 3D texture of
//    one texel per coarse cell that the march samples with the filtering
//    sampler (hardware trilinear between the cells' centres). Over the
//    region's whole height: a tower's top shadows its base and its
//    neighbours, and a base sees little sky.
// 3. `resolve`, one thread per voxel of every level: writes (v, plane) into the field
//    texture, folds v into the coarse cells whose trilinear footprint holds
//    the voxel (so a cell's value bounds every filtered fetch in it), and
//    zeroes the voxel's accumulators for the next bake.

#import "../common.wgsl"
#import "parcel.wgsl"
#import "clipmap.wgsl"
#import "occupancy.wgsl"

// A voxel's key: v + 1 ∈ [0, 2] in the high 16 bits (steps of 3·10⁻⁵,
// finer than the field texture's half floats keep) and the voxel's height
// above the parcel's condensation plane, clamped to ±PLANE_RANGE_M, in the
// low 16 (steps of 6 cm). The plane matters to the lighting only within
// BASE_FADE_M (500 m) above it, and a voxel more than a plane shell under
// it gets no value from the parcel, so the clamp changes nothing it reads.
// 0 = no parcel reaches the voxel.
const KEY_LEVELS: f32 = 65535.0;
const PLANE_RANGE_M: f32 = 2048.0;

// The condensed parcels (the first frame.parcel_count of them).
@group(1) @binding(0) var<storage, read> bake_parcels: array<Parcel>;
// The voxels' keys, all levels one after the other, in two buffers: the
// first KEY_SPLIT keys, then the rest (one binding may hold at most
// 128 MiB on many devices, 2²⁵ keys; the field holds up to 2²⁶ voxels).
@group(1) @binding(1) var<storage, read_write> voxel_keys: array<atomic<u32>>;
@group(1) @binding(5) var<storage, read_write> voxel_keys_hi: array<atomic<u32>>;
@group(1) @binding(2) var<storage, read_write> occupancy_bits: array<atomic<u32>>;
@group(1) @binding(3) var field_out: texture_storage_3d<rgba16float, write>;
@group(1) @binding(4) var light_out: texture_storage_3d<rgba16float, write>;

// Light-march step of `light`, in voxels: two voxels (half a coarse cell)
// resolve a cloud's body; the noise detail near each sample is added by
// the view march's own short light march (lighting.wgsl).
const LIGHT_STEP_VOXELS: f32 = 2.0;
// Most steps of one light march (a 40 km landscape at low sun: ~60 km at
// 2 × 84 m is ~360 steps); the rest of a longer path is left out.
const LIGHT_MAX_STEPS: u32 = 1024u;

// Workgroups per dispatch row of `splat`: SPLAT_ROW of
// src/methods/raymarch/baked.rs (a test compares them).
const SPLAT_ROW: u32 = 32768u;

// Keys in the first buffer: KEY_SPLIT of src/methods/raymarch/baked.rs (a
// test compares them).
const KEY_SPLIT: u32 = 33554432u;

fn key_load(i: u32) -> u32 {
    if i < KEY_SPLIT {
        return atomicLoad(&voxel_keys[i]);
    }
    return atomicLoad(&voxel_keys_hi[i - KEY_SPLIT]);
}

fn key_max(i: u32, key: u32) {
    if i < KEY_SPLIT {
        atomicMax(&voxel_keys[i], key);
    } else {
        atomicMax(&voxel_keys_hi[i - KEY_SPLIT], key);
    }
}

// The key, zeroed for the next bake.
fn key_take(i: u32) -> u32 {
    if i < KEY_SPLIT {
        return atomicExchange(&voxel_keys[i], 0u);
    }
    return atomicExchange(&voxel_keys_hi[i - KEY_SPLIT], 0u);
}

fn voxel_index(v: vec3<u32>, dims: vec3<u32>) -> u32 {
    return v.x + dims.x * (v.y + dims.y * v.z);
}

// The key of value v at `above` metres above the parcel's plane (0: v
// rounds to −1, nothing).
fn voxel_key(v: f32, above: f32) -> u32 {
    let qv = u32(round(0.5 * (v + 1.0) * KEY_LEVELS));
    if qv == 0u {
        return 0u;
    }
    let a = clamp(above, -PLANE_RANGE_M, PLANE_RANGE_M);
    let qa = u32(round((a + PLANE_RANGE_M) / (2.0 * PLANE_RANGE_M) * KEY_LEVELS));
    return (qv << 16u) | qa;
}

fn key_value(key: u32) -> f32 {
    return f32(key >> 16u) / KEY_LEVELS * 2.0 - 1.0;
}

fn key_above(key: u32) -> f32 {
    return f32(key & 0xffffu) / KEY_LEVELS * 2.0 * PLANE_RANGE_M - PLANE_RANGE_M;
}


// The level whose cells along the stacked volumes' z hold cell slice z;
// clip.count.x when none does.
fn stacked_level(z: u32) -> u32 {
    let n = clip.count.x;
    for (var l = 0u; l < n; l++) {
        let c = clip.levels[l].cells;
        if z >= c.w && z < c.w + c.z {
            return l;
        }
    }
    return n;
}

fn voxel_centre(l: u32, v: vec3<u32>) -> vec3<f32> {
    return clip.levels[l].min_voxel.xyz + (vec3<f32>(v) + 0.5) * clip_voxel_m(l);
}

@compute @workgroup_size(64)
fn splat(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let w = wg.x + SPLAT_ROW * wg.y;
    let l = wg.z;
    if w >= frame.parcel_count || l >= clip.count.x {
        return;
    }
    let q = bake_parcels[w];
    let shell = frame.shell_m;
    let h = clip_voxel_m(l);
    let origin = clip.levels[l].min_voxel.xyz;
    let dims = clip_dims(l);
    // v > −1 only inside the sphere's shell and above the plane's shell.
    let reach = q.radius_m + shell;
    var lo = q.center_m - vec3<f32>(reach);
    let hi = q.center_m + vec3<f32>(reach);
    lo.z = min(max(lo.z, q.plane_z_m - PLANE_SHELL * shell), hi.z);
    let first = vec3<i32>(floor((lo - origin) / h - 0.5));
    let last = vec3<i32>(ceil((hi - origin) / h - 0.5));
    // The parcel misses this level (a camera-centred level is cut from
    // the box).
    if any(last < vec3<i32>(0)) || any(first >= vec3<i32>(dims)) {
        return;
    }
    let a = vec3<u32>(clamp(first, vec3<i32>(0), vec3<i32>(dims) - 1));
    let b = vec3<u32>(clamp(last, vec3<i32>(0), vec3<i32>(dims) - 1));
    let n = b - a + 1u;
    let count = n.x * n.y * n.z;
    let keys0 = clip.levels[l].offsets.y;
    for (var j = li; j < count; j += 64u) {
        let v = a + vec3<u32>(j % n.x, (j / n.x) % n.y, j / (n.x * n.y));
        let c = voxel_centre(l, v);
        let key = voxel_key(parcel_value(q, c, shell), c.z - q.plane_z_m);
        let idx = keys0 + voxel_index(v, dims);
        // Keys only grow: a read that already holds as much spares the
        // atomic (a stale smaller read just folds).
        if key != 0u && key > key_load(idx) {
            key_max(idx, key);
        }
    }
}

// The finest level whose voxels hold p (nearest voxel, no filtering);
// clip.count.x outside them all.
fn splatted_level(p: vec3<f32>) -> u32 {
    let n = clip.count.x;
    for (var l = 0u; l < n; l++) {
        let rel = clip_rel(l, p);
        if all(rel >= vec3<f32>(0.0)) && all(rel < vec3<f32>(clip_dims(l))) {
            return l;
        }
    }
    return n;
}

// Parcels-only density ρ = smoothstep(0, 1, v) of level l's voxel holding
// p, from the splat's accumulators (coarse_density of density.wgsl, before
// the texture exists); 0 outside every level.
fn splatted_density(l: u32, p: vec3<f32>) -> f32 {
    if l >= clip.count.x {
        return 0.0;
    }
    let v = vec3<u32>(clip_rel(l, p));
    let key = key_load(clip.levels[l].offsets.y + voxel_index(v, clip_dims(l)));
    if key == 0u {
        return 0.0;
    }
    return smoothstep(0.0, 1.0, key_value(key));
}

// ∫ ρ ds from p along unit `dir` to the whole box's edge (density × m),
// in steps of LIGHT_STEP_VOXELS voxels of the level each step is in.
fn splatted_depth(p: vec3<f32>, dir: vec3<f32>) -> f32 {
    let top = clip.count.x - 1u;
    let box_min = clip.levels[top].min_voxel.xyz;
    let box_max = box_min + vec3<f32>(clip_dims(top)) * clip_voxel_m(top);
    let exit = ray_box(p, dir, box_min, box_max).y;
    var od = 0.0;
    var t = 0.5 * LIGHT_STEP_VOXELS * clip_voxel_m(min(splatted_level(p), top));
    for (var i = 0u; i < LIGHT_MAX_STEPS && t < exit; i++) {
        let q = p + dir * t;
        let l = splatted_level(q);
        let ds = LIGHT_STEP_VOXELS * clip_voxel_m(min(l, top));
        od += splatted_density(l, q) * ds;
        t += ds;
    }
    return od;
}

@compute @workgroup_size(4, 4, 4)
fn light(@builtin(global_invocation_id) gid: vec3<u32>) {
    let l = stacked_level(gid.z);
    if l >= clip.count.x {
        return;
    }
    let cells = clip.levels[l].cells;
    let local = gid - vec3<u32>(0u, 0u, cells.w);
    if any(local >= cells.xyz) {
        return;
    }
    let cell_m = clip_voxel_m(l) * f32(BAKE_BLOCK);
    let centre = clip.levels[l].min_voxel.xyz + (vec3<f32>(local) + 0.5) * cell_m;
    let sun = splatted_depth(centre, frame.sun_dir);
    let up = splatted_depth(centre, vec3<f32>(0.0, 0.0, 1.0));
    let behind = splatted_depth(centre, -frame.sun_dir);
    textureStore(light_out, gid, vec4<f32>(sun, up, behind, 0.0));
}

@compute @workgroup_size(4, 4, 4)
fn resolve(@builtin(global_invocation_id) gid: vec3<u32>) {
    let l = stacked_level(gid.z / BAKE_BLOCK);
    if l >= clip.count.x {
        return;
    }
    let dims = clip_dims(l);
    let v = gid - vec3<u32>(0u, 0u, clip.levels[l].cells.w * BAKE_BLOCK);
    if any(v >= dims) {
        return;
    }
    let key = key_take(clip.levels[l].offsets.y + voxel_index(v, dims));
    // No parcel reaches the voxel: v = −1 and its own height as the plane,
    // as the exact field gives.
    var value = -1.0;
    var plane = voxel_centre(l, v).z;
    if key != 0u {
        value = key_value(key);
        plane -= key_above(key);
    }
    textureStore(field_out, gid, vec4<f32>(value, plane, 0.0, 0.0));
    if key == 0u {
        return;
    }
    // The occupancy holds the bit pattern of v + 1 (> 0 here, so bit order
    // is value order; 0 = nothing).
    let bits = bitcast<u32>(value + 1.0);
    // A trilinear fetch within one voxel of this one's centre can see it.
    let cells = clip.levels[l].cells.xyz;
    let c0 = (max(v, vec3<u32>(1u)) - 1u) / BAKE_BLOCK;
    let c1 = min((v + 1u) / BAKE_BLOCK, cells - 1u);
    for (var z = c0.z; z <= c1.z; z++) {
        for (var y = c0.y; y <= c1.y; y++) {
            for (var x = c0.x; x <= c1.x; x++) {
                atomicMax(&occupancy_bits[occupancy_index(l, vec3<u32>(x, y, z), 0u)], bits);
            }
        }
    }
}

// Slices along z that pyramid level `p` takes per clip level in the
// dispatch of `pyramid1`/`pyramid2`: the deepest level's, rounded up to a
// workgroup (baked.rs `pyramid_dispatch` sizes it the same way).
fn pyramid_slices(p: u32) -> u32 {
    var z = 1u;
    for (var c = 0u; c < clip.count.x; c++) {
        z = max(z, occupancy_dims(c, p).z);
    }
    return (z + 3u) / 4u * 4u;
}

// 4. `pyramid1`, then `pyramid2`, one thread per cell of that pyramid
//    level of every clip level (occupancy.wgsl; the clip levels one after
//    the other along z, pyramid_slices each): the max of its
//    OCCUPANCY_FACTOR³ cells of the level below, written once (the atomics
//    of every voxel into a few upper cells would contend).
fn build_level(gid: vec3<u32>, l: u32) {
    let slices = pyramid_slices(l);
    let c = gid.z / slices;
    if c >= clip.count.x {
        return;
    }
    let cell = vec3<u32>(gid.xy, gid.z % slices);
    if any(cell >= occupancy_dims(c, l)) {
        return;
    }
    let below = occupancy_dims(c, l - 1u);
    var scale = 1u;
    for (var i = 1u; i < l; i++) {
        scale *= OCCUPANCY_FACTOR;
    }
    let first = cell * OCCUPANCY_FACTOR;
    let last = min(first + OCCUPANCY_FACTOR, below) - 1u;
    var bits = 0u;
    for (var z = first.z; z <= last.z; z++) {
        for (var y = first.y; y <= last.y; y++) {
            for (var x = first.x; x <= last.x; x++) {
                // Level l − 1 cell (x, y, z): level-0 cell (x, y, z)·scale.
                let idx = occupancy_index(c, vec3<u32>(x, y, z) * scale, l - 1u);
                bits = max(bits, atomicLoad(&occupancy_bits[idx]));
            }
        }
    }
    atomicStore(&occupancy_bits[occupancy_index(c, cell * scale * OCCUPANCY_FACTOR, l)], bits);
}

@compute @workgroup_size(4, 4, 4)
fn pyramid1(@builtin(global_invocation_id) gid: vec3<u32>) {
    build_level(gid, 1u);
}

@compute @workgroup_size(4, 4, 4)
fn pyramid2(@builtin(global_invocation_id) gid: vec3<u32>) {
    build_level(gid, 2u);
}
