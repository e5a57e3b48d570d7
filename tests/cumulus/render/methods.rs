//! The render methods against each other on lavapipe (≤ 256×192): the baked
//! macro field against the paper's exact per-sample union (also where
//! parcels with different condensation planes overlap), parcel counts
//! beyond the exact path's uniform limit and none at all, no pipeline
//! rebuilt when clouds vanish and come back, and no re-bake while the
//! parcels stand still. Without any adapter these tests fail (see
//! `common::gpu` for the opt-in skip).

use crate::common;

use cumulus::config::{Camera, CameraConfig, RenderConfig, RenderMethod, TerrainConfig};
use cumulus::methods::standin;
use cumulus::physics::CloudParcel;
use cumulus::render::headless::Headless;
use cumulus::render::{FrameInput, GpuContext};
use glam::Vec3;

/// Mean FLIP allowed between baked and exact at the same settings (the
/// issue's target). The baked field is the exact one sampled on voxels of
/// about one plane shell and filtered trilinearly: it is exact where the
/// field is linear and rounds the creases (union seams, the flat base, the
/// saturation edge one shell inside) over about a voxel, a few percent of
/// a cloud's width. What the eye sees differ is a thin rim of the base and
/// the noise-eroded edge; a moved, missing or wrongly lit cloud scores far
/// above 0.02 (see `a_shifted_cloud_fails_the_tolerance`). Both methods
/// shade with a sun march over the whole cloud height (the light volume;
/// exact's grid-culled far march) and march their ground shadows by the
/// same routine (density.wgsl `ground_sun_depth`): measured 0.0137 (towers)
/// and 0.0098 (mixed) on llvmpipe, since the bake keeps the condensation
/// plane of the parcel that gives a voxel its value (0.0138 and 0.0125
/// with the lowest plane of any parcel reaching it). With the ground shadows from the light volume (baked)
/// against the map (exact) the towers measured 0.025: the volume's coarse
/// cells widened every shadow by about a cell.
const BAKED_VS_EXACT_FLIP: f32 = 0.02;

fn context() -> Option<GpuContext> {
    common::context("GPU render-method test")
}

fn with_method(cfg: &RenderConfig, method: RenderMethod) -> RenderConfig {
    RenderConfig {
        method,
        ..cfg.clone()
    }
}

fn render(
    ctx: &GpuContext,
    cfg: &RenderConfig,
    camera: Camera,
    parcels: &[CloudParcel],
    (w, h): (u32, u32),
) -> Vec<u8> {
    common::render::render(ctx, cfg, Vec::new(), camera, parcels, (w, h))
}

/// Renders with both methods; returns (mean FLIP, fraction of pixels the
/// clouds change in the exact image).
fn compare(
    ctx: &GpuContext,
    cfg: &RenderConfig,
    camera: Camera,
    parcels: &[CloudParcel],
    size: (u32, u32),
) -> (f32, f32) {
    let exact = render(
        ctx,
        &with_method(cfg, RenderMethod::Exact),
        camera,
        parcels,
        size,
    );
    let baked = render(
        ctx,
        &with_method(cfg, RenderMethod::Baked),
        camera,
        parcels,
        size,
    );
    let sky = render(
        ctx,
        &with_method(cfg, RenderMethod::Exact),
        camera,
        &[],
        size,
    );
    let cloudy = exact
        .chunks_exact(4)
        .zip(sky.chunks_exact(4))
        .filter(|(a, b)| a.iter().zip(*b).any(|(x, y)| x.abs_diff(*y) > 12))
        .count() as f32
        / (size.0 * size.1) as f32;
    (common::flip::mean_flip(&exact, &baked, size), cloudy)
}

fn towers_camera() -> Camera {
    Camera::from(&CameraConfig {
        position_m: [-3000.0, -6000.0, 1000.0],
        target_m: [-1500.0, -1000.0, 1800.0],
        vfov_deg: 45.0,
        ..CameraConfig::default()
    })
}

/// Parcels of very different fill (0.25 to 1) and condensation planes
/// (1.2 to 2.1 km), overlapping, seen from the side without terrain.
fn mixed_parcels() -> Vec<CloudParcel> {
    (0..12)
        .map(|i| {
            let a = i as f32 * 0.9;
            CloudParcel {
                id: i as u64,
                center_m: Vec3::new(
                    a.cos() * 900.0 + i as f32 * 120.0 - 600.0,
                    a.sin() * 700.0,
                    1500.0 + (i % 4) as f32 * 250.0,
                ),
                radius_m: 160.0 + (i % 3) as f32 * 60.0,
                fill: [1.0, 0.25, 0.6, 0.85][i % 4],
                cond_plane_z_m: [1200.0, 1500.0, 1800.0, 2100.0][i % 3],
            }
        })
        .collect()
}

fn side_camera() -> Camera {
    Camera::from(&CameraConfig {
        position_m: [0.0, -6500.0, 1300.0],
        target_m: [0.0, 0.0, 1800.0],
        vfov_deg: 40.0,
        ..CameraConfig::default()
    })
}

fn no_terrain() -> RenderConfig {
    RenderConfig {
        terrain: TerrainConfig {
            enabled: false,
            ..TerrainConfig::default()
        },
        ..RenderConfig::default()
    }
}

#[test]
fn baked_matches_exact_on_towers_over_terrain() {
    let Some(ctx) = context() else { return };
    let parcels = standin::default_field(900.0);
    let (flip, cloudy) = compare(
        &ctx,
        &RenderConfig::default(),
        towers_camera(),
        &parcels,
        (224, 126),
    );
    eprintln!("towers: mean FLIP baked vs exact {flip:.4}, clouds cover {cloudy:.2}");
    // The comparison means something only if clouds fill much of the frame.
    assert!(cloudy > 0.15, "clouds cover only {cloudy}");
    assert!(flip <= BAKED_VS_EXACT_FLIP, "mean FLIP {flip}");
}

#[test]
fn baked_matches_exact_with_mixed_fills_and_planes() {
    let Some(ctx) = context() else { return };
    let (flip, cloudy) = compare(
        &ctx,
        &no_terrain(),
        side_camera(),
        &mixed_parcels(),
        (192, 144),
    );
    eprintln!("mixed: mean FLIP baked vs exact {flip:.4}, clouds cover {cloudy:.2}");
    assert!(cloudy > 0.1, "clouds cover only {cloudy}");
    assert!(flip <= BAKED_VS_EXACT_FLIP, "mean FLIP {flip}");
}

/// A column of parcels stacked 600 m apart, each cut at its own
/// condensation plane 200 m under its centre, as a tower's successive
/// bubbles condense: the lower parcel's soft shell reaches into the one above.
fn stacked_parcels() -> Vec<CloudParcel> {
    common::render::column(4, (1500.0, 600.0), 180.0, |z| z - 200.0)
}

#[test]
fn baked_keeps_the_plane_of_the_parcel_that_gives_the_value() {
    // The lighting darkens diffuse light toward a sample's cloud base, the
    // plane of the parcel that gives the sample its value (field_exact.wgsl
    // field_sample). A bake keeping the lowest plane of any parcel reaching
    // a voxel lit the upper parcels of a column as if they sat far above
    // their own bases.
    let Some(ctx) = context() else { return };
    let camera = Camera::from(&CameraConfig {
        position_m: [0.0, -5000.0, 2400.0],
        target_m: [0.0, 0.0, 2500.0],
        vfov_deg: 45.0,
        ..CameraConfig::default()
    });
    let size = (96, 128);
    let parcels = stacked_parcels();
    let frame = |method, parcels: &[CloudParcel]| {
        let cfg = with_method(&no_terrain(), method);
        common::hdr::hdr_frames(&ctx, &cfg, camera, cfg.sun(), size, &[parcels]).remove(0)
    };
    let exact = frame(RenderMethod::Exact, &parcels);
    let baked = frame(RenderMethod::Baked, &parcels);
    let sky = frame(RenderMethod::Exact, &[]);
    let mask = common::hdr::cloud_mask(&exact, &sky);
    let mean = |img: &[f32]| {
        let l = common::hdr::luminance(img);
        let cloud: Vec<f32> = l
            .iter()
            .zip(&mask)
            .filter(|(_, m)| **m)
            .map(|(v, _)| *v)
            .collect();
        cloud.iter().sum::<f32>() / cloud.len().max(1) as f32
    };
    let cover = mask.iter().filter(|m| **m).count() as f32 / mask.len() as f32;
    let ratio = mean(&baked) / mean(&exact);
    eprintln!("stacked: cloud luminance baked / exact {ratio:.4}, clouds cover {cover:.2}");
    assert!(cover > 0.1, "clouds cover only {cover}");
    // Measured on llvmpipe: 0.985 (the voxels' rounded edges), and 1.039
    // with the lowest-plane bake this replaced.
    assert!(
        (ratio - 1.0).abs() <= 0.025,
        "baked / exact cloud luminance {ratio}"
    );
}

#[test]
fn a_shifted_cloud_fails_the_tolerance() {
    // The tolerance can fail: the same parcels 150 m to the side score above it.
    let Some(ctx) = context() else { return };
    let cfg = with_method(&no_terrain(), RenderMethod::Exact);
    let size = (192, 144);
    let parcels = mixed_parcels();
    let moved: Vec<CloudParcel> = parcels
        .iter()
        .map(|p| CloudParcel {
            center_m: p.center_m + Vec3::new(150.0, 0.0, 0.0),
            ..*p
        })
        .collect();
    let a = render(&ctx, &cfg, side_camera(), &parcels, size);
    let b = render(&ctx, &cfg, side_camera(), &moved, size);
    let flip = common::flip::mean_flip(&a, &b, size);
    eprintln!("clouds moved 150 m: mean FLIP {flip:.4}");
    assert!(flip > BAKED_VS_EXACT_FLIP, "moved clouds score only {flip}");
}

/// `n` parcels on a square lattice over 12 km, 1.5–1.9 km high.
fn lattice(n: usize) -> Vec<CloudParcel> {
    let side = (n as f32).sqrt().ceil() as usize;
    let pitch = 12_000.0 / side as f32;
    (0..n)
        .map(|i| CloudParcel {
            id: i as u64,
            center_m: Vec3::new(
                (i % side) as f32 * pitch - 6000.0,
                (i / side) as f32 * pitch - 6000.0,
                1500.0 + (i % 5) as f32 * 100.0,
            ),
            radius_m: 90.0,
            fill: 0.9,
            cond_plane_z_m: 1400.0,
        })
        .collect()
}

#[test]
fn four_thousand_parcels_render_baked_and_exact_names_its_limit() {
    let Some(ctx) = context() else { return };
    let parcels = lattice(4096);
    let cfg = RenderConfig::default();
    assert_eq!(cfg.method, RenderMethod::Baked);
    let size = (128, 96);
    let camera = Camera::from(&CameraConfig::default());
    let clouds = render(&ctx, &cfg, camera, &parcels, size);
    let sky = render(&ctx, &cfg, camera, &[], size);
    let changed = clouds
        .chunks_exact(4)
        .zip(sky.chunks_exact(4))
        .filter(|(a, b)| a.iter().zip(*b).any(|(x, y)| x.abs_diff(*y) > 12))
        .count();
    assert!(
        changed > (size.0 * size.1 / 10) as usize,
        "4096 parcels change only {changed} pixels"
    );
    // The exact method refuses, naming the limit, rather than draw a part.
    let exact = with_method(&cfg, RenderMethod::Exact);
    let mut hl = Headless::new(&ctx, &exact, size.0, size.1).unwrap();
    let e = hl
        .render(
            &ctx,
            &FrameInput {
                camera,
                parcels: &parcels,
                sun: cfg.sun(),
                time_s: 0.0,
            },
        )
        .unwrap_err()
        .to_string();
    assert!(e.contains("1024") && e.contains("baked"), "{e}");
}

#[test]
fn no_pipeline_is_built_when_clouds_vanish_and_return_and_still_parcels_are_not_rebaked() {
    let Some(ctx) = context() else { return };
    let cfg = RenderConfig::default();
    let (w, h) = (64, 48);
    let mut hl = Headless::new(&ctx, &cfg, w, h).unwrap();
    let parcels = standin::default_field(900.0);
    let frame = |parcels| FrameInput {
        camera: Camera::from(&CameraConfig::default()),
        parcels,
        sun: cfg.sun(),
        time_s: 0.0,
    };
    // Created empty: the cloud pipelines already exist.
    hl.render(&ctx, &frame(&[])).unwrap();
    let built = hl.renderer.pipelines_built();
    assert!(built > 0);
    let (first, t) = hl.render(&ctx, &frame(&parcels)).unwrap();
    assert!(t.pass_ms("bake").is_some() && t.pass_ms("clouds").is_some());
    assert!(t.pass_ms("shadow").is_some(), "{t:?}");
    let bakes = hl.renderer.bake_info().bakes;
    // Standing still: no bake, and the shadow map of the last bake is
    // kept: the same picture, to within one 8-bit step (the `auto` march
    // alternates fragment and compute in its first frames, and the compute
    // path's RGBA16F detour rounds a few values the other way).
    let (still, t) = hl.render(&ctx, &frame(&parcels)).unwrap();
    assert!(t.pass_ms("bake").is_none(), "{t:?}");
    assert!(t.pass_ms("shadow").is_none(), "{t:?}");
    assert_eq!(hl.renderer.bake_info().bakes, bakes);
    let worst = first.iter().zip(&still).map(|(a, b)| a.abs_diff(*b)).max();
    assert!(
        worst <= Some(1),
        "a still frame differs from the one before by {worst:?}"
    );
    // Gone, back, and moved: bakes again, never a new pipeline.
    hl.render(&ctx, &frame(&[])).unwrap();
    hl.render(&ctx, &frame(&parcels)).unwrap();
    let moved: Vec<CloudParcel> = parcels
        .iter()
        .map(|p| CloudParcel {
            center_m: p.center_m + Vec3::new(10.0, 0.0, 0.0),
            ..*p
        })
        .collect();
    let (_, t) = hl.render(&ctx, &frame(&moved)).unwrap();
    assert!(t.pass_ms("shadow").is_some(), "{t:?}");
    assert_eq!(hl.renderer.bake_info().bakes, bakes + 2);
    assert_eq!(hl.renderer.pipelines_built(), built);
}

/// Mean FLIP allowed between the compute and the fragment march: the same
/// WGSL `march` at the same pixel centres, so only the compute path's
/// detour through an RGBA16F texture (a rounding of ~1/2000, under one 8-bit
/// step) can differ; 0.005 leaves room for that and fails on any shift,
/// missing pass or wrong blend (a moved cloud scores several times more).
const COMPUTE_VS_FRAGMENT_FLIP: f32 = 0.005;

#[test]
fn compute_and_fragment_march_agree_and_auto_decides() {
    let Some(ctx) = context() else { return };
    let parcels = standin::default_field(900.0);
    let size = (160, 90);
    // The march paths exist for the ray-marching methods only.
    for method in RenderMethod::ALL.into_iter().filter(|m| m.ray_marches()) {
        let base = with_method(&RenderConfig::default(), method);
        let path = |march| RenderConfig {
            march,
            ..base.clone()
        };
        let fragment = render(
            &ctx,
            &path(cumulus::config::MarchPath::Fragment),
            towers_camera(),
            &parcels,
            size,
        );
        let compute = render(
            &ctx,
            &path(cumulus::config::MarchPath::Compute),
            towers_camera(),
            &parcels,
            size,
        );
        let flip = common::flip::mean_flip(&fragment, &compute, size);
        eprintln!("{method}: mean FLIP compute vs fragment {flip:.5}");
        assert!(flip <= COMPUTE_VS_FRAGMENT_FLIP, "{method}: {flip}");
    }
    // auto: alternates, then keeps one path, and says which.
    let cfg = RenderConfig::default();
    let mut hl = Headless::new(&ctx, &cfg, 64, 48).unwrap();
    let input = FrameInput {
        camera: towers_camera(),
        parcels: &parcels,
        sun: cfg.sun(),
        time_s: 0.0,
    };
    let mut composite_seen = false;
    for _ in 0..12 {
        let (_, t) = hl.render(&ctx, &input).unwrap();
        composite_seen |= t.pass_ms("composite").is_some();
        if hl.renderer.march_path().is_some() {
            break;
        }
    }
    assert!(composite_seen, "auto never tried the compute path");
    assert!(hl.renderer.march_path().is_some(), "auto did not decide");
}

/// The window's "no stalls" for settings (issue 9): with the background
/// builder on, every panel toggle in a row (normals, shadows, aerial
/// perspective, temporal, terrain, each method, the march path) finds its
/// pipelines built, so the frame after it compiles none on its own
/// thread. The control shows the count can fail: without the builder the
/// first normals toggle compiles on the frame's thread.
#[test]
fn toggling_a_setting_takes_pipelines_built_in_the_background() {
    let Some(ctx) = context() else { return };
    let parcels = standin::default_field(900.0);
    // The window's settings: temporal on.
    let base = RenderConfig {
        temporal: Some(cumulus::config::TemporalMode::Block4),
        ..RenderConfig::default()
    };
    let (w, h) = (64, 48);
    let frame = |parcels| FrameInput {
        camera: Camera::from(&CameraConfig::default()),
        parcels,
        sun: base.sun(),
        time_s: 0.0,
    };
    let normals = RenderConfig {
        normals: !base.normals,
        ..base.clone()
    };

    let mut off = Headless::new(&ctx, &base, w, h).unwrap();
    off.render(&ctx, &frame(&parcels)).unwrap();
    let built = off.renderer.pipelines_built();
    off.renderer.set_config(&ctx, &normals).unwrap();
    off.render(&ctx, &frame(&parcels)).unwrap();
    assert!(
        off.renderer.pipelines_built() > built,
        "the control toggle compiled nothing"
    );

    let mut hl = Headless::new(&ctx, &base, w, h).unwrap();
    hl.renderer.set_prebuild(&ctx, true).unwrap();
    hl.render(&ctx, &frame(&parcels)).unwrap();
    let started = std::time::Instant::now();
    hl.renderer.wait_prebuilt();
    eprintln!(
        "{} pipelines built ahead for the first settings in {:.1} s",
        hl.renderer.pipelines_prebuilt(),
        started.elapsed().as_secs_f64()
    );
    type Toggle = (&'static str, fn(&mut RenderConfig));
    let toggles: [Toggle; 10] = [
        ("normals", |c| c.normals = !c.normals),
        ("shadows", |c| c.shadows = !c.shadows),
        ("aerial perspective", |c| {
            c.aerial_perspective = !c.aerial_perspective
        }),
        ("temporal off", |c| {
            c.temporal = Some(cumulus::config::TemporalMode::Off)
        }),
        ("march compute", |c| {
            c.march = cumulus::config::MarchPath::Compute
        }),
        ("terrain off", |c| c.terrain.enabled = false),
        ("exact", |c| c.method = RenderMethod::Exact),
        ("grid culling", |c| c.grid_culling = !c.grid_culling),
        ("sprites", |c| c.method = RenderMethod::Sprites),
        ("slices", |c| c.method = RenderMethod::Slices),
    ];
    let mut cfg = base.clone();
    for (name, toggle) in toggles {
        // The window draws frames while the builder works; here it is
        // waited for, so the count does not depend on the machine's speed.
        hl.renderer.wait_prebuilt();
        let built = hl.renderer.pipelines_built();
        toggle(&mut cfg);
        hl.renderer.set_config(&ctx, &cfg).unwrap();
        hl.render(&ctx, &frame(&parcels)).unwrap();
        assert_eq!(
            hl.renderer.pipelines_built(),
            built,
            "{name}: a pipeline was compiled on the frame's thread"
        );
    }
    assert!(hl.renderer.pipelines_prebuilt() > 0);
}
