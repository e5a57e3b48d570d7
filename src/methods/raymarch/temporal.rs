//! Temporal upscaling of the cloud march (`[render] temporal`): each frame
//! marches one pixel of every B×B block (B = 4 under "4x4", the window's
//! default, 2 under "2x2"; clouds.wgsl `cs_temporal`), the block offset
//! stepping through a B×B Bayer order, so B² frames cover every pixel, and
//! the resolve pass (shaders/raymarch/temporal.wgsl) reprojects the
//! previous frame's cloud image with the camera's motion at each pixel's
//! cloud depth (Catmull-Rom fetch), clips it to the statistics of the
//! fresh samples around the pixel (variance clipping) and accumulates.
//! The composite then blends the result like the compute march's image.
//! None of this exists when the setting is "off".
//!
//! Resources: fresh colour and depth (one texel per block); two full-size
//! history pairs (colour, samples) used in turn (frame k reads pair
//! k mod 2 and writes the other, which the composite reads); one uniform.

use glam::Mat4;

use super::passes::{TEMPORAL_IN, TEMPORAL_OUT};
use crate::gpu::layouts::{CLOUD_TARGET_FORMAT, Layouts, TEMPORAL_SCALAR_FORMAT, TEXTURE_IN};

use crate::gpu::resources::{bind_in_order, texture_2d};

/// The marched pixel's offset in its `block`×`block` block (a power of
/// two) at frame `k`: the pixel whose entry in the Bayer (ordered-dither)
/// matrix is k mod block², so each frame's pixel is as far as can be from
/// the ones of the frames just before, and any `block`² consecutive frames
/// cover the block. The matrix is built by the usual recursion
/// M₂ₙ = [[4Mₙ, 4Mₙ+2], [4Mₙ+3, 4Mₙ+1]]; at 2 it is [[0, 2], [3, 1]].
pub fn bayer_offset(block: u32, k: u32) -> [u32; 2] {
    let k = k % (block * block);
    // The recursion read backwards: each level's quadrant from two bits
    // of k, the lowest bits choosing the largest quadrant.
    let (mut x, mut y) = (0, 0);
    let mut half = block / 2;
    let mut rest = k;
    while half > 0 {
        let (dx, dy) = [(0, 0), (1, 1), (1, 0), (0, 1)][(rest % 4) as usize];
        x += dx * half;
        y += dy * half;
        rest /= 4;
        half /= 2;
    }
    [x, y]
}

/// The uniform of the temporal march and resolve: `struct Temporal` in
/// shaders/raymarch/temporal_uniform.wgsl (a test compares the layouts).
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct TemporalUniform {
    /// This frame's world offset from the eye → the previous frame's clip
    /// (the current clip when there is no history): camera-relative, so
    /// a still camera reprojects to the same pixel to f32 precision
    /// however far it is from the world's origin.
    pub prev_clip_from_eye: [[f32; 4]; 4],
    /// The marched pixel's offset in its block.
    pub offset: [u32; 2],
    pub frame_index: u32,
    /// 1 when the history holds the previous frame.
    pub history_valid: u32,
    /// Frame width and height. units: px
    pub size: [u32; 2],
    /// Width and height of the grid of blocks (the fresh images). units: px
    pub fresh: [u32; 2],
    /// Side of a block (2 or 4). units: px
    pub block: u32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

const _: () = assert!(std::mem::size_of::<TemporalUniform>() == 112);

/// The grid of `block`×`block` blocks of a `w`×`h` frame.
pub fn fresh_size(w: u32, h: u32, block: u32) -> (u32, u32) {
    (w.div_ceil(block), h.div_ceil(block))
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
    /// Side of a block, one pixel of which is marched per frame. units: px
    pub block: u32,
    /// Frames drawn on this path since the history was made.
    pub frame_index: u32,
    /// The history holds the previous frame (false: first frame, or after
    /// a change of settings or a frame without clouds).
    pub history_valid: bool,
    /// The previous frame's eye offset → clip, and its eye. units: m
    prev_clip_from_eye: Mat4,
    prev_eye: glam::Vec3,
    /// This frame's, set by `prepare`, kept by `finish_frame`.
    current_clip_from_eye: Mat4,
    current_eye: glam::Vec3,
}

impl TemporalGpu {
    pub fn new(device: &wgpu::Device, layouts: &Layouts, width: u32, height: u32, block: u32) -> Self {
        let (qw, qh) = fresh_size(width, height, block);
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
            block,
            frame_index: 0,
            history_valid: false,
            prev_clip_from_eye: Mat4::IDENTITY,
            prev_eye: glam::Vec3::ZERO,
            current_clip_from_eye: Mat4::IDENTITY,
            current_eye: glam::Vec3::ZERO,
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

    /// Workgroups (8×8) of the march of one pixel per block.
    pub fn march_workgroups(&self) -> (u32, u32) {
        let (qw, qh) = fresh_size(self.size.0, self.size.1, self.block);
        (qw.div_ceil(8), qh.div_ceil(8))
    }

    /// Uploads the uniform of the frame about to be drawn from `eye` with
    /// `clip_from_eye` ([`crate::config::Camera::clip_from_eye`]).
    pub fn prepare(&mut self, queue: &wgpu::Queue, clip_from_eye: Mat4, eye: glam::Vec3) {
        self.current_clip_from_eye = clip_from_eye;
        self.current_eye = eye;
        // A point at offset d from this eye is at d + (eye − prev_eye)
        // from the previous one: the small difference, not two large
        // positions, enters the matrix.
        let prev = if self.history_valid {
            self.prev_clip_from_eye * Mat4::from_translation(eye - self.prev_eye)
        } else {
            clip_from_eye
        };
        let (qw, qh) = fresh_size(self.size.0, self.size.1, self.block);
        let u = TemporalUniform {
            prev_clip_from_eye: prev.to_cols_array_2d(),
            offset: bayer_offset(self.block, self.frame_index),
            frame_index: self.frame_index,
            history_valid: self.history_valid as u32,
            size: [self.size.0, self.size.1],
            fresh: [qw, qh],
            block: self.block,
            _pad0: 0,
            _pad1: 0,
            _pad2: 0,
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&u));
    }

    /// After a frame drew the temporal passes: its image is the next
    /// frame's history.
    pub fn finish_frame(&mut self) {
        self.prev_clip_from_eye = self.current_clip_from_eye;
        self.prev_eye = self.current_eye;
        self.frame_index = self.frame_index.wrapping_add(1);
        self.history_valid = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_round_of_frames_covers_every_pixel_of_a_block() {
        for block in [2, 4] {
            let mut seen = vec![false; (block * block) as usize];
            for k in 0..block * block {
                let [x, y] = bayer_offset(block, k);
                assert!(x < block && y < block);
                seen[(y * block + x) as usize] = true;
            }
            assert!(seen.iter().all(|&s| s), "block {block}: {seen:?}");
        }
    }

    #[test]
    fn bayer_orders_are_the_ordered_dither_matrices() {
        let order = |block| (0..block * block).map(|k| bayer_offset(block, k)).collect::<Vec<_>>();
        assert_eq!(order(2), [[0, 0], [1, 1], [1, 0], [0, 1]]);
        // The 4×4 Bayer matrix [[0, 8, 2, 10], [12, 4, 14, 6],
        // [3, 11, 1, 9], [15, 7, 13, 5]] read as "where is k".
        let m = [[0, 8, 2, 10], [12, 4, 14, 6], [3, 11, 1, 9], [15, 7, 13, 5]];
        for (k, [x, y]) in order(4).into_iter().enumerate() {
            assert_eq!(m[y as usize][x as usize], k, "frame {k} at ({x}, {y})");
        }
    }

    #[test]
    fn fresh_size_rounds_up() {
        assert_eq!(fresh_size(64, 48, 2), (32, 24));
        assert_eq!(fresh_size(65, 1, 2), (33, 1));
        assert_eq!(fresh_size(65, 48, 4), (17, 12));
    }
}
