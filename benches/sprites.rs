//! The CPU work of Wang 2003's sprite clouds at the paper's sizes: filling
//! and pruning clouds (5–400 sprites each) and a 200 km overcast deck,
//! sorting its sprites back to front, and shading the 4 corners of every
//! sprite of a 400-sprite cloud and of one 16 km² overcast block; a
//! physics tower (benches/fields/tower.csv) as parcel sprite clouds, and
//! the sunlit shares of their sprites alone.

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use cumulus::methods::sprites::model::order::back_to_front;
use cumulus::methods::sprites::model::parcels::sunlit_shares;
use cumulus::methods::sprites::model::shading::Lighting;
use cumulus::methods::sprites::model::vertices::shade_cloud;
use cumulus::methods::sprites::model::{CloudType, Sprite, parcel_clouds};
use cumulus::physics::cloud_file;
use cumulus::scene::SceneProfile;
use glam::Vec3;

fn sprites(c: &mut Criterion) {
    let overcast =
        SceneProfile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/overcast.toml"))
            .expect("overcast profile loads");
    let cb = CloudType::Cumulonimbus.spec("cb", 0.0, 0.0, 900.0, 1);
    let mut group = c.benchmark_group("sprites");
    group.sample_size(10);
    group.bench_function("fill/cumulonimbus", |b| b.iter(|| black_box(cb.build())));
    group.bench_function("fill/overcast_200km", |b| {
        b.iter(|| black_box(black_box(&overcast).build_sprite_clouds()))
    });

    let clouds = overcast.build_sprite_clouds();
    let all: Vec<Sprite> = clouds
        .iter()
        .flat_map(|c| c.sprites.iter().copied())
        .collect();
    let cam = Vec3::from(overcast.camera.position_m);
    group.bench_function(format!("sort/overcast_{}_sprites", all.len()), |b| {
        b.iter(|| black_box(back_to_front(black_box(&all), cam)))
    });

    let light = Lighting::new(Vec3::new(0.3, 0.2, 0.9), 16.5).expect("valid sun");
    let big = cb.build();
    group.bench_function(
        format!("shade/cumulonimbus_{}_sprites", big.sprites.len()),
        |b| b.iter(|| black_box(shade_cloud(black_box(&big), &light, cam, 1.0))),
    );
    // One 16 km² block of the deck: the clouds whose centre lies in the camera's block.
    let block: Vec<_> = clouds
        .iter()
        .filter(|c| (c.center_m - cam).truncate().abs().max_element() < 2000.0)
        .collect();
    group.bench_function("shade/overcast_block", |b| {
        b.iter(|| {
            for c in &block {
                black_box(shade_cloud(c, &light, cam, 1.0));
            }
        })
    });

    let tower =
        cloud_file::read(&Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/fields/tower.csv"))
            .expect("the tower field loads");
    let sun = Vec3::new(-0.35, -0.17, 0.92);
    let parcel_sprites: Vec<Vec3> = parcel_clouds(&tower, sun)
        .iter()
        .flat_map(|c| c.sprites.iter().map(|s| s.center_m))
        .collect();
    group.bench_function(format!("parcels/tower_{}_parcels", tower.len()), |b| {
        b.iter(|| black_box(parcel_clouds(black_box(&tower), sun)))
    });
    group.bench_function(
        format!("sunlit/tower_{}_sprites", parcel_sprites.len()),
        |b| b.iter(|| black_box(sunlit_shares(black_box(&parcel_sprites), &tower, sun))),
    );
    group.finish();
}

criterion_group!(benches, sprites);
criterion_main!(benches);
