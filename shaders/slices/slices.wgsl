// The `slices` render method (Schpok, Simons, Ebert & Hansen 2003, §4,
// Table 1, Figure 1): slicing planes aligned with the light, drawn back to
// front (painter's algorithm) into the float cloud target, which the
// composite pass then blends over sky and terrain.
//
// The CPU (src/methods/slices/model/slicing.rs) tessellates the planes; the CPU, or the
// compute pass of vertex_field.wgsl, stores at every vertex the implicit
// field (Σ Wyvill blends, eq. 1 before the plane opacity) and the shadow
// accumulated toward the light (eq. 2). Here:
//   vertex   : world → clip; field and shadow interpolated across the plane;
//   fragment : the noise octaves composited with their animated transforms
//              (eq. 3, one texture_from_world per octave and tier), the
//              tier's media filter (Table 2), alpha = 1 − exp(−plane
//              opacity × field × media) (≈ the paper's product for the
//              small per-plane values, and never above 1), the alpha cutoff
//              (Sharpness × plane opacity), and the artist's colours lit by
//              the frame's sky and by its sun through exp(−shadow) (the
//              shadow is an optical depth toward the sun; artist.wgsl).
// Every cloud has its own stack (src/methods/slices/model/clouds.rs), whose
// plane opacity rides on its vertices, compensated for the cloud and its
// shadow scaled likewise: see CloudScale in src/methods/slices/model/slicing.rs.
// Seen through the air per vertex (air.wgsl). Output is premultiplied,
// through output_color() like every pass.

#import "../common.wgsl"
#import "../air.wgsl"
#import "../artist.wgsl"
// The octave transforms, controls and media filters (group 2).
#import "implicit.wgsl"

// Read the terrain depth (false: no terrain pass, nothing hides the planes).
override HAS_TERRAIN: bool = true;
// Drop fragments on the implicit field before the noise fetch
// (`[render.slices] early_discard`).
override EARLY_DISCARD: bool = true;

// The terrain depth, read as an unfilterable float texture (OpenGL's GLSL
// cannot load from a depth texture binding).
@group(1) @binding(0) var depth_tex: texture_2d<f32>;

struct SliceIn {
    @location(0) position_m: vec3<f32>,
    @location(1) density: f32,
    @location(2) shadow: f32,
    @location(3) plane_opacity: f32,
}

struct SliceOut {
    @builtin(position) pos: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) density: f32,
    @location(2) shadow: f32,
    // The air between the eye and the vertex (air.wgsl), interpolated: it
    // changes over kilometres, the planes' vertices over a few hundred metres.
    @location(3) air_light: vec3<f32>,
    @location(4) air_transmittance: vec3<f32>,
    // The same on every vertex of a stack.
    @location(5) @interpolate(flat) plane_opacity: f32,
}

@vertex
fn vs_main(v: SliceIn) -> SliceOut {
    var o: SliceOut;
    o.pos = frame.clip_from_world * vec4<f32>(v.position_m, 1.0);
    o.world = v.position_m;
    o.density = v.density;
    o.shadow = v.shadow;
    o.plane_opacity = v.plane_opacity;
    let from_eye = v.position_m - frame.camera_pos.eye_m;
    let dist = length(from_eye);
    let air = air_toward(from_eye / max(dist, 1e-3), dist);
    o.air_light = air.light;
    o.air_transmittance = air.transmittance;
    return o;
}

@fragment
fn fs_main(in: SliceOut) -> @location(0) vec4<f32> {
    if HAS_TERRAIN {
        // Behind the terrain: hidden (the same projection wrote the depth).
        let depth = textureLoad(depth_tex, vec2<i32>(in.pos.xy), 0).r;
        if in.pos.z > depth {
            discard;
        }
    }
    // The media filters are at most 1: where the field alone leaves τ at
    // or under the cut-off, no noise can lift it over, so the four noise
    // fetches are skipped (the same image: render::slices_discard).
    let cutoff = params.sharpness * in.plane_opacity;
    if EARLY_DISCARD && in.plane_opacity * in.density <= cutoff {
        discard;
    }
    let tau = in.plane_opacity * in.density * media_at(in.world);
    if tau <= cutoff {
        discard;
    }
    let alpha = 1.0 - exp(-tau);
    // Lit: the painted colour under the sky's light and the share of the
    // sun's the light-ray shadow (eq. 2) lets through.
    let lit = exp(-in.shadow);
    let c = artist_light(mix(params.shadow_colour, params.cloud_colour, lit), 1.0, lit);
    let seen = seen_through(Air(in.air_light, in.air_transmittance), c * alpha, alpha);
    return vec4<f32>(output_color(seen), alpha);
}
