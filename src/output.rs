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
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if !dir.exists() {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    }
    let mut tmp = tempfile::NamedTempFile::new_in(dir).map_err(|e| Error::io(dir, e))?;
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
    tmp.persist(path).map_err(|e| Error::io(path, e.error))?;
    Ok(())
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
}
