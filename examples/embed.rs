//! The cloud renderer inside another wgpu program.
//!
//! This program owns its device, its HDR colour target, its camera and its
//! sun; it draws its own background (a sky gradient from a clear colour and
//! a full-screen pass of its own would do the same), asks cumulus to draw
//! the clouds of a cloud field over it, then tone-maps and writes a PNG
//! itself. The cloud field is the default scene's, simulated to the
//! scene's start time on the CPU.
//!
//! ```sh
//! cargo run --release --example embed -- --out clouds.png
//! ```
//!
//! The three calls that matter: [`GpuContext::from_host`] wraps this
//! program's device, [`Renderer::prepare`] uploads a frame (parcels,
//! camera, sun, time) and [`Renderer::render_clouds_over`] draws the
//! clouds into this program's `Rgba16Float` target.

use std::path::PathBuf;

use anyhow::Context as _;
use clap::Parser;
use glam::Vec3;

use cumulus::config::{Camera, RenderConfig};
use cumulus::physics::ParcelWorld;
use cumulus::render::renderer::SCENE_FORMAT;
use cumulus::render::{FrameInput, GpuContext, Renderer};
use cumulus::scene::SceneProfile;
use cumulus::sky::Sun;

/// Render the default scene's clouds into this program's own HDR target.
#[derive(Debug, Parser)]
struct Args {
    /// PNG to write.
    #[arg(long)]
    out: PathBuf,
    /// Frame width. units: px
    #[arg(long, default_value_t = 640)]
    width: u32,
    /// Frame height. units: px
    #[arg(long, default_value_t = 360)]
    height: u32,
}

fn main() -> anyhow::Result<()> {
    let args = Args::parse();
    let (w, h) = (args.width, args.height);
    anyhow::ensure!(
        (16..=4096).contains(&w) && (16..=4096).contains(&h),
        "--width and --height must be 16 to 4096 pixels"
    );

    // The host's own device (any adapter; a CPU one is fine).
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        ..Default::default()
    }))
    .context("no GPU adapter (on a machine without a GPU install mesa-vulkan-drivers)")?;
    eprintln!("adapter: {}", adapter.get_info().name);
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("host"),
        ..Default::default()
    }))?;

    // The cloud field: the default scene's parcels at its start time.
    let scene = SceneProfile::embedded_default();
    let env = scene.atmosphere.build(std::path::Path::new("."))?;
    let mut world = ParcelWorld::new(env, scene.world_config(std::path::Path::new("."))?, 1)?;
    while world.time_s() < scene.simulation.start_s {
        world.step(2.0_f64.min(scene.simulation.start_s - world.time_s()));
    }
    let mut parcels = Vec::new();
    world.cloud_parcels(&mut parcels);
    eprintln!(
        "{} condensed parcels at t = {:.0} s",
        parcels.len(),
        world.time_s()
    );

    // The cloud renderer on the host's device; the host has its own ground.
    let ctx = GpuContext::from_host(instance, adapter, device.clone(), queue.clone());
    let cfg = RenderConfig {
        terrain: cumulus::config::TerrainConfig {
            enabled: false,
            ..Default::default()
        },
        ..scene.render.clone()
    };
    let mut clouds = Renderer::new(&ctx, &cfg, SCENE_FORMAT, w, h)?;

    // The host's camera and sun: looking north at the cloud layer, the
    // sun from the south-east, 35° up.
    let camera = Camera {
        position: Vec3::new(0.0, -9000.0, 600.0),
        target: Vec3::new(0.0, 0.0, 1500.0),
        vfov_rad: 50f32.to_radians(),
        near_m: 10.0,
        far_m: 60_000.0,
    };
    let (az, el) = (135f32.to_radians(), 35f32.to_radians());
    let sun = Sun::from_sky(
        Vec3::new(az.sin() * el.cos(), az.cos() * el.cos(), el.sin()),
        1.0,
        cfg.visibility_km,
    );

    // The host's HDR target, holding its background: a pale blue sky.
    let target = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("host HDR target"),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: SCENE_FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let view = target.create_view(&Default::default());
    let mut enc = device.create_command_encoder(&Default::default());
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("host background"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: &view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color {
                    r: 0.9,
                    g: 1.4,
                    b: 2.6,
                    a: 1.0,
                }),
                store: wgpu::StoreOp::Store,
            },
        })],
        ..Default::default()
    });
    queue.submit([enc.finish()]);

    // The clouds over it.
    clouds.prepare(
        &ctx,
        &FrameInput {
            camera,
            parcels: &parcels,
            sun,
            time_s: world.time_s() as f32,
        },
    )?;
    let timings = clouds.render_clouds_over(&ctx, &view)?;
    eprintln!("cloud passes: {:.2} ms", timings.total_ms());

    // The host's own tone map: exposure, Reinhard, sRGB.
    let hdr = read_rgba16f(&device, &queue, &target, w, h)?;
    let k = cfg.tone_exposure();
    let rgba: Vec<u8> = hdr
        .chunks_exact(4)
        .flat_map(|p| {
            let enc = |x: f32| {
                let y = k * x / (1.0 + k * x);
                let s = if y <= 0.003_130_8 {
                    12.92 * y
                } else {
                    1.055 * y.powf(1.0 / 2.4) - 0.055
                };
                (s.clamp(0.0, 1.0) * 255.0).round() as u8
            };
            [enc(p[0]), enc(p[1]), enc(p[2]), 255]
        })
        .collect();
    image::save_buffer(&args.out, &rgba, w, h, image::ColorType::Rgba8)
        .with_context(|| format!("writing {}", args.out.display()))?;
    eprintln!("wrote {}", args.out.display());
    Ok(())
}

/// The texels of an `Rgba16Float` texture as f32, top row first.
fn read_rgba16f(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    w: u32,
    h: u32,
) -> anyhow::Result<Vec<f32>> {
    let row = (8 * w).div_ceil(256) * 256;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("host readback"),
        size: (row * h) as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut enc = device.create_command_encoder(&Default::default());
    enc.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(h),
            },
        },
        texture.size(),
    );
    queue.submit([enc.finish()]);
    buffer.slice(..).map_async(wgpu::MapMode::Read, |_| {});
    device.poll(wgpu::PollType::wait_indefinitely())?;
    let bytes = buffer.slice(..).get_mapped_range()?;
    let mut out = Vec::with_capacity((4 * w * h) as usize);
    for y in 0..h as usize {
        let line = &bytes[y * row as usize..][..8 * w as usize];
        out.extend(
            line.chunks_exact(2)
                .map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32()),
        );
    }
    Ok(out)
}
