//! The `sprites` render method on the GPU (lavapipe): physics parcels drawn
//! as sprites against a reference image by FLIP, every cloud-type preset
//! draws something, the terrain hides sprites behind it and not those in
//! front, and the method switches live on one renderer. Skips without an
//! adapter unless CI=true. `UPDATE_REFERENCES=1` rewrites the reference.

mod common;

use std::path::PathBuf;

use cumulus::physics::CloudParcel;
use cumulus::render::headless::Headless;
use cumulus::render::{Camera, FrameInput, GpuContext, RenderConfig, RenderMethod, TerrainConfig};
use cumulus::sprites_model::{CloudType, SpriteCloud};
use glam::Vec3;

/// Mean FLIP allowed against the reference: the frame is deterministic on
/// one adapter (seeded sprites, CPU shading); the margin covers another
/// driver's rasterisation and texture-filtering rounding, well below the
/// 0.1+ a changed sprite layout or shading gives.
const MEAN_FLIP_TOLERANCE: f32 = 0.02;

fn rgb(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}

fn render(
    ctx: &GpuContext,
    cfg: &RenderConfig,
    clouds: Vec<SpriteCloud>,
    camera: Camera,
    parcels: &[CloudParcel],
    (w, h): (u32, u32),
) -> Vec<u8> {
    let mut hl = Headless::new(ctx, cfg, w, h).unwrap();
    hl.renderer.set_sprite_clouds(ctx, clouds).unwrap();
    let input = FrameInput {
        camera,
        parcels,
        sun: cfg.sun(),
        time_s: 0.0,
    };
    hl.render(ctx, &input).unwrap().0
}

/// Pixels whose colour differs by more than 8 levels in some channel.
fn changed(a: &[u8], b: &[u8]) -> usize {
    a.chunks_exact(4)
        .zip(b.chunks_exact(4))
        .filter(|(p, q)| (0..3).any(|c| p[c].abs_diff(q[c]) > 8))
        .count()
}

fn camera(position: Vec3, target: Vec3) -> Camera {
    Camera {
        position,
        target,
        vfov_rad: 50f32.to_radians(),
        near_m: 10.0,
        far_m: 100_000.0,
    }
}

fn no_terrain(method: RenderMethod) -> RenderConfig {
    RenderConfig {
        method,
        terrain: TerrainConfig {
            enabled: false,
            ..TerrainConfig::default()
        },
        ..RenderConfig::default()
    }
}

#[test]
fn physics_parcels_as_sprites_match_the_reference() {
    let Some(ctx) = common::context("sprites reference render") else {
        return;
    };
    let cfg = RenderConfig {
        method: RenderMethod::Sprites,
        ..RenderConfig::default()
    };
    let parcels = cumulus::render::standin::default_field(0.0);
    let cam = Camera::from(&cumulus::render::CameraConfig::default());
    let (w, h) = (128, 72);
    let rgba = render(&ctx, &cfg, Vec::new(), cam, &parcels, (w, h));
    let sky = render(&ctx, &cfg, Vec::new(), cam, &[], (w, h));
    // Seven small cumulus 10+ km away cover a few percent of 128 × 72.
    assert!(
        changed(&rgba, &sky) > 100,
        "the parcels show as sprites: {} pixels",
        changed(&rgba, &sky)
    );

    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/reference/render");
    let path = dir.join("sprites_standin.png");
    if std::env::var("UPDATE_REFERENCES").as_deref() == Ok("1") || !path.exists() {
        assert!(
            path.exists() || std::env::var("CI").as_deref() != Ok("true"),
            "missing reference {}",
            path.display()
        );
        cumulus::output::write_png_atomic(&path, w, h, &rgba).unwrap();
        eprintln!("wrote reference {}", path.display());
        return;
    }
    let reference = image::open(&path).unwrap().into_rgb8();
    let map = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(w, h, &reference),
        nv_flip::FlipImageRgb8::with_data(w, h, &rgb(&rgba)),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    let mean = nv_flip::FlipPool::from_image(&map).mean();
    if mean > MEAN_FLIP_TOLERANCE {
        let actual = dir.join("sprites_standin.actual.png");
        cumulus::output::write_png_atomic(&actual, w, h, &rgba).unwrap();
        panic!(
            "mean FLIP {mean:.4} > {MEAN_FLIP_TOLERANCE} (wrote {})",
            actual.display()
        );
    }
    eprintln!("sprites_standin: mean FLIP {mean:.4}");
}

#[test]
fn every_cloud_type_preset_renders_something() {
    let Some(ctx) = common::context("sprite presets") else {
        return;
    };
    let cfg = no_terrain(RenderMethod::Baked);
    let size = (64, 48);
    let mut failures = Vec::new();
    for (i, kind) in CloudType::ALL.into_iter().enumerate() {
        // 2.5 cloud widths away: the cloud spans about a third of the view.
        let cloud = kind
            .spec("", 0.0, 2.5 * kind.width_m(), kind.base_m(), i as u64 + 1)
            .build();
        // From the ground, looking at the cloud: cirrus (flat) is seen from below.
        let cam = camera(Vec3::new(0.0, 0.0, 20.0), cloud.center_m);
        let with = render(&ctx, &cfg, vec![cloud], cam, &[], size);
        let sky = render(&ctx, &cfg, Vec::new(), cam, &[], size);
        let n = changed(&with, &sky);
        // At least 10 pixels changed: the dense types change hundreds; the
        // faint high ones (cirrocumulus: small sprites at alpha 0.5 over
        // bright sky) about 20; an empty or invisible cloud changes none.
        if n < 10 {
            failures.push(format!("{kind:?}: {n} pixels"));
        }
    }
    assert!(
        failures.is_empty(),
        "presets that drew too little: {failures:?}"
    );
}

#[test]
fn terrain_hides_sprites_behind_it_and_not_in_front() {
    let Some(ctx) = common::context("sprites and terrain") else {
        return;
    };
    let cfg = RenderConfig {
        method: RenderMethod::Sprites,
        terrain: TerrainConfig {
            // A flat plane at z = 0 reaching past the clouds.
            height_scale_m: 0.0,
            extent_m: 60_000.0,
            ..TerrainConfig::default()
        },
        ..RenderConfig::default()
    };
    let cam = camera(Vec3::new(0.0, 0.0, 600.0), Vec3::new(0.0, 2500.0, 0.0));
    let size = (64, 48);
    // Cumulus humilis: 800 m wide, 500 m thick, base at `z`.
    let cloud = |z: f32| {
        CloudType::CumulusHumilis
            .spec("", 0.0, 2500.0, z, 3)
            .build()
    };
    let bare = render(&ctx, &cfg, Vec::new(), cam, &[], size);
    // Under the ground plane: every sprite is behind the terrain.
    let buried = render(&ctx, &cfg, vec![cloud(-1200.0)], cam, &[], size);
    assert_eq!(changed(&buried, &bare), 0, "a buried cloud shows through");
    // Without terrain the same cloud is seen (the test can fail).
    let no_ground = no_terrain(RenderMethod::Sprites);
    let seen = render(&ctx, &no_ground, vec![cloud(-1200.0)], cam, &[], size);
    let sky = render(&ctx, &no_ground, Vec::new(), cam, &[], size);
    // The cloud spans about 16 × 16 of the 64 × 48 pixels.
    assert!(changed(&seen, &sky) > 60, "the cloud is in view");
    // Above the ground, in front of it: blended over the terrain.
    let above = render(&ctx, &cfg, vec![cloud(300.0)], cam, &[], size);
    assert!(changed(&above, &bare) > 60, "a cloud over the ground shows");
}

#[test]
fn the_method_switches_live_on_one_renderer() {
    let Some(ctx) = common::context("live method switch") else {
        return;
    };
    let parcels = cumulus::render::standin::default_field(0.0);
    let cam = Camera::from(&cumulus::render::CameraConfig::default());
    let mut cfg = no_terrain(RenderMethod::Baked);
    let mut hl = Headless::new(&ctx, &cfg, 64, 48).unwrap();
    let input = FrameInput {
        camera: cam,
        parcels: &parcels,
        sun: cfg.sun(),
        time_s: 0.0,
    };
    let mut frames = Vec::new();
    for method in [
        RenderMethod::Baked,
        RenderMethod::Sprites,
        RenderMethod::Baked,
    ] {
        cfg.method = method;
        hl.renderer.set_config(&ctx, &cfg).unwrap();
        let (rgba, t) = hl.render(&ctx, &input).unwrap();
        let names: Vec<&str> = t.passes.iter().map(|(n, _)| n.as_str()).collect();
        match method {
            RenderMethod::Sprites => {
                assert!(
                    names.contains(&"sprites") && !names.contains(&"clouds"),
                    "{names:?}"
                )
            }
            _ => assert!(
                names.contains(&"clouds") && !names.contains(&"sprites"),
                "{names:?}"
            ),
        }
        frames.push(rgba);
    }
    // Back to baked: the same frame as before the switch.
    assert_eq!(changed(&frames[0], &frames[2]), 0);
    assert!(
        changed(&frames[0], &frames[1]) > 50,
        "sprites look different from the march"
    );
}

#[test]
fn atlas_command_writes_the_renderers_sheet() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("atlas.png");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_cumulus"))
        .args(["atlas", "--out"])
        .arg(&out)
        .status()
        .unwrap();
    assert!(status.success());
    let png = image::open(&out).unwrap().into_rgba8();
    let sheet = cumulus::render::sprites::atlas::sheet();
    assert_eq!((png.width(), png.height()), (sheet.size, sheet.size));
    assert_eq!(png.into_raw(), sheet.rgba);
    // A tile smaller than the paper's is refused, naming the flag.
    let bad = std::process::Command::new(env!("CARGO_BIN_EXE_cumulus"))
        .args(["atlas", "--tile", "64", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--tile"));
}

#[test]
fn render_command_draws_the_labelled_cloud_types() {
    if common::context("cloud types render").is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("profiles/cloud_types.toml");
    let render = |extra: &[&str], name: &str| {
        let out = dir.path().join(name);
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_cumulus"))
            .arg("render")
            .arg(&scene)
            .args(["--width", "320", "--height", "180", "--out"])
            .arg(&out)
            .args(extra)
            .output()
            .unwrap();
        let log = String::from_utf8_lossy(&o.stderr).into_owned();
        assert!(o.status.success(), "{log}");
        (image::open(&out).unwrap().into_rgba8().into_raw(), log)
    };
    let (types, log) = render(&[], "types.png");
    assert!(log.contains("12 sprite clouds"), "{log}");
    // The same frame under the sprites method: scene clouds draw either way.
    let (as_sprites, _) = render(&["--method", "sprites"], "sprites.png");
    assert_eq!(changed(&types, &as_sprites), 0);
    // The names are written over the frame (--no-labels leaves them out).
    let (unlabelled, _) = render(&["--no-labels"], "unlabelled.png");
    let n = changed(&types, &unlabelled);
    assert!(n > 100, "{n} label pixels");
}
