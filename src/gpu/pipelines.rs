//! The pipeline cache (the formats and bind-group layouts are in
//! [`crate::gpu::layouts`]).
//!
//! No stalls: a pipeline is keyed by (pass, method, `override` constants,
//! target format) and, once built, kept for the renderer's life, so clouds
//! vanishing and reappearing, or an option toggled back, never compile a
//! shader again; the renderer builds the cloud pipelines at creation, ahead
//! of the first condensed parcel, and (in the window) those of the settings
//! one click away on a background thread (src/render/prebuild.rs). `built`
//! counts creations on the calling thread, `prebuilt` the background's
//! (tests check both).

use std::collections::HashMap;

use crate::config::method::RenderMethod;
use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::gpu::prebuild::Prebuilder;
use crate::gpu::shaders::Pass;
use crate::landscape::terrain::TerrainVertex;

pub use crate::gpu::layouts::{
    CLOUD_DEPTH_FORMAT, CLOUD_TARGET_FORMAT, DEPTH_FORMAT, PassLayouts, SCENE_FORMAT,
    SHADOW_FORMAT, TEMPORAL_SCALAR_FORMAT,
};
pub(crate) use crate::gpu::layouts::{
    storage_entry, storage_texture_entry_of, uniform_buffer, uniform_entry,
};

/// What makes two render pipelines different.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct PipelineKey {
    pub pass: Pass,
    pub method: RenderMethod,
    /// `override` constants (name, value bits).
    pub constants: Vec<(&'static str, u64)>,
    pub format: wgpu::TextureFormat,
    /// The compute entry point (the cloud pass's compute path).
    pub compute: bool,
    /// The cloud pass's temporal march (`cs_temporal`, quarter rate).
    pub temporal: bool,
}

impl PipelineKey {
    /// Panics on a constant that the pass's module does not declare under
    /// `method` ([`Pass::overrides`]): wgpu would refuse the pipeline.
    pub fn new(
        pass: Pass,
        method: RenderMethod,
        constants: &[(&'static str, f64)],
        format: wgpu::TextureFormat,
        compute: bool,
    ) -> Self {
        for (name, _) in constants {
            assert!(
                pass.declares(method, name),
                "{} ({method}) declares no override {name}",
                pass.name()
            );
        }
        Self {
            pass,
            method,
            constants: constants.iter().map(|(n, v)| (*n, v.to_bits())).collect(),
            format,
            compute,
            temporal: false,
        }
    }

    /// The temporal variant of a compute cloud key.
    pub fn temporal(self) -> Self {
        Self {
            temporal: true,
            ..self
        }
    }
}

/// A render or compute pipeline.
pub enum Pipeline {
    Render(wgpu::RenderPipeline),
    Compute(wgpu::ComputePipeline),
}

/// Every pipeline built so far; see the module docs.
#[derive(Default)]
pub struct PipelineCache {
    modules: ShaderModules,
    pipelines: HashMap<PipelineKey, Pipeline>,
    /// Pipelines created on the calling thread (a frame waited for them).
    pub built: u32,
    /// Pipelines the background builder created and handed over.
    pub prebuilt: u32,
    /// Builds pipelines the next settings may need on another thread
    /// (None: off, every pipeline is built when first needed).
    prebuilder: Option<Prebuilder>,
}

impl PipelineCache {
    pub fn get(&self, key: &PipelineKey) -> Option<&Pipeline> {
        self.pipelines.get(key)
    }

    /// Builds the pipeline of `key` unless it exists: taken from the
    /// background builder if it has it (waiting for it if it is building
    /// it), else built here. Shader or pipeline errors become an Error, not
    /// wgpu's panic.
    pub fn ensure(
        &mut self,
        ctx: &GpuContext,
        layouts: &PassLayouts,
        key: &PipelineKey,
    ) -> Result<()> {
        self.collect();
        if self.pipelines.contains_key(key) {
            return Ok(());
        }
        if let Some(pre) = self.prebuilder.as_mut()
            && pre.is_pending(key)
        {
            let done = pre.wait_for(key);
            self.take(done);
            if self.pipelines.contains_key(key) {
                return Ok(());
            }
            // It failed over there: build it here for the error message.
        }
        let scope = ctx.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let pipeline = self.modules.build(&ctx.device, layouts, key);
        if let Some(e) = pollster::block_on(scope.pop()) {
            self.modules.forget(key);
            return Err(Error::Gpu(format!(
                "creating the {} pass ({} method): {e}",
                key.pass.name(),
                key.method
            )));
        }
        self.built += 1;
        self.pipelines.insert(key.clone(), pipeline);
        Ok(())
    }

    /// Starts or stops building ahead on a background thread.
    pub fn set_prebuild(&mut self, device: Option<(&wgpu::Device, &PassLayouts)>) {
        self.prebuilder = device.map(|(d, l)| Prebuilder::new(d.clone(), l.clone()));
    }

    /// Whether a background builder is on.
    pub fn prebuilding(&self) -> bool {
        self.prebuilder.is_some()
    }

    /// Asks the background builder for `key` unless it exists (nothing
    /// without one).
    pub fn request(&mut self, key: &PipelineKey) {
        if !self.pipelines.contains_key(key)
            && let Some(pre) = self.prebuilder.as_mut()
        {
            pre.request(key);
        }
    }

    /// Takes what the background builder has finished (does not wait).
    pub fn collect(&mut self) {
        if let Some(pre) = self.prebuilder.as_mut() {
            let done = pre.finished();
            self.take(done);
        }
    }

    /// Waits until the background builder has finished everything asked
    /// of it, and takes it.
    pub fn wait_prebuilt(&mut self) {
        if let Some(pre) = self.prebuilder.as_mut() {
            let done = pre.wait_all();
            self.take(done);
        }
    }

    fn take(&mut self, done: Vec<(PipelineKey, Option<Pipeline>)>) {
        for (key, pipeline) in done {
            if let Some(p) = pipeline
                && !self.pipelines.contains_key(&key)
            {
                self.prebuilt += 1;
                self.pipelines.insert(key, p);
            }
        }
    }
}

/// Shader modules by (pass, method), compiled once each.
#[derive(Default)]
pub(crate) struct ShaderModules(HashMap<(Pass, RenderMethod), wgpu::ShaderModule>);

impl ShaderModules {
    /// Drops the module of `key` (after an error, so a retry recompiles).
    pub(crate) fn forget(&mut self, key: &PipelineKey) {
        self.0.remove(&(key.pass, key.method));
    }

    /// Creates the pipeline of `key` (errors go to the device's error
    /// scope).
    pub(crate) fn build(
        &mut self,
        device: &wgpu::Device,
        layouts: &PassLayouts,
        key: &PipelineKey,
    ) -> Pipeline {
        let pass = key.pass;
        let module = self.0.entry((pass, key.method)).or_insert_with(|| {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(pass.name()),
                source: wgpu::ShaderSource::Wgsl(pass.source(key.method).into()),
            })
        });
        let group1 = match pass {
            Pass::Terrain => Some(&layouts.shadow_tex),
            Pass::Temporal => Some(&layouts.temporal_in),
            Pass::Clouds | Pass::Slices => Some(&layouts.depth),
            Pass::Sprites => Some(&layouts.sprite_depth),
            Pass::Composite | Pass::Tonemap => Some(&layouts.texture_in),
            _ => None,
        };
        let mut layouts_list: Vec<Option<&wgpu::BindGroupLayout>> = match group1 {
            Some(l) => vec![Some(&layouts.common), Some(l)],
            None => vec![Some(&layouts.common)],
        };
        if key.temporal {
            layouts_list.push(Some(&layouts.temporal_out));
        } else if key.compute && pass == Pass::Clouds {
            layouts_list.push(Some(&layouts.cloud_out));
        }
        if pass == Pass::Sprites {
            layouts_list.push(Some(&layouts.sprites));
        }
        if pass == Pass::Slices {
            layouts_list.push(Some(&layouts.slices));
        }
        if pass == Pass::Shadow && key.method == RenderMethod::Slices {
            // The implicit field's group 2 (slices/shadow_field.wgsl); no group 1.
            layouts_list.extend([None, Some(&layouts.slices)]);
        }
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(pass.name()),
            bind_group_layouts: &layouts_list,
            immediate_size: 0,
        });
        let constants: Vec<(&str, f64)> = key
            .constants
            .iter()
            .map(|(n, b)| (*n, f64::from_bits(*b)))
            .collect();
        let options = wgpu::PipelineCompilationOptions {
            constants: &constants,
            ..Default::default()
        };
        if key.compute {
            let (label, entry) = match (pass, key.temporal) {
                (Pass::Temporal, _) => ("temporal resolve", "cs_resolve"),
                (_, true) => ("clouds (temporal)", "cs_temporal"),
                _ => ("clouds (compute)", "cs_main"),
            };
            return Pipeline::Compute(device.create_compute_pipeline(
                &wgpu::ComputePipelineDescriptor {
                    label: Some(label),
                    layout: Some(&layout),
                    module,
                    entry_point: Some(entry),
                    compilation_options: options,
                    cache: None,
                },
            ));
        }
        let vertex_attrs = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3];
        let terrain_buffers = [Some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<TerrainVertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &vertex_attrs,
        })];
        let slice_buffers = [Some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<crate::methods::slices::model::SliceVertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &crate::methods::slices::gpu::VERTEX_ATTRIBUTES,
        })];
        let (target_format, blend) = match pass {
            Pass::Shadow => (SHADOW_FORMAT, None),
            // Sprite shadows splatted into the shadow map: each multiplies
            // the sun's transmittance there by its own (1 − its opacity).
            Pass::Sprites if key.format == SHADOW_FORMAT => (
                SHADOW_FORMAT,
                Some(wgpu::BlendState {
                    color: wgpu::BlendComponent {
                        src_factor: wgpu::BlendFactor::Zero,
                        dst_factor: wgpu::BlendFactor::Src,
                        operation: wgpu::BlendOperation::Add,
                    },
                    alpha: wgpu::BlendComponent::REPLACE,
                }),
            ),
            // Back to front into the float cloud target, premultiplied "over".
            Pass::Slices => (
                CLOUD_TARGET_FORMAT,
                Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
            ),
            Pass::Clouds | Pass::Composite | Pass::Sprites => (
                key.format,
                Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
            ),
            _ => (key.format, None),
        };
        let targets = [Some(wgpu::ColorTargetState {
            format: target_format,
            blend,
            write_mask: wgpu::ColorWrites::ALL,
        })];
        Pipeline::Render(
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(pass.name()),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some("vs_main"),
                    compilation_options: options.clone(),
                    buffers: match pass {
                        Pass::Terrain => &terrain_buffers,
                        Pass::Slices => &slice_buffers,
                        _ => &[],
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
            }),
        )
    }
}
