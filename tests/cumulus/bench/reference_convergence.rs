//! The bench's internal render reference converges: rendering it again with
//! half its view step and more than twice its rays per pixel changes it by
//! less than a stated mean FLIP, while the default setting is measurably
//! farther from it (so the check can see sampling error at all). Renders
//! need an adapter: without one the test fails (see `common::gpu` for the
//! opt-in skip).

use crate::common;

use cumulus::bench::accuracy::{
    REFERENCE_SUPERSAMPLE, reference_config, reference_frame, with_step,
};
use cumulus::bench::measure::Repeats;
use cumulus::bench::stats::{mean_flip, rgb};
use cumulus::config::{Camera, CameraConfig, RenderConfig};

/// Output size: tiny for CI on lavapipe (the reference is rendered at 2×
/// and 3× this). units: px
const SIZE: (u32, u32) = (64, 48);

/// Most mean FLIP between the reference and its refinement. Measured
/// 0.026 on llvmpipe at this size with the mipmapped noise (against 0.042
/// for the default setting; 0.031–0.034 with unfiltered noise, 0.0225
/// before the diffusion-like multiple scattering made cloud bodies whiter,
/// where FLIP weighs the same noise more): what is left is the finest noise
/// octaves averaged over only 4 against 9 rays per pixel; 0.04 leaves room for another
/// driver's rounding, and the assertion below that the default is farther
/// keeps the check able to see sampling error.
const CONVERGED_FLIP: f64 = 0.04;

#[test]
fn halving_the_reference_step_and_doubling_its_rays_changes_it_little() {
    let Some(ctx) = common::context("reference convergence test") else {
        return;
    };
    // One compact tower (about 1.5 km across), so every view ray crosses
    // the grid box within the step limit and the finer step really is half.
    let parcels = cumulus::methods::standin::cumulus_field(1, 1500.0, 1200.0, 1.0, 42);
    let camera = Camera::from(&CameraConfig {
        position_m: [0.0, -4500.0, 900.0],
        target_m: [0.0, 0.0, 1700.0],
        vfov_deg: 40.0,
        ..CameraConfig::default()
    });
    let base = RenderConfig::default();
    let sun = base.sun();
    let reps = Repeats {
        warmup: 0,
        measured: 1,
        budget_ms: 0.0,
    };
    let reference = reference_config(&base, false);
    let (a, _) = reference_frame(
        &ctx,
        &reference,
        camera,
        sun,
        &parcels,
        SIZE,
        REFERENCE_SUPERSAMPLE,
        reps,
    )
    .unwrap();
    let finer = with_step(&reference, 0.5 * reference.step_m);
    assert!(finer.step_m * finer.max_steps as f32 >= 5000.0, "{finer:?}");
    let (b, _) = reference_frame(
        &ctx,
        &finer,
        camera,
        sun,
        &parcels,
        SIZE,
        REFERENCE_SUPERSAMPLE + 1,
        reps,
    )
    .unwrap();
    let (d, _) = reference_frame(&ctx, &base, camera, sun, &parcels, SIZE, 1, reps).unwrap();
    let (w, h) = SIZE;
    let refine = mean_flip(&rgb(&a), &rgb(&b), w, h);
    let default = mean_flip(&rgb(&a), &rgb(&d), w, h);
    eprintln!("mean FLIP: reference vs refined {refine:.5}, default vs reference {default:.5}");
    assert!(
        refine < CONVERGED_FLIP,
        "refining the reference changed it by {refine}"
    );
    assert!(
        default > refine,
        "the default ({default}) should be farther from the reference than its refinement ({refine})"
    );
}
