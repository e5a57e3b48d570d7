//! Temporal upscaling and flying through clouds, on the CPU adapter
//! (lavapipe) at small sizes, on the window's default path (1 pixel in 16
//! per frame, `temporal = "4x4"`) unless a test says otherwise:
//! - a still camera: the accumulated image converges to the
//!   full-resolution march (mean FLIP), at 4×4 and 2×2;
//! - a moving camera: after the move the image matches the full march at
//!   the same camera (no ghosts of where the clouds were on screen);
//! - clouds that jump away: their old place does not linger;
//! - a camera path through a cloud: no jump of mean luminance between
//!   frames (rays start at the near plane; clouds end at the terrain), and
//!   with temporal on, no ghost of the cloud once the camera has left it;
//! - a scripted flight past the clouds: every frame near the full march;
//! - a time-lapse of growing clouds: no smearing behind the change.
//!
//! The scene is the deterministic stand-in field (src/methods/standin.rs)
//! with the default render settings, baked method.

use crate::common;

use cumulus::bench::stats::{mean_flip, rgb};
use cumulus::config::{Camera, CameraConfig, RenderConfig, TemporalMode};
use cumulus::methods::standin;
use cumulus::physics::CloudParcel;
use cumulus::render::headless::Headless;
use cumulus::render::{FrameInput, GpuContext};
use glam::Vec3;

const W: u32 = 160;
const H: u32 = 120;

fn cfg(temporal: TemporalMode) -> RenderConfig {
    RenderConfig {
        temporal: Some(temporal),
        ..RenderConfig::default()
    }
}

/// The window's default path.
const ON: TemporalMode = TemporalMode::Block4;

fn input<'a>(camera: Camera, parcels: &'a [CloudParcel]) -> FrameInput<'a> {
    FrameInput {
        camera,
        parcels,
        sun: RenderConfig::default().sun(),
        time_s: 900.0,
    }
}

/// The full-resolution march of one frame (RGB8).
fn full(ctx: &GpuContext, camera: Camera, parcels: &[CloudParcel], w: u32, h: u32) -> Vec<u8> {
    let mut hl = Headless::new(ctx, &cfg(TemporalMode::Off), w, h).unwrap();
    assert!(!hl.renderer.pass_names().contains(&"temporal"));
    rgb(&hl.render(ctx, &input(camera, parcels)).unwrap().0)
}

fn stand_in_camera() -> Camera {
    Camera::from(&CameraConfig::default())
}

/// Still camera and clouds: after two rounds of the block (32 frames at
/// 4×4, every pixel marched twice over two ray-start jitters; 16 frames at
/// 2×2, four times) the accumulated image is within mean FLIP 0.01 of the
/// full-resolution march (issue 34), and clearly closer than a single
/// frame. Measured on lavapipe: 4×4 0.0039 after 32 frames (0.023 after
/// one), 2×2 0.0013 after 16 (0.012 after one). 0.01: what remains is the
/// full march's own banding from its one fixed jitter per pixel, which
/// the accumulated image averages away, and the clip's softening of
/// one-pixel detail between a pixel's own samples.
#[test]
fn still_camera_converges_to_the_full_resolution_march() {
    let Some(ctx) = common::context("temporal convergence") else {
        return;
    };
    let parcels = standin::default_field(900.0);
    let camera = stand_in_camera();
    let reference = full(&ctx, camera, &parcels, W, H);

    for (mode, frames) in [(TemporalMode::Block4, 32), (TemporalMode::Block2, 16)] {
        let mut hl = Headless::new(&ctx, &cfg(mode), W, H).unwrap();
        let (one, _) = hl.render(&ctx, &input(camera, &parcels)).unwrap();
        assert!(hl.renderer.pass_names().contains(&"temporal"));
        let flip_one = mean_flip(&reference, &rgb(&one), W, H);
        let (last, _) = hl
            .render_after(&ctx, &input(camera, &parcels), frames - 2)
            .unwrap();
        assert_eq!(hl.renderer.temporal_frames(), frames);
        let flip = mean_flip(&reference, &rgb(&last), W, H);
        let name = mode.name();
        eprintln!(
            "{name}: mean FLIP vs full march: 1 frame {flip_one:.4}, {frames} frames {flip:.4}"
        );
        assert!(
            flip < 0.01,
            "{name}, {frames} frames: mean FLIP {flip:.4} ≥ 0.01"
        );
        // The accumulation must do something: one frame has 15/16 (3/4) of
        // its pixels interpolated from the marched ones.
        assert!(
            flip < 0.7 * flip_one,
            "{name}: {frames} frames ({flip:.4}) not clearly better than one ({flip_one:.4})"
        );
    }
}

/// The camera orbits and climbs for 12 frames (1.5° and 40 m a frame: a
/// quick pan that moves the clouds ~5 px a frame at 160×120); the frame
/// after the move is compared with the full march at that camera.
/// Measured on lavapipe (4×4): 0.022, against 0.26 for the view before
/// the move (what a frame made of stale history would cost). Bound 0.05
/// (issue 34): the pixels uncovered by the move (at the image edge and
/// beside the clouds) have one or two marched samples or only the fresh
/// estimate, and the clip softens the rest while the view moves; a ghost
/// of the clouds' old place costs several times more.
#[test]
fn moving_camera_does_not_ghost() {
    let Some(ctx) = common::context("temporal moving camera") else {
        return;
    };
    let parcels = standin::default_field(900.0);
    let start = stand_in_camera();
    let at = |k: f32| {
        let offset = start.position - start.target;
        let rot = glam::Quat::from_rotation_z((1.5 * k).to_radians());
        Camera {
            position: start.target + rot * offset + Vec3::Z * 40.0 * k,
            ..start
        }
    };
    let mut hl = Headless::new(&ctx, &cfg(ON), W, H).unwrap();
    // History of the still camera first, so the move starts from a
    // converged image of another view (the worst case for ghosts).
    hl.render_after(&ctx, &input(at(0.0), &parcels), 7).unwrap();
    let mut last = Vec::new();
    for k in 1..=12 {
        last = hl.render(&ctx, &input(at(k as f32), &parcels)).unwrap().0;
    }
    let reference = full(&ctx, at(12.0), &parcels, W, H);
    let flip = mean_flip(&reference, &rgb(&last), W, H);
    // What a ghost would cost: the frame before the move against the
    // frame after it.
    let before = full(&ctx, at(0.0), &parcels, W, H);
    let ghost = mean_flip(&reference, &before, W, H);
    eprintln!("after the move: mean FLIP {flip:.4} (the view before the move: {ghost:.4})");
    assert!(flip < 0.05, "mean FLIP {flip:.4} ≥ 0.05 after the move");
}

/// Clouds jump 1.5 km east between two frames (a scene edit, or clouds
/// far faster than any wind), after a round of history of the old place:
/// 8 frames later (half the pixels marched since) the image is within
/// mean FLIP 0.05 of the full march of the new field (issue 34: caught
/// within 8 frames; 0.05 as for a camera move), and no further from it
/// than 8 frames of the new field alone (a fresh history, which has the
/// same unmarched pixels) plus a quarter of the distance between the old
/// field's and the new field's full marches: the old clouds do not
/// linger (a ghost that stays adds most of the latter; the quarter is for
/// the edges of the new clouds, whose pixels keep a clipped history of
/// the old sky until marched). Measured on lavapipe: 0.027 after the jump,
/// 0.013 for the new field alone, 0.076 old field against new (with the
/// history never clipped: 0.046).
#[test]
fn clouds_that_jump_away_leave_no_trail() {
    let Some(ctx) = common::context("temporal cloud jump") else {
        return;
    };
    let camera = stand_in_camera();
    let before = standin::default_field(900.0);
    let after: Vec<CloudParcel> = before
        .iter()
        .map(|p| CloudParcel {
            center_m: p.center_m + Vec3::X * 1500.0,
            ..*p
        })
        .collect();
    let reference = full(&ctx, camera, &after, W, H);

    let mut still = Headless::new(&ctx, &cfg(ON), W, H).unwrap();
    let (s, _) = still.render_after(&ctx, &input(camera, &after), 7).unwrap();
    let flip_still = mean_flip(&reference, &rgb(&s), W, H);

    let mut hl = Headless::new(&ctx, &cfg(ON), W, H).unwrap();
    hl.render_after(&ctx, &input(camera, &before), 15).unwrap();
    let (j, _) = hl.render_after(&ctx, &input(camera, &after), 7).unwrap();
    let flip_jump = mean_flip(&reference, &rgb(&j), W, H);
    let ghost = mean_flip(&reference, &full(&ctx, camera, &before, W, H), W, H);
    eprintln!(
        "8 frames after the jump: {flip_jump:.4}; 8 frames of the still field: {flip_still:.4}; \
         old field against new: {ghost:.4}"
    );
    assert!(
        flip_jump < 0.05,
        "8 frames after the jump: mean FLIP {flip_jump:.4} ≥ 0.05"
    );
    assert!(
        flip_jump < flip_still + 0.25 * ghost,
        "the old clouds linger: mean FLIP {flip_jump:.4} against {flip_still:.4} for 8 frames \
         of the new field alone and {ghost:.4} for the old field"
    );
}

/// The stand-in field and a straight path through the middle of its first
/// tower: (parcels, the tower's centroid, the flight direction).
fn tower_path() -> (Vec<CloudParcel>, Vec3, Vec3) {
    let parcels = standin::default_field(900.0);
    // The tower of the first parcel: its parcels' centroid.
    let first = parcels[0];
    let tower: Vec<&CloudParcel> = parcels
        .iter()
        .filter(|p| p.cond_plane_z_m == first.cond_plane_z_m)
        .filter(|p| (p.center_m - first.center_m).truncate().length() < 1500.0)
        .collect();
    let centre = tower.iter().map(|p| p.center_m).sum::<Vec3>() / tower.len() as f32;
    let dir = Vec3::new(0.3, 1.0, 0.0).normalize();
    (parcels, centre, dir)
}

/// Mean Rec. 709 luma of an sRGB-encoded RGBA8 image, 0..1.
fn mean_luma(rgba: &[u8]) -> f64 {
    let n = rgba.len() / 4;
    rgba.chunks_exact(4)
        .map(|p| (0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64) / 255.0)
        .sum::<f64>()
        / n as f64
}

/// The camera flies straight through the middle of a tower (3 km at 25 m
/// a frame, looking ahead), full-resolution march, 64×48, and the mean
/// luma of each frame is taken. Over the path it changes by more than
/// 0.06 (on 0..1: the camera does enter and leave the cloud). Where two
/// frames differ most, the same 25 m are flown again at 2.5 m a frame: a
/// continuous change (the view clearing as the cloud left ahead thins,
/// steep because its mean free path is ~35 m) shrinks with the step, so
/// the largest fine step must be under 0.35× the coarse one (a change
/// spread evenly would give 0.1×); a pop (rays starting behind the near
/// plane, a skipped first sample, a cloud culled once the eye is inside
/// its box) happens between two positions whatever the step, and keeps
/// its whole size. Measured on lavapipe: the largest 25 m step is 0.11
/// (leaving the tower: ~1.0, all cloud, to 0.77, sky and ground), whose
/// largest 2.5 m step is 0.013 (0.11×).
#[test]
fn flying_through_a_cloud_does_not_pop() {
    let Some(ctx) = common::context("fly-through") else {
        return;
    };
    let (parcels, centre, dir) = tower_path();
    let (w, h) = (64, 48);
    let mut hl = Headless::new(&ctx, &cfg(TemporalMode::Off), w, h).unwrap();
    let mut luma_at = |along_m: f32| {
        let position = centre + dir * along_m;
        let camera = Camera {
            position,
            target: position + dir * 1000.0,
            ..stand_in_camera()
        };
        mean_luma(&hl.render(&ctx, &input(camera, &parcels)).unwrap().0)
    };
    let largest_step = |lumas: &[f64]| {
        lumas
            .windows(2)
            .map(|p| (p[1] - p[0]).abs())
            .enumerate()
            .fold(
                (0, 0.0),
                |best, (i, d)| if d > best.1 { (i, d) } else { best },
            )
    };
    let coarse: Vec<f64> = (0..=120)
        .map(|k| luma_at(-1500.0 + 25.0 * k as f32))
        .collect();
    let (k, coarse_step) = largest_step(&coarse);
    let range = coarse.iter().cloned().fold(f64::MIN, f64::max)
        - coarse.iter().cloned().fold(f64::MAX, f64::min);
    let fine: Vec<f64> = (0..=10)
        .map(|j| luma_at(-1500.0 + 25.0 * k as f32 + 2.5 * j as f32))
        .collect();
    let (_, fine_step) = largest_step(&fine);
    eprintln!(
        "mean luma along the path: {coarse:.3?}; range {range:.3}; largest 25 m step {coarse_step:.4} \
         after {k} steps, refined to 2.5 m: {fine:.3?}, largest {fine_step:.4}"
    );
    assert!(
        range > 0.06,
        "the path never entered a cloud (luma range {range:.3})"
    );
    assert!(
        fine_step < 0.35 * coarse_step,
        "a pop: the luma step {coarse_step:.4} over 25 m keeps {fine_step:.4} over 2.5 m"
    );
}

/// The window's default path (temporal on) flying through the same tower
/// as above, 25 m a frame with the history kept all the way: every 10th
/// frame is compared with the full march at that camera. Inside the cloud
/// and out of it again, a reprojected history that was not rejected (the
/// tower's white still on screen after the camera left it: a ghost) would
/// make a frame look like the view some frames before. Measured on
/// lavapipe, 96×72, 4×4: 0.034–0.118 against the full march (0.05
/// typical: flying forward 25 m a frame near clouds, pixels keep one or
/// two marched samples and the clip softens the rest, as in
/// `moving_camera_does_not_ghost`), where a 4-frame-old view would cost
/// 0.046–0.52. The largest of those, 0.52, is the frame after the camera
/// leaves the tower (the old view is all cloud); there the temporal frame
/// measured 0.118, most of it the fresh estimate of a view that is new
/// everywhere (1 pixel in 16 marched; 0.080 at 2×2; 0.120 when every
/// history was clipped to the box, not only a rejected one). Bounds: every
/// checkpoint under 0.16 (1.3× the largest measured, for other drivers),
/// and at the exit under a quarter of what the stale view costs (a ghost
/// of the cloud's white keeps most of it: 0.23 with the history never
/// clipped, 0.45 of it; measured 0.23 of it).
#[test]
fn flying_through_a_cloud_with_temporal_on_leaves_no_ghost() {
    let Some(ctx) = common::context("temporal fly-through") else {
        return;
    };
    let (parcels, centre, dir) = tower_path();
    let (w, h) = (96, 72);
    let camera_at = |k: usize| {
        let position = centre + dir * (-1500.0 + 25.0 * k as f32);
        Camera {
            position,
            target: position + dir * 1000.0,
            ..stand_in_camera()
        }
    };
    let mut hl = Headless::new(&ctx, &cfg(ON), w, h).unwrap();
    // (frame, FLIP against the full march, FLIP of a 4-frame-old view).
    let mut report: Vec<(usize, f64, f64)> = Vec::new();
    for k in 0..=120 {
        let (img, _) = hl.render(&ctx, &input(camera_at(k), &parcels)).unwrap();
        if k % 10 != 0 || k < 10 {
            continue;
        }
        let full_now = full(&ctx, camera_at(k), &parcels, w, h);
        let flip = mean_flip(&full_now, &rgb(&img), w, h);
        // What a ghost of 4 frames (100 m) back would cost here.
        let stale = mean_flip(
            &full_now,
            &full(&ctx, camera_at(k - 4), &parcels, w, h),
            w,
            h,
        );
        report.push((k, flip, stale));
    }
    eprintln!("(frame, mean FLIP against the full march, a 4-frame-old view): {report:.4?}");
    for &(k, flip, _) in &report {
        assert!(
            flip < 0.16,
            "frame {k}: mean FLIP {flip:.4} ≥ 0.16 against the full march"
        );
    }
    let exit = report.iter().max_by(|a, b| a.2.total_cmp(&b.2)).unwrap();
    assert!(
        exit.2 > 0.3,
        "the path never left a cloud (largest stale-view FLIP {:.4})",
        exit.2
    );
    assert!(
        exit.1 < 0.25 * exit.2,
        "a ghost on leaving the cloud (frame {}): {:.4} against {:.4} for the stale view",
        exit.0,
        exit.1,
        exit.2
    );
}

/// The scripted flight (issue 34, "Done when"): after the window's
/// history of the still view has converged (32 frames), the camera orbits
/// the stand-in field by 0.75° and closes in by 20 m every frame for 48
/// frames (the clouds move ~2–3 px a frame at 96×72), and every frame of
/// the path is compared with the full march at the same camera: all
/// within mean FLIP 0.05 (the bound). A ghost is what a stale view
/// costs: the frame 4 frames back is printed beside some (a smeared
/// history would keep part of it). Measured on lavapipe: 0.012 on the
/// first frame of the path, rising to 0.035 (frame 45) as the clouds grow
/// on screen; a 4-frame-old view costs 0.088–0.106.
#[test]
fn a_scripted_flight_stays_near_the_full_march_every_frame() {
    let Some(ctx) = common::context("temporal scripted flight") else {
        return;
    };
    let parcels = standin::default_field(900.0);
    let (w, h) = (96, 72);
    let start = stand_in_camera();
    let at = |k: f32| {
        let offset = start.position - start.target;
        let rot = glam::Quat::from_rotation_z((0.75 * k).to_radians());
        let closer = offset.normalize() * 20.0 * k;
        Camera {
            position: start.target + rot * (offset - closer),
            ..start
        }
    };
    let mut hl = Headless::new(&ctx, &cfg(ON), w, h).unwrap();
    hl.render_after(&ctx, &input(at(0.0), &parcels), 31)
        .unwrap();
    let mut worst = (0, 0.0);
    let mut flips = Vec::new();
    let mut stale = Vec::new();
    for k in 1..=48 {
        let (img, _) = hl.render(&ctx, &input(at(k as f32), &parcels)).unwrap();
        let reference = full(&ctx, at(k as f32), &parcels, w, h);
        let flip = mean_flip(&reference, &rgb(&img), w, h);
        if k % 12 == 0 {
            let old = full(&ctx, at(k as f32 - 4.0), &parcels, w, h);
            stale.push((k, mean_flip(&reference, &old, w, h)));
        }
        if flip > worst.1 {
            worst = (k, flip);
        }
        flips.push(flip);
    }
    eprintln!(
        "flight: mean FLIP per frame {flips:.4?}; worst {:.4} at frame {}; a 4-frame-old view: {stale:.4?}",
        worst.1, worst.0
    );
    assert!(
        worst.1 < 0.05,
        "frame {}: mean FLIP {:.4} ≥ 0.05",
        worst.0,
        worst.1
    );
}

/// A time-lapse at 120× (4 s of cloud time a frame: 120× at 30 frames a
/// second) with a still camera: the stand-in clouds grow (their fill and
/// their columns, from 5 to 9 minutes of growth) and drift with a 15 m/s
/// wind (60 m a frame), and after 32 frames every 8th frame up to 64 is
/// compared with the full march of the field at that time: all within
/// mean FLIP 0.05 (issue 34: the same bounds as a camera move). A history
/// that lags (smearing) shows the clouds of some frames back; a view 24
/// frames (96 s, 1.4 km of drift) old must cost more than the bound, or
/// the test could not see such a lag. Measured on lavapipe:
/// 0.026–0.029 against the full march, 0.056–0.060 for the 24-frame-old
/// view (what is left at 0.025 is the still view's convergence at 96×72,
/// coarser than at 160×120).
#[test]
fn a_time_lapse_does_not_smear() {
    let Some(ctx) = common::context("temporal time-lapse") else {
        return;
    };
    let camera = stand_in_camera();
    let (w, h) = (96, 72);
    let field = |k: u32| {
        let drift = Vec3::X * 60.0 * k as f32;
        let grown = standin::default_field(300.0 + 4.0 * k as f32);
        grown
            .into_iter()
            .map(|p| CloudParcel {
                center_m: p.center_m + drift,
                ..p
            })
            .collect::<Vec<_>>()
    };
    let mut hl = Headless::new(&ctx, &cfg(ON), w, h).unwrap();
    let mut report = Vec::new();
    for k in 0..=64 {
        let parcels = field(k);
        let (img, _) = hl.render(&ctx, &input(camera, &parcels)).unwrap();
        if k < 32 || k % 8 != 0 {
            continue;
        }
        let reference = full(&ctx, camera, &parcels, w, h);
        let flip = mean_flip(&reference, &rgb(&img), w, h);
        let old = full(&ctx, camera, &field(k - 24), w, h);
        report.push((k, flip, mean_flip(&reference, &old, w, h)));
    }
    eprintln!("(frame, mean FLIP against the full march, a 24-frame-old view): {report:.4?}");
    for &(k, flip, old) in &report {
        assert!(
            old > 0.05,
            "frame {k}: the clouds barely changed in 24 frames ({old:.4})"
        );
        assert!(
            flip < 0.05,
            "frame {k}: mean FLIP {flip:.4} ≥ 0.05 against the full march"
        );
    }
}
