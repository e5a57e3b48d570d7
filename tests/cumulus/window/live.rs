//! The live window under a virtual X server on the CPU adapter:
//! `cumulus watch --screenshot out.png --frames N` captures the whole window
//! (3D view and panel) and exits 0, and the picture has real content.
//!
//! Needs an X display: uses `DISPLAY` when set, else starts its own Xvfb on a
//! free display number. Without either, or without a GPU adapter (Mesa's
//! lavapipe on a machine with no GPU), the tests fail like every GPU test
//! (see `common::gpu`: `CUMULUS_SKIP_GPU_TESTS=1` skips them instead, never
//! under CI=true; CI installs both).

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::{cli, gpu};

/// An Xvfb server this test started; killed when dropped, even on panic.
struct Xvfb {
    child: Child,
    display: String,
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        // SIGTERM first: Xvfb then removes its lock file and socket, so the
        // display number is free again. SIGKILL only if it does not go.
        let _ = Command::new("kill")
            .arg(self.child.id().to_string())
            .status();
        let t0 = Instant::now();
        while t0.elapsed() < Duration::from_secs(5) {
            if let Ok(Some(_)) = self.child.try_wait() {
                return;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn on_path(program: &str) -> bool {
    std::env::var_os("PATH")
        .map(|paths| std::env::split_paths(&paths).any(|d| d.join(program).is_file()))
        .unwrap_or(false)
}

/// Starts Xvfb on a display number it picks itself (`-displayfd`: it writes
/// the number once it accepts connections). Choosing the number here raced
/// when two tests of this binary started servers at once: the loser saw the
/// winner's socket, used its display, and lost it when that test ended.
fn start_xvfb() -> Option<Xvfb> {
    let child = Command::new("Xvfb")
        .args([
            "-displayfd",
            "1",
            "-screen",
            "0",
            "1280x800x24",
            "-nolisten",
            "tcp",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .ok()?;
    // Killed on drop from here on, whatever happens below.
    let mut x = Xvfb {
        child,
        display: String::new(),
    };
    let mut line = String::new();
    BufReader::new(x.child.stdout.take()?)
        .read_line(&mut line)
        .ok()?;
    let n: u32 = line.trim().parse().ok()?;
    x.display = format!(":{n}");
    Some(x)
}

/// The display to use, and the server to keep alive while using it.
fn find_display() -> Result<(String, Option<Xvfb>), &'static str> {
    if let Ok(d) = std::env::var("DISPLAY")
        && !d.is_empty()
    {
        return Ok((d, None));
    }
    if !on_path("Xvfb") {
        return Err("DISPLAY is unset and Xvfb is not installed");
    }
    let x = start_xvfb().ok_or("Xvfb did not start")?;
    Ok((x.display.clone(), Some(x)))
}

/// [`find_display`], or without one what the GPU tests' policy says
/// (a failure, or None when skipping was asked for).
fn display(what: &str) -> Option<(String, Option<Xvfb>)> {
    gpu::require(
        what,
        find_display(),
        "no X display",
        "install Xvfb (Debian/Ubuntu: `apt-get install xvfb xauth`) or set DISPLAY",
    )
}

/// Runs `cumulus watch --screenshot` with `args` on `display` and returns
/// the image; without a GPU adapter, what the GPU tests' policy says (a
/// failure, or None when skipping was asked for).
fn capture(display: &str, args: &[&str], keep_as: &str) -> Option<image::RgbaImage> {
    capture_with_log(display, args, keep_as).map(|(img, _)| img)
}

/// [`capture`], with what the run wrote to stderr.
fn capture_with_log(
    display: &str,
    args: &[&str],
    keep_as: &str,
) -> Option<(image::RgbaImage, String)> {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("window.png");
    let run = cli::run_command(
        cli::command()
            .args(["watch", "--screenshot"])
            .arg(&out)
            .args(args)
            .env("DISPLAY", display)
            .env_remove("WAYLAND_DISPLAY"),
    );
    if !run.succeeded() && run.stderr().contains("no GPU adapter") {
        let what = format!("window test ({keep_as})");
        gpu::require::<(), _>(&what, Err(run.stderr()), "no GPU adapter", gpu::ADAPTER_FIX);
        return None;
    }
    let stderr = run.expect_success();
    // Keep the capture for a look when asked (CUMULUS_KEEP_SCREENSHOTS=dir).
    if let Some(k) = std::env::var_os("CUMULUS_KEEP_SCREENSHOTS") {
        std::fs::copy(&out, Path::new(&k).join(keep_as)).unwrap();
    }
    Some((image::open(&out).expect("a PNG").to_rgba8(), stderr))
}

/// Left edge of the 3D view in the capture: the panel is 380 points wide
/// (scale factor 1 under Xvfb); a margin keeps its border out.
const VIEW_X0: u32 = 420;

/// Pixels of the 3D view where the clouds change the picture: `img`
/// against `clear`, the same window, scene, time and camera with
/// `--set render.clouds=false`. The atmosphere model's hazy horizon is
/// nearly white, so brightness alone cannot tell cloud from sky; the
/// difference can (a summed 8-bit change of 30 is well above the
/// dithering and the temporal jitter's few levels).
fn cloud_pixels(img: &image::RgbaImage, clear: &image::RgbaImage) -> u32 {
    let (w, h) = img.dimensions();
    assert_eq!(clear.dimensions(), (w, h));
    let mut n = 0;
    for y in 0..h {
        for x in VIEW_X0..w {
            let (p, q) = (img.get_pixel(x, y), clear.get_pixel(x, y));
            let d: i32 = (0..3).map(|c| (p[c] as i32 - q[c] as i32).abs()).sum();
            if d > 30 {
                n += 1;
            }
        }
    }
    n
}

/// Three frames of the 900×560 window after `warmup` simulated seconds,
/// with or without clouds (`--set render.clouds=false`), for
/// [`cloud_pixels`]; the adapter must be there (an earlier capture found it).
fn window(display: &str, warmup: &str, clouds: bool, name: &str) -> image::RgbaImage {
    let extra: &[&str] = if clouds {
        &[]
    } else {
        &["--set", "render.clouds=false"]
    };
    capture(display, &args("3", warmup, extra), name).expect("the adapter was there a moment ago")
}

/// `watch` arguments: `frames` frames of the 900×560 window after `warmup`
/// simulated seconds, then `extra`.
fn args<'a>(frames: &'a str, warmup: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut a = vec![
        "--frames", frames, "--warmup", warmup, "--width", "900", "--height", "560",
    ];
    a.extend(extra);
    a
}

#[test]
fn screenshot_shows_panel_and_clouds() {
    let Some((display, _xvfb)) = display("window screenshot") else {
        return;
    };
    // Small window (the CPU adapter is slow), a few frames, and ten minutes
    // of simulated warm-up so that clouds have formed.
    let Some(img) = capture(&display, &args("3", "600", &[]), "window.png") else {
        return;
    };
    let (w, h) = img.dimensions();
    assert_eq!((w, h), (900, 560), "the capture is the whole window");

    // Not a blank window: text, plot lines and shading give thousands of
    // colours; a cleared or single-colour frame has one or two.
    let mut colours = std::collections::HashSet::new();
    for p in img.pixels() {
        colours.insert([p[0], p[1], p[2]]);
    }

    // The panel (dark egui theme, left 380 points) differs from the 3D view.
    let mean = |x0: u32, x1: u32| {
        let mut s = [0f64; 3];
        let mut n = 0f64;
        for y in 0..h {
            for x in x0..x1 {
                let p = img.get_pixel(x, y);
                for c in 0..3 {
                    s[c] += p[c] as f64;
                }
                n += 1.0;
            }
        }
        s.map(|v| v / n)
    };
    let panel = mean(0, 360);
    let view = mean(VIEW_X0, w);
    let diff: f64 = (0..3).map(|c| (panel[c] - view[c]).abs()).sum();
    let cloud = cloud_pixels(
        &img,
        &window(&display, "600", false, "window-no-clouds.png"),
    );
    let area = (w - VIEW_X0) * h;
    eprintln!(
        "{} colours, panel {panel:?} vs view {view:?}, {cloud} cloud pixels of {area}",
        colours.len()
    );
    assert!(
        colours.len() > 200,
        "only {} distinct colours",
        colours.len()
    );
    // Mean 8-bit colours: a dark panel against sky and ground differs by far
    // more than 60 summed over channels; the same content would differ by ~0.
    assert!(diff > 60.0, "panel {panel:?} vs view {view:?}");
    // Clouds: at least 0.1% of the view (a few small cumulus several km
    // away cover ~0.5% here).
    assert!(cloud * 1000 > area, "{cloud} cloud pixels of {area}");

    // And the cloud count means cloud: at t = 0 nothing has condensed yet,
    // so the same comparison finds (next to) nothing.
    let clear_cloud = cloud_pixels(
        &window(&display, "0", true, "window-clear.png"),
        &window(&display, "0", false, "window-clear-no-clouds.png"),
    );
    // 0.02% allows a few pixels of the panel's live numbers spilling over.
    assert!(
        clear_cloud * 5000 < area,
        "{clear_cloud} cloud pixels in a clear sky"
    );
}

/// Device loss: `--lose-device-after 2` destroys the device after frame 2
/// (`wgpu::Device::destroy`, which reports it lost with reason Destroyed,
/// as a driver reset would with its own reason). The window must say so,
/// make a new device, and go on drawing clouds: the capture at frame 4 comes
/// from the new device.
#[test]
fn a_lost_device_is_reported_and_replaced() {
    let Some((display, _xvfb)) = display("window device loss") else {
        return;
    };
    let Some((img, log)) = capture_with_log(
        &display,
        &args("4", "600", &["--lose-device-after", "2"]),
        "window-device-lost.png",
    ) else {
        return;
    };
    assert!(
        log.contains("GPU device lost (Destroyed") && log.contains("recreated it"),
        "no recovery message:\n{log}"
    );
    // Two devices were opened: the first and its replacement.
    assert_eq!(log.matches("GPU: ").count(), 2, "{log}");
    let area = (img.width() - VIEW_X0) * img.height();
    let cloud = cloud_pixels(
        &img,
        &window(&display, "600", false, "window-no-clouds.png"),
    );
    // As in screenshot_shows_panel_and_clouds: at least 0.1% of the view.
    assert!(
        cloud * 1000 > area,
        "{cloud} cloud pixels of {area} after the recovery"
    );
}

/// The window's 3D view and `cumulus render` of the same scene, camera,
/// sun and simulated time give the same image: both draw through the one
/// `Renderer::render` path (HDR scene target, one tone map). The window
/// runs one counted frame after a 600 s warm-up (the clock then reads
/// 600 + 1/3 s, which it prints) with temporal amortisation off, so both
/// march every pixel; the 3D view is cut out of the capture where the
/// window says it is, and `render` draws that size at that time.
/// Bound: mean FLIP 0.02. The same frame drawn twice is identical; what
/// remains is the physics' last step (the window steps 1/3 s from 600 s,
/// `render` the same 1/3 s up to the printed time, rounded to 1 µs) and
/// the window's orbit camera rebuilding the eye from yaw, pitch and
/// distance (float round-off of the ray directions); a different tone map
/// or a display-space composite (what the two paths once had) gives 0.1
/// and more.
#[test]
fn window_and_headless_draw_the_same_image() {
    let Some((display, _xvfb)) = display("window against headless") else {
        return;
    };
    let Some((img, log)) = capture_with_log(
        &display,
        &args("1", "600", &["--set", "render.temporal=false"]),
        "window-vs-headless.png",
    ) else {
        return;
    };
    // "…; 3D view at x = X, W×H; t = T s)"
    let tail = log
        .split("3D view at x = ")
        .nth(1)
        .unwrap_or_else(|| panic!("no 3D view rectangle in the log:\n{log}"));
    let (x0, rest) = tail.split_once(", ").unwrap();
    let (size, rest) = rest.split_once("; t = ").unwrap();
    let (w, h) = size.split_once('×').unwrap();
    let t = rest.split_once(' ').unwrap().0;
    let (x0, w, h): (u32, u32, u32) = (x0.parse().unwrap(), w.parse().unwrap(), h.parse().unwrap());
    assert!(x0 + w <= img.width() && h <= img.height(), "{log}");
    let view = image::imageops::crop_imm(&img, x0, 0, w, h).to_image();

    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("headless.png");
    cli::run_command(
        cli::command()
            .args(["render", "--no-labels", "--time", t, "--width"])
            .arg(w.to_string())
            .arg("--height")
            .arg(h.to_string())
            .arg("--out")
            .arg(&out),
    )
    .expect_success();
    let headless = image::open(&out).unwrap().to_rgba8();
    let rgb =
        |i: &image::RgbaImage| -> Vec<u8> { i.pixels().flat_map(|p| [p[0], p[1], p[2]]).collect() };
    let flip = cumulus::bench::stats::mean_flip(&rgb(&headless), &rgb(&view), w, h);
    if let Some(k) = std::env::var_os("CUMULUS_KEEP_SCREENSHOTS") {
        view.save(Path::new(&k).join("window-view.png")).unwrap();
        std::fs::copy(&out, Path::new(&k).join("headless-view.png")).unwrap();
    }
    eprintln!("window 3D view ({w}×{h} at x = {x0}) vs headless at t = {t} s: mean FLIP {flip:.4}");
    assert!(
        flip < 0.02,
        "window and headless differ: mean FLIP {flip:.4}"
    );
}

/// `watch --screenshot` on wgpu's OpenGL backend (`WGPU_BACKEND=gl`,
/// Mesa's llvmpipe OpenGL under Xvfb in CI) with `extra` arguments.
fn capture_gl(display: &str, extra: &[&str], dir: &Path, name: &str) -> cli::Run {
    cli::run_command(
        cli::command()
            .args(["watch", "--screenshot"])
            .arg(dir.join(name))
            .args(args("3", "600", extra))
            .env("DISPLAY", display)
            .env("WGPU_BACKEND", "gl")
            .env_remove("WAYLAND_DISPLAY"),
    )
}

/// The window on OpenGL: the instance is given the window's display (which
/// OpenGL needs to present), the default method GL cannot run is replaced
/// by one it can, said on stderr (and in the panel), and the picture has
/// clouds. Without an OpenGL adapter: the GPU tests' policy (CI installs
/// Mesa's EGL and GL).
#[test]
fn the_window_draws_clouds_on_opengl() {
    let Some((display, _xvfb)) = display("window on OpenGL") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let run = capture_gl(&display, &[], dir.path(), "gl.png");
    if !run.succeeded() && run.stderr().contains("no GPU adapter") {
        gpu::require::<(), _>(
            "window test on OpenGL",
            Err(run.stderr()),
            "no OpenGL adapter",
            "install Mesa's OpenGL (Debian/Ubuntu: `apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri`)",
        );
        return;
    }
    let stderr = run.expect_success();
    assert!(stderr.contains("; Gl;"), "{stderr}");
    assert!(
        stderr.contains("note: drawing with the exact method"),
        "{stderr}"
    );
    capture_gl(
        &display,
        &["--set", "render.clouds=false"],
        dir.path(),
        "clear.png",
    )
    .expect_success();
    let open = |n: &str| image::open(dir.path().join(n)).unwrap().to_rgba8();
    let (img, clear) = (open("gl.png"), open("clear.png"));
    let area = (img.width() - VIEW_X0) * img.height();
    let cloud = cloud_pixels(&img, &clear);
    // As on Vulkan (screenshot_shows_panel_and_clouds): at least 0.1 % of
    // the view is cloud after ten minutes.
    assert!(cloud * 1000 > area, "{cloud} cloud pixels of {area}");
}
