//! The renderer's side of the impostor ring ([`RingGpu`]): created with
//! `[render.sprites] impostor_radius_m`, advanced once per prepared frame
//! (which clouds it holds, which face to re-render), its face rendered by
//! the sprites pipeline into a 256² texture before the sprite pass, and
//! its quads drawn first in the sprite pass (they stand at the ring
//! radius, behind every directly drawn sprite).

use crate::error::Result;
use crate::gpu::GpuContext;
use crate::gpu::pipelines::{Pipeline, PipelineKey};
use crate::gpu::uniform::FrameUniform;
use crate::methods::sprites::gpu::RingGpu;
use crate::methods::sprites::gpu::passes::{SPRITES, SPRITES_GROUP};
use crate::methods::sprites::gpu::ring::face_camera;
use crate::methods::sprites::model::impostor::SECTORS;
use crate::render::FrameInput;

use super::{Renderer, SCENE_FORMAT};

impl Renderer {
    /// The sprites pipeline for a ring face (no terrain test: the face has
    /// no depth) or for the ring's quads.
    pub(super) fn ring_key(&self, quad: bool) -> PipelineKey {
        let b = |v: bool| if v { 1.0 } else { 0.0 };
        let terrain = quad && self.features.around.terrain;
        // Faces hold linear, premultiplied radiance like the scene target
        // the quads are drawn into; the frame's one tone map comes after.
        PipelineKey::new(
            &SPRITES,
            super::slots(self.cfg.method),
            &[("HAS_TERRAIN", b(terrain)), ("IMPOSTOR_QUAD", b(quad))],
            SCENE_FORMAT,
        )
    }

    /// Creates (or drops) the ring for the configured radius, and its
    /// pipelines.
    pub(super) fn ensure_ring(&mut self, ctx: &GpuContext) -> Result<()> {
        let radius = self
            .cfg
            .sprites
            .impostor_radius_m
            .filter(|_| self.features.around.layers);
        match radius {
            None => {
                self.ring = None;
                self.sprite_scene.impostored = None;
            }
            Some(r) => {
                if self.ring.as_ref().map(|g| g.model.config.radius_m) != Some(r) {
                    self.ring = Some(RingGpu::new(
                        ctx,
                        &self.layouts.get(&SPRITES_GROUP),
                        SCENE_FORMAT,
                        r,
                        std::mem::size_of::<FrameUniform>() as u64,
                    ));
                    self.sprite_scene.impostored = None;
                }
                for quad in [false, true] {
                    let key = self.ring_key(quad);
                    self.pipelines.ensure(ctx, &self.layouts, &key)?;
                }
            }
        }
        Ok(())
    }

    /// Advances the ring one frame, before the frame's sprites are built:
    /// the clouds the newest complete set holds are left out of them.
    /// `parcels` are the frame's physics clouds (sprites method): those
    /// beyond the radius go into the ring by the same rules as the
    /// scene's, taken when a set starts; when the ones it would hold are
    /// no longer those of its newest set (one condensed, evaporated or
    /// crossed the radius), a new set is rendered.
    pub(super) fn advance_ring(
        &mut self,
        ctx: &GpuContext,
        input: &FrameInput<'_>,
        parcels: &[crate::physics::CloudParcel],
    ) {
        if let Some(ring) = self.ring.as_mut() {
            let r = ring.model.config.radius_m;
            if let Some(at) = ring.anchor
                && !ring.model.is_building()
                && self
                    .sprite_scene
                    .ring_changed(parcels, at, r, input.sun.direction)
            {
                ring.model.invalidate();
            }
            ring.advance(
                ctx,
                input.camera.position,
                input.sun.direction,
                input.time_s,
            );
            if let Some((k, cam)) = ring.frame.render {
                if k == 0 {
                    self.sprite_scene
                        .ring_started(parcels, cam, r, input.sun.direction);
                }
                if k + 1 == SECTORS {
                    self.sprite_scene.ring_completed();
                }
            }
            self.sprite_scene.impostored = ring.anchor.map(|a| (a, r));
        }
    }

    /// Uploads this frame's face (its sprites and frame uniform, from the
    /// main frame's uniform with the face's camera).
    pub(super) fn upload_ring_face(
        &mut self,
        ctx: &GpuContext,
        input: &FrameInput<'_>,
        frame: &FrameUniform,
    ) -> Result<()> {
        let Some(ring) = self.ring.as_mut() else {
            return Ok(());
        };
        let Some((k, cam)) = ring.frame.render else {
            return Ok(());
        };
        let r = ring.model.config.radius_m;
        let instances = self
            .sprite_scene
            .face_instances(cam, r, k, input.sun.direction);
        ring.face
            .upload(ctx, &self.layouts.get(&SPRITES_GROUP), &instances)?;
        let face_cam = face_camera(cam, k, input.camera.far_m);
        let mut face = *frame;
        face.clip_from_world = face_cam.clip_from_world(1.0).to_cols_array_2d();
        face.eye_from_clip = face_cam.clip_from_eye(1.0).inverse().to_cols_array_2d();
        face.camera_pos = cam.extend(input.time_s).to_array();
        ctx.queue
            .write_buffer(&ring.face_frame_buf, 0, bytemuck::bytes_of(&face));
        ring.face_common = Some(super::resources::make_bind_common(
            &ctx.device,
            &self.layouts,
            &ring.face_frame_buf,
            &self.noise_view,
            &self.repeat_sampler,
            &self.clamp_sampler,
        ));
        Ok(())
    }

    /// Encodes this frame's face render (a pass of its own into the face's
    /// texture, cleared to transparent); `begin` = the timestamp written
    /// at its start. Returns whether a face was rendered.
    pub(super) fn encode_ring_face(
        &self,
        enc: &mut wgpu::CommandEncoder,
        begin: Option<(&wgpu::QuerySet, u32)>,
    ) -> bool {
        let Some(ring) = self.ring.as_ref() else {
            return false;
        };
        let (Some(view), Some(common)) = (ring.job_view(), ring.face_common.as_ref()) else {
            return false;
        };
        let Some(Pipeline::Render(pipeline)) = self.pipelines.get(&self.ring_key(false)) else {
            return false;
        };
        let mut rp = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("impostor face"),
            color_attachments: &[Some(crate::gpu::stored_color(
                view,
                wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
            ))],
            depth_stencil_attachment: None,
            timestamp_writes: begin.map(|(set, i)| wgpu::RenderPassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(i),
                end_of_pass_write_index: None,
            }),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        rp.set_pipeline(pipeline);
        rp.set_bind_group(0, common, &[]);
        rp.set_bind_group(1, self.bind_sprites.as_ref(), &[]);
        rp.set_bind_group(2, &ring.face.bind, &[]);
        rp.draw(0..6, 0..ring.face.count);
        true
    }

    /// Draws the ring's quads (old set, then new) into the sprite pass.
    pub(super) fn draw_ring_quads(&self, rp: &mut wgpu::RenderPass<'_>) {
        let Some(ring) = self.ring.as_ref() else {
            return;
        };
        let Some(Pipeline::Render(pipeline)) = self.pipelines.get(&self.ring_key(true)) else {
            return;
        };
        let draws = ring.draws();
        if draws.is_empty() {
            return;
        }
        rp.set_pipeline(pipeline);
        for (set, _) in draws {
            for k in 0..SECTORS {
                let i = (set * SECTORS + k) as u32;
                rp.set_bind_group(2, &ring.quad_binds[set][k], &[]);
                rp.draw(0..6, i..i + 1);
            }
        }
    }
}
