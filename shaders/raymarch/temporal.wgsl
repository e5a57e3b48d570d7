// Temporal resolve (`[render] temporal`): builds the full-size cloud
// image of a frame from the one pixel per B×B block (B = 2 or 4) that
// clouds.wgsl's cs_temporal marched (the block offset stepping through a
// B×B Bayer order) and the previous frame's image.
//
// For each pixel:
// - Its fresh estimate: the bilinear interpolation of the four nearest
//   fresh samples (they sit on a regular grid B pixels apart), and its
//   cloud depth: theirs, weighted by that and by their opacity (a pixel
//   near a cloud moves with the cloud; none near it: a far point, so the
//   sky moves with the camera's rotation). Per pixel, so the velocity
//   below varies across a block.
// - Its history: the view ray at that depth gives the cloud point, whose
//   pixel in the previous frame is where the history is read, by a 5-tap
//   Catmull-Rom filter (sharper than bilinear: a moving view does not
//   blur the image frame after frame). The reprojection is
//   camera-relative (prev_clip_from_eye): a still view maps every pixel
//   to itself to f32 precision however far the camera is from the
//   world's origin; through world positions 18 km out (the landscape),
//   rays were off by up to a tenth of a pixel, and the history, resampled
//   at that offset each frame, drifted from the full march.
// - Variance clipping as a test: the history is clipped, in YCoCg and
//   alpha, toward the centre of a box from the 3×3 fresh samples around
//   the pixel: mean ± GAMMA·σ (Salvi 2016) inside their min/max where the
//   pixel moves, wider where it stands still (see GAMMA_STILL): whatever
//   the pixel showed before must look like what is around it now, so a
//   cloud that moved away, or the inside of a cloud the camera flew out
//   of, cannot linger (no ghosting). A clip that moved the history far
//   (REJECT) rejects it: its average restarts (and, on a moving pixel,
//   the fresh estimate shows until the pixel is marched). A history the
//   clip moved less is accepted and kept as it was, unclipped: the box of
//   samples 4 px apart cannot resolve one-pixel detail, and clipping to
//   it every frame (15 frames between a pixel's own samples) flattened
//   that detail toward the box's mean.
// - A pixel marched this frame averages its fresh sample into its
//   history (weight 1/(n+1) for n accumulated samples, n capped so the
//   average spans at most HISTORY_FRAMES frames): for a still camera and
//   still clouds each pixel's average runs over the ray-start jitters of
//   successive rounds and converges to the full-resolution march. The
//   others keep the clipped history, or take the fresh estimate where
//   there is none (first frame, off-screen before).
//
// Output: premultiplied linear radiance (as the cloud pass), composited by
// composite.wgsl; and per pixel the samples averaged into it: with the
// colour, the next frame's history.

#import "../common.wgsl"
#import "temporal_uniform.wgsl"

// Most frames a pixel's average spans: its sample cap is this over the
// frames between two of its samples (16 at 2×2, 4 at 4×4), so the image
// follows evolving clouds (a time-lapse) within ~HISTORY_FRAMES frames
// whatever the block.
const HISTORY_FRAMES: f32 = 64.0;
// Distance of the point a cloudless pixel is reprojected at. units: m
const FAR_M: f32 = 100000.0;
// Half-width of the clipping box in standard deviations of the fresh
// neighbourhood where the pixel moved a pixel or more since the previous
// frame: 1 is the usual choice for variance clipping (a tighter box than
// min/max, so a stale colour inside the range of the neighbourhood's
// extremes is still caught), kept inside their min/max. Wider boxes
// reject less of the moving history but let more of a ghost through:
// on lavapipe the landscape flight's worst frame / the tower exit of
// tests/cumulus/render/temporal.rs (whose ghost bound is a quarter of the
// 4-frame-old view's 0.52, 0.129) are 0.046 / 0.118 at 1, 0.042 / 0.122 at
// 1.25, 0.039 / 0.126 at 1.5, 0.036 / 0.134 with the min/max (a ghost by
// that bound): 1 keeps the margin against ghosts. Where it
// stands still the box widens to the union of the min/max and
// mean ± GAMMA_STILL·σ, grown by STILL_MARGIN of the min/max range on each
// side: the sparse samples (one per 4×4 block) are too few to tell
// one-pixel detail from a stale colour, and a still pixel's history is
// that detail, built over its own marched samples (on the stand-in field
// the still view after 32 frames is 0.0046 from the full march with the
// margin, 0.0063 without, 0.0020 with no clip at all); a gross change (a
// cloud gone: a sky-only neighbourhood, σ ≈ 0) still leaves the history
// far outside the box (without any clip, the 1.5 km jump of
// tests/cumulus/render/temporal.rs lingers: 0.046 against 0.027). Those
// numbers are from when every history was clipped to the box; now that
// only a rejected one is, the still view is 0.0039 after 32 frames
// (0.0042 clipped, same run), and the jump 0.0265 in both.
const GAMMA: f32 = 1.0;
const GAMMA_STILL: f32 = 2.0;
const STILL_MARGIN: f32 = 0.25;
// A clip that moves the history by more than this (in premultiplied
// alpha, or luma/chroma relative to the box's largest luma) treats it as
// a different surface: its average restarts (the pixel's next marched
// sample replaces it; until then a moving pixel shows the fresh estimate,
// a still one the clipped value). A clip that moves it less leaves it
// unclipped. Against the 0.05 bounds (lavapipe, mean FLIP against the full
// march): the landscape flight (tests/cumulus/render/temporal_landscape.rs)
// is 0.046 at worst with this test, 0.058 with every history clipped, and
// 0.028 with no clip at all, which ghosts; 0.05 here gives 0.053, 0.15
// gives 0.042. The tower exit in tests/cumulus/render/temporal.rs (the
// frame after the camera leaves a cloud, whose 4-frame-old view is 0.52)
// is 0.118 with this test, 0.120 with every history clipped.
const REJECT: f32 = 0.1;

@group(1) @binding(0) var fresh_color: texture_2d<f32>;
@group(1) @binding(1) var fresh_depth: texture_2d<f32>;
@group(1) @binding(2) var history_color: texture_2d<f32>;
@group(1) @binding(3) var history_aux: texture_2d<f32>;
@group(1) @binding(4) var out_color: texture_storage_2d<rgba16float, write>;
@group(1) @binding(5) var out_aux: texture_storage_2d<r32float, write>;
@group(1) @binding(6) var<uniform> temporal: Temporal;

// Premultiplied RGBA ↔ YCoCg and alpha: luma apart from chroma, so the
// box hugs the neighbourhood's colours (a box in RGB is loose along the
// grey axis that cloud colours spread along).
fn to_ycocg(c: vec4<f32>) -> vec4<f32> {
    let y = 0.25 * c.r + 0.5 * c.g + 0.25 * c.b;
    return vec4<f32>(y, 0.5 * (c.r - c.b), -0.25 * c.r + 0.5 * c.g - 0.25 * c.b, c.a);
}

fn from_ycocg(c: vec4<f32>) -> vec4<f32> {
    let t = c.x - c.z;
    return vec4<f32>(t + c.y, c.x + c.z, t - c.y, c.a);
}

// The history at `uv` by Catmull-Rom, in 5 bilinear taps (the 9-tap form
// of Jimenez's "Filmic SMAA" with the corners dropped, weights
// renormalised); negative lobes clamped away.
fn history_catmull_rom(uv: vec2<f32>, size: vec2<f32>) -> vec4<f32> {
    let pos = uv * size;
    let centre = floor(pos - 0.5) + 0.5;
    let f = pos - centre;
    let f2 = f * f;
    let f3 = f2 * f;
    let w0 = -0.5 * f3 + f2 - 0.5 * f;
    let w1 = 1.5 * f3 - 2.5 * f2 + 1.0;
    let w2 = -1.5 * f3 + 2.0 * f2 + 0.5 * f;
    let w3 = 0.5 * f3 - 0.5 * f2;
    let w12 = w1 + w2;
    let t0 = (centre - 1.0) / size;
    let t3 = (centre + 2.0) / size;
    let t12 = (centre + w2 / w12) / size;
    let s = clamp_sampler;
    var c = textureSampleLevel(history_color, s, vec2<f32>(t12.x, t0.y), 0.0) * (w12.x * w0.y);
    c += textureSampleLevel(history_color, s, vec2<f32>(t0.x, t12.y), 0.0) * (w0.x * w12.y);
    c += textureSampleLevel(history_color, s, t12, 0.0) * (w12.x * w12.y);
    c += textureSampleLevel(history_color, s, vec2<f32>(t3.x, t12.y), 0.0) * (w3.x * w12.y);
    c += textureSampleLevel(history_color, s, vec2<f32>(t12.x, t3.y), 0.0) * (w12.x * w3.y);
    let w = w12.x * w0.y + w0.x * w12.y + w12.x * w12.y + w3.x * w12.y + w12.x * w3.y;
    return max(c / w, vec4<f32>(0.0));
}

// Clips `h` toward `centre` into the box centre ± extent: the point where
// the segment from the centre to h leaves the box (h itself inside it).
fn clip_to_box(h: vec4<f32>, centre: vec4<f32>, extent: vec4<f32>) -> vec4<f32> {
    let d = h - centre;
    let r = abs(d) / max(extent, vec4<f32>(1e-5));
    let m = max(max(r.x, r.y), max(r.z, r.w));
    return select(h, centre + d / m, m > 1.0);
}

@compute @workgroup_size(8, 8)
fn cs_resolve(@builtin(global_invocation_id) gid: vec3<u32>) {
    let full = temporal.size;
    if any(gid.xy >= full) {
        return;
    }
    let b = temporal.block;
    let last = vec2<i32>(temporal.fresh) - 1;
    let own = vec2<i32>(gid.xy / b);
    let marched = all(min(b * (gid.xy / b) + temporal.offset, full - 1u) == gid.xy);

    // The pixel in the grid of fresh samples (sample j at pixel b·j + offset).
    let g = (vec2<f32>(gid.xy) - vec2<f32>(temporal.offset)) / f32(b);
    let g0 = floor(g);
    let fr = g - g0;
    let i0 = clamp(vec2<i32>(g0), vec2<i32>(0), last);
    let i1 = clamp(vec2<i32>(g0) + 1, vec2<i32>(0), last);
    var estimate = vec4<f32>(0.0);
    var depth_sum = 0.0;
    var depth_w = 0.0;
    for (var k = 0; k < 4; k++) {
        let corner = vec2<i32>(k & 1, k >> 1u);
        let q = select(i0, i1, corner == vec2<i32>(1));
        let wv = select(1.0 - fr, fr, corner == vec2<i32>(1));
        let w = wv.x * wv.y;
        let c = textureLoad(fresh_color, q, 0);
        estimate += w * c;
        let wd = w * c.a * f32(textureLoad(fresh_depth, q, 0).x > 0.0);
        depth_sum += wd * textureLoad(fresh_depth, q, 0).x;
        depth_w += wd;
    }
    let fresh = textureLoad(fresh_color, own, 0);
    let own_depth = textureLoad(fresh_depth, own, 0).x;
    let depth = select(select(0.0, depth_sum / max(depth_w, 1e-6), depth_w > 1e-6), own_depth, marched);

    // Mean, deviation and range of the fresh samples around the pixel.
    let near = clamp(vec2<i32>(round(g)), vec2<i32>(0), last);
    var sum = vec4<f32>(0.0);
    var sum2 = vec4<f32>(0.0);
    var lo = vec4<f32>(1e30);
    var hi = vec4<f32>(-1e30);
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = clamp(near + vec2<i32>(dx, dy), vec2<i32>(0), last);
            let c = to_ycocg(textureLoad(fresh_color, q, 0));
            sum += c;
            sum2 += c * c;
            lo = min(lo, c);
            hi = max(hi, c);
        }
    }
    let mean = sum / 9.0;
    let sigma = sqrt(max(sum2 / 9.0 - mean * mean, vec4<f32>(0.0)));

    // Where this pixel's cloud point was in the previous frame.
    let pix = vec2<f32>(gid.xy) + 0.5;
    let ndc = vec2<f32>(2.0 * pix.x / f32(full.x) - 1.0, 1.0 - 2.0 * pix.y / f32(full.y));
    let offset = view_dir(ndc) * select(FAR_M, depth, depth > 0.0);
    let prev = temporal.prev_clip_from_eye * vec4<f32>(offset, 1.0);
    let prev_ndc = prev.xy / max(prev.w, 1e-6);
    let prev_uv = vec2<f32>(0.5 * prev_ndc.x + 0.5, 0.5 - 0.5 * prev_ndc.y);
    let on_screen = prev.w > 0.0 && all(prev_uv >= vec2<f32>(0.0)) && all(prev_uv <= vec2<f32>(1.0));
    let have_history = temporal.history_valid != 0u && on_screen;
    // The variance box, inside the range of the samples, by how far the
    // pixel moved.
    let motion_px = length(prev_uv * vec2<f32>(full) - pix);
    let moving = clamp(motion_px, 0.0, 1.0);
    let margin = STILL_MARGIN * (hi - lo);
    let box_lo = mix(min(mean - GAMMA_STILL * sigma, lo) - margin, max(mean - GAMMA * sigma, lo), moving);
    let box_hi = mix(max(mean + GAMMA_STILL * sigma, hi) + margin, min(mean + GAMMA * sigma, hi), moving);

    // Branch-free below: Mesa's lavapipe (22.3) crashes on this shader
    // with nested branches, and every lane does the same work anyway.
    let uv = clamp(prev_uv, vec2<f32>(0.0), vec2<f32>(1.0));
    let h = to_ycocg(history_catmull_rom(uv, vec2<f32>(full)));
    let prev_pix = min(vec2<u32>(uv * vec2<f32>(full)), full - 1u);
    let box_centre = 0.5 * (box_lo + box_hi);
    let clipped_y = clip_to_box(h, box_centre, 0.5 * (box_hi - box_lo));
    let moved = abs(clipped_y - h);
    let scale = max(hi.x, 1e-3);
    let rejected = moved.w > REJECT || max(moved.x, max(moved.y, moved.z)) > REJECT * scale;
    // A rejected history is clipped; an accepted one kept as it was.
    let clipped = max(from_ycocg(select(clipped_y, h, !rejected)), vec4<f32>(0.0));
    // Samples in the history: none without one (then the fresh estimate
    // stands in, and the pixel's first own sample replaces it).
    var n = select(0.0, textureLoad(history_aux, vec2<i32>(prev_pix), 0).x, have_history);
    n = select(n, 0.0, rejected);
    let max_samples = max(HISTORY_FRAMES / f32(b * b), 1.0);
    // A rejected history of a moving pixel shows another surface: the
    // fresh estimate is the better guess until the pixel's own sample
    // comes. A still pixel keeps its clipped history (the box is its best
    // guess of one-pixel detail the estimate would blur).
    let first = select(estimate, fresh, marched);
    let keep = marched || !rejected || moving < 0.5;
    let past = select(first, clipped, have_history && keep);
    let n_kept = min(n, max_samples - 1.0);
    let color = select(past, mix(past, fresh, 1.0 / (n_kept + 1.0)), marched);
    let samples = select(n, n_kept + 1.0, marched);
    textureStore(out_color, gid.xy, color);
    textureStore(out_aux, gid.xy, vec4<f32>(samples, 0.0, 0.0, 0.0));
}
