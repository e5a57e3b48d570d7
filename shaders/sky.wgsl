// Sky pass: clears the target to a sky gradient with a sun disc. Always
// runs; the terrain and clouds draw over it.

#import "common.wgsl"

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> FullscreenOut {
    return fullscreen_vertex(i);
}

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    let dir = view_dir(in.ndc);
    var c = sky_color(dir);
    let mu = dot(dir, frame.sun_dir);
    c += frame.sun_color * 6.0 * smoothstep(0.99985, 0.99995, mu);
    return vec4<f32>(output_color(c), 1.0);
}
