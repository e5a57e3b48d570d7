// Temporal resolve (`[render] temporal`): builds the full-size cloud
// image of a frame from the quarter of its pixels that clouds.wgsl's
// cs_temporal marched (one per 2×2 block, the block offset stepping
// through a 2×2 Bayer order) and the previous frame's image.
//
// For each pixel: the cloud point it shows is the view ray at the cloud
// depth of its block's fresh sample (no cloud: a far point, so the sky
// moves with the camera's rotation); that point's pixel in the previous
// frame (prev_clip_from_world) is where its history is read, bilinearly.
// The history is clamped into the box (per channel min/max) of the fresh
// samples of the 3×3 blocks around the pixel: whatever the pixel showed
// before must look like what is around it now, so a cloud that moved
// away, or the inside of a cloud the camera flew out of, cannot linger
// (no ghosting); a clamp that moved the history far restarts its average.
// A pixel marched this frame averages its fresh sample into its history
// (weight 1/(n+1) for n accumulated samples, n ≤ MAX_SAMPLES): for a still
// camera and still clouds each pixel's average runs over the ray-start
// jitters of successive frames and converges to the full-resolution
// march. The others keep the clamped history, or take their block's
// fresh sample where there is none (first frame, off-screen before).
//
// Output: premultiplied linear radiance (as the cloud pass), composited by
// composite.wgsl; and per pixel the samples averaged into it: with the
// colour, the next frame's history.

#import "../common.wgsl"
#import "temporal_uniform.wgsl"

// Most frames averaged into a pixel: past this the history weighs
// (MAX_SAMPLES − 1)/MAX_SAMPLES, so the average still follows slow changes
// (clouds evolve) within ~MAX_SAMPLES marched frames (4× as many frames).
const MAX_SAMPLES: f32 = 16.0;
// Distance of the point a cloudless pixel is reprojected at. units: m
const FAR_M: f32 = 100000.0;
// A clamp that moves the history by more than this (in premultiplied
// alpha, or radiance relative to the box's largest channel) treats it as
// a different surface: its average restarts (the pixel's next marched
// sample replaces it; until then it shows the clamped value).
const REJECT: f32 = 0.1;

@group(1) @binding(0) var fresh_color: texture_2d<f32>;
@group(1) @binding(1) var fresh_depth: texture_2d<f32>;
@group(1) @binding(2) var history_color: texture_2d<f32>;
@group(1) @binding(3) var history_aux: texture_2d<f32>;
@group(1) @binding(4) var out_color: texture_storage_2d<rgba16float, write>;
@group(1) @binding(5) var out_aux: texture_storage_2d<r32float, write>;
@group(1) @binding(6) var<uniform> temporal: Temporal;

@compute @workgroup_size(8, 8)
fn cs_resolve(@builtin(global_invocation_id) gid: vec3<u32>) {
    let full = temporal.size;
    if any(gid.xy >= full) {
        return;
    }
    let quarter = vec2<i32>(temporal.quarter);
    let block = vec2<i32>(gid.xy / 2u);
    let fresh = textureLoad(fresh_color, block, 0);
    let depth = textureLoad(fresh_depth, block, 0).x;
    let marched = all(min(2u * (gid.xy / 2u) + temporal.offset, full - 1u) == gid.xy);

    // The box of the fresh samples around the pixel.
    var lo = fresh;
    var hi = fresh;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = clamp(block + vec2<i32>(dx, dy), vec2<i32>(0), quarter - 1);
            let c = textureLoad(fresh_color, q, 0);
            lo = min(lo, c);
            hi = max(hi, c);
        }
    }

    // Where this pixel's cloud point was in the previous frame.
    let pix = vec2<f32>(gid.xy) + 0.5;
    let ndc = vec2<f32>(2.0 * pix.x / f32(full.x) - 1.0, 1.0 - 2.0 * pix.y / f32(full.y));
    let ro = frame.camera_pos.eye_m;
    let point = ro + view_dir(ndc) * select(FAR_M, depth, depth > 0.0);
    let prev = temporal.prev_clip_from_world * vec4<f32>(point, 1.0);
    let prev_ndc = prev.xy / max(prev.w, 1e-6);
    let prev_uv = vec2<f32>(0.5 * prev_ndc.x + 0.5, 0.5 - 0.5 * prev_ndc.y);
    let on_screen = prev.w > 0.0 && all(prev_uv >= vec2<f32>(0.0)) && all(prev_uv <= vec2<f32>(1.0));
    let have_history = temporal.history_valid != 0u && on_screen;

    // Branch-free below: Mesa's lavapipe (22.3) crashes on this shader
    // with nested branches, and every lane does the same work anyway.
    let uv = clamp(prev_uv, vec2<f32>(0.0), vec2<f32>(1.0));
    let h = textureSampleLevel(history_color, clamp_sampler, uv, 0.0);
    let prev_pix = min(vec2<u32>(uv * vec2<f32>(full)), full - 1u);
    let clamped = clamp(h, lo, hi);
    let moved = abs(clamped - h);
    let scale = max(max(hi.r, max(hi.g, hi.b)), 1e-3);
    let rejected = moved.a > REJECT || max(moved.r, max(moved.g, moved.b)) > REJECT * scale;
    // Samples in the history: none without one (then the block's fresh
    // sample stands in, and the pixel's first own sample replaces it).
    var n = select(0.0, textureLoad(history_aux, vec2<i32>(prev_pix), 0).x, have_history);
    n = select(n, 0.0, rejected);
    let past = select(fresh, clamped, have_history);
    let n_kept = min(n, MAX_SAMPLES - 1.0);
    let color = select(past, mix(past, fresh, 1.0 / (n_kept + 1.0)), marched);
    let samples = select(n, n_kept + 1.0, marched);
    textureStore(out_color, gid.xy, color);
    textureStore(out_aux, gid.xy, vec4<f32>(samples, 0.0, 0.0, 0.0));
}
