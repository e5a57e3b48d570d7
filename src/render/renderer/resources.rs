//! GPU resources the renderer creates: the shared bind group (group 0),
//! placeholders, the float cloud image, the sprites' depths and the HDR
//! scene target.

use crate::gpu::GpuContext;
use crate::gpu::layouts::{
    CLOUD_DEPTH_FORMAT, CLOUD_OUT, CLOUD_TARGET_FORMAT, COMMON, DEPTH_FORMAT, Layouts,
    SCENE_FORMAT, SHADOW_FORMAT, TEXTURE_IN,
};
use crate::gpu::method::CloudImage;
use crate::gpu::resources::texture_2d;
use crate::methods::sprites::gpu::passes::SPRITE_DEPTH;

use super::Renderer;

/// Group 0 of every pass: the frame uniform, the noise and the samplers.
pub(super) fn make_bind_common(
    device: &wgpu::Device,
    layouts: &Layouts,
    frame: &wgpu::Buffer,
    noise: &wgpu::TextureView,
    repeat: &wgpu::Sampler,
    clamp: &wgpu::Sampler,
) -> wgpu::BindGroup {
    let entry = |binding, resource| wgpu::BindGroupEntry { binding, resource };
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("common"),
        layout: &layouts.get(&COMMON),
        entries: &[
            entry(0, frame.as_entire_binding()),
            entry(3, wgpu::BindingResource::TextureView(noise)),
            entry(4, wgpu::BindingResource::Sampler(repeat)),
            entry(5, wgpu::BindingResource::Sampler(clamp)),
        ],
    })
}

/// The placeholders bound where a frame has no such texture (never read
/// then): a depth, a cloud depth, and a white (no shadow) shadow map.
pub(super) fn placeholders(
    ctx: &GpuContext,
) -> (wgpu::TextureView, wgpu::TextureView, wgpu::TextureView) {
    let device = &ctx.device;
    let view = |label, format, usage| {
        texture_2d(device, label, 1, 1, format, usage).create_view(&Default::default())
    };
    let depth = view(
        "dummy depth",
        DEPTH_FORMAT,
        wgpu::TextureUsages::TEXTURE_BINDING,
    );
    let cloud_depth = view(
        "no cloud depth",
        CLOUD_DEPTH_FORMAT,
        wgpu::TextureUsages::TEXTURE_BINDING,
    );
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
        &[255; 4],
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(4),
            rows_per_image: None,
        },
        wgpu::Extent3d {
            width: 1,
            height: 1,
            depth_or_array_layers: 1,
        },
    );
    (depth, cloud_depth, white.create_view(&Default::default()))
}

impl Renderer {
    /// The float cloud image: its colour view, the compute march's output
    /// bind group (colour and cloud depth), the composite's input bind
    /// group, and the cloud-depth view (the sprites sort against it).
    pub(super) fn make_cloud_image(&self, device: &wgpu::Device) -> CloudImage {
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
        let (out_layout, in_layout) = (self.layouts.get(&CLOUD_OUT), self.layouts.get(&TEXTURE_IN));
        let out = bind("clouds: compute output", &out_layout, &[&view, &depth]);
        let input = bind("composite: clouds", &in_layout, &[&view]);
        CloudImage {
            view,
            compute_out: out,
            composite_in: input,
            depth,
        }
    }

    /// Group 1 of the sprite pipelines: the terrain depth (or a dummy)
    /// and the march's cloud depth (or a dummy; read only when both draw).
    pub(super) fn make_bind_sprites(&self, device: &wgpu::Device) -> wgpu::BindGroup {
        let depth = self.depth_view.as_ref().unwrap_or(&self.dummy_depth_view);
        let clouds = self
            .cloud_image
            .as_ref()
            .map(|t| &t.depth)
            .unwrap_or(&self.dummy_cloud_depth_view);
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sprites: depths"),
            layout: &self.layouts.get(&SPRITE_DEPTH),
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
            layout: &self.layouts.get(&TEXTURE_IN),
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

/// The linear HDR target the scene passes draw into (see
/// [`crate::gpu::layouts::SCENE_FORMAT`]).
pub(crate) struct SceneTarget {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
    /// Group 1 of the tone-map pass.
    pub bind: wgpu::BindGroup,
}
