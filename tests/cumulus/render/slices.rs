//! The `slices` render method (Schpok 2003) on lavapipe: the WGSL structs
//! against the Rust uniforms, the qualitative controls' independence
//! through `--set` (Quality does not change how much cloud covers the sky,
//! Opacity does not change the silhouette), a reference render by FLIP,
//! the physics' parcels drawn by slicing, and a saved scene reloading to an
//! identical render. Without any adapter the GPU tests fail (see
//! `common::gpu` for the opt-in skip).

use crate::common;

use std::path::{Path, PathBuf};

use cumulus::config::{Camera, RenderConfig, RenderMethod};
use cumulus::methods::standin;
use cumulus::render::headless::Headless;
use cumulus::render::{FrameInput, GpuContext};
use cumulus::scene::{SceneProfile, load_scene_with};

/// Small frames: lavapipe fills 128 planes of the whole cloud per pixel.
const SIZE: (u32, u32) = (192, 108);
/// Mean FLIP allowed against the reference: as render::renderer (same
/// driver gives ~0; float ordering across Mesa/LLVM versions a little;
/// a moved or missing cloud scores far above it).
const MEAN_FLIP_TOLERANCE: f32 = 0.02;

fn authored_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/authored.toml")
}

/// The authored scene with `--set` overrides (terrain off unless asked,
/// so every pixel's background is the sky).
fn authored(sets: &[&str]) -> SceneProfile {
    let mut all = vec!["render.terrain.enabled=false".to_string()];
    all.extend(sets.iter().map(|s| s.to_string()));
    load_scene_with(Some(&authored_path()), &all).unwrap().0
}

/// The scene's authored clouds at its start time from its camera under
/// `cfg`, `size` pixels: the renderer after the frame (its HDR image) and
/// the 8-bit frame.
pub(super) fn render_at(
    ctx: &GpuContext,
    scene: &SceneProfile,
    cfg: &RenderConfig,
    size: (u32, u32),
) -> (Headless, Vec<u8>) {
    let mut hl = Headless::new(ctx, cfg, size.0, size.1).unwrap();
    // Some callers read the HDR scene back.
    hl.renderer.set_scene_whole(true);
    hl.renderer
        .set_authored(&scene.ellipsoids, &scene.particles);
    let input = FrameInput {
        camera: Camera::from(&scene.camera),
        parcels: &[],
        sun: cfg.sun(),
        time_s: scene.simulation.start_s as f32,
    };
    let img = hl.render(ctx, &input).unwrap().0;
    (hl, img)
}

fn render_scene(ctx: &GpuContext, scene: &SceneProfile, cfg: &RenderConfig) -> Vec<u8> {
    render_at(ctx, scene, cfg, SIZE).1
}

fn render(ctx: &GpuContext, scene: &SceneProfile) -> Vec<u8> {
    render_scene(ctx, scene, &scene.render)
}

/// The same scene with no clouds: the sky behind them.
fn sky(ctx: &GpuContext, scene: &SceneProfile) -> Vec<u8> {
    let cfg = RenderConfig {
        clouds: false,
        ..scene.render.clone()
    };
    render_scene(ctx, scene, &cfg)
}

/// Per pixel, the largest channel change the clouds make over the sky.
fn change(img: &[u8], sky: &[u8]) -> Vec<u8> {
    img.chunks_exact(4)
        .zip(sky.chunks_exact(4))
        .map(|(a, b)| (0..3).map(|k| a[k].abs_diff(b[k])).max().unwrap())
        .collect()
}

/// Pixels whose colour the clouds change by more than `threshold`/255.
fn silhouette(img: &[u8], sky: &[u8], threshold: u8) -> usize {
    change(img, sky).iter().filter(|d| **d > threshold).count()
}

/// Mean brightening of the frame over the sky: alpha × (cloud − sky) per
/// pixel, averaged. The cloud colour does not depend on Quality (the
/// shadow is compensated too), so this is the mean alpha up to a factor.
fn mean_change(img: &[u8], sky: &[u8]) -> f64 {
    let c = change(img, sky);
    c.iter().map(|d| *d as f64).sum::<f64>() / c.len() as f64
}

fn context() -> Option<GpuContext> {
    common::context("GPU slices test")
}

#[test]
fn the_field_index_gives_the_field() {
    use cumulus::methods::slices::model::ellipsoid::FieldIndex;
    use cumulus::methods::slices::model::{cumulonimbus, field_at, states_at};
    use glam::Vec3;
    let mut ellipsoids = cumulonimbus([0.0, 0.0, 1500.0], 9500.0);
    // A rotated one and many small overlapping spheres, like parcels.
    ellipsoids.push(cumulus::methods::slices::model::Ellipsoid {
        centre_m: [3000.0, 1000.0, 2000.0],
        radii_m: [1500.0, 400.0, 300.0],
        rotation_deg: [10.0, 20.0, 35.0],
        ..Default::default()
    });
    for i in 0..60 {
        let f = i as f32;
        ellipsoids.push(cumulus::methods::slices::model::Ellipsoid {
            centre_m: [
                (f * 97.0) % 4000.0 - 2000.0,
                (f * 53.0) % 3000.0,
                1500.0 + (f * 31.0) % 800.0,
            ],
            radii_m: [300.0; 3],
            ..Default::default()
        });
    }
    let states = states_at(&ellipsoids, &Default::default(), 900.0);
    let index = FieldIndex::new(&states);
    let mut worst = 0.0f32;
    for i in 0..20_000 {
        let f = i as f32;
        let p = Vec3::new(
            (f * 7.31).sin() * 6000.0,
            (f * 3.17).cos() * 5000.0 + 1000.0,
            (f * 1.13).sin().abs() * 12000.0,
        );
        worst = worst.max((index.field(p) - field_at(&states, p)).abs());
    }
    // Float rounding at a box's face only: the blend there is ~1e-7.
    assert!(worst < 1e-5, "worst difference {worst}");
}

#[test]
fn wgsl_media_filter_ids_match_the_rust_filters() {
    use cumulus::methods::slices::model::MediaFilter;
    let files = cumulus::methods::slices::gpu::passes::FILES;
    let src = files
        .iter()
        .find(|(p, _)| *p == "slices/implicit.wgsl")
        .unwrap()
        .1;
    // The shader's switch names each non-default filter by its id; the
    // default branch is cumulus and stratus (the same formula).
    for (f, comment) in [
        (MediaFilter::Wispy, "// wispy"),
        (MediaFilter::Cirrus, "// cirrus"),
    ] {
        let line = src
            .lines()
            .find(|l| l.contains(comment) && l.contains("case"))
            .unwrap_or_else(|| panic!("no case for {}", f.name()));
        assert!(line.contains(&format!("case {}u", f.gpu_id())), "{line}");
    }
    assert_eq!(
        MediaFilter::Cumulus.apply(0.3),
        MediaFilter::Stratus.apply(0.3)
    );
}

#[test]
fn only_the_slices_method_builds_the_slices_pass() {
    // No ray-march module under slices (nor under sprites); the shadow
    // map of the slices comes from their own implicit field, the
    // ray-marching methods march their parcels into it.
    let modules = cumulus::render::renderer::modules();
    let built = |pass: &str, m: RenderMethod| {
        let s = cumulus::render::renderer::slots(m);
        modules
            .iter()
            .any(|(p, t)| p.name == pass && t.name == p.slots_for(s).name)
    };
    for m in RenderMethod::ALL {
        assert_eq!(built("slices", m), m == RenderMethod::Slices, "{m}");
        assert_eq!(built("clouds", m), m.ray_marches(), "{m}");
        assert_eq!(
            built("shadow", m),
            m.ray_marches() || m == RenderMethod::Slices,
            "{m}"
        );
    }
    let Some(ctx) = context() else { return };
    let scene = authored(&[]);
    let mut hl = Headless::new(&ctx, &scene.render, 32, 24).unwrap();
    // The tone map blends the slices' image (nothing is drawn after it),
    // unless the HDR scene is kept whole for a read-back.
    let names = hl.renderer.pass_names();
    assert!(
        names.contains(&"slices") && !names.contains(&"composite"),
        "{names:?}"
    );
    hl.renderer.set_scene_whole(true);
    let names = hl.renderer.pass_names();
    assert!(
        names.contains(&"slices") && names.contains(&"composite"),
        "{names:?}"
    );
    assert!(
        !names.contains(&"clouds") && !names.contains(&"bake"),
        "{names:?}"
    );
}

#[test]
fn quality_does_not_change_how_much_cloud_there_is() {
    let Some(ctx) = context() else { return };
    let (lo, hi) = (
        authored(&["render.slices.quality=32"]),
        authored(&["render.slices.quality=128"]),
    );
    let sky = sky(&ctx, &hi);
    let (a, b) = (render(&ctx, &lo), render(&ctx, &hi));
    let (ma, mb) = (mean_change(&a, &sky), mean_change(&b, &sky));
    eprintln!("mean change over the sky: quality 32 {ma:.3}, 128 {mb:.3}");
    // The clouds cover a few percent of the frame (mean change ~0.6/255
    // over all pixels at Quality 128); no clouds at all give 0.
    assert!(mb > 0.3, "the clouds barely show ({mb:.3})");
    // Within 5 % (measured 0.3 % on lavapipe): plane opacity = Opacity ÷ planes keeps the optical
    // depth; what remains is the sampling of the field and noise by 32
    // rather than 128 planes (the coarse stack misses or doubles a plane
    // at each cloud's edges) and 1 − exp(−τ) per plane, whose product over
    // fewer, thicker planes is slightly more transparent. Without the
    // compensation Quality 32 would be 4× fainter.
    assert!(
        (ma / mb - 1.0).abs() < 0.05,
        "quality 32: {ma:.3}, 128: {mb:.3}"
    );
}

#[test]
fn opacity_does_not_grow_or_shrink_the_cloud() {
    let Some(ctx) = context() else { return };
    let (half, full) = (
        authored(&["render.slices.opacity=3"]),
        authored(&["render.slices.opacity=6"]),
    );
    let sky = sky(&ctx, &full);
    let (a, b) = (render(&ctx, &half), render(&ctx, &full));
    // The same optical-depth contour in both: where the cloud is thin its
    // brightening is proportional to τ, which halves with Opacity, so the
    // half-opacity image is thresholded at half the change (2/255 against
    // 4/255, both above the 8-bit rounding of the same sky).
    let (sa, sb) = (silhouette(&a, &sky, 2), silhouette(&b, &sky, 4));
    let (ma, mb) = (mean_change(&a, &sky), mean_change(&b, &sky));
    eprintln!("silhouette: opacity ½ {sa} px, 1 {sb} px; mean change {ma:.3}, {mb:.3}");
    assert!(sb > 200, "the clouds barely show ({sb} px)");
    // Halving Opacity halves every fragment's τ but also the alpha cutoff
    // (Sharpness × plane opacity), so the same fragments are drawn: the
    // silhouette stays within 10 % (measured: 0.5 % on lavapipe; what moves
    // is the 8-bit rounding of the faintest rim). Without the cutoff's
    // compensation the cutoff would eat into the cloud (Sharpness × the
    // old plane opacity is twice the new one) and the cloud does get
    // fainter, which the last check sees.
    assert!(
        (sa as f64 / sb as f64 - 1.0).abs() < 0.10,
        "{sa} vs {sb} px"
    );
    assert!(
        ma < 0.9 * mb,
        "halving Opacity should thin the cloud: {ma:.3} vs {mb:.3}"
    );
}

#[test]
fn authored_scene_matches_its_reference() {
    let Some(ctx) = context() else { return };
    let scene = load_scene_with(Some(&authored_path()), &[]).unwrap().0;
    let img = render(&ctx, &scene);
    common::flip::check_reference("authored_slices", &img, SIZE, MEAN_FLIP_TOLERANCE);
}

#[test]
fn parcels_are_drawn_as_slices() {
    let Some(ctx) = context() else { return };
    let cfg = RenderConfig {
        method: RenderMethod::Slices,
        terrain: cumulus::config::TerrainConfig {
            enabled: false,
            ..Default::default()
        },
        ..RenderConfig::default()
    };
    let parcels = standin::default_field(0.0);
    let camera = Camera::from(&cumulus::config::CameraConfig::default());
    let frame = |cfg: &RenderConfig, parcels| {
        let mut hl = Headless::new(&ctx, cfg, SIZE.0, SIZE.1).unwrap();
        let input = FrameInput {
            camera,
            parcels,
            sun: cfg.sun(),
            time_s: 0.0,
        };
        let img = hl.render(&ctx, &input).unwrap().0;
        (img, hl.renderer.slice_primitives())
    };
    let (with, n) = frame(&cfg, &parcels);
    let (without, _) = frame(&cfg, &[]);
    assert_eq!(n as usize, parcels.iter().filter(|p| p.fill > 0.0).count());
    let s = silhouette(&with, &without, 4);
    // The stand-in field covers a good part of the default view (the
    // ray-marched methods' tests see it there too); 2 % of the frame is a
    // floor no empty or misplaced field reaches.
    assert!(
        s > SIZE.0 as usize * SIZE.1 as usize / 50,
        "{s} px of cloud"
    );
}

#[test]
fn a_saved_scene_reloads_to_an_identical_render() {
    let Some(ctx) = context() else { return };
    let scene = authored(&["render.slices.quality=48", "render.slices.detail=2.7"]);
    let text = scene.to_toml().unwrap();
    // Saved beside the original, so its relative sounding path resolves.
    let saved = cumulus::scene::set::load_with_overrides(&text, &authored_path(), &[]).unwrap();
    assert_eq!(saved.render.slices, scene.render.slices);
    assert_eq!(saved.ellipsoids, scene.ellipsoids);
    assert_eq!(render(&ctx, &saved), render(&ctx, &scene));
}

/// Pixel (x, y) of an RGBA8 frame of SIZE.
fn pixel(img: &[u8], x: u32, y: u32) -> [u8; 3] {
    let i = 4 * (y * SIZE.0 + x) as usize;
    [img[i], img[i + 1], img[i + 2]]
}

#[test]
fn the_background_colour_replaces_the_sky_when_the_sky_is_off() {
    let Some(ctx) = context() else { return };
    let flat = |c: &str| {
        let scene = authored(&["render.slices.sky=false", c]);
        render(&ctx, &scene)
    };
    let (warm, cool) = (
        flat("render.slices.background_colour=[0.5, 0.2, 0.05]"),
        flat("render.slices.background_colour=[0.05, 0.2, 0.5]"),
    );
    let sky = render(&ctx, &authored(&[]));
    // The top corners are cloudless: there the background shows, flat
    // (both corners alike) and in the colour asked for.
    let (a, b) = (pixel(&warm, 0, 0), pixel(&warm, SIZE.0 - 1, 0));
    assert_eq!(a, b, "a flat background");
    assert!(a[0] > a[2] + 40, "warm background {a:?}");
    let c = pixel(&cool, 0, 0);
    assert!(c[2] > c[0] + 40, "cool background {c:?}");
    // The sky gradient is gone (zenith and horizon rows differ with it).
    let (top, bottom) = (pixel(&sky, 0, 0), pixel(&sky, 0, SIZE.1 - 1));
    assert_ne!(top, bottom, "the sky is a gradient");
    assert_ne!(pixel(&warm, 0, 0), top);
}

/// The CPU frame of the authored scene at its start, its vertices
/// evaluated on the CPU with the renderer's noise volume.
fn cpu_frame(scene: &SceneProfile) -> cumulus::methods::slices::gpu::SlicesFrame {
    let cfg = &scene.render;
    let camera = Camera::from(&scene.camera);
    let noise = cumulus::noise::NoiseVolume::new(cfg.noise_texels);
    cumulus::methods::slices::gpu::slices_frame(
        &scene.ellipsoids,
        &scene.particles,
        &[],
        cfg,
        scene.simulation.start_s as f32,
        cfg.sun().direction,
        camera.position,
        camera.target - camera.position,
        Some(&noise),
    )
    .unwrap()
}

#[test]
fn the_first_octave_shades_the_vertex_shadow_and_can_be_switched_off() {
    let sets = |on: &str| {
        authored(&[
            "render.slices.quality=32",
            &format!("render.slices.shadow_octave={on}"),
        ])
    };
    let (on, off) = (cpu_frame(&sets("true")), cpu_frame(&sets("false")));
    let (mut moved, mut total) = (0.0f32, 0.0f32);
    for (a, b) in on.slices.vertices().iter().zip(&off.slices.vertices()) {
        assert_eq!(a.density, b.density, "the field itself does not change");
        moved += (a.shadow - b.shadow).abs();
        total += b.shadow;
    }
    eprintln!("first octave moves the shadows by {moved} of {total} in all");
    // The weight averages 1 but varies with the first octave's lumps: the
    // shadows move by a good fraction of themselves, not by rounding.
    assert!(moved > 0.05 * total, "moved {moved} of {total}");
    let Some(ctx) = context() else { return };
    let (a, b) = (render(&ctx, &sets("true")), render(&ctx, &sets("false")));
    assert_ne!(a, b, "the switch changes the image");
}

#[test]
fn parcels_sliced_get_flat_bases_at_their_condensation_planes() {
    use cumulus::physics::CloudParcel;
    let plane = 900.0;
    let parcel = CloudParcel {
        center_m: glam::Vec3::new(0.0, 0.0, 1000.0),
        radius_m: 300.0,
        fill: 1.0,
        cond_plane_z_m: plane,
        id: 0,
    };
    let cfg = RenderConfig {
        method: RenderMethod::Slices,
        ..RenderConfig::default()
    };
    let noise = cumulus::noise::NoiseVolume::new(cfg.noise_texels);
    let frame = cumulus::methods::slices::gpu::slices_frame(
        &[],
        &Default::default(),
        &[parcel],
        &cfg,
        0.0,
        cfg.sun().direction,
        glam::Vec3::new(-3000.0, -10000.0, 2000.0),
        glam::Vec3::new(0.3, 1.0, -0.1),
        Some(&noise),
    )
    .unwrap();
    let v = &frame.slices.vertices();
    // The drawn sphere (radius × radius_scale × PARCEL_BLEND_SCALE) reaches far below the plane,
    // but every vertex under it is empty and the cloud above it is not.
    let below: Vec<_> = v.iter().filter(|v| v.position_m[2] < plane).collect();
    assert!(frame.slices.states[0].centre_m.z - frame.slices.states[0].radii_m.z < plane - 300.0);
    assert!(below.len() > v.len() / 10, "{} of {}", below.len(), v.len());
    assert!(below.iter().all(|v| v.density == 0.0));
    assert!(v.iter().any(|v| v.position_m[2] > plane && v.density > 0.5));
}

#[test]
fn terrain_under_an_authored_cloud_is_darker_with_shadows_on() {
    let Some(ctx) = context() else { return };
    // One broad cloud 2 km up, the sun high, looking down at the ground
    // around it.
    let ellipsoids = vec![cumulus::methods::slices::model::Ellipsoid {
        centre_m: [0.0, 0.0, 2000.0],
        radii_m: [1500.0, 1500.0, 500.0],
        ..Default::default()
    }];
    let camera = Camera::from(&cumulus::config::CameraConfig {
        position_m: [0.0, -7000.0, 5000.0],
        target_m: [0.0, 0.0, 0.0],
        ..Default::default()
    });
    let shot = |shadows: bool| {
        let cfg = RenderConfig {
            method: RenderMethod::Slices,
            shadows,
            sun_elevation_deg: 60.0,
            ..RenderConfig::default()
        };
        let mut hl = Headless::new(&ctx, &cfg, SIZE.0, SIZE.1).unwrap();
        hl.renderer.set_authored(&ellipsoids, &Default::default());
        let input = FrameInput {
            camera,
            parcels: &[],
            sun: cfg.sun(),
            time_s: 0.0,
        };
        let img = hl.render(&ctx, &input).unwrap().0;
        (img, hl.renderer.pass_names())
    };
    let ((on, passes), (off, _)) = (shot(true), shot(false));
    assert!(passes.contains(&"shadow"), "{passes:?}");
    let sum = |img: &[u8]| img.chunks_exact(4).map(|p| p[1] as u64).sum::<u64>();
    let darker = on
        .chunks_exact(4)
        .zip(off.chunks_exact(4))
        .filter(|(a, b)| a[1] + 8 < b[1])
        .count();
    let brighter = on
        .chunks_exact(4)
        .zip(off.chunks_exact(4))
        .filter(|(a, b)| a[1] > b[1] + 1)
        .count();
    eprintln!(
        "shadowed pixels {darker}; green sums on {} off {}",
        sum(&on),
        sum(&off)
    );
    // The shadow is a patch of ground as wide as the cloud (measured 0.4 %
    // of the frame on lavapipe darker by more than 8 levels; 1.2 % before
    // the sky had multiple scattering, whose brighter ambient and haze fill
    // the shadow more); 0.25 % is a floor no missing shadow reaches;
    // nothing gets lighter beyond 8-bit rounding.
    assert!(darker > (SIZE.0 * SIZE.1) as usize / 400, "{darker} px");
    assert_eq!(brighter, 0);
}

#[test]
fn the_compute_pass_gives_the_cpu_vertex_field() {
    let Some(ctx) = context() else { return };
    let sets = ["render.slices.quality=32"];
    let cpu_scene = authored(&sets);
    let gpu_scene = authored(&["render.slices.quality=32", "render.slices.vertex_field=gpu"]);
    let reference = cpu_frame(&cpu_scene);
    let reference = reference.slices.vertices();
    let n = reference.len();
    let cfg = &gpu_scene.render;
    let mut hl = Headless::new(&ctx, cfg, SIZE.0, SIZE.1).unwrap();
    hl.renderer
        .set_authored(&gpu_scene.ellipsoids, &gpu_scene.particles);
    let input = FrameInput {
        camera: Camera::from(&gpu_scene.camera),
        parcels: &[],
        sun: cfg.sun(),
        time_s: gpu_scene.simulation.start_s as f32,
    };
    let gpu_img = hl.render(&ctx, &input).unwrap().0;
    assert!(hl.renderer.pass_names().contains(&"slice_field"));
    let gpu = hl.renderer.slice_vertices(&ctx, n).unwrap();
    let (mut field, mut shadow, mut max_shadow) = (0.0f32, 0.0f32, 0.0f32);
    for (c, g) in reference.iter().zip(&gpu) {
        assert_eq!(c.position_m, g.position_m);
        field = field.max((c.density - g.density).abs());
        shadow = shadow.max((c.shadow - g.shadow).abs());
        max_shadow = max_shadow.max(c.shadow);
    }
    eprintln!("largest differences: field {field:e}, shadow {shadow:e} of {max_shadow}");
    // Field: the same f32 formula, summed in the same order (measured
    // identical on lavapipe); a real GPU may round differently (fused
    // multiply-adds, its division): 1e-4 of a field of order 1.
    assert!(field < 1e-4, "field differs by {field}");
    // Shadow: up to 32 such terms, times the first octave's weight, whose
    // noise fetch the GPU filters with its own interpolation precision
    // (8-bit weights on many GPUs; the CPU's are exact): 1 % of the
    // largest shadow (measured 0.2 % on lavapipe).
    assert!(shadow < 0.01 * max_shadow, "shadow differs by {shadow}");
    let cpu_img = render(&ctx, &cpu_scene);
    let mean = common::flip::mean_flip(&cpu_img, &gpu_img, SIZE);
    assert!(
        mean <= MEAN_FLIP_TOLERANCE,
        "mean FLIP CPU vs GPU {mean:.4}"
    );
}
