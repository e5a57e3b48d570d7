// Terrain pass: the heightfield mesh (procedural fBm or a heightmap PNG,
// built on the CPU by src/render/terrain.rs) with depth, lit by the sun
// (Lambert, darkened by the clouds' transmittance: the light volume for
// `baked` clouds, the cloud-shadow map for `exact` clouds and for sprites)
// and the sky, fading into haze.

// Darken the sun by the clouds (false: no cloud shadows this frame).
override HAS_SHADOWS: bool = true;
// Where the clouds' transmittance comes from (both may hold; they
// multiply): the `baked` method's light volume (field_baked.wgsl, the same
// optical depth toward the sun that lights the clouds), and the shadow map
// (shadow.wgsl's `exact` march and the sprites splatted into it).
override SHADOW_FROM_VOLUME: bool = false;
override SHADOW_FROM_MAP: bool = true;
// The mesh has a water plane (`[render.terrain] water_level_m`), whose
// vertices have the normal (0, 0, −1) (src/render/terrain.rs WATER_NORMAL).
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

// Sun transmittance through the clouds above a terrain point.
fn cloud_shadow(p: vec3<f32>) -> f32 {
    if !HAS_SHADOWS {
        return 1.0;
    }
    let sun = frame.sun_dir.xyz;
    var t = 1.0;
    if SHADOW_FROM_VOLUME {
        t = volume_shadow(p, sun);
    }
    if SHADOW_FROM_MAP {
        t *= map_shadow(p, sun);
    }
    return t;
}

// Transmittance of the baked clouds over p, from the light volume.
fn volume_shadow(p: vec3<f32>, sun: vec3<f32>) -> f32 {
    // The light volume holds, at each point of the cloud region, the
    // optical depth from there to the region's edge toward the sun.
    // Below the region (hills under the clouds) the point's own sun
    // ray enters it at the bottom face (or a side): read it there; a
    // point inside the region (a mountain among the clouds) reads its
    // own height. Same extinction as the clouds' light (LIGHT_DENSITY
    // of lighting.wgsl is 1: the same medium).
    let region_max = frame.grid_min.xyz + frame.grid_cell.xyz * vec3<f32>(frame.grid_dims.xyz);
    let span = ray_box(p, sun, frame.grid_min.xyz, region_max);
    let t0 = max(span.x, 0.0);
    if span.y <= t0 {
        return 1.0;
    }
    return exp(-far_light_depth(p + sun * t0).x * frame.cloud.z);
}

// Transmittance over p from the cloud-shadow map.
fn map_shadow(p: vec3<f32>, sun: vec3<f32>) -> f32 {
    let g = p.xy - p.z * sun.xy / max(sun.z, 0.03);
    let r = frame.shadow_rect;
    let uv = vec2<f32>((g.x - r.x) / max(r.z - r.x, 1.0), (r.w - g.y) / max(r.w - r.y, 1.0));
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
    let v = normalize(frame.camera_pos.xyz - p);
    let sun = frame.sun_dir.xyz;
    let fresnel = 0.02 + 0.98 * pow(1.0 - max(v.z, 0.0), 5.0);
    let shadow = cloud_shadow(p);
    let body = vec3<f32>(0.01, 0.025, 0.03) * (sky_ambient() + frame.sun_color.rgb * max(sun.z, 0.0) * shadow);
    // Glint: a Blinn–Phong lobe of a slightly rippled surface.
    let h = normalize(v + sun);
    let glint = frame.sun_color.rgb * shadow * 2.0 * pow(max(h.z, 0.0), 600.0);
    let sky = sky_color(reflect(-v, vec3<f32>(0.0, 0.0, 1.0)));
    return mix(body, sky, fresnel) + fresnel * glint;
}

// Sunlit and sky-lit ground.
fn ground(in: VertexOut) -> vec3<f32> {
    let n = normalize(in.normal);
    let sun = frame.sun_dir.xyz;
    // Albedo: meadows and fields on gentle slopes, rock on steep ones,
    // patchy by a large-scale noise lookup: the four packed octaves summed
    // with weights 2^-c (a single octave shows its value-noise lattice), at
    // the mip level the pixel's footprint picks (no aliasing far away).
    let octaves = textureSample(noise_tex, repeat_sampler, vec3<f32>(in.world.xy * 1.1e-3, 0.37));
    let patchiness = dot(octaves, vec4<f32>(8.0, 4.0, 2.0, 1.0) / 15.0);
    let fields = smoothstep(0.35, 0.65, patchiness);
    let meadow = mix(vec3<f32>(0.06, 0.10, 0.035), vec3<f32>(0.13, 0.15, 0.06), fields);
    let rock = vec3<f32>(0.22, 0.2, 0.18);
    let steep = smoothstep(0.75, 0.55, n.z);
    let albedo = mix(meadow, rock, steep);
    let direct = frame.sun_color.rgb * max(dot(n, sun), 0.0) * cloud_shadow(in.world);
    let ambient = sky_ambient() * (0.6 + 0.4 * n.z);
    return albedo * (direct + ambient);
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    // The ground's textureSample needs uniform control flow: shade it
    // everywhere, then let the water replace it.
    var c = ground(in);
    if HAS_WATER && in.normal.z < 0.0 {
        c = water(in.world);
    }
    // Aerial perspective: fade into haze over ~60 km.
    let to_eye = in.world - frame.camera_pos.xyz;
    let dist = length(to_eye);
    let haze = 1.0 - exp(-dist / 60000.0);
    c = mix(c, haze_color(to_eye / dist), haze);
    return vec4<f32>(output_color(c), 1.0);
}
