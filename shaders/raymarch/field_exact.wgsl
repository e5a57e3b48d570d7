// Macro field of the `exact` method (the paper's path, §6.2): the union
// over parcels of parcel_value (parcel.wgsl), evaluated per sample from the
// parcels listed in the sample's cell of the CPU-built grid (uniform
// buffers). Cost per sample ∝ the cell's list length. One of the two files
// bound to the `<field>` slot (src/methods/raymarch/passes.rs); the other,
// field_baked.wgsl, reads the same functions from a baked texture:
//   field_value(p)          v(P) ∈ [−1, 1]
//   field_sample(p)         (v(P), condensation plane under P (m))
//   empty_skip(p, rd)       > 0: distance along rd over which v + k/2 ≤ 0
//                           (no density can appear); 0: p may be cloudy.
// The method's far light (the `<far_light>` slot) is far_light_exact.wgsl.

#import "../common.wgsl"
#import "parcel.wgsl"

// Sizes of the grid's arrays: MAX_GRID_CELLS / 2 and MAX_GRID_ENTRIES / 4
// of src/methods/raymarch/pack.rs (a test compares them).
const GRID_CELL_PAIRS: u32 = 1024u;
const GRID_ENTRY_QUADS: u32 = 2048u;

// cells[i / 2]: (start, count) of cell i in .xy (even i) or .zw (odd i);
// entries[j / 4][j % 4]: the j-th parcel index of all cell lists.
struct Grid {
    cells: array<vec4<u32>, GRID_CELL_PAIRS>,
    entries: array<vec4<u32>, GRID_ENTRY_QUADS>,
}

// The `exact` method's field (group 3 of the passes that import it).
@group(3) @binding(0) var<uniform> parcels: Parcels;
@group(3) @binding(1) var<uniform> grid: Grid;

// Evaluate only the parcels listed in the sample's grid cell (paper §6.2).
// false: every parcel at every sample (brute force, for the bench).
override GRID_CULLING: bool = true;

// (start, count) of the parcel list of the grid cell holding p; count 0
// outside the grid. No parcel's density reaches a cell with an empty list.
fn cell_list(p: vec3<f32>) -> vec2<u32> {
    if !GRID_CULLING {
        return vec2<u32>(0u, frame.parcel_count);
    }
    let dims = frame.grid_dims;
    let rel = (p - frame.grid_min) / frame.grid_cell;
    if any(rel < vec3<f32>(0.0)) || any(rel >= vec3<f32>(dims)) {
        return vec2<u32>(0u);
    }
    let ci = vec3<u32>(rel);
    let cell = ci.x + dims.x * (ci.y + dims.y * ci.z);
    let pair = grid.cells[cell / 2u];
    if (cell & 1u) == 1u {
        return pair.zw;
    }
    return pair.xy;
}

// Parcel index of the j-th entry of a list (brute force: j itself).
fn list_parcel(j: u32) -> u32 {
    if GRID_CULLING {
        return grid.entries[j / 4u][j % 4u];
    }
    return j;
}

fn field_value(p: vec3<f32>) -> f32 {
    let list = cell_list(p);
    let shell = frame.shell_m;
    var v = -1.0;
    for (var j = list.x; j < list.x + list.y; j++) {
        v = max(v, parcel_value(parcels.parcels[list_parcel(j)], p, shell));
        // The union saturates at 1 (paper): stop there.
        if v >= 1.0 {
            break;
        }
    }
    return v;
}

// Like field_value, plus (in .y) the condensation-plane height of the
// parcel that gives the value (the lowest plane among saturated ones), so
// the lighting knows how far above its base a sample lies. units: -, m
fn field_sample(p: vec3<f32>) -> vec2<f32> {
    let list = cell_list(p);
    let shell = frame.shell_m;
    var v = -1.0;
    var plane = p.z;
    for (var j = list.x; j < list.x + list.y; j++) {
        let q = parcels.parcels[list_parcel(j)];
        let vi = parcel_value(q, p, shell);
        if vi > v || (vi >= 1.0 && q.plane_z_m < plane) {
            plane = q.plane_z_m;
        }
        v = max(v, vi);
    }
    return vec2<f32>(v, plane);
}

// Empty cells (no parcel listed) are skipped whole.
fn empty_skip(p: vec3<f32>, rd: vec3<f32>) -> f32 {
    if !GRID_CULLING || cell_list(p).y > 0u {
        return 0.0;
    }
    let ci = floor((p - frame.grid_min) / frame.grid_cell);
    let lo = frame.grid_min + ci * frame.grid_cell;
    return max(ray_box(p, rd, lo, lo + frame.grid_cell).y, 1e-3);
}
