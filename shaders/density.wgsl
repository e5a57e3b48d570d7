// Hypertextured parcels (paper §6.1, eq. 18), shared by clouds.wgsl and
// shadow.wgsl.
//
// Each condensed parcel i is a sphere (centre c_i, radius r_i) cut flat below
// by its condensation plane z = z_i, with filling ratio f_i. Its normalised
// pseudo-distance is
//     d_i(P) = clamp(min((r_i - |P - c_i|) / shell, (P.z - z_i) / (PLANE_SHELL · shell)), -1, 1)
// i.e. 0 on the sphere and on the plane, +1 at `shell` metres inside the
// sphere (PLANE_SHELL·shell above the plane), −1 as far outside (sphere ∩
// half-space above the plane, as the min of the two signed distances). The
// plane's shell is thinner than the sphere's so the noise erodes the domes
// deeply while the base stays flat, as cumulus bases are. The union over parcels takes the max of
//     v_i(P) = f_i·(d_i(P) + 1) − 1,
// which we may stop as soon as it saturates at 1 (paper). The density is
//     ρ(P) = smoothstep(0, 1, v(P) + k·noise(P)),
// with noise(P) ∈ [−0.5, 0.5] tiling fBm and k the noise amplitude: smoothstep
// has edges 0 and 1, so a full parcel (f = 1) is opaque one shell inside its
// surface, its edge is noise-eroded over about k/2 shells, and a parcel with
// f < 1 never reaches full density and turns sponge-like as f drops. Below
// the plane d rises at most to −k/2 before ρ vanishes: the base is flat to
// within k/2 · PLANE_SHELL · shell.

// Evaluate only the parcels listed in the sample's grid cell (paper §6.2).
// false: every parcel at every sample (brute force, for the bench).
override GRID_CULLING: bool = true;

// Plane shell thickness relative to the sphere's shell.
const PLANE_SHELL: f32 = 0.3;

fn parcel_value(i: u32, p: vec3<f32>) -> f32 {
    let q = parcels.p[i];
    let shell = frame.cloud.y;
    let d_sphere = (q.center_radius.w - distance(p, q.center_radius.xyz)) / shell;
    let d_plane = (p.z - q.fill_plane.y) / (PLANE_SHELL * shell);
    let d = clamp(min(d_sphere, d_plane), -1.0, 1.0);
    return q.fill_plane.x * (d + 1.0) - 1.0;
}

// (start, count) of the parcel list of the grid cell holding p; count 0
// outside the grid. No parcel's density reaches a cell with an empty list.
fn cell_list(p: vec3<f32>) -> vec2<u32> {
    let dims = frame.grid_dims.xyz;
    let rel = (p - frame.grid_min.xyz) / frame.grid_cell.xyz;
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

// Distance along rd from p (inside the grid) to where the ray leaves p's cell.
fn cell_exit(p: vec3<f32>, rd: vec3<f32>) -> f32 {
    let ci = floor((p - frame.grid_min.xyz) / frame.grid_cell.xyz);
    let lo = frame.grid_min.xyz + ci * frame.grid_cell.xyz;
    return max(ray_box(p, rd, lo, lo + frame.grid_cell.xyz).y, 0.0);
}

// Union over parcels of f·(d + 1) − 1, in [−1, 1]; −1 far from every parcel.
fn macro_value(p: vec3<f32>) -> f32 {
    var v = -1.0;
    if GRID_CULLING {
        let list = cell_list(p);
        let start = list.x;
        let count = list.y;
        for (var j = start; j < start + count; j++) {
            v = max(v, parcel_value(grid.entries[j / 4u][j % 4u], p));
            if v >= 1.0 {
                break;
            }
        }
    } else {
        for (var i = 0u; i < frame.grid_dims.w; i++) {
            v = max(v, parcel_value(i, p));
            if v >= 1.0 {
                break;
            }
        }
    }
    return v;
}

// Like macro_value, plus (in .y) the condensation-plane height of the
// parcel that gives the value (the lowest plane among saturated ones), so
// the cloud pass knows how far above its base a sample lies. `list` is
// cell_list(p), which the caller has already looked up to skip empty cells
// (unused without GRID_CULLING). units: -, m
fn macro_value_plane(p: vec3<f32>, list: vec2<u32>) -> vec2<f32> {
    var v = -1.0;
    var plane = p.z;
    if GRID_CULLING {
        for (var j = list.x; j < list.x + list.y; j++) {
            let i = grid.entries[j / 4u][j % 4u];
            let vi = parcel_value(i, p);
            if vi > v || (vi >= 1.0 && parcels.p[i].fill_plane.y < plane) {
                plane = parcels.p[i].fill_plane.y;
            }
            v = max(v, vi);
        }
    } else {
        for (var i = 0u; i < frame.grid_dims.w; i++) {
            let vi = parcel_value(i, p);
            if vi > v || (vi >= 1.0 && parcels.p[i].fill_plane.y < plane) {
                plane = parcels.p[i].fill_plane.y;
            }
            v = max(v, vi);
        }
    }
    return vec2<f32>(v, plane);
}

// Cloud density ρ(P) ∈ [0, 1] (eq. 18).
fn cloud_density(p: vec3<f32>) -> f32 {
    let v = macro_value(p);
    let k = frame.cloud.x;
    // The noise adds at most k/2: skip the texture fetches where it cannot help.
    if v + 0.5 * k <= 0.0 {
        return 0.0;
    }
    return smoothstep(0.0, 1.0, v + k * noise3(p));
}
