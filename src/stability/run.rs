//! Running one case: build the world, release the cluster, step the frames,
//! watch for NaN/Inf, kinetic-energy growth, escapes and clamps. A panic
//! inside the physics is caught and reported as a failed case.
//!
//! # The kinetic-energy bound
//!
//! A blow-up of the integrator shows as kinetic energy that no force in the
//! model can supply. Every parcel's kinetic energy comes from
//! - its initial kinetic energy (clusters start at rest: 0);
//! - the SPH compression of the start state: for p = K(ρ − ρ₀) the internal
//!   energy per kg is u = K(ln(ρ/ρ₀) + ρ₀/ρ − 1), summed as E_sph,0;
//! - buoyancy (eq 5): bounded per kg by the CAPE of the hottest parcel the
//!   case can make (the warmest start θ with *all* its water condensed, θ_v
//!   with all water as vapour) against the environment θ_v, integrated from
//!   the ground to the top, plus the "downdraft CAPE" of the coldest parcel
//!   (the coolest start θ with all its water evaporated);
//! - drag and entrainment towards the wind: at most ½|w|²_max per kg;
//! - the atmospheric pressure on hidden caps (§5.1): it takes the Archimedes
//!   force of the hidden cap off each overlapping parcel, so an overlapping
//!   pair weighs its lens volume of air and sinks. The world caps that force
//!   at w ρ_env g V per parcel (w = `atm_pressure_weight`; a hit is counted
//!   as an `atm_force` clamp, which fails a case that does not declare it).
//!   The force points down (and, by the tessellation's residue, a little
//!   sideways into the overlap), so, as for buoyancy, its work is bounded a
//!   priori by that cap over a fall through the whole column plus an
//!   overlap's width: E_cap(t) = w g ρ_env(0) ΣV_i(t) (H + 2 r_max), with H
//!   the column the parcels live in and r_max the largest radius allowed.
//!   ρ_env(0) V_i bounds ρ_env V of the parcel anywhere below (the air is
//!   densest at the ground; eq 6 shrinks V as the parcel sinks). The
//!   force's own work W_atm(t) is still measured (trapezoid rule on Σ F·v
//!   at frame ends), but only reported, as its share of E_cap: the budget
//!   does not trust the force it polices.
//!
//! So E_avail(t) = KE₀ + E_sph,0 + E_births(t) + M(t)·e_phys + E_cap(t)
//! with M(t) the mass alive and E_births below, and the **KE ratio** of a case is max_t KE(t)/E_avail(t).
//! The bound is loose (a parcel never has all of it), so a correct
//! integrator stays well under 1; a case fails when the ratio exceeds
//! [`KE_RATIO_BOUND`] = 1. Parcels born overlapping others bring SPH energy
//! too (an emission burst at K = 1e5 turns it into 80 m/s): the harness runs
//! the world's own emission ahead of each step (`ParcelWorld::emit_now`)
//! and adds each frame's jump of E_sph at the births.
//!
//! # The speed cap cannot hide a blow-up
//!
//! The speed guard (`max_speed_m_s`, 80 m/s) bounds the kinetic energy by
//! itself: ½M(80 m/s)² is under the energy bound of most cases, so a case
//! whose integrator blew up would still pass on its capped run. Every case
//! that declares the `speed` clamp is therefore run a second time with the
//! cap off (`ParcelWorld::set_speed_cap(false)`), same seed and frames; if
//! that run panics, stops early, produces a NaN/Inf or kinetic energy above
//! the same bound, the case fails whatever the capped run did
//! ([`Uncapped`]). What the capped run then shows is only that the cap
//! trims a few fast parcels of a motion that is bounded on its own.
//!
//! The table also shows the per-frame **KE growth**: max_n KE(n+1)/max(KE(n),
//! ½ M (1 m/s)²), informational (a real start-up from rest legitimately
//! multiplies it by a lot in a long frame).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::Instant;

use glam::DVec3;

use super::cases::{Case, Cluster};
use crate::atmosphere::{Environment, thermo};
use crate::physics::rng::SplitMix64;
use crate::physics::{ClampCounts, Parcel, ParcelSpec, ParcelWorld, WorldConfig, sph};

/// Largest allowed ratio of kinetic energy to the energy the case can supply.
pub const KE_RATIO_BOUND: f64 = 1.0;
/// Speed below which per-frame growth is measured from the floor. units: m s⁻¹
const GROWTH_FLOOR_SPEED_M_S: f64 = 1.0;

/// What one case did.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseResult {
    pub name: String,
    pub group: String,
    pub note: String,
    /// Requested frame step. units: s
    pub frame_dt_s: f64,
    /// Frames asked for.
    pub frames: u32,
    /// Frames stepped before the end (or the panic).
    pub frames_run: u32,
    /// Parcels at the start.
    pub parcels_start: usize,
    /// Most parcels alive at once.
    pub parcels_peak: usize,
    /// All frames ran without a panic.
    pub completed: bool,
    /// The panic message, if one was caught.
    pub panic: Option<String>,
    /// A setup error (the case could not be built), if any.
    pub error: Option<String>,
    /// NaN/Inf seen: parcels the guard removed for a non-finite state, plus
    /// frames whose diagnostics (water, KE) or parcel states were non-finite.
    pub non_finite: u64,
    /// Largest kinetic energy. units: J
    pub ke_max_j: f64,
    /// max_t KE(t) / E_avail(t) (see the module docs); ≤ 1 is physical.
    pub ke_ratio: f64,
    /// Largest per-frame factor KE(n+1)/max(KE(n), ½M(1 m/s)²).
    pub ke_step_growth: f64,
    /// Energy per kg the environment and wind can give (e_phys). units: J kg⁻¹
    pub e_phys_j_per_kg: f64,
    /// Work done by the §5.1 atmospheric pressure on hidden caps, at the end. units: J
    pub atm_work_j: f64,
    /// Largest W_atm / E_cap: the measured cap work over its a-priori bound
    /// (module docs); above 1 the bound does not hold. units: 1
    pub atm_work_share: f64,
    /// Fastest parcel seen at a frame end. units: m s⁻¹
    pub max_speed_m_s: f64,
    /// Parcels that left through the sides.
    pub escaped_sides: u64,
    /// Parcels that left through the top (domain or profile).
    pub escaped_top: u64,
    /// Sub-steps taken in all.
    pub substeps: u64,
    /// Clamps by kind (cumulative).
    pub clamps: ClampCounts,
    /// Clamp kinds the case declares (see `Case::declared_clamps`).
    pub declared_clamps: Vec<&'static str>,
    /// Wall-clock time of the case. units: s
    pub wall_s: f64,
    /// Wall-clock time inside the physics stages (the world's counters). units: s
    pub physics_s: f64,
    /// The rerun with the speed cap off, for a case that declares `speed`.
    pub uncapped: Option<Uncapped>,
}

/// What the rerun of a case with the speed cap off did (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Uncapped {
    /// All frames ran without a panic or setup error.
    pub completed: bool,
    /// The panic or setup error, if any.
    pub error: Option<String>,
    /// NaN/Inf seen (as [`CaseResult::non_finite`]).
    pub non_finite: u64,
    /// max_t KE(t) / E_avail(t), as [`CaseResult::ke_ratio`].
    pub ke_ratio: f64,
    /// Fastest parcel seen at a frame end. units: m s⁻¹
    pub max_speed_m_s: f64,
}

impl Uncapped {
    /// Why the uncapped run fails its case (empty when it held).
    pub fn failures(&self) -> Vec<String> {
        let mut f = Vec::new();
        if let Some(e) = &self.error {
            f.push(format!("without the speed cap: {e}"));
        } else if !self.completed {
            f.push("without the speed cap: did not complete".into());
        }
        if self.non_finite > 0 {
            f.push(format!(
                "without the speed cap: {} NaN/Inf",
                self.non_finite
            ));
        }
        if !(self.ke_ratio <= KE_RATIO_BOUND) {
            f.push(format!(
                "without the speed cap: KE ratio {:.3} > {KE_RATIO_BOUND}",
                self.ke_ratio
            ));
        }
        f
    }
}

impl CaseResult {
    /// Wall-clock time of the physics (the world's stage timers, without
    /// the harness's set-up and energy sums) per sub-step (0 before any). units: ms
    pub fn wall_per_substep_ms(&self) -> f64 {
        if self.substeps == 0 {
            0.0
        } else {
            self.physics_s * 1e3 / self.substeps as f64
        }
    }
}

impl CaseResult {
    /// Why the case failed (empty when it passed).
    pub fn failures(&self) -> Vec<String> {
        let mut f = Vec::new();
        if let Some(p) = &self.panic {
            f.push(format!("panicked: {p}"));
        } else if let Some(e) = &self.error {
            f.push(format!("setup error: {e}"));
        } else if !self.completed {
            f.push("did not complete".into());
        }
        if self.non_finite > 0 {
            f.push(format!("{} NaN/Inf", self.non_finite));
        }
        let undeclared: Vec<String> = self
            .clamps
            .kinds()
            .iter()
            .filter(|(k, n)| *n > 0 && !self.declared_clamps.contains(k))
            .map(|(k, n)| format!("{k} {n}"))
            .collect();
        if !undeclared.is_empty() {
            f.push(format!("undeclared clamps: {}", undeclared.join(", ")));
        }
        if !(self.ke_ratio <= KE_RATIO_BOUND) {
            f.push(format!(
                "KE ratio {:.3} > {KE_RATIO_BOUND} (energy from nowhere)",
                self.ke_ratio
            ));
        }
        // The a-priori cap-work bound must hold, or the KE budget is wrong.
        if !(self.atm_work_share <= 1.0) {
            f.push(format!(
                "cap work {:.3} × its a-priori bound E_cap",
                self.atm_work_share
            ));
        }
        if let Some(u) = &self.uncapped {
            f.extend(u.failures());
        }
        f
    }

    /// Whether the case passed.
    pub fn passed(&self) -> bool {
        self.failures().is_empty()
    }
}

/// Parcel specs of a cluster: a cubic lattice centred on `base_m` in x, y,
/// rising from it in z, each position jittered by ±10 % of the spacing and
/// each θ excess drawn in [0, theta_excess_k], from `seed`.
pub fn cluster_specs(env: &Environment, c: &Cluster, seed: u64) -> Vec<ParcelSpec> {
    let side = (c.count as f64).cbrt().ceil().max(1.0) as usize;
    let mut rng = SplitMix64::new(seed ^ 0x005e_edc1_u64);
    let half = 0.5 * (side as f64 - 1.0) * c.spacing_m;
    (0..c.count)
        .map(|n| {
            let (i, j, k) = (n % side, (n / side) % side, n / (side * side));
            let jitter = |r: &mut SplitMix64| r.range(-0.1, 0.1) * c.spacing_m;
            let pos = c.base_m
                + DVec3::new(
                    i as f64 * c.spacing_m - half + jitter(&mut rng),
                    j as f64 * c.spacing_m - half + jitter(&mut rng),
                    k as f64 * c.spacing_m + jitter(&mut rng),
                );
            let dth = rng.range(0.0, c.theta_excess_k);
            ParcelSpec::from_environment(env, pos, dth, c.qv_excess, c.radius_m)
        })
        .collect()
}

/// Σ m u with u = K(ln(ρ/ρ₀) + ρ₀/ρ − 1), ρ by poly6 over all pairs, ρ₀ = m W(0).
fn sph_energy_j(parcels: &[Parcel], cfg: &WorldConfig) -> f64 {
    if !cfg.physics.sph || cfg.physics.stiffness == 0.0 {
        return 0.0;
    }
    let h = cfg.physics.support_radius_m;
    let k = cfg.physics.stiffness;
    let w0 = sph::poly6(0.0, h);
    // Sort by x so that each parcel only scans neighbours within h in x.
    let mut order: Vec<usize> = (0..parcels.len()).collect();
    order.sort_by(|&a, &b| parcels[a].position_m.x.total_cmp(&parcels[b].position_m.x));
    let mut rho: Vec<f64> = parcels.iter().map(|p| p.total_mass_kg() * w0).collect();
    for (a, &i) in order.iter().enumerate() {
        let xi = parcels[i].position_m;
        for &j in &order[a + 1..] {
            let xj = parcels[j].position_m;
            if xj.x - xi.x >= h {
                break;
            }
            let w = sph::poly6((xi - xj).length_squared(), h);
            if w > 0.0 {
                rho[i] += parcels[j].total_mass_kg() * w;
                rho[j] += parcels[i].total_mass_kg() * w;
            }
        }
    }
    parcels
        .iter()
        .zip(rho)
        .map(|(p, r)| {
            let m = p.total_mass_kg();
            let r0 = m * w0;
            m * k * ((r / r0).ln() + r0 / r - 1.0)
        })
        .sum()
}

/// e_phys of the module docs, per kg: ½|w|²_max, plus the CAPE of the
/// hottest parcel the case can make (θ = the warmest start, total water
/// `qt_max`, lifted reversibly: at every height its θ and vapour come from
/// thermo's saturation adjustment of that air at the environment pressure,
/// so it gets all the latent heat the water can give), integrated over the
/// whole column, plus the downdraft energy of the coolest start θ below
/// the highest start `z_start_max_m` (sinking is all a parcel can do with
/// negative buoyancy; one that rose first spent CAPE to get there).
/// units: J kg⁻¹
pub fn specific_energy_bound(
    env: &Environment,
    cfg: &WorldConfig,
    theta_range_k: (f64, f64),
    qt_max: f64,
    z_start_max_m: f64,
) -> f64 {
    let speed = |v: [f64; 2]| (v[0] * v[0] + v[1] * v[1]).sqrt();
    // The wind in effect: the scene's [wind] table (linear between its two
    // values), else the sounding's profile (linear between its levels), so
    // its fastest value is at one of the levels.
    let wind = match (&cfg.wind, env.wind()) {
        (Some(w), _) => speed(w.surface_m_s).max(speed(w.aloft_m_s)),
        (None, Some(p)) => p
            .levels()
            .iter()
            .map(|l| speed([l.u_m_s, l.v_m_s]))
            .fold(0.0, f64::max),
        (None, None) => 0.0,
    };
    let alpha = cfg.physics.latent_heat_alpha;
    let top = cfg.physics.domain_top_m.min(env.top_m());
    let dz = 10.0;
    let steps = (top / dz).ceil() as usize;
    let (mut up, mut down) = (0.0, 0.0);
    for s in 0..steps {
        let z = (s as f64 + 0.5) * dz;
        let p = env.pressure_pa(z);
        let ex = thermo::exner(p);
        let tv_env = env.theta_v_k(z);
        let a = thermo::saturation_adjust(theta_range_k.1 * ex, qt_max, 0.0, p, alpha);
        let hot = thermo::virtual_potential_temperature_k(a.t_k / ex, a.qv, 0.0);
        up += thermo::GRAVITY * ((hot - tv_env) / tv_env).max(0.0) * dz;
        if z <= z_start_max_m {
            let cold = theta_range_k.0;
            down += thermo::GRAVITY * ((tv_env - cold) / tv_env).max(0.0) * dz;
        }
    }
    0.5 * wind * wind + up + down
}

/// E_cap of the module docs: the a-priori bound on the work of the §5.1
/// cap force, from the parcels' volumes and the force's cap alone. units: J
fn cap_work_bound_j(world: &ParcelWorld, cfg: &WorldConfig) -> f64 {
    let c = &cfg.physics;
    if !c.atmospheric_pressure {
        return 0.0;
    }
    let env = world.environment();
    let path_m = c.domain_top_m.min(env.top_m()) + 2.0 * c.max_radius_m;
    let volume_m3: f64 = world.parcels().iter().map(|p| p.volume_m3).sum();
    c.atm_pressure_weight * thermo::GRAVITY * env.density_kg_m3(0.0) * volume_m3 * path_m
}

/// θ range and largest total water of every parcel a case can make: the
/// cluster's, the ground's emissions (surface air plus the patch excess), and
/// environment air entrained anywhere. units: K, kg/kg
fn parcel_envelope(case: &Case, specs: &[ParcelSpec]) -> ((f64, f64), f64) {
    let env = &case.env;
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    let mut qt: f64 = 0.0;
    for s in specs {
        lo = lo.min(s.theta_k);
        hi = hi.max(s.theta_k);
        qt = qt.max(s.qv_kg_per_kg + s.ql_kg_per_kg);
    }
    if case.config.emission.enabled {
        let g = &case.config.ground;
        lo = lo.min(env.theta_k(0.0));
        hi = hi.max(env.theta_k(0.0) + g.heat_excess_k);
        qt = qt.max(env.qv(0.0) + g.moisture_excess_kg_per_kg);
    }
    for l in env.levels() {
        qt = qt.max(l.qv_kg_per_kg);
    }
    if !lo.is_finite() {
        (lo, hi) = (env.theta_k(0.0), env.theta_k(0.0));
    }
    ((lo, hi), qt)
}

/// Runs one case; a panic is caught and reported in the result. The
/// panic's own message is kept; the default hook's print is not silenced
/// (set a quiet hook around the whole matrix for that, see [`run_matrix`](super::run_matrix)).
/// A case that declares the `speed` clamp is run again with the cap off
/// (module docs); `on_frame` sees the capped run's frames only.
pub fn run_case(case: &Case, mut on_frame: impl FnMut(u32)) -> CaseResult {
    let mut res = run_once(case, true, &mut on_frame);
    if case.declared_clamps.contains(&"speed") {
        let u = run_once(case, false, &mut |_| {});
        res.uncapped = Some(Uncapped {
            completed: u.completed,
            error: u.panic.map(|p| format!("panicked: {p}")).or(u.error),
            non_finite: u.non_finite,
            ke_ratio: u.ke_ratio,
            max_speed_m_s: u.max_speed_m_s,
        });
    }
    res
}

/// One run of `case`, with or without the speed cap.
fn run_once(case: &Case, speed_cap: bool, on_frame: &mut dyn FnMut(u32)) -> CaseResult {
    let t0 = Instant::now();
    let mut res = CaseResult {
        name: case.name.clone(),
        group: case.group.to_string(),
        note: case.note.clone(),
        frame_dt_s: case.frame_dt_s,
        frames: case.frames,
        frames_run: 0,
        parcels_start: 0,
        parcels_peak: 0,
        completed: false,
        panic: None,
        error: None,
        non_finite: 0,
        ke_max_j: 0.0,
        ke_ratio: 0.0,
        ke_step_growth: 0.0,
        e_phys_j_per_kg: 0.0,
        atm_work_j: 0.0,
        atm_work_share: 0.0,
        max_speed_m_s: 0.0,
        escaped_sides: 0,
        escaped_top: 0,
        substeps: 0,
        clamps: ClampCounts::default(),
        declared_clamps: case.declared_clamps.clone(),
        wall_s: 0.0,
        physics_s: 0.0,
        uncapped: None,
    };
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        simulate(case, speed_cap, &mut res, on_frame)
    }));
    match outcome {
        Ok(Ok(())) => res.completed = res.frames_run == case.frames,
        Ok(Err(e)) => res.error = Some(e.to_string()),
        Err(payload) => {
            let msg = payload
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "non-string panic payload".into());
            res.panic = Some(msg);
        }
    }
    res.wall_s = t0.elapsed().as_secs_f64();
    res
}

fn simulate(
    case: &Case,
    speed_cap: bool,
    res: &mut CaseResult,
    on_frame: &mut dyn FnMut(u32),
) -> crate::Result<()> {
    let mut world = ParcelWorld::new(case.env.clone(), case.config.clone(), case.seed)?;
    world.set_speed_cap(speed_cap);
    let mut e_births = 0.0;
    let specs = case
        .cluster
        .as_ref()
        .map(|c| cluster_specs(&case.env, c, case.seed))
        .unwrap_or_default();
    for s in &specs {
        world.spawn_parcel(*s)?;
    }
    let (theta_range, qt_max) = parcel_envelope(case, &specs);
    let z_start_max = specs.iter().map(|s| s.position_m.z).fold(0.0, f64::max);
    let e_phys = specific_energy_bound(&case.env, &case.config, theta_range, qt_max, z_start_max);
    res.e_phys_j_per_kg = e_phys;
    let d0 = world.diagnostics();
    let e0 = d0.kinetic_energy_j + sph_energy_j(world.parcels(), &case.config);
    res.parcels_start = d0.parcels;
    res.parcels_peak = d0.parcels;
    let mass = |w: &ParcelWorld| w.parcels().iter().map(Parcel::total_mass_kg).sum::<f64>();
    let floor = |m: f64| 0.5 * m * GROWTH_FLOOR_SPEED_M_S * GROWTH_FLOOR_SPEED_M_S;
    let mut ke_prev = d0.kinetic_energy_j;
    // Power of the §5.1 force; the forces of the start state are computed in
    // the first step, so the first interval uses its end value only.
    let atm_power = |w: &ParcelWorld| {
        w.parcels()
            .iter()
            .map(|p| p.atm_force_n.dot(p.velocity_m_s))
            .sum::<f64>()
    };
    let mut power_prev: Option<f64> = None;
    let mut w_atm = 0.0;
    for f in 0..case.frames {
        if case.config.emission.enabled {
            // The world's own emission, done ahead of the step so that the
            // SPH energy the births bring can be measured.
            let before = sph_energy_j(world.parcels(), &case.config);
            if world.emit_now(case.frame_dt_s).emitted > 0 {
                e_births += sph_energy_j(world.parcels(), &case.config) - before;
            }
        }
        let report = world.step(case.frame_dt_s);
        let d = world.diagnostics();
        res.frames_run = f + 1;
        res.substeps += report.substeps as u64;
        res.parcels_peak = res.parcels_peak.max(d.parcels);
        let finite_state = world.parcels().iter().all(|p| {
            p.position_m.is_finite() && p.velocity_m_s.is_finite() && p.theta_k.is_finite()
        });
        if !(d.kinetic_energy_j.is_finite() && d.total_water_kg.is_finite() && finite_state) {
            res.non_finite += 1;
        } else {
            let m = mass(&world);
            let ke = d.kinetic_energy_j;
            res.ke_max_j = res.ke_max_j.max(ke);
            let power = atm_power(&world);
            let mean = power_prev.map_or(power, |p0| 0.5 * (p0 + power));
            w_atm += mean * case.frame_dt_s;
            power_prev = Some(power);
            let e_cap = cap_work_bound_j(&world, &case.config);
            let avail = e0 + e_births + m * e_phys + e_cap;
            if e_cap > 0.0 {
                res.atm_work_share = res.atm_work_share.max(w_atm.max(0.0) / e_cap);
            }
            if avail > 0.0 {
                res.ke_ratio = res.ke_ratio.max(ke / avail);
            } else if ke > 0.0 {
                res.ke_ratio = f64::INFINITY;
            }
            let base = ke_prev.max(floor(m));
            if base > 0.0 {
                res.ke_step_growth = res.ke_step_growth.max(ke / base);
            }
            ke_prev = ke;
            for p in world.parcels() {
                res.max_speed_m_s = res.max_speed_m_s.max(p.velocity_m_s.length());
            }
        }
        on_frame(f + 1);
    }
    let d = world.diagnostics();
    res.atm_work_j = w_atm;
    let c = world.counters();
    res.physics_s =
        (c.neighbours + c.sph + c.exposed_area + c.mixing + c.thermo + c.integrate).as_secs_f64();
    res.clamps = d.clamps;
    res.escaped_sides = d.fates.escaped_sides;
    res.escaped_top = d.fates.escaped_top;
    res.non_finite += d.clamps.non_finite;
    Ok(())
}
