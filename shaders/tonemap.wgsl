// Tone-map pass: the one display transform of a frame. Reads the linear
// HDR scene target (sky, terrain and clouds composited in linear light)
// and writes tone_map() of it (common.wgsl) into the output, which is the
// window's surface or the headless target alike.

#import "common.wgsl"

@group(1) @binding(0) var scene_tex: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> FullscreenOut {
    return fullscreen_vertex(i);
}

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    let c = textureLoad(scene_tex, vec2<i32>(in.pos.xy), 0);
    return vec4<f32>(tone_map(c.rgb), 1.0);
}
