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
    counts: vec4<u32>, // x: vertices; y: rays; z: ray start stride; w: ray start offset
    walk: vec4<i32>,   // x: vertex step along a ray; y: vertices per ray; z: first octave (1) or not (0)
    scale: vec4<f32>,  // x: shadow step (ShadowRays::shadow_step)
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
    if i >= job.counts.x {
        return;
    }
    vertices[5u * i + 3u] = implicit_field(vertex_position(i));
}

@compute @workgroup_size(64)
fn cs_shadow(@builtin(global_invocation_id) id: vec3<u32>) {
    let r = id.x + id.y * 65535u * 64u;
    if r >= job.counts.y {
        return;
    }
    var v = i32(r * job.counts.z + job.counts.w);
    var shadow = 0.0;
    for (var t = 0; t < job.walk.y; t++) {
        let i = u32(v);
        let density = vertices[5u * i + 3u];
        var weight = 1.0;
        if job.walk.z != 0 && density > 0.0 {
            weight = first_octave_weight(vertex_position(i));
        }
        shadow += job.scale.x * density * weight;
        vertices[5u * i + 4u] = shadow;
        v += job.walk.x;
    }
}
