// Cloud-shadow pass (paper §7): for each texel of a 2D map covering, on the
// ground plane z = 0, the rectangle whose sun rays can meet the cloud grid's
// box (frame.shadow_min and shadow_max, set in src/render/renderer/draw.rs),
// march toward the sun through the cloud layer's box and store the sun's
// transmittance exp(−∫σ ds): `ground_sun_depth` of the method's
// `<ground_shadow>` slot (the method's Slots), the ray-marching methods'
// one routine (raymarch/density.wgsl, the parcels of their field) or the
// slices' implicit field (slices/shadow_field.wgsl). The terrain looks it
// up where its own sun ray meets z = 0, so hills (a few hundred metres)
// under clouds (1–3 km) get the right shadow. Texel row 0 is the
// rectangle's north edge (max y), like an image.

#import "common.wgsl"
#import <ground_shadow>

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> FullscreenOut {
    return fullscreen_vertex(i);
}

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    let lo = frame.shadow_min;
    let hi = frame.shadow_max;
    let uv = vec2<f32>(0.5 + 0.5 * in.ndc.x, 0.5 - 0.5 * in.ndc.y);
    let ground = vec3<f32>(lo.x + uv.x * (hi.x - lo.x), hi.y - uv.y * (hi.y - lo.y), 0.0);
    return vec4<f32>(exp(-ground_sun_depth(ground) * frame.extinction_per_m));
}
