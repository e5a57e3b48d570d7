// Lighting of a cloud sample, tuned so clouds read as cumulus (sunlit
// domes bright, bases grey-blue): the sun, attenuated by a short light
// march toward it (the noise detail) and the far light beyond it (the
// `<far_light>` slot: the whole cloud region), through the same medium the
// view rays see, scattered once with a two-lobe Henyey–Greenstein phase
// and many times with a diffusion-like falloff, dimmed where the cloud
// ends behind the sample (`sun_scattering`); plus sky ambient shaded by
// the far light's look upward and, with the multiple scattering, darkened
// toward the sample's condensation plane (the flat base); plus the sunlit
// ground's light from below (without terrain, the sky's lower half), at
// the base. Kept apart from the march (clouds.wgsl) so that a lighting
// model can replace it: the march calls only `ray_lighting` and
// `sample_source`.

#import "../common.wgsl"
#import <field>
#import "density.wgsl"
#import <far_light>

// Finite-difference normals of ρ for extra (voxel) shading: paper Table 1
// "with FDM normals". Off: this code is removed at pipeline creation.
override USE_NORMALS: bool = false;

fn henyey_greenstein(cos_theta: f32, g: f32) -> f32 {
    let g2 = g * g;
    return (1.0 - g2) / (4.0 * PI * pow(1.0 + g2 - 2.0 * g * cos_theta, 1.5));
}

// Growth of the light-march steps: step i is `light step`·LIGHT_GROWTH^i
// long, so a few samples reach across a whole cloud (≈1.4 km with the
// defaults) while the first ones resolve the crisp sunlit edge. The
// bench's light-march length (src/bench/accuracy.rs) uses it too.
const LIGHT_GROWTH: f32 = 1.6;

// Extinction toward the sun over the view rays' extinction: 1, the same
// medium both ways (as the path tracer sees it). A denser light march
// darkens cloud interiors well below the path tracer's.
const LIGHT_DENSITY: f32 = 1.0;

// The phase's back lobe: g and weight in the mix with the forward lobe
// (whose g is the scene's phase_g). The export sidecar gives the path
// tracer these (src/export/sidecar.rs) and LIGHT_DENSITY; a test compares
// the values.
const HG_BACK_G: f32 = -0.3;
const HG_BACK_WEIGHT: f32 = 0.25;

// Height above a cloud's condensation plane over which diffuse light
// recovers from its darkest (at the base) to full. units: m
const BASE_FADE_M: f32 = 500.0;
// The multiply scattered sun at the base, over its value BASE_FADE_M up.
const BASE_MS_FLOOR: f32 = 0.4;

// Upward optical depth over the effective one for the hemisphere's light:
// most skylight arrives slanted, around clouds rather than through them.
const SKY_SOFTENING: f32 = 0.35;

// Short march from p along unit `dir`: up to `steps` samples at the light
// march's steps (the first `frame.light_step_m` long, each LIGHT_GROWTH× the
// one before), the first `detailed` of them with the noise detail and the
// rest of the parcels alone (no texture fetches), stopping once the sum
// reaches `enough`. (density sum × step (× extinction gives the
// exponent), length covered).
fn short_depth(p: vec3<f32>, dir: vec3<f32>, steps: u32, detailed: u32, enough: f32) -> vec2<f32> {
    var ds = frame.light_step_m;
    var t = 0.0;
    var sum = 0.0;
    for (var i = 0u; i < steps && sum < enough; i++) {
        let q = p + dir * (t + 0.5 * ds);
        if i < detailed {
            sum += cloud_density(q) * ds;
        } else {
            sum += coarse_density(q) * ds;
        }
        t += ds;
        ds *= LIGHT_GROWTH;
    }
    return vec2<f32>(sum, t);
}

// Optical depth toward the sun (dimensionless density sum × step; ×
// extinction gives the exponent): a short march of `light steps` samples
// resolves the noise detail near p (only its first step sees the noise:
// past it the detail no longer shows in the shadow), then the light volume
// (the `<far_light>` file's far_light_depth: the parcels alone, over the whole cloud
// region) adds everything beyond, so a tower's top shadows its base and its
// neighbours.
fn light_density_sum(p: vec3<f32>) -> f32 {
    let sun = frame.sun_dir;
    let near = short_depth(p, sun, frame.light_steps, 1u, 3.4e38);
    return near.x + far_light_depth(p + sun * near.y).x;
}

// Samples of the march away from the sun before the light volume takes
// over: four (about 830 m with the default light step, the reach of the
// march toward the sun) find where the cloud ends behind a sample, which
// the light volume's cells (one every four voxels) blur (docs/notes.md,
// "Cloud lighting", compares the counts).
const BEHIND_STEPS: u32 = 4u;
// Behind this much (as 2·falloff·od) the boundary's dimming is under 1 %
// (½·e⁻⁴): the march stops there and the light volume is not read. In
// solid cloud of 0.05 /m that is 112 m, two steps of the default light
// march (90 m, then 144 m).
const BEHIND_ENOUGH: f32 = 4.0;

// Optical depth (as light_density_sum) behind p, away from the sun, up to
// where the boundary's dimming no longer shows; `rate` converts it to
// 2·falloff·od (sun_scattering).
fn behind_density_sum(p: vec3<f32>, rate: f32) -> f32 {
    let away = -frame.sun_dir;
    let enough = BEHIND_ENOUGH / rate;
    let near = short_depth(p, away, BEHIND_STEPS, 0u, enough);
    if near.x >= enough {
        return near.x;
    }
    return near.x + far_behind_depth(p + away * near.y);
}

// How much of the sky a sample sees: transmittance straight up through
// the whole cloud above (the light volume's upward depth), softened
// because skylight arrives from the whole upper hemisphere, not just the
// zenith. Cloud bases, with the whole cloud above them, see little sky and
// turn grey-blue.
fn sky_visibility(p: vec3<f32>) -> f32 {
    return exp(-SKY_SOFTENING * far_light_depth(p).y * frame.extinction_per_m);
}

// Sun light scattered toward the eye at a sample with optical depth `od`
// toward the sun, as (single scattering, multiple scattering):
// - single: the two-lobe Henyey–Greenstein phase (forward lobe g, a weak
//   back lobe) × exp(−od). ×4π: an isotropic phase counts 1, so a lit
//   cloud is about as bright as the sun.
// - multiple: light that has scattered many times inside an albedo-1
//   cloud (the path tracer's) is nearly isotropic and falls off with depth
//   like diffusion, not like exp(−od): the two-stream (Eddington) diffuse
//   transmission of a conservatively scattering slab, 1 / (1 + ¾(1 − ḡ)·od)
//   with ḡ the phase's mean cosine, times MS_GAIN. A powder term takes out
//   part of it within the first mean free paths of the sunlit surface,
//   where the many-times-scattered light has not built up yet.
// MS_GAIN and POWDER were fitted against Mitsuba's volpath (albedo 1, up to
// 64–256 bounces) on the stand-in and fair-weather frames of
// benches/pathtraced.py, where the fit reached mean FLIP 0.030 and 0.044
// (gain 2–4 and powder 0–0.5 all land within 0.005 of that); the falloff
// is the two-stream value, not fitted.
// The phase depends only on the ray (mu): `sun_phase_weights` gives it once
// per ray and `sun_scattering` only adds the per-sample attenuation.
// Brightness of the multiply scattered sun over an isotropic single
// scatter of the unattenuated sun (fitted, see above). The albedo is 1 on
// both sides: cloud droplets absorb about 1e-6 of what they scatter in
// visible light (docs/rendering.md, "Single-scattering albedo"), and the fit against
// the conserving path tracer keeps the sum from making energy.
const MS_GAIN: f32 = 3.5;
// Share of the multiple scattering missing at the sunlit surface (od = 0),
// recovering as 1 − POWDER·exp(−2·od).
const POWDER: f32 = 0.5;
// Share of the multiply scattered light missing where the cloud ends just
// behind the sample, away from the sun, recovering as
// 1 − EXIT_DIP·exp(−2·falloff·od_behind). In diffusion theory the diffuse
// light at a free boundary is about half its value a transport length
// inside: the boundary lets it escape, and nothing beyond scatters it back.
// The falloff used above for depth toward the sun fixes the recovery rate
// (one extrapolation length, ⅔ of a transport length); EXIT_DIP = ½ is the
// boundary's value, not fitted. Without it the lit rims and shaded sides
// of narrow clouds would glow with the multiple scattering of a deep one.
const EXIT_DIP: f32 = 0.5;

// (single-scattering weight 4π·phase(mu), multiple-scattering weight,
// multiple-scattering falloff ¾(1 − ḡ)).
// Rate of the exit term's recovery per optical depth behind the sample:
// 2·falloff, one extrapolation length.
fn exit_rate(w: vec3<f32>) -> f32 {
    return 2.0 * w.z;
}

fn sun_phase_weights(mu: f32) -> vec3<f32> {
    let g = frame.phase_g;
    let phase = mix(henyey_greenstein(mu, g), henyey_greenstein(mu, HG_BACK_G), HG_BACK_WEIGHT);
    let mean_cos = mix(g, HG_BACK_G, HG_BACK_WEIGHT);
    return vec3<f32>(4.0 * PI * phase, MS_GAIN, 0.75 * (1.0 - mean_cos));
}

// `od` toward the sun, `behind` away from it (both optical depths).
fn sun_scattering(w: vec3<f32>, od: f32, behind: f32) -> vec2<f32> {
    let powder = 1.0 - POWDER * exp(-2.0 * od);
    let exit = 1.0 - EXIT_DIP * exp(-exit_rate(w) * behind);
    return vec2<f32>(w.x * exp(-od), w.y * powder * exit / (1.0 + w.z * od));
}

// Outward normal: the tetrahedral 4-tap gradient of the macro field v
// (field_value: one filtered fetch on the baked path, no noise) over half
// a shell: normals cost 1.2–1.6× the cloud pass on llvmpipe (bench frame,
// 85 parcels, 160×120; on against off: mean FLIP 0.026 at 256×192).
// Central differences of ρ (6 cloud_density calls, each with its noise
// fetch) cost about twice that for nearly the same picture: the noise
// octaves finer than the step cannot shape the normal anyway.
fn density_normal(p: vec3<f32>) -> vec3<f32> {
    let h = 0.5 * frame.shell_m;
    let k = vec2<f32>(1.0, -1.0);
    let g = k.xyy * field_value(p + k.xyy * h) + k.yyx * field_value(p + k.yyx * h)
        + k.yxy * field_value(p + k.yxy * h) + k.xxx * field_value(p + k.xxx * h);
    let len = length(g);
    if len < 1e-5 {
        return vec3<f32>(0.0, 0.0, 1.0);
    }
    return -g / len;
}

// Per-ray constants of the lighting (they depend only on the direction).
struct RayLight {
    phase_weights: vec3<f32>,
    sky_base: vec3<f32>,
    bounce: vec3<f32>,
}

// `over_terrain`: a terrain lies below the clouds (else the sky's lower
// half).
fn ray_lighting(rd: vec3<f32>, over_terrain: bool) -> RayLight {
    var l: RayLight;
    l.phase_weights = sun_phase_weights(dot(rd, frame.sun_dir));
    l.sky_base = 0.8 * sky_ambient();
    // Over terrain: the sunlit ground's radiance (the terrain's own
    // Lambert), seen by a cloud base over its lower hemisphere and
    // scattered like the sky's light (0.8 of the mean radiance, as
    // sky_base). The ground taken as sunlit: a cloud's own shadow falls
    // beside its base unless the sun is high, and the wider ground a base
    // sees is mostly in the sun (Mitsuba with the same flat ground,
    // benches/pathtraced.py --ground, gives its clouds a green tint on
    // their shaded sides too). Without terrain, what a cloud sees below
    // it is what the sky pass draws there (and what benches/pathtraced.py
    // gives Mitsuba without --ground): the sky's lower half, the horizon's
    // radiance darkening toward the ground haze (frame.sky_below,
    // integrated on the CPU), scattered the same way.
    if over_terrain {
        let ground_albedo = 0.5 * (MEADOW_ALBEDO + FIELD_ALBEDO);
        l.bounce = 0.8 * lambert(ground_albedo, vec3<f32>(0.0, 0.0, 1.0), 1.0);
    } else {
        l.bounce = 0.8 * frame.sky_below;
    }
    return l;
}

// Light scattered toward the eye per unit extinction at a cloudy sample p
// whose cloud has its condensation plane at `plane_z` (m).
fn sample_source(l: RayLight, p: vec3<f32>, plane_z: f32) -> vec3<f32> {
    let sigma_max = frame.extinction_per_m;
    let od = light_density_sum(p) * sigma_max * LIGHT_DENSITY;
    let rate = exit_rate(l.phase_weights) * sigma_max * LIGHT_DENSITY;
    let behind = behind_density_sum(p, rate) * sigma_max * LIGHT_DENSITY;
    var sun_light = sun_scattering(l.phase_weights, od, behind);
    if USE_NORMALS {
        let n = density_normal(p);
        sun_light *= 0.55 + 0.45 * max(dot(n, frame.sun_dir), 0.0);
    }
    // Diffuse light (skylight and the multiply scattered part of the sun)
    // is weaker the deeper the sample sits toward its cloud's flat base:
    // little of it finds its way down through the cloud above. The
    // skylight is also shaded by a direct look upward. Light bounced off
    // the sunlit ground lights the bases from below, fading over the same
    // BASE_FADE_M as the cloud above shuts the ground out.
    let above_base = clamp((p.z - plane_z) / BASE_FADE_M, 0.0, 1.0);
    // The multiply scattered sun fades more than the skylight, which also
    // reaches the base sideways from the horizon: bases turn blue-grey
    // rather than neutral grey.
    let a2 = above_base * above_base;
    let sky = l.sky_base * mix(0.5, 1.0, a2) * mix(0.5, 1.0, sky_visibility(p));
    let multiple = sun_light.y * mix(BASE_MS_FLOOR, 1.0, a2);
    return frame.sun_color * (sun_light.x + multiple) + sky + l.bounce * (1.0 - a2);
}
