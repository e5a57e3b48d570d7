//! The slices pass's density on the GPU (shaders/slices/implicit.wgsl:
//! `implicit_field` × `media_at`, the tiers, octaves and media filters)
//! against its CPU twin, `AuthoredField::density`
//! (src/methods/slices/gpu/field.rs), which `cumulus export` samples for
//! authored scenes: the same primitives, octaves and noise volume at
//! points across the authored clouds.

use std::path::Path;

use crate::common;
use cumulus::gpu::pass::Slots;
use cumulus::gpu::shaders::assemble_with;
use cumulus::methods::slices::gpu::buffers::GpuPrimitive;
use cumulus::methods::slices::gpu::field::AuthoredField;
use cumulus::methods::slices::gpu::passes::{FILES, SLOTS};
use cumulus::methods::slices::gpu::slices_frame;
use cumulus::scene::SceneProfile;
use glam::Vec3;
use wgpu::util::DeviceExt;

/// The compute entry evaluating the density at each point of `pts`.
const ENTRY: &str = "
@group(1) @binding(0) var<storage, read> pts: array<vec4<f32>>;
@group(1) @binding(1) var<storage, read_write> out: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x < arrayLength(&pts) {
        let p = pts[id.x].xyz;
        out[id.x] = implicit_field(p) * media_at(p);
    }
}
";

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
    let states = &frame.states;
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

    let slots: &Slots = &SLOTS;
    let src = assemble_with("slices/implicit.wgsl", FILES, slots)
        .unwrap()
        .source
        + ENTRY;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("slices twin"),
        source: wgpu::ShaderSource::Wgsl(src.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("slices twin"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    use wgpu::BufferUsages as U;
    let noise = cumulus::noise::NoiseVolume::new(cfg.noise_texels);
    let noise_view = cumulus::gpu::noise::texture(&noise, device, &ctx.queue);
    let sampler = cumulus::gpu::noise::repeat_sampler(device);
    let prims: Vec<GpuPrimitive> = frame.states.iter().map(GpuPrimitive::new).collect();
    let octaves = buffer(device, bytemuck::bytes_of(&frame.octaves), U::UNIFORM);
    let params = buffer(device, bytemuck::bytes_of(&frame.params), U::UNIFORM);
    let prims = buffer(device, bytemuck::cast_slice(&prims), U::STORAGE);
    let lists = buffer(device, bytemuck::cast_slice(&frame.index.lists), U::STORAGE);
    let pts_buf = buffer(device, bytemuck::cast_slice(&pts), U::STORAGE);
    let size = 4 * pts.len() as u64;
    let out = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("slices twin out"),
        size,
        usage: U::STORAGE | U::COPY_SRC,
        mapped_at_creation: false,
    });
    let read = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("slices twin read"),
        size,
        usage: U::MAP_READ | U::COPY_DST,
        mapped_at_creation: false,
    });
    let bind = |group: u32, entries: &[(u32, wgpu::BindingResource)]| {
        let entries: Vec<wgpu::BindGroupEntry> = entries
            .iter()
            .map(|(binding, r)| wgpu::BindGroupEntry {
                binding: *binding,
                resource: r.clone(),
            })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("slices twin"),
            layout: &pipeline.get_bind_group_layout(group),
            entries: &entries,
        })
    };
    let g0 = bind(
        0,
        &[
            (3, wgpu::BindingResource::TextureView(&noise_view)),
            (4, wgpu::BindingResource::Sampler(&sampler)),
        ],
    );
    let g1 = bind(
        1,
        &[
            (0, pts_buf.as_entire_binding()),
            (1, out.as_entire_binding()),
        ],
    );
    let g3 = bind(
        3,
        &[
            (0, octaves.as_entire_binding()),
            (1, params.as_entire_binding()),
            (2, prims.as_entire_binding()),
            (3, lists.as_entire_binding()),
        ],
    );
    let mut enc = device.create_command_encoder(&Default::default());
    {
        let mut cp = enc.begin_compute_pass(&Default::default());
        cp.set_pipeline(&pipeline);
        cp.set_bind_group(0, &g0, &[]);
        cp.set_bind_group(1, &g1, &[]);
        cp.set_bind_group(3, &g3, &[]);
        cp.dispatch_workgroups((pts.len() as u32).div_ceil(64), 1, 1);
    }
    enc.copy_buffer_to_buffer(&out, 0, &read, 0, size);
    ctx.queue.submit([enc.finish()]);
    let bytes = {
        let (tx, rx) = std::sync::mpsc::channel();
        read.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        ctx.wait_idle();
        rx.recv().unwrap().unwrap();
        read.get_mapped_range(0..size).unwrap().to_vec()
    };
    let gpu: &[f32] = bytemuck::cast_slice(&bytes);
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
