// The `slices` method's file of the `<ground_shadow>` slot, for the
// cloud-shadow map (../shadow.wgsl): the field the slicing planes draw,
// Σ Wyvill blends of the authored ellipsoids and the parcels' spheres
// (flat at their condensation planes) × the media filter of the noise
// octaves (implicit.wgsl), scaled so that the map's
// exp(−ground_sun_depth · extinction) is the slices' optical depth along
// the sun ray (params.shadow_extinction_per_m, see SlicesParams::new in
// src/methods/slices/gpu/mod.rs).

#import "../common.wgsl"
#import "implicit.wgsl"

// The field as a density of the ray-march's scale (× extinction_per_m).
fn slices_density(p: vec3<f32>) -> f32 {
    let f = implicit_field(p);
    if f <= 0.0 {
        return 0.0;
    }
    return f * media_at(p) * params.shadow_extinction_per_m / frame.extinction_per_m;
}

// Slicing planes' shadow march: SHADOW_STEPS samples of slices_density
// from p toward the sun through the cloud layer's box (density × m, as
// the ray-march methods' ground_sun_depth in raymarch/density.wgsl).
const SHADOW_STEPS: u32 = 48u;

fn ground_sun_depth(p: vec3<f32>) -> f32 {
    let sun = frame.sun_dir;
    let grid_max = frame.grid_min + frame.grid_cell * vec3<f32>(frame.grid_dims);
    let span = ray_box(p, sun, frame.grid_min, grid_max);
    let t0 = max(span.x, 0.0);
    if span.y <= t0 {
        return 0.0;
    }
    let ds = (span.y - t0) / f32(SHADOW_STEPS);
    var od = 0.0;
    for (var i = 0u; i < SHADOW_STEPS; i++) {
        od += slices_density(p + sun * (t0 + ds * (f32(i) + 0.5)));
    }
    return od * ds;
}
