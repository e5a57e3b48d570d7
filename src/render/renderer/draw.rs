//! Drawing a prepared frame: the frame uniform, and the frame's passes
//! recorded and timed (by GPU timestamps or the CPU clock).

use crate::gpu::GpuContext;
use crate::gpu::timing::{FrameTimings, Recorder, TimingMode};
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
            eye_from_clip: input
                .camera
                .clip_from_eye(aspect)
                .inverse()
                .to_cols_array_2d(),
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
        if self.features.around.terrain {
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
        let scene_view = if clouds_only {
            target.clone()
        } else {
            self.scene
                .as_ref()
                .expect("ensure made the scene target")
                .view
                .clone()
        };
        let views = (target, &scene_view, clouds_only, self.folds(self.features));
        let mut methods = std::mem::take(&mut self.methods);
        let method = methods[crate::methods::index_of(self.cfg.method)].as_mut();
        let mode = self.timing_mode();
        let mut ts = self.timestamps.take();
        let (shadow_drawn, folded);
        match (mode, ts.as_mut()) {
            (TimingMode::GpuBlocking, Some(ts)) => {
                let mut rec = Recorder::gpu(ctx, Some(&ts.set));
                (shadow_drawn, folded) = self.encode_frame(&mut rec, method, views);
                let (enc, names) = rec.finish();
                let mut enc = enc.expect("GPU timing records into one encoder");
                ts.resolve(&mut enc, names.len() as u32);
                ctx.queue.submit([enc.finish()]);
                (timings.passes, timings.frame_ms) = ts.read_now(ctx, &names);
            }
            (TimingMode::GpuLagged, Some(ts)) => {
                (timings.passes, timings.frame_ms) = ts.collect(ctx);
                let measure = ts.lagged_ready();
                let (enc, names) = {
                    let mut rec = Recorder::gpu(ctx, measure.then_some(&ts.set));
                    (shadow_drawn, folded) = self.encode_frame(&mut rec, method, views);
                    rec.finish()
                };
                let mut enc = enc.expect("GPU timing records into one encoder");
                if measure {
                    ts.resolve(&mut enc, names.len() as u32);
                }
                ctx.queue.submit([enc.finish()]);
                if measure {
                    ts.start_map(names);
                }
            }
            _ => {
                let mut rec = Recorder::cpu(ctx);
                (shadow_drawn, folded) = self.encode_frame(&mut rec, method, views);
                timings.passes = rec.cpu.take().unwrap_or_default();
                timings.frame_ms = timings.total_ms();
            }
        }
        self.timestamps = ts;
        self.shadow_fresh |= shadow_drawn;
        self.scene_folded = folded;
        let rebuild = method.frame_drawn(&self.cfg, self.features.around, &timings);
        self.methods = methods;
        if rebuild {
            // Decided: build (normally: find cached) the chosen pipelines.
            let _ = self.ensure(ctx);
        }
        timings
    }
}

/// The sky-view table as the frame uniform lays it out (`sky_view` in
/// src/gpu/uniform.rs).
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
/// src/gpu/uniform.rs).
fn air_table(air: &crate::sky::AirTable) -> [[f32; 4]; 4 * crate::sky::AIR_HEIGHTS] {
    let mut out = [[0.0; 4]; 4 * crate::sky::AIR_HEIGHTS];
    for (node, parts) in out.chunks_exact_mut(4).zip(&air.nodes) {
        for (o, p) in node.iter_mut().zip(parts) {
            *o = p.extend(0.0).to_array();
        }
    }
    out
}
