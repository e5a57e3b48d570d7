//! Parcel theory against MetPy on the two shipped soundings: the LCL within
//! 0.5 hPa and the parcel temperature within 0.5 K at every level up to
//! 300 hPa.
//!
//! Reference numbers come from tests/reference/metpy/parcel_reference.py run
//! with MetPy 1.7.1 (numpy 2.4.6); its output is in parcel_reference.txt
//! beside it. MetPy lifts dry to its `lcl` and then along the pseudo-adiabat
//! (`moist_lapse`, Bolton saturation vapour pressure, c_p = 1004.67); we use
//! Tetens, c_p = 1005.7 and a reversible ascent with dry c_p (see
//! atmosphere::lifting). The tolerances are what is achieved plus a margin,
//! so a change of constants, saturation fit or ascent scheme shows:
//! - LCL: 0.12 hPa (1999) and 0.05 hPa (2011) achieved. Both find where the
//!   dry adiabat meets saturation; only the es fit and c_p differ, which move
//!   the crossing by a tenth of a hPa. 0.5 hPa is a 4× margin and still well
//!   inside the ~5 hPa spread of the approximate LCL formulas.
//! - Parcel T: 0.35 K (1999) and 0.31 K (2011) achieved, worst at 300 hPa:
//!   the es fit and c_p differences accumulate over a 650 hPa moist ascent.
//!   0.5 K keeps a 40 % margin; 1 K (the spread between implementations
//!   that parcel-theory users accept) would hide a doubling of that error.
use std::path::Path;

use cumulus::atmosphere::Sounding;
use cumulus::atmosphere::lifting::{LiftOptions, lift_surface_parcel};
use cumulus::atmosphere::thermo::Thermo;

/// MetPy `lcl` of the surface parcel of oun-2011-05-22-12z.txt. units: hPa
const LCL_2011_HPA: f64 = 948.997;
/// MetPy `parcel_profile` at the sounding's levels: (pressure hPa, parcel T K).
const PROFILE_2011: &[(f64, f64)] = &[
    (966.0, 295.350),
    (953.0, 294.209),
    (936.9, 293.405),
    (925.0, 292.956),
    (904.5, 292.164),
    (896.0, 291.829),
    (890.0, 291.591),
    (886.0, 291.431),
    (873.3, 290.916),
    (873.0, 290.904),
    (850.0, 289.947),
    (846.0, 289.777),
    (813.8, 288.373),
    (802.0, 287.841),
    (785.0, 287.056),
    (757.1, 285.718),
    (730.1, 284.361),
    (700.0, 282.767),
    (653.3, 280.099),
    (639.0, 279.229),
    (606.0, 277.112),
    (605.6, 277.086),
    (584.0, 275.607),
    (582.7, 275.516),
    (582.0, 275.466),
    (577.0, 275.111),
    (571.0, 274.679),
    (561.0, 273.943),
    (560.7, 273.921),
    (539.4, 272.286),
    (539.0, 272.254),
    (500.0, 268.990),
    (478.9, 267.057),
    (453.0, 264.495),
    (443.0, 263.443),
    (406.3, 259.238),
    (400.0, 258.455),
    (389.3, 257.080),
    (327.3, 247.767),
    (313.4, 245.306),
    (300.0, 242.781),
    (286.0, 239.972),
    (250.0, 231.871),
    (249.0, 231.626),
    (220.0, 224.049),
    (210.0, 221.205),
    (200.0, 218.235),
    (197.0, 217.319),
    (196.5, 217.165),
    (190.0, 215.133),
    (181.0, 212.222),
    (173.0, 209.534),
    (159.0, 204.586),
    (155.0, 203.112),
    (154.2, 202.813),
    (150.0, 201.228),
    (148.0, 200.461),
    (146.9, 200.036),
    (146.0, 199.686),
    (142.0, 198.113),
    (140.0, 197.314),
    (137.0, 196.100),
    (133.3, 194.576),
    (127.0, 191.908),
    (126.0, 191.475),
    (120.9, 189.231),
    (111.0, 184.671),
    (109.0, 183.715),
    (104.0, 181.268),
    (100.0, 179.248),
];

/// MetPy `lcl` of the surface parcel of oun-1999-05-04-00z.txt. units: hPa
const LCL_1999_HPA: f64 = 914.622;
/// MetPy `parcel_profile` at the sounding's levels: (pressure hPa, parcel T K).
const PROFILE_1999: &[(f64, f64)] = &[
    (959.0, 295.350),
    (931.3, 292.887),
    (925.0, 292.320),
    (899.3, 290.768),
    (892.0, 290.472),
    (867.9, 289.474),
    (850.0, 288.710),
    (814.0, 287.108),
    (807.9, 286.827),
    (790.0, 285.987),
    (779.2, 285.468),
    (751.3, 284.082),
    (724.3, 282.674),
    (700.0, 281.343),
    (655.0, 278.701),
    (647.5, 278.236),
    (599.4, 275.056),
    (554.7, 271.746),
    (550.0, 271.374),
    (500.0, 267.100),
    (472.5, 264.455),
    (449.0, 261.996),
    (400.0, 256.149),
    (383.7, 253.948),
    (336.4, 246.661),
    (321.9, 244.119),
    (308.1, 241.548),
    (300.0, 239.966),
    (269.0, 233.380),
    (268.6, 233.289),
];

/// How one thermodynamics is held to MetPy's `lcl` and `parcel_profile`.
struct Bounds {
    thermo: Thermo,
    /// Largest |LCL − MetPy's|. units: hPa
    lcl_hpa: f64,
    /// Largest |T − MetPy's| at levels at or below `top_hpa`. units: K
    t_k: f64,
    top_hpa: f64,
}

/// The model's: see the module comment (0.12 hPa and 0.35 K achieved).
const MODEL: Bounds = Bounds {
    thermo: Thermo::Model,
    lcl_hpa: 0.5,
    t_k: 0.5,
    top_hpa: 300.0,
};

/// The forecasters' ascent (`--thermo standard`), at every level to the
/// top of the data: what the model's thermodynamics miss by up to 0.35 K
/// it must match to the solvers' difference. Measured: 0.023 K; 0.05 K
/// keeps a margin yet fails for Tetens instead of Ambaum (0.1–0.3 K), a
/// reversible ascent (≥ 0.3 K aloft) or the model's c_p (~0.1 K). LCL
/// 0.5 hPa: MetPy's is Romps' (2017) formula with moist heat capacities,
/// ours the crossing of the dry adiabat with saturation (0.18 hPa apart).
const STANDARD: Bounds = Bounds {
    thermo: Thermo::Standard,
    lcl_hpa: 0.5,
    t_k: 0.05,
    top_hpa: 0.0,
};

fn check(file: &str, lcl_ref_hpa: f64, profile: &[(f64, f64)], bounds: &Bounds) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("profiles/soundings")
        .join(file);
    let env = Sounding::load(&path)
        .unwrap()
        .to_environment_with(bounds.thermo)
        .unwrap();
    let opts = LiftOptions {
        thermo: bounds.thermo,
        ..Default::default()
    };
    let ascent = lift_surface_parcel(&env, &opts).unwrap();
    let lcl_hpa = ascent.lcl.expect("the surface parcel saturates").p_pa / 100.0;
    let what = format!("{file} ({})", bounds.thermo.key());
    assert!(
        (lcl_hpa - lcl_ref_hpa).abs() < bounds.lcl_hpa,
        "{what}: LCL {lcl_hpa:.2} hPa vs MetPy {lcl_ref_hpa:.2} hPa"
    );
    assert_eq!(
        ascent.levels.len(),
        profile.len(),
        "{what}: one level per row"
    );
    let mut worst = 0.0_f64;
    for (lvl, &(p_hpa, t_ref)) in ascent.levels.iter().zip(profile) {
        assert!(
            (lvl.p_pa / 100.0 - p_hpa).abs() < 1e-6,
            "{what}: level order"
        );
        if p_hpa < bounds.top_hpa {
            continue;
        }
        let d = lvl.t_k - t_ref;
        worst = worst.max(d.abs());
        assert!(
            d.abs() < bounds.t_k,
            "{what}: at {p_hpa} hPa parcel T {:.3} K vs MetPy {t_ref:.3} K",
            lvl.t_k
        );
    }
    eprintln!("{what}: LCL {lcl_hpa:.2} vs {lcl_ref_hpa:.2} hPa, worst |ΔT| {worst:.4} K");
}

#[test]
fn parcel_matches_metpy_on_oun_2011_05_22() {
    check("oun-2011-05-22-12z.txt", LCL_2011_HPA, PROFILE_2011, &MODEL);
}

#[test]
fn parcel_matches_metpy_on_oun_1999_05_04() {
    check("oun-1999-05-04-00z.txt", LCL_1999_HPA, PROFILE_1999, &MODEL);
}

/// MetPy `lfc(which="bottom")` and `el` (temperature-based, pseudo-adiabatic)
/// from parcel_reference.txt. units: hPa
const METPY_LFC_EL_2011_HPA: (f64, f64) = (735.838, 194.832);
/// The 1999 parcel is still buoyant at the sounding's top: no EL. units: hPa
const METPY_LFC_1999_HPA: f64 = 727.055;

#[test]
fn lfc_and_el_differ_from_metpy_only_by_virtual_temperature_and_loading() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/soundings");
    let lift = |f: &str, condensate_loading: bool| {
        let env = Sounding::load(&dir.join(f))
            .unwrap()
            .to_environment()
            .unwrap();
        let opts = LiftOptions {
            condensate_loading,
            ..Default::default()
        };
        lift_surface_parcel(&env, &opts).unwrap()
    };
    let (metpy_lfc, metpy_el) = METPY_LFC_EL_2011_HPA;
    let a = lift("oun-2011-05-22-12z.txt", false);
    let (lfc, el) = (a.lfc.unwrap().p_pa / 100.0, a.el.unwrap().p_pa / 100.0);
    // Under the cap the parcel carries ~12 g/kg of vapour against ~3 g/kg in
    // the dry air above the inversion: its T_v excess is ~1.5 K larger than
    // its T excess, and where the curves cross at a shallow angle (~5 K/km)
    // that moves the LFC down by ~300 m ≈ 30 hPa (765 vs 736 hPa). It can
    // only move down (virtual warming helps the parcel); 40 hPa bounds it.
    assert!(
        lfc > metpy_lfc && lfc < metpy_lfc + 40.0,
        "LFC {lfc:.1} hPa vs MetPy {metpy_lfc:.1}"
    );
    // Near the tropopause vapour is ~0.1 g/kg (0.01 K of T_v): the EL moves
    // only by the constants (Tetens vs Bolton, c_p), ~0.3 K on a crossing
    // that is sharp at the tropopause: 1.4 hPa achieved (193.4 vs 194.8);
    // 2.5 hPa keeps a ~2× margin.
    assert!(
        (el - metpy_el).abs() < 2.5,
        "EL {el:.1} hPa vs MetPy {metpy_el:.1}"
    );
    // With condensate loading the parcel carries ~16 g/kg of liquid near the
    // EL, 3.5 K of T_v; it cools ~9 K/km faster than the nearly isothermal
    // tropopause, so it stops ~0.4 km lower, about 10 hPa (206 vs 195 hPa).
    // Loading can only lower the EL; 40 hPa bounds it.
    let loaded = lift("oun-2011-05-22-12z.txt", true);
    let el_loaded = loaded.el.unwrap().p_pa / 100.0;
    assert!(
        el_loaded > el && el_loaded < metpy_el + 40.0,
        "loaded EL {el_loaded:.1} hPa vs {el:.1} hPa"
    );
    let b = lift("oun-1999-05-04-00z.txt", false);
    let lfc = b.lfc.unwrap().p_pa / 100.0;
    assert!(
        lfc > METPY_LFC_1999_HPA && lfc < METPY_LFC_1999_HPA + 40.0,
        "LFC {lfc:.1} hPa vs MetPy {METPY_LFC_1999_HPA:.1}"
    );
    assert!(b.el.is_none(), "MetPy finds no EL below 268 hPa either");
}

#[test]
fn standard_parcel_matches_metpy_on_both_shipped_soundings() {
    check(
        "oun-2011-05-22-12z.txt",
        LCL_2011_HPA,
        PROFILE_2011,
        &STANDARD,
    );
    check(
        "oun-1999-05-04-00z.txt",
        LCL_1999_HPA,
        PROFILE_1999,
        &STANDARD,
    );
}
