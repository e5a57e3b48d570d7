//! Physics error against run time: a rising cluster simulated at a sweep of
//! time steps, compared with a tiny-step reference (parcel positions, cloud
//! top, total water), with the observed order of convergence.

use std::time::Instant;

use crate::error::Result;
use crate::physics::{ParcelWorld, WorldConfig};

use super::scenes;
use super::stats::{observed_order, pareto_front};

/// One row of the physics error table.
#[derive(Debug, Clone)]
pub struct PhysicsErrorRow {
    /// Frame step = largest sub-step. units: s
    pub dt_s: f64,
    /// Sub-steps taken over the run (the CFL and sound-speed limits may
    /// split a frame).
    pub substeps: u64,
    /// Wall-clock time of the run. units: ms
    pub time_ms: f64,
    /// RMS distance of the parcels from their reference positions. units: m
    pub position_rms_m: f64,
    /// |cloud top − reference| (0 when neither has cloud). units: m
    pub cloud_top_err_m: f64,
    /// |total water − reference| / reference.
    pub water_rel_err: f64,
    /// log2(position error at 2·dt / error at dt); NaN for the coarsest.
    pub order: f64,
    /// On the Pareto front of (time, position error).
    pub pareto: bool,
}

/// The physics sweep's result.
#[derive(Debug, Clone)]
pub struct PhysicsError {
    pub parcels: usize,
    pub duration_s: f64,
    pub reference_dt_s: f64,
    pub reference_ms: f64,
    /// Condensed parcels at the end of the reference run.
    pub reference_condensed: usize,
    /// Cloud top at the end of the reference run. units: m
    pub reference_cloud_top_m: Option<f64>,
    /// Rows from the largest step to the smallest.
    pub rows: Vec<PhysicsErrorRow>,
}

struct PhysicsRun {
    world: ParcelWorld,
    substeps: u64,
    time_ms: f64,
}

fn simulate(cfg: &WorldConfig, parcels: usize, dt_s: f64, duration_s: f64) -> Result<PhysicsRun> {
    let mut cfg = cfg.clone();
    cfg.physics.max_dt_s = dt_s;
    let mut world = scenes::rising_cluster(parcels, cfg)?;
    let frames = (duration_s / dt_s).round().max(1.0) as u64;
    let start = Instant::now();
    let mut substeps = 0;
    for _ in 0..frames {
        substeps += world.step(dt_s).substeps as u64;
    }
    Ok(PhysicsRun {
        world,
        substeps,
        time_ms: start.elapsed().as_secs_f64() * 1e3,
    })
}

/// Runs the physics sweep: `parcels` in a rising cluster for `duration_s`
/// at each of `dts` (largest first) against `reference_dt_s`, all terms on
/// (the bench scenes' configuration).
pub fn physics_sweep(
    parcels: usize,
    duration_s: f64,
    dts: &[f64],
    reference_dt_s: f64,
    tick: impl FnMut(&str),
) -> Result<PhysicsError> {
    physics_sweep_with(
        &scenes::world_config(),
        parcels,
        duration_s,
        dts,
        reference_dt_s,
        tick,
    )
}

/// [`physics_sweep`] with the world configuration `cfg` (its max_dt_s is
/// set to each step in turn).
pub fn physics_sweep_with(
    cfg: &WorldConfig,
    parcels: usize,
    duration_s: f64,
    dts: &[f64],
    reference_dt_s: f64,
    mut tick: impl FnMut(&str),
) -> Result<PhysicsError> {
    tick("physics reference");
    let reference = simulate(cfg, parcels, reference_dt_s, duration_s)?;
    let rd = reference.world.diagnostics();
    let mut dts = dts.to_vec();
    dts.sort_by(|a, b| b.total_cmp(a));
    let mut rows: Vec<PhysicsErrorRow> = Vec::new();
    for dt in dts {
        tick(&format!("physics dt = {dt} s"));
        let run = simulate(cfg, parcels, dt, duration_s)?;
        let d = run.world.diagnostics();
        let a = run.world.parcels();
        let b = reference.world.parcels();
        // Parcels that escaped the domain in one run and not the other
        // cannot be paired: the error is then undefined (NaN), not hidden.
        let position_rms_m = if a.len() == b.len() && !a.is_empty() {
            let s: f64 = a
                .iter()
                .zip(b)
                .map(|(p, q)| p.position_m.distance_squared(q.position_m))
                .sum();
            (s / a.len() as f64).sqrt()
        } else {
            f64::NAN
        };
        let cloud_top_err_m = match (d.cloud_top_m, rd.cloud_top_m) {
            (Some(x), Some(y)) => (x - y).abs(),
            (None, None) => 0.0,
            _ => f64::NAN,
        };
        let water_rel_err = (d.total_water_kg - rd.total_water_kg).abs() / rd.total_water_kg;
        let order = rows
            .last()
            .filter(|prev| (prev.dt_s / dt - 2.0).abs() < 1e-9)
            .map_or(f64::NAN, |prev| {
                observed_order(prev.position_rms_m, position_rms_m)
            });
        rows.push(PhysicsErrorRow {
            dt_s: dt,
            substeps: run.substeps,
            time_ms: run.time_ms,
            position_rms_m,
            cloud_top_err_m,
            water_rel_err,
            order,
            pareto: false,
        });
    }
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| {
            let e = if r.position_rms_m.is_finite() {
                r.position_rms_m
            } else {
                f64::INFINITY
            };
            (r.time_ms, e)
        })
        .collect();
    for (row, p) in rows.iter_mut().zip(pareto_front(&pts)) {
        row.pareto = p && row.position_rms_m.is_finite();
    }
    Ok(PhysicsError {
        parcels,
        duration_s,
        reference_dt_s,
        reference_ms: reference.time_ms,
        reference_condensed: rd.condensed_parcels,
        reference_cloud_top_m: rd.cloud_top_m,
        rows,
    })
}
