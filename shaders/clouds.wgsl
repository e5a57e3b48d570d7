// Cloud pass (paper §6.2): a full-screen fragment ray-march through the box
// of the cloud grid, evaluating the hypertexture density of density.wgsl
// (eq. 18) at fixed steps (stretched so `max steps` always cross the box),
// stopping at the terrain depth written by the terrain pass.
//
// Lighting per sample, tuned so clouds read as cumulus (sunlit domes
// bright, bases grey-blue): the sun, attenuated by a light march toward it
// whose steps grow geometrically (so it crosses a whole cloud) with a denser
// medium than the view rays see, scattered with a two-lobe Henyey–Greenstein
// phase in three multiple-scattering octaves; plus sky ambient shaded by a
// cheap look upward and, with the multiple scattering, darkened toward the
// sample's condensation plane (the flat base); plus a little ground bounce.
// Energy-conserving step integration:
// L += T·S·(1 − exp(−σΔt)), T *= exp(−σΔt). Early exit when T drops below
// the threshold (0 disables it). With GRID_CULLING, empty grid cells are
// skipped whole (the samples kept are the brute-force march's, same
// positions). Output is premultiplied (rgb = L, a = 1 − T)
// and blended over the sky/terrain with (ONE, ONE_MINUS_SRC_ALPHA).

// Finite-difference normals of ρ for extra (voxel) shading: paper Table 1
// "with FDM normals". Off: this code is removed at pipeline creation.
override USE_NORMALS: bool = false;
// Read the terrain depth (false: no terrain pass, rays run to the box end).
override HAS_TERRAIN: bool = true;

@group(1) @binding(0) var depth_tex: texture_depth_2d;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> FullscreenOut {
    return fullscreen_vertex(i);
}

fn henyey_greenstein(cos_theta: f32, g: f32) -> f32 {
    let g2 = g * g;
    return (1.0 - g2) / (4.0 * PI * pow(1.0 + g2 - 2.0 * g * cos_theta, 1.5));
}

// Growth of the light-march steps: step i is `light step`·LIGHT_GROWTH^i
// long, so a few samples reach across a whole cloud (≈1.4 km with the
// defaults) while the first ones resolve the crisp sunlit edge.
const LIGHT_GROWTH: f32 = 1.6;

// Extinction toward the sun over the view rays' extinction: the soft,
// noise-eroded edges the view rays need would let the sun through too
// easily; real cumulus is optically thicker (σ ≈ 0.05–0.1 m⁻¹) than what
// reads well along view rays.
const LIGHT_DENSITY: f32 = 2.5;

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

// Density of the parcels alone (no noise: no texture fetches), for the
// coarse look upward that shades the sky ambient.
fn coarse_density(p: vec3<f32>) -> f32 {
    return smoothstep(0.0, 1.0, macro_value(p));
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
        a *= 0.45;
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
        b *= 0.3;
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

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    let ro = frame.camera_pos.xyz;
    let rd = view_dir(in.ndc);
    var t_end = 1e30;
    if HAS_TERRAIN {
        let depth = textureLoad(depth_tex, vec2<i32>(in.pos.xy), 0);
        if depth < 1.0 {
            t_end = distance(world_from_ndc(in.ndc, depth), ro);
        }
    }
    let grid_max = frame.grid_min.xyz + frame.grid_cell.xyz * vec3<f32>(frame.grid_dims.xyz);
    let span = ray_box(ro, rd, frame.grid_min.xyz, grid_max);
    let t0 = max(span.x, 0.0);
    let t1 = min(span.y, t_end);
    if t1 <= t0 {
        return vec4<f32>(0.0);
    }
    let max_steps = u32(frame.march.y);
    let dt = max(frame.march.x, (t1 - t0) / f32(max_steps));
    let sigma_max = frame.cloud.z;
    let sun = frame.sun_dir.xyz;
    let octave_weights = sun_octave_weights(dot(rd, sun));
    // Light that does not depend on the sample, hoisted out of the march.
    let sky_base = 0.8 * sky_ambient();
    let bounce = vec3<f32>(0.03, 0.033, 0.024) * frame.sun_dir.z * frame.sun_color.rgb;

    // Samples sit at t_first + k·dt, k = 0, 1, …
    let t_first = t0 + dt * hash2(in.pos.xy);
    var k = 0.0;
    var trans = 1.0;
    var radiance = vec3<f32>(0.0);
    var first_hit = -1.0;
    for (var i = 0u; i < max_steps; i++) {
        let t = t_first + k * dt;
        if t >= t1 {
            break;
        }
        let p = ro + rd * t;
        var list = vec2<u32>(0u);
        if GRID_CULLING {
            list = cell_list(p);
            if list.y == 0u {
                // Empty cell: no density until the ray leaves it. Jump to the
                // first sample past its exit, on the same dt lattice, so the
                // samples taken are exactly the brute-force march's.
                let t_exit = t + cell_exit(p, rd);
                k = max(ceil((t_exit - t_first) / dt), k + 1.0);
                continue;
            }
        }
        // The same ρ as cloud_density, with the base plane of the sample's cloud.
        let vp = macro_value_plane(p, list);
        var rho = 0.0;
        if vp.x + 0.5 * frame.cloud.x > 0.0 {
            rho = smoothstep(0.0, 1.0, vp.x + frame.cloud.x * noise3(p));
        }
        if rho > 1e-3 {
            if first_hit < 0.0 {
                first_hit = t;
            }
            let sigma = rho * sigma_max;
            let od = light_density_sum(p) * sigma_max * LIGHT_DENSITY;
            var sun_light = sun_scattering(octave_weights, od);
            if USE_NORMALS {
                let n = density_normal(p);
                sun_light *= 0.55 + 0.45 * max(dot(n, sun), 0.0);
            }
            // Diffuse light (skylight and the multiply scattered part of
            // the sun) is weaker the deeper the sample sits toward its
            // cloud's flat base: little of it finds its way down through
            // the cloud above. The skylight is also shaded by a direct look
            // upward. A little light bounced off the sunlit ground reaches
            // the bases from below.
            let above_base = clamp((p.z - vp.y) / BASE_FADE_M, 0.0, 1.0);
            // The multiply scattered sun fades more than the skylight, which
            // also reaches the base sideways from the horizon: bases turn
            // blue-grey rather than neutral grey.
            let a2 = above_base * above_base;
            let sky = sky_base * mix(0.5, 1.0, a2) * mix(0.5, 1.0, sky_visibility(p));
            let multiple = sun_light.y * mix(0.1, 1.0, a2);
            let source = frame.sun_color.rgb * (sun_light.x + multiple) + sky + bounce;
            let step_t = exp(-sigma * dt);
            radiance += trans * source * (1.0 - step_t);
            trans *= step_t;
            if trans < frame.cloud.w {
                break;
            }
        }
        k += 1.0;
    }
    if first_hit < 0.0 {
        return vec4<f32>(0.0);
    }
    // Aerial perspective, as on the terrain.
    let haze = 1.0 - exp(-first_hit / 60000.0);
    radiance = mix(radiance, haze_color(rd) * (1.0 - trans), haze);
    let alpha = 1.0 - trans;
    // Tone-map the un-premultiplied colour, then premultiply.
    let color = output_color(radiance / max(alpha, 1e-4)) * alpha;
    return vec4<f32>(color, alpha);
}
