//! The paper's equations one by one, for given inputs: eq 6 volume, eqs
//! 11/14/15 mixing, the exchange between touching parcels (eq 16), viscosity
//! (eq 10), the filling ratio (§6.1) and every way a parcel dies.

use cumulus::physics::{Parcel, ParcelSpec, ParcelWorld, PhysicsConfig};
use glam::DVec3;

use crate::common::fair_weather;
use crate::common::physics::{neutral, world};

/// Every term off: tests switch on the one they look at.
pub(crate) fn nothing() -> PhysicsConfig {
    PhysicsConfig {
        sph: false,
        viscosity: false,
        atmospheric_pressure: false,
        mixing: false,
        exchange: false,
        condensation: false,
        buoyancy: false,
        drag: false,
        ..PhysicsConfig::default()
    }
}

fn spawn(w: &mut ParcelWorld, pos: DVec3, vel: DVec3, dth: f64, dq: f64, r: f64) {
    let mut s = ParcelSpec::from_environment(w.environment(), pos, dth, dq, r);
    s.velocity_m_s = vel;
    w.spawn_parcel(s).unwrap();
}

#[test]
fn eq6_volume_follows_pressure_adiabatically() {
    // A parcel carried up at 5 m/s with nothing acting: V₂ = V₁ (P₁/P₂)^{1/γ}.
    let mut w = world(neutral(), nothing(), false, 1);
    spawn(
        &mut w,
        DVec3::new(0.0, 0.0, 500.0),
        DVec3::new(0.0, 0.0, 5.0),
        0.0,
        0.0,
        150.0,
    );
    let (v0, z0) = (w.parcels()[0].volume_m3, 500.0);
    for _ in 0..100 {
        w.step(2.0);
    }
    let p = &w.parcels()[0];
    let env = w.environment();
    let expect = v0 * (env.pressure_pa(z0) / env.pressure_pa(p.position_m.z)).powf(1.0 / 1.4);
    // 1e-12: the volume is a product of per-step pressure ratios that
    // telescope; only rounding separates it from the closed form.
    assert!(
        (p.volume_m3 / expect - 1.0).abs() < 1e-12,
        "{} vs {expect}",
        p.volume_m3
    );
    assert!((p.position_m.z - 1500.0).abs() < 1e-9);
    let r = (3.0 * p.volume_m3 / (4.0 * std::f64::consts::PI)).cbrt();
    assert!((p.radius_m - r).abs() < 1e-9 * r);
}

/// The scalars of one isolated parcel that mixing changes: dry mass, q_v,
/// q_l, θ, and its volume. units: kg, kg/kg, kg/kg, K, m³
#[derive(Debug, Clone, Copy)]
struct Mixed {
    dry: f64,
    qv: f64,
    ql: f64,
    theta: f64,
    volume: f64,
}

impl Mixed {
    fn of(p: &Parcel) -> Self {
        Mixed {
            dry: p.dry_mass_kg,
            qv: p.qv_kg_per_kg,
            ql: p.ql_kg_per_kg,
            theta: p.theta_k,
            volume: p.volume_m3,
        }
    }
    fn mass(&self) -> f64 {
        self.dry * (1.0 + self.qv + self.ql)
    }
    fn radius(&self) -> f64 {
        (3.0 * self.volume / (4.0 * std::f64::consts::PI)).cbrt()
    }
}

/// eqs 11–15 as rates for an isolated parcel (exposed area = the whole
/// sphere) rising at `v` through the air at `z`, detraining when `detrain`:
/// d/dt of (dry mass, q_v, θ) and the entrained mass rate. Entrained mass ṁ_e = K_e ε r A ρ |v|, its dry
/// part ṁ_e/(1 + q_env) (eqs 11, 13); θ mixes by mass (eq 14); detrainment
/// removes K_d δ r A ρ_p |v| of all the parcel's air in proportion (eq 15).
fn mixing_rates(
    env: &cumulus::atmosphere::Environment,
    c: &PhysicsConfig,
    z: f64,
    v: f64,
    s: &Mixed,
    detrain: bool,
) -> [f64; 4] {
    let r = s.radius();
    let area = 4.0 * std::f64::consts::PI * r * r;
    let m = s.mass();
    let ent = c.entrainment_surface_factor
        * c.entrainment_rate_per_m
        * r
        * area
        * env.density_kg_m3(z)
        * v;
    let dry_in = ent / (1.0 + env.qv(z));
    let mut dry = dry_in;
    if detrain {
        let det =
            c.detrainment_surface_factor * c.detrainment_rate_per_m * r * area * (m / s.volume) * v;
        dry -= det / m * s.dry;
    }
    [
        dry,
        dry_in * (env.qv(z) - s.qv) / s.dry,
        ent / m * (env.theta_k(z) - s.theta),
        ent,
    ]
}

/// One sub-step of `dt` by the trapezoidal rule with a forward-Euler
/// predictor (Heun), as the world does it: the rates at the start, a
/// predicted end state (volume by eq 6 at the new pressure), the rates
/// there, and the mean of the two. The only force is the momentum of the
/// entrained air (it arrives at rest: a = −v ṁ_e/m), so the parcel moves by
/// the kick–drift–kick of that deceleration and the end rates see the
/// predicted velocity v + a dt. Returns (dry mass, q_v, θ) at the end.
fn heun_step(
    env: &cumulus::atmosphere::Environment,
    c: &PhysicsConfig,
    z0: f64,
    v0: f64,
    s0: &Mixed,
    detrain: bool,
    dt: f64,
) -> [f64; 3] {
    let g0 = mixing_rates(env, c, z0, v0, s0, detrain);
    let a0 = -v0 * g0[3] / s0.mass();
    let v_half = v0 + 0.5 * dt * a0;
    let z1 = z0 + v_half * dt;
    let v1 = v_half + 0.5 * dt * a0;
    let mut s1 = Mixed {
        dry: s0.dry + g0[0] * dt,
        qv: s0.qv + g0[1] * dt,
        theta: s0.theta + g0[2] * dt,
        ..*s0
    };
    s1.volume = s0.volume
        * (env.pressure_pa(z0) / env.pressure_pa(z1)).powf(1.0 / c.gamma)
        * (s1.mass() / s0.mass());
    let g1 = mixing_rates(env, c, z1, v1, &s1, detrain);
    [
        s0.dry + 0.5 * dt * (g0[0] + g1[0]),
        s0.qv + 0.5 * dt * (g0[1] + g1[1]),
        s0.theta + 0.5 * dt * (g0[2] + g1[2]),
    ]
}

#[test]
fn eqs_11_14_15_entrain_and_detrain_by_the_computed_amounts() {
    // One sub-step of 1 s at 4 m/s through fair-weather air, isolated (its
    // exposed area is the whole sphere), nothing else acting but the
    // entrained air's momentum: the entrained dry air, the vapour and θ
    // (eqs 11–14) are the trapezoidal rule of their rates with a predicted
    // end state.
    let physics = PhysicsConfig {
        mixing: true,
        turbulence_m_s: 0.0,
        max_dt_s: 1.0,
        ..nothing()
    };
    let c = physics.clone();
    let mut w = world(fair_weather(), physics, false, 1);
    let v = 4.0;
    spawn(
        &mut w,
        DVec3::new(0.0, 0.0, 400.0),
        DVec3::new(0.0, 0.0, v),
        1.0,
        1e-3,
        150.0,
    );
    let before: Parcel = w.parcels()[0].clone();
    w.step(1.0);
    let after = &w.parcels()[0];
    let env = w.environment();
    // Below the condensation level there is no detrainment.
    assert!(w.environment_condensation_level_m() > 410.0);
    let [dry, qv, theta] = heun_step(env, &c, 400.0, v, &Mixed::of(&before), false, 1.0);
    // 1e-9: the same formulas evaluated in another order (rounding only).
    for (name, got, want) in [
        ("dry mass", after.dry_mass_kg, dry),
        ("q_v", after.qv_kg_per_kg, qv),
        ("θ", after.theta_k, theta),
    ] {
        assert!((got / want - 1.0).abs() < 1e-9, "{name}: {got} vs {want}");
    }
    // The parcel gained air and vapour, and cooled towards the environment.
    assert!(after.dry_mass_kg > before.dry_mass_kg);
    assert!(after.water_kg() > before.water_kg());
    assert!(after.theta_k < before.theta_k);

    // eq 15 above the condensation level: the same parcel at 2.5 km also
    // loses air and water in proportion, at its own density.
    let mut w = world(fair_weather(), c.clone(), false, 1);
    spawn(
        &mut w,
        DVec3::new(0.0, 0.0, 2500.0),
        DVec3::new(0.0, 0.0, v),
        0.0,
        0.0,
        150.0,
    );
    let b = w.parcels()[0].clone();
    w.step(1.0);
    let a = &w.parcels()[0];
    assert!(w.environment_condensation_level_m() < 2500.0);
    let env = w.environment();
    let [dry, ..] = heun_step(env, &c, 2500.0, v, &Mixed::of(&b), true, 1.0);
    assert!(
        (a.dry_mass_kg / dry - 1.0).abs() < 1e-9,
        "{} vs {dry}",
        a.dry_mass_kg
    );
    let [no_detrain, ..] = heun_step(env, &c, 2500.0, v, &Mixed::of(&b), false, 1.0);
    assert!(a.dry_mass_kg < no_detrain, "detrainment removes air");
}

/// Three touching parcels of different vapour, liquid and θ, exchange only.
fn exchange_trio(reverse: bool) -> Vec<Parcel> {
    let physics = PhysicsConfig {
        exchange: true,
        exchange_velocity_m_s: 0.5,
        ..nothing()
    };
    let mut w = world(neutral(), physics, false, 1);
    let mut specs = vec![
        (DVec3::new(-200.0, 0.0, 2000.0), 0.0, 4e-3, 1e-3),
        (DVec3::new(0.0, 0.0, 2000.0), 1.5, 1e-3, 0.0),
        (DVec3::new(200.0, 30.0, 2050.0), -0.5, 0.0, 2e-3),
    ];
    if reverse {
        specs.reverse();
    }
    for (pos, dth, dq, ql) in specs {
        let mut s = ParcelSpec::from_environment(w.environment(), pos, dth, dq, 150.0);
        s.ql_kg_per_kg = ql;
        w.spawn_parcel(s).unwrap();
    }
    let totals = |ps: &[Parcel]| -> [f64; 3] {
        [
            ps.iter().map(|p| p.dry_mass_kg * p.qv_kg_per_kg).sum(),
            ps.iter().map(|p| p.dry_mass_kg * p.ql_kg_per_kg).sum(),
            ps.iter().map(|p| p.dry_mass_kg * p.theta_k).sum(),
        ]
    };
    let t0 = totals(w.parcels());
    let first = w.parcels().to_vec();
    w.step(2.0);
    let t1 = totals(w.parcels());
    for k in 0..3 {
        // 1e-13: each pair's transfer is applied with opposite signs;
        // only rounding of the per-parcel products and sums remains.
        assert!(
            (t1[k] / t0[k] - 1.0).abs() < 1e-13,
            "quantity {k}: {} → {}",
            t0[k],
            t1[k]
        );
    }
    // Direction: every quantity moves from the richer parcel to the poorer.
    let after = w.parcels();
    let mid = 1;
    let (wet, dry) = if reverse { (2, 0) } else { (0, 2) };
    assert!(after[wet].qv_kg_per_kg < first[wet].qv_kg_per_kg);
    assert!(after[dry].qv_kg_per_kg > first[dry].qv_kg_per_kg);
    assert!(
        after[mid].theta_k < first[mid].theta_k,
        "the warm parcel gives heat"
    );
    assert!(
        after[dry].ql_kg_per_kg < first[dry].ql_kg_per_kg,
        "liquid leaves the cloudy one"
    );
    let mut out = after.to_vec();
    if reverse {
        out.reverse();
    }
    out
}

#[test]
fn exchange_conserves_vapour_liquid_and_heat_and_ignores_pair_order() {
    let a = exchange_trio(false);
    let b = exchange_trio(true);
    for (p, q) in a.iter().zip(&b) {
        // Same physics whatever the parcels' order: 1e-13 relative, the
        // rounding of sums taken in another order.
        for (x, y) in [
            (p.qv_kg_per_kg, q.qv_kg_per_kg),
            (p.ql_kg_per_kg, q.ql_kg_per_kg),
            (p.theta_k, q.theta_k),
        ] {
            assert!((x - y).abs() <= 1e-13 * x.abs().max(1e-3), "{x} vs {y}");
        }
    }
}

#[test]
fn viscosity_damps_relative_velocity_by_the_computed_rate() {
    // Two parcels 200 m apart sliding past each other at ±1 m/s (motion
    // across the line between them, so their distance stays put to first
    // order). Viscosity (eq 10) relaxes the relative velocity at
    // s_i + s_j, s = μ m/(ρ_i ρ_j) ∇²W(d): Δv(t) = Δv(0) e^{−2 s t}.
    let run = |mu: f64, t: f64| -> (f64, f64) {
        let physics = PhysicsConfig {
            viscosity: true,
            viscosity_mu: mu,
            max_dt_s: 0.5,
            ..nothing()
        };
        let h = physics.support_radius_m;
        let mut w = world(neutral(), physics, false, 1);
        spawn(
            &mut w,
            DVec3::new(-100.0, 0.0, 2000.0),
            DVec3::new(0.0, 1.0, 0.0),
            0.0,
            0.0,
            80.0,
        );
        spawn(
            &mut w,
            DVec3::new(100.0, 0.0, 2000.0),
            DVec3::new(0.0, -1.0, 0.0),
            0.0,
            0.0,
            80.0,
        );
        let p = &w.parcels()[0];
        let m = p.total_mass_kg();
        let w0 = 315.0 / (64.0 * std::f64::consts::PI * h.powi(9));
        let poly = |d: f64| w0 * (h * h - d * d).powi(3);
        let rho = m * (w0 * h.powi(6) + poly(200.0));
        let lap = 45.0 / (std::f64::consts::PI * h.powi(6)) * (h - 200.0);
        let s = mu * m / (rho * rho) * lap;
        for _ in 0..(t / 0.5) as usize {
            w.step(0.5);
        }
        let ps = w.parcels();
        (
            ps[0].velocity_m_s.y - ps[1].velocity_m_s.y,
            2.0 * (-2.0 * s * t).exp(),
        )
    };
    // An eddy viscosity (μ = 50 Pa s ≈ ρ K with K ≈ 50 m² s⁻¹) damps
    // within a minute: e^{−2st} ≈ 0.68 after 20 s.
    let (dv, expect) = run(50.0, 20.0);
    assert!(expect < 1.5, "the test must see real damping: {expect}");
    // 1 %: the parcels drift ~35 m apart sideways in 20 s, so d grows to
    // ~203 m and ∇²W(d) falls by up to 3 % at the end (~1.5 % on average),
    // i.e. ~0.5 % of the exponent; leapfrog's error at s dt = 0.005 is less.
    assert!((dv / expect - 1.0).abs() < 0.01, "{dv} vs {expect}");
    // The paper's μ = 0.01 Pa s is all but inert in SI: it acts (the
    // relative velocity falls) but by less than 0.5 % in ten minutes.
    let (dv, _) = run(0.01, 600.0);
    assert!(dv < 2.0 && 2.0 - dv < 0.005 * 2.0, "{dv}");
}

#[test]
fn filling_ratio_is_liquid_content_over_the_opaque_content() {
    let physics = nothing();
    let opaque = physics.opaque_lwc_kg_m3;
    let mut w = world(fair_weather(), physics, false, 1);
    for ql in [1e-4, 5e-3] {
        let mut s = ParcelSpec::from_environment(
            w.environment(),
            DVec3::new(0.0, 0.0, 3000.0),
            0.0,
            0.0,
            150.0,
        );
        s.ql_kg_per_kg = ql;
        w.spawn_parcel(s).unwrap();
    }
    w.step(1.0);
    let ps = w.parcels();
    let f = ps[0].ql_kg_per_kg * ps[0].dry_mass_kg / ps[0].volume_m3 / opaque;
    assert!(f > 0.05 && f < 1.0, "{f}");
    assert!((ps[0].fill - f).abs() < 1e-12);
    // 5 g/kg is ~3 g/m³, above the opaque 0.5 g/m³: shown as 1, counted.
    assert_eq!(ps[1].fill, 1.0);
    let d = w.diagnostics();
    assert_eq!(d.opaque_parcel_frames, 1);
    // A display saturation, not a physics clamp: the total does not count it.
    assert_eq!(d.clamps.total(), 0, "{}", d.clamps);
}

#[test]
fn every_death_path_is_taken_and_counted() {
    let mut physics = nothing();
    physics.max_age_s = 100.0;
    physics.condensation = true;
    let mut w = world(fair_weather(), physics, false, 1);
    let half = 0.5 * w.config().ground.size_m[0];
    let top = w.config().physics.domain_top_m.min(w.environment().top_m());
    let down = DVec3::new(0.0, 0.0, -3.0);
    // grounded: centre below the ground, sinking.
    spawn(&mut w, DVec3::new(0.0, 0.0, 1.0), down, 0.0, 0.0, 100.0);
    // escaped through a side, and through the top.
    spawn(
        &mut w,
        DVec3::new(half - 1.0, 0.0, 500.0),
        DVec3::new(3.0, 0.0, 0.0),
        0.0,
        0.0,
        100.0,
    );
    spawn(
        &mut w,
        DVec3::new(0.0, 1000.0, top - 1.0),
        DVec3::new(0.0, 0.0, 3.0),
        0.0,
        0.0,
        100.0,
    );
    // aged: a quiet parcel older than 100 s.
    spawn(
        &mut w,
        DVec3::new(2000.0, 0.0, 500.0),
        DVec3::ZERO,
        0.0,
        0.0,
        100.0,
    );
    // evaporated: it held liquid, has none now, sinks far below its plane.
    let mut s = ParcelSpec::from_environment(
        w.environment(),
        DVec3::new(-2000.0, 0.0, 300.0),
        0.0,
        0.0,
        100.0,
    );
    s.ql_kg_per_kg = 1e-6;
    s.velocity_m_s = down;
    w.spawn_parcel(s).unwrap();
    w.step(2.0);
    let f = w.diagnostics().fates;
    assert_eq!(
        (f.grounded, f.escaped_sides, f.escaped_top),
        (1, 1, 1),
        "{f:?}"
    );
    assert_eq!(f.evaporated, 1, "{f:?}");
    assert_eq!(f.aged, 0);
    for _ in 0..60 {
        w.step(2.0);
    }
    let f = w.diagnostics().fates;
    assert_eq!(f.aged, 1, "{f:?}");
    assert!(w.parcels().is_empty());
}
