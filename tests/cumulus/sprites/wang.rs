//! Wang 2003's per-vertex mechanisms against hand-computed values: the
//! colour levels, time-of-day tables and biased sun mapping of the artist
//! shading (§5), Listing 1 and the core-first formation (§4), locked facing
//! (§3.3), the impostor ring's thresholds, frames and crossfade (§6.2), the
//! vertex-shading cache (§6.1) and the 16-tile atlas (§3.2).

use cumulus::methods::sprites::model::ColorLevel;
use cumulus::methods::sprites::model::atlas::{self, Atlas, TileKind, tile_kind};
use cumulus::methods::sprites::model::facing::Facing;
use cumulus::methods::sprites::model::formation::{Listing1, ParcelFade, formation_alpha};
use cumulus::methods::sprites::model::impostor::{
    ImpostorRing, RingConfig, ShadeCacheConfig, ShadeStamp, Trigger, in_impostors, sector_of,
};
use cumulus::methods::sprites::model::shading::{
    DirectionalMap, Lighting, TimeTable, default_ambient_table, default_sun_table, level_color,
};
use glam::{Vec3, Vec4};

/// Float comparisons: the formulas are a few f32 operations on values near
/// 1, so 1e-5 is well above rounding and far below any formula error.
fn close(a: f32, b: f32) -> bool {
    (a - b).abs() < 1e-5
}

fn levels() -> Vec<ColorLevel> {
    (0..5)
        .map(|i| ColorLevel {
            height_m: 100.0 * i as f32,
            rgba: [0.2 * i as f32, 0.1, 1.0, 0.5],
        })
        .collect()
}

#[test]
fn colour_levels_interpolate_by_height() {
    // A_V = (200 − 150)/(200 − 100) = 0.5 between levels 1 (0.2) and 2 (0.4).
    let c = level_color(&levels(), 150.0);
    assert!(close(c.x, 0.3) && close(c.w, 0.5), "{c}");
    // A quarter of the way from level 3 to 4: 0.75·0.6 + 0.25·0.8 = 0.65.
    assert!(close(level_color(&levels(), 325.0).x, 0.65));
    assert!(
        close(level_color(&levels(), -10.0).x, 0.0) && close(level_color(&levels(), 900.0).x, 0.8)
    );
}

#[test]
fn time_tables_interpolate_and_wrap_and_default_to_the_frame_s_own_light() {
    let t = TimeTable {
        samples: vec![(6.0, 1.0_f32), (18.0, 0.0)],
    };
    // Midnight lies half-way from 18:00 (0) to 06:00 (1); 03:00 three quarters.
    assert!(close(t.at(0.0), 0.5) && close(t.at(27.0), 0.75) && close(t.at(12.0), 0.5));
    // The defaults are neutral: the frame's sun and sky (the atmosphere
    // model) already carry dawn, dusk and night, which the paper's artist
    // painted into these tables by hand.
    for h in [0.0, 5.5, 6.25, 12.0, 17.75, 23.9] {
        assert!(close(default_ambient_table().at(h), 1.0));
        assert!(close(default_sun_table().at(h), 1.0));
    }
}

#[test]
fn sun_mapping_is_biased_about_the_median() {
    let m = DirectionalMap {
        min: 0.2,
        median: 0.5,
        max: 1.0,
    };
    let got: Vec<f32> = [-1.0, -0.5, 0.0, 0.5, 1.0, 3.0].map(|d| m.map(d)).to_vec();
    for (g, want) in got.iter().zip([0.2, 0.35, 0.5, 0.75, 1.0, 1.0]) {
        assert!(close(*g, want), "{got:?}");
    }
}

#[test]
fn vertex_shade_is_the_level_its_shares_of_the_light_and_formation_alpha() {
    let white = (0..5)
        .map(|i| ColorLevel {
            height_m: i as f32,
            rgba: [1.0, 0.9, 0.8, 0.8],
        })
        .collect::<Vec<_>>();
    let light = Lighting::new(Vec3::X, 12.0).unwrap();
    let g = Vec3::new(0.0, 0.0, 2.0);
    // The sunward vertex gets the whole sun (max 1.0), every vertex the
    // whole sky (neutral tables); alpha is the level's × formation's.
    let v = light.vertex_shade(&white, g + Vec3::X * 10.0, g, 0.5);
    assert!(
        (v.painted - Vec4::new(1.0, 0.9, 0.8, 0.4))
            .abs()
            .max_element()
            < 1e-5,
        "{v:?}"
    );
    assert!(close(v.sun, 1.0) && close(v.sky, 1.0), "{v:?}");
    // Away from the sun: min (0); side-on: median (0.45).
    assert!(light.sun_share(g - Vec3::X, g) < 1e-6);
    assert!(close(light.sun_share(g + Vec3::Y, g), 0.45));
}

#[test]
fn listing_1_alpha_against_hand_values() {
    let mut l = Listing1::new(2.0, 4.0);
    assert!(close(l.alpha(Vec3::ZERO, 100.0), 1.0));
    l.step(1.0); // alpha_at_edges 127.5
    assert!(close(l.alpha(Vec3::new(50.0, 0.0, 0.0), 100.0), 0.75));
    assert!(close(l.alpha(Vec3::new(0.0, 150.0, 0.0), 100.0), 1.0));
    l.step(1.0); // 255
    l.step(1.0); // alpha_of_cloud 255 − 63.75
    assert!(close(l.alpha_of_cloud, 191.25));
    assert!(close(l.alpha(Vec3::new(100.0, 0.0, 0.0), 100.0), 0.75));
    assert!(close(l.alpha(Vec3::ZERO, 100.0), 0.0), "clamped at 0");
}

#[test]
fn formation_fades_the_core_in_first_and_dissipation_the_edges_out_first() {
    // Core reaches full over 60 % of the progress; edges start at 60 % core opacity (p = 0.36).
    assert!(close(formation_alpha(0.3, 0.2), 0.5) && close(formation_alpha(0.3, 0.8), 0.0));
    assert!(close(formation_alpha(0.36, 0.5), 0.6) && close(formation_alpha(0.36, 0.51), 0.0));
    assert!(close(formation_alpha(0.68, 0.9), 0.5) && close(formation_alpha(0.68, 0.1), 1.0));
    assert!(close(formation_alpha(1.0, 1.0), 1.0));
    // Physics: condensation forms at a bounded rate, evaporation reverses.
    let mut f = ParcelFade::new(10.0);
    assert!(close(f.update(1.0, 1.0), 0.1));
    for _ in 0..20 {
        f.update(1.0, 1.0);
    }
    assert!(close(f.progress, 1.0));
    assert!(close(f.update(0.5, 1.0), 0.9));
    assert!(
        close(f.update(f32::NAN, 1.0), 0.8),
        "NaN fill counts as evaporated"
    );
}

#[test]
fn facing_locks_within_half_a_radius_and_fades_by_angle() {
    let mut f = Facing::default();
    let [(n, a), (_, b)] = f.update(Vec3::ZERO, 100.0, Vec3::new(0.0, -50.1, 0.0));
    assert!(f.locked.is_none() && close(a, 1.0) && n.abs_diff_eq(-Vec3::Y, 1e-6));
    assert_eq!(b, 0.0);
    let [(n, a), _] = f.update(Vec3::ZERO, 100.0, Vec3::new(0.0, -49.9, 0.0));
    assert_eq!(f.locked, Some(n));
    assert!(close(a, 1.0));
    // 60° off the locked normal: alpha cos 60° = 0.5, normal unchanged.
    let s = 60.0_f32.to_radians();
    let [(n2, a), (_, b)] = f.update(
        Vec3::ZERO,
        100.0,
        Vec3::new(40.0 * s.sin(), -40.0 * s.cos(), 0.0),
    );
    assert!(n2 == n && close(a, 0.5) && b == 0.0, "{a} {b}");
    let [(_, a), _] = f.update(Vec3::ZERO, 100.0, Vec3::new(40.0, 0.0, 0.0));
    assert!(a.abs() < 1e-6, "edge-on is invisible");
    // Released by a crossfade: at 70 m (40 % of the way from 50 to 100 m),
    // on the far side of the locked plane, the locked quad at |cos 180°|
    // × 0.6, the camera-facing one at 0.4.
    let [(n3, a), (m, b)] = f.update(Vec3::ZERO, 100.0, Vec3::new(0.0, 70.0, 0.0));
    assert!(n3 == n && close(a, 0.6), "{a}");
    assert!(close(b, 0.4) && m.abs_diff_eq(Vec3::Y, 1e-6), "{b}");
    assert!(f.locked.is_some(), "still locked inside the radius");
    f.update(Vec3::ZERO, 100.0, Vec3::new(100.5, 0.0, 0.0));
    assert!(f.locked.is_none(), "unlocks outside the radius");
}

#[test]
fn impostor_ring_triggers_at_15_and_2_percent_and_the_sun_threshold() {
    let cfg = RingConfig {
        radius_m: 10_000.0,
        sun_threshold_rad: 2.0_f32.to_radians(),
        crossfade_s: 1.0,
    };
    let mut ring = ImpostorRing::new(cfg);
    let (c, sun) = (Vec3::new(0.0, 0.0, 1000.0), Vec3::Z);
    assert_eq!(ring.trigger(c, sun), Some(Trigger::First));
    for _ in 0..8 {
        ring.frame(c, sun, 0.1);
    }
    assert_eq!(ring.trigger(c, sun), None);
    assert_eq!(ring.trigger(c + Vec3::new(1499.0, 0.0, 0.0), sun), None);
    assert_eq!(
        ring.trigger(c + Vec3::new(0.0, 1501.0, 0.0), sun),
        Some(Trigger::Horizontal)
    );
    assert_eq!(ring.trigger(c + Vec3::new(0.0, 0.0, 199.0), sun), None);
    assert_eq!(
        ring.trigger(c - Vec3::new(0.0, 0.0, 201.0), sun),
        Some(Trigger::Vertical)
    );
    let tilt = |deg: f32| Vec3::new(deg.to_radians().sin(), 0.0, deg.to_radians().cos());
    assert_eq!(ring.trigger(c, tilt(1.9)), None);
    assert_eq!(ring.trigger(c, tilt(2.1)), Some(Trigger::Sun));
}

#[test]
fn impostor_update_spans_8_frames_then_crossfades() {
    let mut ring = ImpostorRing::new(RingConfig {
        radius_m: 10_000.0,
        sun_threshold_rad: 0.1,
        crossfade_s: 1.0,
    });
    let (c, sun) = (Vec3::ZERO, Vec3::Z);
    for k in 0..8 {
        let f = ring.frame(c, sun, 0.25);
        assert_eq!(f.render, Some((k, c)));
        assert!(close(f.new_weight, if k == 7 { 1.0 } else { 0.0 }) && close(f.old_weight, 0.0));
    }
    assert_eq!(ring.frame(c, sun, 0.25).render, None, "settled");
    let moved = Vec3::new(2000.0, 0.0, 0.0);
    for k in 0..8 {
        let f = ring.frame(moved, sun, 0.25);
        assert_eq!(f.render, Some((k, moved)), "one sector per frame");
        let (old, new) = if k == 7 { (1.0, 0.0) } else { (0.0, 1.0) };
        assert!(
            close(f.old_weight, old) && close(f.new_weight, new),
            "{k}: {f:?}"
        );
    }
    for w in [0.25, 0.5, 0.75, 1.0, 1.0] {
        let f = ring.frame(moved, sun, 0.25);
        assert!(
            close(f.new_weight, w) && close(f.old_weight, 1.0 - w),
            "{f:?}"
        );
    }
}

#[test]
fn impostors_take_far_blocks_within_2000_ft_of_the_camera() {
    let cam = Vec3::new(0.0, 0.0, 1000.0);
    // Block (3, 0) is centred at (14 km, 2 km): 14.1 km from the camera.
    assert!(in_impostors(
        cam,
        10_000.0,
        Vec3::new(14_100.0, 2_100.0, 1609.5)
    ));
    assert!(
        !in_impostors(cam, 10_000.0, Vec3::new(14_100.0, 2_100.0, 1610.0)),
        "above 609.6 m"
    );
    assert!(
        !in_impostors(cam, 10_000.0, Vec3::new(14_100.0, 2_100.0, 390.0)),
        "below 609.6 m"
    );
    assert!(
        !in_impostors(cam, 15_000.0, Vec3::new(14_100.0, 2_100.0, 1000.0)),
        "inside the ring"
    );
    let s = |x, y| sector_of(Vec3::ZERO, Vec3::new(x, y, 0.0));
    assert_eq!(
        [s(1.0, 0.1), s(0.0, 1.0), s(-1.0, -0.01), s(1.0, -0.01)],
        [0, 2, 4, 7]
    );
}

#[test]
fn vertex_cache_recomputes_past_distance_and_time_thresholds() {
    let cfg = ShadeCacheConfig::default();
    let cloud = Vec3::new(0.0, 10_000.0, 0.0);
    let stamp = ShadeStamp {
        time_s: 0.0,
        camera_m: Vec3::ZERO,
    };
    // 10 km: 0.5° of turn = 87.3 m of camera move; 0.1 s/km = 1 s.
    let (d, t) = cfg.thresholds(10_000.0, false);
    assert!((d - 87.266).abs() < 0.01 && close(t, 1.0));
    assert!(!cfg.stale(stamp, 0.5, Vec3::new(87.0, 0.0, 0.0), cloud, false));
    assert!(cfg.stale(stamp, 0.5, Vec3::new(88.0, 0.0, 0.0), cloud, false));
    assert!(!cfg.stale(stamp, 0.99, Vec3::ZERO, cloud, false));
    assert!(cfg.stale(stamp, 1.01, Vec3::ZERO, cloud, false));
    assert!(
        cfg.stale(stamp, 0.51, Vec3::ZERO, cloud, true),
        "twice as often while forming"
    );
}

#[test]
fn atlas_tiles_are_deterministic_distinct_and_of_their_kind() {
    let a = Atlas::generate(128, 7);
    assert_eq!(a.size, 512);
    assert_eq!(a.rgba.len(), 512 * 512 * 4);
    assert_eq!(a, Atlas::generate(128, 7), "same seed, same bytes");
    assert_ne!(a, Atlas::generate(128, 8));
    let tiles: Vec<Vec<u8>> = (0..16).map(|i| a.tile(i)).collect();
    for i in 0..16 {
        let alpha: f32 = tiles[i].chunks(4).map(|p| p[3] as f32).sum::<f32>() / (128.0 * 128.0);
        assert!(alpha > 3.0 && alpha < 200.0, "tile {i} mean alpha {alpha}");
        for j in 0..i {
            // Different by more than a faint dither: mean |Δ| over 2 of 255.
            let d: f32 = tiles[i]
                .iter()
                .zip(&tiles[j])
                .map(|(x, y)| (*x as f32 - *y as f32).abs())
                .sum::<f32>()
                / tiles[i].len() as f32;
            assert!(d > 2.0, "tiles {i} and {j} differ by only {d}");
        }
    }
    let kinds: Vec<TileKind> = (0..16).map(tile_kind).collect();
    assert_eq!(kinds.iter().filter(|k| **k == TileKind::Foggy).count(), 3);
    assert_eq!(kinds.iter().filter(|k| **k == TileKind::Wispy).count(), 6);
    assert_eq!(tile_kind(atlas::FLAT_BOTTOM_TILE), TileKind::FlatBottom);
    // Foggy tiles are bluish grey: blue above red where they are visible.
    for i in atlas::FOGGY_TILES {
        let (r, b) = tiles[i as usize]
            .chunks(4)
            .filter(|p| p[3] > 0)
            .fold((0u64, 0u64), |(r, b), p| (r + p[0] as u64, b + p[2] as u64));
        assert!(b > r, "tile {i}");
    }
    // The flat-bottomed tile is empty below 68 % of its height.
    let flat = &tiles[atlas::FLAT_BOTTOM_TILE as usize];
    assert!(flat[88 * 128 * 4..].chunks(4).all(|p| p[3] == 0));
    assert!(
        flat[60 * 128 * 4..80 * 128 * 4]
            .chunks(4)
            .any(|p| p[3] > 128),
        "a solid body just above the cut"
    );
}

#[test]
fn atlas_writes_a_png_that_reads_back_the_same() {
    let a = Atlas::generate(128, 1);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("atlas.png");
    a.write_png(&path).unwrap();
    let back = image::open(&path).unwrap().to_rgba8();
    assert_eq!((back.width(), back.height()), (512, 512));
    assert_eq!(back.into_raw(), a.rgba);
    // Its parent is a file: the write must fail and name the path.
    let err = a.write_png(&path.join("a.png")).unwrap_err().to_string();
    assert!(err.contains("atlas.png"), "{err}");
}

#[test]
fn sprite_quads_face_the_camera_and_carry_the_shading() {
    use cumulus::methods::sprites::model::vertices::{corners, shade_cloud};
    // A 2 × 4 quad facing a camera on −y, unrotated: x spans ±1, z spans ±2;
    // that camera's right is +x, so bottom-left is (−1, −2), counter-clockwise.
    let q = corners(Vec3::ZERO, -Vec3::Y, 2.0, 4.0, 0.0);
    let want = [
        Vec3::new(-1.0, 0.0, -2.0),
        Vec3::new(1.0, 0.0, -2.0),
        Vec3::new(1.0, 0.0, 2.0),
        Vec3::new(-1.0, 0.0, 2.0),
    ];
    for (a, b) in q.iter().zip(want) {
        assert!(a.abs_diff_eq(b, 1e-5), "{q:?}");
    }
    // Turned 90°: the quad's width now runs vertically.
    let r = corners(Vec3::ZERO, -Vec3::Y, 2.0, 4.0, std::f32::consts::FRAC_PI_2);
    assert!(
        (r[2] - r[0])
            .abs()
            .abs_diff_eq(Vec3::new(4.0, 0.0, 2.0), 1e-5),
        "{r:?}"
    );
    let cloud = cumulus::methods::sprites::model::CloudType::Cirrus
        .spec("c", 0.0, 0.0, 8000.0, 1)
        .build();
    let v = shade_cloud(
        &cloud,
        &Lighting::new(Vec3::Z, 12.0).unwrap(),
        Vec3::ZERO,
        1.0,
    );
    assert_eq!(v.len(), 4 * cloud.sprites.len());
    // Cirrus quads are flat: all four corners at their sprite's height.
    for (s, quad) in cloud.sprites.iter().zip(v.chunks(4)) {
        assert!(
            quad.iter()
                .all(|p| (p.position_m.z - s.center_m.z).abs() < 1e-2)
        );
    }
    // Not yet formed: every vertex transparent.
    assert!(
        shade_cloud(
            &cloud,
            &Lighting::new(Vec3::Z, 12.0).unwrap(),
            Vec3::ZERO,
            0.0
        )
        .iter()
        .all(|p| p.shade.painted.w == 0.0)
    );
}

#[test]
fn a_bad_sun_or_hour_is_an_error_not_a_default() {
    for (sun, hour) in [
        (Vec3::ZERO, 12.0),
        (Vec3::new(f32::NAN, 0.0, 1.0), 12.0),
        (Vec3::Z, f32::INFINITY),
    ] {
        let err = Lighting::new(sun, hour).unwrap_err().to_string();
        assert!(
            err.contains("sun direction") || err.contains("time of day"),
            "{err}"
        );
    }
}
