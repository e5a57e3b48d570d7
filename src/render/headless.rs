//! Headless rendering: an offscreen RGBA8 sRGB target of the renderer's size,
//! rendered with the same `Renderer::render` path as the window, and read
//! back row by row (rows padded to wgpu's 256-byte copy alignment).

use crate::config::RenderConfig;
use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::render::FrameInput;
use crate::render::renderer::{FrameTimings, Renderer, read_buffer};

/// Format of headless images (PNG-ready bytes after readback).
pub const HEADLESS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// A renderer with its own offscreen target, for several frames.
pub struct Headless {
    pub renderer: Renderer,
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    readback: wgpu::Buffer,
    bgra: bool,
}

impl Headless {
    /// A `width`×`height` offscreen renderer in [`HEADLESS_FORMAT`].
    pub fn new(ctx: &GpuContext, cfg: &RenderConfig, width: u32, height: u32) -> Result<Self> {
        Self::with_format(ctx, cfg, width, height, HEADLESS_FORMAT)
    }

    /// Like [`Headless::new`] with another 8-bit RGBA/BGRA target format
    /// (as window surfaces use); readback is RGBA either way.
    pub fn with_format(
        ctx: &GpuContext,
        cfg: &RenderConfig,
        width: u32,
        height: u32,
        format: wgpu::TextureFormat,
    ) -> Result<Self> {
        use wgpu::TextureFormat as F;
        let bgra = match format {
            F::Rgba8Unorm | F::Rgba8UnormSrgb => false,
            F::Bgra8Unorm | F::Bgra8UnormSrgb => true,
            other => {
                return Err(Error::invalid(
                    "headless target format",
                    format!("{other:?}"),
                    "Rgba8Unorm, Rgba8UnormSrgb, Bgra8Unorm or Bgra8UnormSrgb",
                ));
            }
        };
        let renderer = Renderer::new(ctx, cfg, format, width, height)?;
        let texture = super::renderer::texture_2d(
            &ctx.device,
            "headless target",
            width,
            height,
            format,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let view = texture.create_view(&Default::default());
        let readback = readback_buffer(ctx, "headless readback", 4, (width, height));
        Ok(Self {
            renderer,
            texture,
            view,
            readback,
            bgra,
        })
    }

    /// Prepares, renders and reads back one frame: tightly packed RGBA8
    /// (sRGB-encoded) rows, top row first.
    pub fn render(
        &mut self,
        ctx: &GpuContext,
        input: &FrameInput<'_>,
    ) -> Result<(Vec<u8>, FrameTimings)> {
        self.renderer.prepare(ctx, input)?;
        let timings = self.renderer.render(ctx, &self.view);
        let (w, h) = self.renderer.size();
        let mut rgba = read_rows(ctx, &self.texture, &self.readback, 4, (w, h))?;
        if self.bgra {
            rgba.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
        }
        Ok((rgba, timings))
    }
}

impl Headless {
    /// Like [`Headless::render`], after drawing `warmup` frames of the same
    /// input first: the temporal path's accumulation (`render
    /// --accumulate N`), whose history then holds those frames. The
    /// timings are the last frame's.
    pub fn render_after(
        &mut self,
        ctx: &GpuContext,
        input: &FrameInput<'_>,
        warmup: u32,
    ) -> Result<(Vec<u8>, FrameTimings)> {
        for _ in 0..warmup {
            self.renderer.prepare(ctx, input)?;
            self.renderer.render(ctx, &self.view);
        }
        self.render(ctx, input)
    }

    /// The last rendered frame's linear HDR scene (before the tone map) as
    /// RGB floats, top row first: radiance in the renderer's units (sun
    /// irradiance ~2 is daylight). What `render --out x.exr` writes.
    /// Needs [`Renderer::set_scene_whole`] before the frame (else the
    /// tone map blended the clouds and the target lacks them: an error).
    pub fn read_hdr(&self, ctx: &GpuContext) -> Result<Vec<f32>> {
        if self.renderer.scene_folded() {
            return Err(Error::Gpu(
                "the HDR scene target of the last frame lacks its clouds (the tone map blended them); \
                 call renderer.set_scene_whole(true) before rendering a frame to read back"
                    .into(),
            ));
        }
        let texture = self.renderer.scene_texture();
        let (w, h) = self.renderer.size();
        // Rgba16Float: 8 bytes per texel.
        let readback = readback_buffer(ctx, "HDR readback", 8, (w, h));
        let texels = read_rows(ctx, texture, &readback, 8, (w, h))?;
        let mut rgb = Vec::with_capacity((3 * w * h) as usize);
        for texel in texels.chunks_exact(8) {
            for c in texel[..6].chunks_exact(2) {
                rgb.push(half::f16::from_le_bytes([c[0], c[1]]).to_f32());
            }
        }
        Ok(rgb)
    }
}

/// Bytes per row of a texture copy of `width` texels of `texel_bytes`.
fn padded_row(texel_bytes: u32, width: u32) -> u32 {
    (texel_bytes * width).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
}

/// A mappable buffer that holds one copy of a `size` texture.
fn readback_buffer(
    ctx: &GpuContext,
    label: &str,
    texel_bytes: u32,
    (w, h): (u32, u32),
) -> wgpu::Buffer {
    ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: padded_row(texel_bytes, w) as u64 * h as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Copies `texture` (`size`, `texel_bytes` per texel) through `readback`
/// and returns its rows tightly packed, top row first.
fn read_rows(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
    readback: &wgpu::Buffer,
    texel_bytes: u32,
    (w, h): (u32, u32),
) -> Result<Vec<u8>> {
    let row = padded_row(texel_bytes, w);
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    enc.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: readback,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(h),
            },
        },
        wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
    );
    ctx.queue.submit([enc.finish()]);
    let padded = read_buffer(ctx, readback, row as u64 * h as u64)?;
    let mut out = Vec::with_capacity((texel_bytes * w * h) as usize);
    for r in padded.chunks_exact(row as usize) {
        out.extend_from_slice(&r[..(texel_bytes * w) as usize]);
    }
    Ok(out)
}

/// Renders one frame headless: (RGBA8 sRGB bytes, width, height).
pub fn render_to_rgba(
    ctx: &GpuContext,
    cfg: &RenderConfig,
    input: &FrameInput<'_>,
    width: u32,
    height: u32,
) -> Result<(Vec<u8>, u32, u32)> {
    let mut h = Headless::new(ctx, cfg, width, height)?;
    let (rgba, _) = h.render(ctx, input)?;
    Ok((rgba, width, height))
}
