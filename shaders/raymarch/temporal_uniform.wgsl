// The uniform of temporal amortisation (`[render] temporal`), shared by
// the quarter-rate march (clouds.wgsl `cs_temporal`) and the resolve
// (temporal.wgsl); TemporalUniform in src/methods/raymarch/temporal.rs.

struct Temporal {
    prev_clip_from_world: mat4x4<f32>,
    params: vec4<u32>, // x, y: offset of the marched pixel in its 2×2 block; z: frame index; w: history valid
    size: vec4<u32>,   // frame width, height; quarter width, height
}
