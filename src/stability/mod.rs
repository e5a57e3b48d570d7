//! Stability matrix: stiff and extreme cases for the physics (SPH stiffness,
//! frame steps, parcel counts, extreme soundings, wind shear, emission
//! bursts), run headless with every guard counted, summarised as a table.
//! `cumulus stability` writes it as Markdown and CSV and exits non-zero when
//! a case blows up (NaN/Inf, kinetic energy beyond the bound of [`run`], or a
//! panic, which is caught and reported rather than propagated).

pub mod cases;
pub mod report;
pub mod run;

use std::cell::RefCell;

pub use cases::{Case, Cluster, ENVIRONMENTS, Size, environment, matrix};
pub use report::{clamp_summary, to_csv, to_markdown, write_reports};
pub use run::{CaseResult, KE_RATIO_BOUND, cluster_specs, run_case, specific_energy_bound};

thread_local! {
    /// Where the last panic on this thread happened (set by the quiet hook).
    static PANIC_LOCATION: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// Runs `cases` in order with a quiet panic hook (a caught panic is reported
/// in its case's row, with its location, instead of being printed);
/// `progress(case index, frames done in that case)` is called after every frame.
pub fn run_matrix(cases: &[Case], mut progress: impl FnMut(usize, u32)) -> Vec<CaseResult> {
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(|info| {
        let loc = info
            .location()
            .map(|l| format!("{}:{}", l.file(), l.line()));
        PANIC_LOCATION.with(|p| *p.borrow_mut() = loc);
    }));
    let results = cases
        .iter()
        .enumerate()
        .map(|(i, case)| {
            PANIC_LOCATION.with(|p| *p.borrow_mut() = None);
            let mut r = run_case(case, |f| progress(i, f));
            if let Some(msg) = &mut r.panic
                && let Some(loc) = PANIC_LOCATION.with(|p| p.borrow_mut().take())
            {
                msg.push_str(&format!(" (at {loc})"));
            }
            r
        })
        .collect();
    std::panic::set_hook(previous);
    results
}
