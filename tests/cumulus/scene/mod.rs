//! Scenes: `--set` overrides, the pre-simulated start, and the landscape.

mod landscape;
mod set;
mod start;
