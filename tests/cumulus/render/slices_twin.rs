//! The slices pass's density on the GPU (shaders/slices/implicit.wgsl:
//! `implicit_field` × `media_at`, the tiers, octaves and media filters)
//! against its CPU twin, `AuthoredField::density`
//! (src/methods/slices/gpu/field.rs), which `cumulus export` samples for
//! authored scenes: the same primitives, octaves and noise volume at
//! points across the authored clouds.

use std::path::Path;

use crate::common;
use crate::common::points::{eval_at_points, group_of};
use cumulus::gpu::shaders::assemble_with;
use cumulus::methods::slices::gpu::buffers::GpuPrimitive;
use cumulus::methods::slices::gpu::field::AuthoredField;
use cumulus::methods::slices::gpu::passes::{FILES, SLOTS};
use cumulus::methods::slices::gpu::slices_frame;
use cumulus::scene::SceneProfile;
use glam::Vec3;
use wgpu::util::DeviceExt;

/// A storage or uniform buffer holding `bytes`.
fn buffer(device: &wgpu::Device, bytes: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("slices twin"),
        contents: bytes,
        usage,
    })
}

#[test]
fn gpu_slices_density_matches_its_cpu_twin() {
    let Some(ctx) = common::context("the slices' density against its CPU twin") else {
        return;
    };
    let device = &ctx.device;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/authored.toml");
    let scene = SceneProfile::load(&path).unwrap();
    let cfg = &scene.render;
    let frame = slices_frame(
        &scene.ellipsoids,
        &scene.particles,
        &[],
        cfg,
        120.0,
        Vec3::new(0.3, 0.2, 0.9).normalize(),
        Vec3::new(0.0, -20000.0, 3000.0),
        Vec3::Y,
        None,
    )
    .unwrap();
    let cpu = AuthoredField::new(&frame, cfg.noise_texels);
    let (lo, hi) = cpu.bounds().expect("the authored scene has clouds");
    // Points in and around each primitive (its box, rotated with it)
    // and across the clouds' whole box, off any lattice (a fixed LCG).
    let mut s = 777u32;
    let mut rnd = || {
        s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (s >> 8) as f32 / (1u32 << 24) as f32
    };
    let states = &frame.slices.states;
    let pts: Vec<[f32; 4]> = (0..4096)
        .map(|k| {
            let u = Vec3::new(rnd(), rnd(), rnd());
            let p = if k % 4 == 0 {
                lo + (hi - lo) * u
            } else {
                let e = &states[k % states.len()];
                e.centre_m + e.rotation * (e.radii_m * (2.0 * u - Vec3::ONE))
            };
            [p.x, p.y, p.z, 0.0]
        })
        .collect();

    let src = assemble_with("slices/implicit.wgsl", FILES, &SLOTS)
        .unwrap()
        .source;
    use wgpu::BufferUsages as U;
    let noise = cumulus::noise::NoiseVolume::new(cfg.noise_texels);
    let noise_view = cumulus::gpu::noise::texture(&noise, device, &ctx.queue);
    let sampler = cumulus::gpu::noise::repeat_sampler(device);
    let prims: Vec<GpuPrimitive> = frame.slices.states.iter().map(GpuPrimitive::new).collect();
    let octaves = buffer(device, bytemuck::bytes_of(&frame.octaves), U::UNIFORM);
    let params = buffer(device, bytemuck::bytes_of(&frame.params), U::UNIFORM);
    let prims = buffer(device, bytemuck::cast_slice(&prims), U::STORAGE);
    let lists = buffer(device, bytemuck::cast_slice(&frame.index.lists), U::STORAGE);
    let expr = "implicit_field(p) * media_at(p)";
    let gpu = eval_at_points(&ctx, &src, expr, &pts, |pipeline| {
        vec![
            group_of(
                device,
                pipeline,
                0,
                &[
                    (3, wgpu::BindingResource::TextureView(&noise_view)),
                    (4, wgpu::BindingResource::Sampler(&sampler)),
                ],
            ),
            group_of(
                device,
                pipeline,
                3,
                &[
                    (0, octaves.as_entire_binding()),
                    (1, params.as_entire_binding()),
                    (2, prims.as_entire_binding()),
                    (3, lists.as_entire_binding()),
                ],
            ),
        ]
    });
    let (mut worst, mut inside, mut peak) = (0.0f32, 0, 0.0f32);
    for (p, g) in pts.iter().zip(gpu) {
        let want = cpu.density(Vec3::new(p[0], p[1], p[2]));
        worst = worst.max((g - want).abs());
        inside += (want > 0.0) as usize;
        peak = peak.max(want);
    }
    eprintln!(
        "slices density: worst |GPU − CPU| {worst:.5}, peak {peak:.3}, {inside} points inside"
    );
    // Most points lie in some cloud, so the check sees the media filters
    // and every tier the box crosses.
    assert!(inside > 1000, "{inside} points inside the clouds");
    // 0.01 of a density whose peak is ~1 (measured 0.0044 on llvmpipe):
    // the noise texture holds 8-bit
    // texels that the GPU filters in its own fixed-point arithmetic, the
    // CPU in f32 (tests/cumulus/render/noise.rs); a changed octave weight,
    // tier, filter or transform errs by tenths.
    assert!(
        worst < 0.01,
        "the slices' density is off its CPU twin by {worst}"
    );
}
