//! One physics frame (`ParcelWorld::step`, all terms on, mixing included) at
//! the parcel counts of the paper's Table 1 (8, 14, 34, 85) and beyond.
//! Parcels sit on a jittered lattice of spacing 250 m with radius 150 m, so
//! neighbours overlap and the SPH, exposed-area and exchange work is real.

use std::hint::black_box;

use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use cumulus::atmosphere::AtmosphereSpec;
use cumulus::physics::rng::SplitMix64;
use cumulus::physics::{EmissionConfig, ParcelSpec, ParcelWorld, WorldConfig};
use glam::DVec3;

fn world_with(n: usize) -> ParcelWorld {
    let env = AtmosphereSpec::default()
        .build(std::path::Path::new("."))
        .expect("the default atmosphere builds");
    let cfg = WorldConfig {
        emission: EmissionConfig {
            enabled: false,
            ..EmissionConfig::default()
        },
        ..WorldConfig::default()
    };
    let mut w = ParcelWorld::new(env, cfg, 1).expect("valid default config");
    let mut rng = SplitMix64::new(9);
    let side = (n as f64).cbrt().ceil() as usize;
    let spacing = 250.0;
    for i in 0..n {
        let (a, b, c) = (i % side, (i / side) % side, i / (side * side));
        let jitter = DVec3::new(
            rng.range(-20.0, 20.0),
            rng.range(-20.0, 20.0),
            rng.range(-20.0, 20.0),
        );
        let pos = DVec3::new(
            (a as f64 - 0.5 * side as f64) * spacing,
            (b as f64 - 0.5 * side as f64) * spacing,
            1000.0 + c as f64 * spacing,
        ) + jitter;
        let spec = ParcelSpec::from_environment(w.environment(), pos, 1.0, 0.002, 150.0);
        w.spawn_parcel(spec).expect("valid parcel");
    }
    // One frame so that forces and neighbour lists are warm.
    w.step(1.0);
    w
}

fn physics_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("physics_step");
    for n in [8usize, 14, 34, 85, 256, 1024] {
        let world = world_with(n);
        group.bench_with_input(BenchmarkId::from_parameter(n), &world, |b, w| {
            b.iter_batched(
                || w.clone(),
                |mut w| {
                    black_box(w.step(1.0));
                    w
                },
                BatchSize::SmallInput,
            )
        });
    }
    group.finish();
}

criterion_group!(benches, physics_step);
criterion_main!(benches);
