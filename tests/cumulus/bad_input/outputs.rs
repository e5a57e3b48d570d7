//! Output paths that cannot be written, through the real binary: every
//! command with an output option refuses, before its work, a path that is
//! an existing directory or in a folder no file can be created in, with a
//! message naming the option and the path as given and what is wrong
//! (never the temporary file it writes through), and leaves nothing behind.

use std::path::Path;

use crate::common::cli;

fn shipped_sounding() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("profiles/soundings/oun-2011-05-22-12z.txt")
        .to_str()
        .unwrap()
        .to_string()
}

/// A folder where no file can be created, even as root (writes under
/// /proc fail with ENOENT); None where there is no /proc.
fn unwritable_folder() -> Option<&'static str> {
    Path::new("/proc").is_dir().then_some("/proc")
}

/// Runs `args`, checks it failed cleanly with a message holding every one
/// of `expect` and not the temporary file's name (`tempfile` words it
/// `… at path "DIR/.tmpXXXXXX"`); returns stderr.
fn refused(args: &[&str], expect: &[&str]) -> String {
    let err = cli::run(args).expect_failure_containing(expect);
    assert!(!err.contains(" at path "), "a temporary name leaks: {err}");
    err
}

#[test]
fn output_that_is_an_existing_directory() {
    let dir = tempfile::tempdir().unwrap();
    let outs = dir.path().join("outs");
    std::fs::create_dir(&outs).unwrap();
    let o = outs.to_str().unwrap();
    let with_slash = format!("{o}/");
    // `simulate --out outs/` said "outs/: Not a directory", after the run.
    for given in [o, with_slash.as_str()] {
        refused(
            &["simulate", "--duration", "10", "--out", given],
            &["invalid --out", given, "existing directory"],
        );
    }
    // A directory named like an image or a grid.
    let png = dir.path().join("frame.png");
    let vol = dir.path().join("grid.vol");
    std::fs::create_dir(&png).unwrap();
    std::fs::create_dir(&vol).unwrap();
    let (png, vol) = (png.to_str().unwrap(), vol.to_str().unwrap());
    let err = refused(
        &["render", "--stand-in", "--out", png],
        &["invalid --out", png, "existing directory"],
    );
    assert!(
        !err.contains("adapter:"),
        "found after opening the GPU: {err}"
    );
    refused(
        &["export", "--stand-in", "--out", vol],
        &["invalid --out", vol, "existing directory"],
    );
    refused(
        &["atlas", "--out", png],
        &["invalid --out", png, "existing directory"],
    );
    refused(
        &["parcel", "--sounding", &shipped_sounding(), "--plot", png],
        &["invalid --plot", png, "existing directory"],
    );
    refused(
        &[
            "parcel",
            "--sounding",
            &shipped_sounding(),
            "--dynamic",
            "--csv",
            o,
        ],
        &["invalid --csv", o, "existing directory"],
    );
    let fresh = dir.path().join("fresh.png");
    refused(
        &[
            "render",
            "--stand-in",
            "--out",
            fresh.to_str().unwrap(),
            "--save-parcels",
            o,
        ],
        &["invalid --save-parcels", o, "existing directory"],
    );
    refused(
        &["watch", "--screenshot", png],
        &["invalid --screenshot", png, "existing directory"],
    );
    // Nothing was written into them, nor beside them.
    for d in [o, png, vol] {
        assert_eq!(std::fs::read_dir(d).unwrap().count(), 0, "{d}");
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 3);
}

#[test]
fn output_in_a_folder_that_takes_no_file() {
    let Some(folder) = unwritable_folder() else {
        return;
    };
    // `render --out /proc/b.png` rendered, then said "/proc: No such file
    // or directory (os error 2) at path \"/proc/.tmpvwwRWG\"".
    let cannot = format!("cannot create a file in {folder}");
    let png = format!("{folder}/b.png");
    let err = refused(
        &["render", "--stand-in", "--out", &png],
        &["invalid --out", &png, &cannot],
    );
    assert!(
        !err.contains("adapter:"),
        "found after opening the GPU: {err}"
    );
    assert!(!err.contains("/proc/.tmp"), "a temporary name leaks: {err}");
    let csv = format!("{folder}/diag.csv");
    refused(
        &["simulate", "--duration", "10", "--out", &csv],
        &["invalid --out", &csv, &cannot],
    );
    let vdb = format!("{folder}/clouds.vdb");
    refused(
        &["export", "--stand-in", "--out", &vdb],
        &["invalid --out", &vdb, &cannot],
    );
    refused(&["atlas", "--out", &png], &["invalid --out", &png, &cannot]);
    refused(
        &["parcel", "--sounding", &shipped_sounding(), "--plot", &png],
        &["invalid --plot", &png, &cannot],
    );
    // Outputs that are folders: the folder cannot be created.
    let report = format!("{folder}/report");
    for command in ["bench", "stability"] {
        refused(
            &[command, "--out", &report],
            &[
                "invalid --out",
                &report,
                &format!("cannot create the folder {report}"),
            ],
        );
    }
}

#[test]
fn output_folder_that_is_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("notes.txt");
    std::fs::write(&file, "kept\n").unwrap();
    let f = file.to_str().unwrap();
    for command in ["bench", "stability"] {
        refused(
            &[command, "--quick", "--out", f],
            &["invalid --out", f, "is a file, not a folder"],
        );
    }
    let csv = format!("{f}/diag.csv");
    refused(
        &["simulate", "--duration", "10", "--out", &csv],
        &["invalid --out", &csv, "is a file, not a folder"],
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "kept\n");
}
