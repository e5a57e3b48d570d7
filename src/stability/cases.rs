//! The matrix of stiff and extreme cases: environments built in code (inline
//! points through [`AtmosphereSpec`], one Wyoming table parsed from a string)
//! and world configurations that push one knob each to its extreme.

use std::path::Path;

use glam::DVec3;

use crate::atmosphere::{AtmospherePoint, AtmosphereSpec, Environment, Sounding};
use crate::error::Result;
use crate::physics::WorldConfig;

/// How big the matrix is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Size {
    /// The same kinds of case, smaller: about 20 s on 2 shared cores.
    Quick,
    /// The full matrix: a few minutes on 2 shared cores.
    Full,
}

/// A block of parcels released at the start of a case: a cubic lattice,
/// jittered by a deterministic generator, each parcel with the environment's
/// air at its height plus an excess.
#[derive(Debug, Clone, PartialEq)]
pub struct Cluster {
    /// Number of parcels.
    pub count: usize,
    /// Centre of the lowest layer of the lattice. units: m
    pub base_m: DVec3,
    /// Lattice spacing. units: m
    pub spacing_m: f64,
    /// Radius of every parcel. units: m
    pub radius_m: f64,
    /// θ excess over the environment, drawn uniformly in [0, this]. units: K
    pub theta_excess_k: f64,
    /// q_v excess over the environment. units: kg/kg
    pub qv_excess: f64,
}

/// One case of the matrix.
#[derive(Debug, Clone)]
pub struct Case {
    /// Unique, short, file-name-safe name.
    pub name: String,
    /// What kind of extreme this case probes (stiffness, dt, count, sounding, wind, emission).
    pub group: &'static str,
    /// One line on what is extreme about it.
    pub note: String,
    /// The environment.
    pub env: Environment,
    /// Physics, ground, emission and wind tables.
    pub config: WorldConfig,
    /// Requested frame step (the physics sub-steps it as it needs). units: s
    pub frame_dt_s: f64,
    /// Frames to run.
    pub frames: u32,
    /// Parcels released at t = 0, if any.
    pub cluster: Option<Cluster>,
    /// Seed of the world (emission) and of the cluster jitter.
    pub seed: u64,
    /// Clamp kinds (names of `ClampCounts::kinds`) this case is expected to
    /// hit, each for a reason given where the case is made: any other
    /// kind that is hit fails the case. A case that declares `speed` is
    /// also run with the speed cap off (see `run`), and fails if that run
    /// blows up.
    pub declared_clamps: Vec<&'static str>,
}

fn pt(z_m: f64, t_c: f64, td_c: f64) -> AtmospherePoint {
    AtmospherePoint {
        z_m,
        t_c,
        td_c: Some(td_c),
        rh_percent: None,
    }
}

fn rh(z_m: f64, t_c: f64, rh_percent: f64) -> AtmospherePoint {
    AtmospherePoint {
        z_m,
        t_c,
        td_c: None,
        rh_percent: Some(rh_percent),
    }
}

fn inline(points: Vec<AtmospherePoint>, surface_hpa: f64) -> Result<Environment> {
    AtmosphereSpec {
        sounding: None,
        points,
        surface_pressure_hpa: Some(surface_hpa),
        pressure: None,
    }
    .build(Path::new("."))
}

/// A Wyoming table that stops at 700 hPa (a balloon lost early): the
/// environment ends near 3 km and uses the observed pressures.
const SOUNDING_TO_700_HPA: &str = "\
   PRES   HGHT   TEMP   DWPT   RELH   MIXR   DRCT   SKNT   THTA   THTE   THTV
    hPa      m      C      C      %   g/kg    deg   knot      K      K      K
-----------------------------------------------------------------------------
 1000.0    110   28.0   19.0
  950.0    560   23.6   17.4
  900.0   1030   19.4   15.0
  850.0   1520   15.8   12.2
  800.0   2040   12.6    6.6
  750.0   2590    9.4   -0.6
  700.0   3180    5.0   -7.0
";

/// The named environments of the matrix.
pub fn environment(name: &str) -> Result<Environment> {
    match name {
        // Fair-weather cumulus under an inversion (the default scene).
        "fair_weather" => AtmosphereSpec::default().build(Path::new(".")),
        // 20 K/km in the lowest 500 m: absolutely unstable, strong buoyancy at once.
        "superadiabatic" => inline(
            vec![
                pt(0.0, 32.0, 20.0),
                pt(500.0, 22.0, 16.0),
                pt(2000.0, 9.0, 7.0),
                pt(5000.0, -12.0, -20.0),
                pt(10_000.0, -45.0, -55.0),
            ],
            1000.0,
        ),
        // +12 K over 150 m at 800 m: a lid parcels slam into.
        "strong_inversion" => inline(
            vec![
                pt(0.0, 20.0, 15.0),
                pt(800.0, 13.0, 11.0),
                pt(950.0, 25.0, -10.0),
                pt(5000.0, 0.0, -25.0),
                pt(10_000.0, -35.0, -55.0),
            ],
            1000.0,
        ),
        // Saturated from the ground: every parcel condenses at once.
        "fog" => inline(
            vec![
                pt(0.0, 8.0, 8.0),
                pt(300.0, 7.0, 7.0),
                pt(1000.0, 3.0, 3.0),
                pt(3000.0, -8.0, -15.0),
                pt(10_000.0, -50.0, -60.0),
            ],
            1010.0,
        ),
        // No vapour at all: q_v = 0 everywhere (condensation must do nothing).
        "bone_dry" => inline(
            vec![
                rh(0.0, 30.0, 0.0),
                rh(1500.0, 15.0, 0.0),
                rh(5000.0, -10.0, 0.0),
                rh(10_000.0, -45.0, 0.0),
            ],
            1000.0,
        ),
        // Desert afternoon at 45 °C: deep dry-adiabatic layer, high cloud base.
        "hot_45c" => inline(
            vec![
                pt(0.0, 45.0, 12.0),
                pt(3000.0, 15.5, 5.0),
                pt(5000.0, 0.0, -8.0),
                pt(10_000.0, -36.0, -50.0),
            ],
            1000.0,
        ),
        // Polar winter at −40 °C: saturation vapour pressure near nothing.
        "cold_m40c" => inline(
            vec![
                pt(0.0, -40.0, -42.0),
                pt(1000.0, -30.0, -36.0),
                pt(5000.0, -50.0, -60.0),
                pt(10_000.0, -65.0, -80.0),
            ],
            1030.0,
        ),
        // Tropical: moist and deep, tropopause at 18 km, stratosphere above.
        "tropopause_18km" => inline(
            vec![
                pt(0.0, 30.0, 25.0),
                pt(1000.0, 23.0, 20.0),
                pt(5000.0, -1.0, -6.0),
                pt(10_000.0, -36.0, -45.0),
                pt(15_000.0, -68.0, -80.0),
                pt(18_000.0, -83.0, -95.0),
                pt(22_000.0, -62.0, -95.0),
            ],
            1010.0,
        ),
        // A real-format sounding that ends at 700 hPa (~3 km), observed pressure.
        "ends_at_700hpa" => Sounding::parse(
            SOUNDING_TO_700_HPA,
            Path::new("<stability: 700 hPa sounding>"),
        )?
        .to_environment(),
        other => Err(crate::error::Error::invalid(
            "stability environment",
            other,
            "one of fair_weather, superadiabatic, strong_inversion, fog, bone_dry, hot_45c, cold_m40c, tropopause_18km, ends_at_700hpa",
        )),
    }
}

/// Names of the environments, in matrix order.
pub const ENVIRONMENTS: [&str; 9] = [
    "fair_weather",
    "superadiabatic",
    "strong_inversion",
    "fog",
    "bone_dry",
    "hot_45c",
    "cold_m40c",
    "tropopause_18km",
    "ends_at_700hpa",
];

/// A world configuration with emission off (clusters only).
fn quiet() -> WorldConfig {
    let mut cfg = WorldConfig::default();
    cfg.emission.enabled = false;
    cfg
}

/// A world configuration with strong, steady emission (no diurnal cycle).
fn emitting(rate_per_km2_per_h: f64, max_parcels: u32) -> WorldConfig {
    let mut cfg = WorldConfig::default();
    cfg.emission.rate_per_km2_per_h = rate_per_km2_per_h;
    cfg.emission.diurnal = false;
    cfg.emission.max_parcels = max_parcels;
    cfg
}

/// A lattice of `count` parcels just above the ground, spaced 0.9 h: the
/// spheres (r = h/2) overlap a little and SPH sees its neighbours.
fn cluster(count: usize, h: f64) -> Cluster {
    Cluster {
        count,
        base_m: DVec3::new(0.0, 0.0, 300.0),
        spacing_m: 0.9 * h,
        radius_m: 0.5 * h,
        theta_excess_k: 2.0,
        qv_excess: 1.0e-3,
    }
}

/// The matrix.
pub fn matrix(size: Size) -> Result<Vec<Case>> {
    let quick = size == Size::Quick;
    let fair = environment("fair_weather")?;
    let h = crate::physics::PhysicsConfig::default().support_radius_m;
    let mut cases = Vec::new();

    // SPH stiffness K from 1e2 to 1e6 on an interacting cluster.
    let (n, secs) = if quick { (125, 120.0) } else { (343, 600.0) };
    for k in [1e2, 1e3, 1e4, 1e5, 1e6] {
        let mut cfg = quiet();
        cfg.physics.stiffness = k;
        cases.push(Case {
            name: format!("stiffness_{k:.0e}"),
            group: "stiffness",
            note: format!("K = {k:.0e} m²/s², {n}-parcel cluster, dt 1 s"),
            env: fair.clone(),
            config: cfg,
            frame_dt_s: 1.0,
            frames: secs as u32,
            cluster: Some(cluster(n, h)),
            seed: 11,
            // At K = 1e6 the overlap pushes parcels past the 80 m/s speed
            // cap; the uncapped rerun (run.rs) shows the push is bounded on
            // its own (KE ratio 0.18–0.20, 92–93 m/s, quick and full).
            declared_clamps: if k >= 1e6 { vec!["speed"] } else { vec![] },
        });
    }
    // The stiffest SPH at the longest frame: the sub-step budget is hit.
    let mut cfg = quiet();
    cfg.physics.stiffness = 1e6;
    cases.push(Case {
        name: "stiffness_1e6_dt_10".into(),
        group: "stiffness",
        note: format!("K = 1e6 with 10 s frames (sub-step budget), {n}-parcel cluster"),
        env: fair.clone(),
        config: cfg,
        frame_dt_s: 10.0,
        frames: (secs / 10.0) as u32,
        cluster: Some(cluster(n, h)),
        seed: 11,
        // 10 s frames need more sub-steps than the budget, and the
        // over-long sub-steps then drive parcels into the speed cap;
        // uncapped they stay bounded (KE ratio 0.07).
        declared_clamps: vec!["speed", "substep_budget"],
    });

    // The most viscous SPH validate() allows: explicit viscosity past its
    // stable rate (guarded in the physics, counted as `viscosity` clamps).
    let mut cfg = quiet();
    cfg.physics.viscosity_mu = 1e6;
    cases.push(Case {
        name: "viscosity_1e6".into(),
        group: "stiffness",
        note: format!("μ = 1e6 Pa s (the largest allowed), {n}-parcel cluster, dt 1 s"),
        env: fair.clone(),
        config: cfg,
        frame_dt_s: 1.0,
        frames: secs as u32,
        cluster: Some(cluster(n, h)),
        seed: 11,
        // The point of the case: viscosity past its stable rate is scaled down.
        declared_clamps: vec!["viscosity"],
    });

    // Requested frame step from 0.01 s to 10 s, emission and a cluster.
    let secs = if quick { 300.0 } else { 1200.0 };
    let n = if quick { 27 } else { 64 };
    for dt in [0.01, 0.1, 1.0, 10.0] {
        cases.push(Case {
            name: format!("dt_{dt}"),
            group: "dt",
            note: format!("frame dt {dt} s, emission + {n}-parcel cluster"),
            env: fair.clone(),
            config: emitting(300.0, 512),
            frame_dt_s: dt,
            frames: (secs / dt).round() as u32,
            cluster: Some(cluster(n, h)),
            seed: 21,
            declared_clamps: vec![],
        });
    }

    // Parcel counts up to 10 000 (the largest only for a few frames).
    let counts: &[(usize, u32)] = if quick {
        &[(10, 150), (100, 60), (1000, 15), (10_000, 3)]
    } else {
        &[(10, 600), (100, 300), (1000, 150), (10_000, 30)]
    };
    for &(n, frames) in counts {
        let mut cfg = quiet();
        cfg.emission.max_parcels = 20_000;
        cases.push(Case {
            name: format!("parcels_{n}"),
            group: "count",
            note: format!("{n}-parcel cluster, {frames} frames of 2 s"),
            env: fair.clone(),
            config: cfg,
            frame_dt_s: 2.0,
            frames,
            cluster: Some(cluster(n, h)),
            seed: 31,
            declared_clamps: vec![],
        });
    }

    // 100 000 parcels (full matrix only: ~20 s even for one frame, most of
    // it the harness's set-up): a cluster (h = 150 m, so the 47-parcel-wide
    // lattice fits in the domain and under the profile's top) and emission
    // up to 100 000 alive.
    if !quick {
        let mut cfg = quiet();
        cfg.physics.support_radius_m = 150.0;
        cfg.emission.max_parcels = 100_000;
        let frames = 10;
        cases.push(Case {
            name: "parcels_100000".into(),
            group: "count",
            note: format!("100 000-parcel cluster (h = 150 m), {frames} frames of 2 s"),
            env: fair.clone(),
            config: cfg,
            frame_dt_s: 2.0,
            frames,
            cluster: Some(cluster(100_000, 150.0)),
            seed: 32,
            declared_clamps: vec![],
        });
        // Emission that really reaches 100 000 alive. On the 10 km ground
        // the births crowd the hot patches and, overlapping at random, push
        // each other into the ground. Here a 100 km × 100 km ground heats
        // uniformly (background 1, no patches: every cell emits with the
        // full 2 K and 2 g/kg excess) at 1 000 parcels/km²/h: ~2 800 births
        // a second, 1.4 per km² per 5 s frame. Most births do not live long:
        // the young parcels rise slowly (a 2 K excess lifts them ~100 m in
        // the first minute) and crowd the layer near the ground, hence the
        // large ground (docs/notes.md, "Stability matrix").
        // Measured: 99 966 alive at the peak (the cap is 100 000; a few die
        // every frame), 150 sub-steps, 1.3 s of physics per sub-step on 2
        // cores under a load of ~14 (the full matrix only; CI runs --quick).
        let mut cfg = emitting(1000.0, 100_000);
        cfg.ground.size_m = [100_000.0, 100_000.0];
        cfg.ground.patches = 0;
        cfg.ground.background = 1.0;
        let frames = 30;
        cases.push(Case {
            name: "emission_100000".into(),
            group: "count",
            note: format!(
                "1 000 parcels/km²/h over 100 km × 100 km up to 100 000 alive, {frames} frames of 5 s"
            ),
            env: fair.clone(),
            config: cfg,
            frame_dt_s: 5.0,
            frames,
            cluster: None,
            seed: 33,
            // As in the bursts: parcels born overlapping at random.
            declared_clamps: vec!["atm_force"],
        });
    }

    // Extreme soundings: emission plus a cluster from the ground.
    let secs = if quick { 600.0 } else { 2400.0 };
    let n = if quick { 27 } else { 125 };
    for name in ENVIRONMENTS.iter().skip(1) {
        let mut cfg = emitting(300.0, 512);
        let mut cl = cluster(n, h);
        match *name {
            // Nothing may bring water into bone-dry air.
            "bone_dry" => {
                cfg.ground.moisture_excess_kg_per_kg = 0.0;
                cl.qv_excess = 0.0;
            }
            // Let parcels reach the stratosphere.
            "tropopause_18km" => cfg.physics.domain_top_m = 22_000.0,
            _ => {}
        }
        cases.push(Case {
            name: format!("sounding_{name}"),
            group: "sounding",
            note: format!("{name}, emission + {n}-parcel cluster, dt 2 s"),
            env: environment(name)?,
            config: cfg,
            frame_dt_s: 2.0,
            frames: (secs / 2.0) as u32,
            cluster: Some(cl),
            seed: 41,
            // hot_45c: the 3 km deep dry-adiabatic layer ends in a stable
            // one, below the ~4 km condensation level, so dry thermals stop
            // and crowd at its top. One parcel held there among its
            // neighbours for 42 s (ages 679–720 s, z ≈ 3.05 km) sums hidden
            // caps to up to 1.27 ρgV, which the Archimedes bound caps.
            declared_clamps: if *name == "hot_45c" {
                vec!["atm_force"]
            } else {
                vec![]
            },
        });
    }

    // 50 m/s of wind shear over the lowest 2 km, at 2 s and at 10 s frames.
    for dt in [2.0, 10.0] {
        let mut cfg = emitting(300.0, 512);
        cfg.wind = Some(crate::physics::WindConfig {
            surface_m_s: [0.0, 0.0],
            aloft_m_s: [50.0, 0.0],
            aloft_z_m: 2000.0,
        });
        cfg.ground.size_m = [40_000.0, 40_000.0];
        cases.push(Case {
            name: format!("shear_50ms_dt_{dt}"),
            group: "wind",
            note: format!("wind 0 → 50 m/s over 2 km, emission + {n}-parcel cluster, dt {dt} s"),
            env: fair.clone(),
            config: cfg,
            frame_dt_s: dt,
            frames: (secs / dt) as u32,
            cluster: Some(cluster(n, h)),
            seed: 51,
            declared_clamps: vec![],
        });
    }

    // Emission bursts: the highest rate, hundreds of parcels born at once,
    // overlapping at random, at ordinary and at extreme stiffness.
    let (max_parcels, secs) = if quick { (400, 120.0) } else { (2000, 600.0) };
    for k in [1e2, 1e5] {
        let mut cfg = emitting(1.0e5, max_parcels);
        cfg.physics.stiffness = k;
        cases.push(Case {
            name: format!("burst_k_{k:.0e}"),
            group: "emission",
            note: format!("10⁵ parcels/km²/h up to {max_parcels} alive, K = {k:.0e}, dt 5 s"),
            env: fair.clone(),
            config: cfg,
            frame_dt_s: 5.0,
            frames: (secs / 5.0) as u32,
            cluster: None,
            seed: 61,
            // Parcels born overlapping at random: deep overlaps hit the cap on
            // the hidden-cap force, and at K = 1e5 the SPH push exceeds
            // the speed cap (uncapped up to 251 m/s, all of it the SPH
            // energy the births bring: KE ratio 0.08–0.09).
            declared_clamps: if k >= 1e5 {
                vec!["speed", "atm_force"]
            } else {
                vec!["atm_force"]
            },
        });
    }
    Ok(cases)
}
