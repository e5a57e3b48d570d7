//! The worlds of the physics speed measurements, shared by the criterion
//! bench (`benches/physics.rs`) and `cumulus bench`'s physics table: a
//! jittered lattice of overlapping parcels, and the time of one sub-step.

use std::time::Instant;

use glam::DVec3;

use super::rng::SplitMix64;
use super::{EmissionConfig, GroundConfig, ParcelSpec, ParcelWorld, WorldConfig};
use crate::atmosphere::AtmosphereSpec;
use crate::error::Result;

/// Frame length of one measured sub-step: below every stability limit of
/// the lattice (max_dt_s = 1 s), so each frame is exactly one sub-step. units: s
pub const SUBSTEP_DT_S: f64 = 0.5;

/// Lattice spacing (radius 150 m: neighbours overlap). units: m
const SPACING_M: f64 = 250.0;
/// Most lattice layers (16 × 250 m = 4 km of depth from 1 km up).
const MAX_LAYERS: usize = 16;

/// `n` parcels (1 K warmer and 2 g/kg moister than the default atmosphere)
/// on a jittered lattice, emission off, on a ground wide enough to hold
/// them, after one warm-up frame (forces and neighbour lists current).
pub fn lattice_world(n: usize) -> Result<ParcelWorld> {
    let env = AtmosphereSpec::default().build(std::path::Path::new("."))?;
    let layers = ((n as f64).cbrt().ceil() as usize).clamp(1, MAX_LAYERS);
    let side = ((n as f64 / layers as f64).sqrt().ceil() as usize).max(1);
    let width = (side as f64 + 4.0) * SPACING_M * 2.0;
    let cfg = WorldConfig {
        emission: EmissionConfig {
            enabled: false,
            ..EmissionConfig::default()
        },
        ground: GroundConfig {
            size_m: [width.max(10_000.0), width.max(10_000.0)],
            ..GroundConfig::default()
        },
        ..WorldConfig::default()
    };
    let mut w = ParcelWorld::new(env, cfg, 1)?;
    let mut rng = SplitMix64::new(9);
    for i in 0..n {
        let (a, b, c) = (i % side, (i / side) % side, i / (side * side));
        let jitter = DVec3::new(
            rng.range(-20.0, 20.0),
            rng.range(-20.0, 20.0),
            rng.range(-20.0, 20.0),
        );
        let pos = DVec3::new(
            (a as f64 - 0.5 * side as f64) * SPACING_M,
            (b as f64 - 0.5 * side as f64) * SPACING_M,
            1000.0 + c as f64 * SPACING_M,
        ) + jitter;
        let spec = ParcelSpec::from_environment(w.environment(), pos, 1.0, 0.002, 150.0);
        w.spawn_parcel(spec)?;
    }
    w.step(SUBSTEP_DT_S);
    Ok(w)
}

/// Median wall time of one sub-step of `world` over `repeats` sub-steps
/// (each on a fresh copy, so every one starts from the same state). units: ms
pub fn substep_ms(world: &ParcelWorld, repeats: usize) -> f64 {
    let mut times: Vec<f64> = (0..repeats.max(1))
        .map(|_| {
            let mut w = world.clone();
            let t0 = Instant::now();
            let r = w.step(SUBSTEP_DT_S);
            let ms = t0.elapsed().as_secs_f64() * 1e3;
            debug_assert_eq!(r.substeps, 1);
            ms
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}
