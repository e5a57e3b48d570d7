// The `slices` render method (Schpok, Simons, Ebert & Hansen 2003, §4,
// Table 1, Figure 1): slicing planes aligned with the light, drawn back to
// front (painter's algorithm) into the float cloud target, which the
// composite pass then blends over sky and terrain.
//
// The CPU (src/authored/slicing.rs) tessellates the planes and stores at
// every vertex the implicit field (Σ Wyvill blends, eq. 1 before the plane
// opacity) and the shadow accumulated toward the light (eq. 2). Here:
//   vertex   : world → clip; field and shadow interpolated across the plane;
//   fragment : the noise octaves composited with their animated transforms
//              (eq. 3, one texture_from_world per octave and tier), the
//              tier's media filter (Table 2), alpha = 1 − exp(−plane
//              opacity × field × media) (≈ the paper's product for the
//              small per-plane values, and never above 1), the alpha cutoff
//              (Sharpness × plane opacity) and the shadow colour, lit by
//              exp(−shadow) (the shadow is an optical depth toward the sun).
// Plane opacity and shadow come scaled for a cloudscape (one stack of
// planes over many clouds): see CloudscapeScale in src/render/slices/mod.rs.
// Output is premultiplied, through output_color() like every pass.

// Read the terrain depth (false: no terrain pass, nothing hides the planes).
override HAS_TERRAIN: bool = true;

@group(1) @binding(0) var depth_tex: texture_depth_2d;

// 544 bytes; keep in sync with TierUniform in src/authored/octaves.rs.
struct SlicesTier {
    texture_from_world: array<mat4x4<f32>, 8>, // per octave; unused are zero
    bottom_m: vec4<f32>,  // x: bottom of the tier (m); y: first octave's weight
    media: vec4<u32>,     // x: media filter id (MediaFilter::gpu_id)
}

// 2192 bytes; keep in sync with OctaveUniform in src/authored/octaves.rs.
struct SlicesOctaves {
    tiers: array<SlicesTier, 4>,
    counts: vec4<u32>,    // x: tiers in use; y: octaves in use
}

// 48 bytes; keep in sync with SlicesParams in src/render/slices/mod.rs.
struct SlicesParams {
    opacity: vec4<f32>,       // x: plane opacity; y: alpha cutoff; z: sun to colour scale; w: shadow scale
    cloud_colour: vec4<f32>,  // rgb: lit cloud (linear)
    shadow_colour: vec4<f32>, // rgb: fully shadowed cloud (linear)
}

@group(2) @binding(0) var<uniform> octaves: SlicesOctaves;
@group(2) @binding(1) var<uniform> params: SlicesParams;

struct SliceIn {
    @location(0) position_m: vec3<f32>,
    @location(1) density: f32,
    @location(2) shadow: f32,
}

struct SliceOut {
    @builtin(position) pos: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) density: f32,
    @location(2) shadow: f32,
}

@vertex
fn vs_main(v: SliceIn) -> SliceOut {
    var o: SliceOut;
    o.pos = frame.clip_from_world * vec4<f32>(v.position_m, 1.0);
    o.world = v.position_m;
    o.density = v.density;
    o.shadow = v.shadow;
    return o;
}

// The tier holding altitude z: the highest whose bottom is at or below z
// (the first tier also covers everything below it).
fn tier_at(z: f32) -> u32 {
    var t = 0u;
    for (var i = 1u; i < octaves.counts.x; i++) {
        if z >= octaves.tiers[i].bottom_m.x {
            t = i;
        }
    }
    return t;
}

// Octaves of the periodic noise volume at `p`, octave o weighted by the
// first weight × ½^o (persistence ½, normalised on the CPU so the sum of
// weights is 1): the composite stays in [0, 1] like each fetch.
fn composite_noise(tier: u32, p: vec3<f32>) -> f32 {
    var w = octaves.tiers[tier].bottom_m.y;
    var sum = 0.0;
    for (var o = 0u; o < octaves.counts.y; o++) {
        let q = (octaves.tiers[tier].texture_from_world[o] * vec4<f32>(p, 1.0)).xyz;
        sum += w * textureSampleLevel(noise_tex, repeat_sampler, q, 0.0).r;
        w *= 0.5;
    }
    return sum;
}

// The media filters of Table 2; ids and formulas as MediaFilter::apply in
// src/authored/media.rs (keep in sync). n in [0, 1] → [0, 1].
fn media_filter(id: u32, n: f32) -> f32 {
    switch id {
        case 2u: { return 1.0 - 2.0 * abs(n - 0.5); }  // wispy
        case 3u: { return 1.0 / (1.0 + 10.0 * n); }    // cirrus
        default: { return n; }                          // cumulus, stratus
    }
}

@fragment
fn fs_main(in: SliceOut) -> @location(0) vec4<f32> {
    if HAS_TERRAIN {
        // Behind the terrain: hidden (the same projection wrote the depth).
        let depth = textureLoad(depth_tex, vec2<i32>(in.pos.xy), 0);
        if in.pos.z > depth {
            discard;
        }
    }
    let tier = tier_at(in.world.z);
    let m = media_filter(octaves.tiers[tier].media.x, composite_noise(tier, in.world));
    let tau = params.opacity.x * in.density * m;
    if tau <= params.opacity.y {
        discard;
    }
    let alpha = 1.0 - exp(-tau);
    let lit = exp(-in.shadow * params.opacity.w);
    let c = mix(params.shadow_colour.rgb, params.cloud_colour.rgb, lit)
        * frame.sun_color.rgb * params.opacity.z;
    return vec4<f32>(output_color(c) * alpha, alpha);
}
