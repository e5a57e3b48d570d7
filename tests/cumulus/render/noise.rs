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

/// GPU noise3 at `pts` with the frame's `eye`, time, octaves and cone.
fn gpu_noise(
    ctx: &cumulus::render::GpuContext,
    vol: &NoiseVolume,
    pts: &[[f32; 4]],
    eye_time: [f32; 4],
    noise: [f32; 4],
) -> Vec<f32> {
    let device = &ctx.device;
    let src = format!("{}{}", shaders::prelude(), shaders::FILES[0].1);
    let mut frame = FrameUniform::zeroed();
    frame.camera_pos = eye_time;
    frame.noise = noise;
    let frame_buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("frame"),
        contents: bytemuck::bytes_of(&frame),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let view = cumulus::gpu::noise::texture(vol, device, &ctx.queue);
    let sampler = cumulus::gpu::noise::repeat_sampler(device);
    common::points::eval_at_points(ctx, &src, "noise3(p)", pts, |pipeline| {
        vec![common::points::group_of(
            device,
            pipeline,
            0,
            &[
                (0, frame_buf.as_entire_binding()),
                (3, wgpu::BindingResource::TextureView(&view)),
                (4, wgpu::BindingResource::Sampler(&sampler)),
            ],
        )]
    })
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
