//! The forecasters' indices of `cumulus parcel` (atmosphere::indices)
//! against MetPy 1.7.1 on the seven test soundings, reference values from
//! tests/reference/metpy/diagnostics_reference.txt (lapse rates by hand
//! there). Where MetPy has no value (a surface above 850 hPa for the
//! K-index, winds that end below 6 km, no wind at all) ours must be None
//! too, never a zero.
//!
//! Tolerances: both sides evaluate the same formulas on the same levels;
//! what differs is the reading between levels (ours: θ, q_v and wind
//! linear in height; MetPy: T, Td and wind linear in ln p) and, for the
//! lifted index, the parcel (ours 10 m steps, MetPy's adaptive solver, the
//! same pseudo-adiabat). Each bound is the largest difference measured on
//! the seven soundings rounded up to about twice, so a change of
//! definition (virtual temperature in the LI, specific humidity in PW, a
//! pressure-weighted mean replaced by a plain one in Bunkers, the left
//! mover's helicity) fails.

use cumulus::atmosphere::cape::{ParcelKind, parcel_report};
use cumulus::atmosphere::indices::indices;
use cumulus::atmosphere::lifting::LiftOptions;
use cumulus::atmosphere::thermo::Thermo;

use super::reference::{Reference, standard_env};

/// (reference key, tolerance) of the thermodynamic indices.
const TOLERANCES: [(&str, f64); 5] = [
    // 0.044 K measured (high plains: the parcel's 10 m steps against
    // MetPy's solver, and T at 500 hPa between levels); a virtual LI would
    // be ~0.1–1 K off.
    ("lifted_index", 0.1),
    // 0.028 °C measured: Td at 850/700 hPa read between levels.
    ("k_index", 0.06),
    // < 0.001 mm measured: the same trapezoids; specific humidity instead of
    // mixing ratio would be ~0.3 mm off.
    ("precipitable_water_mm", 0.05),
    // 0.004 K/km measured: T at 3 km between levels.
    ("lapse_0_3km_k_per_km", 0.01),
    ("lapse_700_500_k_per_km", 0.01),
];

fn check(what: &str, ours: Option<f64>, reference: Option<f64>, tol: f64) -> f64 {
    match (ours, reference) {
        (Some(o), Some(r)) => {
            assert!(
                (o - r).abs() <= tol,
                "{what}: {o:.3} vs MetPy {r:.3} (±{tol})"
            );
            (o - r).abs()
        }
        (None, None) => 0.0,
        (o, r) => panic!("{what}: ours {o:?}, MetPy {r:?}"),
    }
}

#[test]
fn indices_match_metpy_on_seven_soundings() {
    let reference = Reference::load();
    let opts = LiftOptions {
        thermo: Thermo::Standard,
        ..Default::default()
    };
    for rel in reference.soundings.iter().map(String::as_str) {
        let (_, env) = standard_env(rel);
        let sb = parcel_report(&env, ParcelKind::Surface, &opts).unwrap();
        let idx = indices(&env, &sb.ascent.levels);
        let ours = [
            idx.lifted_index_k,
            idx.k_index_c,
            Some(idx.precipitable_water_mm),
            idx.lapse_0_3km_k_per_km,
            idx.lapse_700_500_k_per_km,
        ];
        for ((key, tol), o) in TOLERANCES.iter().zip(ours) {
            let d = check(&format!("{rel} {key}"), o, reference.get(rel, key), *tol);
            eprintln!("{rel} {key}: |Δ| {d:.4}");
        }
        let Some(w) = &idx.wind else {
            assert!(
                reference.get(rel, "shear_0_1km_m_s").is_none(),
                "{rel}: MetPy has wind"
            );
            continue;
        };
        let mut worst = [0.0_f64; 3];
        // Shear and storm motion: 0.02 m/s measured (wind between levels);
        // 0.05 m/s. A plain instead of pressure-weighted mean moves
        // Bunkers by tenths of a m/s.
        for (key, o) in [
            ("shear_0_1km_m_s", w.shear_0_1km_m_s),
            ("shear_0_6km_m_s", w.shear_0_6km_m_s),
            ("bunkers_right_u", w.bunkers_right_m_s.map(|m| m[0])),
            ("bunkers_right_v", w.bunkers_right_m_s.map(|m| m[1])),
            ("bunkers_left_u", w.bunkers_left_m_s.map(|m| m[0])),
            ("bunkers_left_v", w.bunkers_left_m_s.map(|m| m[1])),
        ] {
            let d = check(&format!("{rel} {key}"), o, reference.get(rel, key), 0.05);
            worst[usize::from(key.starts_with("bunkers"))] =
                worst[usize::from(key.starts_with("bunkers"))].max(d);
        }
        // Helicity: < 0.05 m²/s² measured (it grows with the storm
        // motion's error times the shear); 1 m²/s², under 1 % of typical
        // values.
        for (key, o) in [
            ("srh_0_1km_m2_s2", w.srh_0_1km_m2_s2),
            ("srh_0_3km_m2_s2", w.srh_0_3km_m2_s2),
        ] {
            worst[2] = worst[2].max(check(
                &format!("{rel} {key}"),
                o,
                reference.get(rel, key),
                1.0,
            ));
        }
        eprintln!(
            "{rel}: worst |Δ| shear {:.2}, Bunkers {:.2} m/s, SRH {:.3} m²/s²",
            worst[0], worst[1], worst[2]
        );
    }
}
