//! The physics speed table of `cumulus bench`: wall time of one physics
//! sub-step (all terms on) of jittered lattices of overlapping parcels
//! (`physics::scale_bench`, the same worlds as `benches/physics.rs`), on
//! all of rayon's threads. The scale goals are 10 000 parcels ≤ 10 ms and
//! 100 000 ≤ 100 ms per sub-step on the 2-core machine.

use std::fmt::Write as _;

use crate::error::Result;
use crate::physics::scale_bench::{lattice_world, substep_ms};

/// One row: a parcel count and its median sub-step time.
#[derive(Debug, Clone, PartialEq)]
pub struct PhysicsSpeedRow {
    pub parcels: usize,
    /// rayon threads the physics ran on.
    pub threads: usize,
    /// Median wall time of one sub-step. units: ms
    pub substep_ms: f64,
    /// The goal for this count, where the project sets one. units: ms
    pub goal_ms: Option<f64>,
}

/// The goal of a count: 1 ms per 1000 parcels at 10 000 and 100 000.
fn goal_ms(parcels: usize) -> Option<f64> {
    matches!(parcels, 10_000 | 100_000).then(|| parcels as f64 / 1000.0)
}

/// Measures each count: `repeats` sub-steps, each on a fresh copy.
pub fn physics_speed(
    counts: &[usize],
    repeats: usize,
    mut tick: impl FnMut(&str),
) -> Result<Vec<PhysicsSpeedRow>> {
    counts
        .iter()
        .map(|&n| {
            tick(&format!("physics speed, {n} parcels"));
            let w = lattice_world(n)?;
            Ok(PhysicsSpeedRow {
                parcels: n,
                threads: rayon::current_num_threads(),
                substep_ms: substep_ms(&w, repeats),
                goal_ms: goal_ms(n),
            })
        })
        .collect()
}

/// The Markdown section.
pub fn physics_speed_md(rows: &[PhysicsSpeedRow]) -> String {
    let mut s = String::from(
        "\n### Physics speed\n\n\
         One physics sub-step (all terms on) of a jittered lattice of overlapping parcels \
         (spacing 250 m, radius 150 m), median of fresh copies, on all threads \
         (`benches/physics.rs` measures the same worlds with criterion).\n\n\
         | parcels | threads | ms per sub-step | goal ms | meets goal |\n|---:|---:|---:|---:|:---:|\n",
    );
    for r in rows {
        let (goal, ok) = match r.goal_ms {
            Some(g) => (format!("{g}"), if r.substep_ms <= g { "yes" } else { "no" }),
            None => ("–".into(), ""),
        };
        let _ = writeln!(
            s,
            "| {} | {} | {:.2} | {goal} | {ok} |",
            r.parcels, r.threads, r.substep_ms
        );
    }
    s
}

/// physics_speed.csv.
pub fn physics_speed_csv(rows: &[PhysicsSpeedRow]) -> Vec<u8> {
    let mut s = String::from("parcels,threads,substep_ms,goal_ms\n");
    for r in rows {
        let goal = r.goal_ms.map(|g| g.to_string()).unwrap_or_default();
        let _ = writeln!(s, "{},{},{:.4},{goal}", r.parcels, r.threads, r.substep_ms);
    }
    s.into_bytes()
}
