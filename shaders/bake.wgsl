// Bake of the `baked` method's macro field (compute): M(P) = max over
// parcels of f·(d(P)+1) − 1 (parcel.wgsl) on a voxel grid over the region
// of the condensed parcels, then a coarse occupancy grid for empty-space
// skipping. src/render/raymarch/baked.rs drives it; field_baked.wgsl reads
// the result. The frame's grid is the coarse grid: BAKE_BLOCK³ voxels a
// cell, voxel side grid_cell / BAKE_BLOCK, origin grid_min.
//
// 1. `splat`, one dispatch per chunk of ≤ MAX_PARCELS parcels (a uniform
//    buffer bound at the chunk's dynamic offset): workgroup w takes parcel w
//    of the chunk (every thread reads the same parcel: the broadcast access
//    uniform buffers are made for) and its threads walk the voxels of the
//    parcel's bounding box, folding v into the voxel with an atomic max on
//    the bit pattern of v + 1 (≥ 0, so bit order is value order; 0 = none),
//    and the parcel's condensation plane with an atomic min (as a max of
//    the complemented bit pattern of plane + PLANE_OFFSET_M; 0 = none).
//    Cost ∝ parcels × voxels each, not pixels × parcels.
// 2. `light`, one thread per coarse cell: the light volume. From the
//    cell's centre it marches toward the sun, straight up and away from the
//    sun, through the splatted macro field (parcels only, no noise) to the
//    region's edge and stores the three optical depths (density × m; ×
//    extinction gives the exponent) in the R, G and B of its texel of
//    `light_out`, a 3D texture of
//    one texel per coarse cell that the march samples with the filtering
//    sampler (hardware trilinear between the cells' centres). Over the
//    region's whole height: a tower's top shadows its base and its
//    neighbours, and a base sees little sky.
// 3. `resolve`, one thread per voxel: writes (v, plane) into the field
//    texture, folds v into the coarse cells whose trilinear footprint holds
//    the voxel (so a cell's value bounds every filtered fetch in it), and
//    zeroes the voxel's accumulators for the next bake. (It used to also
//    upsample the light volume into the field's B and A, 8 storage reads a
//    voxel: most of the bake's time.)

// Keep in sync with BAKE_BLOCK in src/render/raymarch/baked.rs.
const BAKE_BLOCK: u32 = 4u;
// Shifts condensation planes (m) to positive floats so their bits order
// like their values (planes lie far above −PLANE_OFFSET_M).
const PLANE_OFFSET_M: f32 = 100000.0;

struct Chunk {
    p: array<Parcel, MAX_PARCELS>,
}

@group(1) @binding(0) var<uniform> chunk: Chunk;
@group(1) @binding(1) var<storage, read_write> value_bits: array<atomic<u32>>;
@group(1) @binding(2) var<storage, read_write> plane_bits: array<atomic<u32>>;
@group(1) @binding(3) var<storage, read_write> occupancy_bits: array<atomic<u32>>;
@group(1) @binding(4) var field_out: texture_storage_3d<rgba16float, write>;
@group(1) @binding(5) var light_out: texture_storage_3d<rgba16float, write>;

// Light-march step of `light`, in voxels: two voxels (half a coarse cell)
// resolve a cloud's body; the noise detail near each sample is added by
// the view march's own short light march (lighting.wgsl).
const LIGHT_STEP_VOXELS: f32 = 2.0;
// Most steps of one light march (a 40 km landscape at low sun: ~60 km at
// 2 × 84 m is ~360 steps); the rest of a longer path is left out.
const LIGHT_MAX_STEPS: u32 = 1024u;

fn voxel_m() -> f32 {
    return frame.grid_cell.x / f32(BAKE_BLOCK);
}

fn voxel_dims() -> vec3<u32> {
    return frame.grid_dims.xyz * BAKE_BLOCK;
}

fn voxel_index(v: vec3<u32>, dims: vec3<u32>) -> u32 {
    return v.x + dims.x * (v.y + dims.y * v.z);
}

fn voxel_centre(v: vec3<u32>) -> vec3<f32> {
    return frame.grid_min.xyz + (vec3<f32>(v) + 0.5) * voxel_m();
}

@compute @workgroup_size(64)
fn splat(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let q = chunk.p[wg.x];
    let shell = frame.cloud.y;
    let h = voxel_m();
    let dims = voxel_dims();
    // v > −1 only inside the sphere's shell and above the plane's shell.
    let reach = q.center_radius.w + shell;
    var lo = q.center_radius.xyz - vec3<f32>(reach);
    let hi = q.center_radius.xyz + vec3<f32>(reach);
    lo.z = min(max(lo.z, q.fill_plane.y - PLANE_SHELL * shell), hi.z);
    let first = vec3<i32>(floor((lo - frame.grid_min.xyz) / h - 0.5));
    let last = vec3<i32>(ceil((hi - frame.grid_min.xyz) / h - 0.5));
    let a = vec3<u32>(clamp(first, vec3<i32>(0), vec3<i32>(dims) - 1));
    let b = vec3<u32>(clamp(last, vec3<i32>(0), vec3<i32>(dims) - 1));
    let n = b - a + 1u;
    let count = n.x * n.y * n.z;
    let plane_key = ~bitcast<u32>(q.fill_plane.y + PLANE_OFFSET_M);
    for (var j = li; j < count; j += 64u) {
        let v = a + vec3<u32>(j % n.x, (j / n.x) % n.y, j / (n.x * n.y));
        let value = parcel_value(q, voxel_centre(v), shell);
        if value > -1.0 {
            let idx = voxel_index(v, dims);
            atomicMax(&value_bits[idx], bitcast<u32>(value + 1.0));
            atomicMax(&plane_bits[idx], plane_key);
        }
    }
}

// Parcels-only density ρ = smoothstep(0, 1, v) of the voxel holding p, from
// the splat's accumulators (coarse_density of density.wgsl, before the
// texture exists); 0 outside the region.
fn splatted_density(p: vec3<f32>) -> f32 {
    let dims = voxel_dims();
    let rel = (p - frame.grid_min.xyz) / voxel_m();
    if any(rel < vec3<f32>(0.0)) || any(rel >= vec3<f32>(dims)) {
        return 0.0;
    }
    let bits = atomicLoad(&value_bits[voxel_index(vec3<u32>(rel), dims)]);
    if bits == 0u {
        return 0.0;
    }
    return smoothstep(0.0, 1.0, bitcast<f32>(bits) - 1.0);
}

// ∫ ρ ds from p along unit `dir` to the region's edge (density × m).
fn splatted_depth(p: vec3<f32>, dir: vec3<f32>) -> f32 {
    let region_max = frame.grid_min.xyz + frame.grid_cell.xyz * vec3<f32>(frame.grid_dims.xyz);
    let exit = ray_box(p, dir, frame.grid_min.xyz, region_max).y;
    let ds = LIGHT_STEP_VOXELS * voxel_m();
    var od = 0.0;
    var t = 0.5 * ds;
    for (var i = 0u; i < LIGHT_MAX_STEPS && t < exit; i++) {
        od += splatted_density(p + dir * t) * ds;
        t += ds;
    }
    return od;
}

@compute @workgroup_size(4, 4, 4)
fn light(@builtin(global_invocation_id) gid: vec3<u32>) {
    let cells = frame.grid_dims.xyz;
    if any(gid >= cells) {
        return;
    }
    let centre = frame.grid_min.xyz + (vec3<f32>(gid) + 0.5) * frame.grid_cell.xyz;
    let sun = splatted_depth(centre, frame.sun_dir.xyz);
    let up = splatted_depth(centre, vec3<f32>(0.0, 0.0, 1.0));
    let behind = splatted_depth(centre, -frame.sun_dir.xyz);
    textureStore(light_out, gid, vec4<f32>(sun, up, behind, 0.0));
}

@compute @workgroup_size(4, 4, 4)
fn resolve(@builtin(global_invocation_id) gid: vec3<u32>) {
    let dims = voxel_dims();
    if any(gid >= dims) {
        return;
    }
    let idx = voxel_index(gid, dims);
    let bits = atomicExchange(&value_bits[idx], 0u);
    let plane_key = atomicExchange(&plane_bits[idx], 0u);
    let value = select(-1.0, bitcast<f32>(bits) - 1.0, bits != 0u);
    // No parcel reaches the voxel: its own height, as the exact field gives.
    var plane = voxel_centre(gid).z;
    if plane_key != 0u {
        plane = bitcast<f32>(~plane_key) - PLANE_OFFSET_M;
    }
    textureStore(field_out, gid, vec4<f32>(value, plane, 0.0, 0.0));
    if bits == 0u {
        return;
    }
    // A trilinear fetch within one voxel of this one's centre can see it.
    let cells = frame.grid_dims.xyz;
    let c0 = (max(gid, vec3<u32>(1u)) - 1u) / BAKE_BLOCK;
    let c1 = min((gid + 1u) / BAKE_BLOCK, cells - 1u);
    for (var z = c0.z; z <= c1.z; z++) {
        for (var y = c0.y; y <= c1.y; y++) {
            for (var x = c0.x; x <= c1.x; x++) {
                atomicMax(&occupancy_bits[x + cells.x * (y + cells.y * z)], bits);
            }
        }
    }
}
