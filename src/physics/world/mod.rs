//! The parcel world: paper Algorithm 1 with a kick–drift–kick leapfrog.
//!
//! One frame ([`ParcelWorld::step`]) = emission, then n equal sub-steps
//! (n from the CFL, acceleration and SPH sound-speed limits, capped by a
//! budget), then deaths and condensation planes. One sub-step (the stage
//! numbers of the submodules' docs):
//!
//! 1. kick: v ← v + a dt/2; drift: x ← x + v dt; the mixed scalars (dry
//!    mass, q_v, q_l, θ, θ_l) take the whole step at their last rates G
//!    (the predictor, `integrate`);
//! 2. environment at the new centres, predicted velocity v + a dt/2, volume
//!    and radius from the new pressure and the predicted mass (eq 6, `moisture`);
//! 3. neighbour grid: counting sort into cells ≥ max(h, 2 r_max), SPH
//!    neighbours and touching spheres listed in a fixed order (`neighbours`);
//! 4. SPH density and pressure p = K(ρ − ρ0) (eqs 7–8, `density`);
//! 5. exposed area and the atmospheric pressure on the hidden part (§5.1, `exposed`);
//! 6. rates of entrainment (eqs 11–14), detrainment (eq 15) and of the
//!    exchange of vapour, liquid water and heat through contact disks
//!    (§5.3) at the new state; the corrector s += dt/2 (G_new − G) (`mixing`);
//! 7. volume again (the masses changed), condensation/evaporation with
//!    latent heat (eqs 1, 3) at the new pressure;
//! 8. forces: SPH pressure and viscosity (eqs 9–10), atmospheric pressure,
//!    buoyancy (eq 5), drag against the wind, momentum of entrained air (`forces`);
//! 9. kick: v ← v + a dt/2.
//!
//! Births, deaths and condensation planes are in `fates`, the reported
//! counts in `stats`.
//!
//! Second order where the model is smooth: velocity-dependent forces
//! (drag, viscosity) and the mixing rates use the predicted end-of-step
//! velocity v + a_old dt/2; the mixed scalars advance by the trapezoidal
//! rule with a predictor (Heun), in step with the leapfrog, so s_{n+1} =
//! s_n + dt/2 (G_n + G_{n+1}) and the forces at the end of the sub-step see
//! s_{n+1}; volume, contacts and exposed area are functions of the state,
//! evaluated after what they depend on; the latent heat of condensation
//! takes the sub-step's mean 1/Π (trapezoidal, `moisture`). This is the symmetric (Strang-like) composition of the
//! split processes and the dynamics, with one force and one rate
//! evaluation per sub-step. Observed (`tests/cumulus/physics/order.rs`): order ≈ 2
//! without the two terms that jump by the paper's design (the tessellated
//! hidden-cap pressure, detrainment switching on at the condensation
//! level), ≈ 1.45 with everything on.
//!
//! Parallel and deterministic: every stage is in gather form (rayon), each
//! parcel's new value computed from the state before the stage, pair terms
//! from a canonical (lower index first) evaluation, counts summed as
//! integers; the same seed gives bit-identical states at any thread count.

use std::time::Instant;

use glam::DVec3;

use super::CloudParcel;
use super::config::{WorldConfig, check};
use super::ground::GroundMap;
use super::parcel::{Parcel, ParcelSpec, sphere_volume_m3};
use super::rng::SplitMix64;
use super::tessellation::UnitSphere;
use crate::atmosphere::{Environment, thermo};
use crate::error::{Error, Result};

/// Fewest parcels one parallel task takes: smaller stages run on one
/// thread (splitting a few dozen parcels costs more in wake-ups than it
/// saves). Has no effect on the results, only on the speed.
const PAR_MIN: usize = 64;

/// Smallest dry mass a parcel may have (counted clamp). units: kg
const MIN_DRY_MASS_KG: f64 = 1.0;
/// Largest share of a parcel's mass entrained, or of its dry air detrained,
/// in one sub-step (counted clamps).
const MAX_MIX_FRACTION: f64 = 0.5;

mod density;
mod exposed;
mod fates;
mod forces;
mod integrate;
mod mixing;
mod moisture;
mod neighbours;
mod stats;

pub use crate::atmosphere::lifting::condensation_level_m;
use neighbours::NeighbourGrid;
pub use stats::{ClampCounts, Counters, Diagnostics, Fates, StepReport};

/// Buffers of the gather stages: each stage computes one value per parcel
/// from the state before it (in parallel), then applies them. Kept in the
/// world so that a sub-step allocates nothing once they have grown.
#[derive(Debug, Clone, Default)]
struct Scratch {
    /// SPH density and pressure (read again by the forces). units: kg m⁻³, Pa
    density: Vec<(f64, f64)>,
    /// Total mass of each parcel, dense (for the neighbour loops of the
    /// density and the forces; each stage refills it). units: kg
    mass: Vec<f64>,
    /// The fields the exchange reads of each neighbour, dense.
    mix_state: Vec<mixing::MixState>,
    /// Contacts per parcel (for the exchange bound).
    contacts: Vec<u32>,
    /// Mixing rates (entrainment, detrainment, exchange) and the entrained
    /// mass rate. units: see `MixRate`, kg s⁻¹
    rates: Vec<(mixing::MixRate, f64)>,
    /// Predicted end-of-step velocity. units: m s⁻¹
    vpred: Vec<DVec3>,
    /// Viscous relaxation rate. units: s⁻¹
    visc_rate: Vec<f64>,
}

/// The wind at height `z_m` that drag and entrainment see: the one place
/// the physics reads the wind. units: m → m s⁻¹ (z component 0)
pub(super) fn wind_at(cfg: &WorldConfig, env: &Environment, z_m: f64) -> DVec3 {
    cfg.wind_at(env, z_m)
}

/// The parcels, their environment and everything needed to step them.
#[derive(Debug, Clone)]
pub struct ParcelWorld {
    env: Environment,
    cfg: WorldConfig,
    rng: SplitMix64,
    ground: GroundMap,
    parcels: Vec<Parcel>,
    /// Id of the next spawned parcel ([`Parcel::id`]).
    next_id: u64,
    time_s: f64,
    sphere: UnitSphere,
    grid: NeighbourGrid,
    /// Positions and radii at the last neighbour build (hot copies).
    hot_pos: Vec<DVec3>,
    hot_radius: Vec<f64>,
    /// Per-parcel results of the gather stages, reused every sub-step.
    scratch: Scratch,
    forces_stale: bool,
    deaths: bool,
    /// The next frame's emission was done by `emit_now`, with these counts.
    emitted_ahead: bool,
    fates_ahead: Fates,
    /// Where surface environment air saturates: the scene's condensation level. units: m
    env_condensation_level_m: f64,
    last_substeps: u32,
    /// Whether the speed guard (`max_speed_m_s`) applies; see [`ParcelWorld::set_speed_cap`].
    speed_cap: bool,
    clamps: ClampCounts,
    /// Parcel-frames shown fully opaque (a display count, not a clamp).
    opaque_parcel_frames: u64,
    fates: Fates,
    counters: Counters,
}

impl ParcelWorld {
    /// A world with no parcels; emission draws come from `seed`.
    pub fn new(env: Environment, cfg: WorldConfig, seed: u64) -> Result<Self> {
        cfg.validate()?;
        let mut world = ParcelWorld {
            ground: GroundMap::new(&cfg.ground),
            env,
            cfg,
            rng: SplitMix64::new(seed),
            parcels: Vec::new(),
            next_id: 0,
            time_s: 0.0,
            sphere: UnitSphere::new(),
            grid: NeighbourGrid::default(),
            hot_pos: Vec::new(),
            hot_radius: Vec::new(),
            scratch: Scratch::default(),
            forces_stale: true,
            deaths: true,
            emitted_ahead: false,
            fates_ahead: Fates::default(),
            env_condensation_level_m: 0.0,
            last_substeps: 0,
            speed_cap: true,
            clamps: ClampCounts::default(),
            opaque_parcel_frames: 0,
            fates: Fates::default(),
            counters: Counters::default(),
        };
        world.env_condensation_level_m = world.environment_condensation_level();
        Ok(world)
    }

    /// Height where the environment's surface air saturates when lifted. units: m
    fn environment_condensation_level(&self) -> f64 {
        condensation_level_m(
            &self.env,
            self.env.theta_k(0.0),
            self.env.qv(0.0),
            self.env.top_m().max(self.cfg.physics.domain_top_m),
        )
    }

    /// The scene's condensation level: where the environment's surface air
    /// saturates when lifted; detrainment acts above it. units: m
    pub fn environment_condensation_level_m(&self) -> f64 {
        self.env_condensation_level_m
    }

    /// Replaces the environment (the live panel's edits); takes effect at
    /// the next sub-step: buoyancy, pressure and mixing read the new profile,
    /// and volumes follow the new pressure through eq 6.
    pub fn set_environment(&mut self, env: Environment) {
        self.env = env;
        self.env_condensation_level_m = self.environment_condensation_level();
        self.forces_stale = true;
    }

    /// Turns deaths (evaporated, grounded, aged) on or off; escapes from the
    /// domain always apply. Single releases turn them off to follow a parcel
    /// through its whole oscillation.
    pub fn set_deaths(&mut self, on: bool) {
        self.deaths = on;
    }

    /// Turns the speed guard (`max_speed_m_s`, counted as `speed` clamps)
    /// on or off. Off, nothing hides a blow-up of the integrator: the
    /// stability matrix reruns every case that declares the speed clamp
    /// without it, to show the cap is not what keeps it stable.
    pub fn set_speed_cap(&mut self, on: bool) {
        self.speed_cap = on;
    }

    /// The environment in use.
    pub fn environment(&self) -> &Environment {
        &self.env
    }

    /// The configuration in use.
    pub fn config(&self) -> &WorldConfig {
        &self.cfg
    }

    /// Replaces the configuration (validated); the ground map is rebuilt.
    pub fn set_config(&mut self, cfg: WorldConfig) -> Result<()> {
        cfg.validate()?;
        self.ground = GroundMap::new(&cfg.ground);
        self.cfg = cfg;
        self.env_condensation_level_m = self.environment_condensation_level();
        self.forces_stale = true;
        Ok(())
    }

    /// The ground's heat and humidity maps.
    pub fn ground(&self) -> &GroundMap {
        &self.ground
    }

    /// The live parcels, in creation order.
    pub fn parcels(&self) -> &[Parcel] {
        &self.parcels
    }

    /// Per-stage timers and work counts.
    pub fn counters(&self) -> &Counters {
        &self.counters
    }

    /// Simulated time. units: s
    pub fn time_s(&self) -> f64 {
        self.time_s
    }

    /// Adds a parcel (tests, benches, single releases). Rejects non-finite or
    /// out-of-range input with an error naming the field.
    pub fn spawn_parcel(&mut self, spec: ParcelSpec) -> Result<()> {
        let finite = spec.position_m.is_finite() && spec.velocity_m_s.is_finite();
        if !finite {
            return Err(Error::invalid(
                "parcel position/velocity",
                format!("{:?} / {:?}", spec.position_m, spec.velocity_m_s),
                "finite numbers",
            ));
        }
        let checks = [
            ("parcel theta_k", spec.theta_k, 150.0, 700.0),
            ("parcel qv_kg_per_kg", spec.qv_kg_per_kg, 0.0, 0.1),
            ("parcel ql_kg_per_kg", spec.ql_kg_per_kg, 0.0, 0.1),
            (
                "parcel radius_m",
                spec.radius_m,
                self.cfg.physics.min_radius_m,
                self.cfg.physics.max_radius_m,
            ),
        ];
        for (name, v, lo, hi) in checks {
            check(name, v, lo, hi)?;
        }
        let p_pa = self.env.pressure_pa(spec.position_m.z);
        let dry = spec.dry_mass_kg(p_pa);
        let volume = sphere_volume_m3(spec.radius_m);
        let mut p = Parcel {
            id: self.next_id,
            position_m: spec.position_m,
            velocity_m_s: spec.velocity_m_s,
            accel_m_s2: DVec3::ZERO,
            dry_mass_kg: dry,
            qv_kg_per_kg: spec.qv_kg_per_kg,
            ql_kg_per_kg: spec.ql_kg_per_kg,
            theta_k: spec.theta_k,
            theta_l_k: spec.theta_k
                - self.cfg.physics.latent_heat_alpha * thermo::LATENT_HEAT_VAPORISATION
                    / thermo::CP_DRY
                    * spec.ql_kg_per_kg
                    / thermo::exner(p_pa),
            volume_m3: volume,
            radius_m: spec.radius_m,
            cond_plane_z_m: 0.0,
            fill: 0.0,
            age_s: 0.0,
            alive: true,
            was_cloudy: spec.ql_kg_per_kg > 0.0,
            origin_theta_k: spec.theta_k,
            origin_qv_kg_per_kg: spec.qv_kg_per_kg,
            sph_density_kg_m3: 0.0,
            sph_pressure_pa: 0.0,
            exposed_area_m2: 4.0 * std::f64::consts::PI * spec.radius_m.powi(2),
            atm_force_n: DVec3::ZERO,
            entrain_rate_kg_s: 0.0,
            volume_ref: (p_pa, 0.0),
            mix_rate: [0.0; 5],
            exner_adjusted: thermo::exner(p_pa),
            env_at_centre: (p_pa, 0.0, thermo::exner(p_pa)),
        };
        p.volume_ref.1 = p.total_mass_kg();
        let z_max = self.env.top_m().max(self.cfg.physics.domain_top_m);
        p.cond_plane_z_m = moisture::condensation_plane_m(&self.env, z_max, &p);
        p.fill = moisture::fill_ratio(&p, self.cfg.physics.opaque_lwc_kg_m3).0;
        self.parcels.push(p);
        self.next_id += 1;
        self.forces_stale = true;
        Ok(())
    }

    /// Condensed parcels (fill > 0) for the renderer; `out` is cleared first.
    pub fn cloud_parcels(&self, out: &mut Vec<CloudParcel>) {
        out.clear();
        out.extend(
            self.parcels
                .iter()
                .filter(|p| p.alive && p.fill > 0.0)
                .map(|p| CloudParcel {
                    id: p.id,
                    center_m: p.position_m.as_vec3(),
                    radius_m: p.radius_m as f32,
                    fill: p.fill as f32,
                    cond_plane_z_m: p.cond_plane_z_m as f32,
                }),
        );
    }

    /// Advances the world by one frame of `frame_dt_s` seconds.
    pub fn step(&mut self, frame_dt_s: f64) -> StepReport {
        // The whole frame runs on a pool thread: its parallel stages then
        // split work among the workers directly, instead of each stage
        // handing a job over from this thread and waiting for it.
        rayon::scope(|_| self.step_frame(frame_dt_s))
    }

    fn step_frame(&mut self, frame_dt_s: f64) -> StepReport {
        let mut report = StepReport::default();
        if !(frame_dt_s.is_finite() && frame_dt_s > 0.0) {
            report.clamps.bad_frame_dt += 1;
            self.clamps.add(&report.clamps);
            return report;
        }
        self.emit(frame_dt_s, &mut report.fates);
        let mut clamps = ClampCounts::default();
        if self.forces_stale {
            self.update(0.0, &mut clamps);
            self.forces_stale = false;
        }

        let limit = self.dt_limit(frame_dt_s);
        let wanted = (frame_dt_s / limit).ceil().max(1.0);
        let n = if wanted > self.cfg.physics.max_substeps as f64 {
            report.budget_hit = true;
            clamps.substep_budget += 1;
            self.cfg.physics.max_substeps
        } else {
            wanted as u32
        };
        let dt = frame_dt_s / n as f64;
        for _ in 0..n {
            self.substep(dt, &mut clamps);
        }
        self.time_s += frame_dt_s;

        let t0 = Instant::now();
        report.opaque_parcels = self.finish_frame(&mut report.fates);
        self.opaque_parcel_frames += report.opaque_parcels;
        self.counters.thermo += t0.elapsed();

        report.substeps = n;
        report.dt_s = dt;
        report.clamps = clamps;
        self.last_substeps = n;
        self.counters.frames += 1;
        self.counters.substeps += n as u64;
        self.clamps.add(&clamps);
        self.fates.add(&report.fates);
        report
    }
}
