//! Editing the profile through the same functions the window's panel calls
//! (`app::profile_edit`) changes the lifted parcel's curve the way parcel
//! theory says, and reaches the running simulation at once.

use cumulus::app::profile_edit::{self as pe, ProfileCurve, ProfileEditor, dewpoint_c};
use cumulus::atmosphere::{AtmospherePoint, AtmosphereSpec, thermo};

fn pt(z_m: f64, t_c: f64, td_c: f64) -> AtmospherePoint {
    AtmospherePoint {
        z_m,
        t_c,
        td_c: Some(td_c),
        rh_percent: None,
    }
}

/// Fair-weather cumulus: a dry-adiabatic mixed layer, a conditionally
/// unstable cloud layer (6.5 K/km, steeper than the moist adiabat) and a
/// 7 K inversion at 2.6–2.8 km that caps the clouds.
fn capped() -> ProfileEditor {
    ProfileEditor::new(AtmosphereSpec {
        points: vec![
            pt(0.0, 28.0, 18.0),
            pt(1200.0, 16.2, 13.0),
            pt(2600.0, 7.1, 0.0),
            pt(2800.0, 14.0, -12.0),
            pt(8000.0, -19.8, -45.0),
        ],
        ..AtmosphereSpec::default()
    })
    .expect("valid profile")
}

#[test]
fn capped_profile_has_cloud_layer_between_lcl_and_inversion() {
    let ed = capped();
    let lcl = ed.lcl_m().expect("moist surface air saturates");
    let el = ed.el_m().expect("the inversion stops the parcel");
    // Espy's rule of thumb, 125 m per K of dewpoint depression (10 K here),
    // holds to ~10% for a well-mixed layer.
    assert!((lcl - 1250.0).abs() < 150.0, "LCL {lcl}");
    // The parcel is buoyant in the 8 K/km layer and stops within the inversion.
    assert!(
        ed.lfc_m().is_some_and(|lfc| lfc < 2600.0),
        "{:?}",
        ed.lfc_m()
    );
    assert!((2600.0..2900.0).contains(&el), "EL {el}");
}

#[test]
fn wetter_surface_lowers_the_lcl_and_drier_raises_it() {
    let mut ed = capped();
    let lcl0 = ed.lcl_m().unwrap();
    let q0 = ed.surface_mixing_ratio();
    pe::set_surface_mixing_ratio(&mut ed, q0 + 0.002).unwrap();
    let wetter = ed.lcl_m().unwrap();
    pe::set_surface_mixing_ratio(&mut ed, q0 - 0.002).unwrap();
    let drier = ed.lcl_m().unwrap();
    // ±2 g/kg moves the dewpoint by ~2.5 K: ~300 m of LCL by Espy's rule.
    assert!(wetter < lcl0 - 150.0, "{wetter} vs {lcl0}");
    assert!(drier > lcl0 + 150.0, "{drier} vs {lcl0}");

    // Dragging the surface dewpoint point does the same.
    let mut ed = capped();
    pe::move_point(&mut ed, ProfileCurve::Dewpoint, 0, 0.0, 20.0).unwrap();
    assert!(ed.lcl_m().unwrap() < lcl0 - 150.0);
}

#[test]
fn condensation_level_handle_puts_the_lcl_where_asked() {
    let mut ed = capped();
    for target in [600.0, 1000.0, 1800.0] {
        pe::set_condensation_level(&mut ed, target).unwrap();
        let lcl = ed.lcl_m().unwrap();
        // The handle inverts the same saturation condition the curve
        // bisects; what is left is the pressure's dependence on humidity,
        // iterated three times: well under a metre.
        assert!((lcl - target).abs() < 1.0, "asked {target}, got {lcl}");
        // The surface temperature is untouched: only the humidity moved.
        assert_eq!(ed.points()[0].t_c, 28.0);
    }
    // Above saturation at the surface is refused, not clamped silently.
    let qs = thermo::saturation_mixing_ratio(28.0 + 273.15, 100_000.0);
    assert!(pe::set_surface_mixing_ratio(&mut ed, qs * 1.1).is_err());
}

#[test]
fn raising_the_inversion_raises_the_equilibrium_level() {
    let mut ed = capped();
    let el0 = ed.el_m().unwrap();
    // Drag the inversion base and top 600 m up, keeping the cloud layer's
    // 6.5 K/km lapse rate below it (top first so the order is kept).
    pe::move_point(&mut ed, ProfileCurve::Temperature, 3, 3400.0, 10.1).unwrap();
    pe::move_point(&mut ed, ProfileCurve::Temperature, 2, 3200.0, 3.2).unwrap();
    let el1 = ed.el_m().unwrap();
    // The parcel now rises through 600 m more of the unstable layer.
    assert!(el1 > el0 + 400.0, "{el1} vs {el0}");

    // Lowering the inversion by 600 m lowers it.
    let mut ed = capped();
    pe::move_point(&mut ed, ProfileCurve::Temperature, 2, 2000.0, 11.0).unwrap();
    pe::move_point(&mut ed, ProfileCurve::Temperature, 3, 2200.0, 17.9).unwrap();
    let el2 = ed.el_m().unwrap();
    assert!(el2 < el0 - 400.0, "{el2} vs {el0}");
}

#[test]
fn added_point_does_not_change_the_environment_until_dragged() {
    let mut ed = capped();
    let env0 = ed.environment().clone();
    let i = pe::add_point(&mut ed, 2000.0).unwrap();
    assert_eq!(i, 2);
    for z in [500.0, 2000.0, 2300.0, 5000.0] {
        // Interpolating T and Td at the new height leaves θ within rounding
        // of the piecewise-linear-in-T vs -in-θ difference (< 0.05 K).
        assert!(
            (ed.environment().theta_k(z) - env0.theta_k(z)).abs() < 0.05,
            "z {z}"
        );
    }
    pe::move_point(&mut ed, ProfileCurve::Temperature, i, 2000.0, 20.0).unwrap();
    assert!(ed.environment().theta_k(2000.0) > env0.theta_k(2000.0) + 5.0);
    pe::remove_point(&mut ed, i).unwrap();
    assert_eq!(ed.points().len(), 5);
    // The surface level cannot go and neither can the last two levels.
    assert!(pe::remove_point(&mut ed, 0).is_err());
}

#[test]
fn points_round_trip_through_the_environment() {
    // T and Td read back from the environment the edited points built match
    // the points: the diagram and the simulation see the same atmosphere.
    let mut ed = capped();
    pe::move_point(&mut ed, ProfileCurve::Temperature, 2, 2500.0, 6.0).unwrap();
    pe::set_condensation_level(&mut ed, 900.0).unwrap();
    let env = ed.environment();
    for p in ed.points() {
        // AtmosphereSpec::build integrates pressure with the environment's
        // own hydrostatic law, so the only error is the environment's 10 m
        // pressure table: well under 0.01 K.
        assert!(
            (env.temperature_k(p.z_m) - 273.15 - p.t_c).abs() < 0.01,
            "{p:?}"
        );
        assert!(
            (env.dewpoint_k(p.z_m) - 273.15 - dewpoint_c(p)).abs() < 0.01,
            "{p:?}"
        );
    }
}

#[test]
fn editor_opens_every_shipped_profile() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let (profile, source) = cumulus::scene::load_scene(Some(&path)).unwrap();
        let ed = ProfileEditor::from_spec(&profile.atmosphere, &source.base_dir())
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        // Every point is editable: it has a dewpoint at most its temperature.
        assert!(
            ed.points()
                .iter()
                .all(|p| p.td_c.is_some_and(|td| td <= p.t_c))
        );
        // The editor keeps the scene's surface air, so its parcel is the
        // scene's parcel (a sampled sounding keeps the surface level exactly).
        let env = profile.atmosphere.build(&source.base_dir()).unwrap();
        // Sounding surfaces are sampled to 0.1 K (inline_points_from rounds).
        assert!((ed.environment().temperature_k(0.0) - env.temperature_k(0.0)).abs() < 0.06);
        n += 1;
    }
    assert!(n >= 4, "found {n} profiles");
}

#[test]
fn edits_reach_the_running_simulation_at_once() {
    let (profile, source) = cumulus::scene::load_scene(None).unwrap();
    let mut m = cumulus::app::state::Model::new(profile, source).unwrap();
    m.advance(0.1);
    let i = 1;
    let z = m.editor.points()[i].z_m;
    let t = m.editor.points()[i].t_c;
    // The editor's point starts where the scene's profile put it.
    let theta0 = m.world.environment().theta_k(z);
    pe::move_point(&mut m.editor, ProfileCurve::Temperature, i, z, t + 3.0).unwrap();
    // The next frame hands the edited environment to the world before stepping.
    m.advance(0.1);
    let theta1 = m.world.environment().theta_k(z);
    // 3 K warmer at the same pressure is 3·(P0/P)^κ K more θ (> 3 K aloft);
    // the tolerance covers the small pressure change from the warmer layer.
    assert!(
        (theta1 - theta0 - 3.0).abs() < 0.5 && theta1 > theta0 + 2.9,
        "{theta0} → {theta1}"
    );
    assert_eq!(
        m.world.environment().theta_k(z),
        m.editor.environment().theta_k(z)
    );
}

#[test]
fn a_sounding_becomes_editable_points_with_the_same_surface_parcel() {
    let base = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles");
    let spec = AtmosphereSpec {
        sounding: Some("soundings/oun-2011-05-22-12z.txt".into()),
        points: vec![],
        surface_pressure_hpa: None,
        pressure: None,
    };
    let ed = ProfileEditor::from_spec(&spec, &base).unwrap();
    assert_eq!(ed.points().len(), pe::SOUNDING_POINTS);
    let env = spec.build(&base).unwrap();
    let theirs = cumulus::atmosphere::lifting::lift_surface_parcel(&env, &Default::default())
        .unwrap()
        .lcl
        .unwrap()
        .z_m;
    let ours = ed.lcl_m().unwrap();
    println!("sounding LCL {theirs:.1} m, editor LCL {ours:.1} m");
    // Same surface air (rounded to 0.1 K: ~12 m of LCL by Espy's 125 m/K)
    // and hydrostatic instead of observed pressure (a few hPa aloft: ~10 m).
    assert!((ours - theirs).abs() < 40.0, "{ours} vs {theirs}");
}

#[test]
fn saved_scene_loads_back_with_the_edits() {
    let (profile, source) = cumulus::scene::load_scene(None).unwrap();
    let mut m = cumulus::app::state::Model::new(profile, source).unwrap();
    pe::set_condensation_level(&mut m.editor, 800.0).unwrap();
    pe::add_point(&mut m.editor, 3000.0).unwrap();
    let mut cfg = m.world_cfg.clone();
    cfg.emission.rate_per_km2_per_h = 77.0;
    m.wind.speed_m_s = 6.0;
    m.wind.from_deg = 225.0;
    m.apply_world_config(cfg).unwrap();
    m.render_cfg.normals = !m.render_cfg.normals;
    m.camera.orbit(120.0, 10.0);

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("edited.toml");
    m.save(&path).unwrap();
    let mut loaded = cumulus::app::state::Model::new(
        cumulus::scene::SceneProfile::load(&path).unwrap(),
        cumulus::scene::SceneSource::File(path.clone()),
    )
    .unwrap();
    assert_eq!(loaded.editor.points(), m.editor.points());
    // Same points, same thermodynamics: the LCL comes back where it was set
    // (TOML keeps f64 exactly, so this is exact up to the build's rounding).
    assert!((loaded.editor.lcl_m().unwrap() - 800.0).abs() < 1.0);
    assert_eq!(loaded.world_cfg, m.world_cfg);
    assert_eq!(loaded.render_cfg, m.render_cfg);
    let w = loaded
        .world_cfg
        .wind
        .as_ref()
        .expect("the moved handle writes [wind]")
        .aloft_m_s;
    // Wind from the south-west blows towards +x and +y.
    assert!(w[0] > 4.2 && w[1] > 4.2, "{w:?}");
    assert!((loaded.wind.from_deg - 225.0).abs() < 1e-9);
    // The saved view is the view the user had (f32 round trip of the eye).
    assert!((loaded.camera.eye_m() - m.camera.eye_m()).length() < 0.1);

    // Loading a broken file is refused with the file named and changes nothing.
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "name = \"x\"\n[atmosphere]\nbogus = 1\n").unwrap();
    let before = loaded.editor.points().to_vec();
    let err = loaded.load(&bad).unwrap_err().to_string();
    assert!(err.contains("bad.toml:3:1"), "{err}");
    assert_eq!(loaded.editor.points(), &before[..]);
}

/// `cumulus parcel`'s default lift: the forecasters' standard
/// thermodynamics, which the panel's CAPE and CIN use too.
fn standard() -> cumulus::atmosphere::lifting::LiftOptions {
    cumulus::atmosphere::lifting::LiftOptions {
        thermo: cumulus::atmosphere::thermo::Thermo::Standard,
        ..Default::default()
    }
}

#[test]
fn mixed_layer_and_most_unstable_energies_follow_every_edit() {
    // The panel lists sb, ml and mu: each must be `cumulus parcel`'s value
    // for the edited environment, recomputed by each edit (exact equality:
    // the same function of the same environment).
    use cumulus::atmosphere::cape::{ParcelKind, parcel_report};
    let fresh = |ed: &ProfileEditor| {
        ParcelKind::ALL.map(|k| {
            let r = parcel_report(ed.environment(), k, &standard()).unwrap();
            (k, r.cape_j_per_kg, r.cin_j_per_kg)
        })
    };
    let mut ed = capped();
    let before = ed.parcel_energies();
    assert_eq!(before, fresh(&ed));
    assert_eq!((before[0].1, before[0].2), ed.cape_cin_j_per_kg());
    // Moisten the lowest 1.2 km (the two lowest points, both within the
    // mixed layer's 100 hPa): every parcel's source air gains latent heat.
    for i in 0..ed.points().len() {
        let p = ed.points()[i];
        if p.z_m <= 1200.0 {
            let td = dewpoint_c(&p);
            pe::move_point(&mut ed, ProfileCurve::Dewpoint, i, p.z_m, td + 1.0).unwrap();
        }
    }
    let after = ed.parcel_energies();
    assert_eq!(after, fresh(&ed));
    for (b, a) in before.iter().zip(&after) {
        assert!(a.1 > b.1, "{} CAPE {} → {}", b.0.key(), b.1, a.1);
    }
}

#[test]
fn cape_and_cin_follow_every_edit() {
    // The panel shows the editor's CAPE/CIN: `cumulus parcel`'s surface-based
    // values of the edited environment, recomputed by each edit.
    let fresh = |ed: &ProfileEditor| {
        let r = cumulus::atmosphere::cape::parcel_report(
            ed.environment(),
            cumulus::atmosphere::cape::ParcelKind::Surface,
            &standard(),
        )
        .unwrap();
        (r.cape_j_per_kg, r.cin_j_per_kg)
    };
    let mut ed = capped();
    let before = ed.cape_cin_j_per_kg();
    assert_eq!(before, fresh(&ed));
    assert!(before.0 > 0.0, "the cloud layer is conditionally unstable");
    // A 1 K moister surface (dewpoint 18 → 19 °C) gives the parcel more
    // latent heat: more CAPE, less CIN.
    let td0 = dewpoint_c(&ed.points()[0]);
    pe::move_point(&mut ed, ProfileCurve::Dewpoint, 0, 0.0, td0 + 1.0).unwrap();
    let after = ed.cape_cin_j_per_kg();
    assert_eq!(after, fresh(&ed));
    assert!(after.0 > before.0, "CAPE {before:?} → {after:?}");
}

#[test]
fn editor_keeps_the_soundings_wind_through_edits() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/soundings");
    let spec = AtmosphereSpec {
        sounding: Some(dir.join("oun-2011-05-22-12z.txt")),
        points: Vec::new(),
        ..AtmosphereSpec::default()
    };
    let mut ed = ProfileEditor::from_spec(&spec, &dir).unwrap();
    let w0 = ed
        .environment()
        .wind()
        .expect("the sounding has DRCT/SKNT")
        .clone();
    let p = ed.points()[1];
    pe::move_point(&mut ed, ProfileCurve::Temperature, 1, p.z_m, p.t_c + 1.0).unwrap();
    assert_eq!(ed.environment().wind(), Some(&w0));
}

#[test]
fn skew_t_view_maps_back_to_the_same_point() {
    use cumulus::app::skewt_panel::{ProfileView, from_plot, to_plot};
    let ed = capped();
    let env = ed.environment();
    for (t, z) in [(28.0, 0.0), (10.0, 1500.0), (-20.0, 7900.0)] {
        let [x, y] = to_plot(ProfileView::SkewT, env, t, z);
        let (t2, z2) = from_plot(ProfileView::SkewT, env, x, y);
        // Bisection of P(z) to far below a centimetre.
        assert!(
            (t2 - t).abs() < 1e-6 && (z2 - z).abs() < 0.01,
            "{t} {z} → {t2} {z2}"
        );
        // Isotherms lean right: the same T higher up is further right.
        if z > 0.0 {
            assert!(x > t);
        }
    }
    assert_eq!(
        to_plot(ProfileView::HeightTemperature, env, 5.0, 900.0),
        [5.0, 900.0]
    );
}
