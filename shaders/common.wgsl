// Shared by every pass: uniforms, camera rays, noise, sun and sky.
//
// Imports nothing: the generated prelude that starts every module
// (src/gpu/shaders/mod.rs) gives the array sizes SKY_AZIMUTHS,
// SKY_ELEVATIONS, AIR_HEIGHTS, AIR_TOP_M and AIR_STEPS from the Rust
// constants, and the prelude and this file make a module by themselves.
// The uniform structs are those of src/gpu/uniform.rs, member by member
// (a test in src/render/twins.rs compares names, offsets and sizes).
// Group 0 (frame, noise, samplers) is every pass's; a method's field is
// group 3 of its own files.
//
// Colours are linear RGB; sun irradiance ~2 gives daylight exposure.

// Encode sRGB in the tone-map pass (its target format is not sRGB).
override ENCODE_SRGB: bool = false;

// Where the eye is, and when.
struct CameraPos {
    eye_m: vec3<f32>,
    time_s: f32,
}

// The density noise (noise3).
struct FrameNoise {
    inv_scale_per_m: f32, // 1 / noise scale
    octaves: f32,
    _pad: f32,
    // Noise texels of a pixel's view-cone width per metre of eye distance
    // (the mip level of noise3; 0: level 0).
    texels_per_m: f32,
}

struct Frame {
    clip_from_world: mat4x4<f32>,
    eye_from_clip: mat4x4<f32>,   // clip → world offset from the eye (no translation)
    camera_pos: CameraPos,
    sun_dir: vec3<f32>,          // unit vector toward the sun
    phase_g: f32,                // the clouds' Henyey–Greenstein g (forward lobe)
    sun_color: vec3<f32>,        // sun irradiance scale
    exposure: f32,               // display exposure k (tone_map)
    step_m: f32,                 // view march step
    max_steps: u32,              // view march steps across the box
    light_steps: u32,            // light march samples
    light_step_m: f32,           // first light march step
    noise_amplitude: f32,        // k of eq. 18
    shell_m: f32,                // hypertexture shell thickness
    extinction_per_m: f32,       // extinction of density 1
    early_exit_transmittance: f32, // the march stops below it (0: never)
    noise: FrameNoise,
    grid_min: vec3<f32>,         // origin of the frame's grid (m)
    _pad0: f32,
    grid_cell: vec3<f32>,        // its cell size (m)
    _pad1: f32,
    grid_dims: vec3<u32>,        // its cells per axis
    parcel_count: u32,
    shadow_min: vec2<f32>,       // ground rectangle of the shadow map: min x, min y (m)
    shadow_max: vec2<f32>,       // max x, max y (m)
    sky_ambient: vec3<f32>,      // the sky's irradiance on an up-facing surface / π
    sky_mie_g: f32,              // asymmetry g of the sky's Mie phase
    sky_below: vec3<f32>,        // the sky's lower half on a down-facing surface / π
    _pad2: f32,
    // Sky-view table of src/sky/view.rs, texel k = elevation·SKY_AZIMUTHS + azimuth:
    // [3k] Rayleigh per unit phase, [3k + 1] Mie per unit phase, [3k + 2] multiple (rgb).
    sky_view: array<vec4<f32>, 3u * SKY_AZIMUTHS * SKY_ELEVATIONS>,
    // Air table of src/sky/air.rs, node k at height AIR_TOP_M·(k/(AIR_HEIGHTS−1))²:
    // [4k] Rayleigh per unit phase, [4k + 1] Mie per unit phase, [4k + 2] multiple
    // (scattered per metre), [4k + 3] extinction (1/m) (rgb); read by air.wgsl.
    air: array<vec4<f32>, 4u * AIR_HEIGHTS>,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(3) var noise_tex: texture_3d<f32>;
@group(0) @binding(4) var repeat_sampler: sampler;
@group(0) @binding(5) var clamp_sampler: sampler;

const PI: f32 = 3.14159265;

struct FullscreenOut {
    @builtin(position) pos: vec4<f32>,
    @location(0) ndc: vec2<f32>,
}

// One triangle that covers the screen (vertex_index 0, 1, 2).
fn fullscreen_vertex(i: u32) -> FullscreenOut {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    let ndc = uv * 2.0 - 1.0;
    var o: FullscreenOut;
    o.pos = vec4<f32>(ndc, 0.0, 1.0);
    o.ndc = ndc;
    return o;
}

// Offset from the eye of the point at `ndc` and clip depth `depth`.
fn eye_offset_from_ndc(ndc: vec2<f32>, depth: f32) -> vec3<f32> {
    let h = frame.eye_from_clip * vec4<f32>(ndc, depth, 1.0);
    return h.xyz / h.w;
}

fn world_from_ndc(ndc: vec2<f32>, depth: f32) -> vec3<f32> {
    return frame.camera_pos.eye_m + eye_offset_from_ndc(ndc, depth);
}

// Unit view direction through a point of the screen.
fn view_dir(ndc: vec2<f32>) -> vec3<f32> {
    return normalize(eye_offset_from_ndc(ndc, 0.5));
}

// Slab test: (t_near, t_far) of a ray through an axis-aligned box.
fn ray_box(ro: vec3<f32>, rd: vec3<f32>, bmin: vec3<f32>, bmax: vec3<f32>) -> vec2<f32> {
    let safe = select(rd, vec3<f32>(1e-6), abs(rd) < vec3<f32>(1e-6));
    let inv = 1.0 / safe;
    let a = (bmin - ro) * inv;
    let b = (bmax - ro) * inv;
    let lo = min(a, b);
    let hi = max(a, b);
    return vec2<f32>(max(max(lo.x, lo.y), lo.z), min(min(hi.x, hi.y), hi.z));
}

// Tiling fBm noise in [-0.5, 0.5] at a world point, drifting slowly in time.
// noise_tex holds octaves 1-4 in its RGBA channels (channel c: value noise
// with 2^c times channel r's frequency), so one fetch gives all four;
// octaves 5 and 6 are a second fetch at 16x the frequency (the doubling
// continues), 4 mip levels coarser. The mip level is the footprint of the
// pixel's view cone at p in texels: frame.noise.texels_per_m is the cone's width in
// texels per metre of distance from the eye (0: level 0). The weighted mean
// of the octaves clusters near 0, so it is doubled (then clamped) to use
// the whole range. CPU twin: NoiseVolume::noise3_lod and lod in
// src/noise.rs (tests/cumulus/render/noise.rs compares them on the GPU).
// Cost: on GPUs a per-sample level is free. llvmpipe selects mip levels
// lane by lane when the level differs across lanes, which makes its cloud
// pass ~1.8x slower than with the level fixed at 0 (320x240 render,
// default scene).
fn noise3(p: vec3<f32>) -> f32 {
    let drift = vec3<f32>(1.5, 0.8, 0.3) * frame.camera_pos.time_s;
    let q = (p + drift) * frame.noise.inv_scale_per_m;
    let lod = log2(max(distance(p, frame.camera_pos.eye_m) * frame.noise.texels_per_m, 1.0));
    let octaves = u32(frame.noise.octaves);
    // Weights 2^-c of octave c, zero past the octave count.
    let w = select(vec4<f32>(0.0), vec4<f32>(1.0, 0.5, 0.25, 0.125), vec4<u32>(0u, 1u, 2u, 3u) < vec4<u32>(octaves));
    var sum = dot(w, textureSampleLevel(noise_tex, repeat_sampler, q, lod) - 0.5);
    var norm = w.x + w.y + w.z + w.w;
    if octaves > 4u {
        let w2 = select(vec2<f32>(0.0), vec2<f32>(0.0625, 0.03125), vec2<u32>(4u, 5u) < vec2<u32>(octaves));
        let q2 = q * 16.0 + vec3<f32>(0.17, 0.31, 0.53);
        sum += dot(w2, textureSampleLevel(noise_tex, repeat_sampler, q2, lod + 4.0).rg - 0.5);
        norm += w2.x + w2.y;
    }
    return clamp(2.0 * sum / max(norm, 1e-6), -0.5, 0.5);
}

// Cheap per-pixel hash in [0, 1) (ray start jitter against banding).
fn hash2(p: vec2<f32>) -> f32 {
    let q = fract(p * vec2<f32>(0.1031, 0.1030));
    let r = q + dot(q, q.yx + 33.33);
    return fract((r.x + r.y) * r.x);
}

// Rayleigh phase function. units: 1/sr
fn rayleigh_phase(mu: f32) -> f32 {
    return 3.0 / (16.0 * PI) * (1.0 + mu * mu);
}

// Cornette–Shanks phase function (the sky's aerosols). units: 1/sr
fn mie_phase(mu: f32, g: f32) -> f32 {
    let g2 = g * g;
    return 3.0 / (8.0 * PI) * (1.0 - g2) * (1.0 + mu * mu) / ((2.0 + g2) * pow(max(1.0 + g2 - 2.0 * g * mu, 1e-6), 1.5));
}

// One part (0 Rayleigh, 1 Mie, 2 multiple) of sky-view texel k.
fn sky_texel(k: u32, part: u32) -> vec3<f32> {
    return frame.sky_view[3u * k + part].rgb;
}

// Sky radiance along a direction: the sky-view table of the atmosphere
// model (src/sky/view.rs, Hillaire 2020: single scattering with
// transmittance from a table, multiple scattering Ψ_ms) for the frame's
// sun, bilinear in (azimuth from the sun 0..π, √(elevation/(π/2))); the
// Rayleigh and Mie parts times their phase of the angle to the sun (the
// glow around the sun is the Mie lobe), plus the isotropic multiple part;
// below the horizon, the horizon's radiance darkening toward the ground
// haze. CPU twin: SkyLight::radiance in src/sky/view.rs (the test
// sky::aerial::sky_pass_draws_the_cpu_twin_of_sky_color compares them;
// benches/pathtraced.py mirrors it, compared by
// render::pathtraced::the_path_tracer_s_tone_curve_and_sky_are_the_renderer_s).
fn sky_color(dir: vec3<f32>) -> vec3<f32> {
    let sun = frame.sun_dir;
    let el = asin(clamp(dir.z, 0.0, 1.0));
    let y = sqrt(el / (0.5 * PI)) * f32(SKY_ELEVATIONS - 1u);
    let e = min(u32(y), SKY_ELEVATIONS - 2u);
    let fe = y - f32(e);
    let lens = length(dir.xy) * length(sun.xy);
    let cos_az = select(1.0, dot(dir.xy, sun.xy) / lens, lens > 1e-6);
    let x = acos(clamp(cos_az, -1.0, 1.0)) / PI * f32(SKY_AZIMUTHS - 1u);
    let a = min(u32(x), SKY_AZIMUTHS - 2u);
    let fa = x - f32(a);
    let k = e * SKY_AZIMUTHS + a;
    var part: array<vec3<f32>, 3>;
    for (var i = 0u; i < 3u; i++) {
        let lo = mix(sky_texel(k, i), sky_texel(k + 1u, i), fa);
        let hi = mix(sky_texel(k + SKY_AZIMUTHS, i), sky_texel(k + SKY_AZIMUTHS + 1u, i), fa);
        part[i] = mix(lo, hi, fe);
    }
    let mu = dot(dir, sun);
    let c = part[0] * rayleigh_phase(mu) + part[1] * mie_phase(mu, frame.sky_mie_g) + part[2];
    return c * (1.0 - 0.4 * clamp(-3.0 * dir.z, 0.0, 1.0));
}

// Light arriving from the whole sky on an upward-facing surface, over π
// (the sky's cosine-weighted mean radiance), integrated on the CPU from
// the same sky (src/sky/view.rs).
fn sky_ambient() -> vec3<f32> {
    return frame.sky_ambient;
}

// Radiance of a Lambertian surface of `albedo` with normal n, in the
// clouds' units: the sun's irradiance is 4π·sun_color (the march's source
// is sun_color·4π·phase, src/export/sidecar.rs), so the sunlit part is
// albedo/π · 4π·sun_color·cos = 4·albedo·sun_color·cos, darkened by the
// clouds' shadow; the sky's part is albedo/π times its irradiance (π·
// sky_ambient on an up-facing surface, less on a slope that sees less of
// the sky).
fn lambert(albedo: vec3<f32>, n: vec3<f32>, shadow: f32) -> vec3<f32> {
    let sun = frame.sun_dir;
    let direct = 4.0 * frame.sun_color * max(dot(n, sun), 0.0) * shadow;
    return albedo * (direct + sky_ambient() * (0.6 + 0.4 * n.z));
}

// Albedo of the ground's meadows and of its fields, which terrain.wgsl
// mixes by a large-scale noise (about half and half); the clouds' ground
// bounce (lighting.wgsl) sees their mean. Green grass and crops reflect
// 0.05–0.15 of visible light, most in green.
const MEADOW_ALBEDO: vec3<f32> = vec3<f32>(0.06, 0.10, 0.035);
const FIELD_ALBEDO: vec3<f32> = vec3<f32>(0.10, 0.13, 0.05);

// The one display transform, applied once per frame by tonemap.wgsl to the
// HDR scene target: exposure k (`RenderConfig::tone_exposure` in
// src/config/render.rs, also written to the export sidecar), then a filmic
// curve, then the exact sRGB encoding when the output format does not
// encode itself (ENCODE_SRGB). Its twins: tone_map in
// tests/cumulus/common/hdr.rs (render::cli::exr_is_the_linear_scene_the_png_tone_maps
// compares it with this pass) and in benches/pathtraced.py (compared with
// that one by render::pathtraced::the_path_tracer_s_tone_curve_and_sky_are_the_renderer_s).
fn tone_map(c: vec3<f32>) -> vec3<f32> {
    let t = filmic(max(c, vec3<f32>(0.0)) * frame.exposure);
    if ENCODE_SRGB {
        return srgb_encode(t);
    }
    return t;
}

// Narkowicz's 2015 fit of the ACES reference rendering and output
// transforms, x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14), clamped to
// [0, 1] (its limit is 2.51/2.43). An S-curve: a toe (slope 0.21 at 0)
// keeps sunlit ground and the sky's blue from washing out, and a long
// shoulder (0.80 at x = 1, 0.95 at 3, 1 from 7.2 on) keeps the shading of
// sunlit cloud domes, which are 4–6× the ground's radiance.
fn filmic(x: vec3<f32>) -> vec3<f32> {
    return clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), vec3<f32>(0.0), vec3<f32>(1.0));
}

// The sRGB transfer function (IEC 61966-2-1), linear [0, 1] to encoded.
fn srgb_encode(t: vec3<f32>) -> vec3<f32> {
    let lo = t * 12.92;
    let hi = 1.055 * pow(t, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(hi, lo, t <= vec3<f32>(0.0031308));
}

// Per-pass output hook. Every scene pass (sky, terrain, clouds, composite
// and any new one) draws into the Rgba16Float HDR scene target
// (SCENE_FORMAT in src/gpu/layouts.rs), so a pass returns linear
// radiance and this is the identity; the display transform is tone_map,
// once, at the end. Passes call it so the hook stays in one place.
fn output_color(c: vec3<f32>) -> vec3<f32> {
    return c;
}
