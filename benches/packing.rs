//! Packing the condensed parcels and their culling grid for the GPU
//! (`methods::raymarch::pack::pack`, done on the CPU every frame) at the parcel counts
//! of the performance table, on the bench's cloud-field scenes.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use cumulus::bench::{TABLE_COUNTS, scenes};
use cumulus::config::RenderConfig;
use cumulus::methods::raymarch::pack::pack;

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

criterion_group!(benches, packing);
criterion_main!(benches);
