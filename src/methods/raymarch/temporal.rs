//! Temporal amortisation of the cloud march (`[render] temporal`): each
//! frame marches one pixel of every 2×2 block (clouds.wgsl `cs_temporal`,
//! the block offset stepping through a 2×2 Bayer order, so four frames
//! cover every pixel), and the resolve pass (shaders/raymarch/temporal.wgsl)
//! reprojects the previous frame's cloud image with the camera's motion
//! at the clouds' depth, clamps it to the fresh samples around each pixel
//! and accumulates. The composite then blends the result like the compute
//! march's image. None of this exists when the switch is off.
//!
//! Resources: quarter-size fresh colour and depth; two full-size history
//! pairs (colour, samples) used in turn (frame k reads pair k mod 2 and
//! writes the other, which the composite reads); one uniform.

use glam::Mat4;

use super::passes::{TEMPORAL_IN, TEMPORAL_OUT};
use crate::gpu::layouts::{CLOUD_TARGET_FORMAT, Layouts, TEMPORAL_SCALAR_FORMAT, TEXTURE_IN};

use crate::gpu::resources::{bind_in_order, texture_2d};

/// The marched pixel's offset in its 2×2 block, frame by frame: a 2×2
/// Bayer (ordered-dither) order, so consecutive frames are diagonal, not
/// neighbours, and any two consecutive frames cover both rows and columns.
pub const BAYER_2X2: [[u32; 2]; 4] = [[0, 0], [1, 1], [1, 0], [0, 1]];

/// The uniform of the temporal march and resolve: `struct Temporal` in
/// shaders/raymarch/temporal_uniform.wgsl (a test compares the layouts).
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct TemporalUniform {
    /// The previous frame's world → clip (the current one's when there is
    /// no history).
    pub prev_clip_from_world: [[f32; 4]; 4],
    /// The marched pixel's offset in its 2×2 block.
    pub offset: [u32; 2],
    pub frame_index: u32,
    /// 1 when the history holds the previous frame.
    pub history_valid: u32,
    /// Frame width and height. units: px
    pub size: [u32; 2],
    /// Quarter-size width and height. units: px
    pub quarter: [u32; 2],
}

const _: () = assert!(std::mem::size_of::<TemporalUniform>() == 96);

/// The quarter-size grid of blocks of a `w`×`h` frame.
pub fn quarter_size(w: u32, h: u32) -> (u32, u32) {
    (w.div_ceil(2), h.div_ceil(2))
}

/// The temporal path's GPU resources and its frame-to-frame state.
pub struct TemporalGpu {
    uniform: wgpu::Buffer,
    /// Group 2 of `cs_temporal`.
    pub march_bind: wgpu::BindGroup,
    /// Group 1 of the resolve, by the frame's parity.
    resolve_bind: [wgpu::BindGroup; 2],
    /// Group 1 of the composite (the resolved image), by parity.
    composite_bind: [wgpu::BindGroup; 2],
    /// Frame size. units: px
    pub size: (u32, u32),
    /// Frames drawn on this path since the history was made.
    pub frame_index: u32,
    /// The history holds the previous frame (false: first frame, or after
    /// a change of settings or a frame without clouds).
    pub history_valid: bool,
    prev_clip_from_world: Mat4,
    /// This frame's world → clip, set by `prepare`, kept by `finish_frame`.
    current_clip_from_world: Mat4,
}

impl TemporalGpu {
    pub fn new(device: &wgpu::Device, layouts: &Layouts, width: u32, height: u32) -> Self {
        let (qw, qh) = quarter_size(width, height);
        let usage = wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING;
        let view = |label, w, h, format| {
            texture_2d(device, label, w, h, format, usage).create_view(&Default::default())
        };
        let fresh = view("temporal: fresh colour", qw, qh, CLOUD_TARGET_FORMAT);
        let depth = view("temporal: fresh depth", qw, qh, TEMPORAL_SCALAR_FORMAT);
        let color = [0, 1].map(|_| view("temporal: colour", width, height, CLOUD_TARGET_FORMAT));
        let samples =
            [0, 1].map(|_| view("temporal: samples", width, height, TEMPORAL_SCALAR_FORMAT));
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("temporal uniform"),
            size: std::mem::size_of::<TemporalUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind = |label, layout, resources| bind_in_order(device, label, layout, resources);
        let (out_layout, in_layout) = (layouts.get(&TEMPORAL_OUT), layouts.get(&TEMPORAL_IN));
        let texture_layout = layouts.get(&TEXTURE_IN);
        use wgpu::BindingResource::TextureView as Tex;
        let march_bind = bind(
            "temporal: march outputs",
            &out_layout,
            vec![Tex(&fresh), Tex(&depth), uniform.as_entire_binding()],
        );
        let resolve_bind = [0, 1].map(|p| {
            bind(
                "temporal: resolve",
                &in_layout,
                vec![
                    Tex(&fresh),
                    Tex(&depth),
                    Tex(&color[p]),
                    Tex(&samples[p]),
                    Tex(&color[1 - p]),
                    Tex(&samples[1 - p]),
                    uniform.as_entire_binding(),
                ],
            )
        });
        let composite_bind = [0, 1].map(|p| {
            bind(
                "composite: temporal clouds",
                &texture_layout,
                vec![Tex(&color[1 - p])],
            )
        });
        Self {
            uniform,
            march_bind,
            resolve_bind,
            composite_bind,
            size: (width, height),
            frame_index: 0,
            history_valid: false,
            prev_clip_from_world: Mat4::IDENTITY,
            current_clip_from_world: Mat4::IDENTITY,
        }
    }

    fn parity(&self) -> usize {
        (self.frame_index % 2) as usize
    }

    pub fn resolve_bind(&self) -> &wgpu::BindGroup {
        &self.resolve_bind[self.parity()]
    }

    pub fn composite_bind(&self) -> &wgpu::BindGroup {
        &self.composite_bind[self.parity()]
    }

    /// Workgroups (8×8) of the quarter-rate march.
    pub fn march_workgroups(&self) -> (u32, u32) {
        let (qw, qh) = quarter_size(self.size.0, self.size.1);
        (qw.div_ceil(8), qh.div_ceil(8))
    }

    /// Uploads the uniform of the frame about to be drawn with camera
    /// `clip_from_world`.
    pub fn prepare(&mut self, queue: &wgpu::Queue, clip_from_world: Mat4) {
        self.current_clip_from_world = clip_from_world;
        let prev = if self.history_valid {
            self.prev_clip_from_world
        } else {
            clip_from_world
        };
        let [ox, oy] = BAYER_2X2[(self.frame_index % 4) as usize];
        let (qw, qh) = quarter_size(self.size.0, self.size.1);
        let u = TemporalUniform {
            prev_clip_from_world: prev.to_cols_array_2d(),
            offset: [ox, oy],
            frame_index: self.frame_index,
            history_valid: self.history_valid as u32,
            size: [self.size.0, self.size.1],
            quarter: [qw, qh],
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&u));
    }

    /// After a frame drew the temporal passes: its image is the next
    /// frame's history.
    pub fn finish_frame(&mut self) {
        self.prev_clip_from_world = self.current_clip_from_world;
        self.frame_index = self.frame_index.wrapping_add(1);
        self.history_valid = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn four_frames_cover_every_pixel_of_a_block() {
        let mut seen = [[false; 2]; 2];
        for [x, y] in BAYER_2X2 {
            seen[y as usize][x as usize] = true;
        }
        assert_eq!(seen, [[true; 2]; 2]);
    }

    #[test]
    fn quarter_size_rounds_up() {
        assert_eq!(quarter_size(64, 48), (32, 24));
        assert_eq!(quarter_size(65, 1), (33, 1));
    }
}
