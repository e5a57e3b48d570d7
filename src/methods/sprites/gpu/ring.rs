//! The ring of 8 impostors on the GPU (Wang 2003 §6.2): two sets of 8
//! textures of 256² (45° each) around the camera. The scene's sprite
//! clouds beyond the user's radius (and within 609.6 m of the camera's
//! height, counted from the cloud's nearest sprite,
//! [`crate::methods::sprites::model::impostor::span_in_impostors`]) are rendered
//! into them by the sprites pipeline itself (same WGSL, a per-face
//! view-projection, no terrain test), one face per frame, and drawn as 8
//! textured quads at the ring radius (the faces' projection planes), the
//! old set fading out while the new fades in. When to re-render and the
//! weights come from [`ImpostorRing`]; this module holds the textures, the
//! face camera and the ring quads.

use glam::Vec3;

use super::{SpriteInstance, SpritesGpu};
use crate::config::Camera;
use crate::gpu::GpuContext;
use crate::methods::sprites::model::impostor::{
    IMPOSTOR_SIZE, ImpostorRing, RingConfig, RingFrame, SECTOR_RAD, SECTORS,
};

/// Centre direction (horizontal) of face `k`.
fn face_dir(k: usize) -> Vec3 {
    let a = (k as f32 + 0.5) * SECTOR_RAD;
    Vec3::new(a.cos(), a.sin(), 0.0)
}

/// The camera face `k` is rendered with from `ring_cam`: 45° square, looking
/// horizontally at the face's centre direction.
pub fn face_camera(ring_cam: Vec3, k: usize, far_m: f32) -> Camera {
    Camera {
        position: ring_cam,
        target: ring_cam + face_dir(k),
        vfov_rad: SECTOR_RAD,
        near_m: 1.0,
        far_m,
    }
}

/// The quad face `k` is drawn on: its camera's projection plane at
/// `radius_m`, corners counter-clockwise from bottom-left as seen from
/// the ring's centre, so its texture lands where the clouds were.
pub fn face_quad(ring_cam: Vec3, radius_m: f32, k: usize, weight: f32) -> SpriteInstance {
    let d = face_dir(k);
    let right = Vec3::new(d.y, -d.x, 0.0);
    let h = radius_m * (0.5 * SECTOR_RAD).tan();
    let c = ring_cam + d * radius_m;
    let corners = [
        c - right * h - Vec3::Z * h,
        c + right * h - Vec3::Z * h,
        c + right * h + Vec3::Z * h,
        c - right * h + Vec3::Z * h,
    ];
    SpriteInstance {
        corners: corners.map(|p| p.extend(1.0).to_array()),
        colors: [[1.0, 1.0, 1.0, weight]; 4],
        sun: [0.0; 4],
        sky: [0.0; 4],
        uv: [0.0, 0.0, 1.0, 1.0],
    }
}

/// The ring's textures, quads and state.
pub struct RingGpu {
    pub model: ImpostorRing,
    /// `views[set][face]`.
    views: [Vec<wgpu::TextureView>; 2],
    /// Ring quads: instance `set * 8 + face`.
    quad_buf: wgpu::Buffer,
    /// `quad_binds[set][face]`: that texture and the quad buffer.
    pub quad_binds: [Vec<wgpu::BindGroup>; 2],
    /// The face being rendered this frame: its sprites (own atlas copy and
    /// instance buffer) and frame uniform.
    pub face: SpritesGpu,
    pub face_frame_buf: wgpu::Buffer,
    pub face_common: Option<wgpu::BindGroup>,
    /// Set holding the newest complete ring.
    newest: usize,
    /// This frame: (set, face) to render, and the weights drawn.
    pub job: Option<(usize, usize)>,
    pub frame: RingFrame,
    /// Camera of the newest complete set (None until one is complete).
    pub anchor: Option<Vec3>,
    last_time_s: Option<f32>,
}

impl RingGpu {
    pub fn new(
        ctx: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        format: wgpu::TextureFormat,
        radius_m: f32,
        frame_size: u64,
    ) -> Self {
        let device = &ctx.device;
        let make = |set: usize| -> Vec<wgpu::TextureView> {
            (0..SECTORS)
                .map(|k| {
                    device
                        .create_texture(&wgpu::TextureDescriptor {
                            label: Some(&format!("impostor {set}.{k}")),
                            size: wgpu::Extent3d {
                                width: IMPOSTOR_SIZE,
                                height: IMPOSTOR_SIZE,
                                depth_or_array_layers: 1,
                            },
                            mip_level_count: 1,
                            sample_count: 1,
                            dimension: wgpu::TextureDimension::D2,
                            format,
                            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                                | wgpu::TextureUsages::TEXTURE_BINDING,
                            view_formats: &[],
                        })
                        .create_view(&Default::default())
                })
                .collect()
        };
        let views = [make(0), make(1)];
        let quad_buf = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("impostor quads"),
            size: 2 * SECTORS as u64 * std::mem::size_of::<SpriteInstance>() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let face = SpritesGpu::new(ctx, layout);
        let binds = |set: usize| -> Vec<wgpu::BindGroup> {
            views[set]
                .iter()
                .map(|v| super::bind(ctx, layout, v, &face.sampler, &quad_buf))
                .collect()
        };
        let quad_binds = [binds(0), binds(1)];
        let face_frame_buf = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("impostor face frame uniform"),
            size: frame_size,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            model: ImpostorRing::new(RingConfig {
                radius_m,
                ..RingConfig::default()
            }),
            views,
            quad_buf,
            quad_binds,
            face,
            face_frame_buf,
            face_common: None,
            newest: 0,
            job: None,
            frame: RingFrame {
                render: None,
                old_weight: 0.0,
                new_weight: 0.0,
            },
            anchor: None,
            last_time_s: None,
        }
    }

    /// Advances the ring one frame: which face to render into which set,
    /// the sets' weights, and the quads uploaded.
    pub fn advance(&mut self, ctx: &GpuContext, camera_m: Vec3, sun_dir: Vec3, time_s: f32) {
        let dt = self.last_time_s.map_or(0.0, |t| (time_s - t).max(0.0));
        self.last_time_s = Some(time_s);
        let f = self.model.frame(camera_m, sun_dir, dt);
        self.frame = f;
        self.job = None;
        if let Some((k, cam)) = f.render {
            let building = 1 - self.newest;
            self.job = Some((building, k));
            if k + 1 == SECTORS {
                self.newest = building;
                self.anchor = Some(cam);
            }
        }
        let r = self.model.config.radius_m;
        let mut quads = Vec::with_capacity(2 * SECTORS);
        for set in 0..2 {
            // The old set's camera is not kept: its quads stand where the
            // newest set's do (the fade lasts a second of a small move).
            let w = if set == self.newest {
                f.new_weight
            } else {
                f.old_weight
            };
            let at = self.anchor.unwrap_or(camera_m);
            quads.extend((0..SECTORS).map(|k| face_quad(at, r, k, w)));
        }
        ctx.queue
            .write_buffer(&self.quad_buf, 0, bytemuck::cast_slice(&quads));
    }

    /// (set, weight) to draw, oldest first, skipping empty weights.
    pub fn draws(&self) -> Vec<(usize, f32)> {
        [
            (1 - self.newest, self.frame.old_weight),
            (self.newest, self.frame.new_weight),
        ]
        .into_iter()
        .filter(|(_, w)| *w > 0.0)
        .collect()
    }

    /// The target view of this frame's face job.
    pub fn job_view(&self) -> Option<&wgpu::TextureView> {
        self.job.map(|(s, k)| &self.views[s][k])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_face_quad_is_its_cameras_view_at_the_ring_radius() {
        let cam = Vec3::new(100.0, -200.0, 800.0);
        for k in 0..SECTORS {
            let q = face_quad(cam, 12_000.0, k, 1.0);
            let m = face_camera(cam, k, 100_000.0).clip_from_world(1.0);
            // Corners counter-clockwise from bottom-left land on the clip
            // square's corners (-1,-1), (1,-1), (1,1), (-1,1).
            let want = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
            for (c, (x, y)) in q.corners.iter().zip(want) {
                let p = m * glam::Vec4::from(*c);
                let (px, py) = (p.x / p.w, p.y / p.w);
                assert!(
                    (px - x).abs() < 1e-3 && (py - y).abs() < 1e-3,
                    "{k}: {px} {py}"
                );
            }
        }
    }
}
