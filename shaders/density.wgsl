// Cloud density (paper eq. 18) from the macro field of the scene's method
// (field_exact.wgsl or field_baked.wgsl, both giving v ∈ [−1, 1]):
//     ρ(P) = smoothstep(0, 1, v(P) + k·noise(P)),
// with noise(P) ∈ [−0.5, 0.5] tiling fBm and k the noise amplitude: smoothstep
// has edges 0 and 1, so a full parcel (f = 1) is opaque one shell inside its
// surface, its edge is noise-eroded over about k/2 shells, and a parcel with
// f < 1 never reaches full density and turns sponge-like as f drops. Below
// the plane d rises at most to −k/2 before ρ vanishes: the base is flat to
// within k/2 · PLANE_SHELL · shell.

// ρ from a macro value v at p.
fn density_from(v: f32, p: vec3<f32>) -> f32 {
    let k = frame.cloud.x;
    // The noise adds at most k/2: skip the texture fetches where it cannot help.
    if v + 0.5 * k <= 0.0 {
        return 0.0;
    }
    return smoothstep(0.0, 1.0, v + k * noise3(p));
}

// Cloud density ρ(P) ∈ [0, 1] (eq. 18).
fn cloud_density(p: vec3<f32>) -> f32 {
    return density_from(field_value(p), p);
}

// Density of the parcels alone (no noise: no texture fetches), for coarse
// looks (light march far steps, sky visibility).
fn coarse_density(p: vec3<f32>) -> f32 {
    return smoothstep(0.0, 1.0, field_value(p));
}
