//! A single parcel released from the ground and followed through the full
//! dynamic model (paper §7.1, figs 3–4): `cumulus parcel --dynamic`. It runs
//! a [`ParcelWorld`] with one parcel and no emission, so the trajectory is
//! exactly what the scene physics does to a lone thermal.

use std::ops::RangeInclusive;

use glam::DVec3;

use super::config::{EmissionConfig, PhysicsConfig, WorldConfig};
use super::parcel::ParcelSpec;
use super::world::ParcelWorld;
use crate::atmosphere::{Environment, thermo};
use crate::error::{Error, Result};

/// The parcel's temperature at the ground that [`release`] accepts. units: K
pub const SURFACE_T_K: RangeInclusive<f64> = 150.0..=400.0;
/// Its vapour mixing ratio at the ground. units: kg/kg
pub const SURFACE_QV: RangeInclusive<f64> = 0.0..=0.1;
/// How long it may be followed. units: s
pub const DURATION_S: RangeInclusive<f64> = 1e-3..=1e7;
/// Its frame step (the physics' own `max_dt_s` range). units: s
pub const DT_S: RangeInclusive<f64> = 1e-4..=600.0;
/// Most frames (duration over step) one release may take: the trajectory
/// keeps a point of about 140 bytes per frame, so 10⁷ is ~1.4 GB.
pub const MAX_FRAMES: f64 = 1.0e7;

/// The number of frames of `duration_s` over `dt_s` (at least 1), None
/// when more than [`MAX_FRAMES`].
pub fn frames(duration_s: f64, dt_s: f64) -> Option<usize> {
    let n = (duration_s / dt_s).round().max(1.0);
    (n <= MAX_FRAMES).then_some(n as usize)
}

/// What to release.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SingleRelease {
    /// Parcel temperature at the ground. units: K
    pub surface_t_k: f64,
    /// Parcel vapour mixing ratio at the ground. units: kg/kg
    pub surface_qv: f64,
    /// Parcel radius. units: m
    pub radius_m: f64,
    /// Entrainment and detrainment on or off.
    pub mixing: bool,
    /// How long to follow it. units: s
    pub duration_s: f64,
    /// Frame step (the world may sub-step it). units: s
    pub dt_s: f64,
}

/// The parcel and its environment at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrajectoryPoint {
    /// units: s
    pub time_s: f64,
    /// Height of the centre. units: m
    pub z_m: f64,
    /// Vertical velocity. units: m s⁻¹
    pub w_m_s: f64,
    /// Parcel temperature. units: K
    pub t_k: f64,
    /// Parcel potential temperature. units: K
    pub theta_k: f64,
    /// Parcel virtual potential temperature (with condensate loading when
    /// the physics has it on). units: K
    pub theta_v_k: f64,
    /// Environment temperature at z. units: K
    pub env_t_k: f64,
    /// Environment potential temperature at z. units: K
    pub env_theta_k: f64,
    /// Environment virtual potential temperature at z. units: K
    pub env_theta_v_k: f64,
    /// units: kg/kg
    pub qv_kg_per_kg: f64,
    /// units: kg/kg
    pub ql_kg_per_kg: f64,
    /// units: m
    pub radius_m: f64,
    /// Filling ratio. units: 1
    pub fill: f64,
    /// Condensation plane. units: m
    pub cond_plane_z_m: f64,
    /// Total mass. units: kg
    pub mass_kg: f64,
    /// Water (vapour + liquid). units: kg
    pub water_kg: f64,
}

/// The trajectory and its summary.
#[derive(Debug, Clone, PartialEq)]
pub struct SingleRun {
    pub trajectory: Vec<TrajectoryPoint>,
    /// Highest centre height reached. units: m
    pub max_altitude_m: f64,
    /// Mean height over the last third of the run (the late oscillation). units: m
    pub equilibrium_altitude_m: f64,
    /// Oscillation period: twice the mean time between zero crossings of
    /// z − z_eq after the first crossing; None with fewer than 3 crossings. units: s
    pub period_s: Option<f64>,
    /// Whether the parcel died or left the domain before `duration_s`.
    pub ended_early: bool,
}

/// Releases one parcel at z = 0 and follows it for `duration_s`.
pub fn release(env: Environment, physics: &PhysicsConfig, r: SingleRelease) -> Result<SingleRun> {
    let pos = |name: &str, v: f64, range: RangeInclusive<f64>| {
        if v.is_finite() && range.contains(&v) {
            Ok(())
        } else {
            Err(Error::invalid(
                name,
                v,
                format!(
                    "a finite number between {} and {}",
                    range.start(),
                    range.end()
                ),
            ))
        }
    };
    pos("surface_t_k", r.surface_t_k, SURFACE_T_K)?;
    pos("surface_qv", r.surface_qv, SURFACE_QV)?;
    pos("duration_s", r.duration_s, DURATION_S)?;
    pos("dt_s", r.dt_s, DT_S)?;
    // The trajectory's memory is allocated up front.
    let steps = frames(r.duration_s, r.dt_s).ok_or_else(|| {
        Error::invalid(
            "duration_s / dt_s",
            r.duration_s / r.dt_s,
            format!("at most {MAX_FRAMES:e} frames"),
        )
    })?;
    let mut cfg = WorldConfig {
        physics: PhysicsConfig {
            mixing: r.mixing,
            max_dt_s: r.dt_s,
            ..physics.clone()
        },
        emission: EmissionConfig {
            enabled: false,
            ..EmissionConfig::default()
        },
        ..WorldConfig::default()
    };
    // A lone parcel in still air never leaves a wide domain sideways.
    cfg.ground.size_m = [1.0e6, 1.0e6];
    let p0 = env.pressure_pa(0.0);
    let mut world = ParcelWorld::new(env, cfg, 0)?;
    world.set_deaths(false);
    world.spawn_parcel(ParcelSpec {
        position_m: DVec3::ZERO,
        velocity_m_s: DVec3::ZERO,
        theta_k: thermo::potential_temperature_k(r.surface_t_k, p0),
        qv_kg_per_kg: r.surface_qv,
        ql_kg_per_kg: 0.0,
        radius_m: r.radius_m,
    })?;
    let mut trajectory = Vec::with_capacity(steps + 1);
    let mut ended_early = false;
    trajectory.push(point(&world));
    for _ in 0..steps {
        world.step(r.dt_s);
        if world.parcels().is_empty() {
            ended_early = true;
            break;
        }
        trajectory.push(point(&world));
    }
    Ok(summarise(trajectory, ended_early))
}

fn point(world: &ParcelWorld) -> TrajectoryPoint {
    let p = &world.parcels()[0];
    let env = world.environment();
    let z = p.position_m.z;
    let pr = env.pressure_pa(z);
    TrajectoryPoint {
        time_s: world.time_s(),
        z_m: z,
        w_m_s: p.velocity_m_s.z,
        t_k: thermo::temperature_from_theta_k(p.theta_k, pr),
        theta_k: p.theta_k,
        theta_v_k: thermo::virtual_potential_temperature_k(
            p.theta_k,
            p.qv_kg_per_kg,
            if world.config().physics.condensate_loading {
                p.ql_kg_per_kg
            } else {
                0.0
            },
        ),
        env_t_k: env.temperature_k(z),
        env_theta_k: env.theta_k(z),
        env_theta_v_k: env.theta_v_k(z),
        qv_kg_per_kg: p.qv_kg_per_kg,
        ql_kg_per_kg: p.ql_kg_per_kg,
        radius_m: p.radius_m,
        fill: p.fill,
        cond_plane_z_m: p.cond_plane_z_m,
        mass_kg: p.total_mass_kg(),
        water_kg: p.water_kg(),
    }
}

/// Max altitude, equilibrium (mean of the last third) and period from zero
/// crossings of z − z_eq.
pub fn summarise(trajectory: Vec<TrajectoryPoint>, ended_early: bool) -> SingleRun {
    let max_altitude_m = trajectory
        .iter()
        .map(|p| p.z_m)
        .fold(f64::NEG_INFINITY, f64::max);
    let late = &trajectory[trajectory.len() * 2 / 3..];
    let equilibrium_altitude_m = late.iter().map(|p| p.z_m).sum::<f64>() / late.len().max(1) as f64;
    let mut crossings = Vec::new();
    for w in trajectory.windows(2) {
        let (a, b) = (
            w[0].z_m - equilibrium_altitude_m,
            w[1].z_m - equilibrium_altitude_m,
        );
        if (a < 0.0) != (b < 0.0) && a != b {
            let f = a / (a - b);
            crossings.push(w[0].time_s + f * (w[1].time_s - w[0].time_s));
        }
    }
    let period_s = if crossings.len() >= 3 {
        let n = crossings.len() - 1;
        Some(2.0 * (crossings[n] - crossings[0]) / n as f64)
    } else {
        None
    };
    SingleRun {
        trajectory,
        max_altitude_m,
        equilibrium_altitude_m,
        period_s,
        ended_early,
    }
}
