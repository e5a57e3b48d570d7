//! Kinematic parcel ascent: the dry adiabatic lapse rate, conservation of θ
//! and water, the LCL against the saturation condition, and the cost of
//! redrawing a parcel curve (checked by value, timed in benches only).

use std::path::Path;

use cumulus::atmosphere::lifting::{
    LiftOptions, lift_at, lift_surface_parcel, surface_parcel_curve,
};
use cumulus::atmosphere::{EnvLevel, Environment, PressureModel, Sounding, thermo};

fn oun_2011() -> Environment {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/soundings/oun-2011-05-22-12z.txt");
    Sounding::load(&path).unwrap().to_environment().unwrap()
}

#[test]
fn dry_ascent_cools_at_g_over_cp() {
    // A dry isentropic atmosphere: the parcel has the environment's θ_v at
    // every height, so hydrostatic balance gives dT/dz = −g/c_p exactly; the
    // only error is the 10 m pressure table (~1e-6 in Π ≈ 3e-4 K), hence
    // 1e-3 K/km over 8 km.
    let lv = |z_m| EnvLevel {
        z_m,
        theta_k: 300.0,
        qv_kg_per_kg: 1e-5,
        pressure_pa: None,
    };
    let env = Environment::new(
        vec![lv(0.0), lv(10_000.0)],
        100_000.0,
        PressureModel::Hydrostatic,
    )
    .unwrap();
    let a = lift_at(&env, &LiftOptions::default(), &[0.0, 1000.0, 8000.0]).unwrap();
    assert!(
        a.lcl.is_none(),
        "1e-5 kg/kg never saturates below 8 km (ωs ≈ 1e-4 there)"
    );
    let lapse_k_per_km = -(a.levels[2].t_k - a.levels[0].t_k) / 8.0;
    let expect = thermo::GRAVITY / thermo::CP_DRY * 1000.0;
    assert!((expect - 9.75).abs() < 0.01, "g/c_p = {expect} K/km");
    assert!(
        (lapse_k_per_km - expect).abs() < 1e-3,
        "{lapse_k_per_km} vs {expect} K/km"
    );
    let first_km = a.levels[0].t_k - a.levels[1].t_k;
    assert!(
        (first_km - expect).abs() < 1e-3,
        "{first_km} K in the first km"
    );
}

#[test]
fn theta_and_water_are_conserved_below_the_lcl_and_water_above() {
    let env = oun_2011();
    let a = surface_parcel_curve(&env, &LiftOptions::default(), 400).unwrap();
    let lcl = a.lcl.unwrap().z_m;
    let (theta0, qt0) = (a.levels[0].theta_k, a.levels[0].qv);
    let mut above = 0;
    for l in &a.levels {
        // Total water: saturation adjustment moves water between q_v and q_l
        // only; 1e-15 kg/kg is a few ulps.
        assert!((l.qv + l.ql - qt0).abs() < 1e-15, "z = {}", l.z_m);
        if l.z_m < lcl {
            // Dry: θ and q_v are carried unchanged (to rounding).
            assert!(
                (l.theta_k - theta0).abs() < 1e-9,
                "z = {}: θ {}",
                l.z_m,
                l.theta_k
            );
            assert_eq!(l.ql, 0.0);
        } else if l.z_m > lcl + 100.0 {
            above += 1;
            // Condensation heats: θ grows above the LCL.
            assert!(l.theta_k > theta0 && l.ql > 0.0, "z = {}", l.z_m);
        }
    }
    assert!(above > 300, "the curve reaches far above the LCL");
}

#[test]
fn lcl_is_where_the_dry_parcel_reaches_saturation() {
    let env = oun_2011();
    let a = lift_surface_parcel(&env, &LiftOptions::default()).unwrap();
    let lcl = a.lcl.unwrap();
    let s = &a.levels[0];
    let t = s.theta_k * thermo::exner(lcl.p_pa);
    let qs = thermo::saturation_mixing_ratio(t, lcl.p_pa);
    // Bisection to 50 halvings of a 10 m step: relative error ~1e-12.
    assert!((qs - s.qv).abs() < 1e-9, "ωs {qs} vs q_v {}", s.qv);
}

#[test]
fn surface_overrides_move_the_lcl_as_parcel_theory_says() {
    let env = oun_2011();
    let base = lift_surface_parcel(&env, &LiftOptions::default()).unwrap();
    let dry = LiftOptions {
        surface_td_k: Some(273.15 + 11.0),
        ..Default::default()
    };
    let a = lift_surface_parcel(&env, &dry).unwrap();
    // Espy: the LCL rises ~125 m per K of dewpoint depression; 22.2 − 11 = 11.2 K.
    let z = a.lcl.unwrap().z_m;
    assert!((z - 125.0 * 11.2).abs() < 150.0, "LCL {z} m");
    assert!(z > base.lcl.unwrap().z_m);
    let bad = LiftOptions {
        surface_td_k: Some(273.15 + 30.0),
        ..Default::default()
    };
    let msg = lift_surface_parcel(&env, &bad).unwrap_err().to_string();
    assert!(
        msg.contains("surface dewpoint") && msg.contains("up to the surface temperature"),
        "{msg}"
    );
}

#[test]
fn lfc_and_el_bracket_the_buoyant_layer() {
    let env = oun_2011();
    let a = surface_parcel_curve(&env, &LiftOptions::default(), 800).unwrap();
    let (lfc, el) = (a.lfc.unwrap().z_m, a.el.unwrap().z_m);
    assert!(a.lcl.unwrap().z_m <= lfc && lfc < el);
    for l in &a.levels {
        let b = l.tv_k - l.env_tv_k;
        // 30 m margin: the curve is sampled every ~20 m and crossings are interpolated.
        if l.z_m > lfc + 30.0 && l.z_m < el - 30.0 {
            assert!(b > 0.0, "buoyant between LFC and EL, z = {}", l.z_m);
        }
        if l.z_m > el + 30.0 {
            assert!(b < 0.0, "negative above the EL, z = {}", l.z_m);
        }
    }
}

#[test]
fn saturated_surface_air_condenses_at_the_ground() {
    let env = oun_2011();
    let t = env.temperature_k(0.0);
    let opts = LiftOptions {
        surface_td_k: Some(t),
        ..Default::default()
    };
    let a = lift_surface_parcel(&env, &opts).unwrap();
    assert_eq!(a.lcl.unwrap().z_m, 0.0);
    assert!(a.levels[1].ql > 0.0, "condensing from the first step");
}

#[test]
fn without_latent_heat_the_parcel_stays_on_its_dry_adiabat() {
    // α = 0 turns off latent heating: water still condenses but θ cannot
    // change, so T = θ_surface Π(P) at every level (to rounding).
    let env = oun_2011();
    let opts = LiftOptions {
        alpha: 0.0,
        ..Default::default()
    };
    let a = lift_surface_parcel(&env, &opts).unwrap();
    let theta = a.levels[0].theta_k;
    for l in &a.levels {
        let dry = theta * thermo::exner(l.p_pa);
        assert!((l.t_k - dry).abs() < 1e-9, "{} hPa", l.p_pa / 100.0);
    }
    assert!(
        a.levels.last().unwrap().ql > 0.01,
        "most of the vapour condensed"
    );
}

#[test]
fn bad_options_and_heights_are_errors() {
    let env = oun_2011();
    let e = |opts: LiftOptions, h: &[f64]| lift_at(&env, &opts, h).unwrap_err().to_string();
    let msg = e(LiftOptions::default(), &[0.0, 500.0, 100.0]);
    assert!(msg.contains("non-decreasing"), "{msg}");
    let msg = e(LiftOptions::default(), &[f64::NAN]);
    assert!(msg.contains("finite heights"), "{msg}");
    let nan_alpha = LiftOptions {
        alpha: f64::NAN,
        ..Default::default()
    };
    let msg = e(nan_alpha, &[0.0]);
    assert!(
        msg.contains("alpha") && msg.contains("between 0 and 2"),
        "{msg}"
    );
    let hot = LiftOptions {
        surface_t_k: Some(400.0),
        ..Default::default()
    };
    let msg = e(hot, &[0.0]);
    assert!(msg.contains("surface temperature"), "{msg}");
}
