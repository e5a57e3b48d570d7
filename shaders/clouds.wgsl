// Cloud pass (paper §6.2): a full-screen ray-march through the box of the
// frame's grid, evaluating the density of density.wgsl (eq. 18) from the
// method's macro field (field_exact.wgsl or field_baked.wgsl) at fixed
// steps (stretched so `max steps` always cross the box), stopping at the
// terrain depth written by the terrain pass, lit by lighting.wgsl.
// Energy-conserving step integration:
// L += T·S·(1 − exp(−σΔt)), T *= exp(−σΔt). Early exit when T drops below
// the threshold (0 disables it). Empty space (the field's `empty_skip`) is
// crossed in one jump to the first sample past it on the same dt lattice,
// so the samples kept are the unskipped march's, same positions. Output is
// premultiplied (rgb = L, a = 1 − T) and blended over the sky/terrain with
// (ONE, ONE_MINUS_SRC_ALPHA) in the HDR scene target. `march` is the one march routine; the
// entry points only supply the pixel: `fs_main` (fragment path) returns it,
// `cs_main` (compute path) stores it into `cloud_out`, which composite.wgsl
// then blends over the target the same way. The march also leaves the
// pixel's cloud depth (the opacity-weighted mean distance of its samples,
// `march_depth`); the compute path stores it in `cloud_depth_out`, and the
// sprites of a frame that has both sort against it (shaders/sprites.wgsl).

// Read the terrain depth (false: no terrain pass, rays run to the box end).
override HAS_TERRAIN: bool = true;

@group(1) @binding(0) var depth_tex: texture_depth_2d;

// Opacity-weighted mean distance of the last march's samples (1e30: no
// cloud on the ray). units: m
var<private> march_depth: f32;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> FullscreenOut {
    return fullscreen_vertex(i);
}

// Premultiplied linear cloud radiance of the pixel at `pix` (pixel
// centre coordinates), whose centre is at `ndc`.
fn march(pix: vec2<f32>, ndc: vec2<f32>) -> vec4<f32> {
    march_depth = 1e30;
    let ro = frame.camera_pos.xyz;
    let rd = view_dir(ndc);
    var t_end = 1e30;
    if HAS_TERRAIN {
        let depth = textureLoad(depth_tex, vec2<i32>(pix), 0);
        if depth < 1.0 {
            t_end = distance(world_from_ndc(ndc, depth), ro);
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
    // Light that does not depend on the sample, hoisted out of the march.
    let light = ray_lighting(rd);

    // Samples sit at t_first + k·dt, k = 0, 1, …
    let t_first = t0 + dt * hash2(pix);
    var k = 0.0;
    var trans = 1.0;
    var radiance = vec3<f32>(0.0);
    var first_hit = -1.0;
    // Σ opacity × distance and Σ opacity, for march_depth.
    var depth_sum = vec2<f32>(0.0);
    for (var i = 0u; i < max_steps; i++) {
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
            let source = sample_source(light, p, vp.y);
            let step_t = exp(-rho * sigma_max * dt);
            radiance += trans * source * (1.0 - step_t);
            depth_sum += trans * (1.0 - step_t) * vec2<f32>(t, 1.0);
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
    march_depth = depth_sum.x / max(depth_sum.y, 1e-30);
    // Aerial perspective, as on the terrain.
    let haze = 1.0 - exp(-first_hit / 60000.0);
    radiance = mix(radiance, haze_color(rd) * (1.0 - trans), haze);
    // Premultiplied linear radiance, blended in linear light over the
    // sky/terrain in the HDR scene target (tone-mapped once, at the end).
    return vec4<f32>(output_color(radiance), 1.0 - trans);
}

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    return march(in.pos.xy, in.ndc);
}

// Compute path: the march's premultiplied colour per pixel.
@group(2) @binding(0) var cloud_out: texture_storage_2d<rgba16float, write>;
@group(2) @binding(1) var cloud_depth_out: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn cs_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(cloud_out);
    if any(gid.xy >= size) {
        return;
    }
    // The pixel centre and its NDC, as the rasteriser gives fs_main.
    let pix = vec2<f32>(gid.xy) + 0.5;
    let ndc = vec2<f32>(2.0 * pix.x / f32(size.x) - 1.0, 1.0 - 2.0 * pix.y / f32(size.y));
    textureStore(cloud_out, gid.xy, march(pix, ndc));
    textureStore(cloud_depth_out, gid.xy, vec4<f32>(march_depth));
}
