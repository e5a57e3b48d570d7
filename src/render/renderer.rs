//! The renderer: owns the GPU resources of the shared passes, the render
//! method's cloud field ([`crate::render::raymarch`]) and the pipelines,
//! and draws a frame into any texture view (window surface or offscreen).
//! Pass order: bake (baked method, only when the parcels moved) → shadow
//! map → sky → terrain → clouds.
//!
//! "Leave out what a scene does not need": [`Features`] decides which passes
//! and resources exist; pipelines come from a cache keyed by pass, method
//! and `override` constants ([`crate::render::pipelines`]), so a toggled
//! setting builds only pipelines it has never seen and clouds appearing
//! never wait for a shader compile. `prepare` uploads (and times the
//! upload); `render` draws and times each pass ([`crate::render::timing`]).

use std::time::Instant;

use crate::error::{Error, Result};
use crate::render::auto_march::AutoMarch;
use crate::render::gpu::GpuContext;
use crate::render::method::{MarchPath, RenderMethod};
use crate::render::pack::{FrameUniform, GridInfo, GridUniform, ParcelsUniform};
use crate::render::pipelines::{
    CLOUD_TARGET_FORMAT, PassLayouts, Pipeline, PipelineCache, PipelineKey,
};
use crate::render::raymarch::baked::{BakeInfo, BakedField};
use crate::render::raymarch::exact::ExactField;
use crate::render::shaders::Pass;
use crate::render::terrain;
use crate::render::timing::Timestamps;
use crate::render::{Features, FrameInput, RenderConfig, TerrainConfig, noise};

pub use crate::render::pipelines::{DEPTH_FORMAT, SHADOW_FORMAT};
pub(crate) use crate::render::timing::read_buffer;
pub use crate::render::timing::{FrameTimings, TimingMode};

struct TerrainGpu {
    cfg: TerrainConfig,
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
}

/// Draws frames; see the module docs.
pub struct Renderer {
    cfg: RenderConfig,
    format: wgpu::TextureFormat,
    width: u32,
    height: u32,
    features: Features,
    /// The last prepared frame had parcels (true before the first).
    any_clouds: bool,
    grid_info: GridInfo,
    upload_ms: f64,

    frame_buf: wgpu::Buffer,
    exact: ExactField,
    baked: BakedField,
    /// `baked.generation` that `bind_common` holds.
    bound_generation: u64,
    noise_texels: u32,
    noise_view: wgpu::TextureView,
    repeat_sampler: wgpu::Sampler,
    clamp_sampler: wgpu::Sampler,
    layouts: PassLayouts,
    bind_common: wgpu::BindGroup,

    depth_view: Option<wgpu::TextureView>,
    dummy_depth_view: wgpu::TextureView,
    shadow_view: Option<(u32, wgpu::TextureView)>,
    white_view: wgpu::TextureView,
    terrain: Option<TerrainGpu>,

    pipelines: PipelineCache,
    bake_pipelines: u32,
    bind_terrain: Option<wgpu::BindGroup>,
    bind_clouds: Option<wgpu::BindGroup>,
    timestamps: Option<Timestamps>,
    /// How passes are timed (GPU modes fall back to Cpu without timestamps).
    timing: TimingMode,
    /// Re-bake every frame (bench: the cost when every parcel moves).
    always_bake: bool,
    /// The compute march's output: (view, its storage bind group, its
    /// sampled bind group for the composite).
    cloud_target: Option<(wgpu::TextureView, wgpu::BindGroup, wgpu::BindGroup)>,
    /// `march = "auto"`: measurements and decision.
    auto_march: AutoMarch,
}

/// A single-sample, single-mip 2D texture (also the headless target and the
/// window's 3D view and screenshot).
pub(crate) fn texture_2d(
    device: &wgpu::Device,
    label: &str,
    w: u32,
    h: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

fn noise_texture(ctx: &GpuContext, n: u32) -> wgpu::TextureView {
    let tex = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("noise 3d"),
        size: wgpu::Extent3d {
            width: n,
            height: n,
            depth_or_array_layers: n,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: wgpu::TextureFormat::R8Unorm,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    ctx.queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture: &tex,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        &noise::tiling_fbm(n, 1),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(n),
            rows_per_image: Some(n),
        },
        wgpu::Extent3d {
            width: n,
            height: n,
            depth_or_array_layers: n,
        },
    );
    tex.create_view(&wgpu::TextureViewDescriptor::default())
}

impl Renderer {
    pub fn new(
        ctx: &GpuContext,
        cfg: &RenderConfig,
        target_format: wgpu::TextureFormat,
        width: u32,
        height: u32,
    ) -> Result<Self> {
        cfg.validate()?;
        check_size(ctx, width, height)?;
        let device = &ctx.device;
        let limits = device.limits();
        for (name, size) in [
            ("frame uniform", std::mem::size_of::<FrameUniform>()),
            ("parcel uniform", std::mem::size_of::<ParcelsUniform>()),
            ("grid uniform", std::mem::size_of::<GridUniform>()),
        ] {
            if size as u64 > limits.max_uniform_buffer_binding_size as u64 {
                return Err(Error::Gpu(format!(
                    "the {name} needs {size} bytes but this device binds at most {} bytes of uniforms; lower MAX_PARCELS/MAX_GRID_* in src/render/pack.rs",
                    limits.max_uniform_buffer_binding_size
                )));
            }
        }
        if cfg.noise_texels > limits.max_texture_dimension_3d
            || cfg.shadow_texels > limits.max_texture_dimension_2d
        {
            return Err(Error::Gpu(format!(
                "noise texture {}³ or shadow map {}² exceeds the device's texture limits ({}³, {}²)",
                cfg.noise_texels,
                cfg.shadow_texels,
                limits.max_texture_dimension_3d,
                limits.max_texture_dimension_2d
            )));
        }

        let frame_buf = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame uniform"),
            size: std::mem::size_of::<FrameUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let exact = ExactField::new(device);
        let mut bake_pipelines = 0;
        let baked = BakedField::new(ctx, &frame_buf, &mut bake_pipelines)?;

        let sampler = |label: &str, mode: wgpu::AddressMode| {
            device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some(label),
                address_mode_u: mode,
                address_mode_v: mode,
                address_mode_w: mode,
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                ..Default::default()
            })
        };
        let repeat_sampler = sampler("repeat", wgpu::AddressMode::Repeat);
        let clamp_sampler = sampler("clamp", wgpu::AddressMode::ClampToEdge);
        let noise_view = noise_texture(ctx, cfg.noise_texels);

        let layouts = PassLayouts::new(device);

        let dummy_depth_view = texture_2d(
            device,
            "dummy depth",
            1,
            1,
            DEPTH_FORMAT,
            wgpu::TextureUsages::TEXTURE_BINDING,
        )
        .create_view(&Default::default());
        let white = texture_2d(
            device,
            "no shadow",
            1,
            1,
            SHADOW_FORMAT,
            wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        );
        ctx.queue.write_texture(
            white.as_image_copy(),
            &[255],
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(1),
                rows_per_image: None,
            },
            wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
        );
        let white_view = white.create_view(&Default::default());

        let timestamps = ctx
            .timestamps
            .then(|| Timestamps::new(device, Pass::ALL.len() as u32));
        let bind_common = make_bind_common(
            device,
            &layouts,
            &frame_buf,
            &exact,
            &baked,
            &noise_view,
            &repeat_sampler,
            &clamp_sampler,
        );
        let mut r = Self {
            cfg: cfg.clone(),
            format: target_format,
            width,
            height,
            // Built for a frame with clouds, ahead of the first condensed
            // parcel (no compile when it appears).
            features: Features::new(cfg, true),
            any_clouds: true,
            grid_info: crate::render::pack::pack(&[], cfg.shell_m, cfg.radius_scale)?.info,
            upload_ms: 0.0,
            frame_buf,
            bound_generation: baked.generation,
            exact,
            baked,
            noise_texels: cfg.noise_texels,
            noise_view,
            repeat_sampler,
            clamp_sampler,
            layouts,
            bind_common,
            depth_view: None,
            dummy_depth_view,
            shadow_view: None,
            white_view,
            terrain: None,
            pipelines: PipelineCache::default(),
            bake_pipelines,
            bind_terrain: None,
            bind_clouds: None,
            timestamps,
            timing: TimingMode::GpuBlocking,
            always_bake: false,
            cloud_target: None,
            auto_march: AutoMarch::default(),
        };
        r.ensure(ctx)?;
        Ok(r)
    }

    /// The current configuration.
    pub fn config(&self) -> &RenderConfig {
        &self.cfg
    }

    /// The features the current frame uses.
    pub fn features(&self) -> Features {
        self.features
    }

    /// Where the last frame's grid sits and how full it is (exact: the
    /// culling grid; baked: the coarse occupancy grid over the bake region).
    pub fn grid_info(&self) -> GridInfo {
        self.grid_info
    }

    /// What the baked field covers (zeros before the first bake).
    pub fn bake_info(&self) -> BakeInfo {
        self.baked.info()
    }

    /// Names of the passes that exist for the current features, in
    /// execution order (the bake runs only in frames whose parcels moved).
    pub fn pass_names(&self) -> Vec<&'static str> {
        Pass::ALL
            .into_iter()
            .filter(|p| self.needed(*p))
            .map(|p| p.name())
            .collect()
    }

    /// Times passes with GPU timestamps (when the device has them; the
    /// default) or with the CPU clock and a queue sync per pass.
    pub fn set_gpu_timestamps(&mut self, on: bool) {
        self.set_timing_mode(if on {
            TimingMode::GpuBlocking
        } else {
            TimingMode::Cpu
        });
    }

    /// Chooses how passes are timed; see [`TimingMode`].
    pub fn set_timing_mode(&mut self, mode: TimingMode) {
        self.timing = mode;
    }

    /// The timing actually used: GPU modes need timestamp support.
    pub fn timing_mode(&self) -> TimingMode {
        match (self.timing, self.timestamps.is_some()) {
            (TimingMode::Cpu, _) | (_, false) => TimingMode::Cpu,
            (mode, true) => mode,
        }
    }

    /// Re-bake the baked field every frame, moved or not (for the bench:
    /// the cost of a frame whose parcels all moved).
    pub fn set_always_bake(&mut self, on: bool) {
        self.always_bake = on;
    }

    /// How many pipelines (render and compute) this renderer has created.
    pub fn pipelines_built(&self) -> u32 {
        self.pipelines.built + self.bake_pipelines
    }

    /// Frame size in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Changes the frame size (recreates the depth buffer).
    pub fn resize(&mut self, ctx: &GpuContext, width: u32, height: u32) -> Result<()> {
        check_size(ctx, width, height)?;
        if (width, height) != (self.width, self.height) {
            self.width = width;
            self.height = height;
            self.depth_view = None;
            self.bind_clouds = None;
            self.cloud_target = None;
            self.ensure(ctx)?;
        }
        Ok(())
    }

    /// Applies new settings, rebuilding only what depends on what changed.
    /// A new method takes effect at the next `prepare`.
    pub fn set_config(&mut self, ctx: &GpuContext, cfg: &RenderConfig) -> Result<()> {
        cfg.validate()?;
        if cfg.noise_texels != self.noise_texels {
            self.noise_view = noise_texture(ctx, cfg.noise_texels);
            self.noise_texels = cfg.noise_texels;
            self.rebind_common(ctx);
        }
        self.cfg = cfg.clone();
        self.features = Features::new(cfg, self.any_clouds);
        self.ensure(ctx)
    }

    fn rebind_common(&mut self, ctx: &GpuContext) {
        self.bind_common = make_bind_common(
            &ctx.device,
            &self.layouts,
            &self.frame_buf,
            &self.exact,
            &self.baked,
            &self.noise_view,
            &self.repeat_sampler,
            &self.clamp_sampler,
        );
        self.bound_generation = self.baked.generation;
    }

    /// The `override` constants of `pass` under the current features.
    fn constants(&self, pass: Pass) -> Vec<(&'static str, f64)> {
        let b = |v: bool| if v { 1.0 } else { 0.0 };
        let f = self.features;
        let srgb = b(!self.format.is_srgb());
        let exact = self.cfg.method == RenderMethod::Exact;
        let mut c = match pass {
            Pass::Bake | Pass::Sky | Pass::Composite => vec![("ENCODE_SRGB", srgb)],
            Pass::Shadow => vec![("ENCODE_SRGB", srgb)],
            Pass::Terrain => vec![("ENCODE_SRGB", srgb), ("HAS_SHADOWS", b(f.shadows))],
            Pass::Clouds => vec![
                ("ENCODE_SRGB", srgb),
                ("USE_NORMALS", b(f.normals)),
                ("HAS_TERRAIN", b(f.terrain)),
            ],
        };
        if exact && matches!(pass, Pass::Shadow | Pass::Clouds) {
            c.push(("GRID_CULLING", b(self.cfg.grid_culling)));
        }
        c
    }

    fn needed(&self, pass: Pass) -> bool {
        match pass {
            Pass::Bake => self.features.clouds && self.cfg.method == RenderMethod::Baked,
            Pass::Shadow => self.features.shadows,
            Pass::Sky => true,
            Pass::Terrain => self.features.terrain,
            Pass::Clouds => self.features.clouds,
            Pass::Composite => self.features.clouds && self.compute_path(),
        }
    }

    /// Whether the next frame marches in a compute shader.
    fn compute_path(&self) -> bool {
        self.auto_march.path(self.cfg.march) == MarchPath::Compute
    }

    /// The march path in use: the configured one, or what `auto` chose
    /// (None while it is still measuring).
    pub fn march_path(&self) -> Option<MarchPath> {
        match self.cfg.march {
            MarchPath::Auto => self.auto_march.chosen(),
            p => Some(p),
        }
    }

    fn key(&self, pass: Pass) -> PipelineKey {
        let compute = pass == Pass::Clouds && self.compute_path();
        PipelineKey::new(
            pass,
            self.cfg.method,
            &self.constants(pass),
            self.format,
            compute,
        )
    }

    /// Both cloud-pass pipelines when `auto` is still measuring (it
    /// alternates), else the one in use.
    fn cloud_keys(&self) -> Vec<PipelineKey> {
        let mut keys = vec![self.key(Pass::Clouds)];
        if self.cfg.march == MarchPath::Auto && self.auto_march.chosen().is_none() {
            let mut other = keys[0].clone();
            other.compute = !other.compute;
            keys.push(other);
            keys.push(PipelineKey::new(
                Pass::Composite,
                self.cfg.method,
                &self.constants(Pass::Composite),
                self.format,
                false,
            ));
        }
        keys
    }

    /// Creates what the current features need and drops what they do not.
    fn ensure(&mut self, ctx: &GpuContext) -> Result<()> {
        let device = &ctx.device;
        let f = self.features;

        // Resources.
        if f.terrain {
            if self.terrain.as_ref().map(|t| &t.cfg) != Some(&self.cfg.terrain) {
                let mesh = terrain::build_mesh(&self.cfg.terrain)?;
                use wgpu::util::DeviceExt as _;
                self.terrain = Some(TerrainGpu {
                    cfg: self.cfg.terrain.clone(),
                    vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("terrain vertices"),
                        contents: bytemuck::cast_slice(&mesh.vertices),
                        usage: wgpu::BufferUsages::VERTEX,
                    }),
                    indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("terrain indices"),
                        contents: bytemuck::cast_slice(&mesh.indices),
                        usage: wgpu::BufferUsages::INDEX,
                    }),
                    index_count: mesh.indices.len() as u32,
                });
            }
            if self.depth_view.is_none() {
                self.depth_view = Some(
                    texture_2d(
                        device,
                        "depth",
                        self.width,
                        self.height,
                        DEPTH_FORMAT,
                        wgpu::TextureUsages::RENDER_ATTACHMENT
                            | wgpu::TextureUsages::TEXTURE_BINDING,
                    )
                    .create_view(&Default::default()),
                );
                self.bind_clouds = None;
            }
        } else {
            self.terrain = None;
            if self.depth_view.take().is_some() {
                self.bind_clouds = None;
            }
        }
        let shadow_n = self.cfg.shadow_texels;
        if f.shadows {
            if self.shadow_view.as_ref().map(|(n, _)| *n) != Some(shadow_n) {
                let tex = texture_2d(
                    device,
                    "cloud shadow map",
                    shadow_n,
                    shadow_n,
                    SHADOW_FORMAT,
                    wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
                );
                self.shadow_view = Some((shadow_n, tex.create_view(&Default::default())));
                self.bind_terrain = None;
            }
        } else if self.shadow_view.take().is_some() {
            self.bind_terrain = None;
        }

        // Bind groups of group 1.
        if f.terrain && self.bind_terrain.is_none() {
            let view = self
                .shadow_view
                .as_ref()
                .map(|(_, v)| v)
                .unwrap_or(&self.white_view);
            self.bind_terrain = Some(device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("terrain: shadow map"),
                layout: &self.layouts.shadow_tex,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(view),
                }],
            }));
        }
        if f.clouds && self.bind_clouds.is_none() {
            let view = self.depth_view.as_ref().unwrap_or(&self.dummy_depth_view);
            self.bind_clouds = Some(device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("clouds: depth"),
                layout: &self.layouts.depth,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(view),
                }],
            }));
        }

        // Pipelines: built once per key and kept (see pipelines.rs), for
        // the frame with clouds and the one without as well as the current
        // one, so clouds appearing or vanishing never wait for a compile.
        let current = self.features;
        for features in [
            Features::new(&self.cfg, true),
            Features::new(&self.cfg, false),
            current,
        ] {
            self.features = features;
            let mut keys: Vec<PipelineKey> = Pass::ALL
                .into_iter()
                .filter(|p| *p != Pass::Bake && self.needed(*p))
                .map(|p| self.key(p))
                .collect();
            if self.features.clouds {
                keys.extend(self.cloud_keys());
            }
            self.features = current;
            for key in keys {
                self.pipelines.ensure(ctx, &self.layouts, &key)?;
            }
        }
        let compute_possible = self.cfg.march != MarchPath::Fragment;
        if current.clouds && compute_possible && self.cloud_target.is_none() {
            self.cloud_target = Some(self.make_cloud_target(device));
        }
        Ok(())
    }

    fn make_cloud_target(
        &self,
        device: &wgpu::Device,
    ) -> (wgpu::TextureView, wgpu::BindGroup, wgpu::BindGroup) {
        let view = texture_2d(
            device,
            "clouds (compute)",
            self.width,
            self.height,
            CLOUD_TARGET_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
        )
        .create_view(&Default::default());
        let bind = |label, layout| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view),
                }],
            })
        };
        let out = bind("clouds: compute output", &self.layouts.cloud_out);
        let input = bind("composite: clouds", &self.layouts.cloud_in);
        (view, out, input)
    }

    /// Packs and uploads a frame's data (the exact method fails, without
    /// drawing anything wrong, past its uniform limits; see [`pack`]).
    ///
    /// [`pack`]: crate::render::pack
    pub fn prepare(&mut self, ctx: &GpuContext, input: &FrameInput<'_>) -> Result<()> {
        let start = Instant::now();
        let (shell, scale) = (self.cfg.shell_m, self.cfg.radius_scale);
        let info = match self.cfg.method {
            RenderMethod::Exact => self.exact.upload(ctx, input.parcels, shell, scale)?,
            RenderMethod::Baked => self.baked.update(ctx, input.parcels, shell, scale)?,
        };
        if self.always_bake {
            self.baked.invalidate();
        }
        if self.baked.generation != self.bound_generation {
            self.rebind_common(ctx);
        }
        self.grid_info = info;
        self.any_clouds = info.parcel_count > 0;
        let features = Features::new(&self.cfg, self.any_clouds);
        if features != self.features {
            self.features = features;
            self.ensure(ctx)?;
        }
        let frame = self.frame_uniform(input);
        ctx.queue
            .write_buffer(&self.frame_buf, 0, bytemuck::bytes_of(&frame));
        self.upload_ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(())
    }

    fn frame_uniform(&self, input: &FrameInput<'_>) -> FrameUniform {
        let aspect = self.width as f32 / self.height as f32;
        let clip_from_world = input.camera.clip_from_world(aspect);
        let c = &self.cfg;
        let g = &self.grid_info;
        FrameUniform {
            clip_from_world: clip_from_world.to_cols_array_2d(),
            world_from_clip: clip_from_world.inverse().to_cols_array_2d(),
            camera_pos: input.camera.position.extend(input.time_s).to_array(),
            sun_dir: input.sun.direction.normalize().extend(0.0).to_array(),
            sun_color: input.sun.color.extend(0.0).to_array(),
            march: [
                c.step_m,
                c.max_steps as f32,
                c.light_steps as f32,
                c.light_step_m,
            ],
            cloud: [
                c.noise_amplitude,
                c.shell_m,
                c.extinction_per_m,
                c.early_exit_transmittance,
            ],
            noise: [
                1.0 / c.noise_scale_m,
                c.noise_octaves as f32,
                c.phase_g,
                0.0,
            ],
            grid_min: g.min.extend(0.0).to_array(),
            grid_cell: g.cell.extend(0.0).to_array(),
            grid_dims: [g.dims[0], g.dims[1], g.dims[2], g.parcel_count],
            shadow_rect: shadow_rect(g, input.sun.direction),
        }
    }

    /// Draws the prepared frame into `target` (a view of a `target_format`
    /// texture) and returns per-pass timings. A target of another size than
    /// the renderer's resizes the renderer first (a window that forgot to
    /// call `resize` gets a correct frame, not a validation panic); a size
    /// the device cannot hold draws nothing and returns no pass timings.
    pub fn render(&mut self, ctx: &GpuContext, target: &wgpu::TextureView) -> FrameTimings {
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
            .filter(|p| self.needed(*p) && (*p != Pass::Bake || self.baked.dirty()))
            .collect();
        let names: Vec<&'static str> = passes.iter().map(|p| p.name()).collect();
        let mode = self.timing_mode();
        let mut ts = self.timestamps.take();
        match (mode, ts.as_mut()) {
            (TimingMode::GpuBlocking, Some(ts)) => {
                let mut enc = ctx.device.create_command_encoder(&Default::default());
                for (i, pass) in passes.iter().enumerate() {
                    self.encode_pass(&mut enc, *pass, target, Some((&ts.set, 2 * i as u32)));
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
                    self.encode_pass(&mut enc, *pass, target, writes);
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
                    self.encode_pass(&mut enc, pass, target, None);
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
        timestamps: Option<(&wgpu::QuerySet, u32)>,
    ) {
        if pass == Pass::Bake {
            self.baked.encode(enc, timestamps);
            return;
        }
        let pipeline = match self.pipelines.get(&self.key(pass)) {
            Some(Pipeline::Render(p)) => p,
            Some(Pipeline::Compute(p)) => {
                let (_, out, _) = self.cloud_target.as_ref().expect("compute target exists");
                let mut cp = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("clouds (compute)"),
                    timestamp_writes: timestamps.map(|(set, i)| wgpu::ComputePassTimestampWrites {
                        query_set: set,
                        beginning_of_pass_write_index: Some(i),
                        end_of_pass_write_index: Some(i + 1),
                    }),
                });
                cp.set_pipeline(p);
                cp.set_bind_group(0, &self.bind_common, &[]);
                cp.set_bind_group(1, self.bind_clouds.as_ref(), &[]);
                cp.set_bind_group(2, out, &[]);
                cp.dispatch_workgroups(self.width.div_ceil(8), self.height.div_ceil(8), 1);
                return;
            }
            None => panic!("ensure built every needed pipeline ({})", pass.name()),
        };
        let timestamp_writes = timestamps.map(|(set, i)| wgpu::RenderPassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: Some(i),
            end_of_pass_write_index: Some(i + 1),
        });
        let color = |view, load| {
            [Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                },
            })]
        };
        let clear = wgpu::LoadOp::Clear(wgpu::Color::WHITE);
        let attachments = match pass {
            Pass::Shadow => color(
                &self.shadow_view.as_ref().expect("shadow map exists").1,
                clear,
            ),
            Pass::Sky => color(target, clear),
            _ => color(target, wgpu::LoadOp::Load),
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
        rp.set_pipeline(pipeline);
        rp.set_bind_group(0, &self.bind_common, &[]);
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
            Pass::Composite => {
                let (_, _, input) = self.cloud_target.as_ref().expect("compute target exists");
                rp.set_bind_group(1, input, &[]);
                rp.draw(0..3, 0..1);
            }
            _ => rp.draw(0..3, 0..1),
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn make_bind_common(
    device: &wgpu::Device,
    layouts: &PassLayouts,
    frame: &wgpu::Buffer,
    exact: &ExactField,
    baked: &BakedField,
    noise: &wgpu::TextureView,
    repeat: &wgpu::Sampler,
    clamp: &wgpu::Sampler,
) -> wgpu::BindGroup {
    let (field, occupancy) = baked.field();
    let entries = [
        frame.as_entire_binding(),
        exact.parcels_buf.as_entire_binding(),
        exact.grid_buf.as_entire_binding(),
        wgpu::BindingResource::TextureView(noise),
        wgpu::BindingResource::Sampler(repeat),
        wgpu::BindingResource::Sampler(clamp),
        wgpu::BindingResource::TextureView(field),
        occupancy.as_entire_binding(),
    ];
    let entries: Vec<wgpu::BindGroupEntry> = entries
        .into_iter()
        .enumerate()
        .map(|(i, resource)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource,
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("common"),
        layout: &layouts.common,
        entries: &entries,
    })
}

/// Ground rectangle (min x, min y, max x, max y) whose sun rays can cross
/// the grid box: the box's footprint and its shadow cast from its top.
pub fn shadow_rect(g: &GridInfo, sun: glam::Vec3) -> [f32; 4] {
    let sun = sun.normalize();
    let (lo, hi) = (g.min, g.max());
    // Along the sun ray from ground (x, y, 0), height z is reached at x + z·s.
    let s = glam::Vec2::new(sun.x, sun.y) / sun.z.max(0.03);
    let a = lo.truncate() - s * hi.z;
    let b = hi.truncate() - s * hi.z;
    let c = lo.truncate() - s * lo.z.max(0.0);
    let d = hi.truncate() - s * lo.z.max(0.0);
    let min = a.min(c).min(b).min(d);
    let max = a.max(c).max(b).max(d);
    [min.x, min.y, max.x, max.y]
}

fn check_size(ctx: &GpuContext, width: u32, height: u32) -> Result<()> {
    let max = ctx.device.limits().max_texture_dimension_2d;
    if width == 0 || height == 0 || width > max || height > max {
        return Err(Error::invalid(
            "frame size",
            format!("{width}×{height}"),
            format!("1 to {max} pixels per side on this device"),
        ));
    }
    Ok(())
}
