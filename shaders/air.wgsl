// Aerial perspective: the air between the eye and what a pixel shows (a
// hill, the lake, a cloud, a sprite) dims that object's light and adds its
// own, from the same atmosphere model as the sky (src/sky/air.rs): the
// frame's air table holds, per height, what the air scatters per metre
// (Rayleigh and Mie per unit phase, multiple isotropic) and its extinction.
// The ray marches AIR_STEPS steps from the eye to the object through it,
// its height following the Earth's curve; each step's air is constant and
// integrated exactly (a homogeneous slab). Far hills fade toward the
// horizon sky's colour, blue at noon, red-grey at a low sun. CPU twin:
// SkyLight::aerial in src/sky/air.rs (keep in sync).
// Included by the passes that draw objects (terrain, clouds, sprites,
// slices).

// Off (`[render] aerial_perspective = false`): objects keep their own
// light; this code is removed at pipeline creation.
//
// Every pass that includes this file defines `air_sunlit(p) -> f32`: the
// share of the sun's light that reaches the air at p past the clouds (the
// terrain reads its cloud-shadow map, so air under an overcast or a cloud
// shadow scatters no sunlight; the other passes have no map and return 1).
// The multiply scattered part is left as it is.
override AERIAL_PERSPECTIVE: bool = true;

// Radius of the Earth (the sky model's). units: m
const AIR_EARTH_RADIUS_M: f32 = 6360000.0;

struct Air {
    light: vec3<f32>,
    transmittance: vec3<f32>,
}

// Part (0 Rayleigh, 1 Mie, 2 multiple, 3 extinction) of the air at height
// h (m): linear between the table's nodes at AIR_TOP_M·(k/(N−1))².
fn air_part(x: f32, part: u32) -> vec3<f32> {
    let k = min(u32(x), AIR_HEIGHTS - 2u);
    let f = x - f32(k);
    return mix(frame.air[4u * k + part].rgb, frame.air[4u * (k + 1u) + part].rgb, f);
}

// What the air does over `dist` (m) along unit `dir` from the eye.
fn aerial_perspective(dir: vec3<f32>, dist: f32) -> Air {
    let mu = dot(dir, frame.sun_dir.xyz);
    let pr = rayleigh_phase(mu);
    let pm = mie_phase(mu, frame.sky_ambient.w);
    let dt = dist / f32(AIR_STEPS);
    let eye = max(frame.camera_pos.z, 0.0);
    var air: Air;
    air.light = vec3<f32>(0.0);
    air.transmittance = vec3<f32>(1.0);
    for (var i = 0u; i < AIR_STEPS; i++) {
        let t = (f32(i) + 0.5) * dt;
        // Height above the ground, to second order in t/R (< 10 m off at 200 km).
        let h = eye + dir.z * t + t * t * (1.0 - dir.z * dir.z) / (2.0 * (AIR_EARTH_RADIUS_M + eye));
        let x = sqrt(clamp(h / AIR_TOP_M, 0.0, 1.0)) * f32(AIR_HEIGHTS - 1u);
        let sunlit = air_sunlit(frame.camera_pos.xyz + dir * t);
        let source = (air_part(x, 0u) * pr + air_part(x, 1u) * pm) * sunlit + air_part(x, 2u);
        let ext = air_part(x, 3u);
        let step = exp(-ext * dt);
        air.light += air.transmittance * source * (1.0 - step) / max(ext, vec3<f32>(1e-12));
        air.transmittance *= step;
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
    return Air(vec3<f32>(0.0), vec3<f32>(1.0));
}

// Premultiplied radiance `c` of coverage `alpha` (1: opaque) at `dist` (m)
// along unit `dir`, as the eye sees it through the air.
fn through_air(c: vec3<f32>, alpha: f32, dir: vec3<f32>, dist: f32) -> vec3<f32> {
    if !AERIAL_PERSPECTIVE {
        return c;
    }
    return seen_through(aerial_perspective(dir, dist), c, alpha);
}
