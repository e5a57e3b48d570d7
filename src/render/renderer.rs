//! The renderer: owns the GPU resources and the pass pipelines, and draws a
//! frame into any texture view (window surface or offscreen). Pass order:
//! shadow map → sky → terrain → clouds.
//!
//! "Leave out what a scene does not need": [`Features`] decides which passes
//! and resources exist; each pipeline is keyed by its `override` constants,
//! so changing a setting (normals, culling, shadows) rebuilds only the
//! pipelines whose constants changed, and a pass that is no longer needed is
//! dropped. `prepare` uploads (and times the upload); `render` draws and
//! times each pass with GPU timestamps when the device has them, else with
//! the CPU wall clock and a queue sync per pass (labelled so).

use std::collections::HashMap;
use std::time::Instant;

use crate::error::{Error, Result};
use crate::render::gpu::GpuContext;
use crate::render::pack::{self, FrameUniform, GridInfo, GridUniform, ParcelsUniform};
use crate::render::shaders::Pass;
use crate::render::terrain::{self, TerrainVertex};
use crate::render::{Features, FrameInput, RenderConfig, TerrainConfig, noise};

/// Format of the internal depth buffer (written by terrain, read by clouds).
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Format of the cloud-shadow map (sun transmittance 0..1).
pub const SHADOW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Unorm;

/// How long each pass of one frame took.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FrameTimings {
    /// (pass name, milliseconds), in execution order.
    pub passes: Vec<(String, f64)>,
    /// true: GPU timestamps; false: CPU wall clock with a queue sync per pass.
    pub gpu_timestamps: bool,
    /// CPU time of the last `prepare` (packing + buffer writes). units: ms
    pub upload_ms: f64,
}

impl FrameTimings {
    /// Sum of the pass times. units: ms
    pub fn total_ms(&self) -> f64 {
        self.passes.iter().map(|(_, ms)| ms).sum()
    }

    /// Time of one pass, if it ran. units: ms
    pub fn pass_ms(&self, name: &str) -> Option<f64> {
        self.passes
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, ms)| *ms)
    }
}

struct PassPipeline {
    constants: Vec<(&'static str, f64)>,
    pipeline: wgpu::RenderPipeline,
}

struct Timestamps {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    read: wgpu::Buffer,
    /// Lagged mode: the read buffer is being mapped for these passes;
    /// the flag turns true when the mapping is done (Err: mapping failed).
    in_flight: Option<(Vec<Pass>, std::sync::Arc<std::sync::Mutex<Option<bool>>>)>,
    /// Lagged mode: the latest timings read back.
    last: Vec<(String, f64)>,
}

/// How `render` times its passes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimingMode {
    /// GPU timestamps read back at the end of each frame (waits for the
    /// GPU; exact per frame: headless commands, bench, tests). The default.
    GpuBlocking,
    /// GPU timestamps read back when ready, without waiting: `render`
    /// returns the latest finished frame's timings (a frame or more old).
    /// For the window, so timing does not stall the frame.
    GpuLagged,
    /// CPU wall clock with a queue wait after each pass.
    Cpu,
}

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
    parcels_buf: wgpu::Buffer,
    grid_buf: wgpu::Buffer,
    noise_texels: u32,
    noise_view: wgpu::TextureView,
    repeat_sampler: wgpu::Sampler,
    clamp_sampler: wgpu::Sampler,
    layout_common: wgpu::BindGroupLayout,
    layout_shadow_tex: wgpu::BindGroupLayout,
    layout_depth: wgpu::BindGroupLayout,
    bind_common: wgpu::BindGroup,

    depth_view: Option<wgpu::TextureView>,
    dummy_depth_view: wgpu::TextureView,
    shadow_view: Option<(u32, wgpu::TextureView)>,
    white_view: wgpu::TextureView,
    terrain: Option<TerrainGpu>,

    modules: HashMap<Pass, wgpu::ShaderModule>,
    pipelines: HashMap<Pass, PassPipeline>,
    bind_terrain: Option<wgpu::BindGroup>,
    bind_clouds: Option<wgpu::BindGroup>,
    timestamps: Option<Timestamps>,
    /// How passes are timed (GPU modes fall back to Cpu without timestamps).
    timing: TimingMode,
    /// Pipelines created so far (tests check that a setting rebuilds only
    /// what depends on it).
    pipelines_built: u32,
}

fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn texture_entry(
    binding: u32,
    sample_type: wgpu::TextureSampleType,
    dim: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: dim,
            multisampled: false,
        },
        count: None,
    }
}

fn sampler_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    }
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
    /// Creates the renderer for frames of `width`×`height` in `target_format`.
    /// Until the first `prepare`, the scene is assumed to have clouds.
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

        let buffer = |label: &str, size: usize| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let frame_buf = buffer("frame uniform", std::mem::size_of::<FrameUniform>());
        let parcels_buf = buffer("parcels uniform", std::mem::size_of::<ParcelsUniform>());
        let grid_buf = buffer("grid uniform", std::mem::size_of::<GridUniform>());

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

        let layout_common = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("common"),
            entries: &[
                uniform_entry(0),
                uniform_entry(1),
                uniform_entry(2),
                texture_entry(
                    3,
                    wgpu::TextureSampleType::Float { filterable: true },
                    wgpu::TextureViewDimension::D3,
                ),
                sampler_entry(4),
                sampler_entry(5),
            ],
        });
        let layout_shadow_tex = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("terrain: shadow map"),
            entries: &[texture_entry(
                0,
                wgpu::TextureSampleType::Float { filterable: true },
                wgpu::TextureViewDimension::D2,
            )],
        });
        let layout_depth = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("clouds: depth"),
            entries: &[texture_entry(
                0,
                wgpu::TextureSampleType::Depth,
                wgpu::TextureViewDimension::D2,
            )],
        });

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

        let timestamps = ctx.timestamps.then(|| {
            let count = 2 * Pass::ALL.len() as u32;
            let bytes = 8 * count as u64;
            Timestamps {
                set: device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("pass timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count,
                }),
                resolve: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("timestamp resolve"),
                    size: bytes,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                }),
                read: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("timestamp read"),
                    size: bytes,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                in_flight: None,
                last: Vec::new(),
            }
        });

        let bind_common = Self::make_bind_common(
            device,
            &layout_common,
            [&frame_buf, &parcels_buf, &grid_buf],
            &noise_view,
            &repeat_sampler,
            &clamp_sampler,
        );
        let mut r = Self {
            cfg: cfg.clone(),
            format: target_format,
            width,
            height,
            features: Features::new(cfg, true),
            any_clouds: true,
            grid_info: pack::pack(&[], cfg.shell_m, cfg.radius_scale)?.info,
            upload_ms: 0.0,
            frame_buf,
            parcels_buf,
            grid_buf,
            noise_texels: cfg.noise_texels,
            noise_view,
            repeat_sampler,
            clamp_sampler,
            layout_common,
            layout_shadow_tex,
            layout_depth,
            bind_common,
            depth_view: None,
            dummy_depth_view,
            shadow_view: None,
            white_view,
            terrain: None,
            modules: HashMap::new(),
            pipelines: HashMap::new(),
            bind_terrain: None,
            bind_clouds: None,
            timestamps,
            timing: TimingMode::GpuBlocking,
            pipelines_built: 0,
        };
        r.ensure(ctx)?;
        Ok(r)
    }

    fn make_bind_common(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        bufs: [&wgpu::Buffer; 3],
        noise: &wgpu::TextureView,
        repeat: &wgpu::Sampler,
        clamp: &wgpu::Sampler,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("common"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: bufs[0].as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: bufs[1].as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: bufs[2].as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(noise),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::Sampler(repeat),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: wgpu::BindingResource::Sampler(clamp),
                },
            ],
        })
    }

    /// The current configuration.
    pub fn config(&self) -> &RenderConfig {
        &self.cfg
    }

    /// The features the current frame uses.
    pub fn features(&self) -> Features {
        self.features
    }

    /// Where the last packed grid sits and how full it is.
    pub fn grid_info(&self) -> GridInfo {
        self.grid_info
    }

    /// Names of the passes that exist (and run), in execution order.
    pub fn pass_names(&self) -> Vec<&'static str> {
        Pass::ALL
            .iter()
            .filter(|p| self.pipelines.contains_key(p))
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

    /// How many pipelines this renderer has created so far.
    pub fn pipelines_built(&self) -> u32 {
        self.pipelines_built
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
            self.ensure(ctx)?;
        }
        Ok(())
    }

    /// Applies new settings, rebuilding only what depends on what changed.
    pub fn set_config(&mut self, ctx: &GpuContext, cfg: &RenderConfig) -> Result<()> {
        cfg.validate()?;
        if cfg.noise_texels != self.noise_texels {
            self.noise_view = noise_texture(ctx, cfg.noise_texels);
            self.noise_texels = cfg.noise_texels;
            self.bind_common = Self::make_bind_common(
                &ctx.device,
                &self.layout_common,
                [&self.frame_buf, &self.parcels_buf, &self.grid_buf],
                &self.noise_view,
                &self.repeat_sampler,
                &self.clamp_sampler,
            );
        }
        self.cfg = cfg.clone();
        self.features = Features::new(cfg, self.any_clouds);
        self.ensure(ctx)
    }

    /// The `override` constants of `pass` under the current features.
    fn constants(&self, pass: Pass) -> Vec<(&'static str, f64)> {
        let b = |v: bool| if v { 1.0 } else { 0.0 };
        let f = self.features;
        let srgb = b(!self.format.is_srgb());
        match pass {
            Pass::Shadow => vec![
                ("ENCODE_SRGB", srgb),
                ("GRID_CULLING", b(self.cfg.grid_culling)),
            ],
            Pass::Sky => vec![("ENCODE_SRGB", srgb)],
            Pass::Terrain => vec![("ENCODE_SRGB", srgb), ("HAS_SHADOWS", b(f.shadows))],
            Pass::Clouds => vec![
                ("ENCODE_SRGB", srgb),
                ("GRID_CULLING", b(self.cfg.grid_culling)),
                ("USE_NORMALS", b(f.normals)),
                ("HAS_TERRAIN", b(f.terrain)),
            ],
        }
    }

    fn needed(&self, pass: Pass) -> bool {
        match pass {
            Pass::Shadow => self.features.shadows,
            Pass::Sky => true,
            Pass::Terrain => self.features.terrain,
            Pass::Clouds => self.features.clouds,
        }
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
                layout: &self.layout_shadow_tex,
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
                layout: &self.layout_depth,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(view),
                }],
            }));
        }

        // Pipelines.
        for pass in Pass::ALL {
            if !self.needed(pass) {
                self.pipelines.remove(&pass);
                continue;
            }
            let constants = self.constants(pass);
            if self.pipelines.get(&pass).map(|p| &p.constants) == Some(&constants) {
                continue;
            }
            // Shader or pipeline errors become an Error, not wgpu's panic.
            let scope = ctx.device.push_error_scope(wgpu::ErrorFilter::Validation);
            let pipeline = self.create_pipeline(ctx, pass, &constants);
            if let Some(e) = pollster::block_on(scope.pop()) {
                self.modules.remove(&pass);
                return Err(Error::Gpu(format!(
                    "creating the {} pass: {e}",
                    pass.name()
                )));
            }
            self.pipelines_built += 1;
            self.pipelines.insert(
                pass,
                PassPipeline {
                    constants,
                    pipeline,
                },
            );
        }
        Ok(())
    }

    fn create_pipeline(
        &mut self,
        ctx: &GpuContext,
        pass: Pass,
        constants: &[(&'static str, f64)],
    ) -> wgpu::RenderPipeline {
        let device = &ctx.device;
        let module = self.modules.entry(pass).or_insert_with(|| {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(pass.name()),
                source: wgpu::ShaderSource::Wgsl(pass.source().into()),
            })
        });
        let group1 = match pass {
            Pass::Terrain => Some(&self.layout_shadow_tex),
            Pass::Clouds => Some(&self.layout_depth),
            _ => None,
        };
        let layouts: Vec<Option<&wgpu::BindGroupLayout>> = match group1 {
            Some(l) => vec![Some(&self.layout_common), Some(l)],
            None => vec![Some(&self.layout_common)],
        };
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(pass.name()),
            bind_group_layouts: &layouts,
            immediate_size: 0,
        });
        let options = wgpu::PipelineCompilationOptions {
            constants,
            ..Default::default()
        };
        let vertex_attrs = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3];
        let terrain_buffers = [Some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<TerrainVertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &vertex_attrs,
        })];
        let (target_format, blend) = match pass {
            Pass::Shadow => (SHADOW_FORMAT, None),
            Pass::Clouds => (
                self.format,
                Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
            ),
            _ => (self.format, None),
        };
        let targets = [Some(wgpu::ColorTargetState {
            format: target_format,
            blend,
            write_mask: wgpu::ColorWrites::ALL,
        })];
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(pass.name()),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some("vs_main"),
                compilation_options: options.clone(),
                buffers: if pass == Pass::Terrain {
                    &terrain_buffers
                } else {
                    &[]
                },
            },
            primitive: wgpu::PrimitiveState {
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: (pass == Pass::Terrain).then(|| wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some("fs_main"),
                compilation_options: options,
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        })
    }

    /// Packs and uploads a frame's data. Fails (without drawing anything
    /// wrong) when the parcels exceed the uniform limits (see [`pack`]).
    pub fn prepare(&mut self, ctx: &GpuContext, input: &FrameInput<'_>) -> Result<()> {
        let start = Instant::now();
        let packed = pack::pack(input.parcels, self.cfg.shell_m, self.cfg.radius_scale)?;
        self.grid_info = packed.info;
        self.any_clouds = packed.info.parcel_count > 0;
        let features = Features::new(&self.cfg, packed.info.parcel_count > 0);
        if features != self.features {
            self.features = features;
            self.ensure(ctx)?;
        }
        let frame = self.frame_uniform(input);
        let q = &ctx.queue;
        q.write_buffer(&self.frame_buf, 0, bytemuck::bytes_of(&frame));
        if self.features.clouds {
            let n = packed.info.parcel_count as usize;
            q.write_buffer(
                &self.parcels_buf,
                0,
                bytemuck::cast_slice(&packed.parcels.parcels[..n]),
            );
            q.write_buffer(&self.grid_buf, 0, bytemuck::bytes_of(&*packed.grid));
        }
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
        if (size.width, size.height) != (self.width, self.height)
            && self.resize(ctx, size.width, size.height).is_err()
        {
            return FrameTimings {
                upload_ms: self.upload_ms,
                ..FrameTimings::default()
            };
        }
        let passes: Vec<Pass> = Pass::ALL
            .into_iter()
            .filter(|p| self.pipelines.contains_key(p))
            .collect();
        let mut timings = FrameTimings {
            passes: Vec::new(),
            gpu_timestamps: self.timing_mode() != TimingMode::Cpu,
            upload_ms: self.upload_ms,
        };
        let mode = self.timing_mode();
        if mode == TimingMode::GpuLagged {
            timings.passes = self.render_lagged(ctx, target, &passes);
        } else if let Some(ts) = self
            .timestamps
            .as_ref()
            .filter(|_| mode == TimingMode::GpuBlocking)
        {
            let mut enc = ctx.device.create_command_encoder(&Default::default());
            for (i, pass) in passes.iter().enumerate() {
                let writes = wgpu::RenderPassTimestampWrites {
                    query_set: &ts.set,
                    beginning_of_pass_write_index: Some(2 * i as u32),
                    end_of_pass_write_index: Some(2 * i as u32 + 1),
                };
                self.encode_pass(&mut enc, *pass, target, Some(writes));
            }
            let n = 2 * passes.len() as u32;
            enc.resolve_query_set(&ts.set, 0..n, &ts.resolve, 0);
            enc.copy_buffer_to_buffer(&ts.resolve, 0, &ts.read, 0, 8 * n as u64);
            ctx.queue.submit([enc.finish()]);
            let ticks = read_buffer(ctx, &ts.read, 8 * n as u64)
                .map(|b| bytemuck::pod_collect_to_vec::<u8, u64>(&b))
                .unwrap_or_default();
            let period_ns = ctx.queue.get_timestamp_period() as f64;
            for (i, pass) in passes.iter().enumerate() {
                let ms = match (ticks.get(2 * i), ticks.get(2 * i + 1)) {
                    (Some(a), Some(b)) => b.saturating_sub(*a) as f64 * period_ns / 1e6,
                    _ => f64::NAN,
                };
                timings.passes.push((pass.name().to_string(), ms));
            }
        } else {
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
        }
        timings
    }

    /// Lagged GPU timing: never waits; returns the latest finished timings.
    fn render_lagged(
        &mut self,
        ctx: &GpuContext,
        target: &wgpu::TextureView,
        passes: &[Pass],
    ) -> Vec<(String, f64)> {
        let _ = ctx.device.poll(wgpu::PollType::Poll);
        let period_ns = ctx.queue.get_timestamp_period() as f64;
        let ts = self
            .timestamps
            .as_mut()
            .expect("lagged mode needs timestamps");
        // Collect a finished readback.
        if let Some((done_passes, flag)) = &ts.in_flight {
            let state = *flag.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(ok) = state {
                let n = 2 * done_passes.len() as u64;
                if ok {
                    if let Ok(view) = ts.read.get_mapped_range(0..8 * n) {
                        let ticks = bytemuck::pod_collect_to_vec::<u8, u64>(&view);
                        ts.last = done_passes
                            .iter()
                            .enumerate()
                            .map(|(i, p)| {
                                let ms = ticks[2 * i + 1].saturating_sub(ticks[2 * i]) as f64
                                    * period_ns
                                    / 1e6;
                                (p.name().to_string(), ms)
                            })
                            .collect();
                    }
                    ts.read.unmap();
                }
                ts.in_flight = None;
            }
        }
        let measure = ts.in_flight.is_none();
        let ts = self.timestamps.as_ref().expect("checked above");
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        for (i, pass) in passes.iter().enumerate() {
            let writes = measure.then(|| wgpu::RenderPassTimestampWrites {
                query_set: &ts.set,
                beginning_of_pass_write_index: Some(2 * i as u32),
                end_of_pass_write_index: Some(2 * i as u32 + 1),
            });
            self.encode_pass(&mut enc, *pass, target, writes);
        }
        let n = 2 * passes.len() as u32;
        if measure {
            enc.resolve_query_set(&ts.set, 0..n, &ts.resolve, 0);
            enc.copy_buffer_to_buffer(&ts.resolve, 0, &ts.read, 0, 8 * n as u64);
        }
        ctx.queue.submit([enc.finish()]);
        let last = ts.last.clone();
        if measure {
            let flag = std::sync::Arc::new(std::sync::Mutex::new(None));
            let setter = flag.clone();
            ts.read
                .map_async(wgpu::MapMode::Read, 0..8 * n as u64, move |r| {
                    *setter.lock().unwrap_or_else(|e| e.into_inner()) = Some(r.is_ok());
                });
            self.timestamps.as_mut().expect("checked above").in_flight =
                Some((passes.to_vec(), flag));
        }
        last
    }

    fn encode_pass(
        &self,
        enc: &mut wgpu::CommandEncoder,
        pass: Pass,
        target: &wgpu::TextureView,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let pipeline = &self.pipelines[&pass].pipeline;
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
            _ => rp.draw(0..3, 0..1),
        }
    }
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

/// Maps `buffer` (MAP_READ), waits, and copies out its first `size` bytes.
pub(crate) fn read_buffer(ctx: &GpuContext, buffer: &wgpu::Buffer, size: u64) -> Result<Vec<u8>> {
    let (tx, rx) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, 0..size, move |r| {
        let _ = tx.send(r);
    });
    ctx.wait_idle();
    rx.recv()
        .map_err(|e| Error::Gpu(format!("readback never completed: {e}")))?
        .map_err(|e| Error::Gpu(format!("readback failed: {e}")))?;
    let bytes = buffer
        .get_mapped_range(0..size)
        .map_err(|e| Error::Gpu(format!("readback mapping: {e}")))?
        .to_vec();
    buffer.unmap();
    Ok(bytes)
}
