// Aerial perspective: the air between the eye and what a pixel shows (a
// hill, the lake, a cloud, a sprite) dims that object's light and adds its
// own, from the same atmosphere model as the sky (src/sky/air.rs): the
// frame's air table holds, per height, what the air scatters per metre
// (Rayleigh and Mie per unit phase, multiple isotropic) and its extinction.
// The ray marches AIR_STEPS steps from the eye to the object through it,
// its height following the Earth's curve; each step's air is constant and
// integrated exactly (a homogeneous slab). Far hills fade toward the
// horizon sky's colour, blue at noon, red-grey at a low sun. CPU twin:
// SkyLight::aerial_shadowed in src/sky/air.rs (tests/cumulus/sky/aerial.rs
// compares them).
// Imported by the passes that draw objects (terrain, clouds, sprites,
// slices).
//
// The sun's share: each step's single-scattered light is scaled by the
// share of the sun's light that reaches the air there past the clouds (the
// multiply scattered part is left as it is). `aerial_perspective` lets all
// of it through; a pass that knows where the clouds shadow the air (the
// terrain, from its cloud-shadow map) runs the steps itself, `air_step`
// with its own share at each `air_step_point`.

#import "common.wgsl"

// Off (`[render] aerial_perspective = false`): objects keep their own
// light; this code is removed at pipeline creation.
override AERIAL_PERSPECTIVE: bool = true;

// Radius of the Earth (the sky model's). units: m
const AIR_EARTH_RADIUS_M: f32 = 6360000.0;

struct Air {
    light: vec3<f32>,
    transmittance: vec3<f32>,
}

// What no air does: nothing added, everything let through.
fn clear_air() -> Air {
    return Air(vec3<f32>(0.0), vec3<f32>(1.0));
}

// Part (0 Rayleigh, 1 Mie, 2 multiple, 3 extinction) of the air at height
// h (m): linear between the table's nodes at AIR_TOP_M·(k/(N−1))².
fn air_part(x: f32, part: u32) -> vec3<f32> {
    let k = min(u32(x), AIR_HEIGHTS - 2u);
    let f = x - f32(k);
    return mix(frame.air[4u * k + part].rgb, frame.air[4u * (k + 1u) + part].rgb, f);
}

// The march over `dist` (m) along unit `dir` from the eye: what its steps
// share.
struct AirMarch {
    dir: vec3<f32>,
    dt: f32,    // step length (m)
    pr: f32,    // Rayleigh phase of the angle to the sun (1/sr)
    pm: f32,    // Mie phase (1/sr)
    eye_z: f32, // the eye's height above the ground (m)
}

fn air_march(dir: vec3<f32>, dist: f32) -> AirMarch {
    let mu = dot(dir, frame.sun_dir);
    return AirMarch(
        dir,
        dist / f32(AIR_STEPS),
        rayleigh_phase(mu),
        mie_phase(mu, frame.sky_mie_g),
        max(frame.camera_pos.eye_m.z, 0.0),
    );
}

// Distance from the eye to the middle of step i. units: m
fn air_step_t(m: AirMarch, i: u32) -> f32 {
    return (f32(i) + 0.5) * m.dt;
}

// The middle of step i, where a caller takes its share of the sun.
fn air_step_point(m: AirMarch, i: u32) -> vec3<f32> {
    return frame.camera_pos.eye_m + m.dir * air_step_t(m, i);
}

// `air` carried over step i of `m`, where the share `sunlit` of the sun's
// light reaches the air.
fn air_step(air: Air, m: AirMarch, i: u32, sunlit: f32) -> Air {
    let t = air_step_t(m, i);
    let dir = m.dir;
    let eye = m.eye_z;
    // Height above the ground, to second order in t/R (< 10 m off at 200 km).
    let h = eye + dir.z * t + t * t * (1.0 - dir.z * dir.z) / (2.0 * (AIR_EARTH_RADIUS_M + eye));
    let x = sqrt(clamp(h / AIR_TOP_M, 0.0, 1.0)) * f32(AIR_HEIGHTS - 1u);
    let source = (air_part(x, 0u) * m.pr + air_part(x, 1u) * m.pm) * sunlit + air_part(x, 2u);
    let ext = air_part(x, 3u);
    let step = exp(-ext * m.dt);
    var out = air;
    out.light += air.transmittance * source * (1.0 - step) / max(ext, vec3<f32>(1e-12));
    out.transmittance *= step;
    return out;
}

// What the air does over `dist` (m) along unit `dir` from the eye, all of
// the sun's light reaching it.
fn aerial_perspective(dir: vec3<f32>, dist: f32) -> Air {
    let m = air_march(dir, dist);
    var air = clear_air();
    for (var i = 0u; i < AIR_STEPS; i++) {
        air = air_step(air, m, i, 1.0);
    }
    return air;
}

// Premultiplied radiance `c` of coverage `alpha` (1: opaque) seen through
// `air`: its own light dimmed, the air's added where it covers.
fn seen_through(air: Air, c: vec3<f32>, alpha: f32) -> vec3<f32> {
    return c * air.transmittance + air.light * alpha;
}

// What `aerial_perspective` gives, or clear air when it is off.
fn air_toward(dir: vec3<f32>, dist: f32) -> Air {
    if AERIAL_PERSPECTIVE {
        return aerial_perspective(dir, dist);
    }
    return clear_air();
}

// Premultiplied radiance `c` of coverage `alpha` (1: opaque) at `dist` (m)
// along unit `dir`, as the eye sees it through the air.
fn through_air(c: vec3<f32>, alpha: f32, dir: vec3<f32>, dist: f32) -> vec3<f32> {
    if !AERIAL_PERSPECTIVE {
        return c;
    }
    return seen_through(aerial_perspective(dir, dist), c, alpha);
}
