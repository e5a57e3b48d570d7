//! The parcel world: paper Algorithm 1 with a kick–drift–kick leapfrog.
//!
//! One frame ([`ParcelWorld::step`]) = emission, then n equal sub-steps
//! (n from the CFL, acceleration and SPH sound-speed limits, capped by a
//! budget), then deaths and condensation planes. One sub-step:
//!
//! 1. kick: v ← v + a dt/2; drift: x ← x + v dt;
//! 2. neighbour grid (uniform, cell = support radius, fixed order);
//! 3. SPH density and pressure p = K(ρ − ρ0) (eqs 7–8);
//! 4. exposed area and the atmospheric pressure on the hidden part (§5.1);
//! 5. entrainment (eqs 11–14) and detrainment (eq 15), with the sub-step dt;
//! 6. vapour exchange through contact disks (§5.3);
//! 7. volume from pressure and mass (eq 6);
//! 8. condensation/evaporation with latent heat (eqs 1, 3) at the sub-step;
//! 9. forces: SPH pressure and viscosity (eqs 9–10), atmospheric pressure,
//!    buoyancy (eq 5), drag against the wind, momentum of entrained air;
//! 10. kick: v ← v + a dt/2.
//!
//! Velocity-dependent forces (drag, viscosity) use the predicted end-of-step
//! velocity v + a_old dt/2, which keeps the scheme second order for smooth
//! drag. Everything runs in a fixed order on one thread: the same seed gives
//! bit-identical states.

use std::f64::consts::PI;
use std::time::{Duration, Instant};

use glam::DVec3;

use super::CloudParcel;
use super::config::WorldConfig;
use super::ground::GroundMap;
use super::parcel::{Parcel, ParcelSpec};
use super::rng::SplitMix64;
use super::sph;
use super::tessellation::UnitSphere;
use crate::atmosphere::{Environment, thermo};
use crate::error::{Error, Result};

/// Smallest dry mass a parcel may have (counted clamp). units: kg
const MIN_DRY_MASS_KG: f64 = 1.0;
/// Largest share of a parcel's dry air detrained in one sub-step (counted clamp).
const MAX_DETRAIN_FRACTION: f64 = 0.5;

/// Physical clamps and guards, counted by kind: none of them is silent.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ClampCounts {
    /// Vapour or liquid mixing ratio below zero, set to zero.
    pub negative_humidity: u64,
    /// Radius outside [min_radius_m, max_radius_m].
    pub radius: u64,
    /// Dry mass below 1 kg.
    pub mass: u64,
    /// Saturation vapour pressure capped near es → P (thermo's guard).
    pub saturation_cap: u64,
    /// Detrainment limited to half the dry air in one sub-step.
    pub detrainment: u64,
    /// Vapour exchange limited to half the equalising amount.
    pub exchange: u64,
    /// Speed above max_speed_m_s.
    pub speed: u64,
    /// Frames that needed more sub-steps than max_substeps.
    pub substep_budget: u64,
    /// Parcels removed because a state value became NaN or infinite.
    pub non_finite: u64,
    /// Frames with a non-finite or non-positive frame dt (ignored).
    pub bad_frame_dt: u64,
    /// Atmospheric-pressure force capped at the sphere's weighted Archimedes force.
    pub atm_force: u64,
    /// Parcels whose viscous coupling was too strong for the sub-step
    /// (rate × dt > 1) and was scaled down to keep the step stable.
    pub viscosity: u64,
}

impl ClampCounts {
    fn add(&mut self, o: &ClampCounts) {
        self.negative_humidity += o.negative_humidity;
        self.radius += o.radius;
        self.mass += o.mass;
        self.saturation_cap += o.saturation_cap;
        self.detrainment += o.detrainment;
        self.exchange += o.exchange;
        self.speed += o.speed;
        self.substep_budget += o.substep_budget;
        self.non_finite += o.non_finite;
        self.bad_frame_dt += o.bad_frame_dt;
        self.atm_force += o.atm_force;
        self.viscosity += o.viscosity;
    }

    /// Sum of all counters.
    pub fn total(&self) -> u64 {
        self.negative_humidity
            + self.radius
            + self.mass
            + self.saturation_cap
            + self.detrainment
            + self.exchange
            + self.speed
            + self.substep_budget
            + self.non_finite
            + self.bad_frame_dt
            + self.atm_force
            + self.viscosity
    }
}

/// Births, deaths and escapes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Fates {
    /// Parcels emitted by the ground.
    pub emitted: u64,
    /// Emissions skipped because max_parcels were alive.
    pub suppressed: u64,
    /// Left through the sides of the domain.
    pub escaped_sides: u64,
    /// Left through the top of the domain or of the environment profile.
    pub escaped_top: u64,
    /// Died after losing their cloud: once cloudy, now without liquid water,
    /// sinking, and more than `death_depth_m` below their condensation plane.
    pub evaporated: u64,
    /// Sank with their centre below the ground.
    pub grounded: u64,
    /// Older than max_age_s.
    pub aged: u64,
}

impl Fates {
    fn add(&mut self, o: &Fates) {
        self.emitted += o.emitted;
        self.suppressed += o.suppressed;
        self.escaped_sides += o.escaped_sides;
        self.escaped_top += o.escaped_top;
        self.evaporated += o.evaporated;
        self.grounded += o.grounded;
        self.aged += o.aged;
    }
}

/// What one frame did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepReport {
    /// Sub-steps taken.
    pub substeps: u32,
    /// Sub-step length. units: s
    pub dt_s: f64,
    /// Whether the sub-step budget capped this frame (dt then exceeds the limits).
    pub budget_hit: bool,
    /// Clamps in this frame.
    pub clamps: ClampCounts,
    /// Births and deaths in this frame.
    pub fates: Fates,
}

/// Per-stage CPU time and work counts (cumulative).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Counters {
    pub neighbours: Duration,
    pub sph: Duration,
    pub exposed_area: Duration,
    pub mixing: Duration,
    pub thermo: Duration,
    pub integrate: Duration,
    /// Parcels whose sphere was tessellated (one per parcel with an
    /// overlapping neighbour per sub-step).
    pub exposed_area_evaluations: u64,
    /// Quad-in-neighbour tests done.
    pub quads_tested: u64,
    /// Frames stepped.
    pub frames: u64,
    /// Sub-steps taken.
    pub substeps: u64,
}

/// A snapshot summary of the world.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Diagnostics {
    /// Simulated time. units: s
    pub time_s: f64,
    pub parcels: usize,
    pub condensed_parcels: usize,
    /// Lowest condensation plane of the condensed parcels. units: m
    pub cloud_base_m: Option<f64>,
    /// Highest sphere top of the condensed parcels. units: m
    pub cloud_top_m: Option<f64>,
    /// Vapour and liquid water in all parcels. units: kg
    pub total_water_kg: f64,
    /// Σ ½ m v². units: J
    pub kinetic_energy_j: f64,
    /// Sub-steps of the last frame.
    pub substeps: u32,
    /// Cumulative clamps.
    pub clamps: ClampCounts,
    /// Cumulative births and deaths.
    pub fates: Fates,
    /// Parcels that left the domain (sides + top), cumulative.
    pub escaped: u64,
}

/// One neighbour of a parcel within the support radius.
#[derive(Debug, Clone, Copy)]
struct Neighbour {
    j: usize,
    /// x_i − x_j. units: m
    r: DVec3,
    /// |x_i − x_j|. units: m
    dist: f64,
}

/// The parcels, their environment and everything needed to step them.
#[derive(Debug, Clone)]
pub struct ParcelWorld {
    env: Environment,
    cfg: WorldConfig,
    rng: SplitMix64,
    ground: GroundMap,
    parcels: Vec<Parcel>,
    time_s: f64,
    sphere: UnitSphere,
    nbr_start: Vec<usize>,
    nbrs: Vec<Neighbour>,
    any_neighbours: bool,
    forces_stale: bool,
    deaths: bool,
    /// Where surface environment air saturates: the scene's condensation level. units: m
    env_condensation_level_m: f64,
    last_substeps: u32,
    clamps: ClampCounts,
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
            time_s: 0.0,
            sphere: UnitSphere::new(),
            nbr_start: Vec::new(),
            nbrs: Vec::new(),
            any_neighbours: false,
            forces_stale: true,
            deaths: true,
            env_condensation_level_m: 0.0,
            last_substeps: 0,
            clamps: ClampCounts::default(),
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
            if !(v.is_finite() && v >= lo && v <= hi) {
                return Err(Error::invalid(
                    name,
                    v,
                    format!("a finite number between {lo} and {hi}"),
                ));
            }
        }
        let p_pa = self.env.pressure_pa(spec.position_m.z);
        let dry = spec.dry_mass_kg(p_pa);
        let volume = 4.0 / 3.0 * PI * spec.radius_m.powi(3);
        let mut p = Parcel {
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
            exposed_area_m2: 4.0 * PI * spec.radius_m.powi(2),
            atm_force_n: DVec3::ZERO,
            entrain_rate_kg_s: 0.0,
            volume_ref: (p_pa, 0.0),
            env_at_centre: (p_pa, 0.0),
        };
        p.volume_ref.1 = p.total_mass_kg();
        p.cond_plane_z_m = self.condensation_plane_m(&p);
        p.fill = self.fill(&p);
        self.parcels.push(p);
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
                    center_m: p.position_m.as_vec3(),
                    radius_m: p.radius_m as f32,
                    fill: p.fill as f32,
                    cond_plane_z_m: p.cond_plane_z_m as f32,
                }),
        );
    }

    /// Summary of the current state.
    pub fn diagnostics(&self) -> Diagnostics {
        let mut d = Diagnostics {
            time_s: self.time_s,
            parcels: self.parcels.len(),
            substeps: self.last_substeps,
            clamps: self.clamps,
            fates: self.fates,
            escaped: self.fates.escaped_sides + self.fates.escaped_top,
            ..Diagnostics::default()
        };
        for p in &self.parcels {
            d.total_water_kg += p.water_kg();
            d.kinetic_energy_j += 0.5 * p.total_mass_kg() * p.velocity_m_s.length_squared();
            if p.is_condensed() {
                d.condensed_parcels += 1;
                let base = p.cond_plane_z_m;
                let top = p.position_m.z + p.radius_m;
                d.cloud_base_m = Some(d.cloud_base_m.map_or(base, |b: f64| b.min(base)));
                d.cloud_top_m = Some(d.cloud_top_m.map_or(top, |t: f64| t.max(top)));
            }
        }
        d
    }

    /// Advances the world by one frame of `frame_dt_s` seconds.
    pub fn step(&mut self, frame_dt_s: f64) -> StepReport {
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

        let limit = self.dt_limit();
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
        self.finish_frame(&mut report.fates);
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

    /// Largest stable sub-step: CFL λh/v_max, 0.25·√(h/a_max), the SPH
    /// sound-speed limit λh/√K (only while some parcels interact), max_dt_s.
    fn dt_limit(&self) -> f64 {
        let c = &self.cfg.physics;
        let h = c.support_radius_m;
        let (mut vmax, mut amax) = (0.0_f64, 0.0_f64);
        for p in &self.parcels {
            vmax = vmax.max(p.velocity_m_s.length());
            amax = amax.max(p.accel_m_s2.length());
        }
        let mut dt = c.max_dt_s;
        if vmax > 0.0 {
            dt = dt.min(c.cfl * h / vmax);
        }
        if amax > 0.0 {
            dt = dt.min(0.25 * (h / amax).sqrt());
        }
        if c.sph && self.any_neighbours && c.stiffness > 0.0 {
            dt = dt.min(c.cfl * h / c.stiffness.sqrt());
        }
        dt
    }

    fn emit(&mut self, dt_s: f64, fates: &mut Fates) {
        let e = &self.cfg.emission;
        if !e.enabled {
            return;
        }
        let draws = self.ground.draw(e, self.time_s, dt_s, &mut self.rng);
        for (x, y) in draws {
            if self.parcels.len() >= self.cfg.emission.max_parcels as usize {
                fates.suppressed += 1;
                continue;
            }
            let (dth, dq) = self.ground.excess(x, y);
            let spec = ParcelSpec::from_environment(
                &self.env,
                DVec3::new(x, y, self.ground.height_m(x, y)),
                dth,
                dq,
                self.cfg.emission.radius_m,
            );
            // The ranges are validated config values, so this cannot fail
            // short of a profile at its limits; count it as suppressed then.
            if self.spawn_parcel(spec).is_ok() {
                fates.emitted += 1;
            } else {
                fates.suppressed += 1;
            }
        }
    }

    fn substep(&mut self, dt: f64, clamps: &mut ClampCounts) {
        let t0 = Instant::now();
        for p in &mut self.parcels {
            p.velocity_m_s += p.accel_m_s2 * (0.5 * dt);
            p.position_m += p.velocity_m_s * dt;
        }
        self.counters.integrate += t0.elapsed();

        self.update(dt, clamps);

        let t0 = Instant::now();
        let vmax = self.cfg.physics.max_speed_m_s;
        for p in &mut self.parcels {
            p.velocity_m_s += p.accel_m_s2 * (0.5 * dt);
            let s = p.velocity_m_s.length();
            if s > vmax {
                p.velocity_m_s *= vmax / s;
                clamps.speed += 1;
            }
            p.age_s += dt;
        }
        // Guard: a parcel with any non-finite state is removed and counted,
        // never left to poison its neighbours.
        let before = self.parcels.len();
        self.parcels.retain(|p| {
            p.position_m.is_finite()
                && p.velocity_m_s.is_finite()
                && p.accel_m_s2.is_finite()
                && p.theta_k.is_finite()
                && p.theta_l_k.is_finite()
                && p.qv_kg_per_kg.is_finite()
                && p.ql_kg_per_kg.is_finite()
                && p.dry_mass_kg.is_finite()
                && p.volume_m3.is_finite()
        });
        clamps.non_finite += (before - self.parcels.len()) as u64;
        self.counters.integrate += t0.elapsed();
    }

    /// Everything between the drift and the second kick; with `dt = 0` it
    /// only refreshes forces (new parcels, new environment).
    fn update(&mut self, dt: f64, clamps: &mut ClampCounts) {
        let t0 = Instant::now();
        for p in &mut self.parcels {
            let z = p.position_m.z;
            let pr = self.env.pressure_pa(z);
            let t = thermo::temperature_from_theta_k(self.env.theta_k(z), pr);
            // Same expression as Environment::density_kg_m3, one pressure lookup fewer.
            p.env_at_centre = (pr, thermo::air_density_kg_m3(pr, t, self.env.qv(z)));
        }
        self.build_neighbours();
        let t1 = Instant::now();
        self.counters.neighbours += t1 - t0;

        if self.cfg.physics.sph || self.cfg.physics.viscosity {
            self.sph_density();
        }
        let t2 = Instant::now();
        self.counters.sph += t2 - t1;

        if self.cfg.physics.needs_exposed_area() {
            self.exposed_area(clamps);
        }
        let t3 = Instant::now();
        self.counters.exposed_area += t3 - t2;

        if dt > 0.0 {
            if self.cfg.physics.mixing {
                self.mix_with_environment(dt, clamps);
            }
            if self.cfg.physics.exchange {
                self.exchange_vapour(dt, clamps);
            }
        }
        let t4 = Instant::now();
        self.counters.mixing += t4 - t3;

        self.update_volume(clamps);
        if self.cfg.physics.condensation {
            self.condense(clamps);
        }
        let t5 = Instant::now();
        self.counters.thermo += t5 - t4;

        self.forces(dt, clamps);
        self.counters.integrate += t5.elapsed();
    }

    /// Uniform grid with cell = support radius: parcels sorted by (cell,
    /// index), each parcel scans the 27 surrounding cells in a fixed order.
    fn build_neighbours(&mut self) {
        let h = self.cfg.physics.support_radius_m;
        let cell = |x: DVec3| -> [i64; 3] {
            // Positions are finite (guarded); the cast saturates for far-away parcels.
            [
                (x.x / h).floor() as i64,
                (x.y / h).floor() as i64,
                (x.z / h).floor() as i64,
            ]
        };
        let mut keys: Vec<([i64; 3], usize)> = self
            .parcels
            .iter()
            .enumerate()
            .map(|(i, p)| (cell(p.position_m), i))
            .collect();
        keys.sort_unstable();
        self.nbr_start.clear();
        self.nbrs.clear();
        self.any_neighbours = false;
        let need = self.cfg.physics.sph
            || self.cfg.physics.viscosity
            || self.cfg.physics.needs_exposed_area()
            || self.cfg.physics.exchange;
        let h2 = h * h;
        for i in 0..self.parcels.len() {
            self.nbr_start.push(self.nbrs.len());
            if !need {
                continue;
            }
            let xi = self.parcels[i].position_m;
            let c = cell(xi);
            // Keys sort by (x, y, z) cell then index, so the three cells
            // z − 1, z, z + 1 of one (x, y) column are contiguous: one binary
            // search per column, and the same order as cell-by-cell scans.
            for dx in -1..=1 {
                for dy in -1..=1 {
                    let (kx, ky) = (c[0].saturating_add(dx), c[1].saturating_add(dy));
                    let first = [kx, ky, c[2].saturating_sub(1)];
                    let last = [kx, ky, c[2].saturating_add(1)];
                    let lo = keys.partition_point(|(k, _)| *k < first);
                    for &(k, j) in &keys[lo..] {
                        if k > last {
                            break;
                        }
                        if j == i {
                            continue;
                        }
                        let r = xi - self.parcels[j].position_m;
                        let d2 = r.length_squared();
                        if d2 < h2 {
                            self.nbrs.push(Neighbour {
                                j,
                                r,
                                dist: d2.sqrt(),
                            });
                        }
                    }
                }
            }
        }
        self.nbr_start.push(self.nbrs.len());
        self.any_neighbours = !self.nbrs.is_empty();
    }

    fn neighbours(&self, i: usize) -> &[Neighbour] {
        &self.nbrs[self.nbr_start[i]..self.nbr_start[i + 1]]
    }

    /// ρ_i = Σ_j m_j W(x_i − x_j) (self included) and p_i = K(ρ_i − ρ0_i).
    /// The rest density ρ0_i is the parcel's own isolated density m_i W(0):
    /// parcels of different masses cannot share the paper's single ρ0 = 1.28
    /// without isolated parcels feeling a pressure, so pressure here measures
    /// overlap only, is never negative (no tensile clumping) and pushes
    /// parcels apart "to prevent them getting too close" (paper §5).
    fn sph_density(&mut self) {
        let h = self.cfg.physics.support_radius_m;
        let k = self.cfg.physics.stiffness;
        let w0 = sph::poly6(0.0, h);
        for i in 0..self.parcels.len() {
            let mi = self.parcels[i].total_mass_kg();
            let mut rho = mi * w0;
            for n in self.neighbours(i) {
                rho += self.parcels[n.j].total_mass_kg() * sph::poly6(n.dist * n.dist, h);
            }
            let p = &mut self.parcels[i];
            p.sph_density_kg_m3 = rho;
            p.sph_pressure_pa = k * (rho - mi * w0);
        }
    }

    /// Exposed area of each sphere and the atmospheric pressure force on it
    /// (paper §5.1), from the 18 × 9 tessellation; only SPH neighbours are tested.
    ///
    /// Archimedes' force is the pressure integrated over the whole sphere and
    /// is already in the θ_v buoyancy (eq 5). What the exposed-area term adds
    /// is the difference: the part of the sphere inside a neighbour feels no
    /// environment pressure; the neighbour presses instead on the contact
    /// disk with the pressure at the disk's centre P_ref. So each hidden quad
    /// contributes (P(z_q) − P_ref) n dA, summed over each neighbour's cap.
    /// By the divergence theorem a cap's sum is minus its own buoyancy,
    /// −ρ g V_cap ẑ: overlapping spheres are not buoyed twice for the shared
    /// volume. An isolated sphere gets exactly zero (no quad is evaluated).
    ///
    /// The weight is the paper's calibration. At 1 the whole Archimedes
    /// force of the overlap is removed, but the parcels' masses are not
    /// shared, so overlapping parcels would become heavier than their
    /// surroundings by g V_cap/V, far above thermal buoyancy (g Δθ/θ ≈
    /// 0.01 g): a small weight (default 0.01) keeps the term a gentle
    /// downward and inward pull on overlapping parcels.
    fn exposed_area(&mut self, clamps: &mut ClampCounts) {
        let weight = if self.cfg.physics.atmospheric_pressure {
            self.cfg.physics.atm_pressure_weight
        } else {
            0.0
        };
        // Per overlapping neighbour: axis u towards it, cos of the cap's
        // half-angle, pressure at the contact disk's centre. The part of
        // sphere i inside sphere j is exactly the cap {n : n·u > x/r_i}, x the
        // distance of the intersection plane from c_i, so the quad test is a
        // dot product.
        let mut overl: Vec<(DVec3, f64, f64)> = Vec::new();
        let mut tested = 0u64;
        for i in 0..self.parcels.len() {
            let (ci, ri) = (self.parcels[i].position_m, self.parcels[i].radius_m);
            // P across the sphere by the quadratic through P(z_c − r), P(z_c),
            // P(z_c + r): three lookups instead of one per hidden quad; the
            // cubic remainder is (r/H)³ ≈ 1e-5 of the anomaly for r = 150 m.
            let (pm, p0, pp) = (
                self.env.pressure_pa(ci.z - ri),
                self.env.pressure_pa(ci.z),
                self.env.pressure_pa(ci.z + ri),
            );
            let (d1, d2) = ((pp - pm) / (2.0 * ri), (pp - 2.0 * p0 + pm) / (ri * ri));
            let pressure_anomaly = |dz: f64| d1 * dz + 0.5 * d2 * dz * dz;
            overl.clear();
            for n in self.neighbours(i) {
                let rj = self.parcels[n.j].radius_m;
                if n.dist < ri + rj && n.dist > 0.0 {
                    let axis = -n.r / n.dist;
                    let x = (n.dist * n.dist + ri * ri - rj * rj) / (2.0 * n.dist);
                    // x ≥ r_i: sphere j lies inside sphere i and hides nothing of its surface.
                    if x < ri {
                        let x = x.max(-ri);
                        let p_ref = pressure_anomaly(x * axis.z);
                        overl.push((axis, x / ri, p_ref));
                    }
                }
            }
            if overl.is_empty() {
                let p = &mut self.parcels[i];
                p.exposed_area_m2 = 4.0 * PI * ri * ri;
                p.atm_force_n = DVec3::ZERO;
                continue;
            }
            self.counters.exposed_area_evaluations += 1;
            let mut exposed = 0.0;
            let mut force = DVec3::ZERO;
            let r2 = ri * ri;
            for (nq, area) in self.sphere.normal.iter().zip(&self.sphere.area) {
                let da = area * r2;
                let mut hidden = false;
                let p_q = pressure_anomaly(nq.z * ri);
                // Every neighbour's cap is closed on its own contact disk, so a
                // quad inside two neighbours counts in both caps.
                for (u, cos, p_ref) in &overl {
                    tested += 1;
                    if nq.dot(*u) > *cos {
                        hidden = true;
                        if weight == 0.0 {
                            break;
                        }
                        force += *nq * ((p_q - *p_ref) * da);
                    }
                }
                if !hidden {
                    exposed += da;
                }
            }
            // Bound: the caps cannot lose more than the sphere's whole
            // Archimedes force ρ g V.
            let force = force * weight;
            let bound = weight
                * self.parcels[i].env_at_centre.1
                * thermo::GRAVITY
                * self.parcels[i].volume_m3;
            let force = if force.length() > bound {
                clamps.atm_force += 1;
                force * (bound / force.length())
            } else {
                force
            };
            let p = &mut self.parcels[i];
            p.exposed_area_m2 = exposed;
            p.atm_force_n = force;
        }
        self.counters.quads_tested += tested;
    }

    /// Entrainment (eqs 11–14) and detrainment (eq 15) over one sub-step.
    fn mix_with_environment(&mut self, dt: f64, clamps: &mut ClampCounts) {
        let c = &self.cfg.physics;
        for p in &mut self.parcels {
            let z = p.position_m.z;
            let rel = p.velocity_m_s - self.cfg.wind.at(z);
            // |v + δv_t| with δv_t of random direction: the magnitudes add in quadrature.
            let speed = (rel.length_squared() + c.turbulence_m_s * c.turbulence_m_s).sqrt();
            let r = p.radius_m;
            let area = p.exposed_area_m2;
            let m = p.total_mass_kg();
            // eq 11: ε' = ε r; swept environment air through the exposed area.
            let dma_e = c.entrainment_surface_factor
                * (c.entrainment_rate_per_m * r)
                * area
                * p.env_at_centre.1
                * speed
                * dt;
            // eq 11's ρ_atm is moist air; its dry part is what the mixing ratios count.
            let env_qv = self.env.qv(z);
            let dry_in = dma_e / (1.0 + env_qv);
            // eq 12 prints ω_s; we read it as a typo for the environment's own
            // mixing ratio: entrained air carries the vapour it has, and
            // entraining saturated vapour would moisten a parcel from dry air.
            let vap_in = env_qv * dry_in;
            let dme = dry_in + vap_in; // eq 13
            // eq 14: mass-weighted θ of the mixture.
            let env_theta = self.env.theta_k(z);
            p.theta_k = (m * p.theta_k + dme * env_theta) / (m + dme);
            // Environment air holds no liquid, so θ_l mixes exactly like θ.
            p.theta_l_k = (m * p.theta_l_k + dme * env_theta) / (m + dme);
            let mut vap = p.dry_mass_kg * p.qv_kg_per_kg + vap_in;
            let mut liq = p.dry_mass_kg * p.ql_kg_per_kg;
            let mut dry = p.dry_mass_kg + dry_in;
            p.entrain_rate_kg_s = dme / dt;

            // eq 15: detrainment from the condensation level up (paper §7.1:
            // "detrainment begins at condensation level while entrainment
            // occurs throughout"), at the parcel's own density, removing air
            // and water in proportion. The level is the lower of the parcel's
            // own plane and the scene's (surface environment air), so a
            // parcel that has dried out above the cloud base keeps leaking.
            if z >= p.cond_plane_z_m.min(self.env_condensation_level_m)
                && c.detrainment_rate_per_m > 0.0
            {
                let rho_p = m / p.volume_m3;
                let dm_d = c.detrainment_surface_factor
                    * (c.detrainment_rate_per_m * r)
                    * area
                    * rho_p
                    * speed
                    * dt;
                let mut frac = dm_d / (m + dme);
                if frac > MAX_DETRAIN_FRACTION {
                    frac = MAX_DETRAIN_FRACTION;
                    clamps.detrainment += 1;
                }
                dry *= 1.0 - frac;
                vap *= 1.0 - frac;
                liq *= 1.0 - frac;
            }
            if dry < MIN_DRY_MASS_KG {
                dry = MIN_DRY_MASS_KG;
                clamps.mass += 1;
            }
            p.dry_mass_kg = dry;
            p.qv_kg_per_kg = vap / dry;
            p.ql_kg_per_kg = liq / dry;
        }
    }

    /// Vapour diffusion between overlapping parcels (§5.3): through the
    /// contact disk, mass flux k_ex · A · ρ̄ · (q_i − q_j). Fluxes are computed
    /// from the state before the exchange and applied after, so the result
    /// does not depend on the pair order; water is conserved pair by pair.
    fn exchange_vapour(&mut self, dt: f64, clamps: &mut ClampCounts) {
        let k = self.cfg.physics.exchange_velocity_m_s;
        let mut dvap = vec![0.0; self.parcels.len()];
        for i in 0..self.parcels.len() {
            for n in self.neighbours(i) {
                let j = n.j;
                if j <= i {
                    continue;
                }
                let (a, b) = (&self.parcels[i], &self.parcels[j]);
                let (ri, rj, d) = (a.radius_m, b.radius_m, n.dist);
                if d >= ri + rj {
                    continue;
                }
                let x = (d * d + ri * ri - rj * rj) / (2.0 * d.max(1e-9));
                let a2 = ri * ri - x * x;
                let area = if a2 > 0.0 {
                    PI * a2
                } else {
                    PI * ri.min(rj).powi(2)
                };
                let rho = 0.5 * (a.total_mass_kg() / a.volume_m3 + b.total_mass_kg() / b.volume_m3);
                let dq = a.qv_kg_per_kg - b.qv_kg_per_kg;
                let mut flux = k * area * rho * dq * dt;
                let (mi, mj) = (a.dry_mass_kg, b.dry_mass_kg);
                let equalise = dq * mi * mj / (mi + mj);
                if flux.abs() > 0.5 * equalise.abs() {
                    flux = 0.5 * equalise;
                    clamps.exchange += 1;
                }
                dvap[i] -= flux;
                dvap[j] += flux;
            }
        }
        for (p, dv) in self.parcels.iter_mut().zip(dvap) {
            if dv != 0.0 {
                p.qv_kg_per_kg += dv / p.dry_mass_kg;
            }
        }
    }

    /// eq 6: V₂ = V₁ (P₁/P₂)^{1/γ} (m₂/m₁), then r from V, and humidity guards.
    fn update_volume(&mut self, clamps: &mut ClampCounts) {
        let c = &self.cfg.physics;
        for p in &mut self.parcels {
            if p.qv_kg_per_kg < 0.0 {
                p.qv_kg_per_kg = 0.0;
                clamps.negative_humidity += 1;
            }
            if p.ql_kg_per_kg < 0.0 {
                p.ql_kg_per_kg = 0.0;
                clamps.negative_humidity += 1;
            }
            let p2 = p.env_at_centre.0;
            let m2 = p.total_mass_kg();
            let (p1, m1) = p.volume_ref;
            if p1 != p2 || m1 != m2 {
                p.volume_m3 *= (p1 / p2).powf(1.0 / c.gamma) * (m2 / m1);
                p.volume_ref = (p2, m2);
            }
            let r = (3.0 * p.volume_m3 / (4.0 * PI)).cbrt();
            let rc = r.clamp(c.min_radius_m, c.max_radius_m);
            if rc != r || !r.is_finite() {
                let rc = if r.is_finite() { rc } else { c.min_radius_m };
                clamps.radius += 1;
                p.volume_m3 = 4.0 / 3.0 * PI * rc.powi(3);
                p.radius_m = rc;
            } else {
                p.radius_m = r;
            }
        }
    }

    /// Condensation/evaporation at the parcel's pressure with latent heat
    /// (α = latent_heat_alpha), by thermo's saturation adjustment.
    fn condense(&mut self, clamps: &mut ClampCounts) {
        let alpha = self.cfg.physics.latent_heat_alpha;
        for p in &mut self.parcels {
            let pr = p.env_at_centre.0;
            let ex = thermo::exner(pr);
            let t = p.theta_k * ex;
            let a = thermo::saturation_adjust(t, p.qv_kg_per_kg, p.ql_kg_per_kg, pr, alpha);
            if a.clamped {
                clamps.saturation_cap += 1;
            }
            if a.condensed != 0.0 || a.ql != p.ql_kg_per_kg {
                p.theta_k = a.t_k / ex;
                p.qv_kg_per_kg = a.qv;
                p.ql_kg_per_kg = a.ql;
            }
        }
    }

    /// Accelerations at the new positions (eq 17 per unit mass).
    fn forces(&mut self, dt: f64, clamps: &mut ClampCounts) {
        let c = &self.cfg.physics;
        let h = c.support_radius_m;
        let n = self.parcels.len();
        let vpred: Vec<DVec3> = self
            .parcels
            .iter()
            .map(|p| p.velocity_m_s + p.accel_m_s2 * (0.5 * dt))
            .collect();
        // Guard: explicit viscosity relaxes v_i towards its neighbours at the
        // rate s_i = Σ_j μ m_j/(ρ_i ρ_j) ∇²W, and a pair's relative velocity
        // at up to s_i + s_j; past 1/dt a step overshoots and the velocities
        // blow up (viscosity_mu = 1e6 on a 100-parcel cluster reached the
        // speed cap 2452 times). Each pair's coefficient is scaled by
        // min(1, 1/(2 dt max(s_i, s_j))), symmetric so momentum is kept, and
        // the parcels that needed it are counted. A force refresh (dt = 0)
        // is scaled for max_dt_s.
        let visc_dt = if dt > 0.0 { dt } else { c.max_dt_s };
        let mut visc_rate = vec![0.0; n];
        if c.viscosity && c.viscosity_mu > 0.0 {
            for (i, rate) in visc_rate.iter_mut().enumerate() {
                let rhoi = self.parcels[i].sph_density_kg_m3;
                for nb in self.neighbours(i) {
                    let q = &self.parcels[nb.j];
                    *rate += c.viscosity_mu * q.total_mass_kg() / (rhoi * q.sph_density_kg_m3)
                        * sph::viscosity_laplacian(nb.dist, h);
                }
                if dt > 0.0 && 2.0 * *rate * visc_dt > 1.0 {
                    clamps.viscosity += 1;
                }
            }
        }
        let mut acc = vec![DVec3::ZERO; n];
        for i in 0..n {
            let p = &self.parcels[i];
            let mi = p.total_mass_kg();
            let mut a = DVec3::ZERO;
            if c.sph || c.viscosity {
                let (pi, rhoi) = (p.sph_pressure_pa, p.sph_density_kg_m3);
                let mut fp = DVec3::ZERO;
                let mut fv = DVec3::ZERO;
                for nb in self.neighbours(i) {
                    let q = &self.parcels[nb.j];
                    let mj = q.total_mass_kg();
                    if c.sph {
                        // eq 9 (mass-weighted, antisymmetric: momentum is conserved).
                        let s = pi / (rhoi * rhoi)
                            + q.sph_pressure_pa / (q.sph_density_kg_m3 * q.sph_density_kg_m3);
                        fp -= sph::spiky_gradient(nb.r, h) * (mi * mj * s);
                    }
                    if c.viscosity {
                        // eq 10 is a force density; divided by ρ_i below.
                        let rate = 2.0 * visc_rate[i].max(visc_rate[nb.j]) * visc_dt;
                        let scale = if rate > 1.0 { 1.0 / rate } else { 1.0 };
                        fv += (vpred[nb.j] - vpred[i])
                            * (scale * c.viscosity_mu * mj / q.sph_density_kg_m3
                                * sph::viscosity_laplacian(nb.dist, h));
                    }
                }
                a += fp / mi;
                if c.viscosity {
                    a += fv / rhoi;
                }
            }
            if c.atmospheric_pressure {
                a += p.atm_force_n / mi;
            }
            let z = p.position_m.z;
            if c.buoyancy {
                // eq 5 with θ_v of eq 4 (optionally with condensate loading).
                let ql = if c.condensate_loading {
                    p.ql_kg_per_kg
                } else {
                    0.0
                };
                let tv = thermo::virtual_potential_temperature_k(p.theta_k, p.qv_kg_per_kg, ql);
                let tv_env = self.env.theta_v_k(z);
                a.z += thermo::GRAVITY * (tv - tv_env) / tv_env;
            }
            let rel = vpred[i] - self.cfg.wind.at(z);
            if c.drag {
                let area = PI * p.radius_m * p.radius_m;
                a -=
                    rel * (0.5 * c.drag_coefficient * p.env_at_centre.1 * rel.length() * area / mi);
            }
            if c.mixing {
                // Entrained air arrives with the wind's velocity.
                a -= rel * (p.entrain_rate_kg_s / mi);
            }
            acc[i] = a;
        }
        for (p, a) in self.parcels.iter_mut().zip(acc) {
            p.accel_m_s2 = a;
        }
    }

    /// Filling ratio f = liquid water content / opaque content (paper §6.1:
    /// f = (ω − ω_s)/(V_1kg q_l0)), clamped to [0, 1]. It grows with q_l and
    /// decays as the liquid evaporates.
    fn fill(&self, p: &Parcel) -> f64 {
        let lwc = p.ql_kg_per_kg * p.dry_mass_kg / p.volume_m3;
        (lwc / self.cfg.physics.opaque_lwc_kg_m3).clamp(0.0, 1.0)
    }

    /// Height where this parcel's own air saturates when lifted
    /// dry-adiabatically: the level where ω_s(θ_l Π, P) equals its total
    /// water. θ_l and q_t are conserved by motion and condensation, so the
    /// plane is the base of its cloud and a cluster of the same air gets one
    /// flat base; mixing and vapour exchange move it.
    fn condensation_plane_m(&self, p: &Parcel) -> f64 {
        let qt = p.qv_kg_per_kg + p.ql_kg_per_kg;
        let z_max = self.env.top_m().max(self.cfg.physics.domain_top_m);
        // Warm start: the plane moves little between frames, so a secant
        // iteration from the last plane usually converges in 2–4 steps to
        // 1e-4 m; otherwise bisect in a 64 m bracket around the last plane
        // (19 halvings to the same resolution), else over the whole column.
        let excess = |z: f64| saturation_excess(&self.env, p.theta_l_k, qt, z);
        let (mut z0, mut z1) = (p.cond_plane_z_m, p.cond_plane_z_m + 1.0);
        if z0 > 1.0 && z1 < z_max - 1.0 {
            let (mut f0, mut f1) = (excess(z0), excess(z1));
            for _ in 0..6 {
                let slope = (f1 - f0) / (z1 - z0);
                // ω_s falls with height: a non-negative slope means trouble.
                if !(slope < 0.0) {
                    break;
                }
                let z2 = z1 - f1 / slope;
                if !(z2 > 0.0 && z2 < z_max) {
                    break;
                }
                if (z2 - z1).abs() < 1e-4 {
                    return z2;
                }
                (z0, f0) = (z1, f1);
                (z1, f1) = (z2, excess(z2));
            }
        }
        let (lo, hi) = (p.cond_plane_z_m - 32.0, p.cond_plane_z_m + 32.0);
        if lo > 0.0 && hi < z_max && excess(lo) > 0.0 && !(excess(hi) > 0.0) {
            return bisect_plane(&self.env, p.theta_l_k, qt, lo, hi, 19);
        }
        condensation_level_m(&self.env, p.theta_l_k, qt, z_max)
    }

    /// End of frame: condensation planes, fill, deaths and escapes.
    fn finish_frame(&mut self, fates: &mut Fates) {
        let half = [
            0.5 * self.cfg.ground.size_m[0],
            0.5 * self.cfg.ground.size_m[1],
        ];
        let top = self.cfg.physics.domain_top_m.min(self.env.top_m());
        let max_age = self.cfg.physics.max_age_s;
        let death_depth = self.cfg.physics.death_depth_m;
        for i in 0..self.parcels.len() {
            let plane = self.condensation_plane_m(&self.parcels[i]);
            let fill = self.fill(&self.parcels[i]);
            let pos = self.parcels[i].position_m;
            let floor_m = self.ground.height_m(pos.x, pos.y);
            let p = &mut self.parcels[i];
            p.cond_plane_z_m = plane;
            p.fill = fill;
            p.was_cloudy |= p.ql_kg_per_kg > 0.0;
            let x = p.position_m;
            let sinking = p.velocity_m_s.z < 0.0;
            if x.x.abs() > half[0] || x.y.abs() > half[1] {
                fates.escaped_sides += 1;
                p.alive = false;
            } else if x.z > top {
                fates.escaped_top += 1;
                p.alive = false;
            } else if !self.deaths {
            } else if x.z < floor_m && sinking {
                fates.grounded += 1;
                p.alive = false;
            } else if p.was_cloudy && p.ql_kg_per_kg <= 0.0 && sinking && x.z < plane - death_depth
            {
                fates.evaporated += 1;
                p.alive = false;
            } else if p.age_s > max_age {
                fates.aged += 1;
                p.alive = false;
            }
        }
        let before = self.parcels.len();
        self.parcels.retain(|p| p.alive);
        if self.parcels.len() != before {
            self.forces_stale = true;
        }
    }
}

/// Height at which air of liquid-water potential temperature `theta_l_k` and
/// total water `qt` becomes saturated when lifted through `env` (bisection on
/// ω_s(θ_l Π(P(z)), P(z)) = q_t, which decreases with height). 0 if it is
/// saturated at the ground, `z_max_m` if it never saturates below it. units: m
pub fn condensation_level_m(env: &Environment, theta_l_k: f64, qt: f64, z_max_m: f64) -> f64 {
    if !(saturation_excess(env, theta_l_k, qt, 0.0) > 0.0) {
        return 0.0;
    }
    if saturation_excess(env, theta_l_k, qt, z_max_m) > 0.0 {
        return z_max_m;
    }
    // 40 halvings of ≤ 100 km: below a millimetre.
    bisect_plane(env, theta_l_k, qt, 0.0, z_max_m, 40)
}

/// ω_s − q_t of air with liquid-water potential temperature θ_l lifted to z.
fn saturation_excess(env: &Environment, theta_l_k: f64, qt: f64, z_m: f64) -> f64 {
    let p = env.pressure_pa(z_m);
    thermo::saturation_mixing_ratio(theta_l_k * thermo::exner(p), p) - qt
}

/// Bisection for the saturation level inside [lo, hi] (excess > 0 at lo).
fn bisect_plane(env: &Environment, theta_l_k: f64, qt: f64, lo: f64, hi: f64, n: u32) -> f64 {
    let (mut lo, mut hi) = (lo, hi);
    for _ in 0..n {
        let mid = 0.5 * (lo + hi);
        if saturation_excess(env, theta_l_k, qt, mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}
