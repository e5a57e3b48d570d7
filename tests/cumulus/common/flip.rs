//! Images compared by mean FLIP (nv-flip, default viewing distance), and the
//! rendered reference images in `tests/reference/render/`.

use std::path::PathBuf;

/// RGB bytes of an RGBA frame.
pub fn rgb(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// Mean FLIP between two RGBA frames of `w`×`h`.
pub fn mean_flip(a: &[u8], b: &[u8], (w, h): (u32, u32)) -> f32 {
    let map = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(w, h, &rgb(a)),
        nv_flip::FlipImageRgb8::with_data(w, h, &rgb(b)),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    nv_flip::FlipPool::from_image(&map).mean()
}

/// The folder of the rendered reference images.
pub fn reference_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/reference/render")
}

/// Compares `rgba` (`w`×`h`) with the reference `NAME.png` and panics when
/// its mean FLIP exceeds `tolerance`, writing `NAME.actual.png` and
/// `NAME.difference.png` beside it. `UPDATE_REFERENCES=1` (or a missing
/// reference outside CI) writes the reference instead; under CI=true a
/// missing reference fails.
pub fn check_reference(name: &str, rgba: &[u8], (w, h): (u32, u32), tolerance: f32) {
    let dir = reference_dir();
    let path = dir.join(format!("{name}.png"));
    if std::env::var("UPDATE_REFERENCES").as_deref() == Ok("1") || !path.exists() {
        if !path.exists() && std::env::var("CI").as_deref() == Ok("true") {
            panic!("missing reference {}", path.display());
        }
        cumulus::output::write_png_atomic(&path, w, h, rgba).unwrap();
        eprintln!("wrote reference {}", path.display());
        return;
    }
    let reference = image::open(&path).unwrap().into_rgb8();
    assert_eq!(
        (reference.width(), reference.height()),
        (w, h),
        "{name}: size changed"
    );
    let map = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(w, h, &reference),
        nv_flip::FlipImageRgb8::with_data(w, h, &rgb(rgba)),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    let mean = nv_flip::FlipPool::from_image(&map).mean();
    if mean > tolerance {
        let write = |file: String, bytes: &[u8]| {
            cumulus::output::write_png_atomic(&dir.join(file), w, h, bytes).unwrap()
        };
        write(format!("{name}.actual.png"), rgba);
        let vis: Vec<u8> = map
            .apply_color_lut(&nv_flip::magma_lut())
            .to_vec()
            .chunks_exact(3)
            .flat_map(|p| [p[0], p[1], p[2], 255])
            .collect();
        write(format!("{name}.difference.png"), &vis);
        panic!(
            "{name}: mean FLIP {mean:.4} > {tolerance} (wrote {name}.actual.png and {name}.difference.png)"
        );
    }
    eprintln!("{name}: mean FLIP {mean:.4}");
}
