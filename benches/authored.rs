//! CPU cost of the slice renderer's per-frame work (Schpok 2003 Table 1:
//! slicing geometry, implicit sampling, shadow accumulation, octave
//! matrices) on `profiles/authored.toml`, at the Quality (planes) and
//! tessellation the paper uses (Quality 128 is the target).

use std::hint::black_box;
use std::path::Path;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use cumulus::methods::slices::model::{SlicesConfig, build_slices, octave_uniform, states_at};
use cumulus::scene::SceneProfile;
use glam::Vec3;

fn slicing(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/authored.toml");
    let scene = SceneProfile::load(&path).expect("profiles/authored.toml loads");
    let states = states_at(&scene.ellipsoids, &scene.particles, 600.0);
    let to_light = Vec3::new(0.7, -0.4, 0.6);
    let view = Vec3::from(scene.camera.target_m) - Vec3::from(scene.camera.position_m);
    let mut group = c.benchmark_group("slices");
    group.sample_size(10);
    for (quality, tessellation) in [(32, 32), (64, 32), (128, 16), (128, 32), (128, 64)] {
        let cfg = SlicesConfig {
            quality,
            tessellation,
            ..scene.render.slices.clone()
        };
        group.bench_with_input(
            BenchmarkId::new("build", format!("q{quality}_t{tessellation}")),
            &cfg,
            |b, cfg| {
                b.iter(|| {
                    black_box(
                        build_slices(black_box(&states), cfg, to_light, view)
                            .expect("slices build"),
                    )
                })
            },
        );
    }
    // The paper's split: planes stay on the GPU, only the values refresh.
    let cfg = &scene.render.slices;
    let mut geometry = build_slices(&states, cfg, to_light, view).expect("slices build");
    group.bench_function("refresh/q128_t32", |b| {
        b.iter(|| {
            geometry
                .refresh(black_box(&states), cfg, to_light)
                .expect("refreshes")
        })
    });
    let s = &scene.render.slices;
    group.bench_function("octave_uniform", |b| {
        b.iter(|| {
            black_box(octave_uniform(
                &s.tiers,
                &s.base,
                s.detail,
                s.octaves as usize,
                Vec3::ZERO,
                black_box(600.0),
            ))
        })
    });
    group.finish();
}

criterion_group!(benches, slicing);
criterion_main!(benches);
