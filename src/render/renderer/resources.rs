//! GPU resources the renderer creates: plain textures, the shared bind group (group 0) and the compute march's target.

use crate::gpu::GpuContext;
use crate::gpu::pipelines::{CLOUD_DEPTH_FORMAT, CLOUD_TARGET_FORMAT, PassLayouts, SCENE_FORMAT};
use crate::gpu::resources::{bind_in_order, texture_2d};
use crate::methods::raymarch::baked::BakedField;
use crate::methods::raymarch::exact::ExactField;

use super::Renderer;

#[allow(clippy::too_many_arguments)]
pub(super) fn make_bind_common(
    device: &wgpu::Device,
    layouts: &PassLayouts,
    frame: &wgpu::Buffer,
    exact: &ExactField,
    baked: &BakedField,
    noise: &wgpu::TextureView,
    repeat: &wgpu::Sampler,
    clamp: &wgpu::Sampler,
) -> wgpu::BindGroup {
    let (field, light, occupancy) = baked.field();
    bind_in_order(
        device,
        "common",
        &layouts.common,
        vec![
            frame.as_entire_binding(),
            exact.parcels_buf.as_entire_binding(),
            exact.grid_buf.as_entire_binding(),
            wgpu::BindingResource::TextureView(noise),
            wgpu::BindingResource::Sampler(repeat),
            wgpu::BindingResource::Sampler(clamp),
            wgpu::BindingResource::TextureView(field),
            occupancy.as_entire_binding(),
            wgpu::BindingResource::TextureView(light),
        ],
    )
}

impl Renderer {
    pub(super) fn rebind_common(&mut self, ctx: &GpuContext) {
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

    /// The compute march's target: its colour view, the march's output
    /// bind group (colour and cloud depth), the composite's input bind
    /// group, and the cloud-depth view (the sprites sort against it).
    pub(super) fn make_cloud_target(&self, device: &wgpu::Device) -> CloudTarget {
        let view = texture_2d(
            device,
            "clouds (compute)",
            self.width,
            self.height,
            CLOUD_TARGET_FORMAT,
            // Storage: the compute march writes it; render attachment: the
            // slices pass blends its planes into it.
            wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .create_view(&Default::default());
        let depth = texture_2d(
            device,
            "cloud depth (compute)",
            self.width,
            self.height,
            CLOUD_DEPTH_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
        )
        .create_view(&Default::default());
        let bind = |label, layout, views: &[&wgpu::TextureView]| {
            let entries: Vec<wgpu::BindGroupEntry> = views
                .iter()
                .enumerate()
                .map(|(i, v)| wgpu::BindGroupEntry {
                    binding: i as u32,
                    resource: wgpu::BindingResource::TextureView(v),
                })
                .collect();
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout,
                entries: &entries,
            })
        };
        let out = bind(
            "clouds: compute output",
            &self.layouts.cloud_out,
            &[&view, &depth],
        );
        let input = bind("composite: clouds", &self.layouts.texture_in, &[&view]);
        (view, out, input, depth)
    }

    /// Group 1 of the sprite pipelines: the terrain depth (or a dummy)
    /// and the march's cloud depth (or a dummy; read only when both draw).
    pub(super) fn make_bind_sprites(&self, device: &wgpu::Device) -> wgpu::BindGroup {
        let depth = self.depth_view.as_ref().unwrap_or(&self.dummy_depth_view);
        let clouds = self
            .cloud_target
            .as_ref()
            .map(|t| &t.3)
            .unwrap_or(&self.dummy_cloud_depth_view);
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sprites: depths"),
            layout: &self.layouts.sprite_depth,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(depth),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(clouds),
                },
            ],
        })
    }

    /// The last frame's linear HDR scene (Rgba16Float, the renderer's
    /// size), before the tone map: what `--out x.exr` writes.
    pub fn scene_texture(&self) -> &wgpu::Texture {
        &self
            .scene
            .as_ref()
            .expect("ensure made the scene target")
            .texture
    }

    /// The HDR scene target of the renderer's size and the tone map's bind
    /// group reading it. COPY_SRC: `--out x.exr` reads it back.
    pub(super) fn make_scene_target(&self, device: &wgpu::Device) -> SceneTarget {
        let texture = texture_2d(
            device,
            "HDR scene",
            self.width,
            self.height,
            SCENE_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
        );
        let view = texture.create_view(&Default::default());
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("tonemap: HDR scene"),
            layout: &self.layouts.texture_in,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&view),
            }],
        });
        SceneTarget {
            texture,
            view,
            bind,
        }
    }
}

/// See [`Renderer::make_cloud_target`].
pub(super) type CloudTarget = (
    wgpu::TextureView,
    wgpu::BindGroup,
    wgpu::BindGroup,
    wgpu::TextureView,
);

/// The linear HDR target the scene passes draw into (see
/// [`crate::gpu::layouts::SCENE_FORMAT`]).
pub(crate) struct SceneTarget {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
    /// Group 1 of the tone-map pass.
    pub bind: wgpu::BindGroup,
}
