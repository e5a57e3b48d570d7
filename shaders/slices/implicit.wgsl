// The authored clouds' field on the GPU (Schpok et al. 2003 §3.1, §3.2,
// Table 2), shared by the slices passes: the slicing planes (their noise
// and media filter), the compute pass that evaluates the field and shadow
// at the slice vertices (vertex_field.wgsl) and, under the `slices`
// method, the cloud-shadow map (shadow_field.wgsl). The CPU twin of every
// routine here is the reference: src/methods/slices/model/ellipsoid.rs (Wyvill blend,
// s², the grid index) and src/methods/slices/gpu/field.rs (tiers, octaves,
// media filters, the first-octave shadow weight); the tests
// render::slices_twin::gpu_slices_density_matches_its_cpu_twin (the
// density) and render::slices::the_compute_pass_gives_the_cpu_vertex_field
// (the vertex field and shadows) compare them.
// The structs below are TierUniform and OctaveUniform of
// src/methods/slices/model/octaves.rs, SlicesParams of src/methods/slices/gpu/mod.rs and
// GpuPrimitive of src/methods/slices/gpu/buffers.rs.

#import "../common.wgsl"

struct SlicesTier {
    texture_from_world: array<mat4x4<f32>, 8>, // per octave; unused are zero
    bottom_m: f32,        // bottom of the tier (m)
    first_weight: f32,    // the first octave's weight
    media: u32,           // media filter id (MediaFilter::gpu_id)
    _pad: u32,
}

struct SlicesOctaves {
    tiers: array<SlicesTier, 4>,
    tier_count: u32,      // tiers in use
    octave_count: u32,    // octaves in use
    _pad: vec2<u32>,
}

struct SlicesParams {
    sharpness: f32,               // alpha cutoff ÷ plane opacity (Table 2)
    _pad2: f32,
    _pad3: f32,
    _pad4: f32,
    cloud_colour: vec3<f32>,      // lit cloud (linear)
    _pad0: f32,
    shadow_colour: vec3<f32>,     // fully shadowed cloud (linear)
    _pad1: f32,
    index_min: vec3<f32>,         // the primitive index's minimum corner (m)
    cells_per_axis: f32,
    index_cell: vec3<f32>,        // its cell size (m)
    shadow_extinction_per_m: f32, // shadow-map extinction per unit density (1/m)
}

// s² = |unit_from_world · (p − centre)|² (EllipsoidState::unit_from_world).
struct Primitive {
    row0: vec3<f32>,   // the rows of unit_from_world
    strength: f32,
    row1: vec3<f32>,
    base_z_m: f32,     // flat base altitude (m)
    row2: vec3<f32>,
    _pad0: f32,
    centre_m: vec3<f32>,
    _pad1: f32,
}

@group(3) @binding(0) var<uniform> octaves: SlicesOctaves;
@group(3) @binding(1) var<uniform> params: SlicesParams;
@group(3) @binding(2) var<storage, read> primitives: array<Primitive>;
// FieldIndex::flatten: n³ + 1 list offsets into this array, then the lists.
@group(3) @binding(3) var<storage, read> cell_lists: array<u32>;

// The tier holding altitude z: the highest whose bottom is at or below z
// (the first tier also covers everything below it).
fn tier_at(z: f32) -> u32 {
    var t = 0u;
    for (var i = 1u; i < octaves.tier_count; i++) {
        if z >= octaves.tiers[i].bottom_m {
            t = i;
        }
    }
    return t;
}

// One octave of the periodic noise volume at `p` through its transform.
fn octave_noise(tier: u32, o: u32, p: vec3<f32>) -> f32 {
    let q = (octaves.tiers[tier].texture_from_world[o] * vec4<f32>(p, 1.0)).xyz;
    return textureSampleLevel(noise_tex, repeat_sampler, q, 0.0).r;
}

// Octaves of the noise at `p`, octave o weighted by the first weight × ½^o
// (persistence ½, normalised on the CPU so the weights sum to 1): the
// composite stays in [0, 1] like each fetch.
fn composite_noise(tier: u32, p: vec3<f32>) -> f32 {
    var w = octaves.tiers[tier].first_weight;
    var sum = 0.0;
    for (var o = 0u; o < octaves.octave_count; o++) {
        sum += w * octave_noise(tier, o, p);
        w *= 0.5;
    }
    return sum;
}

// The media filters of Table 2; ids and formulas as MediaFilter::apply in
// src/config/slices.rs (tests/cumulus/render/slices.rs checks the ids,
// render::slices_twin::gpu_slices_density_matches_its_cpu_twin the
// density they give). n in [0, 1] → [0, 1].
fn media_filter(id: u32, n: f32) -> f32 {
    switch id {
        case 2u: { return 1.0 - 2.0 * abs(n - 0.5); }  // wispy
        case 3u: { return 1.0 / (1.0 + 10.0 * n); }    // cirrus
        default: { return n; }                          // cumulus, stratus
    }
}

// The tier's media filter of the composited octaves at `p`.
fn media_at(p: vec3<f32>) -> f32 {
    let tier = tier_at(p.z);
    return media_filter(octaves.tiers[tier].media, composite_noise(tier, p));
}

// The vertex shadow's weight with the first octave (§4): the media filter
// of the composite with octaves 2 and up at their mean ½, over the filter
// at ½, so the shadow keeps its Dirtiness calibration on average.
// first_octave_weight in src/methods/slices/gpu/field.rs is its CPU twin.
fn first_octave_weight(p: vec3<f32>) -> f32 {
    let tier = tier_at(p.z);
    let w0 = octaves.tiers[tier].first_weight;
    let id = octaves.tiers[tier].media;
    let n = w0 * octave_noise(tier, 0u, p) + (1.0 - w0) * 0.5;
    return media_filter(id, n) / media_filter(id, 0.5);
}

// Wyvill's soft-object blend C(s) of s² (wyvill in src/methods/slices/model/ellipsoid.rs).
fn wyvill(s2: f32) -> f32 {
    if s2 >= 1.0 {
        return 0.0;
    }
    let s4 = s2 * s2;
    return 1.0 - (4.0 / 9.0) * s4 * s2 + (17.0 / 9.0) * s4 - (22.0 / 9.0) * s2;
}

// Σ strength · C(s²) over the primitives listed in p's cell of the index
// (FieldIndex::field), 0 below a primitive's flat base.
fn implicit_field(p: vec3<f32>) -> f32 {
    return implicit_field_of(p, 0u, 0xffffffffu);
}

// implicit_field over the primitives numbered in [first, end) alone: one
// cloud's (a stack's vertices hold their own cloud's field).
fn implicit_field_of(p: vec3<f32>, first: u32, end: u32) -> f32 {
    let n = u32(params.cells_per_axis);
    let q = (p - params.index_min) / params.index_cell;
    if any(q < vec3<f32>(0.0)) || any(q >= vec3<f32>(f32(n))) {
        return 0.0;
    }
    let c = vec3<u32>(q);
    let cell = c.x + n * (c.y + n * c.z);
    var sum = 0.0;
    for (var k = cell_lists[cell]; k < cell_lists[cell + 1u]; k++) {
        let j = cell_lists[k];
        if j < first || j >= end {
            continue;
        }
        let e = primitives[j];
        if p.z < e.base_z_m {
            continue;
        }
        let d = p - e.centre_m;
        let u = vec3<f32>(dot(e.row0, d), dot(e.row1, d), dot(e.row2, d));
        sum += e.strength * wyvill(dot(u, u));
    }
    return sum;
}
