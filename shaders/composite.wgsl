// Composite of the clouds drawn into a texture of their own (the compute
// march of raymarch/clouds.wgsl, the temporal resolve, the slicing planes):
// blends it (premultiplied colour, alpha = 1 − transmittance) over the
// sky/terrain with (ONE, ONE_MINUS_SRC_ALPHA), as the fragment path's
// cloud pass does.

#import "common.wgsl"

@group(1) @binding(0) var cloud_tex: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> FullscreenOut {
    return fullscreen_vertex(i);
}

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    return textureLoad(cloud_tex, vec2<i32>(in.pos.xy), 0);
}
