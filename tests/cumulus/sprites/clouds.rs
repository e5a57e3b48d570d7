//! Wang 2003 sprite clouds on the CPU: seeded filling and pruning of
//! `[[sprite_clouds]]` boxes, physics parcels as sprite clouds, the dozen
//! presets and `[[layers]]`, the shipped profiles, back-to-front order and
//! the paper's cloud block overdraw.

use crate::common;

use std::path::Path;

use cumulus::methods::sprites::model::cloud::{PRUNE_TYPICAL, prune};
use cumulus::methods::sprites::model::order::{back_to_front, block_overdraw, view_overdraw};
use cumulus::methods::sprites::model::{CloudType, Sprite, parcel_cloud};
use cumulus::physics::CloudParcel;
use cumulus::scene::SceneProfile;
use glam::Vec3;

fn sprite(x: f32, y: f32, z: f32, h: f32) -> Sprite {
    Sprite {
        center_m: Vec3::new(x, y, z),
        width_m: h,
        height_m: h,
        rotation_rad: 0.0,
        texture: 10,
        group: 0,
        sunlit: 1.0,
    }
}

fn profile(text: &str) -> Result<SceneProfile, String> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.toml");
    std::fs::write(&path, format!("{text}\n{}", common::ATMOSPHERE_TOML)).unwrap();
    SceneProfile::load(&path)
        .map_err(|e| e.to_string().replace(&path.display().to_string(), "s.toml"))
}

const ONE_BOX: &str = r#"
[[sprite_clouds]]
name = "puff"
type = "cumulus_humilis"
center_m = [0.0, 0.0, 1200.0]
seed = 9
boxes = [
  { min_m = [-300.0, -300.0, -200.0], max_m = [300.0, 300.0, 200.0], count = 60, width_m = [150.0, 200.0], height_m = [150.0, 200.0], textures = [10, 11], group = 0 },
  { min_m = [-200.0, -200.0, -220.0], max_m = [200.0, 200.0, -220.0], density_per_km3 = 1000000.0, width_m = [150.0, 150.0], height_m = [150.0, 150.0], rotation_deg = [-5.0, 5.0], textures = [3], group = 1 },
]
"#;

#[test]
fn authored_boxes_fill_deterministically_within_their_boxes() {
    let a = profile(ONE_BOX).unwrap().build_sprite_clouds();
    let b = profile(ONE_BOX).unwrap().build_sprite_clouds();
    assert_eq!(a, b, "same seed, same sprites");
    let c = &a[0];
    assert!(
        c.sprites.len() >= 5 && c.sprites.len() <= 60 + 100,
        "{}",
        c.sprites.len()
    );
    for s in &c.sprites {
        let p = s.center_m - Vec3::new(0.0, 0.0, 1200.0);
        assert!(
            p.x.abs() <= 300.0 && p.y.abs() <= 300.0 && (-220.0..=200.0).contains(&p.z),
            "{p}"
        );
        if s.group == 1 {
            // The flat-bottom box: its tile and a rotation within ±5°.
            assert_eq!(s.texture, 3);
            assert!(s.rotation_rad.abs() <= 5.0_f32.to_radians() + 1e-6);
        } else {
            assert!(s.texture == 10 || s.texture == 11);
        }
    }
    let mut other = profile(ONE_BOX).unwrap();
    other.sprite_clouds[0].seed = 10;
    assert_ne!(
        other.build_sprite_clouds()[0].sprites,
        c.sprites,
        "the seed matters"
    );
}

#[test]
fn pruning_drops_sprites_closer_than_a_fifth_of_their_height() {
    // Height 100 m → 20 m threshold: 19 m apart is pruned, 21 m is kept.
    let all = vec![
        sprite(0.0, 0.0, 0.0, 100.0),
        sprite(19.0, 0.0, 0.0, 100.0),
        sprite(0.0, 21.0, 0.0, 100.0),
    ];
    let (kept, dropped) = prune(all, PRUNE_TYPICAL);
    assert_eq!(dropped, 1);
    assert_eq!(kept.len(), 2);
    assert_eq!(kept[1].center_m, Vec3::new(0.0, 21.0, 0.0));
}

#[test]
fn bad_sprite_clouds_name_file_line_and_column() {
    let bad_count = ONE_BOX.replace("count = 60", "count = 0");
    let msg = profile(&bad_count).unwrap_err();
    assert!(
        msg.starts_with("s.toml:7:1: invalid sprite_clouds[0].boxes"),
        "{msg}"
    );
    assert!(
        msg.contains("box 0") && msg.contains("count (1–100)"),
        "{msg}"
    );
    let bad_prune = ONE_BOX.replace("seed = 9", "seed = 9\nprune_fraction = nan");
    let msg = profile(&bad_prune).unwrap_err();
    assert!(
        msg.starts_with("s.toml:7:1: invalid sprite_clouds[0].prune_fraction = NaN"),
        "{msg}"
    );
    let bad_tex = ONE_BOX.replace("textures = [3]", "textures = [16]");
    assert!(profile(&bad_tex).unwrap_err().contains("atlas tiles 0–15"));
    let bad_layer = "[[layers]]\ntype = \"stratus\"\ncoverage = 1.5\nextent_m = 1000.0\n";
    let msg = profile(bad_layer).unwrap_err();
    assert!(
        msg.starts_with("s.toml:3:1: invalid layers[0].coverage = 1.5"),
        "{msg}"
    );
    let bad_type = "[[layers]]\ntype = \"mammatus\"\ncoverage = 0.5\nextent_m = 1000.0\n";
    assert!(profile(bad_type).unwrap_err().starts_with("s.toml:2:8:"));
}

#[test]
fn parcels_become_sprite_clouds_by_radius_and_fill() {
    let p = |fill| CloudParcel {
        id: 0,
        center_m: Vec3::new(100.0, 0.0, 1500.0),
        radius_m: 300.0,
        fill,
        cond_plane_z_m: 1300.0,
    };
    let full = parcel_cloud(&p(1.0), 3);
    let thin = parcel_cloud(&p(0.2), 3);
    assert_eq!(full, parcel_cloud(&p(1.0), 3), "deterministic");
    assert!(
        full.sprites.len() > thin.sprites.len(),
        "{} vs {}",
        full.sprites.len(),
        thin.sprites.len()
    );
    for s in &full.sprites {
        // Every sprite lies in the sphere's bounds and above the condensation plane.
        assert!(
            (s.center_m - Vec3::new(100.0, 0.0, 1500.0))
                .abs()
                .max_element()
                <= 300.0
        );
        assert!(s.center_m.z >= 1300.0, "{}", s.center_m.z);
    }
    assert!(
        full.sprites.iter().any(|s| s.texture == 3),
        "flat-bottomed tiles at the base"
    );
}

#[test]
fn every_preset_fills_a_cloud_and_cirrus_is_flat() {
    for t in CloudType::ALL {
        let c = t.spec("x", 0.0, 0.0, t.base_m(), 1).build();
        assert!(c.sprites.len() >= 5, "{t:?}: {}", c.sprites.len());
        assert_eq!(c.levels.len(), 5);
        assert_eq!(t.is_flat(), t == CloudType::Cirrus);
    }
    // Cumulonimbus has a dark base; humilis is nearly white (painted
    // levels, shaders/artist.wgsl).
    let bottom = |t: CloudType| t.levels()[0].rgba[0];
    assert!(bottom(CloudType::Cumulonimbus) < 0.45 && bottom(CloudType::CumulusHumilis) > 0.9);
}

#[test]
fn layers_expand_deterministically_with_their_coverage() {
    let text = "[[layers]]\ntype = \"altocumulus\"\ncoverage = 0.5\nextent_m = 24000.0\nseed = 4\n";
    let s = profile(text).unwrap();
    let a = s.build_sprite_clouds();
    assert_eq!(a, s.build_sprite_clouds());
    // 20 × 20 cells at 50 %: about 200 clouds (binomial sd 10; ±4 sd).
    assert!((160..=240).contains(&a.len()), "{}", a.len());
    assert!(
        a.iter()
            .all(|c| c.kind == CloudType::Altocumulus && (c.center_m.z - 3625.0).abs() < 1.0)
    );
}

#[test]
fn shipped_wang_profiles_load_and_show_what_they_promise() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles");
    let types = SceneProfile::load(&dir.join("cloud_types.toml")).unwrap_or_else(|e| panic!("{e}"));
    let clouds = types.build_sprite_clouds();
    let mut kinds: Vec<_> = clouds.iter().map(|c| c.kind).collect();
    kinds.dedup();
    assert_eq!(
        kinds,
        CloudType::ALL.to_vec(),
        "a dozen types, one cloud each"
    );
    assert!(
        clouds
            .iter()
            .all(|c| !c.name.is_empty() && !c.sprites.is_empty()),
        "labelled, filled"
    );

    let overcast = SceneProfile::load(&dir.join("overcast.toml")).unwrap_or_else(|e| panic!("{e}"));
    let clouds = overcast.build_sprite_clouds();
    let sprites: Vec<Sprite> = clouds
        .iter()
        .flat_map(|c| c.sprites.iter().copied())
        .collect();
    let blocks = block_overdraw(&sprites);
    assert!(blocks.len() >= 20, "{} blocks", blocks.len());
    assert!(
        clouds
            .iter()
            .all(|c| matches!(c.kind, CloudType::Stratus | CloudType::Nimbostratus))
    );
    let cam = Vec3::from(overcast.camera.position_m);
    // Dense: more than the paper's "scattered" 200 % (its overcast is 475 %).
    let od = view_overdraw(&sprites, cam, 20_000.0);
    assert!(od > 2.0, "overdraw {od}");
}

#[test]
fn sprites_sort_back_to_front() {
    let s = vec![
        sprite(0.0, 10.0, 0.0, 1.0),
        sprite(0.0, 30.0, 0.0, 1.0),
        sprite(0.0, -20.0, 0.0, 1.0),
        sprite(5.0, 0.0, 0.0, 1.0),
    ];
    assert_eq!(back_to_front(&s, Vec3::ZERO), vec![1, 2, 0, 3]);
    assert_eq!(
        back_to_front(&s, Vec3::new(0.0, 40.0, 0.0)),
        vec![2, 3, 0, 1]
    );
}

#[test]
fn block_overdraw_is_sprite_area_over_16_km2() {
    // Two 2 km × 2 km sprites in block (0, 0) and one in block (−1, 0):
    // 8 km² / 16 km² = 50 % and 25 %.
    let s = vec![
        sprite(100.0, 100.0, 0.0, 2000.0),
        sprite(3900.0, 10.0, 0.0, 2000.0),
        sprite(-1.0, 10.0, 0.0, 2000.0),
    ];
    let b = block_overdraw(&s);
    assert_eq!(b.len(), 2);
    assert!(
        (b[&(0, 0)] - 0.5).abs() < 1e-6 && (b[&(-1, 0)] - 0.25).abs() < 1e-6,
        "{b:?}"
    );
    assert!((view_overdraw(&s, Vec3::ZERO, 10_000.0) - 0.375).abs() < 1e-6);
}

#[test]
fn only_condensed_parcels_become_clouds() {
    use cumulus::methods::sprites::model::parcel_clouds;
    let p = |id: u64, x: f32, fill| CloudParcel {
        id,
        center_m: Vec3::new(x, 0.0, 1500.0),
        radius_m: 200.0,
        fill,
        cond_plane_z_m: 1400.0,
    };
    let clouds = parcel_clouds(
        &[p(7, 0.0, 0.5), p(8, 1000.0, 0.0), p(9, 2000.0, 1.0)],
        Vec3::Z,
    );
    assert_eq!(clouds.len(), 2, "the dry parcel makes no cloud");
    // Laid out as the parcel alone (its sunlit shares are the cloud's).
    let laid_out: Vec<Sprite> = clouds[1]
        .sprites
        .iter()
        .map(|s| Sprite { sunlit: 1.0, ..*s })
        .collect();
    assert_eq!(
        laid_out,
        parcel_cloud(&p(9, 2000.0, 1.0), 9).sprites,
        "seeded by the parcel's id"
    );
}

/// Issue 13: a parcel's sprites are seeded by its stable id, so removing
/// (evaporating) another parcel earlier in the list, or adding one,
/// leaves them where they were; the same list with the ids swapped
/// moves them (the test can fail).
#[test]
fn removing_an_unrelated_parcel_leaves_a_clouds_sprites_unchanged() {
    use cumulus::methods::sprites::model::parcel_clouds;
    let p = |id: u64, x: f32| CloudParcel {
        id,
        center_m: Vec3::new(x, 0.0, 1500.0),
        radius_m: 250.0,
        fill: 1.0,
        cond_plane_z_m: 1350.0,
    };
    let before = parcel_clouds(&[p(3, 0.0), p(4, 1000.0), p(5, 2000.0)], Vec3::Z);
    let after = parcel_clouds(&[p(4, 1000.0), p(5, 2000.0)], Vec3::Z);
    let grown = parcel_clouds(&[p(11, -900.0), p(4, 1000.0), p(5, 2000.0)], Vec3::Z);
    assert_eq!(before[1], after[0]);
    assert_eq!(before[2], after[1]);
    assert_eq!(before[1], grown[1]);
    let swapped = parcel_clouds(&[p(5, 1000.0)], Vec3::Z);
    assert_ne!(before[1].sprites, swapped[0].sprites);
}

#[test]
fn sprite_scenes_survive_the_windows_save_round_trip() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles");
    for name in ["overcast.toml", "cloud_types.toml"] {
        let s = SceneProfile::load(&dir.join(name)).unwrap();
        let back = SceneProfile::from_toml(&s.to_toml().unwrap(), Path::new(name)).unwrap();
        assert_eq!(back, s, "{name}");
    }
}

#[test]
fn dropped_sprites_are_counted_and_shown() {
    use cumulus::methods::sprites::model::FillCounts;
    // Ten sprites in a 1 m box, 100 m tall: all but the first are within 20 m.
    let text = ONE_BOX.replace(
        "min_m = [-300.0, -300.0, -200.0], max_m = [300.0, 300.0, 200.0], count = 60",
        "min_m = [0.0, 0.0, 0.0], max_m = [1.0, 1.0, 1.0], count = 10",
    );
    let clouds = profile(&text).unwrap().build_sprite_clouds();
    let n = FillCounts::of(&clouds);
    assert_eq!((n.clouds, n.capped), (1, 0));
    // The flat second box has no volume: its density gives the minimum, 1 sprite.
    assert_eq!(
        n.pruned + n.sprites,
        10 + 1,
        "every placed sprite is kept or counted"
    );
    assert!(n.pruned >= 9, "{n}");
    assert!(n.to_string().contains(&format!("{} pruned", n.pruned)));
}
