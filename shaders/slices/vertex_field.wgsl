// The slice vertices' field and shadow in a compute pass (Schpok et al.
// 2003 §4.1: "on the CPU (or a compute pass)"), `[render.slices]
// vertex_field = "gpu"`: the same formulas as the CPU reference
// (SliceGeometry::evaluate in src/methods/slices/model/slicing.rs), from implicit.wgsl.
//   cs_field : one invocation per vertex, density = Σ Wyvill blends;
//   cs_shadow: one invocation per light ray (ShadowRays), walking its
//              vertices from the light: shadow += step × density (× the
//              first octave's weight when enabled), eq. 2.

#import "../common.wgsl"
#import "implicit.wgsl"

// FieldJob of src/methods/slices/gpu/gpu_field.rs.
struct FieldJob {
    vertices: u32,
    rays: u32,
    ray_stride: u32,     // vertex index stride between ray starts
    ray_offset: u32,     // vertex index of the first ray's start
    vertex_step: i32,    // vertex index step along a ray
    ray_vertices: i32,   // vertices per ray
    first_octave: i32,   // 1: the shadow weighs the first noise octave
    shadow_step: f32,    // ShadowRays::shadow_step
}

@group(1) @binding(0) var<uniform> job: FieldJob;
// SliceVertex × vertices: position xyz, density, shadow (5 floats each).
@group(1) @binding(1) var<storage, read_write> vertices: array<f32>;

fn vertex_position(i: u32) -> vec3<f32> {
    return vec3<f32>(vertices[5u * i], vertices[5u * i + 1u], vertices[5u * i + 2u]);
}

@compute @workgroup_size(64)
fn cs_field(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x + id.y * 65535u * 64u;
    if i >= job.vertices {
        return;
    }
    vertices[5u * i + 3u] = implicit_field(vertex_position(i));
}

@compute @workgroup_size(64)
fn cs_shadow(@builtin(global_invocation_id) id: vec3<u32>) {
    let r = id.x + id.y * 65535u * 64u;
    if r >= job.rays {
        return;
    }
    var v = i32(r * job.ray_stride + job.ray_offset);
    var shadow = 0.0;
    for (var t = 0; t < job.ray_vertices; t++) {
        let i = u32(v);
        let density = vertices[5u * i + 3u];
        var weight = 1.0;
        if job.first_octave != 0 && density > 0.0 {
            weight = first_octave_weight(vertex_position(i));
        }
        shadow += job.shadow_step * density * weight;
        vertices[5u * i + 4u] = shadow;
        v += job.vertex_step;
    }
}
