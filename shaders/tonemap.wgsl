// Tone-map pass: the one display transform of a frame. Reads the linear
// HDR scene target (sky, terrain and clouds composited in linear light)
// and writes tone_map() of it (common.wgsl) into the output, which is the
// window's surface or the headless target alike.
// Under WITH_CLOUDS the frame has no composite pass: the method's cloud
// image (premultiplied, group 2) is blended over the scene here, as
// composite.wgsl's (ONE, ONE_MINUS_SRC_ALPHA) blend would have done into
// the target (src/render/renderer/passes.rs, `folds`). Else group 2 is the
// scene target again and is not read.

#import "common.wgsl"

override WITH_CLOUDS: bool = false;

@group(1) @binding(0) var scene_tex: texture_2d<f32>;
@group(2) @binding(0) var cloud_tex: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> FullscreenOut {
    return fullscreen_vertex(i);
}

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    let pix = vec2<i32>(in.pos.xy);
    var c = textureLoad(scene_tex, pix, 0).rgb;
    if WITH_CLOUDS {
        let cloud = textureLoad(cloud_tex, pix, 0);
        c = cloud.rgb + (1.0 - cloud.a) * c;
    }
    return vec4<f32>(tone_map(c), 1.0);
}
