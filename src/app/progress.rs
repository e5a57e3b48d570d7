//! The pre-simulation to a scene's start time with an indicatif progress bar
//! on the terminal (screenshot runs, which count frames), or, in the live
//! window, a progress bar over the 3D view (and in the panel) until the
//! clouds appear at the start time.

use super::state::Model;

/// Simulates `model` to its start time, drawing a progress bar on stderr.
pub fn warm_up_with_bar(model: &mut Model) {
    let target = model.start_s;
    if target <= model.world.time_s() {
        return;
    }
    let bar = indicatif::ProgressBar::new(target.ceil() as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "simulating to the start time {bar:40} {pos}/{len} s  [{elapsed_precise} < {eta_precise}]",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    model.warm_up_to(target, |t| bar.set_position(t as u64));
    bar.finish_and_clear();
}

/// While the live window pre-simulates: a progress bar in the middle of the
/// 3D view (`rect`: left edge, width, height in pixels), over the sky and
/// terrain drawn without clouds.
pub fn warm_up_overlay(ctx: &egui::Context, model: &Model, rect: (u32, u32, u32)) {
    let Some(done) = model.warm_up_progress() else {
        return;
    };
    let ppp = ctx.pixels_per_point();
    let (x0, w, h) = rect;
    let centre = egui::pos2((x0 as f32 + 0.5 * w as f32) / ppp, 0.5 * h as f32 / ppp);
    egui::Area::new(egui::Id::unique("warm-up overlay"))
        .fixed_pos(centre)
        .pivot(egui::Align2::CENTER_CENTER)
        .interactable(false)
        .show(ctx, |ui| {
            egui::Frame::popup(ui.style()).show(ui, |ui| {
                ui.set_width(320.0);
                ui.label("Simulating to the scene's start time");
                ui.add(egui::ProgressBar::new(done as f32).text(format!(
                    "{:.0} of {:.0} s",
                    model.world.time_s(),
                    model.start_s
                )));
            });
        });
}
