// Terrain pass: the heightfield mesh (procedural fBm or a heightmap PNG,
// built on the CPU by src/landscape/terrain.rs) with depth, lit as a
// Lambertian surface by the sun, darkened by the clouds' transmittance (the
// cloud-shadow map every method's clouds are marched or splatted into,
// shadow.wgsl), and by the sky, seen through the air (air.wgsl), whose
// sunlight the same map shadows.

#import "common.wgsl"
#import "air.wgsl"
// `ground_sun_depth` for ground inside the clouds' region: the method's
// shadow march (the `<ground_shadow>` slot; only the ray-marched clouds
// switch SHADOW_IN_REGION on).
#import <ground_shadow>

// Darken the sun by the clouds (false: no cloud shadows this frame).
override HAS_SHADOWS: bool = true;
// Ray-marched clouds (`baked`, `exact`): ground inside their region (a
// hill among the clouds) marches its own sun ray (density.wgsl
// `ground_sun_depth`, the routine the shadow map's texels run from z = 0),
// so cloud below it casts no shadow on it. False: the map alone (sprites,
// slicing planes).
override SHADOW_IN_REGION: bool = false;
// The mesh has a water plane (`[render.terrain] water_level_m`), whose
// vertices have the normal (0, 0, −1) (src/landscape/terrain.rs WATER_NORMAL).
override HAS_WATER: bool = false;

@group(1) @binding(0) var shadow_tex: texture_2d<f32>;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var o: VertexOut;
    o.clip = frame.clip_from_world * vec4<f32>(v.position, 1.0);
    o.world = v.position;
    o.normal = v.normal;
    return o;
}

// Sun transmittance through the clouds above a terrain point. Below the
// cloud region the map's texel holds the same sun ray's optical depth
// (the ray from the point and from its projection to z = 0 along the sun
// cross the region alike); inside it the point marches its own.
fn cloud_shadow(p: vec3<f32>) -> f32 {
    if !HAS_SHADOWS {
        return 1.0;
    }
    if SHADOW_IN_REGION && p.z > frame.grid_min.z {
        return exp(-ground_sun_depth(p) * frame.extinction_per_m);
    }
    return map_shadow(p, frame.sun_dir);
}

// The share of the sun's light reaching the air at p: the clouds shadow
// it like the ground below it (the map), except within the ray-marched
// clouds' region and above it, where it counts as sunlit.
fn air_sun_share(p: vec3<f32>) -> f32 {
    if !HAS_SHADOWS || (SHADOW_IN_REGION && p.z > frame.grid_min.z) {
        return 1.0;
    }
    return map_shadow(p, frame.sun_dir);
}

// What the air does over `dist` (m) along unit `dir` from the eye, its
// sunlight shadowed by the clouds (air_sun_share at each step).
fn shadowed_air(dir: vec3<f32>, dist: f32) -> Air {
    let m = air_march(dir, dist);
    var air = clear_air();
    for (var i = 0u; i < AIR_STEPS; i++) {
        air = air_step(air, m, i, air_sun_share(air_step_point(m, i)));
    }
    return air;
}

// Transmittance over p from the cloud-shadow map.
fn map_shadow(p: vec3<f32>, sun: vec3<f32>) -> f32 {
    let g = p.xy - p.z * sun.xy / max(sun.z, 0.03);
    let lo = frame.shadow_min;
    let hi = frame.shadow_max;
    let uv = vec2<f32>((g.x - lo.x) / max(hi.x - lo.x, 1.0), (hi.y - g.y) / max(hi.y - lo.y, 1.0));
    if any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0)) {
        return 1.0;
    }
    return textureSampleLevel(shadow_tex, clamp_sampler, uv, 0.0).r;
}

// A lake's surface: dark water (little light comes back up out of it)
// that mirrors the sky by Fresnel's law (Schlick, water's reflectance 0.02
// at normal incidence, all of it at grazing angles), and the sun's glint,
// both in the clouds' shadow. The mirror shows the sky, not the clouds.
fn water(p: vec3<f32>) -> vec3<f32> {
    let v = normalize(frame.camera_pos.eye_m - p);
    let sun = frame.sun_dir;
    let fresnel = 0.02 + 0.98 * pow(1.0 - max(v.z, 0.0), 5.0);
    let shadow = cloud_shadow(p);
    let body = lambert(vec3<f32>(0.01, 0.025, 0.03), vec3<f32>(0.0, 0.0, 1.0), shadow);
    // Glint: a Blinn–Phong lobe of a slightly rippled surface.
    let h = normalize(v + sun);
    let glint = frame.sun_color * shadow * 2.0 * pow(max(h.z, 0.0), 600.0);
    let sky = sky_color(reflect(-v, vec3<f32>(0.0, 0.0, 1.0)));
    return mix(body, sky, fresnel) + fresnel * glint;
}

// Sunlit and sky-lit ground.
fn ground(in: VertexOut) -> vec3<f32> {
    let n = normalize(in.normal);
    // Albedo: meadows and fields on gentle slopes, rock on steep ones,
    // patchy by a large-scale noise lookup: the four packed octaves summed
    // with weights 2^-c (a single octave shows its value-noise lattice), at
    // the mip level the pixel's footprint picks (no aliasing far away).
    let octaves = textureSample(noise_tex, repeat_sampler, vec3<f32>(in.world.xy * 1.1e-3, 0.37));
    let patchiness = dot(octaves, vec4<f32>(8.0, 4.0, 2.0, 1.0) / 15.0);
    let fields = smoothstep(0.35, 0.65, patchiness);
    let meadow = mix(MEADOW_ALBEDO, FIELD_ALBEDO, fields);
    let rock = vec3<f32>(0.22, 0.2, 0.18);
    let steep = smoothstep(0.75, 0.55, n.z);
    let albedo = mix(meadow, rock, steep);
    return lambert(albedo, n, cloud_shadow(in.world));
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    // The ground's textureSample needs uniform control flow: shade it
    // everywhere, then let the water replace it.
    var c = ground(in);
    if HAS_WATER && in.normal.z < 0.0 {
        c = water(in.world);
    }
    // The air between the eye and the ground.
    if AERIAL_PERSPECTIVE {
        let from_eye = in.world - frame.camera_pos.eye_m;
        let dist = length(from_eye);
        c = seen_through(shadowed_air(from_eye / dist, dist), c, 1.0);
    }
    return vec4<f32>(output_color(c), 1.0);
}
