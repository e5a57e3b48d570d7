//! Bad input through the real binary: malformed profiles and soundings
//! (fixtures in tests/data/bad/) and absurd command-line values. Each must
//! exit non-zero without a panic, with a message naming the file (and line,
//! column where there is one), what was wrong and what is allowed; an output
//! file that existed before a failed run must be unchanged.

use std::path::{Path, PathBuf};

use crate::common::cli;

fn bad(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/bad")
        .join(name)
}

fn shipped_sounding() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/soundings/oun-2011-05-22-12z.txt")
}

/// Runs `args`, checks the failure is clean (exit 1 or 2, no panic) and
/// that stderr holds every one of `expect`; returns stderr.
fn fails_cleanly(args: &[&str], expect: &[&str]) -> String {
    cli::run(args).expect_failure_containing(expect)
}

/// `cumulus simulate PROFILE` into a file that already exists: the run must
/// fail cleanly and leave the file as it was.
fn profile_fails(name: &str, expect: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("old.csv");
    std::fs::write(&out, "previous run\n").unwrap();
    let path = bad(name);
    let p = path.to_str().unwrap();
    let mut want = vec![p];
    want.extend_from_slice(expect);
    fails_cleanly(
        &[
            "simulate",
            p,
            "--duration",
            "4",
            "--out",
            out.to_str().unwrap(),
        ],
        &want,
    );
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "previous run\n");
}

/// `cumulus parcel --sounding FILE --plot existing.png`: clean failure that
/// names the file, the plot left as it was.
fn sounding_fails(name: &str, expect: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let plot = dir.path().join("old.png");
    std::fs::write(&plot, b"previous plot").unwrap();
    let path = bad(name);
    let p = path.to_str().unwrap();
    let mut want = vec![p];
    want.extend_from_slice(expect);
    fails_cleanly(
        &["parcel", "--sounding", p, "--plot", plot.to_str().unwrap()],
        &want,
    );
    assert_eq!(std::fs::read(&plot).unwrap(), b"previous plot");
}

// ---- scene profiles -------------------------------------------------------

#[test]
fn profile_syntax_error() {
    // The string opened at line 1, column 8 runs to the end of the line.
    profile_fails("syntax_error.toml", &["syntax_error.toml:1:", "string"]);
}

#[test]
fn profile_unknown_key() {
    profile_fails(
        "unknown_key.toml",
        &[
            "unknown_key.toml:3:1:",
            "unknown field `stiffnes`",
            "`stiffness`",
        ],
    );
}

#[test]
fn profile_wrong_type() {
    profile_fails(
        "wrong_type.toml",
        &["wrong_type.toml:2:13:", "\"very stiff\"", "expected f64"],
    );
}

#[test]
fn profile_negative_radius() {
    profile_fails(
        "negative_radius.toml",
        &[
            "negative_radius.toml:2:1:",
            "emission.radius_m = -150",
            "between 1 and 5000",
        ],
    );
}

#[test]
fn profile_stiffness_zero_and_negative() {
    for f in ["zero_stiffness.toml", "negative_stiffness.toml"] {
        profile_fails(f, &[":2:1:", "physics.stiffness", "above 0", "sph = false"]);
    }
}

#[test]
fn profile_time_step_zero_and_negative() {
    for f in ["zero_dt.toml", "negative_dt.toml"] {
        profile_fails(f, &[":2:1:", "physics.max_dt_s", "between 0.0001 and 600"]);
    }
}

#[test]
fn profile_nan_and_inf_literals() {
    profile_fails(
        "nan_stiffness.toml",
        &[
            "nan_stiffness.toml:2:1:",
            "physics.stiffness = NaN",
            "finite",
        ],
    );
    profile_fails(
        "inf_wind.toml",
        &[
            "inf_wind.toml:2:1:",
            "wind.aloft_m_s[0] = inf",
            "finite number between -100 and 100",
        ],
    );
    profile_fails(
        "profile_nan_temperature.toml",
        &[
            "profile_nan_temperature.toml:10:1:",
            "atmosphere.points[1].t_c = NaN",
            "between -100 and 60 °C",
        ],
    );
}

#[test]
fn profile_dewpoint_above_temperature() {
    profile_fails(
        "profile_dewpoint_above_temperature.toml",
        &[
            "profile_dewpoint_above_temperature.toml:6:1:",
            "atmosphere.points[0].td_c = 25",
            "up to the temperature t_c = 20",
        ],
    );
}

#[test]
fn profile_binary_file() {
    profile_fails("binary.txt", &["not UTF-8", "TOML"]);
}

#[test]
fn profile_sounding_missing_or_broken() {
    // The profile's line with `sounding`, then the sounding's own path
    // (and line); `render` named neither the profile nor the line.
    let missing = [
        "missing_sounding.toml:2:1: sounding = \"no_such_sounding.txt\": ",
        "no_such_sounding.txt: No such file",
    ];
    let broken = [
        "profile_with_bad_sounding.toml:2:1: sounding = \"text_in_number.txt\": ",
        "text_in_number.txt:5:18:",
        "\"warm\"",
        "TEMP",
    ];
    profile_fails("missing_sounding.toml", &missing);
    profile_fails("profile_with_bad_sounding.toml", &broken);
    let dir = tempfile::tempdir().unwrap();
    for (name, expect) in [
        ("missing_sounding.toml", &missing[..]),
        ("profile_with_bad_sounding.toml", &broken[..]),
    ] {
        let profile = bad(name);
        let p = profile.to_str().unwrap();
        let png = dir.path().join("never.png");
        let vol = dir.path().join("never.vol");
        for (command, out) in [("render", &png), ("export", &vol)] {
            fails_cleanly(&[command, p, "--out", out.to_str().unwrap()], expect);
            assert!(!out.exists(), "{command} wrote {}", out.display());
        }
    }
}

#[test]
fn profile_that_does_not_exist() {
    fails_cleanly(
        &[
            "simulate",
            "/nonexistent/scene.toml",
            "--duration",
            "10",
            "--out",
            "/tmp/never-written.csv",
        ],
        &["/nonexistent/scene.toml", "No such file"],
    );
}

// ---- soundings ------------------------------------------------------------

#[test]
fn sounding_missing_columns() {
    sounding_fails(
        "missing_columns.txt",
        &["missing_columns.txt:6:8:", "missing HGHT", "needs a height"],
    );
}

#[test]
fn sounding_text_and_nan_in_number_columns() {
    sounding_fails(
        "text_in_number.txt",
        &[":5:18:", "\"warm\"", "TEMP", "finite number or a blank"],
    );
    sounding_fails(
        "nan_in_number.txt",
        &[":5:26:", "\"nan\"", "DWPT", "finite number or a blank"],
    );
}

#[test]
fn sounding_pressure_not_decreasing() {
    sounding_fails(
        "pressure_not_decreasing.txt",
        &[":6:3:", "960 hPa does not decrease", "strictly decreasing"],
    );
}

#[test]
fn sounding_dewpoint_above_temperature() {
    sounding_fails(
        "dewpoint_above_temperature.txt",
        &[
            ":5:25:",
            "dewpoint 25 °C above temperature 23.6 °C",
            "DWPT ≤ TEMP",
        ],
    );
}

#[test]
fn sounding_negative_pressure() {
    sounding_fails(
        "negative_pressure.txt",
        &[":6:2:", "-900 hPa", "positive pressures up to 1100 hPa"],
    );
}

#[test]
fn sounding_empty_and_binary() {
    sounding_fails("empty.txt", &["empty file", "PRES HGHT TEMP DWPT"]);
    sounding_fails("binary.txt", &["not UTF-8", "text table"]);
}

// ---- absurd command-line values --------------------------------------------

#[test]
fn render_zero_or_huge_size() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("old.png");
    std::fs::write(&png, b"previous frame").unwrap();
    let out = png.to_str().unwrap();
    for (flag, v) in [("--width", "0"), ("--height", "0"), ("--width", "100000")] {
        fails_cleanly(
            &["render", flag, v, "--out", out],
            &[flag, &format!("'{v}'"), "1..=16384"],
        );
    }
    fails_cleanly(
        &["render", "--time", "-5", "--out", out],
        &["--time", "≥ 0"],
    );
    fails_cleanly(&["render", "--frames", "0", "--out", out], &["--frames"]);
    assert_eq!(std::fs::read(&png).unwrap(), b"previous frame");
}

#[test]
fn image_output_of_another_format() {
    // Refused before anything runs: a frame used to be written as PNG
    // bytes under any other name (x.bmp), and the window never opens.
    let dir = tempfile::tempdir().unwrap();
    let bmp = dir.path().join("x.bmp");
    fails_cleanly(
        &["render", "--out", bmp.to_str().unwrap()],
        &["--out", "x.bmp", ".png", ".exr"],
    );
    assert!(!bmp.exists());
    let jpg = dir.path().join("x.jpg");
    fails_cleanly(
        &["watch", "--screenshot", jpg.to_str().unwrap()],
        &["--screenshot", "x.jpg", ".png"],
    );
    assert!(!jpg.exists());
    // `atlas` and `parcel --plot` wrote PNG bytes under any name and
    // exited 0; a name without an extension is refused too.
    let bare = dir.path().join("atlas");
    for out in [&jpg, &bare] {
        let name = out.file_name().unwrap().to_str().unwrap();
        fails_cleanly(
            &["atlas", "--out", out.to_str().unwrap()],
            &["invalid --out", name, "must end in .png"],
        );
        assert!(!out.exists());
    }
    let s = shipped_sounding();
    fails_cleanly(
        &[
            "parcel",
            "--sounding",
            s.to_str().unwrap(),
            "--plot",
            jpg.to_str().unwrap(),
        ],
        &["invalid --plot", "x.jpg", "must end in .png"],
    );
    assert!(!jpg.exists());
}

#[test]
fn visibility_out_of_range() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never.png");
    for v in ["0", "0.5", "300", "nan"] {
        let set = format!("render.visibility_km={v}");
        fails_cleanly(
            &["render", "--set", &set, "--out", out.to_str().unwrap()],
            &["render.visibility_km", "1 to 280 km"],
        );
    }
    assert!(!out.exists());
}

#[test]
fn simulate_absurd_duration_and_dt() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("old.csv");
    std::fs::write(&csv, "previous run\n").unwrap();
    let out = csv.to_str().unwrap();
    for (flag, v, allowed) in [
        ("--duration", "-5", "positive number of seconds up to 1e7"),
        ("--duration", "0", "positive number of seconds up to 1e7"),
        ("--duration", "nan", "positive number of seconds up to 1e7"),
        ("--dt", "0", "positive number of seconds up to 600"),
        ("--dt", "-1", "positive number of seconds up to 600"),
        ("--dt", "inf", "positive number of seconds up to 600"),
    ] {
        // The other of --duration/--dt is valid (--duration has no default).
        let other = if flag == "--dt" {
            ["--duration", "10"]
        } else {
            ["--dt", "2"]
        };
        fails_cleanly(
            &["simulate", flag, v, other[0], other[1], "--out", out],
            &[flag, allowed],
        );
    }
    // Before the frame bound this tried to allocate terabytes and aborted.
    fails_cleanly(
        &[
            "simulate",
            "--duration",
            "1e7",
            "--dt",
            "1e-4",
            "--out",
            out,
        ],
        &["frames", "at most 10000000"],
    );
    fails_cleanly(
        &["simulate", "--duration", "ten", "--out", out],
        &["--duration", "'ten'"],
    );
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), "previous run\n");
}

#[test]
fn parcel_absurd_surface_values() {
    let s = shipped_sounding();
    let s = s.to_str().unwrap();
    for v in ["500", "-500", "nan"] {
        fails_cleanly(
            &["parcel", "--sounding", s, "--surface-temp", v],
            &["surface temperature", "between -100 and 70 °C"],
        );
    }
    let err = fails_cleanly(
        &["parcel", "--sounding", s, "--surface-dewpoint", "40"],
        &["surface dewpoint", "up to the surface temperature 22.20 °C"],
    );
    assert!(!err.contains("99999"), "unrounded bound: {err}");
    fails_cleanly(
        &["parcel", "--sounding", "/nonexistent/sounding.txt"],
        &["/nonexistent/sounding.txt", "No such file"],
    );
}

#[test]
fn parcel_dynamic_options_are_named_with_their_real_ranges() {
    let s = shipped_sounding();
    let s = s.to_str().unwrap();
    let dynamic = |extra: &[&str], expect: &[&str]| {
        let mut args = vec!["parcel", "--sounding", s, "--dynamic"];
        args.extend_from_slice(extra);
        let err = fails_cleanly(&args, expect);
        // Not the release's field names (surface_t_k, dt_s, surface_qv).
        assert!(
            !err.contains("_k =") && !err.contains("_s =") && !err.contains("_qv"),
            "{err}"
        );
    };
    // The surface-based parcel of this sounding starts at 22.20 °C, so
    // 150 to 400 K leave an excess of -145.35 to 104.65 K.
    for v in ["1e6", "-200", "nan"] {
        dynamic(
            &["--temp-excess", v],
            &["invalid --temp-excess", "from -145.35 to 104.65 K"],
        );
    }
    // The parser said "> 0 and ≤ 1e7 s", then the release refused 1e6.
    for v in ["1e6", "nan", "1e-5"] {
        dynamic(&["--dt", v], &["--dt", "from 0.0001 to 600 s"]);
    }
    dynamic(
        &["--duration", "1e8"],
        &["--duration", "from 0.001 to 1e7 s"],
    );
    for v in ["0", "-5", "1e9"] {
        dynamic(&["--radius", v], &["--radius", "from 5 to 3000 m"]);
    }
    // This aborted allocating 13 TB for the trajectory.
    dynamic(
        &["--duration", "1e7", "--dt", "1e-4"],
        &["--duration", "--dt", "frames", "at most 1e7"],
    );
    dynamic(
        &["--surface-temp", "65", "--surface-dewpoint", "65"],
        &[
            "invalid --surface-dewpoint 65 °C",
            "at most 100 g/kg",
            "dewpoint up to",
        ],
    );
    // The stated bounds are accepted.
    cli::run([
        "parcel",
        "--sounding",
        s,
        "--dynamic",
        "--dt",
        "600",
        "--duration",
        "1200",
        "--radius",
        "3000",
        "--temp-excess",
        "104",
    ])
    .expect_success();
}

#[test]
fn stability_unwritable_report_directory() {
    // Fails at once, before running the matrix.
    fails_cleanly(
        &["stability", "--quick", "--out", "/dev/null/report"],
        &[
            "invalid --out /dev/null/report",
            "cannot create the folder /dev/null/report",
        ],
    );
}
