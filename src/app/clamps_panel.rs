//! The panel's clamp report: every physics clamp by kind since the last
//! reset (the world is rebuilt on reset, so its cumulative counts are
//! exactly that), the emissions refused at `max_parcels`, and the opaque
//! display count, which is not a clamp. The text is built by
//! [`clamp_text`], a plain function the tests call; [`show`] draws it, in
//! an attention colour once any clamp has fired.

use egui::{Color32, RichText};

use crate::physics::Diagnostics;

/// Colour of the clamp lines once a clamp has fired.
pub const ATTENTION_COLOR: Color32 = Color32::from_rgb(240, 150, 30);

/// What the panel shows about clamps.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ClampText {
    /// The heading line: "clamps since reset: none" or "… N".
    pub heading: String,
    /// One line per kind that fired: "speed 12".
    pub kinds: Vec<String>,
    /// Emissions refused at `max_parcels` and the opaque display count.
    pub notes: Vec<String>,
    /// Any clamp fired since the last reset (the lines turn attention-coloured).
    pub attention: bool,
}

/// The clamp report of `d` (cumulative since the world was built).
pub fn clamp_text(d: &Diagnostics) -> ClampText {
    let total = d.clamps.total();
    let heading = if total == 0 {
        "clamps since reset: none".to_string()
    } else {
        format!("clamps since reset: {total}")
    };
    let kinds = d
        .clamps
        .kinds()
        .iter()
        .filter(|(_, n)| *n > 0)
        .map(|(k, n)| format!("{k} {n}"))
        .collect();
    let notes = vec![
        format!("emissions refused at max_parcels: {}", d.fates.suppressed),
        format!(
            "fill shown saturated (display, not a clamp): {} parcel-frames",
            d.opaque_parcel_frames
        ),
    ];
    ClampText {
        heading,
        kinds,
        notes,
        attention: total > 0,
    }
}

/// Draws the clamp report of `d`.
pub fn show(ui: &mut egui::Ui, d: &Diagnostics) {
    let t = clamp_text(d);
    let tint = |s: &str| {
        let r = RichText::new(s).monospace();
        if t.attention {
            r.color(ATTENTION_COLOR)
        } else {
            r
        }
    };
    ui.label(tint(&t.heading).strong());
    for k in &t.kinds {
        ui.label(tint(&format!("  {k}")));
    }
    for n in &t.notes {
        ui.small(n);
    }
}
