//! `cumulus render` end to end: simulated and stand-in scenes give PNGs of
//! the asked size (numbered for several frames); bad arguments fail with a
//! clear message before any GPU work. Renders need an adapter: without one
//! the rendering tests print a notice and pass, unless CI=true.

mod common;

use std::process::Command;

fn cumulus() -> Command {
    Command::new(env!("CARGO_BIN_EXE_cumulus"))
}

#[test]
fn render_simulates_and_writes_a_png() {
    if common::context("GPU render test").is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("frame.png");
    let o = cumulus()
        .args([
            "render", "--width", "96", "--height", "64", "--time", "600", "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let img = image::open(&out).unwrap();
    assert_eq!((img.width(), img.height()), (96, 64));
    // The embedded scene has condensed by 10 minutes: the cloud pass ran.
    assert!(stderr.contains("cloud parcels ("), "{stderr}");
    assert!(stderr.contains("clouds "), "{stderr}");
}

#[test]
fn several_frames_are_numbered() {
    if common::context("GPU render test").is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("anim.png");
    let o = cumulus()
        .args([
            "render",
            "--stand-in",
            "--width",
            "64",
            "--height",
            "48",
            "--frames",
            "3",
            "--every",
            "30",
            "--normals",
            "on",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for i in 0..3 {
        let p = dir.path().join(format!("anim-{i:04}.png"));
        let img = image::open(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        assert_eq!((img.width(), img.height()), (64, 48));
    }
    assert!(!out.exists(), "single-frame name written for a sequence");
    assert!(!dir.path().join("anim-0003.png").exists());
}

#[test]
fn bad_arguments_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    for (args, needle) in [
        (vec!["--frames", "0"], "--frames"),
        (vec!["--every=-1"], "--every"),
        (vec!["--time", "nan"], "--time"),
        (vec!["--normals", "maybe"], "--normals"),
    ] {
        let o = cumulus()
            .arg("render")
            .args(&args)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
        assert!(!out.exists());
    }
}

#[test]
fn bad_render_table_names_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.toml");
    std::fs::write(&scene, "name = \"s\"\n[render]\nstep_m = -3.0\n").unwrap();
    let o = cumulus()
        .arg("render")
        .arg(&scene)
        .arg("--out")
        .arg(dir.path().join("x.png"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(stderr.contains("render.step_m"), "{stderr}");
}
