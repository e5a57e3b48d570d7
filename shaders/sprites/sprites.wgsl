// Sprite clouds (Wang 2003, the `sprites` method and scene layers): one
// instanced quad per sprite, corners and per-corner shading computed on the
// CPU (src/methods/sprites/gpu/, after the paper's §5–§6.1: camera-facing or
// locked corners; per corner the artist's colour level, the shares of the
// sky's light (time-of-day ambient) and of the sun's (biased directional
// mapping), × formation alpha) and sorted back to front. The vertex turns
// the shares into light with the frame's own sun and sky (artist.wgsl) and
// takes the air between the eye and the corner (air.wgsl); the fragment
// multiplies the atlas texel in (eq. 3), hides what lies behind the terrain
// depth and writes premultiplied colour seen through that air, blended with
// (ONE, ONE_MINUS_SRC_ALPHA) as the cloud pass does.
// Depth against ray-marched clouds in the same frame: the march runs first
// and leaves its cloud depth per pixel (raymarch/clouds.wgsl, the opacity-weighted
// mean distance along the ray); the sprite pass keeps the fragments
// farther than it (CLOUD_DEPTH = 1), the clouds are blended over them, and
// a second draw after the composite keeps the nearer ones (CLOUD_DEPTH =
// 2), so each sprite fragment lands on its side of the clouds.
// Shadows (SHADOW_SPLAT): the same instances, turned to face the sun and
// projected along it onto the ground plane into the cloud-shadow map (the
// rectangle and lookup of ../shadow.wgsl and ../terrain.wgsl), each multiplying
// the sun's transmittance there by (1 − its opacity). Only the sprites
// drawn directly cast shadows (not those in the impostor ring).

#import "../common.wgsl"
#import "../air.wgsl"
#import "../artist.wgsl"

// Compare with the terrain depth (false: no terrain pass this frame).
override HAS_TERRAIN: bool = true;
// Drawing the impostor ring's quads (src/methods/sprites/gpu/ring.rs): the
// texture is a face of the ring, already shaded, hazed and premultiplied
// by this same shader; only the set's crossfade weight (colour alpha) is
// applied.
override IMPOSTOR_QUAD: bool = false;
// 0: no ray-marched clouds; 1: keep fragments behind the cloud depth;
// 2: keep those in front of it.
override CLOUD_DEPTH: u32 = 0u;
// Splat into the cloud-shadow map instead of drawing.
override SHADOW_SPLAT: bool = false;

// SpriteInstance of src/methods/sprites/gpu/mod.rs.
struct SpriteInstance {
    corners: array<vec4<f32>, 4>, // xyz (m), counter-clockwise from bottom-left
    colors: array<vec4<f32>, 4>,  // painted sRGB colour level and alpha (× formation × facing) per corner
    sun: vec4<f32>,               // share of the sun's light per corner
    sky: vec4<f32>,               // share of the sky's light per corner
    uv: vec4<f32>,                // atlas rectangle u0, v0, u1, v1 (v down)
}

// The terrain depth, read as an unfilterable float texture (OpenGL's GLSL
// cannot load from a depth texture binding).
@group(1) @binding(0) var depth_tex: texture_2d<f32>;
@group(1) @binding(1) var cloud_depth_tex: texture_2d<f32>;
@group(2) @binding(0) var atlas_tex: texture_2d<f32>;
@group(2) @binding(1) var atlas_sampler: sampler;
@group(2) @binding(2) var<storage, read> sprites: array<SpriteInstance>;

struct SpriteOut {
    @builtin(position) pos: vec4<f32>,
    // Linear radiance of the corner's colour (before the texture) and its alpha.
    @location(0) color: vec4<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) world: vec3<f32>,
    // The air between the eye and the corner.
    @location(3) air_light: vec3<f32>,
    @location(4) air_transmittance: vec3<f32>,
}

@vertex
fn vs_main(@builtin(vertex_index) v: u32, @builtin(instance_index) i: u32) -> SpriteOut {
    // Two triangles: corners 0 1 2 and 0 2 3.
    var corner_of = array<u32, 6>(0u, 1u, 2u, 0u, 2u, 3u);
    let c = corner_of[v];
    let s = sprites[i];
    let p = s.corners[c].xyz;
    // Corner 0 is bottom-left: (u0, v1); 1: (u1, v1); 2: (u1, v0); 3: (u0, v0).
    let right = c == 1u || c == 2u;
    let top = c >= 2u;
    var o: SpriteOut;
    o.pos = frame.clip_from_world * vec4<f32>(p, 1.0);
    o.color = s.colors[c];
    o.uv = vec2<f32>(select(s.uv.x, s.uv.z, right), select(s.uv.w, s.uv.y, top));
    o.world = p;
    o.air_light = vec3<f32>(0.0);
    o.air_transmittance = vec3<f32>(1.0);
    if SHADOW_SPLAT {
        o.pos = shadow_splat_position(s, right, top);
        return o;
    }
    if IMPOSTOR_QUAD {
        return o;
    }
    o.color = vec4<f32>(artist_light(s.colors[c].rgb, s.sky[c], s.sun[c]), s.colors[c].a);
    // The aerial perspective once per corner, not per fragment: across one
    // sprite the air changes little, and the overdraw of a deck runs to
    // several fragments per pixel.
    let to_eye = p - frame.camera_pos.eye_m;
    let dist = length(to_eye);
    let air = air_toward(to_eye / max(dist, 1e-3), dist);
    o.air_light = air.light;
    o.air_transmittance = air.transmittance;
    return o;
}

// Corner (right, top) of sprite `s` turned to face the sun (same centre
// and size; its in-plane rotation is dropped: a shadow's blur hides it),
// carried along the sun ray to the ground plane and placed in the shadow
// map's clip space (texel row 0 at the rectangle's north edge).
fn shadow_splat_position(s: SpriteInstance, right: bool, top: bool) -> vec4<f32> {
    let sun = frame.sun_dir;
    let centre = 0.5 * (s.corners[0].xyz + s.corners[2].xyz);
    // A sprite under the ground plane shades nothing (carried "up" the
    // sun ray it would land on the wrong side): a point outside the clip
    // volume draws no fragment.
    if centre.z <= 0.0 {
        return vec4<f32>(0.0, 0.0, 2.0, 1.0);
    }
    let half_w = 0.5 * distance(s.corners[0].xyz, s.corners[1].xyz);
    let half_h = 0.5 * distance(s.corners[0].xyz, s.corners[3].xyz);
    var side = cross(vec3<f32>(0.0, 0.0, 1.0), sun);
    if dot(side, side) < 1e-6 {
        side = vec3<f32>(1.0, 0.0, 0.0);
    }
    side = normalize(side);
    let up = cross(sun, side);
    let p = centre + side * select(-half_w, half_w, right) + up * select(-half_h, half_h, top);
    let g = p.xy - p.z * sun.xy / max(sun.z, 0.03);
    let lo = frame.shadow_min;
    let hi = frame.shadow_max;
    let uv = vec2<f32>((g.x - lo.x) / max(hi.x - lo.x, 1.0), (hi.y - g.y) / max(hi.y - lo.y, 1.0));
    return vec4<f32>(2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y, 0.5, 1.0);
}

@fragment
fn fs_main(in: SpriteOut) -> @location(0) vec4<f32> {
    // Sampled first, in uniform control flow (implicit mip level).
    let tex = textureSample(atlas_tex, atlas_sampler, in.uv);
    if SHADOW_SPLAT {
        return vec4<f32>(1.0 - clamp(in.color.a * tex.a, 0.0, 1.0));
    }
    if CLOUD_DEPTH != 0u {
        let behind = length(in.world - frame.camera_pos.eye_m)
            > textureLoad(cloud_depth_tex, vec2<i32>(in.pos.xy), 0).r;
        if behind != (CLOUD_DEPTH == 1u) {
            discard;
        }
    }
    if HAS_TERRAIN {
        let depth = textureLoad(depth_tex, vec2<i32>(in.pos.xy), 0).r;
        if in.pos.z > depth {
            discard;
        }
    }
    if IMPOSTOR_QUAD {
        return tex * in.color.a;
    }
    let to_eye = in.world - frame.camera_pos.eye_m;
    // Near fade: a quad the camera flies into reaches zero alpha before
    // the near plane clips it (a fragment at view depth `near` lies within
    // 1.3 × near of the eye at our fields of view), instead of vanishing
    // at once while still partly opaque.
    let near = distance(world_from_ndc(vec2<f32>(0.0), 0.0), frame.camera_pos.eye_m);
    let near_fade = smoothstep(1.5 * near, 6.0 * near, length(to_eye));
    let alpha = clamp(in.color.a * tex.a, 0.0, 1.0) * near_fade;
    if alpha < 1e-3 {
        discard;
    }
    let rgb = in.color.rgb * tex.rgb;
    let seen = seen_through(Air(in.air_light, in.air_transmittance), rgb * alpha, alpha);
    return vec4<f32>(output_color(seen), alpha);
}
