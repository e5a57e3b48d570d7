// The uniform of temporal upscaling (`[render] temporal`), shared by the
// march of one pixel per block (clouds.wgsl `cs_temporal`) and the
// resolve (temporal.wgsl); TemporalUniform in
// src/methods/raymarch/temporal.rs.

struct Temporal {
    prev_clip_from_eye: mat4x4<f32>, // this frame's eye offset → previous clip
    offset: vec2<u32>,   // the marched pixel's offset in its block
    frame_index: u32,
    history_valid: u32,  // 1: the history holds the previous frame
    size: vec2<u32>,     // frame width, height (px)
    fresh: vec2<u32>,    // width, height of the grid of blocks (px)
    block: u32,          // side of a block: 2 or 4 (px)
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}
