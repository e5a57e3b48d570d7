// One hypertextured parcel (paper §6.1, the parcel part of eq. 18), shared
// by the exact field (field_exact.wgsl, per sample) and the bake
// (bake.wgsl, per voxel): the formula is written once, here.
//
// Each condensed parcel is a sphere (centre c, radius r) cut flat below by
// its condensation plane z = z_c, with filling ratio f. Its normalised
// pseudo-distance is
//     d(P) = clamp(min((r - |P - c|) / shell, (P.z - z_c) / (PLANE_SHELL · shell)), -1, 1)
// i.e. 0 on the sphere and on the plane, +1 at `shell` metres inside the
// sphere (PLANE_SHELL·shell above the plane), −1 as far outside (sphere ∩
// half-space above the plane, as the min of the two signed distances). The
// plane's shell is thinner than the sphere's so the noise erodes the domes
// deeply while the base stays flat, as cumulus bases are. The macro field
// is the union (max) over parcels of
//     v(P) = f·(d(P) + 1) − 1  ∈ [−1, 1],
// and density.wgsl turns it into the density ρ = smoothstep(0, 1, v + k·noise).

#import "../common.wgsl"

// Most parcels one uniform array holds: MAX_PARCELS of
// src/methods/raymarch/pack.rs (a test compares them).
const MAX_PARCELS: u32 = 1024u;

// One condensed parcel: a sphere cut flat below at its condensation plane:
// `GpuParcel` of src/methods/raymarch/pack.rs.
struct Parcel {
    center_m: vec3<f32>,
    radius_m: f32,
    fill: f32,      // filling ratio f
    plane_z_m: f32, // height of the condensation plane
    _pad: vec2<f32>,
}

struct Parcels {
    parcels: array<Parcel, MAX_PARCELS>,
}


// Plane shell thickness relative to the sphere's shell; PLANE_SHELL of
// src/methods/raymarch/field.rs and src/methods/raymarch/baked.rs (a test compares
// them).
const PLANE_SHELL: f32 = 0.3;

// f·(d + 1) − 1 of parcel q at p, for a shell of `shell` metres.
fn parcel_value(q: Parcel, p: vec3<f32>, shell: f32) -> f32 {
    let d_sphere = (q.radius_m - distance(p, q.center_m)) / shell;
    let d_plane = (p.z - q.plane_z_m) / (PLANE_SHELL * shell);
    let d = clamp(min(d_sphere, d_plane), -1.0, 1.0);
    return q.fill * (d + 1.0) - 1.0;
}
