//! CAPE and CIN of the surface-based, mixed-layer and most-unstable parcels
//! against MetPy 1.7.1 on the two shipped soundings, and the properties that
//! hold whatever the sounding.
//!
//! Reference numbers come from tests/reference/metpy/cape_reference.py (its
//! output is cape_reference.txt beside it). MetPy lifts along the
//! pseudo-adiabat with Bolton's saturation pressure and integrates
//! trapezoids over the sounding's levels; we lift reversibly with Tetens
//! through ≤ 10 m steps of the piecewise-linear environment (see
//! atmosphere::lifting and atmosphere::cape). The issue asks for agreement
//! within 5 %.

use std::path::Path;

use cumulus::atmosphere::cape::{ParcelKind, parcel_report};
use cumulus::atmosphere::lifting::LiftOptions;
use cumulus::atmosphere::{EnvLevel, Environment, PressureModel, Sounding};

/// MetPy's parcels: (sounding, parcel, start hPa, start T °C, start Td °C,
/// LCL hPa, CAPE J/kg, CIN J/kg), pasted from cape_reference.txt.
type MetpyParcel = (&'static str, &'static str, f64, f64, f64, f64, f64, f64);

#[rustfmt::skip]
const METPY: &[MetpyParcel] = &[
    ("oun-2011-05-22-12z.txt", "sb", 966.00, 22.200, 21.000, 949.00, 3297.2, -128.6),
    ("oun-2011-05-22-12z.txt", "ml", 966.00, 25.501, 20.017, 891.12, 3463.7, -142.1),
    ("oun-2011-05-22-12z.txt", "mu", 886.00, 22.200, 19.000, 844.99, 4630.8, -30.7),
    ("oun-1999-05-04-00z.txt", "sb", 959.00, 22.200, 19.000, 914.62, 2470.5, -41.4),
    ("oun-1999-05-04-00z.txt", "ml", 959.00, 23.728, 17.596, 875.96, 2190.9, -86.7),
    ("oun-1999-05-04-00z.txt", "mu", 959.00, 22.200, 19.000, 914.62, 2470.5, -41.4),
];

fn env_of(name: &str) -> Environment {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("profiles/soundings")
        .join(name);
    Sounding::load(&path).unwrap().to_environment().unwrap()
}

fn kind_of(key: &str) -> ParcelKind {
    ParcelKind::ALL
        .into_iter()
        .find(|k| k.key() == key)
        .unwrap()
}

#[test]
fn cape_and_cin_of_three_parcels_match_metpy_within_5_percent() {
    for &(name, key, p_hpa, t_c, td_c, lcl_hpa, cape, cin) in METPY {
        let env = env_of(name);
        let r = parcel_report(&env, kind_of(key), &LiftOptions::default()).unwrap();
        let what = format!("{name} {key}");
        // The start: the same sounding level (SB, MU) or the same layer mean
        // (ML; 0.1 K covers trapezoids over z instead of p and Tetens vs
        // Bolton in the dewpoint of the mean mixing ratio).
        assert!(
            (r.start_p_pa / 100.0 - p_hpa).abs() < 0.01,
            "{what}: start {} hPa",
            r.start_p_pa / 100.0
        );
        assert!(
            (r.start.t_k - 273.15 - t_c).abs() < 0.1,
            "{what}: start T {}",
            r.start.t_k - 273.15
        );
        assert!(
            (r.start.td_k - 273.15 - td_c).abs() < 0.1,
            "{what}: start Td {}",
            r.start.td_k - 273.15
        );
        // 1 hPa: the spread of LCL formulas (see atmosphere::metpy).
        let lcl = r.ascent.lcl.unwrap().p_pa / 100.0;
        assert!(
            (lcl - lcl_hpa).abs() < 1.0,
            "{what}: LCL {lcl} vs {lcl_hpa} hPa"
        );
        // The 5 %, of the reference value.
        assert!(
            (r.cape_j_per_kg - cape).abs() <= 0.05 * cape,
            "{what}: CAPE {:.1} vs MetPy {cape} J/kg",
            r.cape_j_per_kg
        );
        assert!(
            (r.cin_j_per_kg - cin).abs() <= 0.05 * cin.abs(),
            "{what}: CIN {:.1} vs MetPy {cin} J/kg",
            r.cin_j_per_kg
        );
    }
}

#[test]
fn most_unstable_parcel_is_the_highest_theta_e_and_has_the_most_cape() {
    let env = env_of("oun-2011-05-22-12z.txt");
    let opts = LiftOptions::default();
    let sb = parcel_report(&env, ParcelKind::Surface, &opts).unwrap();
    let mu = parcel_report(&env, ParcelKind::MostUnstable, &opts).unwrap();
    // The 12Z surface is a cool nocturnal layer: the most unstable air sits
    // on top of it, above the ground.
    assert!(mu.start.z_m > 0.0, "MU starts at {} m", mu.start.z_m);
    assert!(mu.cape_j_per_kg > sb.cape_j_per_kg);
    assert!(mu.cin_j_per_kg > sb.cin_j_per_kg, "less inhibition aloft");
    // Its levels begin where it starts.
    assert_eq!(mu.ascent.levels[0].z_m, mu.start.z_m);
}

#[test]
fn stable_dry_profile_has_no_cape_and_no_cin() {
    // θ rising 5 K/km and little vapour: the parcel never becomes buoyant,
    // so there is no LFC and, as in MetPy, both energies are 0.
    let lv = |z_m: f64| EnvLevel {
        z_m,
        theta_k: 290.0 + 0.005 * z_m,
        qv_kg_per_kg: 0.002,
        pressure_pa: None,
    };
    let env = Environment::new(
        vec![lv(0.0), lv(12_000.0)],
        100_000.0,
        PressureModel::Hydrostatic,
    )
    .unwrap();
    for kind in ParcelKind::ALL {
        let r = parcel_report(&env, kind, &LiftOptions::default()).unwrap();
        assert!(r.ascent.lfc.is_none(), "{kind:?}");
        assert_eq!((r.cape_j_per_kg, r.cin_j_per_kg), (0.0, 0.0), "{kind:?}");
    }
}

#[test]
fn warmer_surface_parcel_has_more_cape_and_less_cin() {
    // 3 K more at the surface (same dewpoint) must raise CAPE and shrink
    // CIN: a sign or limit error in the integrals would break this.
    let env = env_of("oun-1999-05-04-00z.txt");
    let base = parcel_report(&env, ParcelKind::Surface, &LiftOptions::default()).unwrap();
    let warm = LiftOptions {
        surface_t_k: Some(env.temperature_k(0.0) + 3.0),
        ..Default::default()
    };
    let w = parcel_report(&env, ParcelKind::Surface, &warm).unwrap();
    assert!(
        w.cape_j_per_kg > base.cape_j_per_kg + 100.0,
        "{} vs {}",
        w.cape_j_per_kg,
        base.cape_j_per_kg
    );
    assert!(w.cin_j_per_kg > base.cin_j_per_kg);
    assert!(base.cin_j_per_kg <= 0.0 && base.cape_j_per_kg >= 0.0);
}
