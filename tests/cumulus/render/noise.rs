//! The GPU noise (`noise3` in shaders/common.wgsl, one fetch of the RGBA
//! octave texture plus a second for octaves 5–6, mip level from the view
//! cone) against its CPU twin (`NoiseVolume::noise3_lod`, which the export
//! and src/methods/raymarch/field.rs use): the real common.wgsl, the real texture and
//! sampler, evaluated by a compute shader at points near and far from the
//! eye. Needs an adapter: without one the test fails (see `common::gpu` for
//! the opt-in skip).

use crate::common;

use bytemuck::Zeroable;
use cumulus::gpu::shaders;
use cumulus::gpu::uniform::FrameUniform;
use cumulus::noise::{self, NoiseVolume};
use wgpu::util::DeviceExt;

/// The compute entry evaluating `noise3` at each point of `pts`.
const ENTRY: &str = "
@group(1) @binding(0) var<storage, read> pts: array<vec4<f32>>;
@group(1) @binding(1) var<storage, read_write> out: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x < arrayLength(&pts) {
        out[id.x] = noise3(pts[id.x].xyz);
    }
}
";

/// GPU noise3 at `pts` with the frame's `eye`, time, octaves and cone.
fn gpu_noise(
    ctx: &cumulus::render::GpuContext,
    vol: &NoiseVolume,
    pts: &[[f32; 4]],
    eye_time: [f32; 4],
    noise: [f32; 4],
) -> Vec<f32> {
    let device = &ctx.device;
    let src = format!("{}{}{}", shaders::prelude(), shaders::FILES[0].1, ENTRY);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("noise3 test"),
        source: wgpu::ShaderSource::Wgsl(src.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("noise3 test"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let mut frame = FrameUniform::zeroed();
    frame.camera_pos = eye_time;
    frame.noise = noise;
    let frame_buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("frame"),
        contents: bytemuck::bytes_of(&frame),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let pts_buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("points"),
        contents: bytemuck::cast_slice(pts),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let size = 4 * pts.len() as u64;
    let out = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("noise out"),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let read = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("noise read"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let view = cumulus::gpu::noise::texture(vol, device, &ctx.queue);
    let sampler = cumulus::gpu::noise::repeat_sampler(device);
    let g0 = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("noise test common"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: frame_buf.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: wgpu::BindingResource::TextureView(&view),
            },
            wgpu::BindGroupEntry {
                binding: 4,
                resource: wgpu::BindingResource::Sampler(&sampler),
            },
        ],
    });
    let g1 = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("noise test io"),
        layout: &pipeline.get_bind_group_layout(1),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: pts_buf.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: out.as_entire_binding(),
            },
        ],
    });
    let mut enc = device.create_command_encoder(&Default::default());
    {
        let mut cp = enc.begin_compute_pass(&Default::default());
        cp.set_pipeline(&pipeline);
        cp.set_bind_group(0, &g0, &[]);
        cp.set_bind_group(1, &g1, &[]);
        cp.dispatch_workgroups((pts.len() as u32).div_ceil(64), 1, 1);
    }
    enc.copy_buffer_to_buffer(&out, 0, &read, 0, size);
    ctx.queue.submit([enc.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    read.slice(..).map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    ctx.wait_idle();
    rx.recv().unwrap().unwrap();
    let bytes = read.get_mapped_range(0..size).unwrap().to_vec();
    bytemuck::cast_slice(&bytes).to_vec()
}

/// Largest |GPU − CPU| at `pts` for `octaves` and view-cone texels per metre
/// `cone` (0: level 0 everywhere).
fn max_error(
    ctx: &cumulus::render::GpuContext,
    vol: &NoiseVolume,
    pts: &[[f32; 4]],
    octaves: u32,
    cone: f32,
) -> (f32, f32) {
    let (eye, time_s, inv) = ([0.0f32, -3000.0, 900.0], 250.0f32, 1.0 / 900.0f32);
    let gpu = gpu_noise(
        ctx,
        vol,
        pts,
        [eye[0], eye[1], eye[2], time_s],
        [inv, octaves as f32, 0.0, cone],
    );
    let (mut worst, mut max_lod) = (0.0f32, 0.0f32);
    for (p, g) in pts.iter().zip(&gpu) {
        let d =
            ((p[0] - eye[0]).powi(2) + (p[1] - eye[1]).powi(2) + (p[2] - eye[2]).powi(2)).sqrt();
        let lod = noise::lod(d, cone);
        max_lod = max_lod.max(lod);
        let cpu = vol.noise3_lod([p[0], p[1], p[2]], time_s, inv, octaves, lod);
        worst = worst.max((g - cpu).abs());
    }
    (worst, max_lod)
}

#[test]
fn gpu_noise_matches_its_cpu_twin_at_level_0_and_through_the_mips() {
    let Some(ctx) = common::context("GPU against CPU noise test") else {
        return;
    };
    let vol = NoiseVolume::new(cumulus::config::RenderConfig::default().noise_texels);
    // Points from 100 m to ~40 km from the eye, scattered off the lattice
    // (a fixed LCG: reproducible).
    let mut s = 12345u32;
    let mut rnd = || {
        s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (s >> 8) as f32 / (1u32 << 24) as f32
    };
    let pts: Vec<[f32; 4]> = (0..4096)
        .map(|_| {
            let r = 100.0 * 400.0f32.powf(rnd());
            [
                r * (rnd() - 0.5),
                -3000.0 + r * rnd(),
                900.0 + r * (rnd() - 0.3),
                0.0,
            ]
        })
        .collect();
    // The renderer's cone at 1080 rows, 45° field of view, 64 texels / 900 m.
    let cone = 2.0 * (22.5f32.to_radians()).tan() / 1080.0 * 64.0 / 900.0;
    // Tolerance 0.02 of the noise's range of 1: GPUs quantise the filter
    // weights (lavapipe and most hardware to 8 bits), so each trilinear
    // channel value may be off by up to 3 × 1/256 of its neighbours'
    // differences (≤ 1) and the mip lerp adds one more 1/256; the
    // doubling in noise3 multiplies by 2: 2 × 4/256 = 0.031 in the worst
    // case, and neighbour differences are far below 1 in practice. A wrong
    // channel, weight, offset, scale or level shows as errors of 0.1 and up.
    for octaves in [1, 4, 6] {
        for c in [0.0, cone, 8.0 * cone] {
            let (err, max_lod) = max_error(&ctx, &vol, &pts, octaves, c);
            eprintln!(
                "octaves {octaves}, cone {c:.2e}: max |GPU − CPU| {err:.4} (levels to {max_lod:.1})"
            );
            assert!(err < 0.02, "octaves {octaves}, cone {c}: {err}");
            if c > 0.0 {
                assert!(
                    max_lod > 1.0,
                    "far points must use coarser levels: {max_lod}"
                );
            }
        }
    }
}
