//! Creating what the current features need and dropping what they do not:
//! terrain mesh, depth, shadow map, cloud targets, bind groups and the
//! pipelines (built ahead for the frame with and without clouds, and in the
//! background for the settings one click away).

use super::*;

impl Renderer {
    /// Creates what the current features need and drops what they do not.
    pub(super) fn ensure(&mut self, ctx: &GpuContext) -> Result<()> {
        let device = &ctx.device;
        let f = self.features;

        // Resources.
        if f.around.terrain {
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
                self.bind_depth = None;
            }
        } else {
            self.terrain = None;
            if self.depth_view.take().is_some() {
                self.bind_depth = None;
            }
        }
        let shadow_n = self.cfg.shadow_texels;
        if f.shadow_map {
            if self.shadow_view.as_ref().map(|(n, _)| *n) != Some(shadow_n) {
                // Storage where the adapter marches the map in compute
                // for some method (the sprites splat into it either way).
                let compute = self.shadow_compute_ok.iter().any(|c| *c);
                let storage = if compute {
                    wgpu::TextureUsages::STORAGE_BINDING
                } else {
                    wgpu::TextureUsages::empty()
                };
                let tex = texture_2d(
                    device,
                    "cloud shadow map",
                    shadow_n,
                    shadow_n,
                    SHADOW_FORMAT,
                    wgpu::TextureUsages::RENDER_ATTACHMENT
                        | wgpu::TextureUsages::TEXTURE_BINDING
                        | storage,
                );
                let view = tex.create_view(&Default::default());
                self.bind_shadow_out = compute.then(|| {
                    device.create_bind_group(&wgpu::BindGroupDescriptor {
                        label: Some("shadow: compute output"),
                        layout: &self.layouts.get(&crate::gpu::layouts::SHADOW_OUT),
                        entries: &[wgpu::BindGroupEntry {
                            binding: 0,
                            resource: wgpu::BindingResource::TextureView(&view),
                        }],
                    })
                });
                self.shadow_view = Some((shadow_n, view));
                self.shadow_fresh = false;
                self.bind_terrain = None;
            }
        } else if self.shadow_view.take().is_some() {
            self.bind_shadow_out = None;
            self.bind_terrain = None;
        }

        // Bind groups of group 1.
        if f.around.terrain && self.bind_terrain.is_none() {
            let view = self
                .shadow_view
                .as_ref()
                .map(|(_, v)| v)
                .unwrap_or(&self.white_view);
            self.bind_terrain = Some(device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("terrain: shadow map"),
                layout: &self.layouts.get(&crate::gpu::layouts::SHADOW_TEX),
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(view),
                }],
            }));
        }
        if self.bind_depth.is_none() {
            let view = self.depth_view.as_ref().unwrap_or(&self.dummy_depth_view);
            self.bind_depth = Some(device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("clouds: depth"),
                layout: &self.layouts.get(&crate::gpu::layouts::DEPTH),
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(view),
                }],
            }));
        }

        // Pipelines: built once per key and kept (see pipelines.rs), for
        // the frame with clouds and the one without as well as the current
        // one, so clouds appearing or vanishing never wait for a compile.
        for key in self.settings_keys(&self.cfg, f) {
            self.pipelines.ensure(ctx, &self.layouts, &key)?;
        }
        // And, in the background, those of every setting one click away.
        self.request_neighbours();
        if f.method.cloud_image && self.cloud_image.is_none() {
            self.cloud_image = Some(self.make_cloud_image(device));
        }
        if f.around.layers {
            self.bind_sprites = Some(self.make_bind_sprites(device));
        }
        if self.scene.is_none() {
            self.scene = Some(self.make_scene_target(device));
        }
        let i = crate::methods::index_of(self.cfg.method);
        self.methods[i].ensure(
            ctx,
            &self.layouts,
            &self.cfg,
            f.around,
            (self.width, self.height),
        )?;
        if f.around.layers && self.sprites.is_none() {
            self.sprites = Some(SpritesGpu::new(
                ctx,
                &self
                    .layouts
                    .get(&crate::methods::sprites::gpu::passes::SPRITES_GROUP),
            ));
        }
        self.ensure_ring(ctx)
    }

    /// Asks the background builder (when on: [`Renderer::set_prebuild`])
    /// for the pipelines of every setting the panel changes in one click:
    /// each method, each march path, and normals, shadows, terrain, the
    /// aerial perspective, temporal amortisation and (under `exact`) grid
    /// culling flipped.
    pub(super) fn request_neighbours(&mut self) {
        if !self.pipelines.prebuilding() {
            return;
        }
        let cfg = &self.cfg;
        let mut variants = Vec::new();
        let mut with = |f: &dyn Fn(&mut RenderConfig)| {
            let mut c = cfg.clone();
            f(&mut c);
            variants.push(c);
        };
        with(&|c| c.normals = !c.normals);
        with(&|c| c.shadows = !c.shadows);
        with(&|c| c.terrain.enabled = !c.terrain.enabled);
        with(&|c| c.aerial_perspective = !c.aerial_perspective);
        for m in TemporalMode::ALL {
            with(&|c| c.temporal = Some(m));
        }
        with(&|c| c.grid_culling = !c.grid_culling);
        for m in RenderMethod::ALL {
            with(&|c| c.method = m);
        }
        for m in [MarchPath::Fragment, MarchPath::Compute, MarchPath::Auto] {
            with(&|c| c.march = m);
        }
        let scene_sprites = !self.sprite_scene.is_empty();
        let mut keys = Vec::new();
        for v in variants.iter().filter(|v| *v != cfg) {
            let current = self.features_for(v, self.any_clouds, scene_sprites);
            keys.extend(self.settings_keys(v, current));
        }
        for key in keys {
            self.pipelines.request(&key);
        }
    }

    /// How many pipelines (render and compute) this renderer has created
    /// on its own thread, where a frame waits for them (the background
    /// builder's are counted apart: [`Renderer::pipelines_prebuilt`]).
    pub fn pipelines_built(&self) -> u32 {
        self.pipelines.built + self.methods.iter().map(|m| m.own_pipelines()).sum::<u32>()
    }

    /// Pipelines the background builder made and handed over so far.
    pub fn pipelines_prebuilt(&self) -> u32 {
        self.pipelines.prebuilt
    }

    /// Builds, on a background thread, the pipelines of every setting one
    /// panel click away from the current one (and again after each change),
    /// so toggling an option does not stop a frame for a shader compile. On
    /// in the window; off by default (headless frames never change their
    /// settings, and it would compile pipelines nobody uses).
    /// The `slices` method's vertex-field compute pass is not in the
    /// pipeline cache: it is made here, at once, when this turns on.
    pub fn set_prebuild(&mut self, ctx: &GpuContext, on: bool) -> Result<()> {
        self.pipelines
            .set_prebuild(on.then_some((&ctx.device, &self.layouts)));
        if on {
            for m in &mut self.methods {
                m.prebuild(ctx, &self.layouts)?;
            }
        }
        self.request_neighbours();
        Ok(())
    }

    /// Waits for the background builder to finish what it was asked for
    /// (tests; the window never waits).
    pub fn wait_prebuilt(&mut self) {
        self.pipelines.wait_prebuilt();
    }
}
