// The slice vertices' field and shadow in a compute pass (Schpok et al.
// 2003 §4.1: "on the CPU (or a compute pass)"), `[render.slices]
// vertex_field = "gpu"`: the same formulas as the CPU reference
// (SliceGeometry::evaluate in src/methods/slices/model/slicing.rs), from implicit.wgsl.
//   cs_field : one invocation per vertex, density = Σ Wyvill blends of
//              its stack's own primitives (its cloud);
//   cs_shadow: one invocation per light ray (every stack's ShadowRays), walking its
//              vertices from the light: shadow += step × density (× the
//              first octave's weight when enabled), eq. 2.

#import "../common.wgsl"
#import "implicit.wgsl"

// Most stacks per frame: MAX_STACKS of src/methods/slices/model/clouds.rs
// (a test compares them).
const MAX_STACKS: u32 = 32u;

// StackJob of src/methods/slices/gpu/gpu_field.rs: one cloud's stack.
struct StackJob {
    first_vertex: u32,
    end_vertex: u32,
    first_ray: u32,
    end_ray: u32,
    ray_stride: u32,     // vertex index stride between ray starts
    ray_offset: u32,     // vertex index of the first ray's start, in the stack
    vertex_step: i32,    // vertex index step along a ray
    ray_vertices: i32,   // vertices per ray
    shadow_step: f32,    // ShadowRays::shadow_step
    first_primitive: u32, // the stack's primitives (its cloud)
    end_primitive: u32,
    _pad: u32,
}

// FieldJob of src/methods/slices/gpu/gpu_field.rs.
struct FieldJob {
    vertices: u32,
    rays: u32,
    stack_count: u32,
    first_octave: i32,   // 1: the shadow weighs the first noise octave
    stacks: array<StackJob, MAX_STACKS>,
}

@group(1) @binding(0) var<uniform> job: FieldJob;
// SliceVertex × vertices: position xyz, density, shadow, plane opacity
// (6 floats each).
@group(1) @binding(1) var<storage, read_write> vertices: array<f32>;

fn vertex_position(i: u32) -> vec3<f32> {
    return vec3<f32>(vertices[6u * i], vertices[6u * i + 1u], vertices[6u * i + 2u]);
}

@compute @workgroup_size(64)
fn cs_field(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x + id.y * 65535u * 64u;
    if i >= job.vertices {
        return;
    }
    var k = 0u;
    while k + 1u < job.stack_count && i >= job.stacks[k].end_vertex {
        k++;
    }
    let s = job.stacks[k];
    vertices[6u * i + 3u] = implicit_field_of(vertex_position(i), s.first_primitive, s.end_primitive);
}

@compute @workgroup_size(64)
fn cs_shadow(@builtin(global_invocation_id) id: vec3<u32>) {
    let r = id.x + id.y * 65535u * 64u;
    if r >= job.rays {
        return;
    }
    var k = 0u;
    while k + 1u < job.stack_count && r >= job.stacks[k].end_ray {
        k++;
    }
    let s = job.stacks[k];
    var v = i32(s.first_vertex + (r - s.first_ray) * s.ray_stride + s.ray_offset);
    var shadow = 0.0;
    for (var t = 0; t < s.ray_vertices; t++) {
        let i = u32(v);
        let density = vertices[6u * i + 3u];
        var weight = 1.0;
        if job.first_octave != 0 && density > 0.0 {
            weight = first_octave_weight(vertex_position(i));
        }
        shadow += s.shadow_step * density * weight;
        vertices[6u * i + 4u] = shadow;
        v += s.vertex_step;
    }
}
