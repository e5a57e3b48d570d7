//! `examples/embed.rs`, the cloud renderer inside another wgpu program,
//! run as a user runs it (`cargo run --release --example embed -- --out
//! x.png`): it writes a PNG of the asked size whose clouds cover part of
//! the program's own background.

use crate::common;

/// The example's binary, which `cargo test` builds beside the test
/// binaries (target/<profile>/examples/embed).
fn example() -> std::path::PathBuf {
    let exe = std::env::current_exe().unwrap();
    let profile_dir = exe.parent().and_then(|d| d.parent()).unwrap();
    let path = profile_dir
        .join("examples")
        .join(format!("embed{}", std::env::consts::EXE_SUFFIX));
    assert!(path.exists(), "{} not built", path.display());
    path
}

#[test]
fn the_embed_example_draws_clouds_over_its_own_background() {
    if common::context("embed example test").is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("embed.png");
    let stderr = common::cli::run_command(
        std::process::Command::new(example())
            .args(["--width", "160", "--height", "90", "--out"])
            .arg(&out),
    )
    .expect_success();
    let img = image::open(&out).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (160, 90));
    // The background is one colour (the program's clear); the clouds are
    // whiter. A pixel counts as cloud when it is 10 levels off the
    // background in any channel (8-bit quantisation is 1 level).
    let bg = *img.get_pixel(0, 0);
    let cloudy = img
        .pixels()
        .filter(|p| (0..3).any(|c| (p[c] as i32 - bg[c] as i32).abs() > 10))
        .count();
    let share = cloudy as f64 / (160.0 * 90.0);
    // The default scene at its start time fills part of this view with
    // cumulus: more than 2 % of the frame, and not all of it.
    assert!(
        share > 0.02 && share < 0.9,
        "cloud share {share:.3}\n{stderr}"
    );
}
