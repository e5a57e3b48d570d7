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
// rectangle's north edge (max y), like an image. Two entry points: a
// full-screen fragment shader (`fs_main`), and a compute shader
// (`cs_main`) writing the map as a storage texture, which the renderer
// uses wherever the adapter runs compute.

#import "common.wgsl"
#import <ground_shadow>

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> FullscreenOut {
    return fullscreen_vertex(i);
}

// The sun's transmittance at the ground point of map coordinates `uv`
// ((0, 0) the north-west corner, (1, 1) the south-east).
fn shadow_at(uv: vec2<f32>) -> f32 {
    let lo = frame.shadow_min;
    let hi = frame.shadow_max;
    let ground = vec3<f32>(lo.x + uv.x * (hi.x - lo.x), hi.y - uv.y * (hi.y - lo.y), 0.0);
    return exp(-ground_sun_depth(ground) * frame.extinction_per_m);
}

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    return vec4<f32>(shadow_at(vec2<f32>(0.5 + 0.5 * in.ndc.x, 0.5 - 0.5 * in.ndc.y)));
}

// Compute path (where the adapter runs compute): the same routine per
// texel at the texel's centre, the rasteriser's sample point.
@group(2) @binding(0) var shadow_out: texture_storage_2d<rgba8unorm, write>;

@compute @workgroup_size(8, 8)
fn cs_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(shadow_out);
    if any(gid.xy >= size) {
        return;
    }
    let uv = (vec2<f32>(gid.xy) + 0.5) / vec2<f32>(size);
    textureStore(shadow_out, gid.xy, vec4<f32>(shadow_at(uv)));
}
