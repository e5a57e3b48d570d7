//! PNG charts with plotters (the parcel diagram with its hodograph, bench
//! plots) and text labels drawn into rendered frames. Fonts come from
//! `epaint_default_fonts`, so no system font library is needed.

pub mod hodograph;
pub mod labels;
pub mod skewt;

use std::path::Path;

use plotters::style::FontStyle;

use crate::error::{Error, Result};

/// Registers the embedded Ubuntu Light font as plotters' "sans-serif" (all
/// styles), once per process. Plotters' ab_glyph backend has no system font
/// lookup, so every chart calls this before drawing text.
pub fn register_fonts() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        for style in [
            FontStyle::Normal,
            FontStyle::Bold,
            FontStyle::Italic,
            FontStyle::Oblique,
        ] {
            // The font is compiled in and known to be valid TrueType; a
            // failure here would show as missing labels, not a crash.
            let _ = plotters::style::register_font(
                "sans-serif",
                style,
                epaint_default_fonts::UBUNTU_LIGHT,
            );
        }
    });
}

/// Registers the fonts, lets `draw` paint a `width`×`height` RGB buffer
/// (plotters' bitmap layout) and writes it atomically as an opaque PNG. A
/// drawing failure is reported as an I/O error on `path` naming `what`.
pub(crate) fn write_rgb_png(
    path: &Path,
    what: &str,
    width: u32,
    height: u32,
    draw: impl FnOnce(&mut [u8]) -> std::result::Result<(), String>,
) -> Result<()> {
    register_fonts();
    let mut rgb = vec![0u8; (width * height * 3) as usize];
    draw(&mut rgb)
        .map_err(|m| Error::io(path, std::io::Error::other(format!("drawing {what}: {m}"))))?;
    let rgba: Vec<u8> = rgb
        .chunks_exact(3)
        .flat_map(|c| [c[0], c[1], c[2], 255])
        .collect();
    crate::output::write_png_atomic(path, width, height, &rgba)
}
