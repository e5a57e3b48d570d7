//! Renders on the CPU Vulkan adapter (lavapipe "llvmpipe"; any adapter when
//! that is absent). Without any adapter these tests fail (see `common::gpu`
//! for the opt-in skip).
//!
//! Small fixed scenes (≤ 256×192) against reference PNGs in
//! tests/reference/render/ by mean FLIP; `UPDATE_REFERENCES=1` rewrites them.
//! On failure `NAME.actual.png` and `NAME.difference.png` are written beside
//! the reference.

use crate::common;

use cumulus::config::{Camera, CameraConfig, RenderConfig, TerrainConfig};
use cumulus::methods::standin;
use cumulus::physics::CloudParcel;
use cumulus::render::headless::Headless;
use cumulus::render::{FrameInput, GpuContext, Renderer};
use glam::Vec3;

/// Mean FLIP allowed against a reference. Same driver gives ~0; the ray start
/// jitter and float ordering differ slightly across Mesa/LLVM versions, and
/// 0.02 is within what wgpu's own example tests accept (0.01–0.04) while a
/// moved cloud or a missing shadow scores far above it.
const MEAN_FLIP_TOLERANCE: f32 = 0.02;

fn context() -> Option<GpuContext> {
    common::context("GPU render test")
}

fn render(
    ctx: &GpuContext,
    cfg: &RenderConfig,
    camera: Camera,
    parcels: &[CloudParcel],
    w: u32,
    h: u32,
) -> Vec<u8> {
    common::render::render(ctx, cfg, Vec::new(), camera, parcels, (w, h))
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

fn compare_with_reference(name: &str, rgba: &[u8], w: u32, h: u32) {
    common::flip::check_reference(name, rgba, (w, h), MEAN_FLIP_TOLERANCE);
}

/// One full parcel with its plane 300 m under the centre.
fn one_parcel(shell_m: f32) -> (RenderConfig, CloudParcel) {
    // radius_scale 1: the drawn sphere is the parcel's, for the geometry checks.
    let cfg = RenderConfig {
        shell_m,
        radius_scale: 1.0,
        ..no_terrain()
    };
    let p = CloudParcel {
        id: 0,
        center_m: Vec3::new(0.0, 0.0, 2000.0),
        radius_m: 600.0,
        fill: 1.0,
        cond_plane_z_m: 1700.0,
    };
    (cfg, p)
}

fn side_camera() -> Camera {
    Camera::from(&CameraConfig {
        position_m: [0.0, -5000.0, 1200.0],
        target_m: [0.0, 0.0, 1900.0],
        vfov_deg: 30.0,
        ..CameraConfig::default()
    })
}

#[test]
fn reference_towers_over_terrain() {
    let Some(ctx) = context() else { return };
    let cfg = RenderConfig::default();
    let (w, h) = (224, 126);
    // Close to two towers, with their shadows on the ground in front.
    let camera = Camera::from(&CameraConfig {
        position_m: [-3000.0, -6000.0, 1000.0],
        target_m: [-1500.0, -1000.0, 1800.0],
        vfov_deg: 45.0,
        ..CameraConfig::default()
    });
    let img = render(&ctx, &cfg, camera, &standin::default_field(900.0), w, h);
    compare_with_reference("towers_over_terrain", &img, w, h);
}

#[test]
fn reference_single_parcel_in_sky() {
    let Some(ctx) = context() else { return };
    let (cfg, p) = one_parcel(RenderConfig::default().shell_m);
    let (w, h) = (160, 120);
    let img = render(&ctx, &cfg, side_camera(), &[p], w, h);
    compare_with_reference("single_parcel_in_sky", &img, w, h);
}

#[test]
fn empty_sky_has_no_cloud_pixels() {
    let Some(ctx) = context() else { return };
    let cfg = no_terrain();
    let (w, h) = (128, 96);
    let mut hl = Headless::new(&ctx, &cfg, w, h).unwrap();
    // Looking up (the lower edge 5° above the horizon): only sky in view.
    let camera = Camera::from(&CameraConfig {
        position_m: [0.0, -5000.0, 1200.0],
        target_m: [0.0, 0.0, 3000.0],
        vfov_deg: 30.0,
        ..CameraConfig::default()
    });
    let input = FrameInput {
        camera,
        parcels: &[],
        sun: cfg.sun(),
        time_s: 0.0,
    };
    let (img, timings) = hl.render(&ctx, &input).unwrap();
    assert_eq!(hl.renderer.pass_names(), ["sky", "tonemap"]);
    assert!(timings.pass_ms("clouds").is_none());
    // Clear sky is blue (b well above r); cloud pixels are grey-white (r ≈ b).
    for (i, p) in img.chunks_exact(4).enumerate() {
        assert!(
            p[2] as i32 - p[0] as i32 > 20,
            "pixel {i} looks like cloud: {p:?}"
        );
    }
}

/// Which pixels a parcel covers: differs from the empty sky by > 12/255.
fn cloud_mask(ctx: &GpuContext, cfg: &RenderConfig, p: CloudParcel, w: u32, h: u32) -> Vec<bool> {
    let sky = render(ctx, cfg, side_camera(), &[], w, h);
    let cloud = render(ctx, cfg, side_camera(), &[p], w, h);
    sky.chunks_exact(4)
        .zip(cloud.chunks_exact(4))
        .map(|(a, b)| (0..3).any(|c| (a[c] as i32 - b[c] as i32).abs() > 12))
        .collect()
}

#[test]
fn one_parcel_has_a_flat_base_at_its_condensation_plane() {
    let Some(ctx) = context() else { return };
    // A thin shell (60 m) so noise moves the base by at most k/2·60 m = 36 m.
    let (cfg, p) = one_parcel(60.0);
    let (w, h) = (160, 120);
    let mask = cloud_mask(&ctx, &cfg, p, w, h);
    let cam = side_camera();
    // The camera is below the plane, so the plane's farthest visible point
    // (the far edge of the cut disk) is its lowest image point.
    let cut_r = (p.radius_m.powi(2) - (p.center_m.z - p.cond_plane_z_m).powi(2)).sqrt();
    let far_edge = Vec3::new(0.0, cut_r, p.cond_plane_z_m);
    let (_, plane_row) = cam.project_to_pixel(far_edge, w, h).unwrap();
    let lowest_in_column = |x: u32| (0..h).rev().find(|&y| mask[(y * w + x) as usize]);
    let cols: Vec<u32> = (0..w).filter(|&x| lowest_in_column(x).is_some()).collect();
    assert!(cols.len() > 10, "the parcel is not in the image");
    let lowest = cols
        .iter()
        .map(|&x| lowest_in_column(x).unwrap())
        .max()
        .unwrap() as f32;
    // 2 px: 36 m of noise at 5 km is 0.4° = 1.6 px at 30°/120 px, plus edge rounding.
    assert!(
        (lowest - plane_row).abs() <= 2.5,
        "cloud base at row {lowest}, condensation plane projects to row {plane_row:.1}"
    );
    // Flat: across the middle half of the cloud the lowest row varies by ≤ 3 px
    // (the disk's depth spans ~2 px at this angle), while its top is round.
    let mid = &cols[cols.len() / 4..3 * cols.len() / 4];
    let lows: Vec<u32> = mid.iter().map(|&x| lowest_in_column(x).unwrap()).collect();
    let highs: Vec<u32> = cols
        .iter()
        .map(|&x| (0..h).find(|&y| mask[(y * w + x) as usize]).unwrap())
        .collect();
    let spread = |v: &[u32]| v.iter().max().unwrap() - v.iter().min().unwrap();
    assert!(spread(&lows) <= 3, "base not flat: {lows:?}");
    assert!(
        spread(&highs) > spread(&lows) + 3,
        "top as flat as the base: {highs:?}"
    );
}

#[test]
fn shadow_pass_darkens_terrain_under_the_cloud() {
    let Some(ctx) = context() else { return };
    let flat = TerrainConfig {
        height_scale_m: 0.0,
        ..TerrainConfig::default()
    };
    let on = RenderConfig {
        terrain: flat.clone(),
        radius_scale: 1.0,
        ..RenderConfig::default()
    };
    let off = RenderConfig {
        shadows: false,
        ..on.clone()
    };
    let p = CloudParcel {
        id: 0,
        center_m: Vec3::new(0.0, 0.0, 1800.0),
        radius_m: 700.0,
        fill: 1.0,
        cond_plane_z_m: 1400.0,
    };
    let cam = Camera::from(&CameraConfig {
        position_m: [-1500.0, -9000.0, 4000.0],
        target_m: [-2000.0, 0.0, 0.0],
        vfov_deg: 45.0,
        ..CameraConfig::default()
    });
    let (w, h) = (160, 120);
    let with = render(&ctx, &on, cam, &[p], w, h);
    let without = render(&ctx, &off, cam, &[p], w, h);
    // Where the sun ray through the parcel's centre meets the flat ground.
    let sun = on.sun_direction();
    let ground = p.center_m - sun * (p.center_m.z / sun.z);
    let (px, py) = cam.project_to_pixel(ground, w, h).unwrap();
    let linear = |c: u8| {
        let c = c as f32 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let luma = |img: &[u8]| {
        let mut s = 0.0;
        for dy in -2..=2 {
            for dx in -2..=2 {
                let (x, y) = (px as i32 + dx, py as i32 + dy);
                let i = ((y * w as i32 + x) * 4) as usize;
                s += 0.2126 * linear(img[i])
                    + 0.7152 * linear(img[i + 1])
                    + 0.0722 * linear(img[i + 2]);
            }
        }
        s / 25.0
    };
    let (lit, shaded) = (luma(&without), luma(&with));
    if let Ok(dir) = std::env::var("RENDER_TEST_DUMP") {
        let d = std::path::Path::new(&dir);
        cumulus::output::write_png_atomic(&d.join("shadow_on.png"), w, h, &with).unwrap();
        cumulus::output::write_png_atomic(&d.join("shadow_off.png"), w, h, &without).unwrap();
    }
    // Linear luminance (of the tone-mapped pixel). A full parcel 1.4 km
    // thick blocks nearly all of the direct sun, but the ground's light also
    // holds the sky's ambient and, ~10 km from the eye, a haze veil of ~15 %
    // of the horizon sky; since the sky has multiple scattering (Hillaire
    // 2020, src/sky/) both are brighter (ambient ×1.3, horizon ×1.6) and the
    // shadow takes away 17 % (was over a fifth). 0.9: no shadow pass gives a
    // ratio of 1, and a shadow half as dark as measured would fail.
    assert!(
        shaded < 0.9 * lit,
        "ground at ({px:.0},{py:.0}): luminance {shaded:.3} with shadows vs {lit:.3} without"
    );
    // And the cloud itself is not in that spot (we see ground, not cloud).
    let mut hl = Headless::new(&ctx, &on, w, h).unwrap();
    let input = FrameInput {
        camera: cam,
        parcels: &[p],
        sun: on.sun(),
        time_s: 0.0,
    };
    hl.render(&ctx, &input).unwrap();
    // (plus "composite" in frames that march in a compute shader)
    let names: Vec<&str> = hl
        .renderer
        .pass_names()
        .into_iter()
        .filter(|n| *n != "composite")
        .collect();
    // The baked method marches its parcels into the shadow map too.
    assert_eq!(
        names,
        ["bake", "shadow", "sky", "terrain", "clouds", "tonemap"]
    );
}

#[test]
fn normals_on_and_off_both_render_and_differ() {
    let Some(ctx) = context() else { return };
    let (cfg, p) = one_parcel(RenderConfig::default().shell_m);
    let with = RenderConfig {
        normals: true,
        ..cfg.clone()
    };
    let (w, h) = (128, 96);
    let a = render(&ctx, &cfg, side_camera(), &[p], w, h);
    let b = render(&ctx, &with, side_camera(), &[p], w, h);
    let sky = render(&ctx, &cfg, side_camera(), &[], w, h);
    let diff = |x: &[u8], y: &[u8]| {
        x.iter()
            .zip(y)
            .map(|(a, b)| (*a as i32 - *b as i32).abs() as f64)
            .sum::<f64>()
            / x.len() as f64
    };
    // Both draw the cloud (differ from the empty sky) …
    assert!(diff(&a, &sky) > 2.0 && diff(&b, &sky) > 2.0);
    // … and the normal shading changes it visibly (mean > 0.5/255 per channel).
    assert!(
        diff(&a, &b) > 0.5,
        "normals changed nothing: {}",
        diff(&a, &b)
    );
}

#[test]
fn pruned_scenes_create_fewer_passes() {
    let Some(ctx) = context() else { return };
    let fmt = wgpu::TextureFormat::Rgba8UnormSrgb;
    // The baked method (the default) adds its bake pass before the others;
    // both methods march their clouds' shadows into the map.
    let full = Renderer::new(&ctx, &RenderConfig::default(), fmt, 64, 48).unwrap();
    assert_eq!(
        full.pass_names(),
        ["bake", "shadow", "sky", "terrain", "clouds", "tonemap"]
    );
    let exact = RenderConfig {
        method: cumulus::config::RenderMethod::Exact,
        ..RenderConfig::default()
    };
    let exact = Renderer::new(&ctx, &exact, fmt, 64, 48).unwrap();
    assert_eq!(
        exact.pass_names(),
        ["shadow", "sky", "terrain", "clouds", "tonemap"]
    );
    let mut sky_clouds = Renderer::new(&ctx, &no_terrain(), fmt, 64, 48).unwrap();
    assert_eq!(
        sky_clouds.pass_names(),
        ["bake", "sky", "clouds", "tonemap"]
    );
    let no_shadows = RenderConfig {
        shadows: false,
        ..RenderConfig::default()
    };
    let mut r = Renderer::new(&ctx, &no_shadows, fmt, 64, 48).unwrap();
    assert_eq!(
        r.pass_names(),
        ["bake", "sky", "terrain", "clouds", "tonemap"]
    );
    // No parcels: no ray-march, and (with shadows on) no shadow pass either.
    let input = FrameInput {
        camera: Camera::from(&CameraConfig::default()),
        parcels: &[],
        sun: RenderConfig::default().sun(),
        time_s: 0.0,
    };
    r.prepare(&ctx, &input).unwrap();
    assert_eq!(r.pass_names(), ["sky", "terrain", "tonemap"]);
    sky_clouds.prepare(&ctx, &input).unwrap();
    assert_eq!(sky_clouds.pass_names(), ["sky", "tonemap"]);
    // Turning shadows back on with clouds present restores the pass.
    let parcels = standin::default_field(0.0);
    let input = FrameInput {
        parcels: &parcels,
        ..input
    };
    r.prepare(&ctx, &input).unwrap();
    assert_eq!(
        r.pass_names(),
        ["bake", "sky", "terrain", "clouds", "tonemap"]
    );
    // Shadows on: only the terrain pipeline (its HAS_SHADOWS constant
    // changed) and the shadow map's are built anew; sky and clouds are kept.
    let built = r.pipelines_built();
    r.set_config(&ctx, &RenderConfig::default()).unwrap();
    assert_eq!(
        r.pass_names(),
        ["bake", "shadow", "sky", "terrain", "clouds", "tonemap"]
    );
    assert_eq!(r.pipelines_built(), built + 2);
    // Normals: only the cloud pipeline changes.
    let normals = RenderConfig {
        normals: true,
        ..RenderConfig::default()
    };
    // Normals: only the cloud pipelines change (fragment and compute, both
    // built while march = "auto" is still measuring).
    r.set_config(&ctx, &normals).unwrap();
    assert_eq!(r.pipelines_built(), built + 4);
    // A march parameter is a uniform: nothing is rebuilt.
    let steps = RenderConfig {
        step_m: 80.0,
        ..normals
    };
    r.set_config(&ctx, &steps).unwrap();
    assert_eq!(r.pipelines_built(), built + 4);
}

#[test]
fn timings_name_every_pass() {
    let Some(ctx) = context() else { return };
    // One march path throughout ("auto" alternates while it measures).
    let cfg = RenderConfig {
        march: cumulus::config::MarchPath::Fragment,
        ..RenderConfig::default()
    };
    let mut hl = Headless::new(&ctx, &cfg, 64, 48).unwrap();
    let parcels = standin::default_field(300.0);
    let input = common::render::default_view(&cfg, &parcels);
    let (_, t) = hl.render(&ctx, &input).unwrap();
    let names: Vec<&str> = t.passes.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, hl.renderer.pass_names());
    assert_eq!(t.gpu_timestamps, ctx.timestamps);
    for (n, ms) in &t.passes {
        assert!(ms.is_finite() && *ms >= 0.0, "{n}: {ms}");
    }
    assert!(t.upload_ms >= 0.0);
    assert_eq!(names[0], "bake");
    // Whole frame: at least its longest pass (gaps between passes count too).
    let longest = t.passes.iter().map(|(_, ms)| *ms).fold(0.0, f64::max);
    assert!(t.frame_ms >= longest, "{} < {longest}", t.frame_ms);
    // Later frames of the same parcels neither bake again nor redraw the
    // shadow map of the bake.
    let names: Vec<&str> = names
        .into_iter()
        .filter(|n| *n != "bake" && *n != "shadow")
        .collect();
    // The CPU-clock fallback names the same passes and says so.
    hl.renderer.set_gpu_timestamps(false);
    let (_, t) = hl.render(&ctx, &input).unwrap();
    assert!(!t.gpu_timestamps);
    let cpu_names: Vec<&str> = t.passes.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(cpu_names, names);
    // Each pass waited for the queue, so each took measurable time.
    assert!(t.passes.iter().all(|(_, ms)| *ms > 0.0), "{:?}", t.passes);
    // Lagged GPU timing: the first frame has nothing finished yet; once the
    // GPU is idle a later frame reports the earlier frame's passes.
    if ctx.timestamps {
        use cumulus::render::renderer::TimingMode;
        hl.renderer.set_timing_mode(TimingMode::GpuLagged);
        let (_, first) = hl.render(&ctx, &input).unwrap();
        assert!(first.passes.is_empty(), "{:?}", first.passes);
        ctx.wait_idle();
        let (_, second) = hl.render(&ctx, &input).unwrap();
        let lagged: Vec<&str> = second.passes.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(lagged, names);
        assert!(second.gpu_timestamps);
    }
}

#[test]
fn grid_culling_matches_brute_force() {
    let Some(ctx) = context() else { return };
    // Every parcel whose padded sphere touches a cell is in its list, so
    // evaluating only the cell's parcels must give the same image as
    // evaluating all of them (up to float ordering in the max()). The grid
    // is the exact method's.
    let culled = RenderConfig {
        method: cumulus::config::RenderMethod::Exact,
        ..RenderConfig::default()
    };
    let brute = RenderConfig {
        grid_culling: false,
        ..culled.clone()
    };
    let camera = Camera::from(&CameraConfig {
        position_m: [-3000.0, -6000.0, 1000.0],
        target_m: [-1500.0, -1000.0, 1800.0],
        vfov_deg: 45.0,
        ..CameraConfig::default()
    });
    let parcels = standin::default_field(900.0);
    let (w, h) = (128, 72);
    let a = render(&ctx, &culled, camera, &parcels, w, h);
    let b = render(&ctx, &brute, camera, &parcels, w, h);
    let differing = a
        .chunks_exact(4)
        .zip(b.chunks_exact(4))
        .filter(|(x, y)| (0..3).any(|c| (x[c] as i32 - y[c] as i32).abs() > 2))
        .count();
    // 2/255: rounding of identical maths; allow a handful of pixels. With
    // the aerial perspective (src/sky/air.rs) 6 of the 9216 differ, by
    // 3–6/255, inside the clouds (7 without it); a parcel the grid lost
    // would change hundreds.
    assert!(
        differing <= 8,
        "{differing} pixels differ between culled and brute-force marching"
    );
}

#[test]
fn window_like_formats_render_alike() {
    let Some(ctx) = context() else { return };
    // Window and headless frames are the same frame: both draw the same
    // HDR scene target and differ only in the one tone-map pass's output
    // format. A window surface may be BGRA and not sRGB: the tone map then
    // encodes sRGB itself (ENCODE_SRGB, the exact IEC 61966-2-1 curve), so
    // the image must match the sRGB target's up to the 8-bit rounding of
    // the two encoders: at most 1/255 per channel (measured: max 1).
    let cfg = RenderConfig::default();
    let parcels = standin::default_field(900.0);
    let camera = Camera::from(&CameraConfig::default());
    let input = FrameInput {
        camera,
        parcels: &parcels,
        sun: cfg.sun(),
        time_s: 0.0,
    };
    let (w, h) = (96, 64);
    let mut srgb = Headless::new(&ctx, &cfg, w, h).unwrap();
    let reference = srgb.render(&ctx, &input).unwrap().0;
    for format in [
        wgpu::TextureFormat::Bgra8Unorm,
        wgpu::TextureFormat::Bgra8UnormSrgb,
    ] {
        let mut hl = Headless::with_format(&ctx, &cfg, w, h, format).unwrap();
        let img = hl.render(&ctx, &input).unwrap().0;
        let worst = img
            .iter()
            .zip(&reference)
            .map(|(a, b)| (*a as i32 - *b as i32).abs())
            .max()
            .unwrap_or(0);
        eprintln!("{format:?}: largest difference {worst}/255");
        assert!(worst <= 1, "{format:?}: a channel differs by {worst}/255");
    }
    assert!(Headless::with_format(&ctx, &cfg, w, h, wgpu::TextureFormat::R8Unorm).is_err());
}

#[test]
fn the_most_parcels_the_uniforms_hold_render() {
    let Some(ctx) = context() else { return };
    use cumulus::methods::raymarch::pack::MAX_PARCELS;
    let side = (MAX_PARCELS as f32).sqrt() as usize;
    let parcels: Vec<CloudParcel> = (0..MAX_PARCELS)
        .map(|i| CloudParcel {
            id: i as u64,
            center_m: Vec3::new(
                (i % side) as f32 * 300.0 - 4800.0,
                (i / side) as f32 * 300.0 - 4800.0,
                1600.0 + (i % 7) as f32 * 60.0,
            ),
            radius_m: 150.0,
            fill: 0.9,
            cond_plane_z_m: 1500.0,
        })
        .collect();
    // The uniform limit is the exact method's (the baked one has none).
    let cfg = RenderConfig {
        method: cumulus::config::RenderMethod::Exact,
        ..RenderConfig::default()
    };
    let mut hl = Headless::new(&ctx, &cfg, 64, 48).unwrap();
    let input = common::render::default_view(&cfg, &parcels);
    hl.render(&ctx, &input).unwrap();
    assert_eq!(hl.renderer.grid_info().parcel_count as usize, MAX_PARCELS);
    // One more is refused with an error, not drawn truncated.
    let mut more = parcels.clone();
    more.push(parcels[0]);
    let input = FrameInput {
        parcels: &more,
        ..input
    };
    let e = hl.render(&ctx, &input).unwrap_err().to_string();
    assert!(e.contains("condensed parcel count"), "{e}");
}

#[test]
fn a_target_of_another_size_resizes_the_renderer() {
    let Some(ctx) = context() else { return };
    let cfg = RenderConfig::default();
    let fmt = wgpu::TextureFormat::Rgba8UnormSrgb;
    let mut r = Renderer::new(&ctx, &cfg, fmt, 64, 48).unwrap();
    let parcels = standin::default_field(600.0);
    r.prepare(
        &ctx,
        &FrameInput {
            camera: Camera::from(&CameraConfig::default()),
            parcels: &parcels,
            sun: cfg.sun(),
            time_s: 0.0,
        },
    )
    .unwrap();
    let tex = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: None,
        size: wgpu::Extent3d {
            width: 80,
            height: 40,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: fmt,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    });
    let t = r.render(&ctx, &tex.create_view(&Default::default()));
    assert_eq!(r.size(), (80, 40));
    // bake, shadow, sky, terrain, clouds, tonemap
    assert_eq!(t.passes.len(), 6);
}
