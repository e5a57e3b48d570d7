//! The parcel physics: single parcels, the world, the paper's equations,
//! convergence order, thread-count determinism, the moist ascent against
//! parcel theory, `cumulus simulate`, the stability matrix, and the two
//! LES intercomparison cases (BOMEX, ARM SGP).

mod cli;
mod entrainment;
mod fidelity;
mod les;
mod les_arm;
mod moist_ascent;
mod order;
mod scale;
mod single;
mod stability;
mod world;
