//! Preparing a frame: the method's upload (exact's uniforms, the bake's
//! parcels, the slices' planes), the sprites of this frame, the features
//! and pipelines it needs, the frame uniform and the temporal history.

use super::*;
use crate::methods::sprites::gpu::passes::SPRITES_GROUP;

impl Renderer {
    /// Packs and uploads a frame's data (the exact method fails, without
    /// drawing anything wrong, past its uniform limits; see [`pack`]).
    ///
    /// [`pack`]: crate::methods::raymarch::pack
    pub fn prepare(&mut self, ctx: &GpuContext, input: &FrameInput<'_>) -> Result<()> {
        let start = Instant::now();
        // Pipelines the background builder finished since the last frame.
        self.pipelines.collect();
        let (shell, scale) = (self.cfg.shell_m, self.cfg.radius_scale);
        let info = match self.cfg.method {
            RenderMethod::Exact => self.exact.upload(ctx, input.parcels, shell, scale)?,
            RenderMethod::Baked => {
                let sun = input.sun.direction.normalize();
                self.baked.update(ctx, input.parcels, shell, scale, sun)?
            }
            RenderMethod::Sprites => GridInfo::EMPTY,
            RenderMethod::Slices => {
                let mode = self.cfg.slices.vertex_field;
                let texels = self.cfg.noise_texels;
                let cpu = mode == crate::methods::slices::model::VertexField::Cpu;
                if cpu && self.slices_noise.as_ref().map(|(n, _)| *n) != Some(texels) {
                    self.slices_noise = Some((texels, NoiseVolume::new(texels)));
                }
                let frame = slices_frame(
                    &self.authored.0,
                    &self.authored.1,
                    input.parcels,
                    &self.cfg,
                    input.time_s,
                    input.sun.direction,
                    input.camera.target - input.camera.position,
                    self.slices_noise.as_ref().filter(|_| cpu).map(|(_, v)| v),
                )?;
                self.slices.upload(ctx, &self.layouts, &frame, mode)?;
                // No ray-march grid: "parcel_count" counts the primitives
                // when there are planes to draw, so features see clouds,
                // and the grid box is the primitives' bounds, which the
                // cloud-shadow map covers (shadow_rect, shadow.wgsl).
                let mut info = GridInfo::EMPTY;
                if self.slices.index_count > 0 {
                    info.parcel_count = self.slices.primitives_drawn;
                    if let Some((lo, hi)) =
                        crate::methods::slices::model::ellipsoid::bounds_m(&frame.states)
                    {
                        info.min = lo;
                        info.cell = (hi - lo).max(glam::Vec3::ONE);
                    }
                }
                info
            }
        };
        if self.always_bake {
            self.baked.invalidate();
        }
        if self.baked.generation != self.bound_generation {
            self.rebind_field(ctx);
        }
        self.grid_info = info;
        let sprite_method = self.cfg.method == RenderMethod::Sprites;
        self.any_clouds = if sprite_method {
            input.parcels.iter().any(|p| p.fill > 0.0)
        } else {
            info.parcel_count > 0
        };
        // The drawn spheres are radius_scale × the parcels' (§6.1, as the
        // ray-march draws them): the sprite clouds fill those.
        let parcels: Vec<CloudParcel> = if sprite_method && self.cfg.clouds {
            input
                .parcels
                .iter()
                .map(|p| CloudParcel {
                    radius_m: p.radius_m * scale,
                    ..*p
                })
                .collect()
        } else {
            Vec::new()
        };
        self.advance_ring(ctx, input, &parcels);
        let instances = if self.cfg.clouds {
            self.sprite_scene.frame(
                &parcels,
                input.sun.direction,
                input.camera.position,
                input.time_s,
            )
        } else {
            Vec::new()
        };
        // A ring keeps the sprite pass even when every sprite went into it.
        let features = self.features_for(
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
        if let Some(t) = self.temporal.as_mut() {
            t.prepare(
                &ctx.queue,
                glam::Mat4::from_cols_array_2d(&frame.clip_from_world),
            );
        }
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
