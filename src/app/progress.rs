//! The pre-simulation to a scene's start time with an indicatif progress bar
//! on the terminal (screenshot runs, which count frames; the live window
//! shows the same progress in its panel instead).

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
