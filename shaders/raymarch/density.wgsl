// Cloud density (paper eq. 18) from the macro field of the scene's method
// (the `<field>` slot: field_exact.wgsl or field_baked.wgsl, both giving
// v ∈ [−1, 1]):
//     ρ(P) = smoothstep(0, 1, v(P) + k·noise(P)),
// with noise(P) ∈ [−0.5, 0.5] tiling fBm and k the noise amplitude: smoothstep
// has edges 0 and 1, so a full parcel (f = 1) is opaque one shell inside its
// surface, its edge is noise-eroded over about k/2 shells, and a parcel with
// f < 1 never reaches full density and turns sponge-like as f drops. Below
// the plane d rises at most to −k/2 before ρ vanishes: the base is flat to
// within k/2 · PLANE_SHELL · shell. Also the ray-marching methods' file of
// the `<ground_shadow>` slot (shadow.wgsl): `ground_sun_depth`, below.

#import "../common.wgsl"
#import "parcel.wgsl"
#import <field>

// ρ from a macro value v at p.
fn density_from(v: f32, p: vec3<f32>) -> f32 {
    let k = frame.noise_amplitude;
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

// Optical depth ∫ρ ds of the parcels alone (no noise; density × m) from p
// along unit `dir` to the cloud region's (the frame grid's box) edge, at
// a fixed step `ds` (m), samples at the step centres counted from p. Empty
// cells (`empty_skip`) are crossed in one jump to the next sample on the
// same lattice, so the skip leaves out only samples where no density can
// be. The step is fixed in metres, not a share of the box, so the samples
// do not move with the box's size.
const FAR_LIGHT_MAX_STEPS: u32 = 256u;

fn far_depth_along(p: vec3<f32>, dir: vec3<f32>, ds: f32) -> f32 {
    let box_max = frame.grid_min + frame.grid_cell * vec3<f32>(frame.grid_dims);
    let span = ray_box(p, dir, frame.grid_min, box_max);
    // First sample at or past the box's entry, on the lattice (k + ½)·ds.
    var k = max(ceil(max(span.x, 0.0) / ds - 0.5), 0.0);
    var od = 0.0;
    for (var i = 0u; i < FAR_LIGHT_MAX_STEPS; i++) {
        let t = (k + 0.5) * ds;
        if t >= span.y {
            break;
        }
        let q = p + dir * t;
        let skip = empty_skip(q, dir);
        if skip > 0.0 {
            k = max(ceil((t + skip) / ds - 0.5), k + 1.0);
            continue;
        }
        od += coarse_density(q);
        k += 1.0;
    }
    return od * ds;
}

// The clouds' shadow on the ground, as an optical depth toward the sun
// from the ground point p: the parcels alone (the noise's detail is finer
// than a shadow's penumbra seen from afar, and the far light of the
// clouds themselves leaves it out too) at a step of one plane shell (one
// voxel of the baked field), by the same routine under both methods, so
// their ground shadows differ only as their fields do. shadow.wgsl stores
// it per texel of the shadow map; terrain.wgsl evaluates it per fragment
// for ground inside the cloud region.
fn ground_sun_depth(p: vec3<f32>) -> f32 {
    return far_depth_along(p, frame.sun_dir, PLANE_SHELL * frame.shell_m);
}
