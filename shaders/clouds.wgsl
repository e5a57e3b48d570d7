// Cloud pass (paper §6.2): a full-screen fragment ray-march through the box
// of the cloud grid, evaluating the hypertexture density of density.wgsl
// (eq. 18) at fixed steps (stretched so `max steps` always cross the box),
// stopping at the terrain depth written by the terrain pass.
//
// Lighting per sample: the sun, attenuated by a short light march toward it
// (self-shadowing), with a two-lobe Henyey–Greenstein phase function and a
// cheap multiple-scattering term; plus sky ambient that falls off toward the
// cloud base, so bases are dark. Energy-conserving step integration:
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

// Optical depth toward the sun over `light steps` samples (dimensionless
// density sum × step; × extinction gives the exponent).
fn light_density_sum(p: vec3<f32>) -> f32 {
    let steps = u32(frame.march.z);
    let ds = frame.march.w;
    let sun = frame.sun_dir.xyz;
    var sum = 0.0;
    for (var i = 0u; i < steps; i++) {
        sum += cloud_density(p + sun * (ds * (f32(i) + 0.5)));
    }
    return sum * ds;
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
    let mu = dot(rd, sun);
    let g = frame.noise.z;
    // ×4π: an isotropic phase counts 1, so a lit cloud is about as bright as the sun.
    let phase = 4.0 * PI * mix(henyey_greenstein(mu, g), henyey_greenstein(mu, -0.25), 0.3);
    let base_z = frame.grid_min.z;
    let top_z = grid_max.z;

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
        if GRID_CULLING && cell_list(p).y == 0u {
            // Empty cell: no density until the ray leaves it. Jump to the
            // first sample past its exit, on the same dt lattice, so the
            // samples taken are exactly the brute-force march's.
            let t_exit = t + cell_exit(p, rd);
            k = max(ceil((t_exit - t_first) / dt), k + 1.0);
            continue;
        }
        let rho = cloud_density(p);
        if rho > 1e-3 {
            if first_hit < 0.0 {
                first_hit = t;
            }
            let sigma = rho * sigma_max;
            let od = light_density_sum(p) * sigma_max;
            var sun_light = phase * exp(-od) + 0.2 * exp(-0.25 * od);
            if USE_NORMALS {
                let n = density_normal(p);
                sun_light *= 0.55 + 0.45 * max(dot(n, sun), 0.0);
            }
            let height = clamp((p.z - base_z) / max(top_z - base_z, 1.0), 0.0, 1.0);
            let ambient = sky_ambient() * mix(0.12, 1.0, height);
            let source = frame.sun_color.rgb * sun_light + ambient;
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
