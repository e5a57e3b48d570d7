//! Packing the condensed parcels and their culling grid for the GPU
//! (`methods::raymarch::pack::pack`, done on the CPU every frame) at the parcel counts
//! of the performance table, on the bench's cloud-field scenes; and the CPU
//! field `cumulus export` samples (`CloudField`: its uncapped culling grid
//! built, then ρ at 64³ points over its box) at and past the exact
//! method's 1024 parcels (a landscape at 1800 s holds ~2300); and the
//! export of that landscape frame itself (`export_landscape_1800s`: the
//! field, the default grid within the memory cap, every cell sampled; the
//! simulation to 1800 s is done once, outside the timing).

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use cumulus::bench::{TABLE_COUNTS, scenes};
use cumulus::config::RenderConfig;
use cumulus::export::{self, GridSpec};
use cumulus::methods::raymarch::field::CloudField;
use cumulus::methods::raymarch::pack::pack;
use cumulus::physics::ParcelWorld;

fn packing(c: &mut Criterion) {
    let cfg = RenderConfig::default();
    let mut group = c.benchmark_group("pack");
    for n in TABLE_COUNTS {
        let world = scenes::cloud_field(n).expect("bench scene builds");
        let parcels = scenes::cloud_parcels(&world);
        assert_eq!(parcels.len(), n);
        group.bench_with_input(BenchmarkId::from_parameter(n), &parcels, |b, p| {
            b.iter(|| black_box(pack(black_box(p), cfg.shell_m, cfg.radius_scale).expect("packs")))
        });
    }
    group.finish();
}

fn cpu_field(c: &mut Criterion) {
    let cfg = RenderConfig::default();
    let mut group = c.benchmark_group("cpu_field");
    group.sample_size(10);
    for n in [1024, 2304, 4096] {
        let world = scenes::cloud_field(n).expect("bench scene builds");
        let parcels = scenes::cloud_parcels(&world);
        group.bench_with_input(BenchmarkId::from_parameter(n), &parcels, |b, p| {
            b.iter(|| {
                let field = CloudField::new(black_box(p), &cfg, 0.0).expect("any count");
                let (lo, hi) = field.bounds();
                let mut sum = 0.0f32;
                for i in 0..64 * 64 * 64 {
                    let t = glam::Vec3::new(
                        (i % 64) as f32 + 0.5,
                        (i / 64 % 64) as f32 + 0.5,
                        (i / 4096) as f32 + 0.5,
                    ) / 64.0;
                    sum += field.density(lo + t * (hi - lo));
                }
                black_box(sum)
            })
        });
    }
    group.finish();
}

fn export_landscape(c: &mut Criterion) {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let path = root.join("profiles/landscape.toml");
    let (scene, source) = cumulus::scene::load_scene_with(Some(&path), &[]).expect("scene loads");
    let base = source.base_dir();
    let env = scene.atmosphere.build(&base).expect("atmosphere");
    let mut world =
        ParcelWorld::new(env, scene.world_config(&base).expect("world"), 1).expect("world");
    // The CLI's frames of 2 s (`--dt` default) to 1800 s.
    while world.time_s() < 1800.0 - 1e-9 {
        world.step(2.0f64.min(1800.0 - world.time_s()));
    }
    let mut parcels = Vec::new();
    world.cloud_parcels(&mut parcels);
    let cfg = scene.render.clone();
    let mut group = c.benchmark_group("export");
    group.sample_size(10);
    group.bench_function(BenchmarkId::new("landscape_1800s", parcels.len()), |b| {
        b.iter(|| {
            let field = CloudField::new(&parcels, &cfg, 1800.0).expect("any count");
            let (lo, hi) = field.bounds();
            let wanted = export::default_voxel_m(&cfg, &field);
            let spec =
                GridSpec::fitting(lo, hi, wanted, export::DEFAULT_MAX_MEMORY_MIB).expect("fits");
            black_box(export::sample_grid(&spec, |p| field.density(p), |_, _| {}))
        })
    });
    group.finish();
}

criterion_group!(benches, packing, cpu_field, export_landscape);
criterion_main!(benches);
