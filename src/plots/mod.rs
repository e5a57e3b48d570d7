//! PNG charts with plotters (parcel diagram, bench plots). Fonts come from
//! `epaint_default_fonts`, so no system font library is needed.

pub mod skewt;

use plotters::style::FontStyle;

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
