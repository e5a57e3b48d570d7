//! Drawing a prepared frame: the frame uniform, the pass order, each pass's
//! encoding (render, compute bake, compute march) and its timing.

use std::time::Instant;

use super::passes::Pass;
use crate::gpu::GpuContext;
use crate::gpu::pipelines::Pipeline;
use crate::gpu::timing::{FrameTimings, TimingMode};
use crate::gpu::uniform::{CameraPos, FrameNoise, FrameUniform};
use crate::render::FrameInput;

use super::{Renderer, SCENE_FORMAT, shadow_rect, shadow_rect_of};

impl Renderer {
    pub(super) fn frame_uniform(&self, input: &FrameInput<'_>) -> FrameUniform {
        let aspect = self.width as f32 / self.height as f32;
        let clip_from_world = input.camera.clip_from_world(aspect);
        let c = &self.cfg;
        let g = &self.grid_info;
        // Width of one pixel's view cone per metre of distance (rad), in
        // noise texels: the mip level of the noise (noise3 in common.wgsl).
        let pixel_rad = 2.0 * (0.5 * input.camera.vfov_rad).tan() / self.height as f32;
        let camera = CameraPos {
            eye_m: input.camera.position.to_array(),
            time_s: input.time_s,
        };
        let noise = FrameNoise {
            inv_scale_per_m: 1.0 / c.noise_scale_m,
            octaves: c.noise_octaves as f32,
            _pad: 0.0,
            texels_per_m: pixel_rad * c.noise_texels as f32 / c.noise_scale_m,
        };
        let [min_x, min_y, max_x, max_y] = self.shadow_rect(input.sun.direction);
        FrameUniform {
            clip_from_world: clip_from_world.to_cols_array_2d(),
            world_from_clip: clip_from_world.inverse().to_cols_array_2d(),
            camera_pos: bytemuck::cast(camera),
            sun_dir: input.sun.direction.normalize().to_array(),
            phase_g: c.phase_g,
            sun_color: input.sun.color.to_array(),
            exposure: c.tone_exposure(),
            step_m: c.step_m,
            max_steps: c.max_steps,
            light_steps: c.light_steps,
            light_step_m: c.light_step_m,
            noise_amplitude: c.noise_amplitude,
            shell_m: c.shell_m,
            extinction_per_m: c.extinction_per_m,
            early_exit_transmittance: c.early_exit_transmittance,
            noise: bytemuck::cast(noise),
            grid_min: g.min.to_array(),
            _pad0: 0.0,
            grid_cell: g.cell.to_array(),
            _pad1: 0.0,
            grid_dims: g.dims,
            parcel_count: g.parcel_count,
            shadow_min: [min_x, min_y],
            shadow_max: [max_x, max_y],
            sky_ambient: input.sun.sky.ambient.to_array(),
            sky_mie_g: input.sun.sky.mie_g,
            sky_below: input.sun.sky.below.to_array(),
            _pad2: 0.0,
            sky_view: sky_view(&input.sun.sky),
            air: air_table(&input.sun.sky.air),
        }
    }

    /// The shadow map's ground rectangle: the march grid's and this
    /// frame's sprites' shadows together.
    fn shadow_rect(&self, sun: glam::Vec3) -> [f32; 4] {
        let g = &self.grid_info;
        let grid = (g.parcel_count > 0 || self.sprite_box.is_none()).then(|| shadow_rect(g, sun));
        let sprites = self.sprite_box.map(|(lo, hi)| shadow_rect_of(lo, hi, sun));
        match (grid, sprites) {
            (Some(a), Some(b)) => [
                a[0].min(b[0]),
                a[1].min(b[1]),
                a[2].max(b[2]),
                a[3].max(b[3]),
            ],
            (a, b) => a.or(b).expect("one of the two exists"),
        }
    }

    /// Draws the prepared frame into `target` (a view of a `target_format`
    /// texture) and returns per-pass timings. A target of another size than
    /// the renderer's resizes the renderer first (a window that forgot to
    /// call `resize` gets a correct frame, not a validation panic); a size
    /// the device cannot hold draws nothing and returns no pass timings.
    pub fn render(&mut self, ctx: &GpuContext, target: &wgpu::TextureView) -> FrameTimings {
        self.draw(ctx, target, false)
    }

    /// Draws only the clouds of the prepared frame over `hdr_target`, a
    /// view of another program's [`SCENE_FORMAT`] texture of the
    /// renderer's size that already holds that program's scene in linear
    /// radiance: no sky, no terrain, no tone map (the program tone-maps
    /// the result itself; cloud radiance is in the renderer's units, where
    /// [`crate::config::RenderConfig::tone_exposure`] brings sunlit cloud
    /// tops near 1). The clouds are blended "over" with premultiplied
    /// alpha. The configuration must have the terrain off: this renderer
    /// cannot see the program's ground. Returns the per-pass timings.
    pub fn render_clouds_over(
        &mut self,
        ctx: &GpuContext,
        hdr_target: &wgpu::TextureView,
    ) -> crate::error::Result<FrameTimings> {
        let format = hdr_target.texture().format();
        if format != SCENE_FORMAT {
            return Err(crate::error::Error::invalid(
                "cloud target format",
                format!("{format:?}"),
                format!("{SCENE_FORMAT:?} (linear HDR, as the renderer's own scene target)"),
            ));
        }
        if self.features.terrain {
            return Err(crate::error::Error::invalid(
                "render.terrain.enabled",
                true,
                "false when the clouds are drawn into another program's target (its ground is not this renderer's)",
            ));
        }
        Ok(self.draw(ctx, hdr_target, true))
    }

    /// [`Renderer::render`] into `target`, or with `clouds_only` the cloud
    /// passes alone over `target` as the scene target.
    fn draw(
        &mut self,
        ctx: &GpuContext,
        target: &wgpu::TextureView,
        clouds_only: bool,
    ) -> FrameTimings {
        let size = target.texture().size();
        let mut timings = FrameTimings {
            gpu_timestamps: self.timing_mode() != TimingMode::Cpu,
            upload_ms: self.upload_ms,
            ..FrameTimings::default()
        };
        if (size.width, size.height) != (self.width, self.height)
            && self.resize(ctx, size.width, size.height).is_err()
        {
            timings.gpu_timestamps = false;
            return timings;
        }
        let passes: Vec<Pass> = Pass::ALL
            .into_iter()
            .filter(|p| match p {
                Pass::Bake => self.baked.dirty(),
                Pass::Shadow => !self.shadow_reusable(),
                _ => true,
            } && self.needed(*p)
                && !(clouds_only && matches!(p, Pass::Sky | Pass::Terrain | Pass::Tonemap)))
            .collect();
        let scene_view = if clouds_only {
            target.clone()
        } else {
            self.scene
                .as_ref()
                .expect("ensure made the scene target")
                .view
                .clone()
        };
        let names: Vec<&'static str> = passes.iter().map(|p| p.name()).collect();
        let mode = self.timing_mode();
        let mut ts = self.timestamps.take();
        match (mode, ts.as_mut()) {
            (TimingMode::GpuBlocking, Some(ts)) => {
                let mut enc = ctx.device.create_command_encoder(&Default::default());
                for (i, pass) in passes.iter().enumerate() {
                    self.encode_pass(
                        &mut enc,
                        *pass,
                        target,
                        &scene_view,
                        Some((&ts.set, 2 * i as u32)),
                    );
                }
                ts.resolve(&mut enc, passes.len() as u32);
                ctx.queue.submit([enc.finish()]);
                (timings.passes, timings.frame_ms) = ts.read_now(ctx, &names);
            }
            (TimingMode::GpuLagged, Some(ts)) => {
                (timings.passes, timings.frame_ms) = ts.collect(ctx);
                let measure = ts.lagged_ready();
                let mut enc = ctx.device.create_command_encoder(&Default::default());
                for (i, pass) in passes.iter().enumerate() {
                    let writes = measure.then_some((&ts.set, 2 * i as u32));
                    self.encode_pass(&mut enc, *pass, target, &scene_view, writes);
                }
                if measure {
                    ts.resolve(&mut enc, passes.len() as u32);
                }
                ctx.queue.submit([enc.finish()]);
                if measure {
                    ts.start_map(names);
                }
            }
            _ => {
                for pass in passes {
                    let start = Instant::now();
                    let mut enc = ctx.device.create_command_encoder(&Default::default());
                    self.encode_pass(&mut enc, pass, target, &scene_view, None);
                    ctx.queue.submit([enc.finish()]);
                    ctx.wait_idle();
                    timings
                        .passes
                        .push((pass.name().to_string(), start.elapsed().as_secs_f64() * 1e3));
                }
                timings.frame_ms = timings.total_ms();
            }
        }
        self.timestamps = ts;
        if let Some(t) = self.temporal.as_mut() {
            t.finish_frame();
        }
        // The temporal path, and frames with sprites (which sort against
        // the compute march's cloud depth), always march in compute: such
        // frames say nothing about fragment against compute.
        if self.features.temporal || self.split() {
            return timings;
        }
        if self.features.clouds {
            self.auto_march.drew();
        }
        let was = self.auto_march.chosen();
        self.auto_march.record(&timings);
        if was != self.auto_march.chosen() {
            // Decided: build (normally: find cached) the chosen pipelines.
            let _ = self.ensure(ctx);
        }
        timings
    }

    /// Encodes one pass; `timestamps` = (query set, index of its begin
    /// query; the end query follows).
    fn encode_pass(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        pass: Pass,
        target: &wgpu::TextureView,
        scene_view: &wgpu::TextureView,
        timestamps: Option<(&wgpu::QuerySet, u32)>,
    ) {
        if pass == Pass::Bake {
            self.baked.encode(enc, timestamps);
            return;
        }
        if pass == Pass::SliceField {
            self.slices.encode_field(enc, &self.bind_common, timestamps);
            return;
        }
        let pipeline = match self.pipelines.get(&self.key(pass)) {
            Some(Pipeline::Render(p)) => Some(p),
            Some(Pipeline::Compute(p)) => {
                let mut cp = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(pass.name()),
                    timestamp_writes: timestamps.map(|(set, i)| wgpu::ComputePassTimestampWrites {
                        query_set: set,
                        beginning_of_pass_write_index: Some(i),
                        end_of_pass_write_index: Some(i + 1),
                    }),
                });
                cp.set_pipeline(p);
                cp.set_bind_group(0, &self.bind_common, &[]);
                if let Some(g) = self.slot_group() {
                    cp.set_bind_group(crate::gpu::pass::SLOT_GROUP, g, &[]);
                }
                let full = (self.width.div_ceil(8), self.height.div_ceil(8));
                let (x, y) = match (pass, self.temporal.as_ref()) {
                    (Pass::Temporal, Some(t)) => {
                        cp.set_bind_group(1, t.resolve_bind(), &[]);
                        full
                    }
                    (_, Some(t)) => {
                        cp.set_bind_group(1, self.bind_clouds.as_ref(), &[]);
                        cp.set_bind_group(2, &t.march_bind, &[]);
                        t.march_workgroups()
                    }
                    (_, None) => {
                        let (_, out, _, _) =
                            self.cloud_target.as_ref().expect("compute target exists");
                        cp.set_bind_group(1, self.bind_clouds.as_ref(), &[]);
                        cp.set_bind_group(2, out, &[]);
                        full
                    }
                };
                cp.dispatch_workgroups(x, y, 1);
                return;
            }
            // The shadow map of sprites alone (no ray-marched clouds): the
            // pass only clears it and splats them.
            None if pass == Pass::Shadow => None,
            None => panic!("ensure built every needed pipeline ({})", pass.name()),
        };
        // The impostor ring's face of this frame is rendered first; the
        // pair of timestamps then spans both passes.
        let face = pass == Pass::Sprites && self.encode_ring_face(enc, timestamps);
        let timestamp_writes = timestamps.map(|(set, i)| wgpu::RenderPassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: (!face).then_some(i),
            end_of_pass_write_index: Some(i + 1),
        });
        let color = |view, load| [Some(crate::gpu::stored_color(view, load))];
        let clear = wgpu::LoadOp::Clear(wgpu::Color::WHITE);
        let slices = self.cfg.method == crate::config::RenderMethod::Slices;
        // The paper's Background control: a flat colour instead of the sky.
        let background = (slices && !self.cfg.slices.sky).then(|| {
            let [r, g, b] = self.cfg.slices.background_colour.map(f64::from);
            wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a: 1.0 })
        });
        let scene = self.scene.as_ref().expect("ensure made the scene target");
        let cloud_target = || &self.cloud_target.as_ref().expect("cloud target exists").0;
        let attachments = match pass {
            Pass::Slices => color(
                cloud_target(),
                wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
            ),
            Pass::Shadow => color(
                &self.shadow_view.as_ref().expect("shadow map exists").1,
                clear,
            ),
            Pass::Sky => color(scene_view, background.unwrap_or(clear)),
            Pass::Tonemap => color(target, clear),
            _ => color(scene_view, wgpu::LoadOp::Load),
        };
        let depth = (pass == Pass::Terrain).then(|| wgpu::RenderPassDepthStencilAttachment {
            view: self.depth_view.as_ref().expect("depth exists with terrain"),
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        });
        let mut rp = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(pass.name()),
            color_attachments: &attachments,
            depth_stencil_attachment: depth,
            timestamp_writes,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        if let Some(p) = pipeline {
            rp.set_pipeline(p);
        }
        rp.set_bind_group(0, &self.bind_common, &[]);
        if self.spec_slotted(pass)
            && let Some(g) = self.slot_group()
        {
            rp.set_bind_group(crate::gpu::pass::SLOT_GROUP, g, &[]);
        }
        match pass {
            Pass::Terrain => {
                let t = self.terrain.as_ref().expect("terrain mesh exists");
                rp.set_bind_group(1, self.bind_terrain.as_ref(), &[]);
                rp.set_vertex_buffer(0, t.vertices.slice(..));
                rp.set_index_buffer(t.indices.slice(..), wgpu::IndexFormat::Uint32);
                rp.draw_indexed(0..t.index_count, 0, 0..1);
            }
            Pass::Clouds => {
                rp.set_bind_group(1, self.bind_clouds.as_ref(), &[]);
                rp.draw(0..3, 0..1);
            }
            Pass::Sprites => {
                rp.set_bind_group(1, self.bind_sprites.as_ref(), &[]);
                self.draw_ring_quads(&mut rp);
                self.draw_sprites(&mut rp, pipeline);
            }
            Pass::Shadow => {
                self.shadow_fresh = true;
                // The march of the ray-marched clouds' parcels, or of the
                // slices' implicit field (group 2, see slices/shadow_field.wgsl).
                if pipeline.is_some() && (!slices || self.slices.bind.is_some()) {
                    rp.draw(0..3, 0..1);
                }
                if self.features.sprites {
                    let key = self.sprite_shadow_key();
                    rp.set_bind_group(1, self.bind_sprites.as_ref(), &[]);
                    self.draw_sprites(&mut rp, self.render_pipeline(&key));
                }
            }
            Pass::Slices => {
                rp.set_bind_group(1, self.bind_clouds.as_ref(), &[]);
                self.slices.draw(&mut rp);
            }
            Pass::Composite => {
                let input = match self.temporal.as_ref() {
                    Some(t) => t.composite_bind(),
                    None => &self.cloud_target.as_ref().expect("compute target exists").2,
                };
                rp.set_bind_group(1, input, &[]);
                rp.draw(0..3, 0..1);
                if self.split() {
                    // The sprite fragments in front of the clouds.
                    let key = self.sprites_front_key();
                    rp.set_bind_group(1, self.bind_sprites.as_ref(), &[]);
                    self.draw_sprites(&mut rp, self.render_pipeline(&key));
                }
            }
            Pass::Tonemap => {
                rp.set_bind_group(1, &scene.bind, &[]);
                rp.draw(0..3, 0..1);
            }
            // The background colour is the clear; nothing to draw.
            Pass::Sky if background.is_some() => {}
            _ => rp.draw(0..3, 0..1),
        }
    }

    /// Whether `pass`'s pipeline takes the method's slot group.
    fn spec_slotted(&self, pass: Pass) -> bool {
        !matches!(pass, Pass::Bake | Pass::SliceField) && self.spec(pass).slotted
    }

    /// A render pipeline `ensure` built.
    fn render_pipeline(
        &self,
        key: &crate::gpu::pipelines::PipelineKey,
    ) -> Option<&wgpu::RenderPipeline> {
        match self.pipelines.get(key) {
            Some(Pipeline::Render(p)) => Some(p),
            _ => None,
        }
    }

    /// Draws this frame's sprite instances with `pipeline` (group 1 set
    /// by the caller).
    fn draw_sprites(&self, rp: &mut wgpu::RenderPass<'_>, pipeline: Option<&wgpu::RenderPipeline>) {
        let s = self.sprites.as_ref().expect("sprite resources exist");
        let p = pipeline.expect("ensure built the sprite pipelines");
        rp.set_pipeline(p);
        rp.set_bind_group(2, &s.bind, &[]);
        rp.draw(0..6, 0..s.count);
    }
}

/// The sky-view table as the frame uniform lays it out (`sky_view` in
/// src/methods/raymarch/pack.rs).
fn sky_view(sky: &crate::sky::SkyLight) -> [[f32; 4]; 3 * crate::sky::SKY_TEXELS] {
    let mut out = [[0.0; 4]; 3 * crate::sky::SKY_TEXELS];
    for (k, texel) in out.chunks_exact_mut(3).enumerate() {
        texel[0] = sky.rayleigh[k].extend(0.0).to_array();
        texel[1] = sky.mie[k].extend(0.0).to_array();
        texel[2] = sky.multiple[k].extend(0.0).to_array();
    }
    out
}

/// The air table as the frame uniform lays it out (`air` in
/// src/methods/raymarch/pack.rs).
fn air_table(air: &crate::sky::AirTable) -> [[f32; 4]; 4 * crate::sky::AIR_HEIGHTS] {
    let mut out = [[0.0; 4]; 4 * crate::sky::AIR_HEIGHTS];
    for (node, parts) in out.chunks_exact_mut(4).zip(&air.nodes) {
        for (o, p) in node.iter_mut().zip(parts) {
            *o = p.extend(0.0).to_array();
        }
    }
    out
}
