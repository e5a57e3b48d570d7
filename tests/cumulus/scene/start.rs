//! Opening on clouds: `[simulation] start_s`, the pre-simulation the window
//! runs before its first frame (live, with a progress display, or at once
//! for captures), Reset back to the start, and the time slider moving the sun.

use std::path::Path;

use cumulus::app::state::Model;
use cumulus::physics::ParcelWorld;
use cumulus::scene::{SceneProfile, SceneSource};

fn shipped(name: &str) -> (SceneProfile, SceneSource) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("profiles")
        .join(name);
    (SceneProfile::load(&path).unwrap(), SceneSource::File(path))
}

/// The world's state, bit for bit.
fn fingerprint(w: &ParcelWorld) -> Vec<u64> {
    let mut v = vec![w.time_s().to_bits()];
    for p in w.parcels() {
        v.extend(p.position_m.to_array().map(f64::to_bits));
        v.push(p.ql_kg_per_kg.to_bits());
    }
    v
}

#[test]
fn bad_start_times_name_the_key_and_the_range() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.toml");
    for bad in ["-5.0", "1e9", "nan"] {
        std::fs::write(
            &path,
            format!("name = \"s\"\n[simulation]\nstart_s = {bad}\n"),
        )
        .unwrap();
        let msg = SceneProfile::load(&path).unwrap_err().to_string();
        assert!(
            msg.starts_with(&format!(
                "{}:3:1: invalid simulation.start_s",
                path.display()
            )) && msg.contains("0 to 86400"),
            "{msg}"
        );
    }
}

#[test]
fn the_live_pre_simulation_lands_on_the_start_like_the_blocking_one() {
    let (mut profile, source) = shipped("fair_weather.toml");
    // Short, so the test is quick; the frames are the same at any length.
    profile.simulation.start_s = 120.0;
    let mut live = Model::new(profile.clone(), source.clone()).unwrap();
    live.begin_warm_up();
    assert_eq!(live.warm_up_progress(), Some(0.0));
    let mut frames = 0;
    while live.warm_up_progress().is_some() {
        live.advance(1.0 / 30.0);
        frames += 1;
        assert!(frames < 10_000, "the pre-simulation never ends");
    }
    assert_eq!(live.world.time_s(), 120.0);

    let mut blocking = Model::new(profile, source).unwrap();
    let mut seen = Vec::new();
    blocking.warm_up_to(120.0, |t| seen.push(t));
    // 2-s frames, the same as `cumulus render --time 120`.
    assert_eq!(seen.len(), 60);
    assert_eq!(fingerprint(&live.world), fingerprint(&blocking.world));

    // Play a little, then Reset: back to the start, through the same frames.
    live.advance(0.1);
    assert!(live.world.time_s() > 120.0);
    live.reset().unwrap();
    assert!(live.warm_up_progress().is_some());
    while live.warm_up_progress().is_some() {
        live.advance(1.0 / 30.0);
    }
    assert_eq!(fingerprint(&live.world), fingerprint(&blocking.world));
}

#[test]
fn the_time_slider_moves_the_sun_and_the_ground_heating() {
    let (profile, source) = shipped("fair_weather.toml");
    let mut m = Model::new(profile, source).unwrap();
    let clock = m
        .clock
        .expect("the shipped scenes set the sun by the clock");
    m.set_time_of_day_h(7.0).unwrap();
    assert!((m.time_of_day_h() - 7.0).abs() < 1e-9);
    let dawn = m.sun();
    m.set_time_of_day_h(12.0).unwrap();
    let noon = m.sun();
    // A summer sun stands far higher at noon than at 7 h, and the drawn sun
    // is the clock's.
    assert!(
        noon.direction.z > dawn.direction.z + 0.4,
        "{dawn:?} {noon:?}"
    );
    let c = m.clock.unwrap();
    assert!((noon.direction - c.position(m.world.time_s()).direction()).length() < 1e-6);
    assert_eq!(
        (c.latitude_deg, c.start_day),
        (clock.latitude_deg, clock.start_day)
    );
    // The ground heats by the same clock's solar time.
    assert!((m.world.config().emission.start_hour - c.solar_time_h(0.0)).abs() < 1e-12);
    // What "save" writes reads back as the same clock.
    let saved = m.edited_profile();
    let back = saved.clock().unwrap().unwrap();
    assert!((back.local_time_h(0.0) - c.local_time_h(0.0)).abs() < 1e-9);
}

#[test]
fn every_shipped_scene_has_clouds_at_its_start_time() {
    // What the window's first frame shows: the scene pre-simulated to
    // start_s with the window's frames (2 s, seed 1). A cloud in view needs
    // at least one condensed parcel; the camera of each scene looks at its
    // whole domain.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles");
    let mut scenes: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 5, "{scenes:?}");
    for path in scenes {
        let name = path.file_name().unwrap().to_str().unwrap().to_string();
        let (profile, source) = shipped(&name);
        if !profile.emission.enabled {
            // Authored scenes (Schpok ellipsoids, Wang sprite clouds and
            // layers) grow no parcels: their clouds exist from t = 0 by
            // construction, so they must hold some.
            assert!(
                !profile.ellipsoids.is_empty()
                    || !profile.sprite_clouds.is_empty()
                    || !profile.layers.is_empty(),
                "{name}: emission off and no authored cloud"
            );
            continue;
        }
        assert!(profile.sun.is_some(), "{name}: no [sun] clock");
        // The clear-sky scene: no parcel is ever buoyant, so it opens at once.
        let clear = name == "stable_dry.toml";
        let mut m = Model::new(profile, source).unwrap();
        let start = m.start_s;
        m.warm_up_to(start, |_| {});
        let d = m.world.diagnostics();
        eprintln!(
            "{name}: t = {start} s, {} condensed of {}",
            d.condensed_parcels, d.parcels
        );
        if clear {
            assert_eq!((start, d.condensed_parcels), (0.0, 0), "{name}");
            continue;
        }
        assert!(
            d.condensed_parcels > 0,
            "{name}: no cloud at its start {start} s"
        );
        assert_eq!(m.parcels.len(), d.condensed_parcels);
        // And in view: some condensed parcel's centre lands inside the
        // frame of the scene's camera (a 16:9 frame, narrower than the
        // window's 3D view, so this is the stricter of the two), in front
        // of it and nearer than its far plane.
        let cam = m.render_camera();
        let (w, h) = (1600, 900);
        let in_view = m.parcels.iter().filter(|p| {
            cam.position.distance(p.center_m) < cam.far_m
                && cam
                    .project_to_pixel(p.center_m, w, h)
                    .is_some_and(|(x, y)| {
                        (0.0..w as f32).contains(&x) && (0.0..h as f32).contains(&y)
                    })
        });
        assert!(
            in_view.count() > 0,
            "{name}: no cloud in the camera's view at the start"
        );
    }
}

#[test]
fn the_live_window_shows_clouds_only_from_the_start_time() {
    // The fair-weather scene at its own start time: clouds form during the
    // pre-simulation, but the window draws none until the start is reached,
    // so its first cloudy frame is the start state (issue 10, item 8).
    let (profile, source) = shipped("fair_weather.toml");
    let mut live = Model::new(profile, source).unwrap();
    live.begin_warm_up();
    let mut condensed_while_warming = false;
    while live.warm_up_progress().is_some() {
        live.advance(1.0 / 30.0);
        if live.warm_up_progress().is_some() {
            condensed_while_warming |= live.world.diagnostics().condensed_parcels > 0;
            assert!(
                live.parcels.is_empty(),
                "clouds drawn before the start time"
            );
        }
    }
    assert!(
        condensed_while_warming,
        "no cloud formed before the start: the test shows nothing"
    );
    assert_eq!(live.world.time_s(), live.start_s);
    let mut now = Vec::new();
    live.world.cloud_parcels(&mut now);
    assert!(!now.is_empty());
    assert_eq!(live.parcels.len(), now.len(), "the start's clouds drawn");
}
