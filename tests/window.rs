//! The live window under a virtual X server on the CPU adapter:
//! `cumulus watch --screenshot out.png --frames N` captures the whole window
//! (3D view and panel) and exits 0, and the picture has real content.
//!
//! Needs an X display: uses `DISPLAY` when set, else starts its own Xvfb on a
//! free display number. Without either the test FAILS when CI=true (CI
//! installs Xvfb) and otherwise prints a notice and passes.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

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

/// Starts Xvfb on the first display number with neither a lock file nor a
/// socket, and waits for its socket.
fn start_xvfb() -> Option<Xvfb> {
    for n in 90..140 {
        let lock = format!("/tmp/.X{n}-lock");
        let socket = format!("/tmp/.X11-unix/X{n}");
        if Path::new(&lock).exists() || Path::new(&socket).exists() {
            continue;
        }
        let child = Command::new("Xvfb")
            .args([
                &format!(":{n}"),
                "-screen",
                "0",
                "1280x800x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .ok()?;
        let mut x = Xvfb {
            child,
            display: format!(":{n}"),
        };
        let t0 = Instant::now();
        while t0.elapsed() < Duration::from_secs(10) {
            if Path::new(&socket).exists() {
                return Some(x);
            }
            if let Ok(Some(_)) = x.child.try_wait() {
                break; // lost a race for this number: try the next
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    }
    None
}

/// The display to use, and the server to keep alive while using it.
fn display() -> Option<(String, Option<Xvfb>)> {
    if let Ok(d) = std::env::var("DISPLAY")
        && !d.is_empty()
    {
        return Some((d, None));
    }
    if on_path("Xvfb") {
        let x = start_xvfb()?;
        return Some((x.display.clone(), Some(x)));
    }
    None
}

fn no_display(why: &str) {
    if std::env::var("CI").as_deref() == Ok("true") {
        panic!("CI=true but the window test cannot run: {why}");
    }
    eprintln!("NOTICE: window test skipped: {why}");
}

#[test]
fn screenshot_shows_panel_and_clouds() {
    let Some((display, _xvfb)) = display() else {
        no_display("DISPLAY is unset and Xvfb is not installed");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("window.png");
    // Small window (the CPU adapter is slow), a few frames, and ten minutes
    // of simulated warm-up so that clouds have formed.
    let output = Command::new(env!("CARGO_BIN_EXE_cumulus"))
        .args(["watch", "--screenshot"])
        .arg(&out)
        .args([
            "--frames", "3", "--warmup", "600", "--width", "900", "--height", "560",
        ])
        .env("DISPLAY", &display)
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("run cumulus");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "cumulus watch failed:\n{stderr}");

    let img = image::open(&out).expect("a PNG").to_rgba8();
    let (w, h) = img.dimensions();
    assert_eq!((w, h), (900, 560), "the capture is the whole window");

    // Not a blank window: text, plot lines and shading give hundreds of
    // colours; a cleared or single-colour frame has one or two.
    let mut colours = std::collections::HashSet::new();
    for p in img.pixels() {
        colours.insert([p[0], p[1], p[2]]);
    }
    assert!(
        colours.len() > 200,
        "only {} distinct colours",
        colours.len()
    );

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
    let view = mean(420, w);
    let diff: f64 = (0..3).map(|c| (panel[c] - view[c]).abs()).sum();
    // Mean colours 8-bit: a dark panel against sky and ground differs by far
    // more than 60 summed over channels; the same content would differ by ~0.
    assert!(diff > 60.0, "panel {panel:?} vs view {view:?}");

    // Clouds: bright, nearly grey pixels in the 3D view (sky is blue, ground
    // green/brown, so low saturation and high brightness mean cloud).
    let mut cloud = 0u32;
    for y in 0..h {
        for x in 420..w {
            let p = img.get_pixel(x, y);
            let (mx, mn) = (p[0].max(p[1]).max(p[2]), p[0].min(p[1]).min(p[2]));
            if mn > 150 && mx - mn < 30 {
                cloud += 1;
            }
        }
    }
    let area = (w - 420) * h;
    // At least 0.2% of the view: a few small cumulus at several km distance.
    assert!(cloud * 500 > area, "{cloud} cloud pixels of {area}");
}
