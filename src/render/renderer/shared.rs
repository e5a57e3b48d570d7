//! Recording one frame: the shared passes (shadow map, sky, terrain,
//! sprite layer, composite, tone map) around the method's phases, in the
//! order of the module docs of [`super`].

use super::*;
use crate::gpu::begin_pass as begin;
use crate::gpu::method::{Phase, Shared};
use crate::gpu::pass::{SLOT_GROUP, flag};
use crate::gpu::passes::{COMPOSITE, SKY, TERRAIN};
use crate::gpu::pipelines::{Pipeline, PipelineKey};
use crate::gpu::timing::Recorder;

/// The output view, the scene view, whether only the clouds are drawn and
/// whether the tone map may blend the cloud image (`Renderer::folds`).
pub(super) type Views<'v> = (&'v wgpu::TextureView, &'v wgpu::TextureView, bool, bool);

const WHITE: wgpu::LoadOp<wgpu::Color> = wgpu::LoadOp::Clear(wgpu::Color::WHITE);

impl Renderer {
    /// A render pipeline `ensure` built.
    pub(super) fn render_pipeline(&self, key: &PipelineKey) -> Option<&wgpu::RenderPipeline> {
        match self.pipelines.get(key) {
            Some(Pipeline::Render(p)) => Some(p),
            _ => None,
        }
    }

    /// Records the frame's passes with `method` (taken out of the
    /// renderer while it encodes); returns whether the shadow map was
    /// drawn and whether the tone map blended the clouds (no composite
    /// pass: the scene target lacks them).
    pub(super) fn encode_frame(
        &self,
        rec: &mut Recorder<'_>,
        method: &mut dyn CloudMethod,
        (target, scene_view, clouds_only, folds): Views<'_>,
    ) -> (bool, bool) {
        let (cfg, f) = (&self.cfg, self.features);
        let shared = Shared {
            cfg,
            pipelines: &self.pipelines,
            common: &self.bind_common,
            depth: self
                .bind_depth
                .as_ref()
                .expect("ensure made the depth group"),
            scene: scene_view,
            cloud_image: self.cloud_image.as_ref(),
            size: (self.width, self.height),
            around: f.around,
        };
        // The map of an earlier frame still holds: the method's clouds did
        // not move since it was drawn (the `baked` field was not re-baked:
        // asked before the Prepare passes bake) and no sprite splats into
        // it. A paused scene then neither bakes nor marches its shadows.
        let reusable = self.shadow_fresh && !f.around.layers && method.shadow_reusable(cfg);
        method.encode(Phase::Prepare, rec, &shared);
        let shadow = f.shadow_map && !reusable;
        if shadow {
            self.encode_shadow(rec, method);
        }
        if !clouds_only {
            let background = method.background(cfg);
            let sky = self.render_pipeline(&self.shared_key(&SKY, cfg, f));
            rec.pass("sky", |enc, ts| {
                let load = match background {
                    Some([r, g, b]) => wgpu::LoadOp::Clear(wgpu::Color {
                        r: r.into(),
                        g: g.into(),
                        b: b.into(),
                        a: 1.0,
                    }),
                    None => WHITE,
                };
                let mut rp = begin(enc, "sky", scene_view, load, None, writes(ts));
                // The background colour is the clear; nothing to draw.
                if background.is_none() {
                    rp.set_pipeline(sky.expect("ensure built the sky"));
                    rp.set_bind_group(0, &self.bind_common, &[]);
                    rp.draw(0..3, 0..1);
                }
            });
            if f.around.terrain {
                self.encode_terrain(rec, method, scene_view);
            }
        }
        method.encode(Phase::Clouds, rec, &shared);
        if f.around.layers {
            let behind = self.sprites_key(cfg, f, flag(f.method.cloud_depth));
            rec.pass("sprites", |enc, ts| {
                // The impostor ring's face of this frame is rendered first;
                // the pair of timestamps then spans both passes.
                let face = self.encode_ring_face(enc, ts);
                let ts = ts.map(|(set, i)| wgpu::RenderPassTimestampWrites {
                    query_set: set,
                    beginning_of_pass_write_index: (!face).then_some(i),
                    end_of_pass_write_index: Some(i + 1),
                });
                let mut rp = begin(enc, "sprites", scene_view, wgpu::LoadOp::Load, None, ts);
                rp.set_bind_group(0, &self.bind_common, &[]);
                rp.set_bind_group(1, self.bind_sprites.as_ref(), &[]);
                self.draw_ring_quads(&mut rp);
                self.draw_sprites(&mut rp, self.render_pipeline(&behind));
            });
        }
        method.encode(Phase::Resolve, rec, &shared);
        let input = method.composite_input(&shared);
        let fold = !clouds_only && folds && input.is_some();
        if f.method.composite && !fold {
            let composite = self.render_pipeline(&self.shared_key(&COMPOSITE, cfg, f));
            rec.pass("composite", |enc, ts| {
                let mut rp = begin(
                    enc,
                    "composite",
                    scene_view,
                    wgpu::LoadOp::Load,
                    None,
                    writes(ts),
                );
                rp.set_pipeline(composite.expect("ensure built the composite"));
                rp.set_bind_group(0, &self.bind_common, &[]);
                rp.set_bind_group(1, input, &[]);
                rp.draw(0..3, 0..1);
                if f.method.cloud_depth && f.around.layers {
                    // The sprite fragments in front of the clouds.
                    let front = self.sprites_key(cfg, f, 2.0);
                    rp.set_bind_group(1, self.bind_sprites.as_ref(), &[]);
                    self.draw_sprites(&mut rp, self.render_pipeline(&front));
                }
            });
        }
        if !clouds_only {
            let tonemap = self.render_pipeline(&self.tonemap_key(cfg, fold));
            let scene = self.scene.as_ref().expect("ensure made the scene target");
            // Without clouds to blend, group 2 is the scene (unread).
            let clouds = input.filter(|_| fold).unwrap_or(&scene.bind);
            rec.pass("tonemap", |enc, ts| {
                let mut rp = begin(enc, "tonemap", target, WHITE, None, writes(ts));
                rp.set_pipeline(tonemap.expect("ensure built the tone map"));
                rp.set_bind_group(0, &self.bind_common, &[]);
                rp.set_bind_group(1, &scene.bind, &[]);
                rp.set_bind_group(2, clouds, &[]);
                rp.draw(0..3, 0..1);
            });
        }
        (shadow, fold)
    }

    /// The cloud-shadow map: the method's field marched into it (in a
    /// compute pass where the adapter runs one, else a full-screen
    /// fragment pass), then the sprites' shadows splatted in. One timed
    /// pass: its timestamps span both.
    fn encode_shadow(&self, rec: &mut Recorder<'_>, method: &dyn CloudMethod) {
        let (cfg, f) = (&self.cfg, self.features);
        let view = &self.shadow_view.as_ref().expect("shadow map exists").1;
        let march = self
            .pipelines
            .get(&self.shared_key(self.shadow_spec(cfg), cfg, f))
            .filter(|_| f.method.marches_shadow)
            .zip(method.slot_group(cfg));
        let splat = self.render_pipeline(&self.sprite_shadow_key(cfg));
        let layers = f.around.layers;
        rec.pass("shadow", |enc, ts| {
            let mut load = WHITE;
            let mut render_ts = writes(ts);
            if let Some((Pipeline::Compute(p), slot)) = march {
                let n = self.cfg.shadow_texels;
                let mut cp = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("shadow"),
                    timestamp_writes: ts.map(|(set, i)| wgpu::ComputePassTimestampWrites {
                        query_set: set,
                        beginning_of_pass_write_index: Some(i),
                        end_of_pass_write_index: (!layers).then_some(i + 1),
                    }),
                });
                cp.set_pipeline(p);
                cp.set_bind_group(0, &self.bind_common, &[]);
                cp.set_bind_group(2, self.bind_shadow_out.as_ref(), &[]);
                cp.set_bind_group(SLOT_GROUP, slot, &[]);
                cp.dispatch_workgroups(n.div_ceil(8), n.div_ceil(8), 1);
                drop(cp);
                if !layers {
                    return;
                }
                // The splat blends over what the march wrote.
                load = wgpu::LoadOp::Load;
                render_ts = ts.map(|(set, i)| wgpu::RenderPassTimestampWrites {
                    query_set: set,
                    beginning_of_pass_write_index: None,
                    end_of_pass_write_index: Some(i + 1),
                });
            }
            let mut rp = begin(enc, "shadow", view, load, None, render_ts);
            rp.set_bind_group(0, &self.bind_common, &[]);
            if let Some((Pipeline::Render(p), slot)) = march {
                rp.set_pipeline(p);
                rp.set_bind_group(SLOT_GROUP, slot, &[]);
                rp.draw(0..3, 0..1);
            }
            if layers {
                rp.set_bind_group(1, self.bind_sprites.as_ref(), &[]);
                self.draw_sprites(&mut rp, splat);
            }
        });
    }

    /// The terrain mesh with depth, shadowed by the map (group 3: the
    /// method's field, for its in-region sun march).
    fn encode_terrain(
        &self,
        rec: &mut Recorder<'_>,
        method: &dyn CloudMethod,
        scene_view: &wgpu::TextureView,
    ) {
        let (cfg, f) = (&self.cfg, self.features);
        let pipeline = self.render_pipeline(&self.shared_key(&TERRAIN, cfg, f));
        let t = self.terrain.as_ref().expect("terrain mesh exists");
        let depth = self.depth_view.as_ref().expect("depth exists with terrain");
        let slot = method.slot_group(cfg);
        rec.pass("terrain", |enc, ts| {
            let load = wgpu::LoadOp::Load;
            let mut rp = begin(enc, "terrain", scene_view, load, Some(depth), writes(ts));
            rp.set_pipeline(pipeline.expect("ensure built the terrain"));
            rp.set_bind_group(0, &self.bind_common, &[]);
            rp.set_bind_group(1, self.bind_terrain.as_ref(), &[]);
            if let Some(slot) = slot {
                rp.set_bind_group(SLOT_GROUP, slot, &[]);
            }
            rp.set_vertex_buffer(0, t.vertices.slice(..));
            rp.set_index_buffer(t.indices.slice(..), wgpu::IndexFormat::Uint32);
            rp.draw_indexed(0..t.index_count, 0, 0..1);
        });
    }

    /// Draws this frame's sprite instances with `pipeline` (group 1 set
    /// by the caller).
    pub(super) fn draw_sprites(
        &self,
        rp: &mut wgpu::RenderPass<'_>,
        pipeline: Option<&wgpu::RenderPipeline>,
    ) {
        let s = self.sprites.as_ref().expect("sprite resources exist");
        let p = pipeline.expect("ensure built the sprite pipelines");
        rp.set_pipeline(p);
        rp.set_bind_group(2, &s.bind, &[]);
        rp.draw(0..6, 0..s.count);
    }
}

/// A render pass's timestamp writes from the recorder's queries.
fn writes(ts: Option<(&wgpu::QuerySet, u32)>) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
    crate::gpu::timing::render_writes(ts)
}
