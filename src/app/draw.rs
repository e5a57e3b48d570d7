//! What one window frame records on the GPU: the 3D view (into its own
//! texture beside the panel, or the whole window), the panel on top, and
//! the `--screenshot` read-back of the whole window.

use winit::window::Window;

use super::panel;
use super::window::Gfx;
use crate::error::{Error, Result};
use crate::render::renderer::texture_2d;

/// Where the 3D view goes in a `w`×`h` window: (left edge, width, height)
/// in pixels. Split: right of the panel; else the whole window.
pub(super) fn view3d_rect(split: bool, window: &Window, w: u32, h: u32) -> (u32, u32, u32) {
    if !split || w < 2 {
        return (0, w.max(1), h.max(1));
    }
    let panel_px = (panel::PANEL_WIDTH as f64 * window.scale_factor()).ceil() as u32;
    let x0 = panel_px.min(w - 1);
    (x0, w - x0, h.max(1))
}

fn color_pass(
    encoder: &mut wgpu::CommandEncoder,
    view: &wgpu::TextureView,
    label: &str,
    load: wgpu::LoadOp<wgpu::Color>,
) -> wgpu::RenderPass<'static> {
    encoder
        .begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[Some(crate::gpu::stored_color(view, load))],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        })
        .forget_lifetime()
}

/// The 3D view, then the panel on top, into `target` (whose view is `view`).
pub(super) fn draw_frame(
    g: &mut Gfx,
    encoder: &mut wgpu::CommandEncoder,
    target: &wgpu::Texture,
    view: &wgpu::TextureView,
    jobs: &[egui::ClippedPrimitive],
    screen: &egui_wgpu::ScreenDescriptor,
) -> crate::render::FrameTimings {
    // The 3D view: the one render path shared with the headless commands.
    // It submits its own passes (timed) before the encoder below.
    let timings = if g.split {
        let (x0, w, h) = view3d_rect(true, &g.window, g.config.width, g.config.height);
        let (tex, tex_view) = g.view3d.get_or_insert_with(|| {
            let tex = texture_2d(
                &g.ctx.device,
                "3D view",
                w,
                h,
                g.config.format,
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            );
            let v = tex.create_view(&Default::default());
            (tex, v)
        });
        let timings = g.renderer.render(&g.ctx, tex_view);
        // Clear first so no pixel is left undefined where the panel's
        // rounded width leaves a gap.
        drop(color_pass(
            encoder,
            view,
            "clear",
            wgpu::LoadOp::Clear(wgpu::Color::BLACK),
        ));
        encoder.copy_texture_to_texture(
            tex.as_image_copy(),
            wgpu::TexelCopyTextureInfo {
                texture: target,
                mip_level: 0,
                origin: wgpu::Origin3d { x: x0, y: 0, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        timings
    } else {
        g.renderer.render(&g.ctx, view)
    };
    let mut pass = color_pass(encoder, view, "egui", wgpu::LoadOp::Load);
    g.egui_renderer.render(&mut pass, jobs, screen);
    timings
}

/// Copies `tex` to the CPU as tightly packed RGBA8.
pub(super) fn read_back(
    g: &Gfx,
    mut encoder: wgpu::CommandEncoder,
    user_cmds: Vec<wgpu::CommandBuffer>,
    tex: &wgpu::Texture,
) -> Result<Vec<u8>> {
    let (w, h) = (g.config.width, g.config.height);
    let unpadded = w * 4;
    let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let padded = unpadded.div_ceil(align) * align;
    let buffer = g.ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("screenshot readback"),
        size: padded as u64 * h as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    encoder.copy_texture_to_buffer(
        tex.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(h),
            },
        },
        wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
    );
    g.ctx
        .queue
        .submit(user_cmds.into_iter().chain([encoder.finish()]));
    let slice = buffer.slice(..);
    slice.map_async(wgpu::MapMode::Read, |_| {});
    g.ctx
        .device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| Error::Gpu(format!("waiting for the screenshot copy: {e}")))?;
    let data = slice
        .get_mapped_range()
        .map_err(|e| Error::Gpu(format!("reading the screenshot back: {e}")))?;
    let bgra = matches!(
        g.config.format,
        wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
    );
    let mut rgba = Vec::with_capacity((unpadded * h) as usize);
    for row in data.chunks(padded as usize).take(h as usize) {
        for px in row[..unpadded as usize].chunks_exact(4) {
            if bgra {
                rgba.extend_from_slice(&[px[2], px[1], px[0], 255]);
            } else {
                rgba.extend_from_slice(&[px[0], px[1], px[2], 255]);
            }
        }
    }
    Ok(rgba)
}
