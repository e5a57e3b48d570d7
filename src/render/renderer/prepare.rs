//! Preparing a frame: the method's upload, the sprites of this frame, the
//! features and pipelines it needs, and the frame uniform.

use super::*;
use crate::methods::sprites::gpu::passes::SPRITES_GROUP;

impl Renderer {
    /// Uploads a frame's data (the exact method fails, without drawing
    /// anything wrong, past its uniform limits; see
    /// [`crate::methods::raymarch::pack`]).
    pub fn prepare(&mut self, ctx: &GpuContext, input: &FrameInput<'_>) -> Result<()> {
        let start = Instant::now();
        // Pipelines the background builder finished since the last frame.
        self.pipelines.collect();
        let i = crate::methods::index_of(self.cfg.method);
        let prepared = self.methods[i].prepare(ctx, &self.layouts, &self.cfg, input)?;
        self.grid_info = prepared.grid;
        self.any_clouds = prepared.any_clouds;
        let parcels = &prepared.layer_parcels;
        self.advance_ring(ctx, input, parcels);
        let instances = if self.cfg.clouds {
            self.sprite_scene.frame(
                parcels,
                input.sun.direction,
                input.camera.position,
                input.time_s,
            )
        } else {
            Vec::new()
        };
        // A ring keeps the sprite pass even when every sprite went into it.
        let features = self.features_for(
            &self.cfg,
            self.any_clouds,
            !instances.is_empty() || self.ring.is_some(),
        );
        if features != self.features {
            self.features = features;
            self.ensure(ctx)?;
        }
        if let Some(gpu) = self.sprites.as_mut() {
            gpu.upload(ctx, &self.layouts.get(&SPRITES_GROUP), &instances)?;
        }
        self.sprite_box = sprite_box(&instances);
        let frame = self.frame_uniform(input);
        ctx.queue
            .write_buffer(&self.frame_buf, 0, bytemuck::bytes_of(&frame));
        self.methods[i].prepared(ctx, &frame);
        self.upload_ring_face(ctx, input, &frame)?;
        self.upload_ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(())
    }
}

/// Box around every sprite of `instances` turned any way (centre ± the
/// larger half size), or None without sprites. units: m
fn sprite_box(
    instances: &[crate::methods::sprites::gpu::SpriteInstance],
) -> Option<(glam::Vec3, glam::Vec3)> {
    use glam::{Vec3, Vec4};
    instances
        .iter()
        .map(|s| {
            let (a, b) = (Vec4::from(s.corners[0]), Vec4::from(s.corners[2]));
            let half = 0.5 * (b - a).truncate().length();
            let c = 0.5 * (a + b).truncate();
            (c - Vec3::splat(half), c + Vec3::splat(half))
        })
        .reduce(|(lo, hi), (a, b)| (lo.min(a), hi.max(b)))
}
