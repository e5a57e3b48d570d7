//! The paper's equations one by one, for given inputs: eq 6 volume, eqs
//! 11/14/15 mixing, the exchange between touching parcels (eq 16), viscosity
//! (eq 10), the filling ratio (§6.1) and every way a parcel dies.

use cumulus::physics::{Parcel, ParcelSpec, ParcelWorld, PhysicsConfig};
use glam::DVec3;

mod common;
use common::fair_weather;
use common::physics::{neutral, world};

/// Every term off: tests switch on the one they look at.
fn nothing() -> PhysicsConfig {
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

#[test]
fn eqs_11_14_15_entrain_and_detrain_by_the_computed_amounts() {
    // One sub-step of 1 s at 4 m/s through fair-weather air, isolated (its
    // exposed area is the whole sphere): the dry air gained is
    // K_e ε r A ρ |v_rel| dt /(1 + q_env) (eq 11, 13), θ mixes by mass (eq 14),
    // with the environment taken at the sub-step's midpoint height.
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
    // The air met at the sub-step's midpoint (the midpoint rule).
    let z = 400.0 + 0.5 * v;
    let rho = env.density_kg_m3(z);
    let r = before.radius_m;
    let area = 4.0 * std::f64::consts::PI * r * r;
    let dma = c.entrainment_surface_factor * c.entrainment_rate_per_m * r * area * rho * v;
    let dry_in = dma / (1.0 + env.qv(z));
    let dme = dry_in * (1.0 + env.qv(z));
    // 1e-9: ρ from the environment's table vs the world's own expression.
    assert!(
        ((after.dry_mass_kg - before.dry_mass_kg) / dry_in - 1.0).abs() < 1e-9,
        "{} vs {dry_in}",
        after.dry_mass_kg - before.dry_mass_kg
    );
    let m = before.total_mass_kg();
    let theta = (m * before.theta_k + dme * env.theta_k(z)) / (m + dme);
    assert!(
        (after.theta_k - theta).abs() < 1e-9,
        "{} vs {theta}",
        after.theta_k
    );
    // Below the condensation level there is no detrainment: the water only
    // gains the entrained vapour.
    let water = before.water_kg() + env.qv(z) * dry_in;
    assert!((after.water_kg() / water - 1.0).abs() < 1e-9);

    // eq 15 above the condensation level: the same parcel at 2.5 km loses
    // K_d δ r A ρ_p |v| dt of its mass in proportion.
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
    let z = 2500.0 + 0.5 * v;
    let dma = c.entrainment_rate_per_m * r * area * env.density_kg_m3(z) * v;
    let dry_in = dma / (1.0 + env.qv(z));
    let m = b.total_mass_kg();
    let dmd = c.detrainment_rate_per_m * r * area * (m / b.volume_m3) * v;
    let frac = dmd / (m + dry_in * (1.0 + env.qv(z)));
    let dry = (b.dry_mass_kg + dry_in) * (1.0 - frac);
    assert!(w.environment_condensation_level_m() < 2500.0);
    assert!(
        (a.dry_mass_kg / dry - 1.0).abs() < 1e-9,
        "{} vs {dry}",
        a.dry_mass_kg
    );
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
    assert_eq!(w.diagnostics().clamps.opaque, 1);
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
