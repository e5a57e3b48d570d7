//! Every shipped scene profile parses, builds its environment, and lifts a
//! surface parcel into the weather situation its comments promise (with
//! LiftOptions::default(): α = 1, no condensate loading, as the physics
//! defaults).

use std::path::{Path, PathBuf};

use cumulus::atmosphere::lifting::{LiftOptions, ParcelAscent, lift_surface_parcel};
use cumulus::atmosphere::{AtmosphereSpec, Environment};
use cumulus::scene::{SceneProfile, SceneSource};

fn profiles_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles")
}

fn load(name: &str) -> (SceneProfile, Environment, ParcelAscent) {
    let path = profiles_dir().join(format!("{name}.toml"));
    let scene = SceneProfile::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let base = SceneSource::File(path.clone()).base_dir();
    let env = scene
        .atmosphere
        .build(&base)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let ascent = lift_surface_parcel(&env, &LiftOptions::default()).unwrap();
    let show = |m: Option<cumulus::atmosphere::lifting::LevelMark>| {
        m.map(|m| format!("{:.0} hPa / {:.0} m", m.p_pa / 100.0, m.z_m))
            .unwrap_or_else(|| "none".into())
    };
    eprintln!(
        "{name}: LCL {}, LFC {}, EL {}",
        show(ascent.lcl),
        show(ascent.lfc),
        show(ascent.el)
    );
    (scene, env, ascent)
}

#[test]
fn every_shipped_profile_parses_and_builds() {
    let mut n = 0;
    for entry in std::fs::read_dir(profiles_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let scene = SceneProfile::load(&path).unwrap_or_else(|e| panic!("{e}"));
            assert!(
                !scene.name.is_empty() && !scene.description.is_empty(),
                "{}",
                path.display()
            );
            scene.atmosphere.validate().unwrap();
            let base = SceneSource::File(path.clone()).base_dir();
            scene
                .atmosphere
                .build(&base)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            n += 1;
        }
    }
    assert!(n >= 4, "expected the four shipped profiles, found {n}");
}

#[test]
fn fair_weather_is_the_default_atmosphere_with_shallow_clouds() {
    let (scene, _, a) = load("fair_weather");
    // The embedded default and AtmosphereSpec::default() describe the same air.
    assert_eq!(scene.atmosphere, AtmosphereSpec::default());
    let lcl = a.lcl.unwrap().z_m;
    assert!((1000.0..=1300.0).contains(&lcl), "LCL {lcl} m");
    // Shallow clouds: buoyant above the LCL but stopped by the inversion.
    let el = a.el.expect("an equilibrium level under the inversion").z_m;
    assert!(a.lfc.is_some() && el < 2500.0, "EL {el} m");
}

#[test]
fn towering_cumulus_reaches_above_8_km() {
    let (_, _, a) = load("towering_cumulus");
    assert!(a.lfc.is_some());
    let el = a.el.expect("an equilibrium level").z_m;
    assert!(el > 8000.0, "EL {el} m");
}

#[test]
fn stable_dry_has_no_free_convection() {
    let (_, _, a) = load("stable_dry");
    assert!(a.lfc.is_none() && a.el.is_none(), "{:?} {:?}", a.lfc, a.el);
    assert!(
        a.levels
            .iter()
            .all(|l| l.tv_k < l.env_tv_k + 1e-9 || l.z_m == 0.0)
    );
}

#[test]
fn high_based_has_a_high_condensation_level() {
    let (_, _, a) = load("high_based");
    let lcl = a.lcl.unwrap().z_m;
    assert!(lcl >= 2500.0, "LCL {lcl} m");
    assert!(
        a.lfc.is_some(),
        "high-based cumulus still need free convection"
    );
}
