//! More condensed parcels than the exact method's uniform array holds
//! (`pack::MAX_PARCELS`): the CPU field the export samples takes them all,
//! culled by its own uncapped grid, and where the GPU's capped grid applies
//! (≤ MAX_PARCELS) the two give the same density bit for bit. No GPU needed.

use cumulus::config::RenderConfig;
use cumulus::export::{GridSpec, read_vol, sample_grid, vol_grid, write_vol};
use cumulus::methods::raymarch::field::CloudField;
use cumulus::methods::raymarch::pack::{MAX_PARCELS, pack};
use cumulus::physics::CloudParcel;
use glam::Vec3;

/// `n` parcels on a 500 m lattice 50 wide, radii 120–300 m, bases and tops
/// varying: a field of small cumulus (deterministic, no RNG).
fn lattice(n: usize) -> Vec<CloudParcel> {
    (0..n)
        .map(|i| {
            let h = (i * 7919 % 101) as f32 / 100.0;
            let z = 1400.0 + 600.0 * h;
            CloudParcel {
                id: i as u64,
                center_m: Vec3::new((i % 50) as f32 * 500.0, (i / 50) as f32 * 500.0, z),
                radius_m: 120.0 + 180.0 * h,
                fill: 0.6 + 0.4 * (1.0 - h),
                cond_plane_z_m: 1300.0,
            }
        })
        .collect()
}

#[test]
fn more_parcels_than_the_uniform_array_export_on_the_cpu() {
    let parcels = lattice(2000);
    // No noise: what shows where is the parcels' union alone.
    let cfg = RenderConfig {
        noise_amplitude: 0.0,
        ..RenderConfig::default()
    };
    // The GPU's exact method cannot take them; the CPU field can.
    assert!(pack(&parcels, cfg.shell_m, cfg.radius_scale).is_err());
    assert!(parcels.len() > MAX_PARCELS);
    let field = CloudField::new(&parcels, &cfg, 0.0).unwrap();
    assert_eq!(field.parcels().len(), 2000);
    let (lo, hi) = field.bounds();
    for p in &parcels {
        assert!(p.center_m.cmpge(lo).all() && p.center_m.cmple(hi).all());
    }
    let spec = GridSpec::covering(lo, hi, 150.0, 256).unwrap();
    let values = sample_grid(&spec, |p| field.density(p), |_, _| {});
    let mut bytes = Vec::new();
    write_vol(&mut bytes, &vol_grid(&spec, values)).unwrap();
    let back = read_vol(&bytes, "many.vol").unwrap();
    assert_eq!(back.dims, spec.dims);
    assert_eq!(back.values.len() as u64, spec.cells());
    assert!(back.values.iter().all(|v| (0.0..=1.0).contains(v)));
    // Every parcel of the last rows (past the first 1024) shows: its
    // centre is a full shell inside its sphere and above its base, so
    // v ≥ 2f − 1 ≥ 0.2 there and ρ = smoothstep(v) > 0.
    for p in &parcels[1500..] {
        assert!(field.density(p.center_m) > 0.0, "{p:?}");
    }
    let dense = back.values.iter().filter(|&&v| v > 0.5).count();
    assert!(dense > 1000, "only {dense} dense cells");
}

#[test]
fn the_uncapped_grid_gives_the_capped_grids_density_bit_for_bit() {
    let parcels = lattice(MAX_PARCELS);
    let cfg = RenderConfig::default();
    let packed = pack(&parcels, cfg.shell_m, cfg.radius_scale).unwrap();
    let capped = CloudField::from_packed(&packed, &cfg, 30.0);
    let ours = CloudField::new(&parcels, &cfg, 30.0).unwrap();
    assert_eq!(ours.parcels(), capped.parcels());
    // The same union over every parcel that can reach a point (a max, in
    // any order): identical bits, no tolerance, noise included.
    let (lo, hi) = capped.bounds();
    let spec = GridSpec::covering(lo, hi, 120.0, 256).unwrap();
    let a = sample_grid(&spec, |p| capped.density(p), |_, _| {});
    let b = sample_grid(&spec, |p| ours.density(p), |_, _| {});
    let differ = a
        .iter()
        .zip(&b)
        .filter(|(x, y)| x.to_bits() != y.to_bits())
        .count();
    assert_eq!(differ, 0, "{differ} of {} cells differ", a.len());
    assert!(a.iter().filter(|&&v| v > 0.0).count() > 10_000);
}
