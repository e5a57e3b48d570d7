//! On wgpu's OpenGL backend (`WGPU_BACKEND=gl`, Mesa's llvmpipe OpenGL in
//! CI): `render` draws clouds with a method GL can run and says so, the
//! method it cannot run exits 2 naming the adapter, what it lacks and the
//! fix, and nothing panics. Without an OpenGL adapter the test prints a
//! notice and passes, unless CI=true (.ci/run installs Mesa's EGL/GL).

use crate::common::cli;

/// `cumulus render` on the GL backend with `args`, 96×54, into `out`.
fn render_gl(out: &std::path::Path, args: &[&str]) -> cli::Run {
    cli::run_command(
        cli::command()
            .env("WGPU_BACKEND", "gl")
            .args(["render", "--width", "96", "--height", "54"])
            .args(args)
            .arg("--out")
            .arg(out),
    )
}

/// Whether a GL adapter answered (else the run names none).
fn gl_adapter(run: &cli::Run) -> bool {
    if run.stderr().contains("no GPU adapter") {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "CI=true needs Mesa's OpenGL (libegl1 libegl-mesa0 libgl1-mesa-dri): {}",
            run.stderr()
        );
        eprintln!("NOTICE: skipping the OpenGL test: no OpenGL adapter");
        return false;
    }
    true
}

#[test]
fn opengl_renders_clouds_with_a_method_it_can_run_and_refuses_the_other() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("gl.png");
    let run = render_gl(&png, &[]);
    if !gl_adapter(&run) {
        return;
    }
    let stderr = run.expect_success();
    assert!(stderr.contains("Gl"), "{stderr}");
    // The default (baked) cannot draw on GL: the exact method does, and
    // the note says so.
    assert!(
        stderr.contains("note: drawing with the exact method"),
        "{stderr}"
    );
    // Clouds: bright, nearly grey pixels in the upper half of the frame
    // (the sky there is blue, the ground below green).
    let img = image::open(&png).unwrap().into_rgb8();
    let cloudy = img
        .enumerate_pixels()
        .filter(|(_, y, p)| {
            let [r, g, b] = p.0.map(i32::from);
            *y < img.height() / 2 && r.min(g).min(b) > 180 && r.max(g).max(b) - r.min(g).min(b) < 30
        })
        .count();
    let half = (img.width() * img.height() / 2) as usize;
    assert!(cloudy > half / 50, "{cloudy} cloud pixels of {half}");
    // Asked for by name, the method GL cannot run exits 2 with the fix.
    let run = render_gl(&dir.path().join("baked.png"), &["--method", "baked"]);
    let stderr = run.expect_failure_containing(&[
        "the baked method cannot draw on",
        "Gl",
        "--method exact",
        "mesa-vulkan-drivers",
    ]);
    assert_eq!(run.output.status.code(), Some(2), "{stderr}");
    assert!(!dir.path().join("baked.png").exists());
    // The other methods draw on GL as asked.
    for m in ["sprites", "slices"] {
        render_gl(&dir.path().join(format!("{m}.png")), &["--method", m]).expect_success();
    }
}

/// The bench on GL either writes its report or stops with exit 2 naming
/// the method and what GL lacks (its scaling table and the landscape
/// measure the baked ray-march, which GL cannot run) and the fix; never a
/// panic, and nothing half-written.
#[test]
fn the_bench_on_opengl_reports_or_names_what_it_lacks() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    let run = cli::run_command(
        cli::command()
            .env("WGPU_BACKEND", "gl")
            .args(["bench", "--tiny", "--out"])
            .arg(&out),
    );
    if !gl_adapter(&run) {
        return;
    }
    if run.succeeded() {
        run.expect_success();
        assert!(out.join("report.md").is_file());
    } else {
        let stderr =
            run.expect_failure_containing(&["cannot draw on", "Gl", "mesa-vulkan-drivers"]);
        assert_eq!(run.output.status.code(), Some(2), "{stderr}");
        assert!(!out.join("report.md").exists());
    }
}
