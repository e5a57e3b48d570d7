//! Writing outputs whole or not at all: every file goes to a temporary file in
//! the same directory and is renamed over the target only once complete, so an
//! interrupted run never leaves a truncated PNG or CSV behind and never
//! clobbers a good file with a bad one.

use std::io::Write;
use std::path::Path;

use crate::error::{Error, Result};

/// Writes `bytes` to `path` atomically (temporary file + rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// Calls `fill` with a writer on a temporary file beside `path`, then renames
/// it over `path`. If `fill` fails, `path` is untouched.
pub fn write_atomic_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let mut tmp = temp_beside(path)?;
    {
        let mut buf = std::io::BufWriter::new(tmp.as_file_mut());
        fill(&mut buf).map_err(|e| Error::io(path, e))?;
        buf.flush().map_err(|e| Error::io(path, e))?;
    }
    tmp.as_file().sync_all().map_err(|e| Error::io(path, e))?;
    // tempfile creates files readable by the owner only; an output gets the
    // mode of the file it replaces, or the usual rw-r--r--.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt as _;
        let mode = std::fs::metadata(path)
            .map(|m| m.permissions().mode())
            .unwrap_or(0o644);
        tmp.as_file()
            .set_permissions(std::fs::Permissions::from_mode(mode))
            .map_err(|e| Error::io(path, e))?;
    }
    tmp.persist(path).map_err(|e| {
        Error::io(
            path,
            std::io::Error::new(e.error.kind(), os_reason(&e.error)),
        )
    })?;
    Ok(())
}

/// Checks, before the work that produces it, that the file `path` can be
/// written: it is not a directory, its folder exists or can be created,
/// and a file can be created in that folder. It leaves nothing behind
/// (folders it made to try are removed again). The error is an
/// [`Error::Io`] on `path` whose source says what is wrong and the OS's
/// reason, as writing it would give.
pub fn check_writable(path: &Path) -> Result<()> {
    not_a_directory(path)?;
    probe(folder_of(path)).map_err(|e| Error::io(path, e))
}

/// Checks that files can be written into the folder `dir` (which may not
/// exist yet): for outputs that are a folder of files. The error is an
/// [`Error::Io`] on `dir`, as [`check_writable`]'s.
pub fn check_folder_writable(dir: &Path) -> Result<()> {
    probe(dir).map_err(|e| Error::io(dir, e))
}

/// Creates a temporary file in `dir` as writing would (making `dir` when
/// missing), then removes it and the folders it made.
fn probe(dir: &Path) -> std::io::Result<()> {
    // Innermost first, so each is empty when removed.
    let missing: Vec<&Path> = dir
        .ancestors()
        .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
        .collect();
    let probed = temp_in(dir).map(drop);
    for made in missing {
        let _ = std::fs::remove_dir(made);
    }
    probed
}

/// A new temporary file beside `path`, for writing it whole or not at all;
/// errors name `path` and say what is wrong, never the temporary name.
fn temp_beside(path: &Path) -> Result<tempfile::NamedTempFile> {
    not_a_directory(path)?;
    temp_in(folder_of(path)).map_err(|e| Error::io(path, e))
}

/// An output file's name must not be an existing directory's.
fn not_a_directory(path: &Path) -> Result<()> {
    if path.is_dir() {
        return Err(Error::io(
            path,
            std::io::Error::new(
                std::io::ErrorKind::IsADirectory,
                "it is an existing directory, not a file name",
            ),
        ));
    }
    Ok(())
}

/// The folder a file `path` goes into: its parent, or `.` for a bare name.
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// A new temporary file in `dir`, creating `dir` when missing. The error
/// says which of the two failed, in `dir`, and the OS's reason.
fn temp_in(dir: &Path) -> std::io::Result<tempfile::NamedTempFile> {
    let why = |what: String, e: std::io::Error| {
        std::io::Error::new(e.kind(), format!("{what}: {}", os_reason(&e)))
    };
    if dir.exists() && !dir.is_dir() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::NotADirectory,
            format!("{} is a file, not a folder", dir.display()),
        ));
    }
    std::fs::create_dir_all(dir)
        .map_err(|e| why(format!("cannot create the folder {}", dir.display()), e))?;
    tempfile::NamedTempFile::new_in(dir)
        .map_err(|e| why(format!("cannot create a file in {}", dir.display()), e))
}

/// The OS's reason for `e` without the temporary file's name that
/// `tempfile` appends to its errors (as `{reason} at path "{temp}"`, the
/// OS error itself not kept as a source).
fn os_reason(e: &std::io::Error) -> String {
    let text = e.to_string();
    match text.rfind(" at path \"") {
        Some(i) => text[..i].to_string(),
        None => text,
    }
}

/// Encodes an RGBA8 image as PNG and writes it atomically.
pub fn write_png_atomic(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<()> {
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(rgba, width, height, image::ExtendedColorType::Rgba8)
        .map_err(|e| Error::io(path, std::io::Error::other(e)))?;
    write_atomic(path, &png)
}

/// Encodes linear RGB float pixels (3 per pixel, top row first) as an
/// OpenEXR image (32-bit float channels R, G, B) and writes it atomically.
pub fn write_exr_atomic(path: &Path, width: u32, height: u32, rgb: &[f32]) -> Result<()> {
    if rgb.len() != 3 * width as usize * height as usize {
        return Err(Error::io(
            path,
            std::io::Error::other(format!(
                "{} floats for a {width}×{height} RGB image (needs {})",
                rgb.len(),
                3 * width as usize * height as usize
            )),
        ));
    }
    // The encoder seeks, so it writes into memory first.
    let mut exr = std::io::Cursor::new(Vec::new());
    image::codecs::openexr::OpenExrEncoder::new(&mut exr)
        .write_image(
            bytemuck::cast_slice(rgb),
            width,
            height,
            image::ExtendedColorType::Rgb32F,
        )
        .map_err(|e| Error::io(path, std::io::Error::other(e)))?;
    write_atomic(path, exr.get_ref())
}

use image::ImageEncoder as _;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_whole_files_and_keeps_failed_writes_out() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        write_atomic(&path, b"first").unwrap();
        // A writer that fails half-way leaves the old file untouched.
        let err = write_atomic_with(&path, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("interrupted"))
        });
        assert!(err.is_err());
        assert_eq!(std::fs::read(&path).unwrap(), b"first");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt as _;
            let mode = std::fs::metadata(&path).unwrap().permissions().mode() & 0o777;
            assert_eq!(mode, 0o644, "outputs are world-readable like any new file");
        }
        // No temporary file is left behind.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn unwritable_outputs_are_found_before_writing_and_named() {
        let dir = tempfile::tempdir().unwrap();
        // An existing directory is not a file name (it used to fail only at
        // the rename, as "Not a directory").
        let msg = format!(
            "{:#}",
            anyhow::Error::new(check_writable(dir.path()).unwrap_err())
        );
        assert!(msg.contains("existing directory"), "{msg}");
        let err = write_atomic(dir.path(), b"x").unwrap_err();
        assert!(matches!(err, Error::Io { ref path, .. } if path == dir.path()));
        // A folder no file can be created in: the OS's reason and the
        // folder, never the temporary file's name.
        let proc_out = Path::new("/proc/cumulus-out.png");
        if Path::new("/proc").is_dir() {
            let err = check_writable(proc_out).unwrap_err();
            let msg = format!("{:#}", anyhow::Error::new(err));
            assert!(
                msg.starts_with("/proc/cumulus-out.png: cannot create a file in /proc: "),
                "{msg}"
            );
            assert!(!msg.contains(".tmp"), "the temporary name leaks: {msg}");
        }
        // A file where a folder is needed.
        let file = dir.path().join("file");
        std::fs::write(&file, b"").unwrap();
        let msg = format!(
            "{:#}",
            anyhow::Error::new(check_folder_writable(&file.join("report")).unwrap_err())
        );
        assert!(msg.contains("cannot create the folder"), "{msg}");
        // Missing folders pass, and the check leaves nothing behind: not
        // the folders it made to try, not its temporary file.
        check_writable(&dir.path().join("a/b/out.csv")).unwrap();
        check_folder_writable(&dir.path().join("c/d")).unwrap();
        check_writable(&dir.path().join("e.png")).unwrap();
        let left: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left, ["file"], "left behind");
    }
}
