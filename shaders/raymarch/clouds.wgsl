// Cloud pass (paper §6.2): a full-screen ray-march through the box of the
// frame's grid, evaluating the density of density.wgsl (eq. 18) from the
// method's macro field (the `<field>` slot: field_exact.wgsl or
// field_baked.wgsl) at fixed steps (stretched so `max_steps` always cross
// the box), stopping at the terrain depth written by the terrain pass, lit
// by lighting.wgsl.
// Energy-conserving step integration:
// L += T·S·(1 − exp(−σΔt)), T *= exp(−σΔt), with Δt growing to 2 and 4
// steps as T falls (`march_stride`). Early exit when T drops below
// the threshold (0 disables it). Empty space (the field's `empty_skip`) is
// crossed in one jump to the first sample past it on the same dt lattice,
// so the samples kept are the unskipped march's, same positions. Output is
// premultiplied (rgb = L, a = 1 − T) and blended over the sky/terrain with
// (ONE, ONE_MINUS_SRC_ALPHA) in the HDR scene target. `march` is the one
// march routine; the entry points only supply the pixel: `fs_main`
// (fragment path) returns it, `cs_main` (compute path) stores it into
// `cloud_out`, which composite.wgsl then blends over the target the same
// way; `cs_temporal` (temporal upscaling, `[render] temporal`) marches
// one pixel of each 2×2 or 4×4 block per frame into textures of one texel
// per block, with its cloud depth, for temporal.wgsl to reproject and
// accumulate. The
// full-size compute path stores its cloud depth too (`cloud_depth_out`):
// the sprites of a frame that has both sort against it
// (sprites/sprites.wgsl).
// Rays start at the near plane (not at the eye), so a camera inside a
// cloud sees the cloud from its first visible point on, as the terrain
// does: flying into a cloud and out of it is continuous.

#import "../common.wgsl"
#import "../air.wgsl"
#import <field>
#import "density.wgsl"
#import "lighting.wgsl"
#import "temporal_uniform.wgsl"

// Read the terrain depth (false: no terrain pass, rays run to the box end).
override HAS_TERRAIN: bool = true;
// Debug (`[render] debug_march_steps`): output the march's iteration count
// (samples and empty-space jumps) as opaque grey radiance instead of the
// colour. False in every ordinary frame, where the branch is compiled out.
override MARCH_STEPS: bool = false;

// The terrain depth, read as an unfilterable float texture (OpenGL's GLSL
// cannot load from a depth texture binding).
@group(1) @binding(0) var depth_tex: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> FullscreenOut {
    return fullscreen_vertex(i);
}

// What a view ray gathered: premultiplied linear radiance (rgb = L,
// a = 1 − T) and the cloud's depth along the ray, weighted by where the
// light came from (Σ wᵢ·tᵢ / Σ wᵢ with wᵢ = Tᵢ·(1 − exp(−σᵢΔt)), the
// sample's share of the opacity; 0 where the ray met no cloud). The depth
// is what temporal reprojection moves a pixel by. units: depth m
struct MarchOut {
    color: vec4<f32>,
    depth: f32,
    // Loop iterations the march took (read only under MARCH_STEPS).
    steps: u32,
}

// What a pixel shows: the march's colour, or under MARCH_STEPS its
// iteration count (opaque, so the composite keeps it as it is).
fn shown(m: MarchOut) -> vec4<f32> {
    if MARCH_STEPS {
        return vec4<f32>(vec3<f32>(f32(m.steps)), 1.0);
    }
    return m.color;
}

// Lattice steps (of dt) an in-cloud sample stands for at transmittance
// `trans`: 1 while more than half the light gets through, then 2, then 4
// below a quarter. Samples stay on the dt lattice (the skip's landing
// points are unchanged) and each one's extinction covers its whole
// stretch (exp(−σρ·m·dt)), so the opacity is the same integral and only
// the lighting behind the front half of the opacity is sampled coarser.
// The lit samples (a short light march each) are most of what the pass
// costs as the parcel count grows, and about half of them lie behind
// T < 0.5 (docs/notes.md, "Cloud march").
fn march_stride(trans: f32) -> f32 {
    return select(select(1.0, 2.0, trans < 0.5), 4.0, trans < 0.25);
}

// The march of the pixel at `pix` (pixel centre coordinates), whose
// centre is at `ndc`; `jitter` in [0, 1) offsets the first sample by that
// fraction of a step (against banding).
fn march(pix: vec2<f32>, ndc: vec2<f32>, jitter: f32) -> MarchOut {
    var out: MarchOut;
    out.color = vec4<f32>(0.0);
    out.depth = 0.0;
    out.steps = 0u;
    let ro = frame.camera_pos.eye_m;
    let rd = view_dir(ndc);
    // The near plane along this ray (depth 0 in wgpu's clip space).
    let t_near = distance(world_from_ndc(ndc, 0.0), ro);
    var t_end = 1e30;
    if HAS_TERRAIN {
        let depth = textureLoad(depth_tex, vec2<i32>(pix), 0).r;
        if depth < 1.0 {
            t_end = distance(world_from_ndc(ndc, depth), ro);
        }
    }
    let grid_max = frame.grid_min + frame.grid_cell * vec3<f32>(frame.grid_dims);
    let span = ray_box(ro, rd, frame.grid_min, grid_max);
    let t0 = max(span.x, t_near);
    let t1 = min(span.y, t_end);
    if t1 <= t0 {
        return out;
    }
    let max_steps = frame.max_steps;
    let dt = max(frame.step_m, (t1 - t0) / f32(max_steps));
    let sigma_max = frame.extinction_per_m;
    // Light that does not depend on the sample, hoisted out of the march.
    let light = ray_lighting(rd, HAS_TERRAIN);

    // Samples sit at t_first + k·dt, k = 0, 1, …
    let t_first = t0 + dt * jitter;
    var k = 0.0;
    var trans = 1.0;
    var radiance = vec3<f32>(0.0);
    var first_hit = -1.0;
    var depth_sum = 0.0;
    // Lattice steps the last in-cloud sample stood for.
    var m = 1.0;
    for (var i = 0u; i < max_steps; i++) {
        out.steps = i + 1u;
        let t = t_first + k * dt;
        if t >= t1 {
            break;
        }
        let p = ro + rd * t;
        let skip = empty_skip(p, rd);
        if skip > 0.0 {
            k = max(ceil((t + skip - t_first) / dt), k + 1.0);
            continue;
        }
        // The field and the base plane of the sample's cloud.
        let vp = field_sample(p);
        let rho = density_from(vp.x, p);
        if rho > 1e-3 {
            if first_hit < 0.0 {
                first_hit = t;
            }
            // Once little light gets through, the samples stand for longer
            // stretches of the same dt lattice; past the cloud the march
            // keeps the last stride (the next sample lands on the lattice).
            m = march_stride(trans);
            let source = sample_source(light, p, vp.y);
            let step_t = exp(-rho * sigma_max * dt * m);
            let w = trans * (1.0 - step_t);
            radiance += w * source;
            depth_sum += w * t;
            trans *= step_t;
            if trans < frame.early_exit_transmittance {
                break;
            }
        }
        k += m;
    }
    if first_hit < 0.0 {
        return out;
    }
    // Σ w = 1 − T exactly (the weights telescope).
    out.depth = depth_sum / max(1.0 - trans, 1e-6);
    // The air between the eye and the cloud (air.wgsl), as on the terrain,
    // up to the opacity-weighted depth where the cloud's light comes from
    // (smooth across the cloud, unlike its faint first sample); what lies
    // behind the cloud has its own.
    radiance = through_air(radiance, 1.0 - trans, rd, out.depth);
    // Premultiplied linear radiance, blended in linear light over the
    // sky/terrain in the HDR scene target (tone-mapped once, at the end).
    out.color = vec4<f32>(output_color(radiance), 1.0 - trans);
    return out;
}

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    return shown(march(in.pos.xy, in.ndc, hash2(in.pos.xy)));
}

// NDC of the pixel centre `pix` in a `size` frame, as the rasteriser
// gives fs_main.
fn ndc_of(pix: vec2<f32>, size: vec2<u32>) -> vec2<f32> {
    return vec2<f32>(2.0 * pix.x / f32(size.x) - 1.0, 1.0 - 2.0 * pix.y / f32(size.y));
}

// Compute path: the march's premultiplied colour and cloud depth per pixel
// (the depth binding is shared with the temporal path's one-per-block one).
@group(2) @binding(0) var cloud_out: texture_storage_2d<rgba16float, write>;
@group(2) @binding(1) var cloud_depth_out: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn cs_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(cloud_out);
    if any(gid.xy >= size) {
        return;
    }
    let pix = vec2<f32>(gid.xy) + 0.5;
    let m = march(pix, ndc_of(pix, size), hash2(pix));
    textureStore(cloud_out, gid.xy, shown(m));
    // No cloud on this ray: infinitely far (every sprite is in front).
    let depth = select(m.depth, 1e30, m.color.a <= 0.0);
    textureStore(cloud_depth_out, gid.xy, vec4<f32>(depth, 0.0, 0.0, 0.0));
}

// Temporal path: one texel per block of the frame (`temporal.block`
// pixels square) and the frame's block offset.
@group(2) @binding(2) var<uniform> temporal: Temporal;

// Interleaved gradient noise (Jimenez 2014), a cheap blue-noise-like
// pattern (neighbouring pixels get well spread values), shifted each frame
// by the golden ratio so one pixel's jitters over frames fill [0, 1)
// evenly: the accumulated pixel averages the ray-start offsets that the
// full-resolution march samples once each (hash2).
fn temporal_jitter(pix: vec2<f32>, frame_index: u32) -> f32 {
    let ign = fract(52.9829189 * fract(dot(pix, vec2<f32>(0.06711056, 0.00583715))));
    return fract(ign + 0.61803399 * f32(frame_index % 4096u));
}

@compute @workgroup_size(8, 8)
fn cs_temporal(@builtin(global_invocation_id) gid: vec3<u32>) {
    if any(gid.xy >= temporal.fresh) {
        return;
    }
    let full = temporal.size;
    // The block's marched pixel this frame (inside the frame on odd sizes).
    let p = min(temporal.block * gid.xy + temporal.offset, full - 1u);
    let pix = vec2<f32>(p) + 0.5;
    // The frame index advances the jitter once per round of the block, so
    // a pixel's successive samples take successive golden-ratio jitters.
    let round = temporal.frame_index / (temporal.block * temporal.block);
    let m = march(pix, ndc_of(pix, full), temporal_jitter(pix, round));
    textureStore(cloud_out, gid.xy, shown(m));
    textureStore(cloud_depth_out, gid.xy, vec4<f32>(m.depth, 0.0, 0.0, 0.0));
}
