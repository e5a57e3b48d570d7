// The uniform of temporal amortisation (`[render] temporal`), shared by
// the quarter-rate march (clouds.wgsl `cs_temporal`) and the resolve
// (temporal.wgsl); TemporalUniform in src/methods/raymarch/temporal.rs.

struct Temporal {
    prev_clip_from_world: mat4x4<f32>,
    offset: vec2<u32>,   // the marched pixel's offset in its 2×2 block
    frame_index: u32,
    history_valid: u32,  // 1: the history holds the previous frame
    size: vec2<u32>,     // frame width, height (px)
    quarter: vec2<u32>,  // quarter-size width, height (px)
}
