// Bake of the `baked` method's macro field (compute): M(P) = max over
// parcels of f·(d(P)+1) − 1 (parcel.wgsl) on a voxel grid over the region
// of the condensed parcels, then a coarse occupancy grid for empty-space
// skipping. src/render/raymarch/baked.rs drives it; field_baked.wgsl reads
// the result. The frame's grid is the coarse grid: BAKE_BLOCK³ voxels a
// cell (a brick), voxel side grid_cell / BAKE_BLOCK, origin grid_min.
//
// 1. `gather`, one workgroup per brick that a parcel touches (or that held
//    cloud at the last bake and must be emptied): the CPU bins the parcels
//    into the bricks their boxes (one voxel larger all round) overlap, and
//    the brick's 64 threads, one per voxel, fold v and the lowest
//    condensation plane over that brick's list only (every thread reads
//    the same parcel: broadcast). No atomics on the field, and bricks far
//    from every parcel cost nothing. Cost ∝ bricks touched × their list
//    length. Each voxel then folds v into the coarse cells whose trilinear
//    footprint holds it (so a cell's value bounds every filtered fetch in
//    it).
// 2. `clear`, one thread per voxel of the region: v = −1 everywhere, run
//    once when the field texture is (re)created; afterwards bricks no
//    parcel touches keep −1 because `gather` empties those it leaves.

// Keep in sync with BAKE_BLOCK in src/render/raymarch/baked.rs.
const BAKE_BLOCK: u32 = 4u;
// Dispatch width of `gather` (workgroups per row); keep in sync with
// GATHER_ROW in src/render/raymarch/baked.rs.
const GATHER_ROW: u32 = 32768u;

// The condensed parcels (all of them; the bricks' lists index it).
@group(1) @binding(0) var<storage, read> bake_parcels: array<Parcel>;
// The bricks' parcel lists, back to back.
@group(1) @binding(1) var<storage, read> lists: array<u32>;
// bricks[0].x: how many bricks follow; bricks[1 + i]: brick index, list
// start, list length, unused.
@group(1) @binding(2) var<storage, read> bricks: array<vec4<u32>>;
@group(1) @binding(3) var<storage, read_write> occupancy_bits: array<atomic<u32>>;
@group(1) @binding(4) var field_out: texture_storage_3d<rgba16float, write>;

fn voxel_m() -> f32 {
    return frame.grid_cell.x / f32(BAKE_BLOCK);
}

fn voxel_dims() -> vec3<u32> {
    return frame.grid_dims.xyz * BAKE_BLOCK;
}

fn voxel_centre(v: vec3<u32>) -> vec3<f32> {
    return frame.grid_min.xyz + (vec3<f32>(v) + 0.5) * voxel_m();
}

// Writes voxel `gid`'s (v, plane) and folds v into the occupancy.
fn store_voxel(gid: vec3<u32>, value: f32, plane: f32) {
    textureStore(field_out, gid, vec4<f32>(value, plane, 0.0, 0.0));
    if value <= -1.0 {
        return;
    }
    // Bit pattern of v + 1 (≥ 0, so bit order is value order; 0 = none).
    let bits = bitcast<u32>(value + 1.0);
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

@compute @workgroup_size(4, 4, 4)
fn gather(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    let r = wg.x + GATHER_ROW * wg.y;
    if r >= bricks[0].x {
        return;
    }
    let b = bricks[1u + r];
    let cells = frame.grid_dims.xyz;
    let brick = vec3<u32>(b.x % cells.x, (b.x / cells.x) % cells.y, b.x / (cells.x * cells.y));
    let gid = brick * BAKE_BLOCK + lid;
    let p = voxel_centre(gid);
    let shell = frame.cloud.y;
    var value = -1.0;
    // No parcel reaches the voxel: its own height, as the exact field gives.
    var plane = p.z;
    var reached = false;
    for (var j = b.y; j < b.y + b.z; j++) {
        let q = bake_parcels[lists[j]];
        let v = parcel_value(q, p, shell);
        if v > -1.0 {
            value = max(value, v);
            plane = select(q.fill_plane.y, min(plane, q.fill_plane.y), reached);
            reached = true;
        }
    }
    store_voxel(gid, value, plane);
}

@compute @workgroup_size(4, 4, 4)
fn clear(@builtin(global_invocation_id) gid: vec3<u32>) {
    if any(gid >= voxel_dims()) {
        return;
    }
    textureStore(field_out, gid, vec4<f32>(-1.0, voxel_centre(gid).z, 0.0, 0.0));
}
