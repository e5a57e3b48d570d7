// Lighting of a cloud sample, tuned so clouds read as cumulus (sunlit
// domes bright, bases grey-blue): the sun, attenuated by a light march
// toward it whose steps grow geometrically (so it crosses a whole cloud)
// through the same medium the view rays see, scattered with a two-lobe
// Henyey–Greenstein phase in three multiple-scattering octaves; plus sky
// ambient shaded by a cheap look upward and, with the multiple scattering,
// darkened toward the sample's condensation plane (the flat base); plus a
// little ground bounce. Kept apart from the march (clouds.wgsl) so that a
// lighting model (e.g. a light volume) can replace it: the march calls only
// `ray_lighting` and `sample_source`.

// Finite-difference normals of ρ for extra (voxel) shading: paper Table 1
// "with FDM normals". Off: this code is removed at pipeline creation.
override USE_NORMALS: bool = false;

fn henyey_greenstein(cos_theta: f32, g: f32) -> f32 {
    let g2 = g * g;
    return (1.0 - g2) / (4.0 * PI * pow(1.0 + g2 - 2.0 * g * cos_theta, 1.5));
}

// Growth of the light-march steps: step i is `light step`·LIGHT_GROWTH^i
// long, so a few samples reach across a whole cloud (≈1.4 km with the
// defaults) while the first ones resolve the crisp sunlit edge.
const LIGHT_GROWTH: f32 = 1.6;

// Extinction toward the sun over the view rays' extinction: 1, the same
// medium both ways (as the path tracer sees it). A denser light march
// (2.5 before) darkened cloud interiors well below the path tracer's.
const LIGHT_DENSITY: f32 = 1.0;

// Multiple-scattering octaves (Wrenninge 2013, Hillaire 2016): octave j
// has brightness OCTAVE_A^j and sees the optical depth × OCTAVE_B^j.
// OCTAVE_A ≤ OCTAVE_B keeps the sum energy conserving (the octaves never
// scatter more than the medium received).
const OCTAVE_A: f32 = 0.7;
const OCTAVE_B: f32 = 0.7;

// Height above a cloud's condensation plane over which diffuse light
// recovers from its darkest (at the base) to full. units: m
const BASE_FADE_M: f32 = 500.0;

// Optical depth toward the sun (dimensionless density sum × step; ×
// extinction gives the exponent).
fn light_density_sum(p: vec3<f32>) -> f32 {
    let steps = u32(frame.march.z);
    var ds = frame.march.w;
    let sun = frame.sun_dir.xyz;
    var t = 0.0;
    var sum = 0.0;
    for (var i = 0u; i < steps; i++) {
        let q = p + sun * (t + 0.5 * ds);
        // Past the first step the noise detail no longer shows in the
        // shadow: the parcels alone (no texture fetches) are cheaper.
        if i < 1u {
            sum += cloud_density(q) * ds;
        } else {
            sum += coarse_density(q) * ds;
        }
        t += ds;
        ds *= LIGHT_GROWTH;
    }
    return sum;
}

// How much of the sky a sample sees: transmittance of a cheap two-sample
// march straight up (150 m and 600 m), softened because skylight arrives
// from the whole upper hemisphere, not just the zenith. Cloud bases, with
// the whole cloud above them, see little sky and turn grey-blue.
fn sky_visibility(p: vec3<f32>) -> f32 {
    let up = vec3<f32>(0.0, 0.0, 1.0);
    let od = coarse_density(p + up * 150.0) * 300.0 + coarse_density(p + up * 600.0) * 600.0;
    return exp(-0.35 * od * frame.cloud.z);
}

// Sun light scattered toward the eye at a sample with optical depth `od`
// toward the sun: a sum of three scattering "octaves" (Wrenninge's
// multiple-scattering approximation: each octave is dimmer, sees a thinner
// medium and a more isotropic phase), each with a two-lobe Henyey–Greenstein
// phase (forward lobe g, a weak back lobe). ×4π: an isotropic phase counts
// 1, so a lit cloud is about as bright as the sun.
// The phases depend only on the ray (mu), so `sun_octave_weights` gives each
// octave's brightness × phase once per ray and `sun_scattering` only adds
// the per-sample attenuation.
fn sun_octave_weights(mu: f32) -> vec3<f32> {
    let g = frame.noise.z;
    var a = 1.0;
    var c = 1.0;
    var w = vec3<f32>(0.0);
    for (var j = 0; j < 3; j++) {
        let phase = mix(henyey_greenstein(mu, g * c), henyey_greenstein(mu, -0.2 * c), 0.25);
        w[j] = a * 4.0 * PI * phase;
        a *= OCTAVE_A;
        c *= 0.5;
    }
    return w;
}

// Returns (single scattering, multiple scattering) for octave weights `w`.
fn sun_scattering(w: vec3<f32>, od: f32) -> vec2<f32> {
    var b = 1.0;
    var sum = vec2<f32>(0.0);
    for (var j = 0; j < 3; j++) {
        let term = w[j] * exp(-b * od);
        if j == 0 {
            sum.x += term;
        } else {
            sum.y += term;
        }
        b *= OCTAVE_B;
    }
    return sum;
}

// Outward normal from central differences of ρ.
fn density_normal(p: vec3<f32>) -> vec3<f32> {
    let h = 0.5 * frame.cloud.y;
    let g = vec3<f32>(
        cloud_density(p + vec3<f32>(h, 0.0, 0.0)) - cloud_density(p - vec3<f32>(h, 0.0, 0.0)),
        cloud_density(p + vec3<f32>(0.0, h, 0.0)) - cloud_density(p - vec3<f32>(0.0, h, 0.0)),
        cloud_density(p + vec3<f32>(0.0, 0.0, h)) - cloud_density(p - vec3<f32>(0.0, 0.0, h)),
    );
    let len = length(g);
    if len < 1e-5 {
        return vec3<f32>(0.0, 0.0, 1.0);
    }
    return -g / len;
}

// Per-ray constants of the lighting (they depend only on the direction).
struct RayLight {
    octave_weights: vec3<f32>,
    sky_base: vec3<f32>,
    bounce: vec3<f32>,
}

fn ray_lighting(rd: vec3<f32>) -> RayLight {
    var l: RayLight;
    l.octave_weights = sun_octave_weights(dot(rd, frame.sun_dir.xyz));
    l.sky_base = 0.8 * sky_ambient();
    l.bounce = vec3<f32>(0.03, 0.033, 0.024) * frame.sun_dir.z * frame.sun_color.rgb;
    return l;
}

// Light scattered toward the eye per unit extinction at a cloudy sample p
// whose cloud has its condensation plane at `plane_z` (m).
fn sample_source(l: RayLight, p: vec3<f32>, plane_z: f32) -> vec3<f32> {
    let sigma_max = frame.cloud.z;
    let od = light_density_sum(p) * sigma_max * LIGHT_DENSITY;
    var sun_light = sun_scattering(l.octave_weights, od);
    if USE_NORMALS {
        let n = density_normal(p);
        sun_light *= 0.55 + 0.45 * max(dot(n, frame.sun_dir.xyz), 0.0);
    }
    // Diffuse light (skylight and the multiply scattered part of the sun)
    // is weaker the deeper the sample sits toward its cloud's flat base:
    // little of it finds its way down through the cloud above. The
    // skylight is also shaded by a direct look upward. A little light
    // bounced off the sunlit ground reaches the bases from below.
    let above_base = clamp((p.z - plane_z) / BASE_FADE_M, 0.0, 1.0);
    // The multiply scattered sun fades more than the skylight, which also
    // reaches the base sideways from the horizon: bases turn blue-grey
    // rather than neutral grey.
    let a2 = above_base * above_base;
    let sky = l.sky_base * mix(0.5, 1.0, a2) * mix(0.5, 1.0, sky_visibility(p));
    let multiple = sun_light.y * mix(0.4, 1.0, a2);
    return frame.sun_color.rgb * (sun_light.x + multiple) + sky + l.bounce;
}
