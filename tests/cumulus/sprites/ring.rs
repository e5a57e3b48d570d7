//! The impostor ring's clouds on the CPU (Wang 2003 §6.2, issue 13): faces
//! take whole 16 km² blocks, and physics clouds beyond the radius go into
//! the ring by the same rules as the scene's, re-rendering it when they
//! condense or evaporate.

use cumulus::methods::sprites::gpu::{SpriteInstance, SpriteScene};
use cumulus::methods::sprites::model::impostor::{
    ImpostorRing, RingConfig, SECTORS, Trigger, block_of,
};
use cumulus::methods::sprites::model::{CloudType, SpriteCloud};
use cumulus::physics::CloudParcel;
use glam::{Vec3, Vec4};

const RADIUS_M: f32 = 10_000.0;

fn centre(s: &SpriteInstance) -> Vec3 {
    (0.5 * (Vec4::from(s.corners[0]) + Vec4::from(s.corners[2]))).truncate()
}

/// Sprites a cloud draws facing `cam` (every sprite of a formed cloud).
fn drawn(cloud: &SpriteCloud, cam: Vec3) -> usize {
    let mut scene = SpriteScene::new(vec![cloud.clone()]);
    scene.frame(&[], Vec3::Z, cam, 0.0).len()
}

#[test]
fn ring_faces_take_whole_blocks() {
    let cam = Vec3::new(0.0, 0.0, 1500.0);
    // A congestus on the 90° border between faces 1 and 2 (block (0, 6)
    // from x = 0 to 4 km, its sprites reaching west of x = 0), and a
    // humilis at 67° (block (2, 6), face 1 alone).
    let border = CloudType::CumulusCongestus
        .spec("", 500.0, 25_000.0, 1200.0, 1)
        .build();
    let inside = CloudType::CumulusHumilis
        .spec("", 10_000.0, 25_000.0, 1300.0, 2)
        .build();
    assert_eq!(block_of(border.center_m), (0, 6));
    assert_eq!(block_of(inside.center_m), (2, 6));
    assert!(border.sprites.iter().any(|s| s.center_m.x < 0.0));
    let (nb, ni) = (drawn(&border, cam), drawn(&inside, cam));
    let scene = SpriteScene::new(vec![border.clone(), inside.clone()]);
    let faces: Vec<Vec<SpriteInstance>> = (0..SECTORS)
        .map(|k| scene.face_instances(cam, RADIUS_M, k, Vec3::Z))
        .collect();
    let counts: Vec<usize> = faces.iter().map(Vec::len).collect();
    // Whole blocks: face 1 holds both clouds complete, face 2 the border
    // block complete (its sprites east of 90° too: the face's projection
    // cuts them at the edge, where face 1's quad takes over).
    assert_eq!(counts, [0, nb + ni, nb, 0, 0, 0, 0, 0]);
    assert!(faces[2].iter().any(|s| centre(s).x > 0.0));
    assert!(
        faces[2]
            .iter()
            .all(|s| (centre(s).x - 500.0).abs() < 3000.0)
    );
    // Back to front from the ring's centre within a face.
    let d: Vec<f32> = faces[1].iter().map(|s| centre(s).distance(cam)).collect();
    assert!(d.windows(2).all(|w| w[0] >= w[1]));
}

fn parcel(id: u64, x: f32, y: f32) -> CloudParcel {
    CloudParcel {
        id,
        center_m: Vec3::new(x, y, 1500.0),
        radius_m: 500.0,
        fill: 1.0,
        cond_plane_z_m: 1200.0,
    }
}

#[test]
fn physics_clouds_beyond_the_radius_go_into_the_ring() {
    let cam = Vec3::new(0.0, 0.0, 1500.0);
    let far = parcel(7, 2000.0, 25_000.0);
    let near = parcel(8, 0.0, 3000.0);
    let parcels = [far, near];
    let mut scene = SpriteScene::default();
    scene.frame(&parcels, Vec3::Z, cam, 0.0);
    assert_eq!(scene.stats.parcel_clouds, 2);
    let all = scene.stats.sprites;

    // A set starts: the far parcel (its block beyond 10 km, at the
    // camera's height) is in the faces, the near one is not.
    scene.ring_started(&parcels, cam, RADIUS_M, Vec3::Z);
    let in_faces: Vec<SpriteInstance> = (0..SECTORS)
        .flat_map(|k| scene.face_instances(cam, RADIUS_M, k, Vec3::Z))
        .collect();
    assert!(!in_faces.is_empty());
    assert!(in_faces.iter().all(|s| centre(s).y > 20_000.0));
    // Until the set completes both are drawn directly; then the far one
    // leaves the direct draw.
    scene.impostored = Some((cam, RADIUS_M));
    scene.frame(&parcels, Vec3::Z, cam, 0.0);
    assert_eq!(scene.stats.parcel_clouds, 2);
    scene.ring_completed();
    let direct = scene.frame(&parcels, Vec3::Z, cam, 0.0);
    assert_eq!(scene.stats.parcel_clouds, 1);
    assert!(direct.iter().all(|s| centre(s).y < 10_000.0));
    assert!(direct.len() < all);

    // Same far clouds: no re-render. One evaporated, one condensed
    // beyond the radius, or the near one moved out: re-render.
    assert!(!scene.ring_changed(&parcels, cam, RADIUS_M, Vec3::Z));
    assert!(scene.ring_changed(&[near], cam, RADIUS_M, Vec3::Z));
    let born = parcel(9, -3000.0, -22_000.0);
    assert!(scene.ring_changed(&[far, near, born], cam, RADIUS_M, Vec3::Z));
    let moved = parcel(8, 0.0, 30_000.0);
    assert!(scene.ring_changed(&[far, moved], cam, RADIUS_M, Vec3::Z));
    // A parcel 2000 ft above the camera stays out of the ring, as the
    // scene's clouds do: no change.
    let high = CloudParcel {
        center_m: Vec3::new(0.0, -25_000.0, 3500.0),
        cond_plane_z_m: 3200.0,
        ..parcel(10, 0.0, 0.0)
    };
    assert!(!scene.ring_changed(&[far, near, high], cam, RADIUS_M, Vec3::Z));
}

#[test]
fn a_changed_field_restarts_a_settled_ring() {
    let mut ring = ImpostorRing::new(RingConfig {
        radius_m: RADIUS_M,
        ..RingConfig::default()
    });
    let (cam, sun) = (Vec3::new(0.0, 0.0, 1500.0), Vec3::Z);
    for _ in 0..SECTORS {
        ring.frame(cam, sun, 0.1);
    }
    assert!(!ring.is_building());
    assert_eq!(ring.trigger(cam, sun), None);
    ring.invalidate();
    assert_eq!(ring.trigger(cam, sun), Some(Trigger::Clouds));
    let f = ring.frame(cam, sun, 0.1);
    assert_eq!(f.render, Some((0, cam)));
    assert!(ring.is_building());
    // Taken into the new set: no second trigger once it completes.
    for _ in 1..SECTORS {
        ring.frame(cam, sun, 0.1);
    }
    assert_eq!(ring.trigger(cam, sun), None);
}
