//! One physics sub-step (`ParcelWorld::step` of one sub-step, all terms on,
//! mixing included) at the parcel counts of the paper's Table 1 (8, 14, 34,
//! 85) and up to 100 000 (the scale goals: 10 000 parcels ≤ 10 ms and
//! 100 000 ≤ 100 ms per sub-step on the 2-core machine). Parcels sit on a
//! jittered lattice of spacing 250 m with radius 150 m, at most 16 layers
//! deep, so neighbours overlap and the SPH, exposed-area and exchange work is
//! real; the ground is widened so that none of them leaves the domain.

use std::hint::black_box;

use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use cumulus::physics::scale_bench::{SUBSTEP_DT_S, lattice_world};

fn physics_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("physics_substep");
    for n in [8usize, 14, 34, 85, 256, 1024, 10_000, 100_000] {
        if n >= 10_000 {
            // Each sample is a whole sub-step of ≥ 10 ms: 10 samples suffice.
            group.sample_size(10);
        }
        let world = lattice_world(n).expect("the bench world builds");
        group.bench_with_input(BenchmarkId::from_parameter(n), &world, |b, w| {
            b.iter_batched(
                || w.clone(),
                |mut w| {
                    let r = w.step(SUBSTEP_DT_S);
                    assert_eq!(r.substeps, 1, "one sub-step per measured frame");
                    black_box(r);
                    w
                },
                BatchSize::LargeInput,
            )
        });
    }
    group.finish();
}

criterion_group!(benches, physics_step);
criterion_main!(benches);
