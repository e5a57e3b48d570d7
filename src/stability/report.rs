//! The stability table as Markdown (for people) and CSV (for scripts),
//! written whole or not at all.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::run::{CaseResult, KE_RATIO_BOUND};
use crate::error::Result;
use crate::physics::ClampCounts;

/// "speed 12, radius 3" (non-zero kinds only), or "–" when none was hit.
pub fn clamp_summary(c: &ClampCounts) -> String {
    if c.total() == 0 {
        "–".into()
    } else {
        c.to_string()
    }
}

/// "0.123 / 95.0 m/s" (and the NaN/Inf count) of the uncapped rerun, or "–".
fn uncapped_cell(r: &CaseResult) -> String {
    match &r.uncapped {
        None => "–".into(),
        Some(u) if u.non_finite > 0 => format!(
            "{:.3} / {:.1} m/s, {} NaN/Inf",
            u.ke_ratio, u.max_speed_m_s, u.non_finite
        ),
        Some(u) => format!("{:.3} / {:.1} m/s", u.ke_ratio, u.max_speed_m_s),
    }
}

fn verdict(r: &CaseResult) -> String {
    let f = r.failures();
    if f.is_empty() {
        "ok".into()
    } else {
        format!("**FAIL**: {}", f.join("; "))
    }
}

/// The Markdown report: what the columns mean, the table, the failures.
pub fn to_markdown(results: &[CaseResult], title: &str) -> String {
    let mut s = String::new();
    let failed = results.iter().filter(|r| !r.passed()).count();
    let _ = writeln!(s, "# {title}\n");
    let _ = writeln!(
        s,
        "{} cases, {} passed, {} failed.\n",
        results.len(),
        results.len() - failed,
        failed
    );
    let _ = writeln!(
        s,
        "- **KE ratio**: max over frames of KE(t) / (KE₀ + E_sph,0 + E_births + M(t)·e_phys + E_cap), \
         the kinetic energy over all the energy the case can supply (initial SPH compression, SPH \
         energy of parcels born overlapping others, CAPE of the \
         hottest and downdraft CAPE of the coldest parcel possible, ½|wind|²); a case fails above \
         {KE_RATIO_BOUND}. `e_phys` is that energy per kg. E_cap bounds a priori the work of the \
         atmospheric pressure on hidden caps (paper §5.1: overlapping parcels weigh their lens \
         volume): the force's cap w ρ_env(0) g ΣV over the column height plus an overlap; \
         **W_atm share** is the measured work W_atm over E_cap (the bound holds below 1).\n\
         - **KE step**: largest per-frame factor KE(n+1)/max(KE(n), ½M·(1 m/s)²) (information only).\n\
         - **NaN/Inf**: parcels removed by the non-finite guard plus frames with a non-finite state; \
         any fails the case. A panic fails it too (caught, not propagated).\n\
         - **escaped**: parcels that left through the sides / the top (of the domain or the profile).\n\
         - **clamps**: guards hit, by kind (see `physics::ClampCounts`); a kind the case does not \
         declare (listed under Cases) fails it.\n\
         - **uncapped**: a case that declares the `speed` clamp is run again with the 80 m/s cap \
         off; its KE ratio and fastest parcel are shown, and a NaN/Inf, panic or KE ratio above \
         the bound there fails the case whatever the capped run did (the cap alone bounds the \
         kinetic energy; only this run shows the motion is bounded without it). – for other cases.\n\
         - **wall/sub-step**: wall-clock time in the physics stages per sub-step (the harness's \
         set-up and energy sums left out).\n"
    );
    let _ = writeln!(
        s,
        "| case | dt (s) | frames | parcels start/peak | NaN/Inf | KE ratio | KE step | e_phys (J/kg) | W_atm share | max speed (m/s) | escaped sides/top | sub-steps | clamps | uncapped KE ratio / max speed | wall (s) | wall/sub-step (ms) | result |"
    );
    let _ = writeln!(
        s,
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|---:|---:|---|"
    );
    for r in results {
        let _ = writeln!(
            s,
            "| {} | {} | {}/{} | {}/{} | {} | {:.3} | {:.3e} | {:.0} | {:.2} | {:.1} | {}/{} | {} | {} | {} | {:.2} | {:.2} | {} |",
            r.name,
            r.frame_dt_s,
            r.frames_run,
            r.frames,
            r.parcels_start,
            r.parcels_peak,
            r.non_finite,
            r.ke_ratio,
            r.ke_step_growth,
            r.e_phys_j_per_kg,
            r.atm_work_share,
            r.max_speed_m_s,
            r.escaped_sides,
            r.escaped_top,
            r.substeps,
            clamp_summary(&r.clamps),
            uncapped_cell(r),
            r.wall_s,
            r.wall_per_substep_ms(),
            verdict(r)
        );
    }
    let _ = writeln!(s, "\n## Cases\n");
    for r in results {
        let declared = if r.declared_clamps.is_empty() {
            "none".to_string()
        } else {
            r.declared_clamps.join(", ")
        };
        let _ = writeln!(
            s,
            "- `{}` ({}): {}; declared clamps: {declared}",
            r.name, r.group, r.note
        );
    }
    s
}

/// The CSV report: one row per case, every clamp kind in its own column.
pub fn to_csv(results: &[CaseResult]) -> String {
    let mut s = String::from(
        "case,group,frame_dt_s,frames,frames_run,parcels_start,parcels_peak,completed,panic,non_finite,ke_max_j,ke_ratio,ke_step_growth,e_phys_j_per_kg,atm_work_j,atm_work_share,max_speed_m_s,escaped_sides,escaped_top,substeps",
    );
    for (k, _) in ClampCounts::default().kinds() {
        let _ = write!(s, ",clamp_{k}");
    }
    s.push_str(",uncapped_completed,uncapped_non_finite,uncapped_ke_ratio,uncapped_max_speed_m_s");
    s.push_str(",wall_s,wall_ms_per_substep,passed,failures\n");
    let quote = |t: &str| format!("\"{}\"", t.replace('"', "\"\""));
    for r in results {
        let _ = write!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{:.6e},{:.6},{:.6e},{:.3},{:.6e},{:.4},{:.3},{},{},{}",
            r.name,
            r.group,
            r.frame_dt_s,
            r.frames,
            r.frames_run,
            r.parcels_start,
            r.parcels_peak,
            r.completed,
            quote(r.panic.as_deref().unwrap_or("")),
            r.non_finite,
            r.ke_max_j,
            r.ke_ratio,
            r.ke_step_growth,
            r.e_phys_j_per_kg,
            r.atm_work_j,
            r.atm_work_share,
            r.max_speed_m_s,
            r.escaped_sides,
            r.escaped_top,
            r.substeps
        );
        for (_, n) in r.clamps.kinds() {
            let _ = write!(s, ",{n}");
        }
        // Empty for a case without the uncapped rerun.
        match &r.uncapped {
            Some(u) => {
                let _ = write!(
                    s,
                    ",{},{},{:.6},{:.3}",
                    u.completed, u.non_finite, u.ke_ratio, u.max_speed_m_s
                );
            }
            None => s.push_str(",,,,"),
        }
        let _ = writeln!(
            s,
            ",{:.3},{:.3},{},{}",
            r.wall_s,
            r.wall_per_substep_ms(),
            r.passed(),
            quote(&r.failures().join("; "))
        );
    }
    s
}

/// Writes `stability.md` and `stability.csv` into `dir` (created if
/// needed), each atomically; returns their paths.
pub fn write_reports(dir: &Path, results: &[CaseResult], title: &str) -> Result<[PathBuf; 2]> {
    let md = dir.join("stability.md");
    let csv = dir.join("stability.csv");
    crate::output::write_atomic(&md, to_markdown(results, title).as_bytes())?;
    crate::output::write_atomic(&csv, to_csv(results).as_bytes())?;
    Ok([md, csv])
}
